"""Reference checks of the steady-state friction figures: FM Fig. 1, OBS Fig. 1, the FM Fig. 6 surface
(``docs/models/lugre_friction.md`` §4.2, §5, §9, §10). Peaks are the sweep's root-found ones (``data/peaks.csv``)."""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check
from tirecli.studies.sweep_curves import curve, curve_peak, first_model

MU_TOL = 5e-4   # reference values are printed to 4 decimals
S_TOL = 2e-3    # peak slip, printed to 3 decimals

_REF_SPEEDS = {  # docs/models/lugre_friction.md §9: v -> (peak |mu|, at |s|, |mu(0.05)|, |mu(1)|)
    5: (1.2818, 0.374, 0.6556, 1.1594),
    10: (1.1770, 0.279, 0.6520, 0.9817),
    15: (1.1074, 0.237, 0.6486, 0.9035),
    20: (1.0552, 0.212, 0.6451, 0.8717),
    25: (1.0137, 0.196, 0.6417, 0.8617),
    30: (0.9795, 0.184, 0.6384, 0.8618),
}
_REF_THETA = {  # docs/models/lugre_friction.md §5: theta_fm -> (peak, at |s|, |mu(1)|) at v = 20 m/s
    1.0: (1.0552, 0.212, 0.8717),
    0.8: (0.8714, 0.187, 0.7046),
    0.6: (0.6795, 0.159, 0.5374),
    0.4: (0.4764, 0.128, 0.3703),
}
_REF_T2 = {15: (1.1247, 0.206), 20: (1.0549, 0.175), 25: (0.9970, 0.155)}


def value_at(s, mu, s0):
    """``|mu|`` at ``|s| = s0`` by linear interpolation."""
    return float(np.interp(s0, s, mu))


def peak_checks(pk, ref_peak, ref_slip, tag, what, source):
    """Two checks of a curve's root-found peak ``pk = (|s|, |mu|, ...)``: its height ``|mu|`` and its slip ``|s|``."""
    ps, pm = pk[0], pk[1]
    return [Check(f"peak-{tag}", f"peak |mu| {what}", float(pm), ref_peak, MU_TOL, "-", source),
            Check(f"speak-{tag}", f"|s| of the peak {what}", float(ps), ref_slip, S_TOL, "-", source)]


def _speed_checks(result, model, theta=1.0, source="docs/models/lugre_friction.md §9"):
    df = result.data["sweep"]
    out = []
    for v, (pk, sp, m05, m1) in _REF_SPEEDS.items():
        s, mu = curve(df, model, v, theta)
        peak_ = curve_peak(result, model, v, theta)
        if len(s) == 0 or peak_ is None:
            continue
        out += peak_checks(peak_, pk, sp, f"v{v}", f"at v = {v} m/s", source) + [
            Check(f"mu005-v{v}", f"|mu(0.05)| at v = {v} m/s", value_at(s, mu, 0.05), m05, MU_TOL, "-", source),
            Check(f"mu1-v{v}", f"|mu(1)| (locked wheel) at v = {v} m/s", peak_[2], m1, MU_TOL, "-", source),
        ]
    return out


def _slope_check(result, v=20.0):
    p = result.payload["params"]
    var = result.payload["variants"][0]
    ds = 1e-7
    slope = abs(float(var.mu_ss(-v * ds, v * (1 - ds), p))) / ds
    return Check("slope-v20", "initial slope d|mu|/d|s| at v = 20 m/s (sigma0 L/2 + sigma2 v)", slope, 18.19, 0.005,
                 "-", "docs/models/lugre_friction.md §9")


def fig1_left_checks(result):
    df = result.data["sweep"]
    return _speed_checks(result, first_model(df)) + [_slope_check(result)]


def fig1_right_checks(result):
    df = result.data["sweep"]
    model = first_model(df)
    out = []
    for th, (pk, sp, m1) in _REF_THETA.items():
        peak_ = curve_peak(result, model, 20.0, th)
        if peak_ is None:
            continue
        out += peak_checks(peak_, pk, sp, f"th{th:g}", f"for theta_fm = {th:g}, v = 20 m/s", "docs/models/lugre_friction.md §5") + [
            Check(f"mu1-th{th:g}", f"|mu(1)| for theta_fm = {th:g}", peak_[2], m1, MU_TOL, "-", "docs/models/lugre_friction.md §5"),
        ]
    return out + [_slope_check(result)]


def obs_fig1_checks(result):
    df = result.data["sweep"]
    models = list(dict.fromkeys(df["model"]))
    dist = models[0]
    out = _speed_checks(result, dist, 1.0)
    pk = curve_peak(result, dist, 20.0, 0.4)
    if pk is not None:
        out += peak_checks(pk, 0.4764, 0.128, "thobs2.5", "for theta_obs = 2.5 at v = 20 m/s",
                           "docs/models/lugre_friction.md §10 (OBS Fig. 1)")
    pk = curve_peak(result, models[1], 20.0, 1.0) if len(models) > 1 else None
    if pk is not None:
        out += peak_checks(pk, 0.9767, 0.272, "lumped-k2", "of the lumped model, kappa0 = 2 (kappa = 10 1/m), "
                           "v = 20 m/s", "docs/models/lugre_friction.md §4.2")
    return out


def fig6_surface_checks(result):
    df = result.data["sweep"]
    model = first_model(df)
    out = []
    for v, (pk, sp) in _REF_T2.items():
        peak_ = curve_peak(result, model, v, 1.0)
        if peak_ is None:
            continue
        out += peak_checks(peak_, pk, sp, f"v{v}", f"of the Table 2 surface at v = {v} m/s", "docs/models/lugre_friction.md §10 (FM Fig. 6)")
    return out
