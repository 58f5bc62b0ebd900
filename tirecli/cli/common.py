"""Options, output helpers and the progress bar shared by all commands."""
from __future__ import annotations

import contextlib
import sys
import time
from pathlib import Path
from typing import List, Optional

import typer

#: Set by :func:`tirecli.cli.main.main` from the global ``--quiet`` / ``--debug`` flags.
STATE = {"quiet": False, "debug": False}

ConfigArg = typer.Argument(..., metavar="CONFIG", help="YAML config file of the run (see examples/).", show_default=False)
OutOpt = typer.Option(None, "--out", "-o", metavar="DIR", help="Output directory [default: tirecli-out/COMMAND-CONFIG].")
JunitOpt = typer.Option(None, "--junit", metavar="FILE",
                        help="Also write the reference checks as JUnit XML to FILE (one test case per check, "
                             "failed checks as failures), for the test report of a CI pipeline.")
StrictOpt = typer.Option(False, "--strict", help="Exit 1 when any reference check fails.")
SetOpt = typer.Option(None, "--set", "-s", metavar="KEY=VALUE",
                      help="Override a config value, e.g. --set tire.sigma0=170 (repeatable).")
MaxSamplesOpt = typer.Option(None, "--max-samples", metavar="N",
                             help="Sample budget of the run: rows, output times and solver steps it may store "
                                  "[default: the config's run.max_samples, else 1000000]. A run over it is refused "
                                  "with its estimate.")


def echo(msg: str = "") -> None:
    """Print to stdout unless --quiet."""
    if not STATE["quiet"]:
        _print(msg)


def result_line(msg: str) -> None:
    """Print a result line (always, even with --quiet: it is the command's answer)."""
    _print(msg)


def _print(msg: str) -> None:
    """Print a line to stdout. When its reader has gone (``tirecli params list | head -1``), the rest of
    the output is dropped quietly and the command goes on (a run still writes its results): the exit
    code is the command's own, as if the reader had read everything (see :func:`tirecli.cli.main.main`)."""
    if STATE.get("stdout_closed"):
        return
    try:
        typer.echo(msg)
    except BrokenPipeError:
        stdout_closed()


def stdout_closed() -> None:
    """Stdout's reader has gone: send what remains (the interpreter's final flush included) to the null device."""
    import os

    STATE["stdout_closed"] = True
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


def stdout_reader_gone() -> bool:
    """Whether stdout is a pipe whose reading end is closed (poll reports an error on the write end)."""
    import select

    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(ev & select.POLLERR for _, ev in poller.poll(0))
    except (OSError, ValueError, AttributeError):
        return False


def table(rows: list[tuple]) -> list[str]:
    """Rows of text cells as aligned lines: each column as wide as its widest cell, two spaces apart."""
    rows = [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in rows if i < len(r)) for i in range(max((len(r) for r in rows), default=0))]
    return ["  ".join(c.ljust(widths[i]) if i < len(r) - 1 else c for i, c in enumerate(r)) for r in rows]


def warn(msg: str) -> None:
    """Print ``warning: MSG`` on stderr (always, even with --quiet: a result to look at twice)."""
    typer.echo(f"warning: {msg}", err=True)


class TerminalProgress:
    """A progress bar on stderr that appears only once work has taken over a second, with the
    name of the item in work (:meth:`item`); :meth:`refresh` redraws it (elapsed time, eta).

    Silent with ``--quiet`` or when stderr is not a terminal.
    """

    WIDTH = 100  # characters of the line at most (less in a narrower terminal)

    def __init__(self, delay: float = 1.0):
        self.delay = delay
        self.enabled = not STATE["quiet"] and sys.stderr.isatty()
        self.total = 0
        self.done = 0
        self.t0 = 0.0
        self.shown = False
        self.label = ""
        self.current = ""
        if self.enabled:
            import shutil

            self.WIDTH = min(self.WIDTH, max(shutil.get_terminal_size((self.WIDTH + 1, 20)).columns - 1, 40))

    def start(self, total: int, label: str = "") -> None:
        self.total, self.done, self.label, self.current = max(int(total), 1), 0, label, ""
        self.t0 = time.perf_counter()
        self.shown = False

    def item(self, name: str) -> None:
        """Name the item now in work (shown after the bar)."""
        self.current = name
        self.refresh()

    def advance(self, n: int = 1) -> None:
        self.done += n
        self.refresh()

    def refresh(self) -> None:
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.t0
        if elapsed < self.delay and not self.shown:
            return
        self.shown = True
        frac = min(self.done / self.total, 1.0)
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        eta = f"eta {elapsed / frac - elapsed:5.1f} s" if frac > 0 else f"{elapsed:5.1f} s"
        line = f"{self.label:>10} [{bar}] {frac * 100:5.1f}%  {eta}" + (f"  {self.current}" if self.current else "")
        sys.stderr.write("\r" + line[:self.WIDTH].ljust(self.WIDTH))
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled and self.shown:
            sys.stderr.write("\r" + " " * self.WIDTH + "\r")
            sys.stderr.flush()


def progress() -> TerminalProgress:
    return TerminalProgress()


def overrides(values: Optional[List[str]]) -> list[str]:
    return list(values or [])


#: The most workers ``--jobs`` may name for a campaign on a remote Dask cluster (its batches are sized for them).
MAX_CLUSTER_JOBS = 100_000


def jobs_option(value: Optional[int], scheduler: Optional[str] = None) -> Optional[int]:
    """The value of ``--jobs`` (UsageError if it is below 1, or more processes than
    :func:`tirecli.parallel.max_jobs` start here), for ``report`` and ``campaign`` alike; with a remote
    ``scheduler`` (a campaign's ``--scheduler`` other than ``local``) the workers are the cluster's, and
    at most :data:`MAX_CLUSTER_JOBS`."""
    from tirecli.errors import UsageError
    from tirecli.parallel import JOBS_PER_CORE, default_jobs, max_jobs

    if value is None:
        return None
    shown = str(value) if len(str(value)) <= 20 else f"{str(value)[:17]}..."
    if value < 1:
        raise UsageError(f"--jobs {shown}: give a number of processes >= 1")
    if scheduler and scheduler.strip() and scheduler.strip() != "local":
        if value > MAX_CLUSTER_JOBS:
            raise UsageError(f"--jobs {shown}: more workers than a cluster has (at most {MAX_CLUSTER_JOBS:,})")
    elif value > max_jobs():
        raise UsageError(f"--jobs {shown}: more processes than this machine can use (at most {max_jobs()}: "
                         f"{JOBS_PER_CORE} per core of the {default_jobs()} this process may use)")
    return value


def pairs(values: Optional[List[str]], option: str = "--map", form: str = "FILE_COLUMN=NAME",
          example: str = "slip=kappa") -> dict | None:
    """Repeated ``KEY=VALUE`` options (``--map FILE_COLUMN=NAME``, ``--units NAME=UNIT``) as a dict
    (None when none is given); UsageError naming a value without ``=``."""
    from tirecli.errors import UsageError

    out = {}
    for text in values or []:
        if "=" not in text:
            raise UsageError(f"{option} {text!r}: expected {form}, e.g. {option} {example}")
        key, _, value = text.partition("=")
        out[key.strip()] = value.strip()
    return out or None


def max_samples(text: Optional[str]) -> Optional[int]:
    """The value of ``--max-samples`` (UsageError if it is not a whole number >= 1)."""
    from tirecli.limits import parse_max_samples

    return parse_max_samples(text)


def run(command: str, config: Path, set_: Optional[List[str]], out: Optional[str], junit: Optional[str],
        extra: list[str] | tuple = (), max_samples_: Optional[str] = None, data_format: str = "csv"):
    """Run ``config`` as ``tirecli COMMAND`` (:func:`tirecli.app.run.run_config`; ``extra``: more overrides;
    ``max_samples_``: the text of ``--max-samples``, checked before the run; ``data_format``: ``csv`` or
    ``parquet``, of the data files).

    ``--junit FILE`` is checked before the run (exit 2 for a directory, an empty name); a run that
    fails (exit 1) is recorded in FILE as an error, so a CI test report shows it.
    """
    from tirecli.app.run import run_config
    from tirecli.errors import Interrupted, TirecliError, UsageError
    from tirecli.io import junit as jx

    budget = max_samples(max_samples_)
    target = jx.target(junit, inputs=[config], outputs=run_outputs(out)) if junit is not None else None

    def outputs_of(out_dir, study):  # the study's own files too (fitted.yaml), once it is known
        if target is not None:
            jx.target(junit, inputs=[config], outputs=run_outputs(out, study.files))

    t0 = time.perf_counter()
    try:
        return run_config(command, config, overrides(set_) + list(extra), out, progress(), budget,
                          data_format=data_format, on_study=outputs_of)
    except (UsageError, Interrupted):
        raise
    except Exception as exc:
        if target is not None:
            if isinstance(exc, TirecliError):
                text = str(exc) + (f"; {exc.tirecli_note}" if getattr(exc, "tirecli_note", None) else "")
            else:
                import traceback

                text = f"internal error: {type(exc).__name__}: {exc}\n" + traceback.format_exc()
            case = jx.Case(Path(config).stem, "run", time.perf_counter() - t0, error=text, error_type=type(exc).__name__)
            with contextlib.suppress(TirecliError):  # the run's own error is the one to report
                jx.write(target, [jx.Suite(f"{command} {Path(config).stem}", [case], case.time)], f"tirecli {command}")
        raise


def run_outputs(out, files=()) -> list[Path]:
    """What a run command writes in ``--out`` (files, and folders it writes into; ``files``: the study's
    own, known once the config is read), for refusing a ``--junit`` there before the run (none when the
    folder is the default, known only after loading)."""
    from tirecli.app.run import RUN_OUTPUTS

    if out is None or not str(out).strip():
        return []
    return [Path(out) / name for name in (*RUN_OUTPUTS, *files)]


def run_command(command: str, config: Path, set_: Optional[List[str]], out: Optional[str], junit: Optional[str],
                strict: bool, max_samples_: Optional[str] = None, extra: list[str] | tuple = (),
                data_format: str = "csv") -> None:
    """A run command (``sweep``, ``simulate``, ``compare``, ``fit``, ``observe``): the run (:func:`run`), the
    study's summary lines, the extra files written, then :func:`finish`."""
    summary = run(command, config, set_, out, junit, extra=extra, max_samples_=max_samples_, data_format=data_format)
    for line in summary.lines:
        if line.kind == "warning":
            warn(line.text)
        elif line.kind == "note":
            echo(line.text)
        else:
            result_line(line.text)
    for name in summary.result.files:
        result_line(f"wrote {Path(summary.out) / name}")
    finish(summary, command, config, junit, strict, overridden=bool(set_))


def finish(summary, command: str, config: Path, junit: Optional[str], strict: bool, overridden: bool) -> None:
    """The end of a run command: :func:`report_run`, the ``--junit`` file, the ``--strict`` exit code."""
    report_run(summary, command, overridden=overridden)
    records = [c.record() for c in summary.checks]
    if junit is not None:
        from tirecli.io import junit as jx

        stem = Path(config).stem
        run_case = jx.Case(stem, "run", summary.wall_time,
                           output=f"study: {summary.result.study}\nconfig: {config}\n"
                                  f"outputs: {Path(summary.out) / 'run.json'}")
        suite = jx.checks_suite(f"{command} {stem}", records, summary.wall_time, first=run_case)
        written = [summary.paths["run"], *summary.paths["data"], *summary.paths["figures"], *summary.paths["files"]]
        result_line(f"wrote {jx.write(junit, [suite], f'tirecli {command}', done=f'the results are in {summary.out}', outputs=written)}")
    strict_exit(records, strict)


def strict_exit(records: list[dict], strict: bool) -> None:
    """Under ``--strict``, RunError (exit 1) when a check record failed."""
    failed = sum(not r["passed"] for r in records)
    if strict and failed:
        from tirecli.errors import RunError

        raise RunError(f"{failed} of {len(records)} reference check(s) failed (--strict)")


def failed_check_line(rec: dict) -> str:
    """``check failed: ID: DESCRIPTION: VALUE vs reference R (tolerance T)`` (``upper bound`` or ``lower
    bound`` for a check that bounds the value) of a check record (:meth:`tirecli.studies.base.Check.record`)."""
    word = {"max": "upper bound", "min": "lower bound"}.get(rec.get("bound"), "reference")
    value = "n/a" if rec.get("value") is None else f"{rec['value']:.6g}"
    return (f"check failed: {rec['id']}: {rec.get('description') or ''}: {value} vs {word} {rec['reference']:.6g} "
            f"(tolerance {rec['tolerance']:g})")


def report_run(summary, what: str, overridden: bool = False) -> None:
    """The closing lines of a run command: where outputs are, and failed checks.

    ``overridden``: the config was changed by ``--set`` (then failed reference checks are expected).
    """
    out = Path(summary.out)
    for flag in (summary.result.meta or {}).get("flags") or []:  # results to look at twice (also in run.json)
        warn(flag)
    echo(f"{what}: {len(summary.paths['data'])} data file(s), {len(summary.paths['figures'])} figure file(s) "
         f"in {summary.wall_time:.2f} s")
    removed, kept = summary.paths.get("removed") or [], summary.paths.get("kept") or []
    if removed:
        echo(f"note: removed {len(removed)} file(s) of the earlier run in {out} that this run does not "
             f"write (e.g. {removed[0]})")
    if kept:
        echo(f"note: kept {out / kept[0]} of the earlier run in {out}: an input of this run"
             + (f" (and {len(kept) - 1} more)" if len(kept) > 1 else ""))
    failed = summary.failed_checks
    if failed and overridden:  # expected: one line, the details are in run.json
        result_line(f"{len(failed)} of {len(summary.checks)} reference checks differ from the paper's values "
                    f"(the checks hold the paper's scenario; --set overrides change it): see checks in {out / 'run.json'}")
    else:
        for c in failed:
            result_line(failed_check_line(c.record()))
    result_line(f"wrote {out / 'run.json'}")
