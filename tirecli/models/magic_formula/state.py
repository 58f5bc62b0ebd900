"""The normalised quantities shared by every output of the MF 6.1 / 5.2 kernel (docs/models/magic_formula_tyre.md §3).

:func:`basic` computes them once per block of points (``dfz``, ``dpi``, alpha*, gamma*, the friction
lambdas); :func:`_quad` is the load polynomial ``a0 + a1 dfz + a2 dfz^2`` over them.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tirecli.models.magic_formula.curve import _is_zero, _lin, _sgn
from tirecli.models.magic_formula.tire import Convention, MFTire


def basic(t: MFTire, cv: Convention, kappa, alpha, gamma, fz, vx, p):
    """Normalised quantities shared by every output (§3): ``dfz``, ``dpi``, alpha*, gamma*, lambdas.

    Returns a namespace with ``dfz`` (4.E2a), ``dpi`` (4.E2b; a plain 0 without pressure
    effect), ``a_fy`` (alpha used in Fy0), ``a_star`` (alpha* used in combined slip and Mz),
    ``g_star`` (gamma*), ``lmux_s``/``lmuy_s`` (lambda*, 4.E7), ``lmux_p``/``lmuy_p`` (lambda',
    4.E8) and ``sgn_vx``.
    """
    c = t.coef
    fz0p = c["FNOMIN"] * c["LFZO"]
    b = SimpleNamespace()
    b.fz0p = fz0p
    b.dfz = fz * (1.0 / fz0p) - 1.0
    b.dfz2 = None
    pi0 = t.nominal_pressure
    dpi = 0.0 if (pi0 is None or p is None) else (p - pi0) * (1.0 / pi0)
    b.dpi = 0.0 if not np.any(dpi) else dpi
    b.has_dpi = not _is_zero(b.dpi)
    backward = bool(np.any(vx < 0))
    b.backward = backward
    b.sgn_vx = _sgn(vx, 1.0) if backward else 1.0
    tan_a = None
    a_tan = None
    if cv.alpha_star in ("tan", "mixed"):
        tan_a = np.tan(alpha)
        a_tan = tan_a * b.sgn_vx if backward else tan_a
    b.a_fy = a_tan if cv.alpha_star == "tan" else alpha
    b.a_star = alpha if cv.alpha_star == "alpha" else a_tan
    b.g_star = np.sin(gamma) if cv.gamma_sin else gamma
    b.gamma = gamma
    b.has_camber = bool(np.any(gamma != 0))
    lmux, lmuy = c["LMUX"], c["LMUY"]
    if c.get("LMUV", 0.0):
        v0 = t.reference_speed
        ta = np.tan(alpha) if tan_a is None else tan_a
        vs = np.abs(vx) * np.sqrt(np.square(kappa) + np.square(ta))  # |V_s| = |Vx| sqrt(kappa^2 + tan^2)
        den = 1.0 + c["LMUV"] * vs / v0
        b.lmux_s, b.lmuy_s = lmux / den, lmuy / den
    else:
        b.lmux_s, b.lmuy_s = lmux, lmuy
    am = cv.a_mu
    if am == 1.0:
        b.lmux_p, b.lmuy_p = b.lmux_s, b.lmuy_s
    else:
        b.lmux_p = am * b.lmux_s / (1.0 + (am - 1.0) * b.lmux_s)
        b.lmuy_p = am * b.lmuy_s / (1.0 + (am - 1.0) * b.lmuy_s)
    return b


def _dfz2(b):
    if b.dfz2 is None:
        b.dfz2 = np.square(b.dfz)
    return b.dfz2


def _quad(a0, a1, a2, b):
    """``a0 + a1 dfz + a2 dfz^2``."""
    y = _lin(a0, a1, b.dfz)
    return y if a2 == 0.0 else y + a2 * _dfz2(b)
