"""Reference checks of the observer figures: OBS Fig. 2 and its design numbers, the initial speed-error
study, the gain study (``docs/models/observer_model.md`` §4-§9). Adhesion values are in the OBS
convention (theta_obs = 1/theta_fm: 1 dry, larger = less grip)."""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check

OBS7 = "docs/models/observer_model.md §7"

#: theta_hat(t) of the Fig. 2 scenario: t [s] -> (reference, tolerance) (docs/models/observer_model.md §7; 3-decimal values
#: +-1e-3, 4-decimal ones +-3e-4).
FIG2_THETA_HAT = {5.5: (1.413, 1e-3), 6.0: (1.565, 1e-3), 7.0: (1.646, 1e-3), 8.0: (1.6669, 3e-4),
                  10.0: (1.6672, 3e-4), 12.5: (1.974, 1e-3), 15.0: (2.487, 1e-3), 16.0: (2.498, 1e-3),
                  20.0: (2.4978, 3e-4)}


def _runs(result):
    """``(case, trajectory, run record)`` of each case of an observe result."""
    return list(zip(result.payload["cases"], result.payload["trajectories"], result.payload["runs"]))


def _at(tr, x, t):
    return float(np.interp(t, tr.t, x))


def fig2_checks(result):
    from tirecli.observers import metrics as om

    case, tr, run = _runs(result)[0]
    met = run["metrics"]
    plant = result.payload["plant"]
    out = []
    s_lo, s_hi = met["slip_range"]
    out += [Check("slip-min", "most negative slip (braking)", s_lo, -0.0502, 5e-4, "-", OBS7),
            Check("slip-max", "largest slip (acceleration)", s_hi, 0.0301, 5e-4, "-", OBS7),
            Check("v-min", "lowest vehicle speed", met["v_range"][0], 19.47, 0.01, "m/s", OBS7),
            Check("v-max", "highest vehicle speed", met["v_range"][1], 38.78, 0.01, "m/s", OBS7)]
    cr = met["crossings_s"] + [float("nan")] * 2
    out += [Check("crossing-1", "first v_r zero crossing (reference: the first 5 ms output sample after it)", cr[0],
                  7.395, 0.005, "s", OBS7),
            Check("crossing-2", "second v_r zero crossing (reference: the first 5 ms sample after it)", cr[1], 12.535, 0.005,
                  "s", OBS7)]
    for t, (ref, tol) in FIG2_THETA_HAT.items():
        out.append(Check(f"theta-hat-{t:g}s", f"theta_hat at {t:g} s", _at(tr, tr.theta_hat, t), ref, tol, "-", OBS7))
    out.append(Check("theta-12.5s", "true theta at 12.5 s (half-cosine wet -> snow)", _at(tr, tr.theta, 12.5), 2.083,
                     1e-3, "-", OBS7))
    err = tr.theta_hat - tr.theta
    ph = om.phase_errors(tr.t, err, [0, 5, 8, 10, 15, 20])
    rms = {(p["start"], p["end"]): p["rms"] for p in ph}
    rms[(5.0, 10.0)] = om.phase_errors(tr.t, err, [5, 10])[0]["rms"]
    for (a, b), ref, tol in (((0.0, 5.0), 0.0, 1e-4), ((5.0, 10.0), 0.153, 2e-3), ((8.0, 10.0), 0.0004, 2e-4),
                             ((10.0, 15.0), 0.073, 2e-3), ((15.0, 20.0), 0.0030, 3e-4)):
        out.append(Check(f"rms-{a:g}-{b:g}", f"RMS(theta_hat - theta) on [{a:g}, {b:g})", rms[(a, b)], ref, tol, "-", OBS7))
    out.append(Check("max-v-error", "max |v_hat - v|", met["max_abs_v_error"], 4.6e-4, 0.05e-4, "m/s", OBS7))
    return out + _design_checks(plant, case.gains, tr)


def _design_checks(plant, gains, tr):
    """docs/models/observer_model.md §4-§6 numbers of the OBS gains."""
    from tirecli.observers import lugre_observer as lo

    s4, s5, s6 = "docs/models/observer_model.md §4", "docs/models/observer_model.md §5", "docs/models/observer_model.md §6"
    obs = lo.observability(plant)
    tf = lo.transfer_function(plant, gains)
    poles = np.sort(lo.error_poles(plant, gains).real)
    zeros = np.sort(np.real(tf["zeros"]))
    c0, c1, c2 = tf["re_coeffs"]
    vr = plant.car.r * tr.omega - tr.v
    lip = lo.lipschitz_sizes(plant, float(np.max(np.abs(vr))), float(np.max(tr.omega)), float(np.max(np.abs(tr.z))))
    pm = lo.passivity_margin(plant, gains)
    k3_min = plant.car.J * plant.tire.sigma0 / (plant.car.r * plant.car.F_n * plant.tire.sigma1 ** 2)
    return [
        Check("det-O", "observability determinant det(C; CA; CA^2)", obs["det"], -2.24e10, 0.005e10, "-", s4),
        Check("obs-factor", "F_n sigma1 sigma2 - m sigma0", obs["factor"], -63532.7, 0.1, "kg/m", s4),
        Check("pole-fast", "fastest eig(A - K C)", float(poles[0]), -3.733e6, 0.0005e6, "1/s", s6),
        Check("pole-mid", "middle eig(A - K C)", float(poles[1]), -181.55, 0.01, "1/s", s6),
        Check("pole-slow", "slow eig(A - K C) (speed-error mode)", float(poles[2]), -0.0294, 0.0001, "1/s", s6),
        Check("G-kc", "k_c = r F_n sigma1/J", tf["k_c"], 3733.3, 0.1, "-", s6),
        Check("G-a1", "a1", tf["a1"], 181.558, 0.001, "1/s", s6),
        Check("G-a0", "a0", tf["a0"], 3.2677, 1e-4, "1/s^2", s6),
        Check("G-b2", "b2", tf["b2"], 3.7333e6, 0.0001e6, "1/s", s6),
        Check("G-b1", "b1", tf["b1"], 6.7786e8, 0.0001e8, "1/s^2", s6),
        Check("G-b0", "b0", tf["b0"], 1.9945e7, 0.0001e7, "1/s^3", s6),
        Check("ReG-c0", "Re G coefficient of w^0", c0, 6.5e7, 0.05e7, "-", s6),
        Check("ReG-c1", "Re G coefficient of w^2", c1, 1.23e11, 0.005e11, "-", s6),
        Check("ReG-c2", "Re G coefficient of w^4", c2, 3.73e6, 0.005e6, "-", s6),
        Check("zero-1", "zero of G near -181.54", float(zeros[0]), -181.54, 0.01, "1/s", s6),
        Check("zero-2", "zero of G near -0.018", float(zeros[1]), -0.018, 5e-4, "1/s", s6),
        Check("k3-threshold", "-k3 > J sigma0/(r F_n sigma1^2)", k3_min, 0.0486, 1e-4, "m", s6),
        Check("lambda-min-Q", "best lambda_min(Q) with P B = C' (numerical search; reference: <~ 1.1e-6)",
              pm["lambda_min_q"], 1.1e-6, 0.1e-6, "-", s6),
        Check("k_z", "Lipschitz size k_z = sigma0 |vr|max/mu_c", lip["k_z"], 4.2e2, 0.1e2, "1/s", s5),
        Check("L_psi", "Lipschitz constant L_psi = kappa r |omega|max", lip["L_psi"], 3.9e2, 0.1e2, "1/s", s5),
    ]


def speed_error_checks(result):
    from tirecli.observers import metrics as om

    runs = {case.label: (case, tr, run) for case, tr, run in _runs(result)}
    s8 = "docs/models/observer_model.md §8"
    out = []
    if "exact start" in runs:
        _, tr, run = runs["exact start"]
        lo_, hi_ = run["metrics"]["slip_range"]
        out += [Check("slip-min-250", "Ua = Ub = 250 N m: most negative slip", lo_, -0.042, 1e-3, "-", OBS7),
                Check("slip-max-250", "Ua = Ub = 250 N m: largest slip", hi_, 0.017, 1e-3, "-", OBS7),
                Check("theta-hat-15s-250", "Ua = Ub = 250 N m: theta_hat at 15 s (lags: less slip)",
                      _at(tr, tr.theta_hat, 15.0), 2.14, 0.01, "-", OBS7),
                Check("theta-hat-20s-250", "Ua = Ub = 250 N m: theta_hat at 20 s", _at(tr, tr.theta_hat, 20.0),
                      2.39, 0.01, "-", OBS7)]
    if "v_hat(0) = v(0) + 0.1 m/s" in runs:
        _, tr, _ = runs["v_hat(0) = v(0) + 0.1 m/s"]
        out += [Check("v-error-20s", "+0.1 m/s start: speed error v_hat - v at 20 s", _at(tr, tr.v_hat - tr.v, 20.0),
                      0.063, 1e-3, "m/s", s8),
                Check("theta-hat-4.9s", "+0.1 m/s start: theta_hat at 4.9 s (true 1)", _at(tr, tr.theta_hat, 4.9),
                      -0.17, 0.01, "-", s8),
                Check("theta-hat-20s", "+0.1 m/s start: theta_hat at 20 s (true 2.5)", _at(tr, tr.theta_hat, 20.0),
                      1.34, 0.01, "-", s8)]
    if "v_hat(0) = v(0) + 2 m/s" in runs:
        _, tr, _ = runs["v_hat(0) = v(0) + 2 m/s"]
        out.append(Check("theta-hat-20s-2ms", "+2 m/s start: theta_hat at 20 s (reference: about -11)",
                         _at(tr, tr.theta_hat, 20.0), -11.0, 0.5, "-", s8))
    known = [v for k, v in runs.items() if k.startswith("theta known")]
    if known:
        case, tr, _ = known[0]
        rate = om.decay_rate(tr.t, tr.v_hat - tr.v, 2.0, tr.t[-1])
        out.append(Check("slow-mode-rate", "theta known: fitted decay rate of the speed error vs the slow pole of "
                         "A - K C (the friction terms, left out of A - K C, shift it by a few %)", rate, -0.0294, 0.004,
                         "1/s", "docs/models/observer_model.md §6"))
    return out


def gain_checks(result):
    gs = result.data.get("gain_study")
    if gs is None or result.meta["gain_study"]["gain"] != "gamma":
        return []
    st = gs["settle_time_s"].to_numpy()
    bad = int(np.sum(~(np.diff(st) < 0))) if np.all(np.isfinite(st)) else len(st)
    return [Check("monotone", "settling time falls as gamma grows (number of exceptions)", float(bad), 0.0, 0.0, "-",
                  "docs/models/observer_model.md §8 (convergence speed grows with excitation and gain)")]
