"""The Magic Formula curve and the small numeric helpers of the MF 6.1 / 5.2 kernel (pure numpy).

:func:`sin_curve` and :func:`cos_curve` are the basic curve of docs/models/magic_formula_tyre.md §5, §13.1
and its cosine version (weighting functions, trail); the helpers around them (signs, guarded denominators,
scaling that skips a factor of 1, in-place arithmetic on the caller's own temporaries) are shared by the
equations of :mod:`~tirecli.models.magic_formula.pure`, :mod:`~tirecli.models.magic_formula.combined`, :mod:`~tirecli.models.magic_formula.aligning`
and the kernel :mod:`~tirecli.models.magic_formula.mf61`.
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula.tire import Convention


def _sgn(x, zero: float):
    """sgn(x) with sgn(0) = ``zero`` (+1: mfeval's ``x >= 0 ? 1 : -1``; 0: MATLAB ``sign``)."""
    if zero == 1.0:
        return np.copysign(1.0, x + 0.0)  # + 0.0 turns -0.0 into +0.0
    return np.sign(x)


def _guard(x, eps: float):
    """``x + eps sgn(x)`` (book 4.E6a): a denominator kept away from zero with its own sign."""
    return x + np.copysign(eps, x)


def _scale(x, s: float):
    """``x * s``, skipping the work when the factor is exactly 1 (scaling factors, zeta)."""
    return x if s == 1.0 else x * s


def _lin(a0: float, a1: float, x):
    """``a0 + a1 x`` (a load polynomial), a plain number when ``a1 = 0``."""
    return a0 if a1 == 0.0 else a0 + a1 * x


def _inplace_ok(base, *others) -> bool:
    return np.ndim(base) > 0 and all(np.size(o) <= np.size(base) for o in others)


def _curve_angle(B, E, x):
    """``arctan(Bx - E(Bx - arctan(Bx)))`` [rad]: the inner angle of the Magic Formula (§5)."""
    bx = np.multiply(B, x)
    if not _inplace_ok(bx, E):
        return np.arctan(bx - E * (bx - np.arctan(bx)))
    a = np.arctan(bx)
    np.subtract(bx, a, out=a)
    np.multiply(a, E, out=a)
    np.subtract(bx, a, out=a)
    return np.arctan(a, out=a)


def sin_curve(B, C, D, E, x):
    """The Magic Formula ``y = D sin(C arctan(Bx - E(Bx - arctan Bx)))`` (§5, §13.1)."""
    a = _curve_angle(B, E, x)
    if not _inplace_ok(a, C, D):
        return D * np.sin(C * a)
    np.multiply(a, C, out=a)
    np.sin(a, out=a)
    return np.multiply(a, D, out=a)


def cos_curve(B, C, E, x):
    """The cosine version ``cos(C arctan(Bx - E(Bx - arctan Bx)))`` (weighting functions, trail)."""
    a = _curve_angle(B, E, x)
    if not _inplace_ok(a, C):
        return np.cos(C * a)
    np.multiply(a, C, out=a)
    return np.cos(a, out=a)


def _cos_atan(x):
    """``cos(arctan(x)) = 1/sqrt(1 + x^2)`` (exact identity, cheaper than two trig calls)."""
    return 1.0 / np.sqrt(1.0 + np.square(x))


def _clip_e(E, cv: Convention):
    return np.minimum(E, 1.0) if cv.e_clip else E


def _is_zero(x) -> bool:
    return np.ndim(x) == 0 and x == 0


def _own(a, b) -> bool:
    return isinstance(a, np.ndarray) and a.ndim > 0 and np.size(b) <= a.size


def _imul(a, b):
    """``a * b``, in place when ``a`` is a full-size array owned by the caller."""
    return np.multiply(a, b, out=a) if _own(a, b) else a * b


def _iadd(a, b):
    return np.add(a, b, out=a) if _own(a, b) else a + b


def _isub(a, b):
    return np.subtract(a, b, out=a) if _own(a, b) else a - b
