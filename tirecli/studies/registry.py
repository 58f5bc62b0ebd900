"""The study registry: every study is one :class:`~tirecli.studies.study.Study` entry.

:data:`STUDY_MODULES` names the module of each built-in study; a module registers its entries
(:func:`register`) when imported, and a command imports only the module of its config's study
(start-up time). A study registered at runtime (a plugin, a test) is used like a built-in one.

The CLI, the report and campaigns go through this module only: :func:`plan` checks a config
completely (its ``study:`` against the command that runs it), :func:`run` runs a plan.
"""
from __future__ import annotations

import contextlib
import importlib

from tirecli.config.loader import Config
from tirecli.config.schema import Context, Str
from tirecli.errors import ConfigError
from tirecli.studies.study import Plan, Study

#: The module of each built-in study (imported on demand).
STUDY_MODULES: dict[str, str] = {
    "sweep": "tirecli.studies.sweep",
    "simulate": "tirecli.studies.simulate",
    "fit": "tirecli.studies.fit",
    "observe": "tirecli.studies.observe",
    "mf-golden": "tirecli.studies.mf_golden",
    "mf-eval": "tirecli.studies.mf_eval",
    "mf-fit": "tirecli.studies.mf_fit",
    "mcps-stationary": "tirecli.studies.mcps.stationary",
    "mcps-slider": "tirecli.studies.mcps.slider",
    "mcps-standstill": "tirecli.studies.mcps.standstill",
    "mcps-relaxation": "tirecli.studies.mcps.relaxation",
    "relaxation": "tirecli.studies.relaxation",
}

#: Study name -> entry (filled as study modules are imported, or by :func:`register`).
REGISTRY: dict[str, Study] = {}


def register(study: Study) -> Study:
    """Add ``study`` to the registry (ValueError if another entry has its name); returns it."""
    if not isinstance(study, Study):
        raise TypeError(f"register() takes a Study, not {type(study).__name__}")
    old = REGISTRY.get(study.name)
    if old is not None and old is not study:
        raise ValueError(f"study {study.name!r} registered twice")
    REGISTRY[study.name] = study
    return study


def unregister(name: str) -> None:
    """Remove the entry of study ``name`` (a study registered at runtime)."""
    REGISTRY.pop(name, None)


def names() -> list[str]:
    """The names of every study: built-in and registered."""
    return sorted(set(STUDY_MODULES) | set(REGISTRY))


def get(name: str) -> Study:
    """The entry of study ``name``, importing its module first (KeyError for an unknown name)."""
    if name not in REGISTRY:
        importlib.import_module(STUDY_MODULES[name])
    return REGISTRY[name]


def load_all() -> dict[str, Study]:
    """Import every built-in study module; returns the registry."""
    for name in STUDY_MODULES:
        get(name)
    return REGISTRY


def study_name(config: Config, command: str | None = None) -> str:
    """The ``study:`` of a config, checked against the ``command`` that runs it (when one is given)."""
    from tirecli.io.yamlio import require_kind
    from tirecli.studies.base import common_fields

    raw = config.data.get("study", command)
    require_kind(config.data, config.origins, "a study config", {"study", *common_fields(), "tire", "vehicle", str(command)},
                 "a config key (study, title, tire, figures, ...)", also="no 'study' key, and ")
    if raw is None:
        raise ConfigError(config.origins.problem((), f"missing required key 'study' (one of: {', '.join(names())})"))
    ctx = Context(config.origins)
    name = Str(choices=tuple(names())).check(raw, ("study",), ctx)
    ctx.raise_if_any()
    if command is not None and get(name).command != command:
        raise ConfigError(config.origins.problem(("study",), f"this config is for 'tirecli {get(name).command}', "
                                                             f"not 'tirecli {command}'"))
    return name


def plan(config: Config, command: str | None = None) -> Plan:
    """Check ``config`` completely and size its run (the study's ``plan``); ``command``: the command
    that runs it (its ``study:`` must be one of that command's)."""
    study = get(study_name(config, command))
    with formulas_located(config):
        out = study.plan(config)
    if not isinstance(out, Plan) or out.study != study.name:
        raise TypeError(f"the plan of study {study.name!r} must return a Plan of that study")
    return out


def run(plan_: Plan, progress=None):
    """Run a plan (the study's ``run``): its :class:`~tirecli.studies.base.StudyResult`."""
    with formulas_located(plan_.config):
        return get(plan_.study).run(plan_, progress)


def run_study(config: Config, command: str | None = None, progress=None):
    """Plan and run the study a config names."""
    return run(plan(config, command), progress)


def check(config: Config) -> str:
    """Check a config without running it (``tirecli params validate``); returns the study name."""
    return plan(config).study


@contextlib.contextmanager
def formulas_located(config: Config):
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


__all__ = ["STUDY_MODULES", "REGISTRY", "register", "unregister", "names", "get", "load_all", "study_name", "plan",
           "run", "run_study", "check", "formulas_located"]
