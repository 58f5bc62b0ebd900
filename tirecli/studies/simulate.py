"""Transient runs: the quarter car braking/driving with lumped or distributed LuGre tires, and the tire alone.

Config (``tirecli simulate CONFIG``)::

    study: simulate
    tire: canudas2003-table2                 # LuGre set (name, file, or {set: ..., overrides})
    vehicle: canudas2003-obs-quarter-car     # quarter-car set (default) [assumed for FM, docs/models/lugre_friction.md §7]
    initial: {v: 20, slip: 0}                # or {v: 20, omega: 80}; the bristles start undeformed
    input:                                   # exactly one of torque / brake_torque / pressure
      brake_torque: {initial: 0, changes: [{at: 0.5, duration: 1.5, to: 1000, shape: linear},
                                           {at: 2.0, duration: 0.6, to: 0, shape: linear}]}
      # torque: PROFILE         signed wheel torque [N m] (> 0 drives, < 0 brakes)
      # pressure: PROFILE       brake pressure [bar], brake torque = pressure_gain * pressure
      pressure_gain: 20                      # [N m/bar] (docs/models/lugre_friction.md §10, FM Fig. 4) [assumed]
      theta: 1.0                             # adhesion profile, FM convention unless theta_convention: obs
    t_end: 5.0                               # [s]
    stop: {v_min: 0.1}                       # the run ends when v falls to v_min [m/s]
    solver: {tol: null, h_max: 0.05}         # null: 1e-3 lumped, 3e-4 distributed
    cases:                                   # model variants, run side by side
      - {model: lumped, kappa0: 1}
      - {model: lumped, kappa0: Z}
      - {model: distributed, load: uniform, label: PDE}
      - {model: lumped, kappa0: 2, drive: {case: PDE}}          # open loop, driven by another case
      - {model: lumped, kappa0: Z, drive: {csv: run.csv, map: {slip: s}}}   # ... by measured t, v, s
      - {model: distributed, drive: {v: 20, slip: {expr: "-0.1*(t > 0.01)"}}}   # ... by formulas
    open_loop: {models: [{model: lumped, kappa0: 1}]}   # every model driven by every coupled case
    measurement: {rate: 100, noise: {speed: 0.05, pressure: 0.5}, seed: 2003}  # synthetic samples
    output: {dt: 0.001}                      # time step of data/timeseries.csv (0: solver steps)

A case may override ``input``, ``initial`` and ``solver``. Profiles are those of
:mod:`tirecli.models.profiles` (number, table, transitions, CSV, formula). Brake torque never turns
the wheel backwards: the wheel locks and stays locked while the brake can hold the tire torque
(docs/models/lugre_friction.md §7). Frames: ``timeseries`` (``case, mode, t, v, omega, romega, slip, vr, mu, torque,
brake_torque, pressure, theta, zbar, zdot, kappa0, locked, distance``), ``events`` (one row per
case) and, with ``measurement``, ``measured`` / ``measured_clean`` (synthetic samples ``t, pressure,
torque, v, romega, s, mu`` with and without noise).
"""
from __future__ import annotations

import copy
from pathlib import Path

from typing import TYPE_CHECKING

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.profiles import profile_from_checked, profile_problems, profile_spec
from tirecli.config.schema import AnyOf, ListOf, Map, Nullable, Num, Raw, Str, collect
from tirecli.conventions import THETA_CONVENTIONS, omega_from_slip, slip_from_speeds, slip_of
from tirecli.errors import ConfigError, DataError, RunError, token
from tirecli.models.profiles import Constant, Table, run_times
from tirecli.models.variants import MODELS
from tirecli.numerics import runs
from tirecli.numerics.ros2 import StepUnderflow
from tirecli.studies.base import StudyResult, common_fields, register_study
from tirecli.studies.sweep import VARIANT, make_variant

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

DEFAULT_VEHICLE = "canudas2003-obs-quarter-car"
TORQUE_KEYS = ("torque", "brake_torque", "pressure")
#: Brake pressure to torque (docs/models/lugre_friction.md §10, FM Fig. 4): torque = 20 N m/bar * pressure [assumed].
DEFAULT_PRESSURE_GAIN = 20.0


def _optional(spec):
    spec.default = None
    return spec


def _input_fields(defaults: bool) -> dict:
    return {
        "torque": _optional(profile_spec("N m")),
        "brake_torque": _optional(profile_spec("N m", lo=0.0)),
        "pressure": _optional(profile_spec("bar", lo=0.0)),
        "pressure_gain": Num(unit="N m/bar", gt=0, default=DEFAULT_PRESSURE_GAIN if defaults else None,
                             doc="brake torque per unit pressure [assumed 20, docs/models/lugre_friction.md §7]"),
        "theta": _optional(profile_spec("-", gt=0.0)) if not defaults else
        _with_default(profile_spec("-", gt=0.0), 1.0),
        "theta_convention": Str(choices=THETA_CONVENTIONS, default="fm" if defaults else None,
                                doc="fm (g -> theta g, 1 = dry) or obs (1/theta_fm)"),
    }


def _with_default(spec, value):
    spec.default = value
    return spec


def _input_post(v, path, ctx):
    given = [k for k in TORQUE_KEYS if v.get(k) is not None]
    if len(given) > 1:
        ctx.fail(path + (given[1],), f"give one of {', '.join(TORQUE_KEYS)}, not both {given[0]} and {given[1]}")


INPUT = Map(fields=_input_fields(True), post=_input_post)
DEFAULT_INPUT = {"torque": None, "brake_torque": None, "pressure": None, "pressure_gain": DEFAULT_PRESSURE_GAIN,
                 "theta": 1.0, "theta_convention": "fm"}
INPUT_OVERRIDE = Map(fields=_input_fields(False), post=_input_post)

INITIAL_FIELDS = {
    "v": Num(unit="m/s", gt=0, doc="initial vehicle speed"),
    "slip": Num(unit="-", ge=-1, lt=1, default=0.0, doc="initial slip (omega from it)"),
    "omega": Num(unit="rad/s", ge=0, default=None, doc="initial wheel speed (instead of slip)"),
}
INITIAL = Map(fields={**INITIAL_FIELDS, "v": Num(unit="m/s", gt=0, default=20.0, doc="initial vehicle speed")})
INITIAL_OVERRIDE = Map(fields={k: _optional(Num(**{**s.__dict__})) for k, s in INITIAL_FIELDS.items()})

#: ``solver.method: auto`` picks ROS2: L-stable, so stable for any bristle stiffness and wheel mode, and
#: at equal accuracy 25x faster than scipy's Radau on the same model (README benchmark).
ROS2_BECAUSE = ("ROS2 (adaptive L-stable Rosenbrock): stable at any bristle stiffness; scipy's implicit "
                "methods were measured >= 25x slower at equal accuracy")

SOLVER = Map(fields={
    "method": Str(choices=("auto", "ros2"), default="auto",
                  doc="auto (= ros2, the fastest stable method measured for these models) or ros2"),
    "tol": Nullable(spec=Num(unit="-", gt=0, lt=0.1), default=None,
                    doc="local error tolerance (m/s, friction units); null: 1e-3 lumped, 3e-4 distributed"),
    "h_max": Num(unit="s", gt=0, le=0.5, default=0.05, doc="largest time step"),
})
SOLVER_OVERRIDE = Map(fields={k: _optional(copy.copy(s)) for k, s in SOLVER.fields.items()})


def _drive_post(v, path, ctx):
    kinds = [k for k in ("case", "csv") if v[k] is not None] + (["profiles"] if v["v"] is not None else [])
    if len(kinds) != 1:
        ctx.fail(path, "drive by exactly one of: case (another case's run), csv (a file), or v with slip/omega/romega profiles")
        return
    if kinds == ["profiles"]:
        second = [k for k in ("slip", "omega", "romega") if v[k] is not None]
        if len(second) != 1:
            ctx.fail(path, "with v, give exactly one of slip, omega, romega")
    elif any(v[k] is not None for k in ("slip", "omega", "romega")):
        ctx.fail(path, "slip/omega/romega profiles go with v, not with case or csv")
    if v["where"] is not None and v["csv"] is None:
        ctx.fail(path + ("where",), "where selects rows of a csv drive: give csv too")


DRIVE = Map(fields={
    "case": Str(default=None, doc="label of a coupled case whose v(t), omega(t) drive this one"),
    "csv": Str(default=None, doc="CSV file of the kinematics (relative to the config)"),
    "map": Map(open_keys=Str(), default=None,
               doc="rename file columns: {FILE_COLUMN: NAME}; names t [s], v [m/s] and s [-] (or romega [m/s], omega [rad/s])"),
    "where": Map(open_keys=AnyOf(options=(Num(), Str())), default=None,
                 doc="keep the CSV rows with column == value, e.g. {case: 'braking #2'}"),
    "v": _optional(profile_spec("m/s", lo=0.0)),
    "slip": _optional(profile_spec("-", lo=-1.0, hi=1.0)),
    "omega": _optional(profile_spec("rad/s", lo=0.0)),
    "romega": _optional(profile_spec("m/s", lo=0.0)),
}, post=_drive_post)

_VARIANT_MAP = VARIANT.options[1]


def _case_post(v, path, ctx):
    _VARIANT_MAP.post(v, path, ctx)


CASE = AnyOf(options=(
    Str(choices=MODELS),
    Map(fields={**_VARIANT_MAP.fields,
                "input": _optional(INPUT_OVERRIDE),
                "initial": _optional(INITIAL_OVERRIDE),
                "solver": _optional(SOLVER_OVERRIDE),
                "drive": _optional(DRIVE)}, post=_case_post),
), what="a model name (distributed, lumped) or a mapping {model, load, kappa0, label, input, initial, drive, solver}")

MEASUREMENT = Map(fields={
    "rate": Num(unit="Hz", gt=0, le=100_000, default=100.0, doc="sampling rate"),
    "noise": Map(fields={
        "speed": Num(unit="m/s", ge=0, default=0.05, doc="std. dev. on v and r*omega"),
        "pressure": Num(unit="bar", ge=0, default=0.5, doc="std. dev. on the brake pressure"),
        "mu": Num(unit="-", ge=0, default=0.0, doc="std. dev. on the measured friction F_x/F_z"),
    }, default={"speed": 0.05, "pressure": 0.5, "mu": 0.0}),
    "seed": Num(unit="-", integer=True, ge=0, default=2003, doc="random seed of the noise"),
    "cases": ListOf(item=Str(), default=None, doc="labels of the coupled cases to sample (default: all)"),
    "record_starts": ListOf(item=Num(unit="s", ge=0), default=None,
                            doc="start time of each sampled case in one record (FM: 80, 97, 115 s)"),
})

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="lugre", doc="LuGre parameter set: a name, a file, or {set: ..., overrides}"),
    "vehicle": Raw(kind="quarter_car", default=None, doc=f"quarter-car parameter set (default {DEFAULT_VEHICLE})"),
    "initial": _with_default(INITIAL, {"v": 20.0, "slip": 0.0, "omega": None}),
    "input": _with_default(INPUT, None),
    "t_end": Num(unit="s", gt=0, le=3600, default=5.0, doc="end time"),
    "stop": Map(fields={"v_min": Num(unit="m/s", ge=0, default=0.1, doc="stop speed")}, default={"v_min": 0.1}),
    "solver": _with_default(SOLVER, {"method": "auto", "tol": None, "h_max": 0.05}),
    "cases": ListOf(item=CASE, default=["distributed"], doc="model variants"),
    "open_loop": Map(fields={"models": ListOf(item=VARIANT, doc="tire models driven by each coupled case"),
                             "cases": ListOf(item=Str(), default=None, doc="coupled cases that drive them (default: all)")},
                     default=None),
    "measurement": _with_default(MEASUREMENT, None),
    "output": Map(fields={"dt": Num(unit="s", ge=0, default=0.001, doc="output time step (0: solver steps)")},
                  default={"dt": 0.001}),
})


# --------------------------------------------------------------------------- plan


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


def plan(config: Config):
    """Check a simulate config completely; returns ``(checked, tire set, vehicle set, cases)``."""
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
    _estimate(checked, cases, to_check).check(config.origins)
    return checked, tire, vehicle, cases


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


# --------------------------------------------------------------------------- run


def _sample_times(meas, t_end):
    if meas is None:
        return ()
    dt = 1.0 / meas["rate"]
    n = int(np.floor(t_end / dt + 1e-9))
    return tuple(np.round(np.arange(n + 1) * dt, 12))


#: The facts of one run (``_events``), with the extremum each needs root-found (the costly part).
EVENT_FACTS = ("case", "mode", "model", "t_final", "end", "peak_abs_slip", "t_peak_abs_slip", "min_slip", "t_min_slip",
               "peak_abs_mu", "t_peak_abs_mu", "wheel_lock", "locked_at_end", "stop_time", "stopping_distance",
               "distance", "v_final", "steps", "rejected_steps")


def _events(tr, case: Case, r: float, which=None) -> dict:
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


def _event_rows(ev: dict) -> list:
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


def _thinned(n: int, points: int) -> np.ndarray:
    """Indices of every k-th of ``n`` rows, the last one kept: at most ``points + 1`` rows."""
    keep = np.zeros(n, dtype=bool)
    keep[::-(-n // points)] = True
    keep[-1:] = True
    return np.flatnonzero(keep)


def _frame(tr, case: Case, dt: float, r: float, gain: float, points: int | None = None,
           keep: bool = True) -> pd.DataFrame:
    """The time series of a run on the output grid, from the integrator's dense output (states
    interpolated by the step's cubic Hermite, outputs evaluated by the model there).

    ``points``: only every k-th row of the grid, the last kept (:func:`_thinned`; the rows the
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
            tg = tg[_thinned(tg.size, points)]
        Y, O = tr.sample(tg, keep)
        distance = runs.distance_at(tr, tg)
    else:
        tg, Y, O, distance = t, tr.y, tr.out, tr.out["distance"]
        if points is not None:
            rows = _thinned(t.size, points)
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


def _timeseries(trs: dict, cases: list, dt: float, r: float, gain: float):
    """``(timeseries, drawn, events)``: the frame ``timeseries`` of every case (:func:`_frame`), when it
    is streamed ``{label: frame}`` of each case's rows thinned for the figures (else None), and the
    facts of every case (:func:`_events`).

    Up to :data:`SPOOL_CASES` cases the frame is a DataFrame. With more, each case's rows are written
    to disk, :data:`SPOOL_ROWS` rows at a time (:class:`tirecli.io.output.SpooledFrame`, copied into
    ``data/timeseries.csv``; the same text) and the figures draw every k-th row (at most
    :data:`DRAWN_POINTS` a case, the last kept). With a spare core a helper process finds the events
    and formats the rows (:meth:`~tirecli.io.output.SpooledFrame.extend`) while this one evaluates
    the rows drawn and goes on to the figures; the same numbers and text."""
    import pandas as pd

    def events():
        return [_events(trs[c.label], c, r) for c in cases]

    if len(cases) <= SPOOL_CASES:
        frame = pd.concat([_frame(trs[c.label], c, dt, r, gain) for c in cases], ignore_index=True)
        return frame, None, events()
    from tirecli.io.output import SpooledFrame
    from tirecli.parallel import helper_process_ok

    drawn = {}
    helper = helper_process_ok()

    def parts():  # a few cases at a time: fewer, larger CSV blocks
        pending, rows = [], 0
        for i, c in enumerate(cases):
            f = _frame(trs[c.label], c, dt, r, gain, keep=False)
            if not helper:  # in this process: the rows drawn taken from the whole frame
                drawn[c.label] = f.iloc[_thinned(len(f), DRAWN_POINTS)].reset_index(drop=True)
            pending.append(f)
            rows += len(f)
            if rows >= SPOOL_ROWS or i == len(cases) - 1:
                yield pd.concat(pending, ignore_index=True) if len(pending) > 1 else f
                pending, rows = [], 0

    spool = SpooledFrame(TIMESERIES_COLUMNS)
    found = spool.extend(parts(), background=helper, first=events)
    if helper:  # the helper makes the whole frames: the rows drawn evaluated alone here, meanwhile
        drawn = {c.label: _frame(trs[c.label], c, dt, r, gain, DRAWN_POINTS, keep=False) for c in cases}
    return spool, drawn, found()


def _measure(trs: dict, labels: list, meas: dict, r: float, gain: float):
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


@register_study("simulate", check=plan, spec=SPEC)
def run_simulate(config: Config, progress=None) -> StudyResult:
    """Run a simulate config (see module doc)."""
    checked, tire, vehicle, cases = plan(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    p, car = tire.model(), vehicle.model()
    meas = checked["measurement"]
    t_end = checked["t_end"]
    gain = (checked["input"] or {}).get("pressure_gain") or DEFAULT_PRESSURE_GAIN
    trs = run_cases(cases, p, car, t_end, _sample_times(meas, t_end), progress)
    timeseries, drawn, events = _timeseries(trs, cases, checked["output"]["dt"], car.r, gain)
    data = {"timeseries": timeseries,
            "events": pd.DataFrame([row for e in events for row in _event_rows(e)])}
    synthetic = False
    if meas is not None:
        labels = meas["cases"] or [c.label for c in cases if c.mode == "coupled"]
        data["measured"], data["measured_clean"] = _measure(trs, labels, meas, car.r, gain)
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
