"""Input profiles in a config: their schema (:func:`profile_spec`), the profiles built from checked values
(:func:`profile_from_checked`; a ``csv:`` profile is read by :mod:`tirecli.io.data`), and the check of
profiles over a whole run at their config keys (:func:`profile_problems`).

Config forms::

    torque: 350
    torque: {table: {t: [0, 0.5, 2.0, 2.6], value: [0, 0, 1000, 0]}}
    torque: {initial: 350, changes: [{at: 7, duration: 1, to: -250, shape: half-cosine}]}
    torque: {csv: measured.csv, t: t, value: torque}      # read by tirecli.io.data
    theta: {expr: "1 - 0.4*(t > 5)"}                      # a formula of t

The profiles themselves (pure functions of time) are :mod:`tirecli.models.profiles`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.config.schema import AnyOf, ListOf, Num, Str
from tirecli.config.schema import Map as _Map
from tirecli.errors import UsageError
from tirecli.models.profiles import (SHAPES, Change, Constant, Expression, FormulaError, Limits, Table, Transitions,
                                     check_over_run, expression_problem)


def _post_table(v, path, ctx):
    t, y = v["t"], v["value"]
    if len(t) != len(y):
        ctx.fail(path + ("value",), f"expected as many values as times ({len(t)}), got {len(y)}")
    elif any(b < a for a, b in zip(t, t[1:])):
        ctx.fail(path + ("t",), "times must not decrease")


def _post_transitions(v, path, ctx):
    last = -np.inf
    for i, c in enumerate(v["changes"] or []):
        if c["at"] < last:
            ctx.fail(path + ("changes", i, "at"), f"changes must be in time order (this one starts before {last:g} s)")
        last = c["at"] + (c["duration"] or 0.0)


def _post_expr(v, path, ctx):
    problem = expression_problem(v["expr"])
    if problem is None:  # also evaluate it at the start (later times are checked as the run goes)
        try:
            Expression(v["expr"])(0.0)
        except FormulaError as exc:
            problem = exc.reason
    if problem is not None:
        ctx.fail(path + ("expr",), problem)


def profile_problems(items, origins, t_end: float, dt: float | None = None) -> list:
    """Check input profiles over a whole run: ``items`` are ``(profile, spec, path)`` (``spec`` from
    :func:`profile_spec`, or a :class:`Limits`; ``path`` the config key of the profile). One
    :class:`~tirecli.errors.Problem` per profile that leaves its limits, naming the config line and
    key, the time and the value (each path is checked once)."""
    problems, seen = [], set()
    for prof, spec, path in items:
        path = tuple(path)
        if path in seen or prof is None:
            continue
        seen.add(path)
        lim = spec if isinstance(spec, Limits) or spec is None else getattr(spec, "limits", None)
        try:
            found = check_over_run(prof, lim, t_end, dt)
        except UsageError as exc:  # a formula that cannot be evaluated or switches too often (FormulaError)
            problems.append(origins.problem(path + ("expr",), getattr(exc, "reason", str(exc))))
            continue
        if found is not None:
            sub, msg = found
            problems.append(origins.problem(path + (sub,) if sub in ("expr", "csv") else path, msg))
    return problems


def profile_spec(unit: str, lo: float | None = None, hi: float | None = None, gt: float | None = None):
    """Schema of a profile whose values are in ``unit`` and within the given bounds.

    Each mapping form is recognised by its key (``table``, ``initial``, ``csv``, ``expr``), so a
    problem inside one form is reported as such.
    """
    def Map(fields, post=None):
        key = next(iter(fields))

        class _Keyed(_Map):
            def accepts(self, value):
                return isinstance(value, dict) and key in value

        return _Keyed(fields=fields, post=post)

    val = Num(unit=unit, ge=lo, le=hi, gt=gt)
    time = Num(unit="s", ge=0)
    spec = ProfileSpec(options=(
        val,
        Map(fields={"table": Map(fields={"t": ListOf(item=time, min_len=1), "value": ListOf(item=val, min_len=1)},
                                 post=_post_table)}),
        Map(fields={"initial": val, "changes": ListOf(item=Map(fields={
            "at": time, "to": val,
            "duration": Num(unit="s", ge=0, default=0.0, doc="transition length"),
            "shape": Str(choices=SHAPES, default="half-cosine", doc="transition shape"),
        }), min_len=0, default=[])}, post=_post_transitions),
        Map(fields={"csv": Str(doc="CSV file (relative to the config)"),
                    "t": Str(default="t", doc="time column"), "value": Str(doc="value column")}),
        Map(fields={"expr": Str(doc=f"formula of t [s] giving the value [{unit}]")}, post=_post_expr),
    ), what=f"a number [{unit}], {{table: {{t, value}}}}, {{initial, changes}}, {{csv, t, value}} or {{expr}}",
        limits=Limits(unit, lo, hi, gt))
    return spec


@dataclass
class ProfileSpec(AnyOf):
    """:class:`~tirecli.config.schema.AnyOf` with the profile's :class:`~tirecli.models.profiles.Limits`
    (kept by ``dataclasses.replace``)."""

    limits: object = None


def profile_from_checked(v, base_dir=None, origin=("", None)):
    """Build a profile from a value checked by :func:`profile_spec`."""
    if isinstance(v, (int, float)):
        return Constant(float(v))
    if "table" in v:
        return Table(tuple(v["table"]["t"]), tuple(v["table"]["value"]))
    if "expr" in v:
        return Expression(v["expr"])
    if "initial" in v:
        return Transitions(v["initial"], tuple(Change(c["at"], c["to"], c["duration"], c["shape"])
                                               for c in v["changes"] or []))
    from pathlib import Path

    from tirecli.io.data import read_columns

    path = Path(v["csv"])
    if base_dir is not None and not path.is_absolute():
        path = Path(base_dir) / path
    cols = read_columns(path, [v["t"], v["value"]], increasing=v["t"])
    return Table(tuple(cols[v["t"]]), tuple(cols[v["value"]]), source=str(path), column=v["value"])


__all__ = ["profile_spec", "profile_from_checked", "profile_problems", "ProfileSpec"]
