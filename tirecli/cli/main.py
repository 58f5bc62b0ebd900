"""The ``tirecli`` command: Typer app, global flags and the one place errors map to exit codes.

Exit codes: 0 success; 1 run failure (numerical failure, failed checks under ``--strict``,
internal error); 2 usage or input error (bad option, bad config, bad data file); 130 Ctrl-C
(or SIGTERM).
Errors print one line each on stderr without a traceback; ``--debug`` shows the traceback. A run
that fails or is interrupted leaves its earlier outputs as they were and says so.
"""
from __future__ import annotations

import signal
import sys
import threading
import traceback

import typer

from tirecli import __version__
from tirecli.cli import campaign, common, compare, figures, fit, mf, observe, params, report, simulate, sweep, tir

app = typer.Typer(
    name="tirecli",
    help="Tire/road friction analysis: LuGre models, the adhesion observer, the Magic Formula, "
         "the MCPS multi-DOF tire, paper figures and an HTML report. Run 'tirecli report' for everything on built-in defaults.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"tirecli {__version__}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", "-V", callback=_version, is_eager=True,
                                 help="Print the version and exit."),
    debug: bool = typer.Option(False, "--debug", help="Show tracebacks on errors (also accepted after the command)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="Only print results; no progress bar (also after the command)."),
) -> None:
    """Global options."""


app.command("sweep")(sweep.sweep)
app.command("simulate")(simulate.simulate)
app.command("compare")(compare.compare)
app.command("fit")(fit.fit)
app.command("observe")(observe.observe)
app.command("report")(report.report)
app.command("campaign")(campaign.campaign)
app.add_typer(params.app, name="params")
app.add_typer(figures.app, name="figures")
app.add_typer(tir.app, name="tir")
app.add_typer(mf.app, name="mf")


def _error(msg: str, exc: BaseException | None = None) -> None:
    """``error: MSG`` on stderr, one line per line of MSG; the note of a failed run (what it kept) joins the last."""
    lines = str(msg).splitlines() or [""]
    note = getattr(exc, "tirecli_note", None)
    if note:
        lines[-1] += f"; {note}"
    for line in lines:
        sys.stderr.write(f"error: {line}\n")


class _CtrlC:
    """Notes a Ctrl-C (then raises KeyboardInterrupt as Python does), so that an interrupt Typer
    turned into an exit code is reported as one: one line, exit 130. SIGTERM (``kill``, ``timeout``)
    is handled as Ctrl-C, so a run stopped either way keeps the earlier results and removes its
    staging. A signal ignored at start (SIGINT in a background job) stays ignored."""

    def __init__(self):
        self.seen = False
        self.old = {}

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for sig, default in ((signal.SIGINT, signal.default_int_handler), (signal.SIGTERM, signal.SIG_DFL)):
                if signal.getsignal(sig) is default:
                    self.old[sig] = signal.signal(sig, self._handle)
        return self

    def _handle(self, signum, frame):
        self.seen = True
        raise KeyboardInterrupt

    def __exit__(self, *exc):
        for sig, handler in self.old.items():
            signal.signal(sig, handler)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``tirecli`` script; returns (and exits with) the exit code."""
    from tirecli.errors import Interrupted, TirecliError
    from tirecli.io.files import forget_inputs

    forget_inputs()
    args = list(sys.argv[1:] if argv is None else argv)
    common.STATE["debug"] = "--debug" in args
    common.STATE["quiet"] = "--quiet" in args or "-q" in args
    args = [a for a in args if a not in ("--debug", "--quiet", "-q")]
    code = 0
    ctrl_c = _CtrlC()
    try:
        with ctrl_c:
            # standalone mode: Typer prints usage errors itself and exits 2 (SystemExit below)
            app(args=args, prog_name="tirecli")
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if ctrl_c.seen and code != 0:  # Typer's own handling of a Ctrl-C outside a run
            _error("interrupted")
            code = 130
    except TirecliError as exc:
        _error(str(exc), exc)
        code = exc.exit_code
        if common.STATE["debug"] and not isinstance(exc, Interrupted):
            traceback.print_exc()
    except KeyboardInterrupt:
        _error("interrupted")
        code = 130
    except Exception as exc:  # noqa: BLE001 - the one place internal errors become exit code 1
        _error(f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)", exc)
        code = 1
        if common.STATE["debug"]:
            traceback.print_exc()
    if argv is None:
        sys.exit(code)
    return code


if __name__ == "__main__":  # pragma: no cover
    main()
