"""Calibration of the MCPS rubber parameters to Magic Formula curves (docs/models/mcps_tire.md §8, procedure assumed).

Three bounded least-squares fits (``scipy.optimize.least_squares``, trust-region reflective,
residuals in N or N m, equal weights), each on an even grid that excludes zero slip:

1. ``(r_x, mu_x, alpha_x, beta_x)`` on the Magic Formula ``Fx(kappa)`` at ``alpha = 0``
   (``kappa`` in ``(0, kappa_max]``; closed form of the pure longitudinal slip);
2. ``(r_y, mu_y, alpha_y, beta_y)`` on ``Fy(alpha)`` at ``kappa = 0`` (``alpha`` in ``(0, alpha_max]``;
   the chosen carcass: the complete model solves its fixed point at every evaluation);
3. ``c_Mz`` on ``Mz(alpha)`` at ``kappa = 0`` with the fitted lateral parameters. In the complete model
   ``c_Mz`` sets the aligning stiffness and with it the belt twist, which changes ``Fy`` again: with
   ``rounds > 1`` steps 2 and 3 alternate (up to ``rounds`` times, until no parameter changes by more
   than ``ROUND_TOL``, relative).

The report gives each group's gap before calibration (the start set), right after its own fit
(``max_gap_stage``) and for the final set (``max_gap``: the set drawn and written).

Bounds (docs/models/mcps_tire.md §8): ``r`` in ``[1e6, 1e9]`` N/m^3 (fitted in log10), ``mu`` in ``[0.7, 1.2]``,
``alpha``, ``beta`` in ``[1.001, 5]``, ``c_Mz`` in ``[0, 5]`` [assumed]. A value within 1e-6
(relative to the bound range) of a bound is reported *at its bound*.
"""
from __future__ import annotations

import math

import numpy as np

#: Bounds of the fitted parameters (docs/models/mcps_tire.md §8; c_Mz's are tirecli's).
BOUNDS = {
    "r_x": (1e6, 1e9), "mu_x": (0.7, 1.2), "alpha_x": (1.001, 5.0), "beta_x": (1.001, 5.0),
    "r_y": (1e6, 1e9), "mu_y": (0.7, 1.2), "alpha_y": (1.001, 5.0), "beta_y": (1.001, 5.0),
    "c_Mz": (0.0, 5.0),
}
#: Stopping rule of repeated lateral rounds (relative change of every lateral parameter).
ROUND_TOL = 1e-4
GROUPS = {
    "fx": ("r_x", "mu_x", "alpha_x", "beta_x"),
    "fy": ("r_y", "mu_y", "alpha_y", "beta_y"),
    "mz": ("c_Mz",),
}


def _to_x(names, values):
    return np.array([math.log10(values[n]) if n.startswith("r_") else values[n] for n in names])


def _from_x(names, x):
    return {n: float(10.0 ** v if n.startswith("r_") else v) for n, v in zip(names, x)}


def _bounds(names):
    lo = [math.log10(BOUNDS[n][0]) if n.startswith("r_") else BOUNDS[n][0] for n in names]
    hi = [math.log10(BOUNDS[n][1]) if n.startswith("r_") else BOUNDS[n][1] for n in names]
    return np.array(lo), np.array(hi)


def calibrate(p, fz: float, targets: dict, grid: dict, carcass: str = "complete", rounds: int = 1) -> tuple:
    """Fit the rubber parameters of ``p`` (MCPSParams) to target curves.

    Parameters
    ----------
    fz : float
        Load of the fit [N].
    targets : dict
        ``{"fx": fn(kappa) -> Fx [N], "fy": fn(alpha) -> Fy [N], "mz": fn(alpha) -> Mz [N m]}``
        (ISO-W, road on tire); a missing key skips that fit.
    grid : dict
        ``{"kappa": array, "alpha": array}`` of the fits.
    carcass : {"complete", "rigid"}
        Model of the lateral fits.
    rounds : int
        Largest number of alternations of the lateral fits (step 2 then 3); 1 is the sequence of docs/models/mcps_tire.md §8.

    Returns
    -------
    (MCPSParams, report) : the calibrated parameters and, per fitted group, a dict with the
    values, their bounds, whether each ended at a bound, the max and RMS gap before and after, the
    optimiser's status, and ``failure``: why the group is not a fitted result (None when it is).
    """
    from scipy.optimize import least_squares

    from tirecli.models.mcps.tire import pure_longitudinal_fx
    from tirecli.numerics.mcps_stationary import solve

    kap = np.asarray(grid["kappa"], dtype=float)
    alp = np.asarray(grid["alpha"], dtype=float)
    report = {}
    cur = p
    warm = {}

    def model_curve(group, q):
        if group == "fx":
            return pure_longitudinal_fx(kap, q, fz)
        st = solve(q, fz, np.zeros_like(alp), alp, np.zeros_like(alp), carcass=carcass, start=warm.get("Q"),
                   tol=1e-13)
        if not st.converged.all():
            warm.pop("Q", None)
            return np.full(alp.shape, np.nan)
        warm["Q"] = st.Q  # the next evaluation starts from this solution (parameters change little)
        return st.fy if group == "fy" else st.mz

    def fit(group, cur):
        names = GROUPS[group]
        x_in = kap if group == "fx" else alp
        target = np.asarray(targets[group](x_in), dtype=float)
        lo, hi = _bounds(names)
        x0 = np.clip(_to_x(names, cur.__dict__), lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))

        def resid(x):
            r = model_curve(group, cur.with_values(**_from_x(names, x))) - target
            return np.where(np.isfinite(r), r, 1e6)

        with np.errstate(all="ignore"):
            sol = least_squares(resid, x0, bounds=(lo, hi), method="trf", x_scale="jac", xtol=1e-12, ftol=1e-12,
                                gtol=1e-12, max_nfev=400)
        span = hi - lo
        at_bound = {n: bool(min(abs(v - a), abs(b - v)) <= 1e-6 * sp) for n, v, a, b, sp in zip(names, sol.x, lo, hi, span)}
        return cur.with_values(**_from_x(names, sol.x)), sol, at_bound, float(np.max(np.abs(resid(sol.x))))

    info = {g: {"evaluations": 0, "success": True, "status": "", "at_bound": {}, "stage": None} for g in GROUPS}

    def record(g, sol, ab, gap):
        info[g].update(evaluations=info[g]["evaluations"] + int(sol.nfev), success=bool(sol.success),
                       status=sol.message, at_bound=ab, stage=gap)

    with np.errstate(all="ignore"):  # a target the Magic Formula cannot evaluate: fail before fitting anything
        for g in GROUPS:
            if g in targets and not np.all(np.isfinite(np.asarray(targets[g](kap if g == "fx" else alp), dtype=float))):
                return p, {g: {"failure": "the Magic Formula target curve is not finite on the calibration grid"}}
    cur = p
    if "fx" in targets:
        cur, *res = fit("fx", cur)
        record("fx", *res)
    lateral = [g for g in ("fy", "mz") if g in targets]
    done = 0
    for done in range(1, (max(1, int(rounds)) if carcass == "complete" and len(lateral) == 2 else 1) + 1):
        prev = np.array([getattr(cur, n) for g in lateral for n in GROUPS[g]])
        for g in lateral:
            cur, *res = fit(g, cur)
            record(g, *res)
        now = np.array([getattr(cur, n) for g in lateral for n in GROUPS[g]])
        if np.all(np.abs(now - prev) <= ROUND_TOL * np.maximum(np.abs(now), 1e-12)):
            break
    report = {}
    for g, names in GROUPS.items():  # gaps of the start set and of the final set (the one drawn and written)
        if g not in targets:
            continue
        x_in = kap if g == "fx" else alp
        target = np.asarray(targets[g](x_in), dtype=float)
        with np.errstate(all="ignore"):
            before = model_curve(g, p) - target
            after = model_curve(g, cur) - target
        report[g] = {
            "parameters": {n: float(getattr(cur, n)) for n in names},
            "start": {n: float(getattr(p, n)) for n in names},
            "bounds": {n: BOUNDS[n] for n in names},
            "at_bound": info[g]["at_bound"],
            "max_gap_before": float(np.max(np.abs(before))), "rms_gap_before": float(np.sqrt(np.mean(before**2))),
            "max_gap_stage": info[g]["stage"],
            "max_gap": float(np.max(np.abs(after))), "rms_gap": float(np.sqrt(np.mean(after**2))),
            "unit": "N m" if g == "mz" else "N", "points": int(x_in.size),
            "success": info[g]["success"], "status": info[g]["status"], "evaluations": info[g]["evaluations"],
            "rounds": done if g in lateral else 1,
        }
        report[g]["failure"] = _failure(g, names, target, after, info[g])
    return cur, report


def _failure(group, names, target, after, info) -> str | None:
    """Why a group's calibration is not a fitted result (None when it is): a target or the final
    model curve is not finite (the Magic Formula or the belt fixed point fails there), the optimiser
    did not converge, or every fitted parameter ended on a bound."""
    if not np.all(np.isfinite(target)):
        return "the Magic Formula target curve is not finite on the calibration grid"
    if not np.all(np.isfinite(after)):
        return "the calibrated model gives no finite value on the grid (the belt fixed point fails)"
    if not info["success"]:
        return f"the optimiser stopped without converging ({str(info['status']).rstrip('.')})"
    ab = info["at_bound"]
    if len(names) > 1 and ab and all(ab.get(n, False) for n in names):
        return f"every fitted parameter ended on a bound ({', '.join(names)})"
    return None


__all__ = ["calibrate", "BOUNDS", "GROUPS"]
