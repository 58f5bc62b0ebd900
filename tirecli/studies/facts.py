"""Facts of a study result: flat scalars by name, for campaigns (``outputs:``) and the public API.

A study's facts are ``NAME`` or ``NAME[LABEL]`` (the case ``LABEL`` of a study with several cases; the
plain ``NAME`` too when there is one case), each a float (None -> NaN, booleans -> 0/1) or a text. A
study that keeps its facts under ``meta["facts"]`` gets them flattened (:func:`meta_facts`); others give
their own ``facts`` function (:class:`tirecli.studies.study.Study`).
"""
from __future__ import annotations

import numpy as np

#: Unit suffixes of fact names (``last_period_max_force_N``), longest first: the unit of a fact of a
#: study that lists no units (:func:`fact_unit`).
UNIT_SUFFIXES = (("_Nm_per_rad", "N m/rad"), ("_N_per_m", "N/m"), ("_1_s", "1/s"), ("_Nm", "N m"), ("_N", "N"),
                 ("_rad", "rad"), ("_J", "J"), ("_m", "m"), ("_s", "s"))


def scalar(v):
    """A fact as a float (None -> NaN, booleans -> 0/1) or a text; None for a non-scalar."""
    if v is None:
        return float("nan")
    if isinstance(v, (bool, np.bool_)):
        return float(v)
    if isinstance(v, (int, float, np.integer, np.floating)):
        return float(v)
    if isinstance(v, str):
        return v
    return None


def named(per_case: dict) -> dict:
    """``{LABEL: {NAME: value}}`` -> ``{NAME[LABEL]: value}``, and ``NAME`` alone for a single case."""
    out = {}
    for label, facts in per_case.items():
        out.update({f"{k}[{label}]": v for k, v in facts.items()})
    if len(per_case) == 1:
        out.update(next(iter(per_case.values())))
    return out


def wanted_base(wanted) -> set | None:
    """The base names (``NAME`` of ``NAME[LABEL]``) asked for; None for all."""
    if wanted is None:
        return None
    return {w.split("[", 1)[0] for w in wanted}


def flatten(facts, prefix: str = "") -> dict:
    """Scalar facts of a nested ``meta.facts``: ``{a: 1, b: {x: 2}, rows: [{y: 3}, {y: 4}]}`` ->
    ``{a: 1, x[b]: 2, y[0]: 3, y[1]: 4}`` (``y`` alone when the list has one row)."""
    out = {}
    if isinstance(facts, dict):
        for k, v in facts.items():
            s = scalar(v)
            if s is not None:
                out[f"{k}{prefix}"] = s
            elif isinstance(v, dict):
                out.update(flatten(v, f"[{k}]" if not prefix else f"{prefix[:-1]}, {k}]"))
            elif isinstance(v, list) and v and all(isinstance(r, dict) for r in v):
                if len(v) == 1:
                    out.update(flatten(v[0], prefix))
                else:
                    for i, r in enumerate(v):
                        out.update(flatten(r, f"[{i}]" if not prefix else f"{prefix[:-1]}, {i}]"))
    return out


def meta_facts(result) -> dict:
    """The facts a result keeps under ``meta["facts"]``, flattened (:func:`flatten`)."""
    return flatten(result.meta.get("facts") or {})


def fact_unit(study, name: str) -> str | None:
    """The unit of fact ``name`` (``NAME[LABEL]`` too) of a run of ``study`` (a
    :class:`~tirecli.studies.study.Study`): from its ``fact_units``, else from a unit suffix of the name
    (:data:`UNIT_SUFFIXES`); None when unknown."""
    base = name.split("[", 1)[0]
    if study.fact_units is not None:
        return study.fact_units.get(base)
    return next((unit for suffix, unit in UNIT_SUFFIXES if base.endswith(suffix)), None)


__all__ = ["scalar", "named", "wanted_base", "flatten", "meta_facts", "fact_unit", "UNIT_SUFFIXES"]
