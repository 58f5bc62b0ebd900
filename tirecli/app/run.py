"""Application layer: what one command does, independent of the CLI framework.

``run_config`` loads a config, runs its study, draws the figures the result asks for,
evaluates their reference checks and writes the output contract (:mod:`tirecli.app.results`).
The Typer commands in :mod:`tirecli.cli` only parse arguments and call these functions.
"""
from __future__ import annotations

import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from tirecli import limits
from tirecli.app.results import write_result
from tirecli.config.budget import resolve_budget
from tirecli.config.loader import Config, load_config
from tirecli.errors import UsageError
from tirecli.figures import registry
from tirecli.io import output
from tirecli.studies import base as studies_base
from tirecli.studies.base import Check, StudyResult, run_study
from tirecli.studies.checks import checks_for

DEFAULT_OUT = Path("tirecli-out")

# the figure ids a config names are looked up in the figure registry, a layer above the studies
studies_base.FIGURE_LOOKUP = registry.get


@dataclass
class RunSummary:
    """What a command produced."""

    result: StudyResult
    out: Path
    paths: dict
    checks: list
    wall_time: float

    @property
    def failed_checks(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]


def command_line() -> str:
    """The command line as typed (for ``run.json``)."""
    return "tirecli " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def draw(result: StudyResult, ids=None, progress=None) -> tuple[dict, list]:
    """Draw the figures ``ids`` (default: the result's) and evaluate the checks of those asked for.

    A figure's checks compare the run with what the paper shows for *its* scenario, so they run only
    for figures asked for by name: ``ids`` given, or listed under the config's ``figures:`` (every
    built-in paper config lists its figures). A custom config without ``figures:`` gets the study's
    default figures and its own facts, and no paper checks.
    """
    figs, checks = {}, []
    asked = set(ids) if ids else set(_listed_figures(result))
    ids = list(ids or result.figures)
    if progress is not None:
        progress.start(len(ids), "figures")
    try:
        for fid in ids:
            fdef = registry.get(fid)
            try:
                figs[fid] = fdef.draw(result)
            except UsageError as exc:  # a figure of another kind of run: name the config line
                raise _figure_problem(result, fid, exc) from None
            fchecks = checks_for(fid) if fid in asked else None
            if fchecks is not None:
                for c in fchecks(result):
                    c.id = f"{fid}/{c.id}"
                    checks.append(c)
            if progress is not None:
                progress.advance(1)
    finally:
        if progress is not None:
            progress.close()
    return figs, checks


def _listed_figures(result: StudyResult) -> list:
    """The figure ids the result's config lists under ``figures:`` (empty without a config or the key)."""
    listed = result.config.data.get("figures") if result.config is not None else None
    return list(listed) if isinstance(listed, list) else []


def _figure_problem(result: StudyResult, fid: str, exc: UsageError) -> UsageError:
    """The error of figure ``fid`` at its place in the config's ``figures:`` list, if it is there."""
    from tirecli.errors import ConfigError

    listed = _listed_figures(result)
    if fid in listed:
        return ConfigError(result.config.origins.problem(("figures", listed.index(fid)), f"{fid}: {exc}"))
    return UsageError(f"figure {fid}: {exc}" if fid not in str(exc) else str(exc))


def close_figures(figs: dict) -> None:
    for fig in figs.values():
        if hasattr(fig, "clf"):
            fig.clf()


def default_out(config: Config, command: str) -> Path:
    stem = Path(config.label).stem if not config.label.startswith("<") else command
    return DEFAULT_OUT / f"{command}-{stem}"


def run_config(command: str, config_path: str | Path, overrides=(), out: str | Path | None = None,
               progress=None, max_samples: int | None = None, data_format: str = "csv") -> RunSummary:
    """Run the study of ``config_path`` as ``tirecli COMMAND`` and write its outputs.

    The run holds the output directory's lock from the study to the last file and writes into a
    staging directory moved into place at the end (:func:`tirecli.io.atomic.staged_dir`): on an
    error or Ctrl-C the earlier results there stay byte-identical.

    Parameters
    ----------
    command : str
        The command (``sweep``, ``simulate``, ...); the config's ``study`` must match it.
    overrides : sequence of str
        ``KEY=VALUE`` overrides (``--set``).
    out : path or None
        Output directory (default ``tirecli-out/COMMAND-CONFIGSTEM``).
    progress : object or None
        Progress reporter with ``start(total, label)``, ``advance(n)``, ``close()``.
    max_samples : int or None
        Sample budget (``--max-samples``; default: the config's ``run.max_samples``, else
        :data:`tirecli.limits.DEFAULT_MAX_SAMPLES`).
    data_format : str
        ``csv`` (default) or ``parquet`` (needs pyarrow): the format of ``data/NAME.*``.
    """
    from tirecli.io.atomic import out_path, staged_dir
    from tirecli.io.files import check_output_dir

    t0 = time.perf_counter()
    output.check_data_format(data_format)  # a missing pyarrow fails before the run
    out = out_path(out) if out is not None else None  # an empty --out fails before the study runs
    config = load_config(config_path, overrides)
    out = out or default_out(config, command)
    # before the run: a bad location fails in a second, not after it
    check_output_dir(out, files=("run.json",), dirs=("data", "figures"))
    budget = resolve_budget(config, max_samples)
    with staged_dir(out) as stage:
        with limits.budget(budget):
            result = run_study(config, expected=command, progress=progress)
        figs, checks = draw(result, progress=progress)
        wall = time.perf_counter() - t0
        paths = write_result(stage, result, figs, checks, command_line(), wall, progress=progress,
                                    data_format=data_format)
        close_figures(figs)
    paths.update(removed=stage.removed, kept=stage.kept)
    return RunSummary(result=result, out=out, paths=paths, checks=checks, wall_time=time.perf_counter() - t0)


def show_parameter_set(ref: str) -> str:
    """Text table of a parameter set (built-in name or file): value, unit, meaning, source."""
    from tirecli.io.files import exists
    from tirecli.parameters.sets import builtin_names, load_set

    if ref not in builtin_names() and exists(ref) and not ref.lower().endswith(".tir"):
        from tirecli.io.yamlio import load_yaml

        data, _ = load_yaml(ref)
        if isinstance(data, dict) and "study" in data:
            raise UsageError(f"{ref}: a study config, not a parameter set (its sets are named under tire:, "
                             f"vehicle:, ...; check it with 'tirecli params validate {ref}')")
    ps = load_set(ref, Path.cwd())
    lines = [f"{ps.name} ({ps.kind}): {ps.title}", f"citation: {ps.citation}", ""]
    rows = ps.rows()
    w = max(len(r["name"]) for r in rows)
    for r in rows:
        flag = "  [ASSUMED]" if r["assumed"] else ""
        lines.append(f"  {r['name']:<{w}}  {r['value']:>12.6g} {r['unit']:<9} {r['meaning']} ({r['equation']}){flag}")
    assumed = [r for r in rows if r["assumed"]]
    if assumed:
        lines += ["", "assumed values (documented defaults, override with --set GROUP.NAME=VALUE):"]
        lines += [f"  {r['name']}: {r['assumed']}" for r in assumed]
    notes = [r for r in rows if r["note"]]
    if notes:
        lines += ["", "notes:"] + [f"  {r['name']}: {r['note']}" for r in notes]
    return "\n".join(lines)


def validate_file(path: str | Path, max_samples: int | None = None) -> str:
    """Check a parameter-set file or a study config without running it (its sample budget included:
    ``max_samples`` as in :func:`run_config`); ConfigError lists problems."""
    from tirecli.io.yamlio import load_yaml
    from tirecli.parameters.sets import parse_set
    from tirecli.studies.base import check_study

    if str(path).lower().endswith(".tir"):  # a Magic Formula property file
        from tirecli.app.mf import load_tire

        ps, tire = load_tire(str(path))
        return (f"{path}: reads as a Magic Formula tyre ({tire.version}); for the coefficients' sanity run "
                f"'tirecli tir check {path}'")
    data, origins = load_yaml(path)
    if isinstance(data, dict) and "campaign" in data and "study" not in data:
        from tirecli.campaign.check import check_points
        from tirecli.campaign.spec import load_campaign

        campaign = load_campaign(path, max_samples)
        with limits.budget(campaign.max_samples):
            ids, study = check_points(campaign)
        return f"{path}: valid campaign {campaign.name!r}: {len(ids)} points of the {study} study"
    if isinstance(data, dict) and "kind" in data and "study" not in data:
        ps = parse_set(data, origins, label=str(path))
        return f"{path}: valid {ps.kind} parameter set {ps.name!r} ({len(ps.values)} values)"
    config = load_config(path)
    with limits.budget(resolve_budget(config, max_samples)):
        name = check_study(config)
    return f"{path}: valid {name} config"
