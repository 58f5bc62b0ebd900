"""Application layer: what one command does, independent of the CLI framework.

``run_config`` loads a config, plans its study (every problem at its key and line, the figure ids it
lists included, the run sized against the sample budget), runs it, draws the figures the result asks
for with their reference checks (:mod:`tirecli.app.draw`) and writes the output contract
(:mod:`tirecli.app.results`). The Typer commands in :mod:`tirecli.cli` only parse arguments, call
these functions and print the study's summary (``RunSummary.lines``).
"""
from __future__ import annotations

import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from tirecli import limits
from tirecli.app.draw import close_figures, draw
from tirecli.app.results import write_result
from tirecli.app.plan import plan_config
from tirecli.config.budget import resolve_budget
from tirecli.config.loader import Config, load_config
from tirecli.errors import UsageError
from tirecli.io import output
from tirecli.studies import registry as studies
from tirecli.studies.base import Check, StudyResult
from tirecli.studies.study import Line, Study

DEFAULT_OUT = Path("tirecli-out")
#: What every run command writes in its output directory (and a study's ``files``).
RUN_OUTPUTS = ("run.json", "data", "figures")


@dataclass
class RunSummary:
    """What a command produced."""

    result: StudyResult
    out: Path
    paths: dict
    checks: list
    wall_time: float
    study: Study | None = None

    @property
    def failed_checks(self) -> list[Check]:
        return [c for c in self.checks if not c.passed]

    @property
    def lines(self) -> list[Line]:
        """The study's summary of the run: the lines the CLI prints (:attr:`Study.summary`)."""
        return (self.study or studies.get(self.result.study)).lines(self.result)


def command_line() -> str:
    """The command line as typed (for ``run.json``)."""
    return "tirecli " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def default_out(config: Config, command: str) -> Path:
    stem = Path(config.label).stem if not config.label.startswith("<") else command
    return DEFAULT_OUT / f"{command}-{stem}"


def execute(config: Config, command: str | None = None, progress=None, max_samples: int | None = None,
            on_study: Callable[[Study], None] | None = None) -> StudyResult:
    """Plan and run the study of ``config`` (as ``tirecli COMMAND`` when a command is given) within its
    sample budget (``max_samples``, else the config's ``run.max_samples``, else the default);
    ``on_study(entry)`` is called once the study is known, before it is planned."""
    with limits.budget(resolve_budget(config, max_samples)):
        study = studies.get(studies.study_name(config, command))
        if on_study is not None:
            on_study(study)
        return studies.run(plan_config(config, command), progress)


def run_config(command: str, config_path: str | Path | Config, overrides=(), out: str | Path | None = None,
               progress=None, max_samples: int | None = None, data_format: str = "csv",
               on_study: Callable[[Path, Study], None] | None = None, command_text: str | None = None) -> RunSummary:
    """Run the study of ``config_path`` as ``tirecli COMMAND`` and write its outputs.

    The run holds the output directory's lock from the study to the last file and writes into a
    staging directory moved into place at the end (:func:`tirecli.io.staging.staged_dir`): on an
    error or Ctrl-C the earlier results there stay byte-identical.

    Parameters
    ----------
    command : str or None
        The command (``sweep``, ``simulate``, ...); the config's ``study`` must be one it runs (None: any).
    config_path : path or Config
        The config file (or a loaded config: ``overrides`` are then already applied).
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
    on_study : callable or None
        ``on_study(out, entry)``, called once the study is known, before it runs (e.g. to refuse a
        ``--junit`` file among the study's outputs).
    command_text : str or None
        The command line recorded in ``run.json`` (default: this process's).
    """
    from tirecli.io.staging import out_path, staged_dir
    from tirecli.io.files import check_output_dir

    t0 = time.perf_counter()
    output.check_data_format(data_format)  # a missing pyarrow fails before the run
    out = out_path(out) if out is not None else None  # an empty --out fails before the study runs
    config = config_path if isinstance(config_path, Config) else load_config(config_path, overrides)
    out = out or default_out(config, command or "run")
    # before the run: a bad location fails in a second, not after it
    check_output_dir(out, files=("run.json",), dirs=("data", "figures"))
    budget = resolve_budget(config, max_samples)  # a bad run.max_samples fails before the output is locked
    entry = []
    with staged_dir(out) as stage:
        result = execute(config, command, progress, budget,
                         on_study=lambda s: (entry.append(s), on_study and on_study(out, s)))
        figs, checks = draw(result, progress=progress)
        wall = time.perf_counter() - t0
        paths = write_result(stage, result, figs, checks, command_text or command_line(), wall, progress=progress,
                             data_format=data_format)
        close_figures(figs)
    paths.update(removed=stage.removed, kept=stage.kept)
    return RunSummary(result=result, out=out, paths=paths, checks=checks, wall_time=time.perf_counter() - t0,
                      study=entry[0])


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
        name = plan_config(config).study
    return f"{path}: valid {name} config"
