"""The ``tirecli`` command: Typer app, global flags and the one place errors map to exit codes.

Exit codes: 0 success; 1 run failure (numerical failure, failed checks under ``--strict``,
internal error); 2 usage, input or environment error (bad option, bad config, bad data file, an
unusable input or output path); 130 Ctrl-C (or SIGTERM). Errors print one line each on stderr
without a traceback (at most the offending token of an input, see :mod:`tirecli.errors`);
``--debug`` shows the traceback. A run that fails or is interrupted leaves its earlier outputs as
they were and says so.

A closed output pipe (``tirecli params list | head -1``) is not an error: the rest of the output is
dropped quietly, the command finishes its work (a run still writes its results) and exits with its
own code, 0 when all went well, as ``ls`` or ``git`` do when they are not killed by SIGPIPE (Python
ignores that signal, so a tirecli ends through its exit code, never as "killed by SIGPIPE" (141)).
"""
from __future__ import annotations

import errno
import signal
import sys
import threading
import traceback

import typer

from tirecli._version import __version__
from tirecli.cli import campaign, common, compare, data, figures, fit, mf, observe, params, report, simulate, sweep, tir

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
app.add_typer(data.app, name="data")


def _error(msg) -> None:
    """Print an error: one ``error:`` line per problem, each sanitized (see :func:`tirecli.errors.error_lines`);
    the note of a failed run (what it kept) joins the last."""
    from tirecli.errors import clean_line, error_lines

    lines = error_lines(msg if isinstance(msg, BaseException) else Exception(str(msg)))
    note = getattr(msg, "tirecli_note", None)
    if note:
        lines[-1] += f"; {clean_line(note)}"
    for line in lines:
        sys.stderr.write(f"error: {line}\n")


def _click():
    try:
        from typer import _click as click  # typer >= 0.16 vendors click
    except ImportError:  # pragma: no cover - older typer uses click itself
        import click
    return click


def _usage_line(exc) -> str:
    """One line for a command-line usage error: the problem and where the help is."""
    ctx = getattr(exc, "ctx", None)
    where = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
    return f"{exc.format_message().rstrip('.')}{where}"


#: ``OSError`` numbers that are the environment's doing (a file, a directory, a disk): exit 2.
_ENVIRONMENT_ERRNOS = {errno.ENOENT, errno.ENOTDIR, errno.EISDIR, errno.EEXIST, errno.EACCES, errno.EPERM,
                       errno.EROFS, errno.ENOSPC, errno.ENAMETOOLONG, errno.ELOOP, errno.EXDEV, errno.EBUSY,
                       errno.ETXTBSY, errno.EFBIG, errno.EMFILE, errno.ENFILE, errno.ENXIO, errno.ENODEV,
                       getattr(errno, "EDQUOT", errno.ENOSPC)}


def _os_error_line(exc: OSError) -> str:
    from tirecli.io.files import os_reason, show_path

    name = exc.filename if exc.filename is not None else None
    reason = os_reason(exc)
    if name is None:
        return f"file system: {reason}"
    if exc.filename2 is not None:
        return f"{show_path(name)} -> {show_path(exc.filename2)}: {reason}"
    return f"{show_path(name)}: {reason}"


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
    """Entry point of the ``tirecli`` script; returns (and exits with) the exit code.

    The one place errors become exit codes: 0 success; 1 a run failure (:class:`~tirecli.errors.RunError`,
    failed checks under ``--strict``) or an internal error; 2 a usage, input or environment problem
    (:class:`~tirecli.errors.UsageError`, a command-line error, a file-system error such as a read-only
    output location); 130 interrupted.
    """
    from tirecli.errors import Interrupted, TirecliError
    from tirecli.io.files import forget_inputs

    forget_inputs()
    click = _click()  # the exception classes, looked up before anything can fail
    no_args_help = getattr(click.exceptions, "NoArgsIsHelpError", ())
    usage_error = getattr(click.exceptions, "UsageError", ())
    click_error = getattr(click.exceptions, "ClickException", ())
    abort = getattr(typer, "Abort", None) or getattr(click.exceptions, "Abort", ())
    args = list(sys.argv[1:] if argv is None else argv)
    common.STATE["debug"] = "--debug" in args
    common.STATE["quiet"] = "--quiet" in args or "-q" in args
    common.STATE["stdout_closed"] = False
    args = [a for a in args if a not in ("--debug", "--quiet", "-q")]
    code = 0
    ctrl_c = _CtrlC()
    try:
        with ctrl_c:
            rv = app(args=args, prog_name="tirecli", standalone_mode=False)
        code = rv if isinstance(rv, int) and not isinstance(rv, bool) else 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        pipe = exc.__context__
        if code == 1 and isinstance(pipe, OSError) and pipe.errno == errno.EPIPE:  # Click's exit 1 on a broken pipe
            code = _broken_pipe(pipe)
        if ctrl_c.seen and code != 0:  # Typer's own handling of a Ctrl-C outside a run
            _error("interrupted")
            code = 130
    except TirecliError as exc:
        _error(exc)
        code = exc.exit_code
        if common.STATE["debug"] and not isinstance(exc, Interrupted):
            traceback.print_exc()
    except no_args_help as exc:  # 'tirecli' or 'tirecli tir' alone: the help, exit 2
        exc.show()
        code = 2
    except usage_error as exc:
        _error(_usage_line(exc))
        code = 2
    except click_error as exc:
        _error(exc.format_message())
        code = exc.exit_code
    except (KeyboardInterrupt, abort):
        _error("interrupted")
        code = 130
    except MemoryError as exc:  # the sample budget's estimates should prevent this; never a traceback if not
        from tirecli.errors import clean_line

        note = getattr(exc, "tirecli_note", None)   # what the run kept
        _error("out of memory: this run needs more memory than is available; make it smaller "
               "(or lower --max-samples, the samples a run may store)" + (f"; {clean_line(note)}" if note else ""))
        code = 2
        if common.STATE["debug"]:
            traceback.print_exc()
    except BrokenPipeError as exc:
        code = _broken_pipe(exc)
    except OSError as exc:
        if exc.errno not in _ENVIRONMENT_ERRNOS:
            _internal(exc)
            code = 1
        else:  # a file or directory the environment refuses: an environment problem, not a failure of tirecli
            _error(_os_error_line(exc))
            code = 2
            if common.STATE["debug"]:
                traceback.print_exc()
    except ModuleNotFoundError as exc:  # an optional library that a code path imported without asking first
        from tirecli.errors import OPTIONAL, missing_dependency

        if (exc.name or "").split(".")[0] not in OPTIONAL:
            _internal(exc)
            code = 1
        else:
            _error(missing_dependency(exc.name, "this command"))
            code = 2
            if common.STATE["debug"]:
                traceback.print_exc()
    except Exception as exc:  # noqa: BLE001 - the one place internal errors become exit code 1
        _internal(exc)
        code = 1
    if argv is None:
        sys.exit(code)
    return code


def _broken_pipe(exc: OSError) -> int:
    """The exit code of a broken pipe: 0, quietly, when it is stdout's (its reader went away:
    ``tirecli --help | head -1``, see the module doc); an internal error (1) when it is a pipe of the
    work itself (a worker's)."""
    if common.STATE.get("stdout_closed") or common.stdout_reader_gone():
        common.stdout_closed()
        return 0
    _internal(exc)
    return 1


def _internal(exc: BaseException) -> None:
    from tirecli.errors import clip

    note = getattr(exc, "tirecli_note", None)
    _error(f"internal error: {type(exc).__name__}: {clip(str(exc), 200)} (run with --debug for the traceback)"
           + (f"; {note}" if note else ""))
    if common.STATE["debug"]:
        traceback.print_exc()


if __name__ == "__main__":  # pragma: no cover
    main()
