"""Planning and running a ``fit``: the FM procedure (steady state, then sigma1) and the distributed model in the
loop, the fitted parameter set (see :mod:`tirecli.studies.fit`)."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import collect
from tirecli.errors import ConfigError, DataError, RunError, token
from tirecli.io.files import exists
from tirecli.io.yamlio import dump_yaml
from tirecli.models.lugre import mu_of_deflection
from tirecli.models.profiles import Constant, Table
from tirecli.numerics import identify, runs
from tirecli.numerics.identify_oe import OE_PARAMETERS as OE_TIRE
from tirecli.studies.base import StudyResult
from tirecli.studies.configs import builtin_config_names
from tirecli.studies.fit.data import _window_mask, load_samples
from tirecli.studies.fit.spec import DEFAULT_VEHICLE, MAX_UNEXPLAINED, MIN_SAMPLES_PER_PARAMETER, SIGMA1_DEFAULT, SPEC
from tirecli.studies.study import Plan
from tirecli.studies.sweep import make_variant

def plan(config: Config) -> Plan:
    """Check a fit config completely, without reading its data (sets ``tire`` and ``vehicle``; the size
    estimate is checked once the data are read)."""
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
    return Plan("fit", config, checked, {"tire": tire, "vehicle": vehicle})


STAGES = {"steady": "steady state (FM eq. 4)", "sigma1": "transient (sigma1)",
          "distributed": "transient, distributed model (all at once)",
          "output-error": "output error (coupled quarter car from the brake input)"}
#: The ``fit`` column of frame ``parameters``: the FM procedure (stages 1-2) or stage 3.
FIT_FM, FIT_DISTRIBUTED = "FM 4.3", "distributed"


def fitted_set(name: str, start_set, p, steady: identify.FitResult, s1: identify.FitResult | None, source: str,
               synthetic: bool, dist: identify.FitResult | None = None, oe: identify.FitResult | None = None) -> dict:
    """A parameter-set document (kind lugre) of the fitted values, with estimates and intervals as notes.

    ``dist`` (stage 3) and then ``oe`` (the output-error fit), when given, supersede the estimates of the
    stages before them for the parameters they fitted.
    """
    values = {}
    fits = {**{k: steady for k in steady.names}, **({"sigma1": s1} if s1 is not None else {}),
            **({k: dist for k in dist.names} if dist is not None else {}),
            **({k: oe for k in oe.names if k in OE_TIRE} if oe is not None else {})}
    for key in ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "L", "alpha", "kappa0", "sigma_w"):
        val = float(getattr(p, key))
        if key in fits:
            f = fits[key]
            lvl = int(round(100 * f.confidence))
            how = (" with the distributed model in the loop" if f is dist else
                   " by output error (the quarter car simulated from the brake input)" if f is oe else "")
            note = (f"fitted{how}: {f.estimate[key]:.6g} +/- {f.se[key]:.3g} (SE), {lvl}% CI [{f.ci_low[key]:.6g}, "
                    f"{f.ci_high[key]:.6g}]" + ("; on a bound" if f.at_bound[key] else ""))
            if key in unidentified(f):
                why = f" ({f.identifiability_text()})" if key in f.unidentifiable else ""
                note = (f"NOT IDENTIFIED{how}: the data do not determine it{why}; "
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
                    "(FM eqs. 1-2) driven by the measured kinematics" if dist is not None else "")
                 + ("; then by output error: the coupled quarter car simulated from the measured brake input, fitted "
                    "to the measured v, r omega and mu" if oe is not None else ""))
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

    est = Estimate().add(n, (("data", "file"), ("data", "csv"), ("data", "simulate"), ("data",)), f"the {n:,} data samples",
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
    missing = unidentified(f)
    rows = [{"fit": fit, "parameter": k, "estimate": f.estimate[k], "se": f.se[k], "ci_low": f.ci_low[k],
             "ci_high": f.ci_high[k], "unit": f.extra.get("units", identify.UNITS).get(k, "-"), "at_bound": f.at_bound[k],
             "start": f.extra.get("start", {}).get(k, (initial or {}).get(k, getattr(start, k, float("nan")))), "stage": stage}
            for k in f.names]
    if missing:   # a column only when the data leave a parameter undetermined (outputs unchanged otherwise)
        for row in rows:
            row["identified"] = row["parameter"] not in missing
    return rows


def unidentified(f: identify.FitResult) -> list:
    """The parameters of fit ``f`` the data do not determine: the rank test of the least-squares fits
    (``f.unidentifiable``) and those the output-error fit names (``extra["not_identifiable"]``)."""
    return list(dict.fromkeys([*f.unidentifiable, *(f.extra.get("not_identifiable") or ())]))


def run(plan_: Plan, progress=None) -> StudyResult:
    """Run a planned fit (see :mod:`tirecli.studies.fit`)."""
    import time

    config, checked, tire, vehicle = plan_.config, plan_.checked, plan_.sets["tire"], plan_.sets["vehicle"]
    start, car = tire.model(), vehicle.model()
    d, fc = checked["data"], checked["fit"]
    oe_on = fc["method"] == "output-error"
    data = load_samples(d, config.base_dir, car.r, inputs=oe_on)
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
    p_dist = p_fit if dist is not None else None
    oe = oe_record = None
    if oe_on:  # the output-error fit from the last stage's values
        from tirecli.studies.fit.output_error import FIT_OE, run_stage

        oe, p_fit, frames["output_error"], oe_record = run_stage(data, p_fit, car, fc, free, bounds,
                                                                 s1cfg["bounds"] if s1 is not None else None)
        _require(oe, "output-error", data, mu)
    rows = _parameter_rows(steady, STAGES["steady"], FIT_FM, start, fc["initial"])
    if s1 is not None:
        rows += _parameter_rows(s1, STAGES["sigma1"], FIT_FM, start, fc["initial"])
    if dist is not None:
        rows += _parameter_rows(dist, STAGES["distributed"], FIT_DISTRIBUTED, start, fc["initial"])
    if oe is not None:
        rows += _parameter_rows(oe, STAGES["output-error"], FIT_OE, start, fc["initial"])
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
    if oe is not None:
        oc_ = pd.DataFrame(oe.corr, columns=oe.names)
        oc_.insert(0, "parameter", oe.names)
        frames["correlation_output_error"] = oc_
    set_doc = fitted_set(fc["name"], tire, p_fit, steady, s1, data["source"], data["synthetic"], dist, oe)
    meta = {
        "title": checked["title"],
        "data": {"source": data["source"], "samples": int(len(t)), "used_steady": int(sel.sum()),
                 "window": d["window"], "min_abs_slip": d["min_abs_slip"], "where": d["where"],
                 "synthetic": data["synthetic"]},
        "steady_state": steady.record(),
        "sigma1": s1.record() if s1 is not None else None,
        "sigma1_model": _variant(s1cfg["model"]).record() if s1 is not None else None,
        "model": "distributed" if dist is not None else "lumped",
        "method": fc["method"],
        "output_error": oe_record,
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
        data=frames, meta=meta, figures=checked["figures"] or ["fit-steady", "fit-transient"] + (["fit-output-error"] if oe is not None else []),
        payload={"start": start, "fitted": p_fit, "fitted_fm": p_fm, "table2": _table2(), "steady": steady,
                 "sigma1": s1, "distributed": dist, "output_error": oe,
                 "fitted_distributed": p_dist, "samples": data, "used": sel, "car": car, "checked": checked},
        synthetic=data["synthetic"], files={"fitted.yaml": dump_yaml(set_doc)},
    )


def _require(result: identify.FitResult, stage: str, data: dict, mu) -> None:
    """RunError (exit 1, nothing written: no ``fitted.yaml``) when a stage did not give a fitted result
    (:meth:`~tirecli.numerics.identify.FitResult.failure`): start values are never written as if fitted."""
    why = result.failure()
    if why is not None and result.unidentifiable and why == result.identifiability_text():   # the data, not the run
        raise DataError(f"{data['source']}: the {STAGES[stage]} fit is refused: {why}; no fitted.yaml was written")
    if why and why.startswith("the covariance") and result.extra.get("not_identifiable"):
        why = None  # named as not identifiable, without an interval (the summary and the set say so)
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
