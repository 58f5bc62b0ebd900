"""The config schema of the ``observe`` study (see :mod:`tirecli.studies.observe`)."""
from __future__ import annotations

from dataclasses import replace

from tirecli.config.profiles import profile_spec
from tirecli.config.schema import ListOf, Map, Nullable, Num, Raw, Str
from tirecli.conventions import THETA_CONVENTIONS
from tirecli.limits import MAX_TITLE_CHARS
from tirecli.observers.measurement import METHODS
from tirecli.studies.base import common_fields

GAINS = ("k1", "k2", "k3", "gamma", "alpha")
DEFAULT_GAINS = "canudas2003-obs-gains"
DEFAULT_VEHICLE = "canudas2003-obs-quarter-car"


def _measurement_post(v, path, ctx):
    if v["log"] is not None and any(v[k] is not None for k in ("rate", "noise", "encoder")):
        ctx.fail(path, "a measured 'log' brings its own samples: drop 'rate', 'noise' and 'encoder'")
    if v["log"] is None and (v["map"] or v["units"] or v["torque_gain"] is not None):
        ctx.fail(path, "'map', 'units' and 'torque_gain' describe a measured 'log'; give one or drop them")
    if v["rate"] is None and (v["noise"] is not None or v["encoder"] is not None):
        ctx.fail(path, "noise and encoder quantisation need a sampling 'rate' [Hz] (the measurement is held between samples)")


MEASUREMENT = Map(fields={
    "rate": Num(unit="Hz", gt=0, default=None, doc="sampling rate with zero-order hold; omit for the ideal continuous measurement"),
    "noise": Map(fields={"std": Num(unit="rad/s", ge=0, doc="standard deviation of the Gaussian noise"),
                         "seed": Num(unit="-", integer=True, ge=0, default=0, doc="noise seed")}, default=None),
    "encoder": Map(fields={"teeth": Num(unit="-", integer=True, ge=1, doc="encoder teeth per revolution"),
                           "method": Str(choices=METHODS, default="period",
                                         doc="count: edges per sample period; period: time of the last tooth interval"),
                           "clock": Num(unit="Hz", gt=0, default=None, doc="timer that time-stamps the edges (period method)")},
                   default=None),
    "log": Str(default=None, doc="a measured log (.csv, .parquet, .mf4, .tdx): the observer runs on its wheel speed "
                                 "and torque, no plant is simulated (docs/observe.md, On a measured log)"),
    "map": Map(open_keys=Str(), default={}, doc="FILE_COLUMN -> NAME of the log (t; omega or romega; torque, "
                                                "brake_torque or p; vx)"),
    "torque_gain": Num(unit="N m/Pa", gt=0, default=None,
                       doc="brake torque per unit brake pressure: a log without a torque gives u = -gain p"),
    "units": Map(open_keys=Str(), default={}, doc="NAME -> UNIT of the log's columns"),
}, post=_measurement_post, default=None)


def _estimate(required: bool) -> Map:
    d = (lambda x: x) if required else (lambda x: None)  # noqa: E731
    return Map(fields={
        "v_error": Num(unit="m/s", default=d(0.0), doc="initial speed estimate error v_hat(0) - v(0)"),
        "z": Num(unit="m", default=d(0.0), doc="initial deflection estimate z_hat(0)"),
        "theta": Num(unit="-", gt=0, default=d(1.0), doc="initial adhesion estimate theta_hat(0) (scenario.theta_convention)"),
    }, default=None)


THETA_PROFILE = profile_spec("-", gt=0)
TORQUE_PROFILE = profile_spec("N m")

SCENARIO = Map(fields={
    "duration": Num(unit="s", gt=0, le=3600, doc="simulated time"),
    "theta_convention": Str(choices=THETA_CONVENTIONS, default="obs", doc="convention of the theta values"),
    "theta": THETA_PROFILE,
    "torque": TORQUE_PROFILE,
    "v0": Num(unit="m/s", gt=0, doc="initial vehicle speed"),
    "slip0": Num(unit="-", gt=-1, lt=1, default=0.0, doc="initial slip (0: pure rolling)"),
    "z0": Num(unit="m", default=0.0, doc="initial bristle deflection"),
    "assumed": Str(default="", doc="why the scenario values are assumed defaults (flagged in outputs)"),
})

SOLVER_METHODS = ("auto", "fixed", "lsoda", "radau", "bdf")

SOLVER = Map(fields={
    "method": Str(choices=SOLVER_METHODS, default="auto",
                  doc="auto: the fastest stable and accurate method for the gains and the measurement; fixed: the "
                      "structured fixed-step scheme; lsoda, radau, bdf: adaptive (scipy) on the full system"),
    "rtol": Num(unit="-", gt=0, lt=1, default=1e-7, doc="relative tolerance of the adaptive methods"),
    "atol": Nullable(spec=Num(unit="-", gt=0), default=None,
                doc="absolute tolerance of the adaptive methods (default: rtol times each state's typical size)"),
    "step": Num(unit="s", gt=0, le=0.05, default=2.5e-3, doc="largest step of the fixed scheme"),
    "h_max": Nullable(spec=Num(unit="s", gt=0), default=None,
                      doc="largest step of the adaptive methods (null: unlimited)"),
}, default=None)

#: Deprecated ``numerics:`` block (``fast``: the fixed scheme, ``reference``: Radau); use ``solver:``.
NUMERICS = Map(fields={
    "method": Str(choices=("fast", "reference"), default="fast",
                  doc="deprecated (use solver.method): fast = fixed, reference = radau"),
    "step": Num(unit="s", gt=0, le=0.05, default=2.5e-3, doc="deprecated (use solver.step)"),
    "rtol": Num(unit="-", gt=0, lt=1, default=1e-8, doc="deprecated (use solver.rtol)"),
}, default=None)

METRICS = Map(fields={
    "phases": ListOf(item=Num(unit="s", ge=0), min_len=2, default=None, doc="phase boundaries (default: quarters)"),
    "crossing_margin": Num(unit="s", ge=0, default=0.5, doc="excluded window around each v_r zero crossing"),
    "settle_tolerance": Num(unit="-", gt=0, default=0.05, doc="band of |theta_hat - theta| for the settling time"),
    "excitation_threshold": Num(unit="m/s", ge=0, default=0.05, doc="|v_r| counted as excitation"),
    "min_excitation": Num(unit="-", ge=0, le=1, default=0.5, doc="warn below this share of excited time"),
}, default=None)

GAIN_OVERRIDES = Map(fields={k: Num(unit="", default=None) for k in GAINS}, default=None)

CASE = Map(fields={
    "label": Str(doc="name of the case in legends and the CSV", max_len=MAX_TITLE_CHARS),
    "estimate": _estimate(required=False),
    "observer": GAIN_OVERRIDES,
    "measurement": MEASUREMENT,
    "theta": replace(THETA_PROFILE, default=None, doc="adhesion profile of this case"),
    "torque": replace(TORQUE_PROFILE, default=None, doc="torque profile of this case"),
})

GAIN_STUDY = Map(fields={
    "gain": Str(choices=GAINS, doc="the gain that varies"),
    "values": ListOf(item=Num(unit=""), min_len=2, doc="its values"),
}, default=None)

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="lugre", doc="LuGre parameter set (lumped, constant kappa0)"),
    "vehicle": Raw(kind="quarter_car", default=None, doc="quarter-car parameter set"),
    "observer": Raw(kind="observer", default=None, doc="observer gains (kind observer)"),
    "scenario": replace(SCENARIO, default=None),   # required unless measurement.log is given
    "estimate": _estimate(required=True),
    "measurement": MEASUREMENT,
    "solver": SOLVER,
    "numerics": NUMERICS,
    "metrics": METRICS,
    "cases": ListOf(item=CASE, default=None, doc="variants of the run"),
    "gain_study": GAIN_STUDY,
    "output": Map(fields={"dt": Num(unit="s", gt=0, default=0.01, doc="CSV sampling interval")}, default=None),
})
