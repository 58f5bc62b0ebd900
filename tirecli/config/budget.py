"""The sample budget a config asks for: the schema of its ``run:`` block and the budget of a run.

The budget itself (the numbers, :class:`~tirecli.limits.Estimate`, the context in force) is
:mod:`tirecli.limits`, which imports no config code; this module reads the config's side of it.
"""
from __future__ import annotations

from tirecli.config.schema import Map, Num, check_document
from tirecli.limits import CONFIG_KEY, DEFAULT_MAX_SAMPLES, MAX_MAX_SAMPLES, OPTION


def run_spec() -> Map:
    """Schema of a config's ``run:`` block (every study accepts it)."""
    return Map(fields={CONFIG_KEY[1]: Num(unit="samples", integer=True, ge=1, le=MAX_MAX_SAMPLES, default=None,
                                          doc=f"sample budget of the run (default {DEFAULT_MAX_SAMPLES:,}; "
                                              f"also {OPTION})")}, default=None)


def resolve_budget(config, cli_value: int | None) -> int | None:
    """The budget of a run: ``--max-samples`` if given, else the config's ``run.max_samples``, else None (default)."""
    if cli_value is not None:
        return cli_value
    run = config.data.get(CONFIG_KEY[0]) if isinstance(config.data, dict) else None
    if not isinstance(run, dict) or run.get(CONFIG_KEY[1]) is None:
        return None
    checked = check_document(run, run_spec(), config.origins, (CONFIG_KEY[0],))
    return checked[CONFIG_KEY[1]]


__all__ = ["run_spec", "resolve_budget"]
