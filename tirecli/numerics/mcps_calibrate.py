"""Calibration of the MCPS parameters to a Magic Formula tyre (docs/models/mcps_tire.md §8, procedure assumed).

:func:`calibrate_to_mf` is *the* calibration to the tyre that is drawn: it fits MCPS to the Magic
Formula curves on the drawn grids and returns the calibrated set together with its own curves, gaps
(:func:`tirecli.numerics.gaps.curve_gap`), aligning-torque peaks and the parameters that ended on a
bound, so that what a figure draws and what a card quotes are the same numbers. Two bounded
least-squares fits (``scipy.optimize.least_squares``, trust-region reflective), each model's own
output (ISO-W, road on tire; never a mirrored curve), residuals over the reference peak magnitude:

1. ``(r_x, mu_x, alpha_x, beta_x)`` on the Magic Formula ``Fx(kappa)`` at ``alpha = 0`` (closed form of
   the pure longitudinal slip; the same with and without the carcass);
2. one joint lateral fit of ``(r_y, mu_y, alpha_y, beta_y, c_Mz, k_delta)`` (``k_delta`` with the
   complete carcass only) on ``Fy(alpha)`` and ``Mz(alpha)`` at ``kappa = 0``: ``Fy`` on every drawn
   point, ``Mz`` with weight :data:`MZ_WEIGHT` on the points up to the Magic Formula's sign change of
   ``Mz`` (the run of points around its peak with the peak's sign), a feature MCPS cannot follow
   (docs/models/mcps_tire.md §8). ``c_Mz`` scales the pneumatic trail ``c_Mz l/6``; the patch length
   ``l`` is not fitted, because the stationary curves depend on it only through ``c_Mz l`` and
   ``w r l^2`` (:meth:`~tirecli.models.mcps.params.MCPSParams.with_patch_length`); ``k_delta`` is the
   twist that turns the patch against the slip angle.

Bounds (:data:`FIT_BOUNDS`, docs/models/mcps_tire.md §8) carry the source of each end. A value
within 1e-6 (relative to the bound range, in log10 for the stiffnesses) of a bound is reported *at its bound*.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Bound:
    """Bounds of one fitted parameter and where each end comes from.

    ``lo_source``/``hi_source`` start with the kind of source: ``paper`` (the MCPS paper's
    equations), ``physics`` (what the quantity can be) or ``tirecli`` (tirecli's assumption).
    ``log``: fitted in log10.
    """

    lo: float
    hi: float
    lo_source: str
    hi_source: str
    log: bool = False


_R = "tirecli: assumed range of the rubber stiffness per unit area (three decades)"
_MU = "tirecli: assumed dry-road range of the sliding friction"
_OVER_LO = "paper: the second-order law needs alpha, beta > 1 (eq. 6)"
_OVER_HI = "tirecli: assumed largest overshoot factor"
#: Bounds of every fitted parameter, with their sources (docs/models/mcps_tire.md §8).
FIT_BOUNDS = {
    "r_x": Bound(1e6, 1e9, _R, _R, log=True),
    "mu_x": Bound(0.7, 1.2, _MU, _MU),
    "alpha_x": Bound(1.001, 5.0, _OVER_LO, _OVER_HI),
    "beta_x": Bound(1.001, 5.0, _OVER_LO, _OVER_HI),
    "r_y": Bound(1e6, 1e9, _R, _R, log=True),
    "mu_y": Bound(0.7, 1.2, _MU, _MU),
    "alpha_y": Bound(1.001, 5.0, _OVER_LO, _OVER_HI),
    "beta_y": Bound(1.001, 5.0, _OVER_LO, _OVER_HI),
    "c_Mz": Bound(0.0, 5.0, "physics: a negative weight would reverse the lever-arm torque of eq. (10)",
                  "tirecli: assumed largest trail factor"),
    "k_delta": Bound(1e2, 1e6, "tirecli: assumed softest belt twist (0.5 rad at 50 N m, beyond the "
                               "first-order rotation of eq. 16)", "tirecli: assumed stiffest belt twist (nearly rigid)",
                     log=True),
}
#: Parameters of the two fits of :func:`calibrate_to_mf` (``k_delta`` only with the complete carcass).
LONGITUDINAL = ("r_x", "mu_x", "alpha_x", "beta_x")
LATERAL = ("r_y", "mu_y", "alpha_y", "beta_y", "c_Mz", "k_delta")
#: Weight of the aligning-torque residuals (over the Magic Formula's |Mz| peak) against the side-force
#: residuals (over its |Fy| peak) in the joint lateral fit [assumed; docs/models/mcps_tire.md §8].
MZ_WEIGHT = 0.1
#: A fitted value this close to a bound (relative to the bound range) is *at* it.
AT_BOUND = 1e-6


def _to_x(names, values):
    return np.array([math.log10(values[n]) if FIT_BOUNDS[n].log else values[n] for n in names])


def _from_x(names, x):
    return {n: float(10.0 ** v if FIT_BOUNDS[n].log else v) for n, v in zip(names, x)}


def _bounds(names):
    lo = [math.log10(FIT_BOUNDS[n].lo) if FIT_BOUNDS[n].log else FIT_BOUNDS[n].lo for n in names]
    hi = [math.log10(FIT_BOUNDS[n].hi) if FIT_BOUNDS[n].log else FIT_BOUNDS[n].hi for n in names]
    return np.array(lo), np.array(hi)


# --------------------------------------------------------------------------- the calibration to the drawn tyre


@dataclass(frozen=True)
class Fitted:
    """One fitted parameter: its value, start value, bounds with their sources, and whether it ended
    on a bound (``at_bound``: ``"lower"``, ``"upper"`` or None)."""

    name: str
    value: float
    start: float
    bound: Bound
    at_bound: str | None

    @property
    def source(self) -> str | None:
        """Source of the bound the value ended on (None when inside)."""
        if self.at_bound is None:
            return None
        return self.bound.lo_source if self.at_bound == "lower" else self.bound.hi_source

    def as_dict(self) -> dict:
        return {"value": self.value, "start": self.start, "lower": self.bound.lo, "upper": self.bound.hi,
                "at_bound": self.at_bound, "bound_source": self.source}


@dataclass
class MFCalibration:
    """The calibration of MCPS to a Magic Formula tyre on the drawn grids (:func:`calibrate_to_mf`).

    Every number is of the returned set ``params`` (or of ``start``), on the drawn grids, as
    :func:`tirecli.numerics.mcps_stationary.solve` gives it at its default tolerance.

    Attributes
    ----------
    params, start : MCPSParams
        The calibrated set (to draw and to write) and the set it started from.
    fz : float
        Load [N].
    carcass : str
        ``complete`` or ``rigid``.
    kappa, alpha, alpha_fy : ndarray
        The drawn grids: ``Fx`` against ``kappa`` [-] at ``alpha = 0``; ``Mz`` against ``alpha``
        [rad] and ``Fy`` against ``alpha_fy`` [rad] at ``kappa = 0`` (the paper draws the side force
        at negative slip angles, the torque at positive ones).
    curves : dict
        ``{"mf" | "calibrated" | "start": {"fx", "fy", "mz": ndarray}}`` [N, N m], each model's own
        ISO-W output (road on tire).
    gaps : dict
        ``{"calibrated" | "start": {"fx" | "fy" | "mz": CurveGap}}`` against the Magic Formula
        (``at`` in [-] for fx, [rad] for fy and mz; fy over ``alpha_fy``).
    fitted : dict
        Parameter name -> :class:`Fitted`.
    peaks : dict
        ``{"mf" | "calibrated" | "start": {"alpha": rad, "mz": N m, "interior": bool}}``: the
        aligning-torque peak, refined on the model function (``interior`` False: at a grid end).
    sign_change : dict
        Where ``Mz`` changes sign after its peak inside the drawn range [rad] (None: it does not):
        ``mf``, ``calibrated``, ``start``; ``beyond``: the calibrated ``Mz`` gap over the points past
        the Magic Formula's sign change (CurveGap, None without one); ``fitted_up_to``: the largest
        slip angle of the ``Mz`` fit [rad]; ``within``: the calibrated ``Mz`` gap over the fitted points.
    offsets : dict
        The Magic Formula's ``fx, fy, mz`` at zero slip [N, N m] (its shifts; MCPS gives 0).
    fit : dict
        How it was fitted: weights, points, per fit the optimiser's status, success and
        evaluations.
    failure : str or None
        Why the set is not a calibrated result (None when it is).
    """

    params: object
    start: object
    fz: float
    carcass: str
    kappa: np.ndarray
    alpha: np.ndarray
    alpha_fy: np.ndarray
    curves: dict
    gaps: dict
    fitted: dict
    peaks: dict
    sign_change: dict
    offsets: dict
    fit: dict
    failure: str | None = None

    def at_bound(self) -> list:
        """The fitted parameters that ended on a bound (:class:`Fitted`), in fit order."""
        return [f for f in self.fitted.values() if f.at_bound is not None]

    def as_dict(self) -> dict:
        """Plain numbers by name (run.json), without the curves."""
        return {
            "fz": self.fz, "carcass": self.carcass, "failure": self.failure,
            "fitted": {n: f.as_dict() for n, f in self.fitted.items()},
            "at_bound": [f.name for f in self.at_bound()],
            "gaps": {s: {g: v.as_dict() for g, v in d.items()} for s, d in self.gaps.items()},
            "peaks": self.peaks,
            "sign_change": {k: (v.as_dict() if hasattr(v, "as_dict") else v) for k, v in self.sign_change.items()},
            "offsets": self.offsets, "fit": self.fit,
        }


def _peak_run(y):
    """Mask of the contiguous run of points around the peak of ``|y|`` that share the peak's sign."""
    y = np.asarray(y, dtype=float)
    i = int(np.argmax(np.abs(y)))
    s = np.sign(y[i])
    keep = np.zeros(y.size, dtype=bool)
    if s == 0:
        return keep | True
    lo = i
    while lo > 0 and np.sign(y[lo - 1]) == s:
        lo -= 1
    hi = i
    while hi < y.size - 1 and np.sign(y[hi + 1]) == s:
        hi += 1
    keep[lo:hi + 1] = True
    return keep


def _refined_peak(fun, x, y):
    """Peak of ``|y|`` refined on the function ``fun`` (bounded scalar search between the neighbours
    of the sampled peak): ``{"alpha", "mz", "interior"}``."""
    from scipy.optimize import minimize_scalar

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    i = int(np.argmax(np.abs(y)))
    if i == 0 or i == y.size - 1:
        return {"alpha": float(x[i]), "mz": float(y[i]), "interior": False}
    s = 1.0 if y[i] >= 0 else -1.0
    r = minimize_scalar(lambda a: -s * fun(a), bounds=(float(x[i - 1]), float(x[i + 1])), method="bounded",
                        options={"xatol": 1e-9})
    a, v = (float(r.x), float(fun(r.x))) if -r.fun >= s * y[i] else (float(x[i]), float(y[i]))
    return {"alpha": a, "mz": v, "interior": True}


def _sign_change(fun, x, y):
    """First slip angle [rad] after the peak of ``|y|`` where ``y`` changes sign (root of ``fun`` between
    the bracketing grid points), None when it keeps its sign to the end of the range."""
    from scipy.optimize import brentq

    run = _peak_run(y)
    last = int(np.flatnonzero(run)[-1])
    if last == len(y) - 1:
        return None
    a, b = float(x[last]), float(x[last + 1])
    if y[last + 1] == 0:
        return b
    return float(brentq(lambda v: fun(v), a, b, xtol=1e-12))


def calibrate_to_mf(p, fz: float, reference, kappa, alpha, *, alpha_fy=None, carcass: str = "complete",
                    mz_weight: float = MZ_WEIGHT) -> MFCalibration:
    """Calibrate MCPS to a Magic Formula tyre over the drawn range (docs/models/mcps_tire.md §8).

    Parameters
    ----------
    p : MCPSParams
        Start set; every parameter not fitted keeps its value.
    fz : float
        Load of the curves [N].
    reference : callable
        ``reference(kappa, alpha) -> (fx, fy, mz)`` [N, N, N m]: the Magic Formula tyre at ``fz``
        (ISO-W, road on tire, steady state), broadcast over its arguments.
    kappa : array_like
        Drawn slips of ``Fx(kappa)`` at ``alpha = 0`` [-], > -1.
    alpha : array_like
        Drawn slip angles of ``Mz(alpha)`` at ``kappa = 0`` [rad], in increasing order.
    alpha_fy : array_like or None
        Drawn slip angles of ``Fy(alpha)`` at ``kappa = 0`` [rad] (default ``alpha``): each model's own
        output there, so an asymmetric tyre is compared where it is drawn, never mirrored.
    carcass : {"complete", "rigid"}
        The MCPS model drawn (``k_delta`` is fitted with the complete carcass only).
    mz_weight : float
        Weight of the ``Mz`` residuals in the lateral fit (:data:`MZ_WEIGHT`).

    Returns
    -------
    MFCalibration
        Deterministic: the same inputs give the same numbers bit for bit.

    Raises
    ------
    ValueError
        A Magic Formula curve that is not finite on the drawn grids (nothing is fitted), or an
        unknown carcass.
    """
    from scipy.optimize import least_squares

    from tirecli.models.mcps.tire import pure_longitudinal_fx
    from tirecli.numerics.gaps import curve_gap
    from tirecli.numerics.mcps_stationary import solve, solve_sideslip

    if carcass not in ("complete", "rigid"):
        raise ValueError(f"carcass must be complete or rigid, got {carcass!r}")
    fz = float(fz)
    kap = np.asarray(kappa, dtype=float).ravel()
    alp = np.asarray(alpha, dtype=float).ravel()
    alf = alp if alpha_fy is None else np.asarray(alpha_fy, dtype=float).ravel()
    lat = np.unique(np.concatenate([alf, alp]))  # the lateral solutions: every drawn slip angle once
    iy, iz = np.searchsorted(lat, alf), np.searchsorted(lat, alp)
    zk, za = np.zeros_like(kap), np.zeros_like(lat)
    with np.errstate(all="ignore"):
        mf = {"fx": np.asarray(reference(kap, 0.0)[0], dtype=float) * np.ones_like(kap)}
        mf["fy"] = np.asarray(reference(0.0, alf)[1], dtype=float) * np.ones_like(alf)
        mf["mz"] = np.asarray(reference(0.0, alp)[2], dtype=float) * np.ones_like(alp)
    for g, v in mf.items():
        if not np.all(np.isfinite(v)):
            raise ValueError(f"the Magic Formula {g} curve is not finite on the drawn grid: nothing was fitted")
    peak = {g: float(np.max(np.abs(v))) or 1.0 for g, v in mf.items()}
    mz_run = _peak_run(mf["mz"])
    fit_info = {"mz_weight": float(mz_weight), "residuals": "each curve over its Magic Formula peak magnitude",
                "points": {"fx": int(kap.size), "fy": int(alf.size), "mz": int(np.count_nonzero(mz_run))}}
    warm = {}

    def lateral(q, tol=1e-12):  # the fit's evaluations: the twist-only fixed point (same model as solve)
        st = (solve_sideslip(q, fz, lat, tol=tol, start=warm.get("Q")) if carcass == "complete"
              else solve(q, fz, za, lat, za, carcass=carcass))
        if not st.converged.all():
            warm.pop("Q", None)
            return None
        warm["Q"] = st.Q
        return st.fy[iy], st.mz[iz]

    def fit(names, cur, resid_of):
        lo, hi = _bounds(names)
        x0 = np.clip(_to_x(names, cur.__dict__), lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))

        def resid(x):
            return resid_of(cur.with_values(**_from_x(names, x)))

        with np.errstate(all="ignore"):
            sol = least_squares(resid, x0, bounds=(lo, hi), method="trf", x_scale="jac", xtol=1e-10, ftol=1e-10,
                                gtol=1e-10, max_nfev=300)
        return cur.with_values(**_from_x(names, sol.x)), sol, lo, hi

    def fx_resid(q):
        r = (pure_longitudinal_fx(kap, q, fz) - mf["fx"]) / peak["fx"]
        return np.where(np.isfinite(r), r, 1e3)

    def lat_resid(q):
        out = lateral(q)
        if out is None:
            return np.full(alf.size + int(np.count_nonzero(mz_run)), 1e3)
        r = np.concatenate([(out[0] - mf["fy"]) / peak["fy"], mz_weight * (out[1] - mf["mz"])[mz_run] / peak["mz"]])
        return np.where(np.isfinite(r), r, 1e3)

    lat_names = LATERAL if carcass == "complete" else LATERAL[:-1]
    cur, fitted = p, {}
    for tag, names, resid_of in (("fx", LONGITUDINAL, fx_resid), ("lateral", lat_names, lat_resid)):
        cur, sol, lo, hi = fit(names, cur, resid_of)
        fit_info[tag] = {"parameters": list(names), "success": bool(sol.success), "status": str(sol.message),
                         "evaluations": int(sol.nfev), "jacobians": int(sol.njev or 0)}
        span = hi - lo
        for n, v, a, b, sp in zip(names, sol.x, lo, hi, span):
            side = "lower" if v - a <= AT_BOUND * sp else "upper" if b - v <= AT_BOUND * sp else None
            fitted[n] = Fitted(n, float(getattr(cur, n)), float(getattr(p, n)), FIT_BOUNDS[n], side)

    curves, gaps, peaks, changes, failure = {"mf": mf}, {}, {}, {}, None
    for tag, q in (("start", p), ("calibrated", cur)):
        sx = solve(q, fz, kap, zk, zk, carcass=carcass)
        sa = solve(q, fz, za, lat, za, carcass=carcass)
        ok = sx.converged.all() and sa.converged.all()
        c = {"fx": sx.fx, "fy": sa.fy[iy], "mz": sa.mz[iz]}
        if not ok or not all(np.all(np.isfinite(v)) for v in c.values()):
            failure = failure or f"the {tag} set's belt fixed point (MCPS eq. 18) does not converge on the drawn grid"
            continue
        curves[tag] = c
        gaps[tag] = {g: curve_gap({"fx": kap, "fy": alf, "mz": alp}[g], c[g], mf[g]) for g in ("fx", "fy", "mz")}

        def mz_of(a, q=q):  # the same model as solve(), at a tighter tolerance
            st = (solve_sideslip(q, fz, [a], tol=1e-13) if carcass == "complete"
                  else solve(q, fz, [0.0], [a], [0.0], carcass=carcass))
            return float(st.mz[0])

        peaks[tag] = _refined_peak(mz_of, alp, c["mz"])
        changes[tag] = _sign_change(mz_of, alp, c["mz"])

    def mf_mz(a):
        return float(np.asarray(reference(0.0, a)[2], dtype=float))

    peaks["mf"] = _refined_peak(mf_mz, alp, mf["mz"])
    changes["mf"] = _sign_change(mf_mz, alp, mf["mz"])
    past = ~mz_run & (np.arange(alp.size) > int(np.argmax(np.abs(mf["mz"]))))
    changes["beyond"] = (curve_gap(alp[past], curves["calibrated"]["mz"][past], mf["mz"][past], peak=peak["mz"])
                         if past.any() and "calibrated" in curves else None)
    changes["within"] = (curve_gap(alp[mz_run], curves["calibrated"]["mz"][mz_run], mf["mz"][mz_run], peak=peak["mz"])
                         if "calibrated" in curves else None)
    changes["fitted_up_to"] = float(alp[mz_run].max())
    with np.errstate(all="ignore"):
        off = reference(0.0, 0.0)
    offsets = {g: float(np.asarray(v, dtype=float)) for g, v in zip(("fx", "fy", "mz"), off)}
    if failure is None:
        bad = [t for t in ("fx", "lateral") if not fit_info[t]["success"]]
        if bad:
            failure = f"the optimiser stopped without converging ({fit_info[bad[0]]['status'].rstrip('.')})"
    return MFCalibration(params=cur, start=p, fz=fz, carcass=carcass, kappa=kap, alpha=alp, alpha_fy=alf, curves=curves,
                         gaps=gaps,
                         fitted=fitted, peaks=peaks, sign_change=changes, offsets=offsets, fit=fit_info,
                         failure=failure)


__all__ = ["calibrate_to_mf", "MFCalibration", "Fitted", "Bound", "FIT_BOUNDS", "LONGITUDINAL", "LATERAL", "MZ_WEIGHT"]
