"""A config checked completely before anything runs: its study's plan (:func:`tirecli.studies.registry.plan`)
and the figure ids it lists, which the application layer looks up (the figure registry is a layer above the
studies); every problem is reported together, each at its key and line.

Used by the run commands, ``tirecli params validate`` and every point of a campaign.
"""
from __future__ import annotations

from tirecli.config.loader import Config
from tirecli.errors import ConfigError, TirecliError, UsageError
from tirecli.studies import registry as studies
from tirecli.studies.study import Plan


def figure_problems(config: Config) -> list:
    """The figure ids the config lists that are not registered figures: a problem at each one's key and
    line, with a did-you-mean (the figure registry is a layer above the studies, so the application
    layer looks them up)."""
    from tirecli.figures import registry

    listed = config.data.get("figures") if isinstance(config.data, dict) else None
    problems = []
    for i, fid in enumerate(listed if isinstance(listed, list) else []):
        if isinstance(fid, str):
            try:
                registry.get(fid)
            except UsageError as err:  # "unknown figure 'x'; did you mean 'y'? (see ...)"
                problems.append(config.origins.problem(("figures", i), str(err)))
    return problems


def plan_config(config: Config, command: str | None = None) -> Plan:
    """Check a config completely and size its run (:func:`tirecli.studies.registry.plan`), the figure ids
    it lists included: every problem found is raised together (one ConfigError)."""
    figs = figure_problems(config)
    try:
        plan = studies.plan(config, command)
    except ConfigError as err:
        raise ConfigError(figs + [p for p in err.problems if p not in figs]) from None
    except TirecliError:
        if figs:  # the config's own keys first: a bad figure id before a data file's problem
            raise ConfigError(figs) from None
        raise
    if figs:
        raise ConfigError(figs)
    return plan


__all__ = ["plan_config", "figure_problems"]
