"""Find the sweeps of a measured tyre data table and name them (a pure helper on the channel table).

A rig measures sweeps: the slip ratio ``kappa`` (pure longitudinal) or the slip angle ``alpha`` (pure
lateral) swept at a held load, camber, pressure and speed, or one of them swept with the other held
at a non-zero value (combined). :func:`find_sweeps` cuts a table (:mod:`tirecli.io.measured`) into
contiguous segments and classifies each:

1. a new segment starts where the measurement number ``run`` changes, where a held condition jumps
   (``fz`` by more than 10 % of its median magnitude, ``gamma`` by more than 0.5 deg, ``p`` by more than 5 %,
   ``vx`` by more than 5 % or 1 m/s between two rows; noise of a few percent does not cut), or where a
   slip jumps by more than a quarter of its span over the table (the rig resetting between sweeps);
2. a segment holding pure longitudinal rows and pure lateral rows but no combined ones is cut where one
   kind follows the other;
3. each segment is classified from robust ranges (2nd to 98th percentile): a slip *varies* when its
   range exceeds 0.02 (``kappa``) or 1 deg (``alpha``) and is *zero* when its largest magnitude stays below
   0.01 or 0.5 deg. A missing slip channel counts as zero.

Kinds: ``pure longitudinal`` (kappa varies, alpha zero), ``pure lateral`` (alpha varies, kappa zero),
``combined`` (one varies, the other is held non-zero, or both vary), ``steady`` (neither varies),
``other`` (the load or the camber varies within the segment: a load or camber sweep).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: Kinds of sweep, in the order :func:`summary` lists them.
KINDS = ("pure longitudinal", "pure lateral", "combined", "steady", "other")

_DEG = math.pi / 180.0
#: Thresholds (see the module docstring).
KAPPA_VARIES, ALPHA_VARIES = 0.02, 1.0 * _DEG
KAPPA_ZERO, ALPHA_ZERO = 0.01, 0.5 * _DEG
GAMMA_STEP, GAMMA_VARIES = 0.5 * _DEG, 1.0 * _DEG
FZ_STEP, P_STEP, VX_STEP, VX_MIN_STEP = 0.10, 0.05, 0.05, 1.0


@dataclass
class Sweep:
    """One segment of a table (rows ``start`` to ``stop - 1``).

    ``fz``, ``gamma``, ``p``, ``vx`` are medians over the segment (None where the table lacks the
    channel); ``swept`` names the slip that varies (``kappa``, ``alpha``, ``kappa+alpha`` or ``""``) and
    ``lo``/``hi`` its range; ``held`` gives the other slip's median where it is held non-zero.
    """

    kind: str
    start: int
    stop: int
    run: float | None = None
    fz: float | None = None
    gamma: float | None = None
    p: float | None = None
    vx: float | None = None
    swept: str = ""
    lo: float = 0.0
    hi: float = 0.0
    held: dict = field(default_factory=dict)

    @property
    def rows(self) -> int:
        return self.stop - self.start


def _col(frame, name):
    return frame[name].to_numpy(dtype=float) if name in frame.columns else None


def _span(x) -> float:
    lo, hi = np.percentile(x, [2, 98])
    return float(hi - lo)


def _reach(x) -> float:
    """The robust largest magnitude (98th percentile of |x|)."""
    return float(np.percentile(np.abs(x), 98))


def _cuts(frame) -> np.ndarray:
    """Row indices where a new segment starts (step 1 of the module docstring), 0 first."""
    n = len(frame)
    cut = np.zeros(n, dtype=bool)
    cut[0] = True
    run = _col(frame, "run")
    if run is not None:
        cut[1:] |= run[1:] != run[:-1]
    fz = _col(frame, "fz")
    if fz is not None and n:
        scale = max(float(np.median(np.abs(fz))), 1.0)
        cut[1:] |= np.abs(np.diff(fz)) > FZ_STEP * scale
    gamma = _col(frame, "gamma")
    if gamma is not None:
        cut[1:] |= np.abs(np.diff(gamma)) > GAMMA_STEP
    p = _col(frame, "p")
    if p is not None:
        cut[1:] |= np.abs(np.diff(p)) > P_STEP * np.maximum(np.abs(p[:-1]), 1.0)
    vx = _col(frame, "vx")
    if vx is not None:
        cut[1:] |= np.abs(np.diff(vx)) > np.maximum(VX_STEP * np.abs(vx[:-1]), VX_MIN_STEP)
    for name in ("kappa", "alpha"):
        x = _col(frame, name)
        if x is not None and n > 1:
            span = _span(x)
            if span > 0:
                cut[1:] |= np.abs(np.diff(x)) > 0.25 * span
    return np.flatnonzero(cut)


def _split_pure(kappa, alpha, start: int, stop: int) -> list[int]:
    """Starts of the pieces of a segment that holds pure longitudinal and pure lateral rows but no
    combined ones (step 2): a piece starts at the first row of the other kind."""
    k = np.abs(kappa[start:stop]) > KAPPA_ZERO
    a = np.abs(alpha[start:stop]) > ALPHA_ZERO
    both = k & a
    if both.mean() > 0.05 or not (k & ~a).any() or not (a & ~k).any():
        return [start]
    kind = np.where(k & ~a, 1, np.where(a & ~k, 2, 0))
    active = np.flatnonzero(kind)
    changes = active[1:][kind[active[1:]] != kind[active[:-1]]]
    return [start, *(start + int(c) for c in changes)]


def _classify(frame, start: int, stop: int, cols: dict) -> Sweep:
    sl = slice(start, stop)
    kappa = cols["kappa"][sl]
    alpha = cols["alpha"][sl]
    med = {k: (None if cols.get(k) is None else float(np.median(cols[k][sl]))) for k in ("fz", "gamma", "p", "vx", "run")}
    s = Sweep("steady", start, stop, med["run"], med["fz"], med["gamma"], med["p"], med["vx"])
    k_var, a_var = _span(kappa) > KAPPA_VARIES, _span(alpha) > ALPHA_VARIES
    k_zero, a_zero = _reach(kappa) < KAPPA_ZERO, _reach(alpha) < ALPHA_ZERO
    fz, gamma = cols.get("fz"), cols.get("gamma")
    if (fz is not None and _span(fz[sl]) > 0.2 * max(abs(med["fz"]), 1.0)) or \
            (gamma is not None and _span(gamma[sl]) > GAMMA_VARIES):
        s.kind = "other"
    elif k_var and a_zero:
        s.kind = "pure longitudinal"
    elif a_var and k_zero:
        s.kind = "pure lateral"
    elif k_var or a_var:
        s.kind = "combined"
    if k_var and not a_var:
        s.swept, x = "kappa", kappa
        if not a_zero:
            s.held["alpha"] = float(np.median(alpha))
    elif a_var and not k_var:
        s.swept, x = "alpha", alpha
        if not k_zero:
            s.held["kappa"] = float(np.median(kappa))
    elif k_var and a_var:
        s.swept, x = "kappa+alpha", kappa
    else:
        x = None
    if x is not None:
        s.lo, s.hi = float(x.min()), float(x.max())
    return s


def find_sweeps(frame) -> list[Sweep]:
    """The sweeps of a channel table (a DataFrame with canonical column names), in row order."""
    n = len(frame)
    if n == 0:
        return []
    zeros = np.zeros(n)
    cols = {k: _col(frame, k) for k in ("fz", "gamma", "p", "vx", "run")}
    cols["kappa"] = _col(frame, "kappa") if "kappa" in frame.columns else zeros
    cols["alpha"] = _col(frame, "alpha") if "alpha" in frame.columns else zeros
    starts = list(_cuts(frame))
    bounds = []
    for a, b in zip(starts, [*starts[1:], n]):
        pieces = _split_pure(cols["kappa"], cols["alpha"], int(a), int(b))
        bounds += list(zip(pieces, [*pieces[1:], int(b)]))
    return [_classify(frame, a, b, cols) for a, b in bounds]


def summary(sweeps) -> dict:
    """``{kind: number of sweeps}`` for the kinds present, in :data:`KINDS` order."""
    out = {}
    for kind in KINDS:
        k = sum(s.kind == kind for s in sweeps)
        if k:
            out[kind] = k
    return out


__all__ = ["Sweep", "find_sweeps", "summary", "KINDS"]
