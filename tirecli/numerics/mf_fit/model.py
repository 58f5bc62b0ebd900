"""The model of one fit stage: one channel of the Magic Formula at the stage's points, for trial coefficients.

:class:`StageModel` is :func:`tirecli.models.magic_formula.evaluate` cut to what a least-squares loop
needs. The inputs are limited once (:func:`tirecli.models.magic_formula.inputs.prepare`, which depends on
the ranges and ``VXLOW`` only, never on a fitted coefficient). Then, by the stage's ``kind``:

``fx0``, ``fy0``
    :func:`~tirecli.models.magic_formula.mf61.evaluate_kernel` for the pure-slip force
    (``combined=False``), every call;
``gxa``, ``gyk``, ``mz``
    the orchestration of :func:`~tirecli.models.magic_formula.mf61.evaluate_kernel` (combined slip)
    inlined: the parts the stage cannot change (``Fx0``, ``Fy0`` and their factors, and for ``mz``
    the combined ``Fx`` and ``Fy``) are computed once with the fixed coefficients, and each call
    evaluates only ``Fx = Fx0 G_xa`` (:func:`~.combined.g_xa`), ``Fy = G_yk Fy0 + S_Vyk``
    (:func:`~.combined.g_yk`, :func:`~.combined.sv_yk`) or ``Mz`` (``aligning._mz``, given the zero-camber Fy0
    of ``aligning._fy0_zero_camber`` computed once).

No equation is copied: the values are those of ``evaluate(tire, ..., outputs=(channel,), combined=...)``
at the same points (tests/test_mf_fit.py checks every kind to 1e-12 relative), as long as only the
stage's own coefficients change between calls (the cached parts hold the others). Large inputs are
split into blocks evaluated on the evaluator's thread pool, as ``evaluate`` does.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tirecli.models.magic_formula import inputs as _inputs
from tirecli.models.magic_formula import aligning, combined, mf61, pure, state
from tirecli.models.magic_formula.curve import _is_zero
from tirecli.models.magic_formula.tire import MFTire, get_convention
from tirecli.parallel import default_threads, thread_pool

#: Points per block (a Jacobian column of a large stage runs its blocks on two or more threads).
BLOCK = 8192

#: Stage kinds: the channel and whether the model is evaluated with combined slip.
KINDS = {"fx0": ("fx", False), "fy0": ("fy", False), "gxa": ("fx", True), "gyk": ("fy", True),
         "mz": ("mz", True)}


class StageModel:
    """The channel of a stage ``kind`` at fixed points as a function of the stage's coefficients.

    Parameters
    ----------
    tire : MFTire
        The tyre whose other coefficients (and ranges) hold.
    points : dict
        ``kappa, alpha, gamma, fz, vx`` arrays [-, rad, rad, N, m/s] and ``p`` [Pa] (or None).
    kind : str
        ``fx0``, ``fy0`` (pure slip), ``gxa`` (combined Fx), ``gyk`` (combined Fy), ``mz`` (combined Mz).
    convention : str
        ``mfeval`` or ``teasit`` (as in ``evaluate``).
    """

    def __init__(self, tire: MFTire, points: dict, kind: str, convention: str = "mfeval", block: int = BLOCK):
        self.base = dict(tire.coef)
        self.version, self.side = tire.version, tire.side
        self.cv = get_convention(convention)
        self.kind = kind
        self.channel, self.combined = KINDS[kind]
        self.n = len(points["kappa"])
        self.blocks = []
        for lo in range(0, self.n, block):
            sl = slice(lo, min(lo + block, self.n))
            part = {k: (None if v is None else np.asarray(v, dtype=float)[sl]) for k, v in points.items()}
            with np.errstate(all="ignore"):
                pr = _inputs.prepare(tire, part["kappa"], part["alpha"], part["gamma"], part["fz"], part["vx"],
                                     part["p"], None, True, True, need_my=False)
                cache = _fixed_parts(tire, self.cv, pr, kind)
            self.blocks.append((sl, pr, cache))

    def tire(self, values: dict) -> MFTire:
        """The tyre with ``values`` (name -> value) replacing its coefficients."""
        coef = dict(self.base)
        coef.update(values)
        return MFTire(coef, self.version, self.side)

    def __call__(self, values: dict) -> np.ndarray:
        """The channel [N or N m] at every point for the coefficient ``values``."""
        t = self.tire(values)
        out = np.empty(self.n)
        if len(self.blocks) > 1 and default_threads() > 1:
            pool = thread_pool(default_threads())
            for f in [pool.submit(self._block, t, b, out) for b in self.blocks]:
                f.result()
        else:
            for b in self.blocks:
                self._block(t, b, out)
        return out

    def _block(self, t, block, out) -> None:
        sl, pr, cache = block
        with np.errstate(all="ignore"):
            out[sl] = _variable_part(t, self.cv, pr, self.kind, cache)


def _fixed_parts(t, cv, pr, kind):
    """What a stage of ``kind`` cannot change (evaluate_kernel's steps before the stage's own part)."""
    if kind in ("fx0", "fy0"):
        return None
    red = pr.kernel.get("red")
    c = SimpleNamespace()
    b = c.b = state.basic(t, cv, pr.kappa, pr.alpha, pr.gamma, pr.fz, pr.vx, pr.p)
    if kind in ("gxa", "mz"):
        c.fxf = pure.fx0_factors(t, cv, b, pr.fz, pr.gamma, 1.0, red)
        fx0 = pure.fx0_curve(t, cv, c.fxf, pr.kappa)
        c.fx0 = fx0 * b.sgn_vx if b.backward else fx0
    if kind in ("gyk", "mz"):
        c.L = pure.fy0_load(t, cv, b, pr.fz)
        c.fyf = pure.fy0_factors(t, cv, b, pr.fz, b.g_star, None, red, c.L)
        fy0 = pure.fy0_curve(t, cv, b, c.fyf, pr.alpha)
        c.fy0 = fy0 * b.sgn_vx if (b.backward and cv.alpha_star == "tan") else fy0
    if kind == "mz":
        c.fx = _gxa(t, cv, c, pr)
        c.gyk, c.svyk, c.fy = _gyk(t, cv, c, pr, red)
        c.fy0_zero = aligning._fy0_zero_camber(t, cv, b, pr.fz, pr.alpha, red, c.L)
    return c


def _gxa(t, cv, c, pr):
    return c.fx0 * combined.g_xa(t, cv, c.b, pr.kappa, c.b.g_star)


def _gyk(t, cv, c, pr, red):
    b = c.b
    gyk = combined.g_yk(t, cv, b, pr.kappa, b.g_star)
    svyk = combined.sv_yk(t, b, pr.kappa, pr.fz, c.fyf.mu, b.g_star, 1.0, red)
    fy = gyk * c.fy0
    if not _is_zero(svyk):
        fy = fy + svyk
    return gyk, svyk, fy


def _variable_part(t, cv, pr, kind, c):
    """The stage's own part of evaluate_kernel for the trial tyre ``t``."""
    if c is None:
        ch = KINDS[kind][0]
        return mf61.evaluate_kernel(t, cv, pr.kappa, pr.alpha, pr.gamma, pr.fz, pr.vx, pr.p, (ch,), combined=False,
                                    **pr.kernel)[ch]
    red = pr.kernel.get("red")
    if kind == "gxa":
        return _gxa(t, cv, c, pr)
    if kind == "gyk":
        return _gyk(t, cv, c, pr, red)[2]
    return aligning._mz(t, cv, c.b, pr.kappa, pr.alpha, pr.vx, pr.fz, pr.kernel.get("fz_mz"), c.fxf, c.fyf, c.L, c.fy0,
                    c.gyk, c.svyk, c.fx, c.fy, red, None, fy0_zero=c.fy0_zero)
