"""The config schema of the ``simulate`` study (see :mod:`tirecli.studies.simulate`)."""
from __future__ import annotations

import copy

from tirecli.config.profiles import profile_spec
from tirecli.config.schema import AnyOf, ListOf, Map, Nullable, Num, Raw, Str
from tirecli.conventions import THETA_CONVENTIONS
from tirecli.models.variants import MODELS
from tirecli.studies.base import common_fields
from tirecli.studies.sweep import VARIANT

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

