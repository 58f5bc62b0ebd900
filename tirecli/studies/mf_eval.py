"""The Magic Formula at a few operating points, from a config: the ``mf eval`` of a campaign.

``tirecli mf eval TIRE --points P.csv`` evaluates a tyre at the rows of a CSV; this study does the
same for points written in a config, so that a campaign (``tirecli campaign``) can vary the tyre's
coefficients and the operating point like any other key::

    study: mf-eval
    tire: pacejka2006-205-60r15          # a built-in tyre, a .tir path, or {set: ..., LMUY: 0.9}
    convention: mfeval                   # or teasit (docs/models/magic_formula_tyre.md §10)
    side: null                           # optional mount side (mirroring)
    limits: true                         # input clipping and low-speed rules (§11)
    points:                              # numbers, or lists of equal length (one point per item)
      kappa: 0                           # [-] ISO-W
      alpha: 0.04                        # [rad]
      gamma: 0                           # [rad] (default 0)
      fz: 4000                           # [N]
      # p [Pa] (default INFLPRES, else NOMPRES) and vx [m/s] (default LONGVL)

Frame ``points``: ``kappa, alpha, gamma, fz, p, vx, fx, fy, mz, mx, my`` (ISO-W, SI), then mfeval's
further outputs the tyre gives (``sigmax, sigmay, Kxk, Kya, Cx, Cy, Cz, re, a, b``; the others are listed
under ``meta["omitted"]``), evaluated as ``tirecli mf eval`` does (:mod:`tirecli.studies.mf_points`).
Facts (``meta["facts"]``): every output at a single point (``fx``, ``fy``, ...), ``fx[i]`` ... at point
``i`` of several. Its command is ``tirecli campaign`` (a base study); ``tirecli mf eval`` reads CSVs.
"""
from __future__ import annotations

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Bool, ListOf, Map, Num, Raw, Str, collect
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mf_points import OUTPUT_COLUMNS as OUTPUTS
from tirecli.studies.mf_points import EXTRA_COLUMNS, UNITS, PointError, evaluate_points, needs_speed
from tirecli.studies.registry import register
from tirecli.studies.study import Plan, Study


def _values(unit, doc, default=..., **bounds):
    num = Num(unit=unit, **bounds)
    spec = ListOf(item=num, doc=doc)
    if default is not ...:
        spec.default = default
    return spec


POINTS = Map(fields={
    "kappa": _values("-", "longitudinal slip (ISO-W, > 0 driving)", ge=-1.0, le=10.0),
    "alpha": _values("rad", "slip angle", ge=-1.5, le=1.5),
    "gamma": _values("rad", "camber angle", [0.0], ge=-0.5, le=0.5),
    "fz": _values("N", "vertical load", gt=0),
    "p": _values("Pa", "inflation pressure (default INFLPRES, else NOMPRES)", None, gt=0),
    "vx": _values("m/s", "forward speed (default LONGVL)", None),
})

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="magic_formula", doc="Magic Formula tyre: a built-in name, a .tir path, or {set: ..., overrides}"),
    "convention": Str(choices=("mfeval", "teasit"), default="mfeval", doc="variant of docs/models/magic_formula_tyre.md §10"),
    "side": Str(choices=("left", "right"), default=None, doc="mount side (mirroring)"),
    "limits": Bool(default=True, doc="input clipping and low-speed rules"),
    "points": POINTS,
})


def plan(config: Config) -> Plan:
    """Check an mf-eval config completely (set ``tire``; detail ``(MFTire, {column: array})``, the points
    broadcast to one length)."""
    from tirecli.errors import ConfigError
    from tirecli.parameters.sets import resolve_tire

    checked, tire = collect(lambda: config.checked(SPEC),
                            lambda: resolve_tire(config.data.get("tire"), config.origins, ("tire",), config.base_dir))
    ps, t = tire
    pts = checked["points"]
    given = {k: v for k, v in pts.items() if v is not None}
    n = max(len(v) for v in given.values())
    problems = [config.origins.problem(("points", k), f"expected one value or {n} (as many as the longest list), got {len(v)}")
                for k, v in given.items() if len(v) not in (1, n)]
    if needs_speed(t, pts["vx"]):
        problems.append(config.origins.problem(("points",), "no vx and the tyre has no LONGVL to default to"))
    if problems:
        raise ConfigError(problems)
    cols = {k: np.broadcast_to(np.asarray(v, dtype=float), (n,)).copy() for k, v in given.items()}
    return Plan("mf-eval", config, checked, {"tire": ps}, None, (t, cols))


def _evaluate(plan_: Plan, extras: bool = True):
    """The outputs at the plan's points (:func:`~tirecli.studies.mf_points.evaluate_points`); a non-finite
    one is the config's problem at ``points`` (an input beyond the tyre) or a RunError."""
    from tirecli.errors import ConfigError, RunError

    checked, (t, cols) = plan_.checked, plan_.detail
    try:
        return evaluate_points(t, cols, convention=checked["convention"], side=checked["side"],
                               limits=checked["limits"], extras=extras)
    except PointError as err:  # never an empty cell: the point, its inputs and why
        text = f"point {err.index}: {err.text}; nothing was written"
        if err.at_fault:
            raise ConfigError(plan_.config.origins.problem(("points",), text)) from None
        raise RunError(f"{plan_.config.label}: {text}") from None


def _facts(outputs: dict, n: int) -> dict:
    """Every output at a single point by its name, ``NAME[i]`` at point ``i`` of several."""
    facts = {}
    for k, v in outputs.items():
        vals = np.asarray(v, dtype=float)
        if n == 1:
            facts[k] = float(vals.ravel()[0])
        else:
            facts.update({f"{k}[{i}]": float(x) for i, x in enumerate(vals)})
    return facts


def run(plan_: Plan, progress=None) -> StudyResult:
    """Evaluate the tyre at the config's points (see module doc)."""
    import pandas as pd

    config, checked, ps = plan_.config, plan_.checked, plan_.sets["tire"]
    cols = plan_.detail[1]
    ev = _evaluate(plan_)
    n = cols["fz"].size
    res = ev.result
    frame = pd.DataFrame({"kappa": cols["kappa"], "alpha": cols["alpha"], "gamma": cols["gamma"], "fz": cols["fz"],
                          "p": _column(ev.p, n), "vx": _column(ev.vx, n),
                          **{k: np.asarray(v, dtype=float) for k, v in ev.outputs().items()}})
    meta = {"title": checked["title"] or f"Magic Formula at {n} point(s): {ps.name}", "convention": res.convention,
            "limits": checked["limits"], "input_rules": {k: v for k, v in res.counts.items() if v},
            "facts": _facts(ev.outputs(), n)}
    if ev.omitted:
        meta["omitted"] = ev.omitted
    return StudyResult(study="mf-eval", config=config, parameter_sets={"tire": ps}, data={"points": frame}, meta=meta,
                       figures=[])


def point(plan_: Plan, wanted=None, keep: bool = False):
    """A campaign's point: the facts ``wanted`` without a frame (the extra outputs only when one is wanted),
    or the whole run with ``keep``: ``(facts, frame or None)``."""
    if keep:
        result = run(plan_)
        return result.meta["facts"], result.data["points"]
    extras = wanted is None or any(w.split("[", 1)[0] in EXTRA_COLUMNS for w in wanted)
    return _facts(_evaluate(plan_, extras).outputs(), plan_.detail[1]["fz"].size), None


def _column(x, n: int) -> np.ndarray:
    """A point column as ``n`` values: the points' own, the default for all, or NaN (none)."""
    if x is None:
        return np.full(n, np.nan)
    return np.broadcast_to(np.asarray(x, dtype=float), (n,)).copy()


STUDY = register(Study(
    name="mf-eval", command="campaign", spec=SPEC, plan=plan, run=run,  # a campaign's base (mf eval reads CSVs)
    fact_units=UNITS, point=point,
))

__all__ = ["STUDY", "SPEC", "plan", "run", "OUTPUTS"]
