"""Options, output helpers and the progress bar shared by all commands."""
from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import List, Optional

import typer

#: Set by :func:`tirecli.cli.main.main` from the global ``--quiet`` / ``--debug`` flags.
STATE = {"quiet": False, "debug": False}

ConfigArg = typer.Argument(..., metavar="CONFIG", help="YAML config file of the run (see examples/).", show_default=False)
OutOpt = typer.Option(None, "--out", "-o", help="Output directory [default: tirecli-out/COMMAND-CONFIG].")
SetOpt = typer.Option(None, "--set", "-s", metavar="KEY=VALUE",
                      help="Override a config value, e.g. --set tire.sigma0=170 (repeatable).")


def echo(msg: str = "") -> None:
    """Print to stdout unless --quiet."""
    if not STATE["quiet"]:
        typer.echo(msg)


def result_line(msg: str) -> None:
    """Print a result line (always, even with --quiet: it is the command's answer)."""
    typer.echo(msg)


def warn(msg: str) -> None:
    """Print ``warning: MSG`` on stderr (always, even with --quiet: a result to look at twice)."""
    typer.echo(f"warning: {msg}", err=True)


class TerminalProgress:
    """A progress bar on stderr that appears only once work has taken over a second.

    Silent with ``--quiet`` or when stderr is not a terminal.
    """

    def __init__(self, delay: float = 1.0):
        self.delay = delay
        self.enabled = not STATE["quiet"] and sys.stderr.isatty()
        self.total = 0
        self.done = 0
        self.t0 = 0.0
        self.shown = False
        self.label = ""

    def start(self, total: int, label: str = "") -> None:
        self.total, self.done, self.label = max(int(total), 1), 0, label
        self.t0 = time.perf_counter()
        self.shown = False

    def advance(self, n: int = 1) -> None:
        self.done += n
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.t0
        if elapsed < self.delay and not self.shown:
            return
        self.shown = True
        frac = min(self.done / self.total, 1.0)
        width = 30
        bar = "#" * int(frac * width) + "-" * (width - int(frac * width))
        eta = elapsed / frac - elapsed if frac > 0 else 0.0
        sys.stderr.write(f"\r{self.label:>10} [{bar}] {frac * 100:5.1f}%  eta {eta:5.1f} s")
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled and self.shown:
            sys.stderr.write("\r" + " " * 70 + "\r")
            sys.stderr.flush()


def progress() -> TerminalProgress:
    return TerminalProgress()


def overrides(values: Optional[List[str]]) -> list[str]:
    return list(values or [])


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
            result_line(f"check failed: {c.id}: {c.value:.6g} vs reference {c.reference:.6g} "
                        f"(tolerance {c.tolerance:g})")
    result_line(f"wrote {out / 'run.json'}")
