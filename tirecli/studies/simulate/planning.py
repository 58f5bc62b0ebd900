"""Planning a ``simulate`` run: the config checked completely, its cases (inputs, initial states, solver
options, open-loop drives) built and its size estimated (see :mod:`tirecli.studies.simulate`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.profiles import profile_from_checked, profile_problems
from tirecli.config.schema import collect
from tirecli.conventions import omega_from_slip
from tirecli.errors import ConfigError, DataError, token
from tirecli.models.profiles import Constant, Table, run_times
from tirecli.numerics import runs
from tirecli.studies.simulate.spec import (DEFAULT_INPUT, DEFAULT_VEHICLE, DRIVE, INPUT, ROS2_BECAUSE, SPEC,
                                           TORQUE_KEYS)
from tirecli.studies.study import Plan
from tirecli.studies.sweep import make_variant

class _Reciprocal:
    """A profile's reciprocal (theta given in the OBS convention: theta_fm = 1/theta_obs)."""

    def __init__(self, prof):
        self.prof = prof

    def __call__(self, t):
        return 1.0 / np.asarray(self.prof(t), dtype=float) if np.ndim(t) else 1.0 / self.prof(t)

    def at(self, t):
        return 1.0 / self.prof.at(t)

    def breakpoints(self, t_end=None):
        return self.prof.breakpoints(t_end)

    def record(self):
        return {"kind": "reciprocal (theta_obs -> theta_fm)", "of": self.prof.record()}


class _Scaled:
    """``factor * profile`` (brake torque from pressure, signed torque from brake torque)."""

    def __init__(self, prof, factor, what):
        self.prof, self.factor, self.what = prof, float(factor), what

    def __call__(self, t):
        return self.factor * np.asarray(self.prof(t), dtype=float) if np.ndim(t) else self.factor * self.prof(t)

    def at(self, t):
        return self.factor * self.prof.at(t) + 0.0  # no negative zero

    def breakpoints(self, t_end=None):
        return self.prof.breakpoints(t_end)

    def record(self):
        return {"kind": self.what, "factor": self.factor, "of": self.prof.record()}

    def __eq__(self, other):  # by value, like the profiles (the key of a kept run, tirecli.numerics.runs)
        return type(other) is _Scaled and (self.prof, self.factor, self.what) == (other.prof, other.factor, other.what)

    def __hash__(self):
        return hash((self.prof, self.factor, self.what))


class Case:
    """One planned run: variant, inputs, initial state, solver options, open-loop drive."""

    def __init__(self, variant, label, torque=None, pressure=None, theta=None, v0=None, omega0=None,
                 solver=None, drive=None, drive_case=None, mode="coupled", driven_by=""):
        self.variant, self.label = variant, label
        self.torque, self.pressure, self.theta = torque, pressure, theta
        self.v0, self.omega0 = v0, omega0
        self.solver = solver
        self.drive, self.drive_case = drive, drive_case
        self.mode, self.driven_by = mode, driven_by

    def record(self) -> dict:
        rec = {"label": self.label, "mode": self.mode, "variant": self.variant.record(),
               "solver": {"method": "ros2", "chosen_because": ROS2_BECAUSE,
                          "tol": self.solver.tol_for(self.variant), "h_max": self.solver.h_max,
                          "v_stop": self.solver.v_stop}}
        if self.mode == "coupled":
            rec.update({"v0": self.v0, "omega0": self.omega0, "torque": self.torque.record(),
                        "theta_fm": self.theta.record()})
        else:
            rec["driven_by"] = self.driven_by
            if self.drive is not None:
                rec["kinematics"] = {"v": self.drive[0].record(), "omega": self.drive[1].record()}
        return rec


def _merge_input(base: dict, over: dict | None) -> dict:
    if not over:
        return base
    out = dict(base)
    if any(over.get(k) is not None for k in TORQUE_KEYS):
        for k in TORQUE_KEYS:
            out[k] = over.get(k)
    for k in ("pressure_gain", "theta", "theta_convention"):
        if over.get(k) is not None:
            out[k] = over[k]
    return out


def _inputs(inp: dict, base_dir):
    """(signed torque profile, pressure profile or None, theta_fm profile, {key: profile as given})
    from a checked input block (the profiles as given are checked against their limits over the run)."""
    gain = inp["pressure_gain"]
    pressure = None
    given = {}
    if inp.get("torque") is not None:
        torque = given["torque"] = profile_from_checked(inp["torque"], base_dir)
    elif inp.get("brake_torque") is not None:
        given["brake_torque"] = profile_from_checked(inp["brake_torque"], base_dir)
        torque = _Scaled(given["brake_torque"], -1.0, "brake torque (u = -T_b)")
    elif inp.get("pressure") is not None:
        pressure = given["pressure"] = profile_from_checked(inp["pressure"], base_dir)
        torque = _Scaled(pressure, -gain, f"brake pressure (u = -{gain:g} N m/bar * p)")
    else:
        torque = Constant(0.0)
    theta = given["theta"] = profile_from_checked(inp["theta"], base_dir)
    if inp["theta_convention"] == "obs":
        theta = _Reciprocal(theta)
    return torque, pressure, theta, given


def _drive_profiles(drive: dict, base_dir, r: float, where: str):
    """Kinematics profiles ``(v, omega)`` of an open-loop drive given by CSV or profiles."""
    if drive["csv"] is not None:
        from tirecli.io.data import data_rows, frame_columns, read_table, rename_columns, select_rows

        path = Path(drive["csv"])
        if not path.is_absolute():
            path = Path(base_dir) / path
        frame = select_rows(rename_columns(read_table(path), drive["map"], path), drive["where"], path,
                            f"{where}.where")
        data = frame_columns(frame, ["t", "v"], path, increasing="t", optional=["s", "romega", "omega"])
        t, v = data["t"], data["v"]
        if "s" in data:
            omega = omega_from_slip(data["s"], v, r)
        elif "romega" in data:
            omega = data["romega"] / r
        elif "omega" in data:
            omega = data["omega"]
        else:
            raise DataError(f"{path}: {where}: needs a slip column 's', or 'romega' [m/s], or 'omega' [rad/s] "
                            "(rename columns with drive.map: {FILE_COLUMN: NAME})")
        rows = data_rows(frame)  # data rows of the file (before 'where' selected some)
        second = "s" if "s" in data else ("romega" if "romega" in data else "omega")
        if "s" in data:
            bad = np.flatnonzero((data["s"] < -1.0) | (data["s"] > 1.0))
            if bad.size:
                i = int(bad[0])
                raise DataError(f"{path}: {where}: column 's' row {rows[i]} (t = {t[i]:g} s): slip {data['s'][i]:g} "
                                "is out of range: must be >= -1 and <= 1")
        for name, col in (("v", v), (second, data[second])):
            bad = np.flatnonzero(col < 0)
            if bad.size and name != "s":
                i = int(bad[0])
                raise DataError(f"{path}: {where}: column {name!r} row {rows[i]} (t = {t[i]:g} s): {col[i]:g} is "
                                "negative (speeds are forward motion, >= 0)")
        bad = np.flatnonzero(~np.isfinite(omega))
        if bad.size:
            i = int(bad[0])
            raise DataError(f"{path}: {where}: row {rows[i]} (t = {t[i]:g} s): slip 1 at the speed v = {v[i]:g} m/s "
                            "has no finite wheel speed")
        src = str(path)
        return Table(tuple(t), tuple(v), source=src), Table(tuple(t), tuple(omega), source=src), {}
    given = {"v": profile_from_checked(drive["v"], base_dir)}
    vp = given["v"]
    if drive["omega"] is not None:
        given["omega"] = profile_from_checked(drive["omega"], base_dir)
        return vp, given["omega"], given
    if drive["romega"] is not None:
        given["romega"] = profile_from_checked(drive["romega"], base_dir)
        return vp, _Scaled(given["romega"], 1.0 / r, "romega / r"), given
    given["slip"] = profile_from_checked(drive["slip"], base_dir)
    return vp, _SlipOmega(vp, given["slip"], r), given


class _SlipOmega:
    """``omega(t)`` from prescribed ``v(t)`` and slip ``s(t)`` (conventions.omega_from_slip)."""

    def __init__(self, vp, sp, r):
        self.vp, self.sp, self.r = vp, sp, r

    def __call__(self, t):
        return omega_from_slip(self.sp(t), self.vp(t), self.r)

    def at(self, t):
        s = self.sp.at(t)
        v = self.vp.at(t)
        return (v * (1.0 + s) if s <= 0.0 else v / (1.0 - s)) / self.r

    def breakpoints(self, t_end=None):
        return tuple(self.vp.breakpoints(t_end)) + tuple(self.sp.breakpoints(t_end))

    def record(self):
        return {"kind": "omega from v and slip", "v": self.vp.record(), "slip": self.sp.record()}


def _slip_problems(slip_cases, origins, t_end, dt) -> list:
    """A prescribed slip of 1 while v > 0 has no finite wheel speed: name the time (open-loop drives)."""
    out = []
    for case, path in slip_cases:
        wp = case.drive[1]
        t = run_times(t_end, dt, wp.breakpoints(t_end))
        with np.errstate(all="ignore"):
            w = np.asarray(wp(t), dtype=float)
        bad = np.flatnonzero(~np.isfinite(w))
        if bad.size:
            k = int(bad[0])
            out.append(origins.problem(path, f"slip {float(wp.sp(t[k])):g} at v = {float(wp.vp(t[k])):g} m/s "
                                             f"(t = {t[k]:.9g} s) has no finite wheel speed (slip 1 needs v = 0)"))
    return out


def plan(config: Config) -> Plan:
    """Check a simulate config completely: sets ``tire`` and ``vehicle``, detail the list of :class:`Case`
    (coupled cases first as given, then the open-loop models of ``open_loop`` driven by them)."""
    checked, tire, vehicle = collect(lambda: config.checked(SPEC), lambda: config.group("tire", "lugre"),
                                     lambda: config.group("vehicle", "quarter_car", DEFAULT_VEHICLE))
    tire.model()  # builds the tyre model: checks the set's values against each other
    car = vehicle.model()
    base_dir = config.base_dir
    gsolver = checked["solver"]
    cases = []
    problems = []
    to_check, slip_cases = [], []
    for i, raw in enumerate(checked["cases"]):
        path = ("cases", i)
        variant = make_variant(raw)
        extra = raw if isinstance(raw, dict) else {}
        inp = _merge_input(checked["input"] or DEFAULT_INPUT, extra.get("input"))
        torque, pressure, theta, given = _inputs(inp, base_dir)
        over_inp = extra.get("input") or {}
        for key, prof in given.items():
            own = any(over_inp.get(k) is not None for k in TORQUE_KEYS) if key in TORQUE_KEYS else \
                over_inp.get(key) is not None
            to_check.append((prof, INPUT.fields[key], (path + ("input", key)) if own else ("input", key)))
        init = dict(checked["initial"])
        over = extra.get("initial") or {}
        if over.get("v") is not None:
            init["v"] = over["v"]
        if over.get("slip") is not None or over.get("omega") is not None:
            init["slip"], init["omega"] = over.get("slip") or 0.0, over.get("omega")
        v0 = init["v"]
        omega0 = init["omega"] if init["omega"] is not None else float(omega_from_slip(init["slip"], v0, car.r))
        if not np.isfinite(omega0):
            problems.append(config.origins.problem(path + ("initial",), "slip 1 at a positive speed has no finite wheel speed"))
        sol = {**gsolver, **{k: v for k, v in (extra.get("solver") or {}).items() if v is not None}}
        options = runs.SolverOptions(tol=sol["tol"], h_max=sol["h_max"], v_stop=checked["stop"]["v_min"])
        drive = extra.get("drive")
        case = Case(variant, variant.label, torque, pressure, theta, v0, omega0, options)
        if drive is not None:
            case.mode = "open-loop"
            if drive["case"] is not None:
                case.drive_case = drive["case"]
                case.driven_by = drive["case"]
            else:
                try:
                    vp, wp, dgiven = _drive_profiles(drive, base_dir, car.r, f"cases[{i}].drive")
                except DataError as err:
                    raise DataError(f"{config.label}: cases[{i}].drive: {err}") from None
                case.drive = (vp, wp)
                to_check += [(prof, DRIVE.fields[key], path + ("drive", key)) for key, prof in dgiven.items()]
                if "slip" in dgiven:
                    slip_cases.append((case, path + ("drive", "slip")))
                case.driven_by = "csv" if drive["csv"] is not None else "profiles"
        cases.append(case)
    # every input profile within its limits over the whole run (the output grid, a fine uniform grid,
    # and both sides of every breakpoint: a formula's switch times, a table's rows, a transition's ends)
    t_end, dt = checked["t_end"], checked["output"]["dt"]
    if not problems:  # the sample budget first (the open-loop cases come below): the checks over the run cost time
        _estimate(checked, cases, to_check).check(config.origins)
    problems += profile_problems(to_check, config.origins, t_end, dt)
    if not problems:
        problems += _slip_problems(slip_cases, config.origins, t_end, dt)
    labels = [c.label for c in cases]
    for i, c in enumerate(cases):
        if labels.count(c.label) > 1:
            problems.append(config.origins.problem(("cases", i), f"two cases share the label {token(c.label)}; give each a distinct 'label'"))
            break
    coupled = [c.label for c in cases if c.mode == "coupled"]
    for i, c in enumerate(cases):
        if c.drive_case is not None and c.drive_case not in coupled:
            problems.append(config.origins.problem(("cases", i, "drive", "case"),
                                                   f"no coupled case labelled {token(c.drive_case)} (coupled cases: {', '.join(coupled) or 'none'})"))
    ol = checked["open_loop"]
    if ol is not None:
        for j, lab in enumerate(ol["cases"] or []):
            if lab not in coupled:
                problems.append(config.origins.problem(("open_loop", "cases", j), f"no coupled case labelled {token(lab)}"))
    meas = checked["measurement"]
    if meas is not None:
        for j, lab in enumerate(meas["cases"] or []):
            if lab not in coupled:
                problems.append(config.origins.problem(("measurement", "cases", j), f"no coupled case labelled {token(lab)}"))
        n = len(meas["cases"] or coupled)
        if meas["record_starts"] is not None and len(meas["record_starts"]) != n:
            problems.append(config.origins.problem(("measurement", "record_starts"),
                                                   f"expected one start time per sampled case ({n}), got {len(meas['record_starts'])}"))
    if problems:
        raise ConfigError(problems)
    if ol is not None:
        drivers = ol["cases"] or coupled
        for raw in ol["models"]:
            variant = make_variant(raw)
            for lab in drivers:
                base = next(c for c in cases if c.label == lab)
                cases.append(Case(variant, f"{variant.label} | {lab}", theta=base.theta, solver=base.solver,
                                  drive_case=lab, mode="open-loop", driven_by=lab))
                cases[-1].solver = runs.SolverOptions(tol=gsolver["tol"], h_max=gsolver["h_max"],
                                                      v_stop=checked["stop"]["v_min"])
    est = _estimate(checked, cases, to_check)
    est.check(config.origins)
    return Plan("simulate", config, checked, {"tire": tire, "vehicle": vehicle}, est, cases)


#: Memory of one stored solver step, of one row of data/timeseries.csv and of one measured sample [bytes]
#: (measured: 200,000 steps and rows of the distributed model peak at 0.6 GB above the interpreter's).
BYTES_PER_STEP, BYTES_PER_ROW, BYTES_PER_SAMPLE = 1000, 2000, 400


def _estimate(checked: dict, cases: list, inputs=()):
    """Samples of a run before it starts: solver steps (at least ``t_end/h_max``, and a step end at each
    measurement sample), the steps the ``inputs`` (``(profile, spec, key path)``) force by their switches and
    oscillations (:func:`tirecli.numerics.runs.input_steps`), output rows (``t_end/output.dt``, or the steps
    when 0) and measured samples."""
    from tirecli.limits import Estimate, steps

    t_end, dt, meas = checked["t_end"], checked["output"]["dt"], checked["measurement"]
    per_case = steps(t_end, 1.0 / meas["rate"]) if meas is not None else 0.0
    coupled = [c.label for c in cases if c.mode == "coupled"]
    n_steps = sum(steps(t_end, c.solver.h_max) + (per_case if c.mode == "coupled" else 0.0) for c in cases)
    est = Estimate()
    est.add(n_steps, (("solver", "h_max"), ("t_end",)) + tuple(("cases", i, "solver", "h_max") for i in range(len(cases))),
            f"the solver steps ({len(cases)} case(s) x {t_end:g} s, steps of at most h_max"
            + (f" ending at each of {meas['rate']:g} samples per second)" if meas is not None else ")"), BYTES_PER_STEP)
    for prof, _, path in inputs:
        forced, switches, hz = runs.input_steps(prof, t_end)
        if forced:
            how = ", ".join(([f"{switches:,} switches"] if switches else []) + ([f"oscillating at up to {hz:.3g} Hz"] if hz else []))
            est.add(forced, (tuple(path),), f"the solver steps to follow {'.'.join(map(str, path))} ({how} over {t_end:g} s)",
                    BYTES_PER_STEP)
    rows = n_steps if dt == 0 else len(cases) * steps(t_end, dt)
    est.add(rows, (("output", "dt"), ("t_end",), ("cases",)),
            f"data/timeseries.csv ({len(cases)} case(s) x {t_end:g} s every {dt:g} s)", BYTES_PER_ROW)
    if meas is not None:
        n = len(meas["cases"] or coupled)
        est.add(2 * n * per_case, (("measurement", "rate"), ("t_end",)),
                f"the measured samples ({n} case(s) x {t_end:g} s x {meas['rate']:g} Hz, noisy and clean)", BYTES_PER_SAMPLE)
    return est

