"""The observer on a measured log: ``measurement: {log: FILE}`` in an observe config.

No plant is simulated. The log (read by :func:`tirecli.io.readers.read_measured`: CSV, Parquet, MDF4 or
TYDEX, with ``map`` and ``units`` as ``--map``/``--units``) gives the time ``t`` [s], the wheel speed
``omega`` [rad/s] and the wheel torque ``torque`` [N m] (> 0 drives, < 0 brakes), and optionally the
vehicle speed ``vx`` [m/s]. The observer (:func:`tirecli.numerics.observer_log.observe_log`) is driven by
the samples, each held until the next (zero-order hold). ``estimate.v_error`` is the initial speed error
against the measured ``vx(0)`` when the log has it, else against the pure-rolling ``r omega(0)``.

Frame ``observer``: ``case, t, theta_hat, theta_hat_fm, v_hat, omega_meas, torque, z_hat, vr_hat`` and,
when the log has ``vx``, ``v`` (measured) and ``v_error = v_hat - v``. Metrics against the measured
speed: RMS, largest ``|v_hat - v|`` and where, the final error.

:func:`tirecli.app.data.synthetic_log` makes a SYNTHETIC log from an observe config's simulated plant.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tirecli.errors import ConfigError, DataError
from tirecli.studies.base import StudyResult
from tirecli.studies.study import Line, Plan

#: Channels of a log: the time; the wheel speed as ``omega`` [rad/s] or ``romega`` = r omega [m/s]; the torque as
#: ``torque`` (wheel torque, > 0 drives), ``brake_torque`` (> 0 brakes) or the brake pressure ``p`` [Pa] times
#: ``torque_gain``; optionally the vehicle speed ``vx``.
SPEEDS = ("omega", "romega")
TORQUES = ("torque", "brake_torque", "p")

@dataclass
class LogCase:
    """One observer run on the log."""

    label: str
    gains: object             # ObserverGains
    v_hat0: float
    z_hat0: float
    theta_hat0: float         # OBS convention


@dataclass
class ObserveLog:
    """The detail of an observe plan on a measured log."""

    plant: object             # ObserverPlant
    cases: list
    t: np.ndarray
    omega: np.ndarray
    torque: np.ndarray
    v: np.ndarray | None      # measured vehicle speed [m/s], or None
    source: str
    synthetic: bool
    solver: object            # SolverOptions (rtol, atol, h_max)
    notes: list               # warnings of the run (deprecated keys)


def _log_path(ref: str, base_dir) -> str:
    p = Path(ref)
    return ref if p.is_absolute() else str(Path(base_dir) / p)


def _unit(data, name: str, expected: str) -> None:
    unit = data.channels[name].unit
    if unit not in (expected, ""):
        raise DataError(f"{data.source}: channel {name}: unit {unit}, expected {expected} "
                        f"(override with units: {{{name}: {expected}}})")


def _first(data, names, what: str) -> str:
    have = [n for n in names if data.has(n)]
    if not have:
        data.require(names[0])   # the reader's message: missing channel, what the file gives
    if len(have) > 1:
        raise DataError(f"{data.source}: {what} given twice ({' and '.join(have)}); map one of them")
    return have[0]


def read_log(path: str, mapping: dict, units: dict, r: float, torque_gain: float | None = None):
    """``(t, omega, torque, v or None, data)`` of a log in SI (``omega`` [rad/s], the wheel torque [N m], > 0
    drives), checked: DataError (one line, exit 2) for a missing channel, a value that is not finite, a unit of
    the wrong kind, time that does not increase. ``r`` [m]: the wheel radius of a ``romega`` channel."""
    from tirecli.conventions import wheel_torque_from_brake
    from tirecli.io.readers import read_measured

    data = read_measured(path, mapping=mapping or None, units=units or None, require=("t",))
    speed = _first(data, SPEEDS, "the wheel speed")
    torque = _first(data, TORQUES if torque_gain is not None else TORQUES[:2], "the torque")
    if torque == "p" and torque_gain is None:
        raise DataError(f"{data.source}: a brake pressure p needs measurement.torque_gain [N m/Pa]")
    if speed == "romega":
        _unit(data, "romega", "m/s")
    if torque != "p":
        _unit(data, torque, "N m")
    t = data.column("t")
    if len(t) < 2:
        raise DataError(f"{data.source}: {len(t)} sample(s); the observer needs at least 2")
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise DataError(f"{data.source}: t does not increase at row {i + 1} ({t[i - 1]:g} s then {t[i]:g} s); "
                        "a log needs strictly increasing time")
    omega = data.column(speed) / (r if speed == "romega" else 1.0)
    u = data.column(torque)
    if torque == "brake_torque":
        u = wheel_torque_from_brake(u)
    elif torque == "p":
        u = wheel_torque_from_brake(torque_gain * u)
    v = data.column("vx") if data.has("vx") else None
    return t, omega, u, v, data

def plan_log(config, checked: dict, plant, gains, sets: dict, solver, deprecated: list, bytes_per_point: float) -> Plan:
    """Check an observe config on a log: read and check the log, build the cases, size the run."""
    from tirecli.studies.observe.work import log_work_estimate

    meas = checked["measurement"]
    why = {"gain_study": "not available on a measured log; use 'cases' with observer gains",
           "scenario": "a measured log replaces the simulated scenario; drop 'scenario' (estimate.theta is in "
                       "the OBS convention on a log)",
           "metrics": "the phase metrics need the true theta of a simulated plant; a log run is measured against "
                      "the log's vx",
           "output": "a log run is written at the log's sample times; drop 'output'"}
    for key, text in why.items():
        if (key,) in config.origins.where:
            raise ConfigError(config.origins.problem((key,), text))
    path = _log_path(meas["log"], config.base_dir)
    t, omega, torque, v, data = read_log(path, meas["map"], meas["units"], plant.car.r, meas["torque_gain"])
    est = checked["estimate"] or {"v_error": 0.0, "z": 0.0, "theta": 1.0}
    v_ref0 = float(v[0]) if v is not None else plant.car.r * float(omega[0])
    raw = checked["cases"] or [{"label": "nominal"}]
    cases = []
    for j, c in enumerate(raw):
        for key in ("theta", "torque", "measurement"):
            if c.get(key) is not None:
                raise ConfigError(config.origins.problem(("cases", j, key), "a case on a measured log takes only "
                                                                           "'label', 'estimate' and 'observer'"))
        g = gains.replace(**{k: x for k, x in (c.get("observer") or {}).items() if x is not None})
        e = {**est, **{k: x for k, x in (c.get("estimate") or {}).items() if x is not None}}
        cases.append(LogCase(c["label"], g, v_ref0 + e["v_error"], e["z"],
                             float(e["theta"])))
    est_ = log_work_estimate(len(t), len(cases), bytes_per_point)
    est_.check(config.origins)
    return Plan("observe", config, checked, sets, est_,
                ObserveLog(plant, cases, t, omega, torque, v, data.source, data.synthetic, solver, list(deprecated)))


def run_log(plan_: Plan, progress=None) -> StudyResult:
    """Run the observer of every case on the log."""
    import pandas as pd

    from tirecli.conventions import theta_fm_from_obs
    from tirecli.numerics.observer_log import observe_log

    d, checked = plan_.detail, plan_.checked
    r = d.plant.car.r
    frames, runs, trajs, facts = [], [], [], {}
    if progress is not None:
        progress.start(len(d.cases), "observe (log)")
    for case in d.cases:
        tr = observe_log(d.plant, case.gains, d.t, d.omega, d.torque, case.v_hat0, case.z_hat0, case.theta_hat0,
                         rtol=d.solver.rtol, atol=d.solver.atol, h_max=d.solver.h_max)
        cols = {"case": case.label, "t": tr.t, "theta_hat": tr.theta_hat, "theta_hat_fm": theta_fm_from_obs(tr.theta_hat),
                "v_hat": tr.v_hat, "omega_meas": tr.y, "torque": tr.torque, "z_hat": tr.z_hat,
                "vr_hat": r * tr.y - tr.v_hat}
        m = {"theta_hat_final": float(tr.theta_hat[-1]), "v_hat_final": float(tr.v_hat[-1])}
        if d.v is not None:
            tr.v = d.v
            err = tr.v_hat - d.v
            i = int(np.argmax(np.abs(err)))
            cols |= {"v": d.v, "v_error": err}
            m |= {"rms_v_error": float(np.sqrt(np.mean(err ** 2))), "max_abs_v_error": float(abs(err[i])),
                  "max_abs_v_error_at_s": float(d.t[i]), "final_v_error": float(err[-1])}
        frames.append(pd.DataFrame(cols))
        trajs.append(tr)
        runs.append({"label": case.label, "gains": case.gains.as_dict(), "v_hat0": case.v_hat0,
                     "theta_hat0_obs": case.theta_hat0, "integrator": tr.method, "integrator_info": tr.info,
                     "metrics": m})
        facts[case.label] = m
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    return StudyResult(
        study="observe", config=plan_.config,
        parameter_sets={k: plan_.sets[k] for k in ("tire", "vehicle", "observer")},
        data={"observer": pd.concat(frames, ignore_index=True)},
        meta={"title": checked["title"], "log": {"file": d.source, "samples": len(d.t), "t_start_s": float(d.t[0]),
                                                  "t_end_s": float(d.t[-1]), "measured_speed": d.v is not None,
                                                  "hold": "zero-order (each sample held until the next)"},
              "theta_convention": "theta_hat: OBS convention (1 dry, larger = less grip); theta_hat_fm = 1/theta_hat",
              "runs": runs, "warnings": list(d.notes), "assumed": []},
        figures=checked["figures"] or ["obs-fig2"],
        payload={"plant": d.plant, "cases": d.cases, "trajectories": trajs, "runs": runs, "log": True},
        synthetic=d.synthetic,
    )


def facts(result) -> dict:
    """Per case: ``theta_hat_final, v_hat_final`` and, with a measured speed, ``rms_v_error,
    max_abs_v_error, max_abs_v_error_at_s, final_v_error``."""
    from tirecli.studies.facts import named

    return named({r["label"]: dict(r["metrics"]) for r in result.meta["runs"]})


def summary(result) -> list:
    lg = result.meta["log"]
    lines = [f"log {lg['file']}: {lg['samples']} samples, {lg['t_start_s']:g}-{lg['t_end_s']:g} s, "
             "held between samples (zero-order hold); no plant simulated"]
    for r in result.meta["runs"]:
        m = r["metrics"]
        text = f"case {r['label']!r}: theta_hat(end) = {m['theta_hat_final']:.4g} (OBS), v_hat(end) = {m['v_hat_final']:.4g} m/s"
        if "rms_v_error" in m:
            text += (f"; against the measured speed: RMS {m['rms_v_error']:.3g} m/s, max {m['max_abs_v_error']:.3g} m/s "
                     f"at {m['max_abs_v_error_at_s']:.3f} s, final {m['final_v_error']:.3g} m/s")
        lines.append(text)
    if not lg["measured_speed"]:
        lines.append(Line("the log has no vehicle speed (vx): v_hat is not compared with a reference", "note"))
    return lines + [Line(w, "warning") for w in result.meta["warnings"]]
