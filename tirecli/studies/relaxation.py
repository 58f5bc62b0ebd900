"""``relaxation`` (``tirecli simulate``): force build-up after a slip-ratio step and after a slip-angle step,
the transient Magic Formula against MCPS and the distributed LuGre tire, over the rolled distance.

At ``t = 0`` the tire, rolling freely at ``speed`` under ``fz``, gets a step of the slip ratio ``kappa`` (then,
in a second run, of the slip angle ``alpha``), held afterwards. Each model's force (``Fx`` after the
slip-ratio step, ``Fy`` after the slip-angle step) is normalised by its own steady state,
``(F - F_start)/(F_steady - F_start)``, and drawn against the distance the wheel centre has rolled,
``s = Vx t``:

- **transient Magic Formula** (:mod:`tirecli.models.magic_formula.transient`, docs/models/magic_formula_tyre.md
  §18): first-order lag of the slip with the relaxation lengths of the ``.tir`` (§17.2);
- **MCPS** (docs/models/mcps_tire.md §7), solid (``rigid``) and flexible (``complete``) carcass. The slip-angle
  step is the ``mcps-relaxation`` study's own run (its reference checks apply); the slip-ratio step runs the
  same solver with ``r omega = Vx (1 + kappa)``;
- **distributed LuGre** (uniform load, :mod:`tirecli.numerics.driven`), slip-ratio step only (the model is
  longitudinal): ``v = Vx``, ``r omega = Vx (1 + kappa)``; ``Fx = mu Fz``.

Config (defaults in brackets)::

    study: relaxation
    mf: externdata-205-60r15          # Magic Formula tyre: built-in name or .tir path, or {tire, convention}
    sigma_source: auto                # auto | version | stiffness | pt: rule of the relaxation lengths
    tire: sorine2000-mcps             # MCPS parameter set
    lugre: canudas2003-table1         # LuGre parameter set (distributed, uniform load)
    fz: 4000                          # [N] vertical load
    speed: 20                         # [m/s] forward speed Vx
    kappa: 0.02                       # [-] slip ratio after the longitudinal step (not 0)
    alpha: 0.017453293                # [rad] slip angle after the lateral step (1 deg; not 0)
    distance: 4                       # [m] rolled distance
    samples: 2001                     # points of the Magic Formula and LuGre responses over the distance
    carcass: [rigid, complete]        # MCPS carcasses
    cells: 100                        # MCPS patch cells (raised automatically as mcps-relaxation does)

Outputs: ``data/relaxation.csv`` (``step, model, s, t, force, ratio, slip_state``) and
``data/relaxation_distances.csv`` (per step and model: steady force, the 63 % and 95 % distances, first
reached and settled, and the gaps to the Magic Formula). Facts (``run.json``): ``NAME[STEP, MODEL]``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import ListOf, Map, Num, Raw, Str, collect
from tirecli.errors import ConfigError, RunError
from tirecli.limits import Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mcps.common import BYTES_PER_ROW, CARCASSES, DEG, MAX_ELEMENT_STEPS, mf_side, tire_set
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

#: Rules of the relaxation lengths: ``auto`` (the file version's rule, or the other rule where the file
#: lacks that rule's coefficients) and those of :data:`tirecli.models.magic_formula.relaxation.SIGMA_SOURCES`.
SIGMA_CHOICES = ("auto", "version", "stiffness", "pt")
#: Levels of the tabulated distances (fractions of the change): 63.2 % (``1 - 1/e``: the slip state of the
#: first-order lag reaches it after one relaxation length) and 95 %.
LEVELS = (1.0 - math.exp(-1.0), 0.95)
STEPS = ("kappa", "alpha")
DEFAULT_LUGRE = "canudas2003-table1"

SCHEMA = Map(fields=common_fields() | {
    "mf": Raw(default=None, doc="Magic Formula tyre: a built-in name or a .tir path (default externdata-205-60r15), "
                                "or {tire, convention}"),
    "sigma_source": Str(choices=SIGMA_CHOICES, default="auto",
                        doc="relaxation lengths: auto (the file version's rule; the other where the file lacks its "
                            "coefficients), version (mfeval's), stiffness (K/C, MF 6.x) or pt (PTX/PTY, MF 5.2)"),
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set (default sorine2000-mcps)"),
    "lugre": Raw(kind="lugre", default=None, doc="LuGre parameter set (default canudas2003-table1)"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="vertical load"),
    "speed": Num(unit="m/s", gt=0, le=200, default=20.0, doc="forward speed Vx"),
    "kappa": Num(unit="-", gt=-1, le=1, default=0.02, doc="slip ratio after the longitudinal step (not 0)"),
    "alpha": Num(unit="rad", ge=-1.5, le=1.5, default=1.0 * DEG, doc="slip angle after the lateral step (not 0)"),
    "distance": Num(unit="m", gt=0, le=1000, default=4.0, doc="rolled distance of the wheel centre"),
    "samples": Num(unit="-", integer=True, ge=11, le=2_000_000, default=2001,
                   doc="points of the Magic Formula and LuGre responses over the distance"),
    "carcass": ListOf(item=Str(choices=CARCASSES), min_len=1, max_len=2, default=["rigid", "complete"],
                      doc="MCPS carcasses"),
    "cells": Num(unit="-", integer=True, ge=10, le=20_000, default=100,
                 doc="MCPS patch cells (raised automatically at low speed and large slip)"),
})


@dataclass
class Detail:
    """What a ``relaxation`` run needs beyond the checked config."""

    mf: object          # MFSide
    transient: object   # TransientMF
    rule: str           # the rule of the relaxation lengths used (stiffness or pt)
    rule_note: str
    mcps: object        # MCPSParams
    lugre: object       # LuGreParams


def _transient_mf(config: Config, side, wanted: str):
    """The transient Magic Formula of the config's tyre and the rule of its relaxation lengths."""
    from tirecli.models.magic_formula import relaxation as rel
    from tirecli.models.magic_formula.transient import TransientMF

    if side.kind != "tir" or side.model.family != "mf":
        what = {"none": "none", "simple": "the simple form"}.get(side.kind) or f"a {side.model.version} tyre"
        raise ConfigError(config.origins.problem(("mf",), f"needs an MF 6.x or 5.2 tyre that gives relaxation lengths, "
                                                          f"not {what}"))
    t = side.model
    own = rel.sigma_source(t, "version")
    other = "pt" if own == "stiffness" else "stiffness"
    both = {r: all(rel.available(t, r)[k] for k in ("sigmax", "sigmay")) for r in (own, other)}
    need = {"stiffness": "LONGITUDINAL_STIFFNESS and LATERAL_STIFFNESS", "pt": "PTX1, PTY1 and PTY2"}
    if wanted == "auto":
        rule = own if both[own] else (other if both[other] else None)
    else:
        rule = own if wanted == "version" else wanted
    if rule is None or not both[rule]:
        which = rule or own
        raise ConfigError(config.origins.problem(("sigma_source",) if wanted != "auto" else ("mf",),
                                                 f"the tyre {side.name} gives no relaxation lengths by the {which!r} rule "
                                                 f"(it needs {need[which]})"))
    version = "MF 5.2" if t.is_52 else "MF 6.x"
    note = (f"{need[rule]} ({'the rule of its version, ' + version + ', as mfeval' if rule == own else 'forced: the file is ' + version + ' but lacks ' + need[own]})")
    return TransientMF(t, convention=side.convention, sigma_source=rule), rule, note


def _mcps_steps(p, fz, V, slip, carcass, cells, distance):
    """``(cells, transport steps)`` of an MCPS rolling run (as ``mcps-relaxation`` sizes it)."""
    from tirecli.numerics.mcps_transient import cells_needed

    kappa, alpha = slip
    romega = V * (1.0 + kappa)
    n = cells_needed(p, fz, romega, cells, carcass, (), slip=(-kappa / (1.0 + kappa), math.tan(alpha)))
    return n, distance * (1.0 + kappa) / (p.patch(fz).l / n)


def plan(config: Config) -> Plan:
    """Check a ``relaxation`` config completely and size its run."""
    checked, ps, lugre, side = collect(lambda: config.checked(SCHEMA), lambda: tire_set(config),
                                       lambda: config.group("lugre", "lugre", DEFAULT_LUGRE), lambda: mf_side(config))
    for key in ("kappa", "alpha"):
        if checked[key] == 0:
            raise ConfigError(config.origins.problem((key,), "must not be 0: the study is the force build-up after a step"))
    tmf, rule, note = _transient_mf(config, side, checked["sigma_source"])
    p = ps.model()
    est = Estimate()
    n_s = int(checked["samples"])
    est.add(n_s * 5, (("samples",),), "data/relaxation.csv (Magic Formula and LuGre rows)", BYTES_PER_ROW)
    cap = compute_cap(MAX_ELEMENT_STEPS)
    for step, slip in (("kappa", (checked["kappa"], 0.0)), ("alpha", (0.0, checked["alpha"]))):
        for c in checked["carcass"]:
            n, steps = _mcps_steps(p, checked["fz"], checked["speed"], slip, c, checked["cells"], checked["distance"])
            est.add(steps + 1, (("distance",), ("cells",), ("speed",)),
                    f"data/relaxation.csv (MCPS {c}, {step} step: {steps:,.0f} steps of {n} cells)", BYTES_PER_ROW)
            if n * steps > cap:
                raise ConfigError(config.origins.problem((), f"MCPS {c} after the {step} step: the run needs {n} cells x "
                                                             f"{steps:.3g} steps, over the budget of {cap:.0e} element-steps: "
                                                             "shorten 'distance' or raise 'speed' " + cap_hint()))
    est.check(config.origins)
    sets = {"mf": side.ps, "tire": ps, "lugre": lugre}
    return Plan("relaxation", config, checked, sets, est, Detail(side, tmf, rule, note, p, lugre.model()))


# --------------------------------------------------------------------------- distances


def distances(s, ratio, level):
    """``(first, settled)`` rolled distances [m] of a normalised response: ``first`` where it first reaches
    ``level`` (0 when it starts there or above), ``settled`` from where on it stays within ``1 +- (1 - level)``
    (linear between samples); None when never reached."""
    s, ratio = np.asarray(s, dtype=float), np.asarray(ratio, dtype=float)
    hit = np.flatnonzero(ratio >= level)
    if hit.size == 0:
        first = None
    elif hit[0] == 0:
        first = 0.0
    else:
        i = hit[0] - 1
        first = float(s[i] + (level - ratio[i]) * (s[i + 1] - s[i]) / (ratio[i + 1] - ratio[i]))
    band = 1.0 - level
    out = np.abs(ratio - 1.0) > band
    if not out.any():
        return first, 0.0
    j = int(np.flatnonzero(out)[-1])
    if j == len(s) - 1:
        return first, None
    d0, d1 = abs(ratio[j] - 1.0), abs(ratio[j + 1] - 1.0)
    return first, float(s[j] + (d0 - band) * (s[j + 1] - s[j]) / (d0 - d1))


def _facts(s, ratio, steady, start):
    f = {"steady_N": steady, "start_N": start}
    for lev in LEVELS:
        first, settled = distances(s, ratio, lev)
        f[f"s{int(lev * 100)}_m"] = first
        f[f"s{int(lev * 100)}_settled_m"] = settled
    f["peak_ratio"] = float(np.max(ratio))
    return f


def gaps(s_mf, r_mf, s, r):
    """Largest ``|r - r_MF|`` over the model's samples (the MF response interpolated), where, and the RMS."""
    d = np.asarray(r, dtype=float) - np.interp(s, s_mf, r_mf)
    i = int(np.argmax(np.abs(d)))
    return {"gap_max": float(abs(d[i])), "gap_at_m": float(s[i]), "gap_rms": float(np.sqrt(np.mean(d**2)))}


# --------------------------------------------------------------------------- run


def _mcps_alpha(plan_: Plan, progress):
    """The slip-angle step of MCPS: the ``mcps-relaxation`` study's run (its cases rigid / complete)."""
    from tirecli.studies.mcps import relaxation as mr

    c = plan_.checked
    sub = {k: c[k] for k in ("fz", "alpha", "speed", "distance", "cells")}
    sub.update(title="", figures=None, frame_term=True, carcass=list(c["carcass"]))
    cases = [mr.RelaxCase(k, k, ()) for k in c["carcass"]]
    return mr.run(Plan("mcps-relaxation", plan_.config, sub, {"tire": plan_.sets["tire"]}, None,
                       mr.Relaxation(plan_.detail.mcps, cases)), progress)


def _mcps_kappa(plan_: Plan, carcass: str, progress):
    """The slip-ratio step of MCPS: ``(s, t, fx, fx_inf, transport distance)``."""
    from tirecli.numerics.mcps_stationary import solve
    from tirecli.numerics.mcps_transient import simulate_rolling

    c, p = plan_.checked, plan_.detail.mcps
    fz, V, k = c["fz"], c["speed"], c["kappa"]
    st = solve(p, fz, [k], [0.0], [0.0], carcass=carcass)
    if not st.converged.all():
        raise RunError(f"MCPS {carcass}: the stationary fixed point (MCPS eq. 18) did not converge at kappa = {k:g}; "
                       "nothing was written")
    n, _ = _mcps_steps(p, fz, V, (k, 0.0), carcass, c["cells"], c["distance"])
    run = simulate_rolling(p, fz, V, 0.0, V * (1.0 + k), 0.0, c["distance"] * (1.0 + k), cells=n, carcass=carcass,
                           progress=progress)
    return run.t * V, run.t, run.fx, float(st.fx[0]), run.s


def run(plan_: Plan, progress=None) -> StudyResult:
    """The steps, each model's normalised response, its 63 % and 95 % distances and the gaps to the MF."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    from tirecli.models.lugre import mu_ss_uniform
    from tirecli.numerics.driven import DrivenDistributed
    from tirecli.numerics.mf_transient import step_responses

    c, d = plan_.checked, plan_.detail
    fz, V, dist = c["fz"], c["speed"], c["distance"]
    mf = step_responses(d.transient, fz, V, c["kappa"], c["alpha"], distance=dist, samples=int(c["samples"]),
                        levels=LEVELS)
    frames, facts, curves = [], {"kappa": {}, "alpha": {}}, {"kappa": {}, "alpha": {}}

    def add(step, model, s, t, force, ratio, steady, start, state=None):
        curves[step][model] = (np.asarray(s), np.asarray(ratio))
        frames.append(pd.DataFrame({"step": step, "model": model, "s": s, "t": t, "force": force, "ratio": ratio,
                                    "slip_state": np.nan if state is None else state}))
        facts[step][model] = _facts(s, ratio, steady, start)

    for step in STEPS:
        r = mf[step]
        add(step, "mf", r.s, r.t, r.force, r.force_norm, r.force_steady, r.force_start, r.state)
        f = facts[step]["mf"]
        f["sigma_m"] = r.sigma
        f["s63_exact_m"], f["s95_exact_m"] = (r.distances["force"][lv] for lv in LEVELS)
        f["state_s63_m"], f["state_s95_m"] = (r.distances["state"][lv] for lv in LEVELS)
    sub = _mcps_alpha(plan_, progress)
    rel = sub.data["relaxation"]
    for carcass in c["carcass"]:
        g = rel[rel["case"] == carcass]
        fy_inf = sub.meta["facts"][carcass]["fy_inf_N"]
        add("alpha", f"mcps-{carcass}", g["s"].to_numpy(), g["t"].to_numpy(), g["fy"].to_numpy(),
            g["ratio"].to_numpy(), fy_inf, 0.0)
        s, t, fx, fx_inf, _ = _mcps_kappa(plan_, carcass, progress)
        add("kappa", f"mcps-{carcass}", s, t, fx, fx / fx_inf, fx_inf, 0.0)
    lp, k = d.lugre, c["kappa"]
    s = np.linspace(0.0, dist, int(c["samples"]))
    t = s / V
    mu = DrivenDistributed(t, np.full_like(t, V), np.full_like(t, V * (1.0 + k)), lp.L).mu(lp)
    mu_inf = float(mu_ss_uniform(V * k, V * (1.0 + k), lp))
    add("kappa", "lugre", s, t, mu * fz, mu / mu_inf, mu_inf * fz, 0.0)
    facts["kappa"]["lugre"]["transit_m"] = lp.L / (1.0 + k)
    facts["kappa"]["lugre"]["start_ratio"] = float(mu[0] / mu_inf)
    for step in STEPS:
        s_mf, r_mf = curves[step]["mf"]
        for model, (s_m, r_m) in curves[step].items():
            if model == "mf":
                continue
            f = facts[step][model]
            f.update(gaps(s_mf, r_mf, s_m, r_m))
            for lev in LEVELS:
                a, b = f[f"s{int(lev * 100)}_m"], facts[step]["mf"][f"s{int(lev * 100)}_m"]
                f[f"gap_s{int(lev * 100)}_m"] = None if a is None or b is None else a - b
    df = pd.concat(frames, ignore_index=True)
    if not np.isfinite(df[["s", "force", "ratio"]].to_numpy()).all():
        raise RunError("a response is not finite; nothing was written")
    table = _distance_table(facts)
    side = d.mf
    lines = [f"{step} step, {m}: 63 % at {_m(f['s63_m'])}, 95 % at {_m(f['s95_m'])} (settled {_m(f['s95_settled_m'])})"
             for step in STEPS for m, f in facts[step].items()]
    return StudyResult(
        study="relaxation", config=plan_.config, parameter_sets=dict(plan_.sets),
        data={"relaxation": df, "relaxation_distances": table},
        meta={"title": c["title"] or "Relaxation: the transient Magic Formula, MCPS and LuGre after a slip step",
              "scenario": {"fz_N": fz, "speed_m_per_s": V, "kappa": c["kappa"], "alpha_rad": c["alpha"],
                           "distance_m": dist, "start": "free rolling (every state at rest), step of the slip at t = 0, "
                                                        "held; Vx constant; no yaw",
                           "distance": "s = Vx t, the distance rolled by the wheel centre"},
              "mf": {**side.record(), "sigma_rule": d.rule, "sigma_note": d.rule_note,
                     "settings": "transient: first-order lag of the slips (docs/models/magic_formula_tyre.md §18), "
                                 "camber 0, input limits on, low-speed rules off, the run's speed, pressure INFLPRES"},
              "assumed": ["slip step from free rolling at constant speed and load (docs/models/magic_formula_tyre.md §18.1)"],
              "signs": "force: Fx (kappa step) or Fy (alpha step), road on tire, ISO-W; ratio = (F - F_start)/(F_steady - "
                       "F_start); slip_state: the transient Magic Formula's kappa' [-] or alpha' [rad]",
              "facts": facts, "summary": lines},
        figures=c["figures"] or ["relaxation-compare"],
        payload={"mf_steps": mf, "mcps_alpha": sub, "params": d.mcps, "lugre": lp, "transient": d.transient},
    )


def _m(v) -> str:
    return "not reached" if v is None else f"{v:.4g} m"


def _distance_table(facts):
    import pandas as pd

    rows = []
    for step in STEPS:
        for model, f in facts[step].items():
            rows.append({"step": step, "model": model, "steady_N": f["steady_N"], "start_N": f["start_N"],
                         **{k: f.get(k) for k in ("s63_m", "s95_m", "s63_settled_m", "s95_settled_m", "peak_ratio",
                                                  "gap_s63_m", "gap_s95_m", "gap_max", "gap_at_m", "gap_rms")},
                         "sigma_m": f.get("sigma_m")})
    return pd.DataFrame(rows)


def summary(result) -> list[str]:
    return [f"  {line}" for line in result.meta.get("summary", [])]


FACT_UNITS = {"steady_N": "N", "start_N": "N", "s63_m": "m", "s95_m": "m", "s63_settled_m": "m", "s95_settled_m": "m",
              "peak_ratio": "-", "sigma_m": "m", "s63_exact_m": "m", "s95_exact_m": "m", "state_s63_m": "m",
              "state_s95_m": "m", "transit_m": "m", "start_ratio": "-", "gap_max": "-", "gap_at_m": "m", "gap_rms": "-",
              "gap_s63_m": "m", "gap_s95_m": "m"}

STUDY = register(Study(
    name="relaxation", command="simulate", spec=SCHEMA, plan=plan, run=run, figures=("relaxation-compare",),
    checks={"relaxation-compare": Lazy("tirecli.studies.checks.relaxation", "relaxation_checks")},
    fact_units=FACT_UNITS, summary=summary, primary_frame="relaxation",
))

__all__ = ["STUDY", "SCHEMA", "plan", "run", "distances", "gaps", "LEVELS"]
