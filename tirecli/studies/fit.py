"""Identification of the LuGre parameters from braking data (FM §4.3; docs/models/lugre_friction.md §8).

Config (``tirecli fit CONFIG``)::

    study: fit
    tire: canudas2003-table1        # starting values and fixed parameters (L; alpha unless fitted)
    data:
      csv: braking.csv              # columns t [s], v [m/s], s [-] (or romega [m/s]), mu [-]
      # simulate: fm-fig4           # ... or the samples of a simulate config (built-in name or file)
      # frame: measured             # which of its frames (measured, measured_clean)
      # cases: ["braking #2"]       # run only these cases of it
      map: {slip_ratio: s}          # rename file columns {FILE_COLUMN: NAME}
      where: {braking: 2}           # keep rows whose column equals the value
      window: {start: 0, end: 2.6}  # [s], steady-state fit only (post-release samples are biased)
      min_abs_slip: 0.005           # steady-state fit only
    fit:
      parameters: [sigma0, sigma2, mu_c, mu_s, v_s]   # add alpha to fit the Stribeck exponent
      initial: {sigma0: 150}        # default: the tire set
      bounds: {v_s: [0.5, 20]}      # default: identify.DEFAULT_BOUNDS
      confidence: 0.95
      sigma1: {model: {model: lumped, kappa0: Z}, bounds: [0, 100]}   # or false
      model: lumped                 # default: the FM procedure (stages 1-2) only
      # model: distributed          # ... then stage 3, or with options:
      # model: {model: distributed, load: uniform, window: {start: 0.05}, substeps: 4, interpolation: cubic}
      name: fitted-braking          # name of the fitted set
    figures: [fit-steady, fit-transient]

Stage 1 fits FM eq. (4) to the ``(s, v, mu)`` samples; stage 2 fits ``sigma1`` to ``mu(t)`` with
the tire model driven by the measured ``v(t)``, ``s(t)`` over the whole selection (see
:mod:`tirecli.numerics.identify`). With ``model: distributed``, stage 3 starts from their result
and fits the parameters of ``fit.parameters`` and ``sigma1`` (unless ``sigma1: false``) together
to ``mu(t)`` with the distributed model (FM eqs. (1)-(2), uniform load unless ``load`` says
otherwise) driven open loop by the measured ``v(t)``, ``r omega(t)`` in the least-squares loop
(:func:`tirecli.numerics.identify.fit_distributed`): no lumped approximation biases the estimates.
The model starts undeflected at the first sample; ``window`` selects the samples compared (earlier
samples still drive it). Output: ``fitted.yaml`` (the last stage's set), a parameter set every
command accepts (``tire: {set: fitted.yaml}``), and frames ``parameters`` (column ``fit``:
``FM 4.3`` for stages 1-2, ``distributed`` for stage 3), ``correlation``, ``samples``,
``transient`` and, with stage 3, ``distributed`` and ``correlation_distributed``.
"""
from __future__ import annotations

import json
import os
from dataclasses import replace
from pathlib import Path

import numpy as np

from tirecli.config.loader import Config, load_config
from tirecli.config.schema import AnyOf, Bool, ListOf, Map, Num, Raw, Spec, Str, collect
from tirecli.errors import ConfigError, DataError, RunError, token
from tirecli.io.files import exists
from tirecli.io.yamlio import dump_yaml
from tirecli.limits import MAX_TITLE_CHARS
from tirecli.models.lugre import mu_of_deflection
from tirecli.numerics import identify, runs
from tirecli.models.profiles import Constant, Table
from tirecli.studies.base import StudyResult, builtin_config, builtin_config_names, common_fields, register_study
from tirecli.models.variants import LOADS
from tirecli.studies.sweep import VARIANT, make_variant

DEFAULT_VEHICLE = "canudas2003-obs-quarter-car"
#: Fewest samples per fitted parameter.
MIN_SAMPLES_PER_PARAMETER = 3
#: Largest residual RMS of a fit, relative to the RMS of the friction data it fits: above it the
#: model explains next to nothing of the data (the optimum lies outside the bounds), not a fit.
MAX_UNEXPLAINED = 0.5


def _data_post(v, path, ctx):
    if (v["csv"] is None) == (v["simulate"] is None):
        ctx.fail(path, "give exactly one data source: csv (a file) or simulate (a simulate config)")
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

FIT = Map(fields={
    "parameters": ListOf(item=Str(choices=identify.STEADY_PARAMETERS),
                         default=["sigma0", "sigma2", "mu_c", "mu_s", "v_s"], doc="steady-state parameters to fit"),
    "initial": Map(open_keys=Num(), default=None, doc="starting values (default: the tire set)"),
    "bounds": Map(open_keys=ListOf(item=Num(), min_len=1), default=None, doc="{name: [low, high]}"),
    "confidence": Num(unit="-", gt=0, lt=1, default=0.95, doc="level of the confidence intervals"),
    "sigma1": AnyOf(options=(Bool(), SIGMA1), default={}, what="false, or {model, bounds, window}"),
    "model": MODEL,
    "name": Str(default="fitted", doc="name of the fitted parameter set", max_len=MAX_TITLE_CHARS),
}, post=_fit_post, default={"parameters": ["sigma0", "sigma2", "mu_c", "mu_s", "v_s"], "initial": None, "bounds": None,
                            "confidence": 0.95, "sigma1": {}, "model": "lumped", "name": "fitted"})

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="lugre", doc="LuGre set with the starting values and the fixed parameters"),
    "vehicle": Raw(kind="quarter_car", default=None, doc=f"quarter-car set (rolling radius for omega; default {DEFAULT_VEHICLE})"),
    "data": DATA,
    "fit": FIT,
})


# --------------------------------------------------------------------------- data


def _simulate_frame(d: dict, base_dir: Path):
    """Run a simulate config (only ``cases``) and return the frame ``d['frame']`` and whether it is synthetic."""
    from tirecli.studies.simulate import run_simulate

    ref = d["simulate"]
    if ref in builtin_config_names() and not ref.endswith((".yaml", ".yml")):
        sim = builtin_config(ref)
    else:
        p = Path(ref)
        sim = load_config(p if p.is_absolute() else base_dir / p)
    if d["cases"]:
        keep = set(d["cases"])
        raw_cases = sim.data.get("cases") or []
        labels = [c.get("label") if isinstance(c, dict) and isinstance(c.get("label"), str) else None
                  for c in (raw_cases if isinstance(raw_cases, list) else [])]
        missing = keep - set(lab for lab in labels if lab)
        if missing:
            raise DataError(f"{sim.label}: no case(s) labelled {', '.join(map(token, sorted(map(str, missing))))}")
        sim.data["cases"] = [c for c, lab in zip(raw_cases, labels) if lab in keep]
        sim.data.pop("open_loop", None)
        meas = sim.data.get("measurement")
        if isinstance(meas, dict) and isinstance(meas.get("cases"), list):  # (checked by the simulate study)
            idx = [i for i, lab in enumerate(meas["cases"]) if isinstance(lab, str) and lab in keep]
            meas["cases"] = [meas["cases"][i] for i in idx]
            starts = meas.get("record_starts")
            if isinstance(starts, list) and starts:
                meas["record_starts"] = [starts[i] for i in idx if i < len(starts)]
    res = run_simulate(sim)
    if d["frame"] not in res.data:
        raise DataError(f"{sim.label}: no frame {token(d['frame'])} (frames: {', '.join(res.data)})")
    return res.data[d["frame"]].copy(), res.synthetic, f"{d['frame']} of simulate config {sim.label}"


def load_samples(d: dict, base_dir: Path) -> dict:
    """The selected samples: ``t, v, s, mu`` arrays (plus source description and synthetic flag)."""
    from tirecli.io.data import data_rows, frame_columns, leading_comments, names, read_table, rename_columns, select_rows
    from tirecli.io.output import SYNTHETIC_NOTE

    if d["csv"] is not None:
        path = Path(d["csv"])
        if not path.is_absolute():
            path = base_dir / path
        frame = read_table(path)
        synthetic = any("SYNTHETIC" in c.upper() for c in leading_comments(path))
        source, where_name = str(path), str(path)
    else:
        frame, synthetic, source = _simulate_frame(d, base_dir)
        where_name = source
    frame = rename_columns(frame, d["map"], where_name)
    frame = select_rows(frame, d["where"], where_name, "data.where")
    has_s = "s" in frame.columns
    rows = data_rows(frame)  # rows of the file, also after 'where' kept some
    cols = frame_columns(frame, ["t", "v", "mu"] + (["s"] if has_s else []), where_name, increasing="t",
                         optional=() if has_s else ("romega",))
    if not has_s:
        if "romega" not in cols:
            raise DataError(f"{where_name}: missing column 's' (slip) and no 'romega' to compute it "
                            f"(file has: {names(frame.columns)}; map names with --map FILE_COLUMN=NAME)")
        from tirecli.conventions import slip_from_speeds

        cols["s"] = slip_from_speeds(cols["v"], cols["romega"], 1.0)
    if np.any(cols["v"] < 0):
        i = int(np.argmax(cols["v"] < 0))
        raise DataError(f"{where_name}: column 'v' row {rows[i]}: negative speed {cols['v'][i]:g} (forward motion, >= 0)")
    if np.any(np.abs(cols["s"]) > 1):
        i = int(np.argmax(np.abs(cols["s"]) > 1))
        what = "column 's'" if has_s else "slip from columns 'v', 'romega'"
        raise DataError(f"{where_name}: {what} row {rows[i]}: |slip| = {abs(cols['s'][i]):g} > 1")
    return {"t": cols["t"], "v": cols["v"], "s": cols["s"], "mu": cols["mu"], "source": source,
            "synthetic": synthetic, "note": SYNTHETIC_NOTE if synthetic else ""}


def _window_mask(t, w):
    m = np.ones_like(t, dtype=bool)
    if w:
        if w["start"] is not None:
            m &= t >= w["start"] - 1e-12
        if w["end"] is not None:
            m &= t <= w["end"] + 1e-12
    return m


# --------------------------------------------------------------------------- plan / run


def plan(config: Config):
    """Check a fit config completely (without reading data); returns ``(checked, tire, vehicle)``."""
    checked, tire, vehicle = collect(lambda: config.checked(SPEC), lambda: config.group("tire", "lugre"),
                                     lambda: config.group("vehicle", "quarter_car", DEFAULT_VEHICLE))
    tire.model()
    vehicle.model()
    d = checked["data"]
    if d["simulate"] is not None and d["simulate"] not in builtin_config_names():
        p = Path(d["simulate"])
        if not exists(p if p.is_absolute() else config.base_dir / p):
            raise ConfigError(config.origins.problem(("data", "simulate"),
                                                     f"no built-in simulate config or file {token(d['simulate'])} "
                                                     f"(built-in: {', '.join(builtin_config_names())})"))
    return checked, tire, vehicle


STAGES = {"steady": "steady state (FM eq. 4)", "sigma1": "transient (sigma1)",
          "distributed": "transient, distributed model (all at once)"}
#: The ``fit`` column of frame ``parameters``: the FM procedure (stages 1-2) or stage 3.
FIT_FM, FIT_DISTRIBUTED = "FM 4.3", "distributed"


def fitted_set(name: str, start_set, p, steady: identify.FitResult, s1: identify.FitResult | None, source: str,
               synthetic: bool, dist: identify.FitResult | None = None) -> dict:
    """A parameter-set document (kind lugre) of the fitted values, with estimates and intervals as notes.

    ``dist`` (stage 3), when given, supersedes the estimates of stages 1-2 for the parameters it fitted.
    """
    values = {}
    fits = {**{k: steady for k in steady.names}, **({"sigma1": s1} if s1 is not None else {}),
            **({k: dist for k in dist.names} if dist is not None else {})}
    for key in ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "L", "alpha", "kappa0", "sigma_w"):
        val = float(getattr(p, key))
        if key in fits:
            f = fits[key]
            lvl = int(round(100 * f.confidence))
            how = " with the distributed model in the loop" if f is dist else ""
            note = (f"fitted{how}: {f.estimate[key]:.6g} +/- {f.se[key]:.3g} (SE), {lvl}% CI [{f.ci_low[key]:.6g}, "
                    f"{f.ci_high[key]:.6g}]" + ("; on a bound" if f.at_bound[key] else ""))
            if key in f.unidentifiable:
                note = (f"NOT IDENTIFIED{how}: the data do not determine it ({f.identifiability_text()}); "
                        f"{f.estimate[key]:.6g} is only where the optimiser stopped, no interval")
            values[key] = {"value": val, "note": note}
        elif key in start_set.assumed:
            values[key] = {"value": val, "assumed": f"not identified; from {start_set.name}: {start_set.assumed[key]}"}
        else:
            origin = start_set.source.get(key, start_set.name)
            values[key] = {"value": val, "note": f"not identified (fixed, from {start_set.name}"
                                                + (f", set at {origin})" if key in start_set.overridden else ")")}
    label = "SYNTHETIC data" if synthetic else "data"
    procedure = ("procedure of FM §4.3: steady-state least squares of FM eq. 4, then sigma1 from the transient"
                 + ("; then all fitted parameters at once by least squares of mu(t) with the distributed model "
                    "(FM eqs. 1-2) driven by the measured kinematics" if dist is not None else ""))
    return {
        "name": name, "kind": "lugre",
        "title": f"LuGre tire identified by tirecli fit from {label}: {source}",
        "citation": f"tirecli fit ({procedure}); {label} {source}",
        "values": values,
    }


#: Memory per data sample (stages 1-2: frames, the open-loop run) and per node of the distributed model's
#: time grids (stage 3: states of every parameter set of a Jacobian) [bytes].
BYTES_PER_SAMPLE, BYTES_PER_NODE = 2000, 600


def _estimate(n: int, dopt: dict | None):
    """Samples of a fit of ``n`` data samples: the samples, and with stage 3 the nodes of its two time grids
    (``substeps`` and twice as many per sample interval)."""
    from tirecli.limits import Estimate

    est = Estimate().add(n, (("data", "csv"), ("data", "simulate"), ("data",)), f"the {n:,} data samples",
                         BYTES_PER_SAMPLE)
    if dopt is not None:
        est.add(3 * dopt["substeps"] * n, (("fit", "model", "substeps"), ("fit", "model")),
                f"the distributed model's time grids ({n:,} samples x 3 x {dopt['substeps']} substeps)", BYTES_PER_NODE)
    return est


def _distributed_options(raw) -> dict | None:
    """Stage-3 options from a checked ``fit.model`` (None for ``lumped``)."""
    if raw == "lumped" or (isinstance(raw, dict) and raw["model"] == "lumped"):
        return None
    o = raw if isinstance(raw, dict) else {}
    from tirecli.models.variants import FrictionVariant

    variant = FrictionVariant(model="distributed", load=o.get("load") or "uniform", lam=o.get("lambda") or 0.0,
                              u=tuple(o["u"]) if o.get("u") else None, f=tuple(o["f"]) if o.get("f") else None)
    return {"variant": variant, "window": o.get("window"), "substeps": o.get("substeps") or 4,
            "interpolation": o.get("interpolation") or "cubic"}


def _parameter_rows(f: identify.FitResult, stage: str, fit: str, start, initial) -> list:
    rows = [{"fit": fit, "parameter": k, "estimate": f.estimate[k], "se": f.se[k], "ci_low": f.ci_low[k],
             "ci_high": f.ci_high[k], "unit": identify.UNITS.get(k, "-"), "at_bound": f.at_bound[k],
             "start": f.extra.get("start", {}).get(k, (initial or {}).get(k, getattr(start, k))), "stage": stage}
            for k in f.names]
    if f.unidentifiable:   # a column only when the data leave a parameter undetermined (outputs unchanged otherwise)
        for row in rows:
            row["identified"] = row["parameter"] not in f.unidentifiable
    return rows


@register_study("fit", check=plan, spec=SPEC)
def run_fit(config: Config, progress=None) -> StudyResult:
    """Run a fit config (see module doc)."""
    import time

    checked, tire, vehicle = plan(config)
    start, car = tire.model(), vehicle.model()
    d, fc = checked["data"], checked["fit"]
    data = load_samples(d, config.base_dir)
    t, v, s, mu = data["t"], data["v"], data["s"], data["mu"]
    _estimate(len(t), _distributed_options(fc["model"])).check(config.origins)
    import pandas as pd  # once the data are checked: a refused run fails at once

    sel = _window_mask(t, d["window"]) & (np.abs(s) > d["min_abs_slip"]) & (v > 0)
    free = [k for k in identify.STEADY_PARAMETERS if k in fc["parameters"]]
    need = MIN_SAMPLES_PER_PARAMETER * len(free) + 1
    if int(sel.sum()) < need:
        raise DataError(f"{data['source']}: too few samples for the steady-state fit: {int(sel.sum())} after the "
                        f"window and |s| > {d['min_abs_slip']:g} (of {len(t)}); need at least {need} for "
                        f"{len(free)} parameters")
    bounds = {k: tuple(b) for k, b in (fc["bounds"] or {}).items()}
    steady, p_fit = identify.fit_steady_state(s[sel], v[sel], mu[sel], start, free, bounds, fc["initial"],
                                              fc["confidence"])
    _require(steady, "steady", data, mu[sel])
    from tirecli.models.lugre import mu_ss_uniform

    rw = identify.romega_of(s, v)
    mu_model = mu_ss_uniform(rw - v, rw, p_fit)
    frames = {}
    s1 = None
    transient = None
    s1cfg = fc["sigma1"]
    if s1cfg is not False:
        s1cfg = {**SIGMA1_DEFAULT, **(s1cfg if isinstance(s1cfg, dict) else {})}
        variant = _variant(s1cfg["model"])
        wm = _window_mask(t, s1cfg["window"])
        if wm.sum() < 3:
            raise DataError(f"{data['source']}: too few samples in fit.sigma1.window ({int(wm.sum())})")
        tt, vv, ss, mm = t[wm], v[wm], s[wm], mu[wm]
        t0 = tt[0]
        tab_t = tuple(tt - t0)
        vp = Table(tab_t, tuple(vv))
        wp = Table(tab_t, tuple(identify.romega_of(ss, vv) / car.r))
        tr = runs.open_loop(variant, p_fit, car, vp, wp, Constant(1.0), float(tab_t[-1]),
                            runs.SolverOptions(tol=1e-4))
        idx = np.clip(np.searchsorted(tr.t, np.asarray(tab_t) - 1e-12), 0, len(tr.t) - 1)
        z, zd, vr = tr.out["zbar"][idx], tr.out["zdot"][idx], tr.out["vr"][idx]
        s1 = identify.fit_sigma1(mm, z, zd, vr, p_fit, tuple(s1cfg["bounds"]), fc["confidence"])
        _require(s1, "sigma1", data, mm)
        p_fit = replace(p_fit, sigma1=s1.estimate["sigma1"])
        transient = pd.DataFrame({"t": tt, "v": vv, "s": ss, "mu": mm,
                                  "mu_model": mu_of_deflection(z, zd, vr, p_fit),
                                  "mu_steady": mu_model[wm], "z": z, "zdot": zd})
        transient["residual"] = transient["mu_model"] - transient["mu"]
        frames["transient"] = transient
    # stage 3: the distributed model in the least-squares loop
    p_fm, dist, dopt = p_fit, None, _distributed_options(fc["model"])
    if dopt is not None:
        dfree = [k for k in identify.DISTRIBUTED_PARAMETERS
                 if k in free or (k == "sigma1" and s1 is not None)]
        use = _window_mask(t, dopt["window"])
        need = MIN_SAMPLES_PER_PARAMETER * len(dfree) + 1
        if int(use.sum()) < need:
            raise DataError(f"{data['source']}: too few samples for the distributed-model fit: {int(use.sum())} in "
                            f"fit.model.window (of {len(t)}); need at least {need} for {len(dfree)} parameters")
        dbounds = {**bounds, **({"sigma1": tuple(s1cfg["bounds"])} if s1 is not None else {})}
        var = dopt["variant"]
        from tirecli.models.lugre_pde import patch_reduction

        red = patch_reduction(var.load, var.lam, var.u, var.f)
        w0 = time.perf_counter()
        dist, p_fit, dout = identify.fit_distributed(t, v, rw, mu, p_fm, dfree, dbounds, None, fc["confidence"],
                                                     use, red, dopt["substeps"], dopt["interpolation"])
        dist.extra["wall_time_s"] = round(time.perf_counter() - w0, 3)
        _require(dist, "distributed", data, mu[use])
        frames["distributed"] = pd.DataFrame({"t": t, "v": v, "s": s, "mu": mu, "mu_model": dout["mu_model"],
                                              "residual": dout["mu_model"] - mu, "used": use.astype(int),
                                              "z": dout["zbar"], "zdot": dout["zdot"]})
    rows = _parameter_rows(steady, STAGES["steady"], FIT_FM, start, fc["initial"])
    if s1 is not None:
        rows += _parameter_rows(s1, STAGES["sigma1"], FIT_FM, start, fc["initial"])
    if dist is not None:
        rows += _parameter_rows(dist, STAGES["distributed"], FIT_DISTRIBUTED, start, fc["initial"])
    frames["parameters"] = pd.DataFrame(rows)
    corr = pd.DataFrame(steady.corr, columns=steady.names)
    corr.insert(0, "parameter", steady.names)
    frames["correlation"] = corr
    frames["samples"] = pd.DataFrame({"t": t, "v": v, "s": s, "mu": mu, "used": sel.astype(int),
                                      "mu_model": mu_model, "residual": mu_model - mu})
    if dist is not None:
        dc = pd.DataFrame(dist.corr, columns=dist.names)
        dc.insert(0, "parameter", dist.names)
        frames["correlation_distributed"] = dc
    set_doc = fitted_set(fc["name"], tire, p_fit, steady, s1, data["source"], data["synthetic"], dist)
    meta = {
        "title": checked["title"],
        "data": {"source": data["source"], "samples": int(len(t)), "used_steady": int(sel.sum()),
                 "window": d["window"], "min_abs_slip": d["min_abs_slip"], "where": d["where"],
                 "synthetic": data["synthetic"]},
        "steady_state": steady.record(),
        "sigma1": s1.record() if s1 is not None else None,
        "sigma1_model": _variant(s1cfg["model"]).record() if s1 is not None else None,
        "model": "distributed" if dist is not None else "lumped",
        "distributed": ({**dist.record(), "model": dopt["variant"].record(), "window": dopt["window"],
                         "samples_used": int(dist.n),
                         "drive": f"v(t), r omega(t) through the samples ({dopt['interpolation']}), "
                                  f"{dopt['substeps']} and {2 * dopt['substeps']} grid steps per sample interval "
                                  "(Richardson extrapolation)",
                         "initial_state": "undeflected at the first sample"} if dist is not None else None),
        "fixed": {k: getattr(start, k) for k in ("L", "alpha", "sigma1", "kappa0", "sigma_w")
                  if k not in free and not (k == "sigma1" and s1 is not None)},
        "fitted_set": "fitted.yaml",
    }
    from tirecli.parameters.sets import ParameterSet

    fitted_ps = ParameterSet(name=fc["name"], kind="lugre",
                             values={k: v["value"] for k, v in set_doc["values"].items()},
                             source={k: "tirecli fit" for k in set_doc["values"]},
                             assumed={k: v["assumed"] for k, v in set_doc["values"].items() if "assumed" in v},
                             notes={k: v["note"] for k, v in set_doc["values"].items() if "note" in v},
                             title=set_doc["title"], citation=set_doc["citation"])
    return StudyResult(
        study="fit", config=config, parameter_sets={"start": tire, "fitted": fitted_ps, "vehicle": vehicle},
        data=frames, meta=meta, figures=checked["figures"] or ["fit-steady", "fit-transient"],
        payload={"start": start, "fitted": p_fit, "fitted_fm": p_fm, "table2": _table2(), "steady": steady,
                 "sigma1": s1, "distributed": dist, "samples": data, "used": sel, "car": car, "checked": checked},
        synthetic=data["synthetic"], files={"fitted.yaml": dump_yaml(set_doc)},
    )


def _require(result: identify.FitResult, stage: str, data: dict, mu) -> None:
    """RunError (exit 1, nothing written: no ``fitted.yaml``) when a stage did not give a fitted result
    (:meth:`~tirecli.numerics.identify.FitResult.failure`): start values are never written as if fitted."""
    why = result.failure()
    if why is not None and result.unidentifiable and why == result.identifiability_text():   # the data, not the run
        raise DataError(f"{data['source']}: the {STAGES[stage]} fit is refused: {why}; no fitted.yaml was written")
    with np.errstate(all="ignore"):
        top = float(np.max(np.abs(mu))) if len(mu) else float("nan")
        scale = float(np.sqrt(np.mean(np.square(mu)))) if len(mu) else float("nan")
    if why is None and np.isfinite(scale) and result.residual_rms > MAX_UNEXPLAINED * scale:
        why = (f"the residual RMS {result.residual_rms:.4g} is {result.residual_rms / scale:.0%} of the data's RMS "
               f"{scale:.4g}: the model cannot represent the data within the bounds")
    if why is None:
        return
    raise RunError(f"fit: the {STAGES[stage]} fit did not converge: {why} (data {data['source']}, |mu| up to "
                   f"{top:.4g}); no fitted.yaml was written")


#: FM Table 2 (docs/models/lugre_friction.md §6): the paper's identified values (also the generating values of
#: the synthetic braking #2), drawn beside tirecli's fits (figure fm-table2) and checked against them.
TABLE2 = {"sigma0": 178.0, "sigma1": 1.0, "sigma2": 0.0, "mu_c": 0.8, "mu_s": 1.5, "v_s": 5.5, "L": 0.2, "alpha": 2.0}


def _table2():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-table2").model()


def _variant(raw):
    """The stage-2 tire model: a checked variant entry, or the default lumped kappa0(Z)."""
    from tirecli.models.variants import FrictionVariant

    if isinstance(raw, str) or (isinstance(raw, dict) and "load" in raw):
        return make_variant(raw)
    return FrictionVariant(model="lumped", kappa0="Z")


def overrides_for(data: str | None, maps: list[str] | None, config: str | Path | None = None) -> list[str]:
    """``--set`` overrides from ``tirecli fit --data CSV --map FILE_COLUMN=NAME``.

    ``--data`` is relative to the current directory and ``data.csv`` to the config's: a relative
    ``--data`` is kept as written when the two are the same (messages and run.json name the file as
    the user typed it), else made absolute."""
    out = []
    if data:
        same_dir = config is not None and os.path.abspath(os.path.dirname(os.fspath(config)) or ".") == os.getcwd()
        given = data if (same_dir and not os.path.isabs(data)) else os.path.abspath(data)
        out += [f"data.csv={json.dumps(given)}", "data.simulate=null"]
    if maps:
        mapping = {}
        for m in maps:
            if "=" not in m:
                from tirecli.errors import UsageError

                raise UsageError(f"--map {m!r}: expected FILE_COLUMN=NAME, e.g. --map slip_ratio=s")
            a, _, b = m.partition("=")
            mapping[a.strip()] = b.strip()
        out.append(f"data.map={json.dumps(mapping)}")
    return out
