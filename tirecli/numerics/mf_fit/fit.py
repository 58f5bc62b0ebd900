"""Plan and run a staged Magic Formula 6.1 fit (:func:`plan_fit`, :func:`run_fit`, :func:`fit_mf`).

:func:`plan_fit` checks everything and decides, without heavy work, which stages run on which points and
which coefficients the data can identify (a later Study's ``plan``); :func:`run_fit` does the least
squares (the Study's ``run``, with a progress object: ``start(total, label)``, ``item(name)``,
``advance(n)``).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import DataError, RunError, UsageError
from tirecli.models.magic_formula.tire import MFTire
from tirecli.numerics.mf_fit import solve
from tirecli.numerics.mf_fit.data import CHANNELS, Census, FitData, census, check_data
from tirecli.numerics.mf_fit.loads import per_load_start
from tirecli.numerics.mf_fit.model import StageModel
from tirecli.numerics.mf_fit.result import (LOSSES, CoefficientFit, FitOptions, FitResult, StageReport,
                                            StepReport)
from tirecli.numerics.mf_fit.stages import FIT_COEFFICIENTS, GROUPS, NEEDS, PARTS, STAGES, Stage, default_bounds

#: Start values used instead of a start tyre's 0 where 0 leaves the coefficient (and those it multiplies)
#: without any gradient: the weighting functions are even in RBX2/RBY2/RVY4, S_Vyk vanishes with RVY5 or
#: RVY6, B_r with QBZ9 and QBZ10.
SEEDS = {"RBX2": 5.0, "RBY2": 5.0, "RVY4": 20.0, "RVY5": 1.9, "RVY6": 10.0, "QBZ9": 10.0}

_SWEEP_TEXT = {"longitudinal": "pure longitudinal (|alpha| <= {a:.2g} deg)",
               "lateral": "pure lateral (|kappa| <= {k:.2g})", "combined": "combined-slip (both slips non-zero)"}


@dataclass
class StagePlan:
    """What a stage will do: its points, the coefficients the data identify, the least-squares steps."""

    stage: Stage
    run: bool
    reason: str = ""
    mask: np.ndarray | None = None
    census: Census | None = None
    status: dict = field(default_factory=dict)  # coefficient -> "" (to fit) or why not
    steps: list = field(default_factory=list)  # (group, point mask, coefficient names)
    bounds: dict = field(default_factory=dict)
    refitted: bool = False  # a later stage fits its coefficients again (its last step then only starts them)


@dataclass
class FitPlan:
    """A checked fit, ready to run (:func:`run_fit`)."""

    data: FitData
    start: MFTire
    base: MFTire
    options: FitOptions
    stages: list
    ranges: dict
    notes: list

    @property
    def steps(self) -> int:
        return sum(len(s.steps) for s in self.stages if s.run)

    @property
    def jacobian_bytes(self) -> int:
        """Largest Jacobian of a step [bytes] (the fit's main memory need besides the data)."""
        sizes = [int(np.count_nonzero(m)) * len(names) * 8 for s in self.stages if s.run for _, m, names in s.steps]
        return max(sizes, default=0)

    def describe(self) -> list[str]:
        """One line per stage: what runs on which points, or why not."""
        out = []
        for s in self.stages:
            if s.run:
                n_fit = sum(1 for v in s.status.values() if not v)
                out.append(f"{s.stage.title}: {s.census.n} points ({s.census.describe()}), {n_fit} of "
                           f"{len(s.status)} coefficients identifiable, {len(s.steps)} step(s)")
            else:
                out.append(f"{s.stage.title}: skipped ({s.reason})")
        return out


def _check_start(start: MFTire) -> None:
    if start.family != "mf" or start.version not in ("6.1", "6.2"):
        what = {"5.2": "an MF 5.2 / PAC2002", "pac89": "a PAC89"}.get(start.version, f"an MF {start.version}")
        name = f" {start.name}" if start.name else ""
        raise UsageError(f"the start tyre{name} is {what} tyre: the fit writes MF 6.1 coefficients (pressure "
                         "terms, PKY5-PKY7, QDZ10-11, RBX3, RBY4, ...) that its equations do not have; start from "
                         "an MF 6.1 or 6.2 .tir")


def _check_options(o: FitOptions) -> None:
    bad = [p for p in o.parts if p not in PARTS]
    if bad or not o.parts:
        raise UsageError(f"unknown fit part(s) {bad} (expected some of {', '.join(PARTS)})")
    if o.loss not in LOSSES:
        raise UsageError(f"unknown loss {o.loss!r} (expected one of {', '.join(LOSSES)})")
    if not (o.f_scale > 0):
        raise UsageError(f"f_scale must be > 0, got {o.f_scale!r}")
    for name, (lo, hi) in dict(o.bounds).items():
        if name not in FIT_COEFFICIENTS:
            raise UsageError(f"bounds: {name!r} is not a coefficient the fit changes")
        if not lo < hi:
            raise UsageError(f"bounds of {name}: low {lo!r} must be below high {hi!r}")
    unknown = [k for k in o.fix if k not in FIT_COEFFICIENTS]
    if unknown:
        raise UsageError(f"fix: {', '.join(map(str, unknown[:5]))} not coefficient(s) the fit changes")
    for ch, w in dict(o.weights).items():
        if ch not in CHANNELS or not (w >= 0) or not math.isfinite(w):
            raise UsageError(f"weights: expected fx, fy or mz with a weight >= 0, got {ch!r}: {w!r}")
    if o.solver not in ("lm", "scipy"):
        raise UsageError(f"solver must be 'lm' or 'scipy', got {o.solver!r}")
    if o.ranges not in ("data", "start"):
        raise UsageError(f"ranges must be 'data' or 'start', got {o.ranges!r}")
    for name in ("alpha_tol", "kappa_tol", "load_tol", "camber_tol", "pressure_tol", "tol", "collinearity"):
        if not getattr(o, name) > 0:
            raise UsageError(f"{name} must be > 0, got {getattr(o, name)!r}")


def data_ranges(data: FitData, start: MFTire) -> dict:
    """The input ranges of the data, widened to hold the nominal point (load FNOMIN, zero slips and
    inclination, NOMPRES and INFLPRES)."""
    x = data.inputs
    c = start.coef
    r = {"FZMIN": min(float(x["fz"].min()), c["FNOMIN"]), "FZMAX": max(float(x["fz"].max()), c["FNOMIN"]),
         "KPUMIN": min(float(x["kappa"].min()), 0.0), "KPUMAX": max(float(x["kappa"].max()), 0.0),
         "ALPMIN": min(float(x["alpha"].min()), 0.0), "ALPMAX": max(float(x["alpha"].max()), 0.0),
         "CAMMIN": min(float(x["gamma"].min()), 0.0), "CAMMAX": max(float(x["gamma"].max()), 0.0)}
    if x["p"] is not None:
        ps = [float(x["p"].min()), float(x["p"].max()), start.nominal_pressure, start.default_pressure]
        r["PRESMIN"], r["PRESMAX"] = min(ps), max(ps)
    return r


def _distinct(v, tol) -> int:
    return int(np.unique(np.round(v / tol)).size)


def _plan_stage(stage: Stage, data: FitData, o: FitOptions, start: MFTire, planned: dict) -> StagePlan:
    if stage.part not in o.parts:
        return StagePlan(stage, False, f"not asked (parts: {', '.join(o.parts)})")
    if stage.channel not in data.channels:
        why = "has weight 0" if o.weights.get(stage.channel, 1.0) == 0 else "is not in the data"
        return StagePlan(stage, False, f"the measured {stage.channel} {why}")
    missing = [a for a in stage.after if not planned.get(a)]
    if missing:
        return StagePlan(stage, False, f"it builds on the {' and '.join(missing)} stage(s), which do not run")
    y = data.channels[stage.channel]
    usable = np.isfinite(y) & (data.weight > 0)
    need = data.sweep[stage.sweep] & usable
    sweep_text = _SWEEP_TEXT[stage.sweep].format(a=math.degrees(o.alpha_tol), k=o.kappa_tol)
    slip = {"longitudinal": ("kappa", o.kappa_tol), "lateral": ("alpha", o.alpha_tol)}.get(stage.sweep)
    n = int(np.count_nonzero(need))
    varied = n and (slip is None or _distinct(data.inputs[slip[0]][need], slip[1]) >= 5)
    if n < o.min_points or not varied:
        what = f"{n} {sweep_text} point(s) with a measured {stage.channel}"
        want = f"at least {o.min_points}" + ("" if slip is None else f", {slip[0]} taking 5 or more values")
        return StagePlan(stage, False, f"no sweep for it in the data: {what} ({want})")
    mask = data.sweep[stage.points or stage.sweep] & usable
    n = int(np.count_nonzero(mask))
    cen = census(data, mask, o, start)
    status, bounds = {}, {}
    for c in stage.coefs:
        if c.name in o.fix:
            status[c.name] = "fixed by the options"
        else:
            unmet = [NEEDS[k] for k in c.needs if not cen.met[k]]
            status[c.name] = f"{unmet[0]} in the points of this stage" if unmet else ""
        bounds[c.name] = tuple(o.bounds.get(c.name, default_bounds(c.name, start.coef[c.name])))
    x = data.inputs
    # reference levels: those nearest FNOMIN, zero inclination and NOMPRES among the points of the sweep the
    # stage needs (the combined sweeps of a rig may all be at one pressure), then the points at those levels
    own = census(data, need, o, start)
    ref = (own.loads.centres[own.loads.nearest(start.coef["FNOMIN"])], own.cambers.centres[own.cambers.nearest(0.0)],
           None if own.pressures is None else own.pressures.centres[own.pressures.nearest(start.nominal_pressure)])
    ref_load = cen.loads.index == cen.loads.nearest(ref[0])
    ref_camber = cen.cambers.index == cen.cambers.nearest(ref[1])
    ref_p = np.ones(n, bool) if cen.pressures is None else cen.pressures.index == cen.pressures.nearest(ref[2])
    filters = {"nominal": ref_load & ref_camber & ref_p, "load": ref_camber & ref_p, "camber": ref_p,
               "pressure": np.ones(n, bool)}
    idx = np.flatnonzero(mask)
    steps, names, last = [], [], ""
    for group in GROUPS:
        new = [c.name for c in stage.coefs if c.group == group and not status[c.name]]
        if not new:
            continue
        names, last = names + new, group
        sub = idx[filters[group]]
        if sub.size >= max(o.min_points, len(names) + 1) and (slip is None or _distinct(x[slip[0]][sub], slip[1]) >= 5):
            steps.append((group, sub, list(names)))
        # else: too few points at that level; its coefficients join the next step
    if not names:
        return StagePlan(stage, False, "the data identify none of its coefficients", mask, cen, status, [], bounds)
    if steps and steps[-1][1].size == idx.size:
        steps.pop()
    steps.append((last, idx, list(names)))  # the last step: every point, every coefficient
    steps = [s for i, s in enumerate(steps) if i == len(steps) - 1 or s[1].size != steps[i + 1][1].size]
    return StagePlan(stage, True, "", mask, cen, status, steps, bounds)


def plan_fit(data, start: MFTire, options: FitOptions | None = None) -> FitPlan:
    """Check a fit completely and plan its stages (no least squares).

    Parameters
    ----------
    data : pandas.DataFrame or mapping of columns
        Measured points (:mod:`~tirecli.numerics.mf_fit.data`).
    start : MFTire
        MF 6.1 / 6.2 start tyre: start values, dimensions, every coefficient not fitted.
    options : FitOptions or None

    Raises
    ------
    UsageError
        A start tyre that is not MF 6.x, bad options.
    DataError
        Data that cannot be used, or that hold no sweep for any stage (the message names each stage's
        reason).
    """
    o = options or FitOptions()
    _check_start(start)
    _check_options(o)
    fd = check_data(data, start, o)
    ranges = data_ranges(fd, start) if o.ranges == "data" else {}
    base = MFTire({**start.coef, **ranges}, start.version, start.side, start.name)
    plans, planned = [], {}
    for stage in STAGES:
        sp = _plan_stage(stage, fd, o, start, planned)
        planned[stage.name] = sp.run
        plans.append(sp)
    for sp in plans:
        sp.refitted = any(p.run and sp.stage.name in p.stage.refit for p in plans)
    if not any(p.run for p in plans):
        why = "; ".join(f"{p.stage.title}: {p.reason}" for p in plans if p.stage.part in o.parts)
        raise DataError(f"no stage of the fit can run: {why}")
    notes = list(fd.notes)
    if ranges:
        notes.append("input ranges of the fitted tyre from the data: " + ", ".join(
            f"{k} {v:.6g}" for k, v in ranges.items()))
    return FitPlan(fd, start, base, o, plans, ranges, notes)


# --------------------------------------------------------------------------- running


def _rms(r) -> float:
    return float(np.sqrt(np.mean(np.square(r)))) if np.size(r) else float("nan")


def _start_values(plan: FitPlan, values: dict, notes: list) -> None:
    """Move start values into their bounds, and away from a 0 that gives no gradient (:data:`SEEDS`)."""
    for sp in plan.stages:
        if not sp.run:
            continue
        for name, why in sp.status.items():
            if why:
                continue
            v = values[name]
            lo, hi = sp.bounds[name]
            if v == 0.0 and name in SEEDS and not (name == "QBZ9" and values.get("QBZ10")):
                values[name] = float(np.clip(SEEDS[name], lo, hi))
                notes.append(f"{name} started from {values[name]:g}: the start tyre's 0 gives it no gradient")
            elif not lo <= v <= hi:
                values[name] = float(np.clip(v, lo, hi))
                notes.append(f"{name} started from {values[name]:g}: the start tyre's {v:g} is outside its bounds "
                             f"[{lo:g}, {hi:g}]")


def _subsample(idx, m: int):
    """About ``m`` of the indices, evenly strided (every sweep keeps its shape)."""
    return idx[:: int(np.ceil(idx.size / m))]


def _typical(x) -> np.ndarray:
    return np.maximum(np.abs(x), 1e-2)


def _step(plan: FitPlan, sp: StagePlan, values: dict, idx, names, final: bool):
    """One least-squares step; returns ``(Residuals, x, solver result, model)``."""
    o = plan.options
    st = sp.stage
    model = StageModel(MFTire({**plan.base.coef, **values}, plan.base.version, plan.base.side),
                       plan.data.subset(idx), st.kind, o.convention)
    y = plan.data.channels[st.channel][idx]
    w = plan.data.weight[idx] * o.weights.get(st.channel, 1.0)
    scale = float(np.max(np.abs(plan.data.channels[st.channel][sp.mask]))) or 1.0
    res = solve.Residuals(model, names, {k: v for k, v in values.items() if k not in names}, y, w, scale)
    x0 = np.array([values[k] for k in names])
    lo = np.array([sp.bounds[k][0] for k in names])
    hi = np.array([sp.bounds[k][1] for k in names])
    tol = o.tol if final else max(o.tol, 1e-5)
    max_nfev = o.max_nfev if final else min(o.max_nfev, 15 * (len(names) + 1))
    try:
        x, r = solve.least_squares(res, x0, lo, hi, _typical(x0), o.loss, o.f_scale, tol, max_nfev, o.solver)
    except ValueError as exc:  # scipy refuses a start where the residuals are not finite
        raise RunError(f"{st.title}: the least squares failed at the start values ({exc})") from None
    return res, x, r, model


def _run_stage(plan: FitPlan, sp: StagePlan, values: dict, start_values: dict, progress, refit: list, rows: dict):
    """Fit one stage in place of ``values`` (its last step also fitting the identified coefficients
    ``refit`` of earlier stages); updates ``rows`` (name -> CoefficientFit) and returns
    ``(StageReport, correlations)``."""
    st = sp.stage
    o = plan.options
    t0 = time.perf_counter()
    idx_all = sp.steps[-1][1]
    y_all = plan.data.channels[st.channel][idx_all]
    full = StageModel(MFTire({**plan.base.coef, **values}, plan.base.version, plan.base.side),
                      plan.data.subset(idx_all), st.kind, o.convention)
    rms_start = _rms(full(values) - y_all)
    rep = StageReport(st.name, st.title, st.channel, "fitted", points=int(idx_all.size),
                      data=sp.census.describe(), rms_start=rms_start, peak=float(np.max(np.abs(y_all))))
    dropped: dict = {}
    started: set = set()
    for pre in st.pre:  # peak and stiffness first, then the shape factor and shifts (Stage.pre)
        pre = [k for k in pre if not sp.status[k]]
        idx0 = sp.steps[0][1]
        if pre:
            _, x, _, _ = _step(plan, sp, values, _subsample(idx0, o.step_points) if idx0.size > o.step_points
                               else idx0, pre, False)
            values.update(zip(pre, map(float, x)))
    for i, (group, idx, names) in enumerate(sp.steps):
        final = i == len(sp.steps) - 1 and not sp.refitted
        if progress is not None:
            progress.item(f"{st.title}: {group}")
        names = (refit if final else []) + [k for k in names if k not in dropped]
        if group == "load" and group not in started:  # start values of the load terms from fits per load level
            started.add(group)
            values.update(per_load_start(plan, sp, values, idx, names, _step))
        if not final:  # a step before the last: on a subsample when the points are many
            sub = _subsample(idx, o.step_points) if idx.size > o.step_points else idx
            pre, x, r, model = _step(plan, sp, values, sub, names, False)
            values.update(zip(names, map(float, x)))
            rep.nfev += pre.nfev
            rep.steps.append(StepReport(group, int(sub.size), list(names), _rms(model(pre.values(x)) - pre.y),
                                        pre.nfev, r.message))
        else:
            res, x, r, model, names = _final_step(plan, sp, values, idx, names, start_values, dropped, rep, group)
        if progress is not None:
            progress.advance(1)
    if sp.refitted:  # the coefficients are judged, and their intervals found, where they are fitted again
        corr = []
        for c in st.coefs:
            rows[c.name] = CoefficientFit(c.name, st.name, c.group, start_values[c.name], values[c.name],
                                          identified=not sp.status[c.name], reason=sp.status[c.name])
    else:
        corr = _intervals(st, sp, names, r, int(idx_all.size), values, start_values, dropped, rows, rep)
    rep.rms_fit = _rms(full(values) - y_all)
    rep.seconds = time.perf_counter() - t0
    return rep, corr


def _drop(plan, sp, res_names, jac, values, start_values, dropped, keep_from=None) -> list:
    """Coefficients whose Jacobian columns are dependent (:func:`.solve.dependent`) go back to their start
    values (named in ``dropped``); the others back to ``keep_from`` when given (a coefficient that drifted
    along a valley with a dependent one would otherwise stay there). Returns the names kept."""
    bad = solve.dependent(jac, plan.options.collinearity)
    if not bad:
        return res_names
    for j, (why, _) in bad.items():
        dropped[res_names[j]] = why
        values[res_names[j]] = start_values[res_names[j]]
    kept = [k for j, k in enumerate(res_names) if j not in bad]
    if keep_from is not None:
        values.update({k: keep_from[k] for k in kept})
    return kept


def _final_step(plan, sp, values, idx, names, start_values, dropped, rep, group):
    """The last step of a stage: every point, with the identifiability test (module :mod:`.solve`) at its
    start, on the subsample that starts it (many points) and at its optimum; a coefficient found
    dependent goes back to its start value and the step is fitted again from its first values."""
    o = plan.options
    sub = _subsample(idx, o.step_points) if idx.size > o.step_points else idx
    st = sp.stage
    probe = solve.Residuals(StageModel(MFTire({**plan.base.coef, **values}, plan.base.version, plan.base.side),
                                       plan.data.subset(sub), st.kind, o.convention), names,
                            {k: v for k, v in values.items() if k not in names}, plan.data.channels[st.channel][sub],
                            plan.data.weight[sub], 1.0)
    x0 = np.array([values[k] for k in names])
    bounds = np.array([sp.bounds[k] for k in names]).reshape(-1, 2)
    jac0 = solve.fd_jacobian(probe, x0, probe(x0), bounds[:, 0], bounds[:, 1], _typical(x0))
    names = _drop(plan, sp, names, jac0, values, start_values, dropped)
    first = dict(values)
    if sub is not idx:
        pre, x, r, model = _step(plan, sp, values, sub, names, False)
        values.update(zip(names, map(float, x)))
        rep.nfev += pre.nfev
        rep.steps.append(StepReport(group, int(sub.size), list(names), _rms(model(pre.values(x)) - pre.y), pre.nfev,
                                    f"subsample: {r.message}"))
        kept = _drop(plan, sp, names, r.jac, values, start_values, dropped, first)
        if kept != names:
            names = kept
            pre, x, r, model = _step(plan, sp, values, sub, names, False)
            values.update(zip(names, map(float, x)))
            rep.nfev += pre.nfev
    nfev = 0
    for _ in range(3):
        res, x, r, model = _step(plan, sp, values, idx, names, True)
        values.update(zip(names, map(float, x)))
        nfev += res.nfev
        kept = _drop(plan, sp, names, r.jac, values, start_values, dropped, first)
        if kept == names or not kept:
            names = kept
            break
        names = kept
    rep.nfev += nfev
    rep.steps.append(StepReport(group, int(idx.size), list(names), _rms(model(res.values(x)) - res.y), nfev,
                                r.message))
    return res, x, r, model, names


def _intervals(st, sp, names, r, n, values, start_values, dropped, rows, rep) -> list:
    """Rows of the stage's coefficients (and of those it refitted) from its last step: values, 95 %
    intervals (module :mod:`.solve`), why a coefficient is not identified; returns the correlations."""
    at_bound = [k for j, k in enumerate(names) if r.active_mask[j] != 0] if names else []
    keep = [j for j, k in enumerate(names) if k not in at_bound]
    cov, s2, dof = solve.covariance(r.jac[:, keep], r.cost, n) if keep else (None, float("nan"), 0)
    rep.s2, rep.dof = s2, dof
    tq = solve.t_quantile(dof) if cov is not None else float("nan")
    se, corr = {}, []
    if cov is not None:
        d = np.sqrt(np.maximum(np.diag(cov), 0.0))
        se = {names[j]: float(d[a]) for a, j in enumerate(keep)}
        corr = [(names[keep[a]], names[keep[b]], float(cov[a, b] / (d[a] * d[b])))
                for a in range(len(keep)) for b in range(a + 1, len(keep)) if d[a] > 0 and d[b] > 0]
    own = {c.name: c for c in st.coefs}
    for name in list(dict.fromkeys([k for k in names if k not in own] + list(own) + list(dropped))):
        row = rows.get(name)
        if row is None:
            c = own[name]
            row = rows[name] = CoefficientFit(name, st.name, c.group, start_values[name], values[name])
        why = sp.status.get(name, "") or dropped.get(name, "")
        row.value = values[name]
        row.fitted_in = st.name
        row.identified, row.at_bound, row.stderr, row.low, row.high = not why, name in at_bound, None, None, None
        row.reason = why
        if why:
            continue
        if name in se:
            row.stderr = se[name]
            row.low, row.high = values[name] - tq * se[name], values[name] + tq * se[name]
        elif row.at_bound:
            row.reason = "ended on its bound: no interval"
    return corr


def run_fit(plan: FitPlan, progress=None) -> FitResult:
    """Run a planned fit (see :func:`fit_mf`)."""
    t0 = time.perf_counter()
    start_values = {k: float(plan.start.coef[k]) for k in FIT_COEFFICIENTS}
    values = dict(start_values)
    notes = list(plan.notes)
    _start_values(plan, values, notes)
    if progress is not None:
        progress.start(plan.steps, "mf fit")
    stages, rows, corr = [], {}, []
    plans = {sp.stage.name: sp for sp in plan.stages}
    for sp in plan.stages:
        if not sp.run:
            stages.append(StageReport(sp.stage.name, sp.stage.title, sp.stage.channel, "skipped", reason=sp.reason))
            for c in sp.stage.coefs:
                rows[c.name] = CoefficientFit(c.name, sp.stage.name, c.group, start_values[c.name],
                                              start_values[c.name], reason=f"stage skipped: {sp.reason}")
            continue
        refit = [k for s in sp.stage.refit for k in plans[s].stage.names() if rows.get(k) and rows[k].identified]
        for s in sp.stage.refit:
            sp.bounds.update(plans[s].bounds)
        rep, c = _run_stage(plan, sp, values, start_values, progress, refit, rows)
        stages.append(rep)
        again = set(refit)
        corr = [t for t in corr if not (t[0] in again and t[1] in again)] + c
    for row in rows.values():  # a seeded start value never stays in a coefficient that was not identified
        if not row.identified:
            values[row.name] = row.value = row.start
    table = [rows[k] for k in FIT_COEFFICIENTS if k in rows]
    fitted = MFTire({**plan.base.coef, **{r.name: values[r.name] for r in table}}, plan.start.version,
                    plan.start.side, (plan.start.name + " fitted").strip())
    corr.sort(key=lambda t: -abs(t[2]))
    return FitResult(start=plan.start, tire=fitted, coefficients=table, correlations=corr[:20], stages=stages,
                     ranges=dict(plan.ranges), notes=notes, options=plan.options,
                     data=_data_text(plan), seconds=time.perf_counter() - t0,
                     sweeps={k: plan.data.sweep[k].copy() for k in ("longitudinal", "lateral", "combined")})


def _data_text(plan: FitPlan) -> str:
    d = plan.data
    parts = [f"{d.n} points"] + [f"{int(np.count_nonzero(d.sweep[s]))} {s}" for s in ("longitudinal", "lateral",
                                                                                      "combined")]
    return ", ".join(parts) + "; channels " + ", ".join(d.channels)


def fit_mf(data, start: MFTire, options: FitOptions | None = None, progress=None) -> FitResult:
    """Fit MF 6.1 coefficients to measured points, stage by stage.

    Parameters
    ----------
    data : pandas.DataFrame or mapping of columns
        One row per point: ``kappa, alpha, gamma, fz, p, vx`` (ISO-W, SI) and measured ``fx, fy, mz``
        (:mod:`~tirecli.numerics.mf_fit.data`).
    start : MFTire
        MF 6.1 / 6.2 start tyre.
    options : FitOptions or None
    progress : object or None
        ``start(total, label)``, ``item(name)``, ``advance(n)`` (one tick per least-squares step).

    Returns
    -------
    FitResult
    """
    return run_fit(plan_fit(data, start, options), progress)
