"""What every study shares: its result, the reference checks of its figures, the config keys of every study.

A *study* turns a checked config into a :class:`StudyResult` (data frames, parameter sets,
metadata); its registry entry (:mod:`tirecli.studies.study`, :mod:`tirecli.studies.registry`) says
how. Commands (``tirecli sweep``, ``simulate``, ...) run one study; ``tirecli report`` runs the
study config of every registered figure. Studies never write files and never plot.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from tirecli.config.budget import run_spec
from tirecli.config.loader import Config
from tirecli.config.schema import Str
from tirecli.limits import MAX_TITLE_CHARS


@dataclass
class Check:
    """A reference check: a computed value against a reference value within a tolerance.

    Attributes
    ----------
    id : str
        Short identifier (unique within a figure).
    description : str
        What is compared, in words.
    value : float
        Computed value.
    reference : float
        The reference value (docs/models/: computed independently of tirecli, or printed in a paper).
    tolerance : float
        Allowed absolute deviation (in ``unit``).
    unit : str
        Unit of value/reference.
    source : str
        Where the reference comes from (a section of docs/models/, or a paper's table or figure).
    bound : str
        ``abs`` (default): pass when ``|value - reference| <= tolerance``; ``max``: pass when
        ``value <= reference + tolerance`` (an upper bound); ``min``: when ``value >= reference - tolerance``.
    """

    id: str
    description: str
    value: float
    reference: float
    tolerance: float
    unit: str = "-"
    source: str = ""
    bound: str = "abs"

    @property
    def deviation(self) -> float:
        if self.bound == "max":
            return max(self.value - self.reference, 0.0)
        if self.bound == "min":
            return max(self.reference - self.value, 0.0)
        return abs(self.value - self.reference)

    @property
    def passed(self) -> bool:
        return bool(math.isfinite(self.value) and self.deviation <= self.tolerance)

    def record(self) -> dict:
        out = {
            "id": self.id, "description": self.description, "value": self.value,
            "reference": self.reference, "tolerance": self.tolerance, "deviation": self.deviation,
            "unit": self.unit, "source": self.source, "passed": self.passed,
        }
        if self.bound != "abs":
            out["bound"] = self.bound  # the reference is an upper (max) or lower (min) bound
        return out


@dataclass
class StudyResult:
    """The outcome of a study.

    Attributes
    ----------
    study : str
        Study name (``sweep``, ``simulate``, ...).
    config : Config
        The config it ran from.
    parameter_sets : dict
        Group name (``tire``, ``vehicle`` ...) -> resolved :class:`~tirecli.parameters.sets.ParameterSet`.
    data : dict
        Name -> pandas DataFrame, written as ``data/NAME.csv``.
    meta : dict
        Study-specific facts for ``run.json`` (events, metrics, profiles, variants).
    figures : list
        Registry ids of the figures drawn from this result by default.
    payload : Any
        Arrays or objects the figure functions need beyond the frames.
    synthetic : bool
        True when the result contains synthetic "measured" data (labelled everywhere).
    files : dict
        Extra text files of the run, name -> text (e.g. a fitted parameter set), written
        into the output directory.
    """

    study: str
    config: Config
    parameter_sets: dict
    data: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)
    figures: list = field(default_factory=list)
    payload: Any = None
    synthetic: bool = False
    files: dict = field(default_factory=dict)

    def citations(self) -> list[str]:
        return [ps.citation for ps in self.parameter_sets.values() if ps.citation]

    def parameter_records(self) -> dict:
        return {k: ps.record() for k, ps in self.parameter_sets.items()}


def common_fields() -> dict:
    """Top-level keys every study config accepts."""
    from tirecli.config.schema import AnyOf, ListOf

    return {
        "study": Str(doc="study to run"),
        "title": Str(default="", doc="title of the run", max_len=MAX_TITLE_CHARS),
        "description": Str(default="", doc="free description"),
        # the ids are looked up in the figure registry by the application layer (a layer above), which
        # reports an unknown one at its key and line with the config's other problems
        "figures": ListOf(item=Str(), default=None, doc="figure ids to draw (tirecli figures list)"),
        "assumed": AnyOf(options=(Str(), ListOf(item=Str())), default=None,
                         what="a text or a list of texts",
                         doc="scenario values the paper does not print, and why (listed in run.json's assumed)"),
        "run": run_spec(),
    }


__all__ = ["Check", "StudyResult", "common_fields"]
