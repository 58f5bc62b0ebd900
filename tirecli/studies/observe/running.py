"""Running a planned ``observe`` study: each case simulated with its observer, its metrics, design facts
and warnings (see :mod:`tirecli.studies.observe`)."""
from __future__ import annotations

from dataclasses import asdict
from typing import TYPE_CHECKING

import numpy as np

from tirecli.conventions import slip_from_speeds, theta_fm_from_obs
from tirecli.observers import lugre_observer as lo
from tirecli.observers import metrics as om
from tirecli.studies.base import StudyResult
from tirecli.studies.observe.planning import Case, Observe
from tirecli.studies.study import Plan

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

def simulate_case(detail: Observe, case: Case):
    """Run one case with the configured solver (``auto``: :func:`tirecli.numerics.observer.method.choose_method`)."""
    from tirecli.numerics.observer.method import simulate

    return simulate(detail.plant, case.gains, case.scenario, case.sensor, detail.solver)


def case_metrics(plant: lo.ObserverPlant, tr, case: Case, m: dict) -> dict:
    """Metrics of one run (docs/models/observer_model.md §7-§8; see :mod:`tirecli.observers.metrics`)."""
    r = plant.car.r
    vr = r * tr.omega - tr.v
    err = tr.theta_hat - tr.theta
    crossings = om.zero_crossings(tr.t, vr)
    slip = slip_from_speeds(tr.v, tr.omega, r)
    return {
        "crossings_s": crossings.tolist(),
        "phases": om.phase_errors(tr.t, err, m["phases"], crossings, m["crossing_margin"]),
        "all_excl_crossings": om.phase_errors(tr.t, err, [tr.t[0], tr.t[-1]], crossings, m["crossing_margin"])[0],
        "settling": om.settle_times(tr.t, err, case.changes, m["settle_tolerance"]),
        "max_abs_v_error": float(np.max(np.abs(tr.v_hat - tr.v))),
        "final_v_error": float(tr.v_hat[-1] - tr.v[-1]),
        "excitation_share": om.excitation_share(tr.t, vr, m["excitation_threshold"]),
        "slip_range": [float(slip.min()), float(slip.max())],
        "v_range": [float(tr.v.min()), float(tr.v.max())],
        "theta_hat_final": float(tr.theta_hat[-1]),
    }


def design_record(plant: lo.ObserverPlant, gains: lo.ObserverGains, tr=None) -> dict:
    """Design facts of a gain set (docs/models/observer_model.md §4-§6), JSON-ready."""
    obs = lo.observability(plant)
    tf = lo.transfer_function(plant, gains)
    rec = {
        "gains": gains.as_dict(),
        "observability": {"det": obs["det"], "det_closed_form": obs["det_closed_form"], "factor": obs["factor"],
                          "rank": obs["rank"]},
        "error_poles_1_s": [complex(p).real if abs(complex(p).imag) < 1e-9 * abs(p) else str(complex(p))
                            for p in lo.error_poles(plant, gains)],
        "slow_pole_estimate_1_s": lo.slow_pole_estimate(plant, gains),
        "fast_rate_1_s": float(plant.fast_rate(gains, 1.0)),
        "transfer_function": {k: tf[k] for k in ("k_c", "a1", "a0", "b2", "b1", "b0")}
        | {"re_coeffs": list(tf["re_coeffs"]), "zeros": [float(np.real(z)) for z in tf["zeros"]]},
        "conditions": [c.record() for c in lo.design_conditions(plant, gains)],
        "k3_threshold_m": plant.car.J * plant.tire.sigma0 / (plant.car.r * plant.car.F_n * plant.tire.sigma1 ** 2),
    }
    if tr is not None:
        vr = plant.car.r * tr.omega - tr.v
        lip = lo.lipschitz_sizes(plant, float(np.max(np.abs(vr))), float(np.max(np.abs(tr.omega))),
                                 float(np.max(np.abs(tr.z))))
        pm = lo.passivity_margin(plant, gains)
        theta_max = float(np.max(tr.theta))
        rec["lipschitz"] = lip | {"vr_max": float(np.max(np.abs(vr))), "omega_max": float(np.max(np.abs(tr.omega))),
                                  "z_max": float(np.max(np.abs(tr.z)))}
        rec["passivity"] = {"lambda_min_q": pm["lambda_min_q"],
                            "alpha_bound_17_m": lo.alpha_bound(pm["lambda_min_q"], theta_max, lip["L_phi"], lip["L_psi"]),
                            "note": "sufficient bound (17); OBS's alpha is a practical tuning value (docs/models/observer_model.md §6)"}
    return rec


def slow_mode(plant: lo.ObserverPlant, case: Case, tr) -> dict:
    """The slow speed-error mode of a run with theta known (adaptation off, docs/models/observer_model.md §6, §8):
    the decay rate [1/s] of ``v_hat - v`` fitted from 2 s to the end, and the largest real part [1/s] of the
    eigenvalues of the error dynamics linearised at the run's middle sample."""
    i = len(tr.t) // 2
    M = lo.linearized_error_matrix(plant, case.gains, float(tr.theta[i]), float(tr.omega[i]), float(tr.v[i]),
                                   float(tr.z[i]))
    return {"fitted_1_s": om.decay_rate(tr.t, tr.v_hat - tr.v, 2.0, tr.t[-1]),
            "linearised_1_s": float(np.max(np.linalg.eigvals(M).real))}


def _frame(plant, tr, label, dt_out) -> pd.DataFrame:
    import pandas as pd

    r = plant.car.r
    keep = _decimate(tr.t, dt_out)
    t = tr.t[keep]
    v, w, y = tr.v[keep], tr.omega[keep], tr.y[keep]
    vh = tr.v_hat[keep]
    return pd.DataFrame({
        "case": label, "t": t,
        "theta": tr.theta[keep], "theta_hat": tr.theta_hat[keep],
        "theta_fm": theta_fm_from_obs(tr.theta[keep]), "theta_hat_fm": _safe_inv(tr.theta_hat[keep]),
        "v": v, "v_hat": vh, "omega": w, "omega_meas": y,
        "vr": r * w - v, "vr_hat": r * y - vh, "slip": slip_from_speeds(v, w, r),
        "z": tr.z[keep], "z_hat": tr.z_hat[keep], "torque": tr.torque[keep],
    })


def _safe_inv(x):
    x = np.asarray(x, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(x != 0.0, 1.0 / np.where(x != 0.0, x, 1.0), np.nan)


def _decimate(t, dt):
    """Indices of ``t`` nearest to a ``dt`` grid (first and last kept)."""
    if dt <= 0 or len(t) < 3:
        return np.arange(len(t))
    target = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    idx = np.unique(np.clip(np.searchsorted(t, target - 1e-9), 0, len(t) - 1))
    return np.unique(np.concatenate([idx, [len(t) - 1]]))


def _adaptation_off(case: Case, tr) -> str:
    """What ``gamma = 0`` means for a run, in words: theta_hat is frozen at its initial value."""
    th0 = float(case.scenario.theta_hat0)
    lo_, hi_ = float(np.min(tr.theta)), float(np.max(tr.theta))
    head = (f"{case.label}: adaptation off (gamma = 0): theta_hat stays at its initial value {th0:g} "
            "(OBS convention) for the whole run and the observer estimates only v and z. ")
    if abs(hi_ - th0) <= 1e-12 * max(1.0, abs(th0)) and abs(lo_ - th0) <= 1e-12 * max(1.0, abs(th0)):
        return head + (f"Here the road's theta is {th0:g} throughout, so this is the 'theta known' observer the case "
                       "asks for; on a road whose theta differs, v_hat and z_hat would be biased. Set gamma > 0 to "
                       "estimate theta (OBS Fig. 2: gamma = 2e5).")
    return head + (f"The road's theta varies over [{lo_:g}, {hi_:g}] and theta_hat cannot follow it, so v_hat and "
                   "z_hat are biased; set gamma > 0 to estimate theta (OBS Fig. 2: gamma = 2e5).")


def _warnings(case: Case, design: dict, met: dict, m: dict, tr) -> list[str]:
    out = []
    for c in design["conditions"]:
        if c["id"] == "gamma-positive" and c["value"] == 0:
            out.append(_adaptation_off(case, tr))
        elif not c["ok"]:
            out.append(f"{case.label}: design condition '{c['id']}' fails: {c['requirement']} "
                       f"(value {c['value']:.4g}); {c['meaning']}")
    if met["excitation_share"] < m["min_excitation"]:
        out.append(f"{case.label}: excitation: |v_r| > {m['excitation_threshold']:g} m/s only "
                   f"{100 * met['excitation_share']:.0f}% of the time (< {100 * m['min_excitation']:.0f}%): theta is "
                   "not observable while v_r = 0 (A4, docs/models/observer_model.md §8)")
    if np.any(tr.v < 0) or np.any(tr.omega < 0):
        out.append(f"{case.label}: the vehicle or the wheel reverses; the model assumes forward motion")
    return out


def run(plan_: Plan, progress=None) -> StudyResult:
    """Run a planned observe study (see :mod:`tirecli.studies.observe`)."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    if not isinstance(plan_.detail, Observe):   # the observer on a measured log
        from tirecli.studies.observe.log import run_log

        return run_log(plan_, progress)
    p, checked = plan_.detail, plan_.checked
    sc = checked["scenario"]
    dt_out = (checked["output"] or {}).get("dt", 0.01)
    frames, rows, runs, trajs, slow = [], [], [], [], {}
    warnings = list(p.deprecated)
    designs = {}
    if progress is not None:
        progress.start(len(p.cases), "observe")
    for k, case in enumerate(p.cases):
        tr = simulate_case(p, case)
        trajs.append(tr)
        key = tuple(case.gains.as_dict().values())
        if key not in designs:
            designs[key] = design_record(p.plant, case.gains, tr if k == 0 else None)
        met = case_metrics(p.plant, tr, case, p.metrics)
        if case.gains.gamma == 0:
            slow[case.label] = slow_mode(p.plant, case, tr)
        warnings += _warnings(case, designs[key], met, p.metrics, tr)
        frames.append(_frame(p.plant, tr, case.label, dt_out))
        for ph in met["phases"]:
            rows.append({"case": case.label, "phase_start": ph["start"], "phase_end": ph["end"], "rms": ph["rms"],
                         "max": ph["max"], "rms_excl_crossings": ph["rms_excl"], "max_excl_crossings": ph["max_excl"]})
        runs.append({"label": case.label, "gains": case.gains.as_dict(), "measurement": case.sensor.record(),
                     "theta_hat0_obs": case.scenario.theta_hat0, "v_hat0": case.scenario.vhat0,
                     "integrator": tr.method, "integrator_info": tr.info, "metrics": met,
                     "theta_profile": case.theta_profile.record()})
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    synthetic = any(c.sensor.synthetic for c in p.cases)
    assumed = [sc["assumed"]] if sc["assumed"] else []
    gstudy = checked["gain_study"]
    data = {"observer": pd.concat(frames, ignore_index=True), "metrics": pd.DataFrame(rows)}
    if gstudy:
        data["gain_study"] = pd.DataFrame({
            "gain": gstudy["gain"], "value": gstudy["values"],
            "settle_time_s": [_first_settle(r["metrics"]["settling"]) for r in runs],
            "rms_excl_crossings": [r["metrics"]["all_excl_crossings"]["rms_excl"] for r in runs],
            "max_abs_v_error": [r["metrics"]["max_abs_v_error"] for r in runs],
        })
    default_fig = "obs-gain-study" if gstudy else "obs-fig2"
    return StudyResult(
        study="observe",
        config=plan_.config,
        parameter_sets={"tire": plan_.sets["tire"], "vehicle": plan_.sets["vehicle"], "observer": plan_.sets["observer"]},
        data=data,
        meta={
            "title": checked["title"],
            "theta_convention": "theta and theta_hat columns: OBS convention (theta multiplies sigma0 |vr|/g; 1 dry, "
                                "larger = less grip); theta_fm = 1/theta_obs (fraction of dry grip)",
            "theta_convention_input": sc["theta_convention"],
            "plant": "quarter car, lumped LuGre with constant kappa = kappa0/L = "
                     f"{p.plant.kappa:g} 1/m, sigma2 in the vehicle equation only (OBS (3)-(5))",
            "assumed": assumed,
            "solver": asdict(p.solver),
            "metric_settings": p.metrics,
            "design": list(designs.values()),
            "runs": runs,
            "warnings": warnings,
            "gain_study": gstudy,
        },
        figures=checked["figures"] or [default_fig],
        payload={"plant": p.plant, "cases": p.cases, "trajectories": trajs, "runs": runs, "designs": designs,
                 "metrics": p.metrics, "slow_mode": slow},
        synthetic=synthetic,
    )


def _first_settle(settling: list) -> float:
    """Settling time [s] after the first adhesion change (nan if it never settles)."""
    for s in settling:
        return float("nan") if s["time"] is None else s["time"]
    return float("nan")
