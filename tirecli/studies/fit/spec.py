"""The config schema of the ``fit`` study (see :mod:`tirecli.studies.fit`)."""
from __future__ import annotations

from tirecli.config.schema import AnyOf, Bool, ListOf, Map, Num, Raw, Spec, Str
from tirecli.conventions import AXIS_CONVENTIONS
from tirecli.limits import MAX_TITLE_CHARS
from tirecli.models.variants import LOADS
from tirecli.numerics import identify
from tirecli.studies.base import common_fields
from tirecli.studies.sweep import VARIANT

DEFAULT_VEHICLE = "canudas2003-obs-quarter-car"
#: Fewest samples per fitted parameter.
MIN_SAMPLES_PER_PARAMETER = 3
#: Largest residual RMS of a fit, relative to the RMS of the friction data it fits: above it the
#: model explains next to nothing of the data (the optimum lies outside the bounds), not a fit.
MAX_UNEXPLAINED = 0.5


def _data_post(v, path, ctx):
    if sum(v[k] is not None for k in ("csv", "file", "simulate")) != 1:
        ctx.fail(path, "give exactly one data source: file (a .csv, .parquet, .tdx or .mf4 file of measured data), "
                       "csv (a CSV of the fit's own columns) or simulate (a simulate config)")
    if v["file"] is None:
        for k in ("units", "convention", "rate"):
            if v[k] is not None:
                ctx.fail(path + (k,), "applies to data.file only (a measured-data file read by tirecli's readers)")
    w = v["window"]
    if w and w["start"] is not None and w["end"] is not None and w["end"] <= w["start"]:
        ctx.fail(path + ("window", "end"), "must be after start")


class _Nullable(Spec):
    """``null`` or a value of ``inner`` (lets ``--data`` switch the source off with ``data.simulate=null``)."""

    def __init__(self, inner, default=None, doc=""):
        super().__init__(doc=doc, default=default)
        self.inner = inner

    def accepts(self, value):
        return value is None or self.inner.accepts(value)

    def check(self, value, path, ctx):
        return None if value is None else self.inner.check(value, path, ctx)


WINDOW = Map(fields={"start": Num(unit="s", default=None, doc="first time"),
                     "end": Num(unit="s", default=None, doc="last time")}, default=None)

DATA = Map(fields={
    "csv": _Nullable(Str(), doc="CSV file: columns t [s], v [m/s], s [-] (or romega [m/s]), mu [-]"),
    "file": _Nullable(Str(), doc="measured-data file (.csv, .parquet, .tdx, .mf4) read into the channel table"),
    "units": Map(open_keys=Str(), default=None, doc="data.file: {COLUMN: UNIT}, the unit of a column (default SI)"),
    "convention": Str(choices=AXIS_CONVENTIONS, default=None, doc="data.file: axis convention of the file"),
    "rate": Num(unit="1/s", gt=0, default=None, doc="data.file, MDF only: resample to this many samples a second"),
    "simulate": _Nullable(Str(), doc="simulate config (built-in name or file) whose samples are the data"),
    "frame": Str(default="measured", doc="frame of the simulate result (measured, measured_clean, ...)"),
    "cases": ListOf(item=Str(), default=None, doc="run only these cases of the simulate config"),
    "map": Map(open_keys=Str(), default=None, doc="rename file columns {FILE_COLUMN: NAME}"),
    "where": Map(open_keys=AnyOf(options=(Num(), Str())), default=None, doc="keep rows with column == value"),
    "window": WINDOW,
    "min_abs_slip": Num(unit="-", ge=0, lt=1, default=0.005, doc="drop samples with smaller |s| (steady fit)"),
}, post=_data_post)


def _fit_post(v, path, ctx):
    for key in ("initial", "bounds"):
        for k in (v[key] or {}):
            allowed = identify.STEADY_PARAMETERS + (("sigma1",) if key == "bounds" else ())
            if k not in allowed:
                ctx.fail(path + (key, k), f"unknown parameter (expected one of: {', '.join(allowed)})")
    for k, b in (v["bounds"] or {}).items():
        if len(b) != 2 or b[0] >= b[1]:
            ctx.fail(path + ("bounds", k), "expected [low, high] with low < high")


SIGMA1_DEFAULT = {"model": None, "bounds": [0.0, 100.0], "window": None}
SIGMA1 = Map(fields={
    "model": AnyOf(options=VARIANT.options, default=None,
                   what="a tire model variant (default lumped kappa0 Z)"),
    "bounds": ListOf(item=Num(unit="s/m", ge=0), min_len=2, max_len=2, default=[0.0, 100.0], doc="[low, high]"),
    "window": WINDOW,
})

FIT_MODELS = ("lumped", "distributed")
INTERPOLATIONS = ("cubic", "linear")
MODEL_OPTIONS = ("load", "lambda", "u", "f", "window", "substeps", "interpolation")


def _model_post(v, path, ctx):
    if v["model"] == "lumped":
        for k in MODEL_OPTIONS:
            if v[k] is not None:
                ctx.fail(path + (k,), "applies to model: distributed only (model: lumped is the FM procedure, "
                                      "stages 1-2)")
        return
    from tirecli.studies.sweep import _variant_post

    _variant_post({**v, "load": v["load"] or "uniform", "kappa0": None, "label": ""}, path, ctx)
    w = v["window"]
    if w and w["start"] is not None and w["end"] is not None and w["end"] <= w["start"]:
        ctx.fail(path + ("window", "end"), "must be after start")


MODEL = AnyOf(options=(
    Str(choices=FIT_MODELS),
    Map(fields={
        "model": Str(choices=FIT_MODELS, doc="lumped: FM procedure only; distributed: then stage 3"),
        "load": Str(choices=LOADS, default=None, doc="normal-load density of the distributed model (uniform)"),
        "lambda": Num(unit="-", ge=0, default=None, doc="exponential load decay", eq="FM eq. (5)"),
        "u": ListOf(item=Num(unit="-", ge=0, le=1), min_len=2, default=None, doc="tabulated load positions zeta/L"),
        "f": ListOf(item=Num(unit="N/m", ge=0), min_len=2, default=None, doc="tabulated load density samples"),
        "window": Map(fields={"start": Num(unit="s", default=None, doc="first time compared"),
                              "end": Num(unit="s", default=None, doc="last time compared")}, default=None),
        "substeps": Num(unit="-", integer=True, ge=1, le=64, default=None,
                        doc="grid steps per sample interval (coarse grid; default 4)"),
        "interpolation": Str(choices=INTERPOLATIONS, default=None,
                             doc="kinematics between samples: cubic spline (default) or linear"),
    }, post=_model_post),
), default="lumped",
    what="lumped, distributed, or a mapping {model: distributed, load, window, substeps, interpolation}")

#: ``fit.method``: the FM procedure (stages 1-2, optionally the driven distributed fit), or then the output-error fit.
METHODS = ("fm", "output-error")
#: The input of the output-error fit: brake pressure times its gain, the brake's torque, or the signed wheel torque.
OE_INPUTS = ("pressure", "brake_torque", "torque")


def _oe_post(v, path, ctx):
    from tirecli.numerics.identify_oe import INITIAL_PARAMETERS, OE_PARAMETERS

    for k in (v["parameters"] or []):
        if k not in OE_PARAMETERS + INITIAL_PARAMETERS:
            ctx.fail(path + ("parameters",), f"unknown parameter {k!r} (expected among: "
                                             f"{', '.join(OE_PARAMETERS + INITIAL_PARAMETERS)})")
    w = v["window"]
    if w and w["start"] is not None and w["end"] is not None and w["end"] <= w["start"]:
        ctx.fail(path + ("window", "end"), "must be after start")


OUTPUT_ERROR_DEFAULT = {"parameters": None, "model": None, "input": None, "pressure_gain": None, "hold": "linear",
                        "window": None, "weighting": "noise"}
OUTPUT_ERROR = Map(fields={
    "parameters": ListOf(item=Str(), default=None,
                         doc="parameters to fit (default: fit.parameters and sigma1); v0, omega0: the initial speeds"),
    "model": AnyOf(options=VARIANT.options, default=None,
                   what="a tire model variant (default distributed, uniform load)"),
    "input": Str(choices=OE_INPUTS, default=None,
                 doc="the brake input: pressure x pressure_gain, brake_torque or torque (default: the first the data give)"),
    "pressure_gain": Num(unit="N m/bar", gt=0, default=None,
                         doc="brake torque per unit pressure (default: the simulate config's, for data.simulate)"),
    "hold": Str(choices=("linear", "zoh"), default="linear", doc="the input between samples: linear or zero-order hold"),
    "window": WINDOW,
    "weighting": Str(choices=("noise", "range"), default="noise", doc="channel weights: estimated noise or range"),
}, post=_oe_post, default=OUTPUT_ERROR_DEFAULT)

FIT = Map(fields={
    "parameters": ListOf(item=Str(choices=identify.STEADY_PARAMETERS),
                         default=["sigma0", "sigma2", "mu_c", "mu_s", "v_s"], doc="steady-state parameters to fit"),
    "initial": Map(open_keys=Num(), default=None, doc="starting values (default: the tire set)"),
    "bounds": Map(open_keys=ListOf(item=Num(), min_len=1), default=None, doc="{name: [low, high]}"),
    "confidence": Num(unit="-", gt=0, lt=1, default=0.95, doc="level of the confidence intervals"),
    "sigma1": AnyOf(options=(Bool(), SIGMA1), default={}, what="false, or {model, bounds, window}"),
    "model": MODEL,
    "method": Str(choices=METHODS, default="fm",
                  doc="fm: the FM procedure (and model: distributed); output-error: then the coupled quarter car from the "
                      "brake input fitted to v, r omega and mu"),
    "output_error": OUTPUT_ERROR,
    "name": Str(default="fitted", doc="name of the fitted parameter set", max_len=MAX_TITLE_CHARS),
}, post=_fit_post, default={"parameters": ["sigma0", "sigma2", "mu_c", "mu_s", "v_s"], "initial": None, "bounds": None,
                            "confidence": 0.95, "sigma1": {}, "model": "lumped", "method": "fm",
                            "output_error": OUTPUT_ERROR_DEFAULT, "name": "fitted"})

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="lugre", doc="LuGre set with the starting values and the fixed parameters"),
    "vehicle": Raw(kind="quarter_car", default=None, doc=f"quarter-car set (rolling radius for omega; default {DEFAULT_VEHICLE})"),
    "data": DATA,
    "fit": FIT,
})
