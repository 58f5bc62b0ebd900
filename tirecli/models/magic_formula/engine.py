"""Evaluate a Magic Formula tyre over arrays that broadcast like numpy (the public entry point).

:func:`evaluate` takes ``(kappa, alpha, gamma, fz, vx, p)`` (and optionally the turn slip
``phit``), broadcasts them, mirrors a tyre used on the other side (§2.4), applies the limits and
low-speed rules (§11), and evaluates MF 6.1 / 6.2 / 5.2 (:mod:`.mf61`) or PAC89 (:mod:`.pac89`).
Large inputs are split into blocks that fit the CPU cache and evaluated on a small thread pool
(numpy releases the GIL inside its loops); scalar inputs stay scalars inside each block, so
load-dependent terms of a sweep at fixed load are computed once. Results are identical whatever
the block size or number of threads (every operation is elementwise).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.models.magic_formula import inputs as _inputs
from tirecli.models.magic_formula.axes import mirror_outputs, needs_mirror
from tirecli.models.magic_formula.mf61 import evaluate_kernel
from tirecli.models.magic_formula.pac89 import evaluate_pac89
from tirecli.models.magic_formula.tire import Convention, MFTire, get_convention
from tirecli.parallel import default_threads, thread_pool

#: Outputs of :func:`evaluate`, in the order of ``tirecli mf eval``'s CSV.
OUTPUTS = ("fx", "fy", "mz", "mx", "my")

#: Points per block (about 0.5 MB per float64 temporary: stays in L2/L3 cache).
BLOCK = 16384

@dataclass
class MFResult:
    """Outputs of :func:`evaluate` (ISO-W, SI) and what the input rules did.

    Attributes
    ----------
    fx, fy : ndarray
        Longitudinal and lateral force [N].
    mz, mx, my : ndarray
        Aligning, overturning and rolling-resistance moments [N m].
    counts : dict
        Counter name -> number of points touched (:data:`~.inputs.COUNTERS`).
    outside : dict
        Input -> number of points evaluated outside the tyre's ranges (with ``limits=False``: an
        extrapolation, :data:`~.inputs.OUTSIDE`), and loads above 10 FNOMIN of a tyre without
        ``FZMAX`` (far beyond any fit); empty when none is.
    mirrored : bool
        Whether the tyre was mirrored to the other side (§2.4).
    convention : str
        Name of the convention used.
    """

    fx: np.ndarray | None = None
    fy: np.ndarray | None = None
    mz: np.ndarray | None = None
    mx: np.ndarray | None = None
    my: np.ndarray | None = None
    counts: dict = field(default_factory=dict)
    mirrored: bool = False
    convention: str = "mfeval"
    outside: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in OUTPUTS if getattr(self, k) is not None}

    @property
    def touched(self) -> int:
        """Largest count of any rule (a lower bound of the points touched by the input rules)."""
        return max(self.counts.values(), default=0)


def _as_input(x, shape, n):
    a = np.asarray(x, dtype=float)
    if a.size == 1:
        return float(a.reshape(()))
    if a.shape == shape and a.flags.c_contiguous:
        return a.reshape(n)
    return np.broadcast_to(a, shape).reshape(n)  # copies a broadcast view


def _block(t, cv, vals, need, limits, low_speed, combined, lo, hi, outs):
    sl = slice(lo, hi)
    kappa, alpha, gamma, fz, vx, p, phit = (v[sl] if isinstance(v, np.ndarray) else v for v in vals)
    # overflow far outside a tyre's ranges gives inf/NaN, reported by the callers with the point
    # (never as numpy's warnings on stderr); errstate is per thread, so it is set in each block
    with np.errstate(all="ignore"):
        pr = _inputs.prepare(t, kappa, alpha, gamma, fz, vx, p, phit, limits, low_speed, need_my="my" in need)
        if t.family == "pac89":
            res = evaluate_pac89(t, pr.kappa, pr.alpha, pr.gamma, pr.fz, need)
        else:
            res = evaluate_kernel(t, cv, pr.kappa, pr.alpha, pr.gamma, pr.fz, pr.vx, pr.p, need, phit=pr.phit,
                                  combined=combined, **pr.kernel)
    for k in need:
        outs[k][sl] = res[k]
    return pr.counts


def evaluate(tire: MFTire, kappa=0.0, alpha=0.0, gamma=0.0, fz=None, vx=None, p=None, phit=None, *,
             convention: str | Convention = "mfeval", alpha_star: bool = False, side: str | None = None,
             limits: bool = True, low_speed: bool | None = None, outputs=OUTPUTS, combined: bool = True,
             threads: int | None = None, block: int = BLOCK) -> MFResult:
    """Forces and moments of a Magic Formula tyre, ISO-W, combined slip (docs/models/magic_formula_tyre.md §5-§9, §13).

    Parameters
    ----------
    tire : MFTire
    kappa : array_like
        Longitudinal slip ``(Omega R_e - Vx)/|Vx|`` [-] (ISO-W, > 0 driving).
    alpha : array_like
        Slip angle [rad] (ISO-W: positive alpha gives negative Fy).
    gamma : array_like
        Inclination angle [rad].
    fz : array_like or None
        Vertical load [N], > 0 in compression (default ``FNOMIN``).
    vx : array_like or None
        Forward speed of the contact centre [m/s] (default ``LONGVL``).
    p : array_like or None
        Inflation pressure [Pa] (default ``INFLPRES``, else ``NOMPRES``; no effect in MF 5.2/PAC89).
    phit : array_like or None
        Turn slip [1/m] (§8, MF 6.x only); None: no turn slip.
    convention : str or Convention
        ``mfeval`` (default; §10 "Recommended here") or ``teasit`` (§15.2, the golden data).
    alpha_star : bool
        Use the book's alpha* = tan(alpha) sgn(Vx) and gamma* = sin(gamma) (mfeval's option).
    side : {"left", "right"} or None
        Side the tyre is mounted on; mirrored when it differs from the file's ``TYRESIDE``.
    limits : bool
        Clip inputs to the tyre's ranges (§11).
    low_speed : bool or None
        Low-speed handling of §11 (default: same as ``limits``).
    outputs : iterable of str
        Subset of ``fx, fy, mz, mx, my`` to compute.
    combined : bool
        Combined slip (default); False gives the pure-slip ``Fx0(kappa)``, ``Fy0(alpha)``,
        ``Mz0(alpha)`` each from its own slip (PAC89 is always uncombined).
    threads : int or None
        Worker threads for inputs larger than one block (default :func:`default_threads`).
    block : int
        Points per block.

    Returns
    -------
    MFResult
        Arrays of the broadcast shape of the inputs.
    """
    cv = get_convention(convention)
    if alpha_star:
        cv = cv.with_alpha_star()
    if low_speed is None:
        low_speed = limits
    need = tuple(k for k in OUTPUTS if k in set(outputs))
    unknown = set(outputs) - set(OUTPUTS)
    if unknown:
        raise ValueError(f"unknown output(s) {sorted(unknown)} (expected some of {OUTPUTS})")
    c = tire.coef
    if tire.family == "pac89":
        fz = 4000.0 if fz is None and "FNOMIN" not in c else (c.get("FNOMIN") if fz is None else fz)
        vx = 0.0 if vx is None else vx
        p = None
    else:
        fz = c["FNOMIN"] if fz is None else fz
        if vx is None:
            if tire.reference_speed is None:
                raise ValueError("no speed given and the tyre has no LONGVL")
            vx = tire.reference_speed
        if tire.nominal_pressure is None:
            p = None
        elif p is None:
            p = tire.default_pressure
    if phit is not None and (tire.family != "mf" or tire.is_52):
        raise ValueError(f"turn slip needs an MF 6.x tyre (this one is {tire.version}; §8)")
    mirrored = needs_mirror(tire.side, side)
    if mirrored:
        alpha = -np.asarray(alpha, dtype=float)
        gamma = -np.asarray(gamma, dtype=float)
    raw = [kappa, alpha, gamma, fz, vx] + ([p] if p is not None else []) + ([phit] if phit is not None else [])
    shape = np.broadcast_shapes(*(np.shape(x) for x in raw))
    n = math.prod(shape)
    vals = [_as_input(x, shape, n) for x in (kappa, alpha, gamma, fz, vx)]
    vals.append(None if p is None else _as_input(p, shape, n))
    vals.append(None if phit is None else _as_input(phit, shape, n))
    outs = {k: np.empty(n) for k in need}
    starts = list(range(0, max(n, 1), block)) if n else []
    nthreads = default_threads() if threads is None else max(1, int(threads))
    if len(starts) <= 1 or nthreads == 1:
        counts_list = [_block(tire, cv, vals, need, limits, low_speed, combined, s, min(s + block, n), outs)
                       for s in starts]
    else:
        pool = thread_pool(nthreads)
        futs = [pool.submit(_block, tire, cv, vals, need, limits, low_speed, combined, s, min(s + block, n), outs)
                for s in starts]
        counts_list = [f.result() for f in futs]
    counts: dict = {}
    for cl in counts_list:
        for k, v in cl.items():
            counts[k] = counts.get(k, 0) + v
    res = {k: v.reshape(shape) for k, v in outs.items()}
    if mirrored:
        mirror_outputs(res)
    outside = _inputs.outside_ranges(tire, vals, limits, n)
    return MFResult(**res, counts=counts, mirrored=mirrored, convention=cv.name, outside=outside)


def nonfinite_point(tire, res, inputs: dict, limits: bool):
    """The first point where an output of ``res`` (an :class:`MFResult` of ``tire``) is not finite: ``(index, text, input_at_fault)``, or None.

    ``inputs`` maps ``kappa, alpha, gamma, fz, vx, p`` to arrays (or scalars, or None) broadcast like
    the outputs. The text names the outputs, the point's inputs and, when an input lies outside the
    tyre's ranges (or a load is far above FNOMIN), that input: then the input is at fault (exit 2),
    else the tyre's coefficients are (a run failure).
    """
    outs = [k for k in OUTPUTS if getattr(res, k) is not None]
    shape = np.shape(getattr(res, outs[0])) if outs else ()
    bad = np.zeros(shape, dtype=bool)
    for k in outs:
        bad |= ~np.isfinite(getattr(res, k))
    if not bad.any():
        return None
    i = int(np.flatnonzero(bad.ravel())[0])

    def at(x):
        if x is None:
            return None
        a = np.broadcast_to(np.asarray(x, dtype=float), shape).ravel()
        return float(a[i])

    vals = {k: at(v) for k, v in inputs.items()}
    which = [k for k in outs if not np.isfinite(np.asarray(getattr(res, k)).ravel()[i])]
    units = {"kappa": "", "alpha": " rad", "gamma": " rad", "fz": " N", "vx": " m/s", "p": " Pa"}
    point = ", ".join(f"{k} = {v:g}{units[k]}" for k, v in vals.items() if v is not None)
    why = []
    names = {"fz": ("load", "FZMIN", "FZMAX"), "kappa": ("slip", "KPUMIN", "KPUMAX"),
             "alpha": ("slip angle", "ALPMIN", "ALPMAX"), "gamma": ("inclination", "CAMMIN", "CAMMAX"),
             "p": ("pressure", "PRESMIN", "PRESMAX")}
    for k, (what, lo_key, hi_key) in names.items():
        v = vals.get(k)
        if v is None or (k == "p" and not tire.nominal_pressure):
            continue
        lo, hi = tire.coef.get(lo_key), tire.coef.get(hi_key)
        if hi is not None and v > hi:
            why.append(f"the {what} is above {hi_key} = {hi:g}{units[k]}")
        elif lo is not None and v < lo:
            why.append(f"the {what} is below {lo_key} = {lo:g}{units[k]}")
    fnom = tire.coef.get("FNOMIN")
    if vals.get("fz") is not None and fnom and vals["fz"] > 10 * fnom and not any(w.startswith("the load") for w in why):
        why.append(f"the load is {vals['fz'] / fnom:.3g} x FNOMIN ({fnom:g} N)")
    n = int(bad.sum())
    text = f"the Magic Formula gives no finite {', '.join(which)} at {point}"
    if n > 1:
        text += f" (and at {n - 1} more point(s))"
    if why:
        mode = " with the limits off" if not limits else ""
        text += f": {'; '.join(why)}, beyond what the tyre can evaluate{mode}"
    else:
        text += ": the tyre's coefficients give no finite value there"
    return i, text, bool(why)
