"""The shape of a study: one registry entry (:class:`Study`) and one plan type (:class:`Plan`).

A study turns a config into a :class:`~tirecli.studies.base.StudyResult` in two steps: ``plan(config)``
checks the config completely and estimates the run's size against the sample budget (no heavy work),
``run(plan, progress)`` does the work. The entry carries everything else the tool needs of the study:
its command, config schema, default figures, the reference checks of its figures, its facts (with
units) for campaigns and ``run.json``, the lines the CLI prints after a run, its primary frame, an
optional fast campaign path, and what the report needs. The CLI, the report and campaigns use only
the entry (:mod:`tirecli.studies.registry`); ``docs/development.md`` walks through adding one.
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Callable, Mapping

from tirecli.studies.facts import meta_facts

if TYPE_CHECKING:
    from tirecli.config.loader import Config
    from tirecli.config.schema import Map
    from tirecli.limits import Estimate
    from tirecli.studies.base import StudyResult


@dataclass
class Plan:
    """A study config checked completely and sized, ready to run.

    Attributes
    ----------
    study : str
        The study's name (its registry entry).
    config : Config
        The config it was planned from.
    checked : dict
        The document checked against the study's schema (defaults filled in).
    sets : dict
        Group name (``tire``, ``vehicle``, ...) -> resolved :class:`~tirecli.parameters.sets.ParameterSet`.
    estimate : Estimate or None
        The samples and memory of the run, already checked against the budget in force (None when
        the size is known only once the run reads its data).
    detail : Any
        What else the study's ``run`` needs (cases, solver options, model objects), study-specific.
    """

    study: str
    config: Config
    checked: dict
    sets: dict = field(default_factory=dict)
    estimate: Estimate | None = None
    detail: Any = None


@dataclass(frozen=True)
class Line:
    """A line the CLI prints after a run: ``result`` lines always (stdout), ``note`` lines unless
    ``--quiet`` (stdout), ``warning`` lines on stderr (``warning: TEXT``)."""

    text: str
    kind: str = "result"

    def __post_init__(self):
        if self.kind not in ("result", "note", "warning"):
            raise ValueError(f"line kind {self.kind!r}: expected result, note or warning")


@dataclass(frozen=True)
class Lazy:
    """A function named by its module and name, imported on its first call (with ``args`` first).

    A study entry lists its figures' reference checks as ``Lazy("tirecli.studies.checks.steady",
    "fig1_left")``: the entry stays cheap to import, and a run imports the check code of the figures
    it draws only."""

    module: str
    name: str
    args: tuple = ()

    def resolve(self) -> Callable:
        return getattr(importlib.import_module(self.module), self.name)

    def __call__(self, *args, **kwargs):
        return self.resolve()(*self.args, *args, **kwargs)


def no_summary(result: StudyResult) -> list:
    """A study without lines of its own after a run."""
    return []


@dataclass(frozen=True, eq=False)
class Study:
    """One study: a registry entry (:func:`tirecli.studies.registry.register`).

    Attributes
    ----------
    name : str
        The config's ``study:`` (``sweep``, ``simulate``, ``mcps-stationary``, ...).
    command : str
        The ``tirecli`` command that runs it (``sweep``, ``simulate``, ``compare``, ``report`` for
        studies only the report runs, ``campaign`` for a campaign's base study).
    spec : Map
        The config schema (:mod:`tirecli.config.schema`): checks the document and gives the units of
        its keys (campaign columns).
    plan : callable
        ``plan(config) -> Plan``: check completely and size the run (ConfigError with every problem
        at its key and line); no heavy work.
    run : callable
        ``run(plan, progress) -> StudyResult`` (``progress``: None or a reporter with
        ``start(total, label)``, ``advance(n)``, ``close()``).
    figures : tuple of str
        The figures a run draws when its config lists none (the result says which for each run).
    checks : mapping
        Figure id -> ``checks(result) -> list[Check]``: the reference checks of the figures this study
        draws (a key ending in ``*`` covers every id with that prefix). Checks run for the figures a
        config asks for by name.
    facts : callable
        ``facts(result) -> dict``: flat scalar facts by name (``NAME[LABEL]`` per case), for campaigns
        and the public API (default: ``meta["facts"]`` flattened, :func:`tirecli.studies.facts.meta_facts`).
    fact_units : mapping or None
        Unit of each fact (by the name before ``[``); None: from a unit suffix of the name
        (:func:`tirecli.studies.facts.fact_unit`).
    summary : callable
        ``summary(result) -> list[str | Line]``: the lines the CLI prints after a run (a ``str`` is a
        result line).
    primary_frame : str or None
        The frame a campaign keeps per point (``keep: timeseries``); None: the result's first frame.
    point : callable or None
        A fast campaign path ``point(plan, wanted, keep) -> (facts, frame or None)``: the facts named in
        ``wanted`` (None: all) without the work the others need, and the primary frame when ``keep``.
    group : str or None
        The report's worker group: the studies of one group run in one process, in order (they share
        the runs they keep, :func:`tirecli.numerics.runs.quarter_car`); None: a group of its own.
    files : tuple of str
        Extra files a run may write into its output directory (``fitted.yaml``), from ``result.files``.
    """

    name: str
    command: str
    spec: Map
    plan: Callable[[Config], Plan]
    run: Callable[[Plan, Any], StudyResult]
    figures: tuple = ()
    checks: Mapping[str, Callable] = field(default_factory=dict)
    facts: Callable[[StudyResult], dict] = meta_facts
    fact_units: Mapping[str, str] | None = None
    summary: Callable[[StudyResult], list] = no_summary
    primary_frame: str | None = None
    point: Callable | None = None
    group: str | None = None
    files: tuple = ()

    def __repr__(self) -> str:
        return f"Study({self.name!r}, command={self.command!r})"

    def checks_for(self, figure_id: str) -> Callable | None:
        """The reference checks of figure ``figure_id`` (None when it has none)."""
        fn = self.checks.get(figure_id)
        if fn is not None:
            return fn
        for key, fn in self.checks.items():
            if key.endswith("*") and figure_id.startswith(key[:-1]):
                return fn
        return None

    def lines(self, result: StudyResult) -> list[Line]:
        """The summary of a result as :class:`Line` objects."""
        return [x if isinstance(x, Line) else Line(str(x)) for x in self.summary(result)]


__all__ = ["Study", "Plan", "Line", "Lazy", "no_summary"]
