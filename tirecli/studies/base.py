"""What every study shares: its result, reference checks, the study registry, built-in configs.

A *study* turns a checked config into a :class:`StudyResult` (data frames, parameter sets,
metadata). Commands (``tirecli sweep``, ``simulate``, ...) run one study; ``tirecli report``
runs the built-in study of every registered figure. Studies never write files and never plot.
"""
from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field
from importlib import resources
from typing import Any, Callable

from tirecli.config.budget import run_spec
from tirecli.config.loader import Config, config_from_text
from tirecli.config.schema import Context, Str
from tirecli.errors import ConfigError, token
from tirecli.io.yamlio import require_kind
from tirecli.limits import MAX_TITLE_CHARS

from tirecli.parameters.sets import ParameterSet


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
        Group name (``tire``, ``vehicle`` ...) -> resolved :class:`ParameterSet`.
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


StudyFn = Callable[..., StudyResult]

STUDIES: dict[str, StudyFn] = {}
CHECKERS: dict[str, Callable] = {}
#: The schema of each study's config (where it has one), for the units of its keys.
SPECS: dict[str, Any] = {}

#: The module that registers each study (imported on demand: a command loads only its own).
STUDY_MODULES: dict[str, str] = {
    "sweep": "tirecli.studies.sweep",
    "simulate": "tirecli.studies.simulate",
    "fit": "tirecli.studies.fit",
    "observe": "tirecli.studies.observe",
    "mf-golden": "tirecli.studies.mf_golden",
    "mcps-stationary": "tirecli.studies.mcps",
    "mcps-slider": "tirecli.studies.mcps",
    "mcps-standstill": "tirecli.studies.mcps",
    "mcps-relaxation": "tirecli.studies.mcps",
    "mf-eval": "tirecli.studies.mf_eval",
}

#: The studies each run command accepts (a command runs the studies of its name unless listed here).
COMMAND_STUDIES: dict[str, tuple] = {
    "simulate": ("simulate", "mcps-slider", "mcps-standstill", "mcps-relaxation"),
    "compare": ("mcps-stationary",),
}


def command_of(study: str) -> str:
    """The ``tirecli`` command that runs ``study``."""
    if study == "mf-golden":
        return "report"  # the golden-data cards have no command of their own
    if study == "mf-eval":
        return "campaign"  # the base of a campaign (tirecli mf eval reads CSVs)
    for command, studies in COMMAND_STUDIES.items():
        if study in studies:
            return command
    return study


def load_study(name: str) -> None:
    """Import the module registering study ``name`` (one of :data:`STUDY_MODULES`)."""
    import importlib

    if name not in STUDIES:
        importlib.import_module(STUDY_MODULES[name])


def load_all_studies() -> dict[str, StudyFn]:
    """Import every study module; returns :data:`STUDIES`."""
    for name in STUDY_MODULES:
        load_study(name)
    return STUDIES


def register_study(name: str, check: Callable | None = None, spec=None):
    """Decorator: register ``fn(config, progress=None) -> StudyResult`` under ``name``.

    ``check(config)`` validates a config completely without running it (``params validate``);
    ``spec`` is the config's schema (:class:`~tirecli.config.schema.Map`), if the study has one.
    """

    def deco(fn: StudyFn) -> StudyFn:
        STUDIES[name] = fn
        if check is not None:
            CHECKERS[name] = check
        if spec is not None:
            SPECS[name] = spec
        return fn

    return deco


def study_name(config: Config, expected: str | None = None) -> str:
    """The ``study:`` of a config (checked against ``expected`` when the command implies one)."""
    raw = config.data.get("study", expected)
    require_kind(config.data, config.origins, "a study config", {"study", *common_fields(), "tire", "vehicle", str(expected)},
                 "a config key (study, title, tire, figures, ...)", also="no 'study' key, and ")
    if raw is None:
        raise ConfigError(config.origins.problem((), f"missing required key 'study' (one of: {', '.join(sorted(STUDY_MODULES))})"))
    ctx = Context(config.origins)
    name = Str(choices=tuple(sorted(STUDY_MODULES))).check(raw, ("study",), ctx)
    ctx.raise_if_any()
    if expected is not None and name not in COMMAND_STUDIES.get(expected, (expected,)):
        raise ConfigError(config.origins.problem(("study",), f"this config is for 'tirecli {command_of(name)}', not 'tirecli {expected}'"))
    return name


def run_study(config: Config, expected: str | None = None, progress=None) -> StudyResult:
    """Run the study a config names (importing its module first)."""
    name = study_name(config, expected)
    load_study(name)
    with _formulas_located(config):
        return STUDIES[name](config, progress=progress)


def check_study(config: Config) -> str:
    """Validate a config without running it; returns the study name."""
    name = study_name(config)
    load_study(name)
    with _formulas_located(config):
        CHECKERS[name](config)
    return name


@contextlib.contextmanager
def _formulas_located(config: Config):
    """A formula of the config that fails while the study plans or runs (it switches too often over the
    run, or gives inf at some time) is reported at its key, with its file and line."""
    from tirecli.models.profiles import FormulaError, formula_path

    try:
        yield
    except FormulaError as exc:
        path = formula_path(config.data, exc.formula)
        if path is None:  # e.g. a formula of another config (fit data simulated by a config)
            raise
        raise ConfigError(config.origins.problem(path, exc.reason)) from None


def builtin_config_names() -> list[str]:
    """Names of the built-in study configs (package data, used by the report)."""
    root = resources.files("tirecli.studies").joinpath("configs")
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml"))


def builtin_config(name: str, overrides=()) -> Config:
    """A built-in study config by name."""
    res = resources.files("tirecli.studies").joinpath("configs").joinpath(name + ".yaml")
    if not res.is_file():
        raise ConfigError(_problem(f"no built-in study config {token(name)} (available: {', '.join(builtin_config_names())})"))
    return config_from_text(res.read_text(encoding="utf-8"), label=f"<built-in {name}>", overrides=overrides)


def _problem(msg: str):
    from tirecli.errors import Problem

    return Problem("<built-in configs>", None, "", msg)


#: Looks up a figure id a config names (:class:`FigureId`): returns for a registered figure, raises
#: UsageError ("unknown figure 'x'; did you mean 'y'? (see ...)") for any other. The figure registry is a
#: layer above the studies, so the application layer, which draws the figures, installs its lookup
#: (:func:`tirecli.figures.registry.get`) before it checks a config; while none is installed, figure
#: ids are not looked up here (only when the figures are drawn).
FIGURE_LOOKUP: Callable[[str], Any] | None = None


@dataclass
class FigureId(Str):
    """A registered figure id (:data:`FIGURE_LOOKUP`); an unknown one is a config problem at its key and
    line, with a did-you-mean, found before the study runs (also by ``tirecli params validate``)."""

    def check(self, value, path, ctx):
        if not isinstance(value, str):
            return super().check(value, path, ctx)
        from tirecli.config.schema import MISSING
        from tirecli.errors import UsageError

        if FIGURE_LOOKUP is None:
            return value
        try:
            FIGURE_LOOKUP(value)
        except UsageError as err:  # "unknown figure 'x'; did you mean 'y'? (see ...)"
            ctx.fail(path, str(err))
            return MISSING
        return value


def common_fields() -> dict:
    """Top-level keys every study config accepts."""
    from tirecli.config.schema import AnyOf, ListOf

    return {
        "study": Str(doc="study to run"),
        "title": Str(default="", doc="title of the run", max_len=MAX_TITLE_CHARS),
        "description": Str(default="", doc="free description"),
        "figures": ListOf(item=FigureId(), default=None, doc="figure ids to draw (tirecli figures list)"),
        "assumed": AnyOf(options=(Str(), ListOf(item=Str())), default=None,
                         what="a text or a list of texts",
                         doc="scenario values the paper does not print, and why (listed in run.json's assumed)"),
        "run": run_spec(),
    }


__all__ = ["Check", "StudyResult", "register_study", "run_study", "load_study", "load_all_studies", "STUDY_MODULES", "builtin_config", "builtin_config_names",
           "ParameterSet", "STUDIES"]
