"""``mcps-relaxation`` (``tirecli simulate``): the side force building up after a slip-angle step."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import AnyOf, Bool, ListOf, Map, Num, Raw, Str, collect
from tirecli.errors import ConfigError, RunError, token
from tirecli.limits import MAX_TITLE_CHARS, Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mcps.common import (BYTES_PER_ROW, CARCASSES, DEG, MAX_ELEMENT_STEPS, meta_summary,
                                         tire_set)
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

LOCKABLE = ("x", "y", "delta")
CASE = AnyOf(options=(
    Str(choices=CARCASSES),
    Map(fields={
        "carcass": Str(choices=CARCASSES, doc="complete or rigid"),
        "locked": ListOf(item=Str(choices=LOCKABLE), min_len=0, max_len=3, default=[], doc="belt DOFs held at 0"),
        "label": Str(default="", doc="name in legends and CSV", max_len=MAX_TITLE_CHARS),
    }),
), what="complete, rigid, or {carcass, locked: [x, y, delta], label}")

RELAXATION = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="vertical load"),
    "alpha": Num(unit="rad", ge=-1.5, le=1.5, default=1.0 * DEG, doc="slip angle after the step (not 0)"),
    "speed": Num(unit="m/s", gt=0, le=200, default=20.0, doc="forward speed Vx = r omega"),
    "carcass": AnyOf(options=(CASE, ListOf(item=CASE, max_len=8)), default="complete",
                     what="a carcass case or a list of them"),
    "distance": Num(unit="m", gt=0, le=1000, default=4.0, doc="rolled distance to simulate"),
    "cells": Num(unit="-", integer=True, ge=10, le=20_000, default=100,
                 doc="patch cells (raised automatically at low speed to resolve the belt)"),
    "frame_term": Bool(default=True, doc="rotate the element states with the belt twist (docs/models/mcps_tire.md §4: on)"),
})


@dataclass
class RelaxCase:
    label: str
    carcass: str
    locked: tuple


@dataclass
class Relaxation:
    """The detail of an ``mcps-relaxation`` plan: the MCPS parameters and the cases."""

    params: object
    cases: list


def plan(config: Config) -> Plan:
    """Check an ``mcps-relaxation`` config completely (set ``tire``; detail :class:`Relaxation`)."""
    checked, ps = collect(lambda: config.checked(RELAXATION), lambda: tire_set(config))
    if checked["alpha"] == 0:
        raise ConfigError(config.origins.problem(("alpha",), "must not be 0: the relaxation is the build-up of the "
                                                             "side force after a slip-angle step"))
    raw = checked["carcass"]
    items = raw if isinstance(raw, list) else [raw]
    cases = []
    for it in items:
        if isinstance(it, str):
            cases.append(RelaxCase(it, it, ()))
        else:
            locked = tuple(sorted({LOCKABLE.index(x) for x in it["locked"]}))
            if it["carcass"] == "rigid" and locked:
                raise ConfigError(config.origins.problem(("carcass",), "'locked' applies to the complete carcass only"))
            label = it["label"] or (it["carcass"] + ("" if not locked else ", " + "+".join(LOCKABLE[j] for j in locked) + " locked"))
            cases.append(RelaxCase(label, it["carcass"], locked))
    labels = [c.label for c in cases]
    if len(set(labels)) != len(labels):
        raise ConfigError(config.origins.problem(("carcass",), "two cases share a label; give each a distinct 'label'"))
    p = ps.model()
    est = Estimate()
    cap = compute_cap(MAX_ELEMENT_STEPS)
    for c in cases:
        n = _cells(p, checked, c)
        steps = checked["distance"] / (p.patch(checked["fz"]).l / n)
        est.add(steps + 1, (("distance",), ("cells",), ("speed",)), f"data/relaxation.csv (case {c.label!r}: "
                f"{steps:,.0f} steps of {n} cells)", BYTES_PER_ROW)
        if n * steps > cap:
            raise ConfigError(config.origins.problem((), f"case {token(c.label)}: the run needs {n} cells x {steps:.3g} steps "
                                                         f"(speed {checked['speed']:g} m/s, distance {checked['distance']:g} m), "
                                                         f"over the budget of {cap:.0e} element-steps (short "
                                                         "relaxation lengths at large slip angles and the belt's fast modes at "
                                                         "low speed need small steps): shorten 'distance' or raise 'speed' " + cap_hint()))
    est.check(config.origins)
    return Plan("mcps-relaxation", config, checked, {"tire": ps}, est, Relaxation(p, cases))


def _cells(p, checked, case) -> int:
    """Patch cells of a case (:func:`tirecli.numerics.mcps_transient.cells_needed`)."""
    from tirecli.numerics.mcps_transient import cells_needed

    return cells_needed(p, checked["fz"], checked["speed"], checked["cells"], case.carcass, case.locked,
                        slip=(0.0, math.tan(checked["alpha"])))


def crossings(s, ratio, level):
    """First and last rolled distance [m] where ``ratio`` rises through ``level`` (linear between
    samples); None when never reached."""
    above = ratio >= level
    idx = np.flatnonzero(~above[:-1] & above[1:])
    if idx.size == 0:
        return None, None

    def at(i):
        r0, r1 = ratio[i], ratio[i + 1]
        return float(s[i] + (level - r0) * (s[i + 1] - s[i]) / (r1 - r0))

    return at(idx[0]), at(idx[-1])


def run(plan_: Plan, progress=None) -> StudyResult:
    """Force build-up after a slip-angle step at constant speed (docs/models/mcps_tire.md §7, scenario assumed)."""
    from tirecli.numerics.mcps_stationary import solve
    from tirecli.numerics.mcps_transient import simulate_rolling

    import pandas as pd  # once the config is checked: a refused run fails at once

    config, checked, ps = plan_.config, plan_.checked, plan_.sets["tire"]
    p, cases = plan_.detail.params, plan_.detail.cases

    fz, a, V, dist = checked["fz"], checked["alpha"], checked["speed"], checked["distance"]
    frames, facts = [], {}
    sti = p.stiffnesses(fz)
    pa = p.patch(fz)
    for c in cases:
        n = _cells(p, checked, c)
        st = solve(p, fz, [0.0], [a], [0.0], carcass=c.carcass, locked=c.locked)
        if not st.converged.all():
            raise RunError(f"case {token(c.label)}: the stationary fixed point (MCPS eq. 18) did not converge at alpha = {a:g} "
                           "rad; nothing was written")
        fy_inf, mz_inf = float(st.fy[0]), float(st.mz[0])
        run = simulate_rolling(p, fz, V, V * math.tan(a), V, 0.0, dist, cells=n, carcass=c.carcass, locked=c.locked,
                               frame_term=checked["frame_term"], progress=progress)
        ratio = run.fy / fy_inf
        frames.append(pd.DataFrame({"case": c.label, "carcass": c.carcass, "s": run.s, "t": run.t, "fy": run.fy,
                                    "mz": run.mz, "fx": run.fx, "ratio": ratio, "x": run.x, "y": run.y,
                                    "delta": run.delta, "rim_fy": run.rim_fy}))
        f = {"fy_inf_N": fy_inf, "mz_inf_Nm": mz_inf, "cells": n, "step_m": pa.l / n,
             "final_fy_minus_fy_inf_N": float(run.fy[-1] - fy_inf)}
        for lev in (0.63, 0.95, 0.99):
            first, last_ = crossings(run.s, ratio, lev)
            f[f"s{int(round(lev * 100))}_first_m"] = first
            f[f"s{int(round(lev * 100))}_last_m"] = last_
        f["monotone"] = bool(np.all(np.diff(np.abs(run.fy)) >= -1e-3 * abs(fy_inf)))  # no dip above 0.1 % of Fy_inf
        f["lag_integral_m"] = float(np.trapezoid(1.0 - ratio, run.s))
        if c.carcass == "complete" and not c.locked:
            e = sti["D_zalpha"] / p.k_delta
            f["lag_integral_linear_theory_m"] = float(pa.l / 3.0 - sti["D_yphi"] / sti["D_yalpha"] * e + (
                sti["D_yalpha"] / p.k_y - e * (pa.l / 2.0 + p.c_delta * V / p.k_delta + sti["D_zphi"] / p.k_delta)) / (1.0 + e))
        facts[c.label] = f
    df = pd.concat(frames, ignore_index=True)
    if not np.isfinite(df[["fy", "mz", "fx"]].to_numpy()).all():
        raise RunError("the rolling run produced non-finite forces; nothing was written")
    lines = []
    for lab, f in facts.items():
        d = ", ".join(f"{k[1:3]} % at {f[k]:.4g} m" if f[k] is not None else f"{k[1:3]} % not reached"
                      for k in ("s63_first_m", "s95_first_m", "s99_first_m"))
        extra = "" if f["monotone"] else f" (not monotone: last 95 % crossing at {f['s95_last_m']:.4g} m)" \
            if f["s95_last_m"] is not None else " (not monotone)"
        lines.append(f"{lab}: Fy -> {f['fy_inf_N']:.5g} N; first crossings {d}{extra}")
    return StudyResult(
        study="mcps-relaxation", config=config, parameter_sets={"tire": ps}, data={"relaxation": df},
        meta={"title": checked["title"] or "MCPS relaxation: side-force build-up after a slip-angle step",
              "scenario": {"alpha_rad": a, "speed_m_per_s": V, "distance_m": dist, "fz_N": fz,
                           "start": "free rolling (element states and belt at rest), step of Vy = Vx tan(alpha) at t = 0; "
                                    "Vx = r omega constant; no yaw",
                           "frame_term": checked["frame_term"],
                           "numerics": "Lagrangian tread elements (CFL = 1), exact per-component element steps, "
                                       "trapezoidal belt with a predictor-corrector coupling"},
              "assumed": ["slip-angle step from free rolling at constant speed (the paper shows no relaxation "
                          "run; docs/models/mcps_tire.md §7)"],
              "signs": "fy, mz, fx: road on tire in R_W about the rim centre (ISO-W, eq. 16); ratio = fy/fy_inf; "
                       "rim_fy = k_y y + c_y ydot, the force the belt puts on the rim",
              "cases": [{"label": c.label, "carcass": c.carcass, "locked": [LOCKABLE[j] for j in c.locked]} for c in cases],
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-relaxation"],
        payload={"params": p, "cases": cases},
    )


STUDY = register(Study(
    name="mcps-relaxation", command="simulate", spec=RELAXATION, plan=plan, run=run, figures=("mcps-relaxation",),
    checks={"mcps-relaxation": Lazy("tirecli.studies.checks.mcps", "relaxation_checks")}, summary=meta_summary,
))

__all__ = ["STUDY", "RELAXATION", "plan", "run", "RelaxCase", "crossings"]
