"""Running a planned ``simulate`` study: the cases solved, their time series, events and synthetic
measurements (see :mod:`tirecli.studies.simulate`)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tirecli.conventions import slip_from_speeds, slip_of
from tirecli.errors import RunError, token
from tirecli.models.profiles import Constant, Table, run_times
from tirecli.numerics import runs
from tirecli.numerics.ros2 import StepUnderflow
from tirecli.studies.base import StudyResult
from tirecli.studies.simulate.planning import Case
from tirecli.studies.simulate.spec import DEFAULT_PRESSURE_GAIN
from tirecli.studies.study import Plan

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

def sample_times(meas, t_end):
    if meas is None:
        return ()
    dt = 1.0 / meas["rate"]
    n = int(np.floor(t_end / dt + 1e-9))
    return tuple(np.round(np.arange(n + 1) * dt, 12))


#: The facts of one run (:func:`case_events`), with the extremum each needs root-found (the costly part).
EVENT_FACTS = ("case", "mode", "model", "t_final", "end", "peak_abs_slip", "t_peak_abs_slip", "min_slip", "t_min_slip",
               "peak_abs_mu", "t_peak_abs_mu", "wheel_lock", "locked_at_end", "stop_time", "stopping_distance",
               "distance", "v_final", "steps", "rejected_steps")


def case_events(tr, case: Case, r: float, which=None) -> dict:
    """Facts of one run: events (lock intervals, stop) and extrema, root-found on the dense output.

    ``which``: the names wanted (default all, :data:`EVENT_FACTS`); an extremum no wanted fact needs
    is not searched (a campaign asks for a few facts of thousands of runs)."""
    def slip(t, Y, O):
        return slip_from_speeds(Y[:, 0], Y[:, 1], r)

    def wanted(*names):
        return which is None or any(n in which for n in names)

    def slip1(t, y, o):  # the same on plain floats (the root-finding's many single points)
        return slip_of(y[0], y[1], r)

    i_mu = tr.out_names.index("mu") if "mu" in tr.out_names else None
    nan = (float("nan"), float("nan"))
    t_s, s_pk = tr.extremum(lambda t, Y, O: np.abs(slip(t, Y, O)), "max", lambda t, y, o: abs(slip1(t, y, o))) \
        if wanted("peak_abs_slip", "t_peak_abs_slip") else nan
    t_smin, s_min = tr.extremum(slip, "min", slip1) if wanted("min_slip", "t_min_slip") else nan
    t_mu, mu_pk = tr.extremum(lambda t, Y, O: np.abs(O["mu"]), "max", lambda t, y, o: abs(o[i_mu])) \
        if wanted("peak_abs_mu", "t_peak_abs_mu") else nan
    stop = tr.events["stop"]
    locks = [[a, b] for a, b in tr.events["lock"]]
    ev = {
        "case": case.label, "mode": case.mode, "model": case.variant.default_label(),
        "t_final": float(tr.t[-1]), "end": tr.events["reason"],
        "peak_abs_slip": float(s_pk), "t_peak_abs_slip": float(t_s),
        "min_slip": float(s_min), "t_min_slip": float(t_smin),
        "peak_abs_mu": float(mu_pk), "t_peak_abs_mu": float(t_mu),
        "wheel_lock": locks, "locked_at_end": bool(tr.out["locked"][-1] > 0.5),
        "stop_time": stop, "stopping_distance": float(tr.out["distance"][-1]) if stop is not None else None,
        "distance": float(tr.out["distance"][-1]), "v_final": float(tr.y[-1, 0]),
        "steps": tr.stats["steps"], "rejected_steps": tr.stats["rejected"],
    }
    return ev if which is None else {k: v for k, v in ev.items() if k in which}


def event_rows(ev: dict) -> list:
    """Long-format rows of data/events.csv: each lock as an interval, the stop, the extrema, the end."""
    base = {"case": ev["case"], "mode": ev["mode"], "model": ev["model"]}
    rows = [{**base, "event": "wheel_lock", "t": a, "t_end": b, "value": np.nan, "unit": ""} for a, b in ev["wheel_lock"]]
    if ev["stop_time"] is not None:
        rows.append({**base, "event": "stop", "t": ev["stop_time"], "t_end": np.nan, "value": ev["stopping_distance"],
                     "unit": "m (stopping distance)"})
    rows += [
        {**base, "event": "peak_abs_slip", "t": ev["t_peak_abs_slip"], "t_end": np.nan, "value": ev["peak_abs_slip"], "unit": "-"},
        {**base, "event": "min_slip", "t": ev["t_min_slip"], "t_end": np.nan, "value": ev["min_slip"], "unit": "-"},
        {**base, "event": "peak_abs_mu", "t": ev["t_peak_abs_mu"], "t_end": np.nan, "value": ev["peak_abs_mu"], "unit": "-"},
        {**base, "event": "end", "t": ev["t_final"], "t_end": np.nan, "value": ev["v_final"], "unit": f"m/s ({ev['end']})"},
    ]
    return rows


def thinned(n: int, points: int) -> np.ndarray:
    """Indices of every k-th of ``n`` rows, the last one kept: at most ``points + 1`` rows."""
    keep = np.zeros(n, dtype=bool)
    keep[::-(-n // points)] = True
    keep[-1:] = True
    return np.flatnonzero(keep)


def case_frame(tr, case: Case, dt: float, r: float, gain: float, points: int | None = None,
           keep: bool = True) -> pd.DataFrame:
    """The time series of a run on the output grid, from the integrator's dense output (states
    interpolated by the step's cubic Hermite, outputs evaluated by the model there).

    ``points``: only every k-th row of the grid, the last kept (:func:`thinned`; the rows the
    figures draw), evaluated alone: the same values as those rows of the whole frame. ``keep=False``:
    the samples are not kept with the run (:meth:`~tirecli.numerics.ros2.Trajectory.sample`)."""
    import pandas as pd

    t = tr.t
    if dt > 0:
        n = int(np.floor(t[-1] / dt + 1e-9))
        tg = np.round(np.arange(n + 1) * dt, 12)
        if tg[-1] < t[-1] - 1e-12:
            tg = np.append(tg, t[-1])
        if points is not None:
            tg = tg[thinned(tg.size, points)]
        Y, O = tr.sample(tg, keep)
        distance = runs.distance_at(tr, tg)
    else:
        tg, Y, O, distance = t, tr.y, tr.out, tr.out["distance"]
        if points is not None:
            rows = thinned(t.size, points)
            O = {k: np.asarray(O[k])[rows] for k in ("vr", "mu", "torque", "brake_torque", "theta", "zdot", "kappa0",
                                                     "zbar", "locked") if k in O}
            tg, Y, distance = t[rows], Y[rows], distance[rows]
    out = {"case": case.label, "mode": case.mode, "model": case.variant.default_label(), "t": tg,
           "v": Y[:, 0], "omega": Y[:, 1], "romega": r * Y[:, 1]}
    for k in ("vr", "mu", "torque", "brake_torque", "theta", "zdot", "kappa0"):
        out[k] = np.asarray(O[k], dtype=float)
    out["zbar"] = np.asarray(O["zbar"], dtype=float) if "zbar" in O else Y[:, 2]
    if case.mode != "coupled":  # the tire alone: no wheel torque
        out["torque"] = np.full(tg.size, np.nan)
        out["brake_torque"] = np.full(tg.size, np.nan)
    out["locked"] = (np.asarray(O["locked"]) > 0.5).astype(int)
    out["distance"] = distance
    out["pressure"] = out["brake_torque"] / gain
    out["slip"] = slip_from_speeds(out["v"], out["omega"], r)
    return pd.DataFrame({k: out[k] for k in TIMESERIES_COLUMNS})


#: Above this many cases the time series is streamed to disk case by case (memory flat in the cases).
SPOOL_CASES = 12
#: Rows of the streamed time series written to disk at once (one CSV block; memory stays flat in the cases).
SPOOL_ROWS = 32768
#: Points of one case's time series kept for the figures when it is streamed (a figure is ~1000 pixels wide).
DRAWN_POINTS = 2000
TIMESERIES_COLUMNS = ["case", "mode", "model", "t", "v", "omega", "romega", "slip", "vr", "mu", "torque", "brake_torque",
                      "pressure", "theta", "zbar", "zdot", "kappa0", "locked", "distance"]


def timeseries_frames(trs: dict, cases: list, dt: float, r: float, gain: float):
    """``(timeseries, drawn, events)``: the frame ``timeseries`` of every case (:func:`case_frame`), when it
    is streamed ``{label: frame}`` of each case's rows thinned for the figures (else None), and the
    facts of every case (:func:`case_events`).

    Up to :data:`SPOOL_CASES` cases the frame is a DataFrame. With more, each case's rows are written
    to disk, :data:`SPOOL_ROWS` rows at a time (:class:`tirecli.io.output.SpooledFrame`, copied into
    ``data/timeseries.csv``; the same text) and the figures draw every k-th row (at most
    :data:`DRAWN_POINTS` a case, the last kept). With a spare core a helper process finds the events
    and formats the rows (:meth:`~tirecli.io.output.SpooledFrame.extend`) while this one evaluates
    the rows drawn and goes on to the figures; the same numbers and text."""
    import pandas as pd

    def events():
        return [case_events(trs[c.label], c, r) for c in cases]

    if len(cases) <= SPOOL_CASES:
        frame = pd.concat([case_frame(trs[c.label], c, dt, r, gain) for c in cases], ignore_index=True)
        return frame, None, events()
    from tirecli.io.output import SpooledFrame
    from tirecli.parallel import helper_process_ok

    drawn = {}
    helper = helper_process_ok()

    def parts():  # a few cases at a time: fewer, larger CSV blocks
        pending, rows = [], 0
        for i, c in enumerate(cases):
            f = case_frame(trs[c.label], c, dt, r, gain, keep=False)
            if not helper:  # in this process: the rows drawn taken from the whole frame
                drawn[c.label] = f.iloc[thinned(len(f), DRAWN_POINTS)].reset_index(drop=True)
            pending.append(f)
            rows += len(f)
            if rows >= SPOOL_ROWS or i == len(cases) - 1:
                yield pd.concat(pending, ignore_index=True) if len(pending) > 1 else f
                pending, rows = [], 0

    spool = SpooledFrame(TIMESERIES_COLUMNS)
    found = spool.extend(parts(), background=helper, first=events)
    if helper:  # the helper makes the whole frames: the rows drawn evaluated alone here, meanwhile
        drawn = {c.label: case_frame(trs[c.label], c, dt, r, gain, DRAWN_POINTS, keep=False) for c in cases}
    return spool, drawn, found()


def measure(trs: dict, labels: list, meas: dict, r: float, gain: float):
    """Synthetic samples of the coupled runs: (noisy, clean) frames ``t, pressure, torque, v, romega, s, mu``."""
    import pandas as pd

    rng = np.random.default_rng(int(meas["seed"]))
    dt = 1.0 / meas["rate"]
    starts = meas["record_starts"] or [0.0] * len(labels)
    noisy, clean = [], []
    for k, (lab, t0) in enumerate(zip(labels, starts)):
        tr = trs[lab]
        n = int(np.floor(tr.t[-1] / dt + 1e-9))
        ts = np.round(np.arange(n + 1) * dt, 12)
        Y, O = tr.sample(ts)   # the sample times are step ends: exact values (dense output elsewhere)
        v = Y[:, 0]
        rw = r * Y[:, 1]
        mu = np.asarray(O["mu"], dtype=float)
        torque = np.asarray(O["torque"], dtype=float)
        pres = np.asarray(O["brake_torque"], dtype=float) / gain
        base = {"braking": k + 1, "case": lab, "t": ts, "t_record": ts + t0}
        clean.append(pd.DataFrame({**base, "pressure": pres, "torque": torque + 0.0, "v": v, "romega": rw,
                                   "s": slip_from_speeds(v, rw / r, r), "mu": mu}))
        nz = meas["noise"]
        vn = v + rng.normal(0.0, nz["speed"], ts.size) if nz["speed"] > 0 else v
        rwn = rw + rng.normal(0.0, nz["speed"], ts.size) if nz["speed"] > 0 else rw
        pn = pres + rng.normal(0.0, nz["pressure"], ts.size) if nz["pressure"] > 0 else pres
        mun = mu + rng.normal(0.0, nz["mu"], ts.size) if nz["mu"] > 0 else mu
        vn, rwn = np.maximum(vn, 0.0), np.maximum(rwn, 0.0)
        noisy.append(pd.DataFrame({**base, "pressure": pn, "torque": -gain * pn, "v": vn, "romega": rwn,
                                   "s": slip_from_speeds(vn, rwn / r, r), "mu": mun}))
    return pd.concat(noisy, ignore_index=True), pd.concat(clean, ignore_index=True)


#: A wheel torque above this multiple of ``r F_n`` (the tire's torque at mu = 1) is named as the likely cause
#: of a step-size underflow (measured: the FM braking still runs at 6e13 r F_n, the wheel locking at once;
#: at 6e18 r F_n the step underflows), far beyond any brake.
IMPLAUSIBLE_TORQUE = 1e6


def _underflow_cause(err, case, car, t_end) -> RunError:
    """The step-size underflow of a coupled case as a one-line error naming an implausible wheel torque
    input (its peak over the run against ``r F_n``) when there is one, else ``err`` with the case's label."""
    tq = case.torque
    peak = float(np.max(np.abs(np.asarray(tq(run_times(t_end, None, tq.breakpoints(t_end))), dtype=float))))
    scale = car.r * car.F_n
    where = f"case {token(case.label)}: {err}"
    if not peak > IMPLAUSIBLE_TORQUE * scale:
        return RunError(where)
    key = "input.pressure * input.pressure_gain" if case.pressure is not None else "the torque input (input.torque or input.brake_torque)"
    return RunError(f"case {token(case.label)}: time step underflow at t = {err.t:.6g} s: the wheel torque reaches "
                    f"{peak:.3g} N m ({key}), {peak / scale:.2g} times r F_n = {scale:.4g} N m, far beyond any brake; "
                    "the wheel speed changes faster than the time step can resolve")


def run_cases(cases, p, car, t_end, sample_times=(), progress=None) -> dict:
    """Run every case (coupled first, then the open-loop ones they drive); ``label -> Trajectory``."""
    trs = {}
    if progress is not None:
        progress.start(len(cases), "simulate")
    for c in sorted(cases, key=lambda c: c.mode != "coupled"):
        if c.mode == "coupled":
            try:
                trs[c.label] = runs.quarter_car(c.variant, p, car, c.torque, c.theta, c.v0, c.omega0, t_end, c.solver,
                                                sample_times, reuse=True)
            except StepUnderflow as err:
                raise _underflow_cause(err, c, car, t_end) from err
        else:
            if c.drive_case is not None:
                drv = trs[c.drive_case]
                dcase = next(d for d in cases if d.label == c.drive_case)
                bps = tuple(dcase.torque.breakpoints(t_end)) + tuple(dcase.theta.breakpoints(t_end)) + tuple(sample_times)
                vp, wp = runs.kinematics_of(drv, c.drive_case, bps)
                c.drive = (vp, wp)
                te = float(drv.t[-1])
            else:
                vp, wp = c.drive
                bps = [b for b in tuple(vp.breakpoints(t_end)) + tuple(wp.breakpoints(t_end))]
                te = min(t_end, max(bps)) if isinstance(vp, Table) and bps else t_end
            tr = runs.open_loop(c.variant, p, car, vp, wp, c.theta or Constant(1.0), te, c.solver)
            if te < t_end and tr.events.get("reason") == "t_end":  # no kinematics after the drive's end
                tr.events["reason"] = "end of the drive"
            trs[c.label] = tr
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    return trs


def run(plan_: Plan, progress=None) -> StudyResult:
    """Run a planned simulate study (see :mod:`tirecli.studies.simulate`)."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    config, checked, cases = plan_.config, plan_.checked, plan_.detail
    tire, vehicle = plan_.sets["tire"], plan_.sets["vehicle"]

    p, car = tire.model(), vehicle.model()
    meas = checked["measurement"]
    t_end = checked["t_end"]
    gain = (checked["input"] or {}).get("pressure_gain") or DEFAULT_PRESSURE_GAIN
    trs = run_cases(cases, p, car, t_end, sample_times(meas, t_end), progress)
    timeseries, drawn, events = timeseries_frames(trs, cases, checked["output"]["dt"], car.r, gain)
    data = {"timeseries": timeseries,
            "events": pd.DataFrame([row for e in events for row in event_rows(e)])}
    synthetic = False
    if meas is not None:
        labels = meas["cases"] or [c.label for c in cases if c.mode == "coupled"]
        data["measured"], data["measured_clean"] = measure(trs, labels, meas, car.r, gain)
        synthetic = True
    figures = checked["figures"] or ["transient-histories", "transient-mu-slip", "transient-overlay"]
    meta = {
        "title": checked["title"],
        "cases": [c.record() for c in cases],
        "events": events,
        "stop_condition": f"a run ends at t_end = {t_end:g} s, or when the vehicle speed falls to v_min = "
                          f"{checked['stop']['v_min']:g} m/s (the quarter car has no model of a vehicle at rest)",
        "wheel_lock": "brake torque never reverses the wheel: omega = 0 is held while |r F| <= T_b (docs/models/lugre_friction.md §7)",
        "pressure_gain_N_m_per_bar": gain,
        "theta_stored": "fm (g -> theta*g; theta_obs = 1/theta)",
        "solver": "adaptive ROS2 (tirecli.numerics.ros2); distributed model exact along characteristics",
        "timeseries_dt_s": checked["output"]["dt"],
    }
    if meas is not None:
        meta["measurement"] = {**meas, "note": "synthetic samples of the simulated runs (seeded noise), not measured data"}
    inp = checked["input"] or {}
    uses_pressure = inp.get("pressure") is not None or meas is not None or any(c.pressure is not None for c in cases)
    if uses_pressure and (inp.get("pressure_gain") in (None, DEFAULT_PRESSURE_GAIN)):
        meta["assumed"] = [f"input.pressure_gain = {DEFAULT_PRESSURE_GAIN:g} N m/bar: brake torque per unit pressure "
                           "(docs/models/lugre_friction.md §10, FM Fig. 4) [assumed]; override with --set input.pressure_gain=VALUE"]
    return StudyResult(
        study="simulate", config=config, parameter_sets={"tire": tire, "vehicle": vehicle}, data=data, meta=meta,
        figures=figures, payload={"params": p, "car": car, "cases": cases, "runs": trs, "checked": checked,
                                  "timeseries_drawn": drawn},
        synthetic=synthetic,
    )
