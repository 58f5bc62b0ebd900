"""Exceptions of tirecli and the exit codes they map to (0 ok, 1 run failure, 2 usage/config, 130 Ctrl-C).

The CLI maps these to exit codes in one place (:mod:`tirecli.cli.main`); library code raises
them and never calls ``sys.exit``.

Messages quote input only through :func:`token` (the offending token, at most
:data:`TOKEN_LIMIT` characters, control characters escaped), and every line printed goes through
:func:`clean_line` (no terminal control sequences, bounded length); :func:`error_lines` is the
one formatter of an error for the terminal.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

#: Most characters of input content an error message quotes (the offending token).
TOKEN_LIMIT = 80
#: Most problem lines printed for one error (the rest are counted).
MAX_PROBLEM_LINES = 20
#: Longest line printed (a last resort: sources quote tokens through :func:`token`).
MAX_LINE = 1000

# C0/C1 control characters, DEL, and the Unicode bidirectional overrides (they reorder what a
# terminal shows): printed escaped, never raw
_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u200e\u200f\u202a-\u202e\u2066-\u2069\ufeff]")


def _escape(m: re.Match) -> str:
    c = ord(m.group(0))
    return f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"


def control_character(text: str) -> tuple[int, str] | None:
    """``(position, escaped form)`` of the first control character of ``text`` (C0 but tab and line feed, DEL,
    C1, the bidirectional overrides), or None: what may not go into a figure, an SVG file or the terminal."""
    m = _CONTROL.search(text)
    return None if m is None else (m.start(), _escape(m))


def clip(text: str, limit: int = TOKEN_LIMIT) -> str:
    """``text`` with control characters escaped, cut to ``limit`` characters (``...`` marks a cut)."""
    text = _CONTROL.sub(_escape, str(text).replace("\t", "\\t").replace("\n", "\\n").replace("\r", "\\r"))
    return text if len(text) <= limit else text[:max(limit - 3, 1)] + "..."


def token(value, limit: int = TOKEN_LIMIT) -> str:
    """The quoted form of an offending value for a message: ``'text'`` (as ``repr``), at most ``limit``
    characters of the input (``...`` marks a cut), control characters escaped. Other values are shown by
    their ``repr``, cut the same way (a list or mapping from a file is never printed whole)."""
    if isinstance(value, str):
        if len(value) <= limit:
            return repr(value)
        r = repr(value[:max(limit - 3, 1)])
        return r[:-1] + "..." + r[-1]
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 100:
        return f"a {_digits(value)}-digit integer"
    return clip(repr(value), limit)


def _digits(value: int) -> int:
    """Number of decimal digits of an integer (without ``str``, which refuses more than 4300)."""
    v = abs(value)
    n = int(v.bit_length() * 0.30102999566398120) + 1
    return n - 1 if 10 ** (n - 1) > v else n


def clean_line(text: str, limit: int = MAX_LINE) -> str:
    """One printable line: control characters and line breaks escaped, at most ``limit`` characters."""
    return clip(text, limit)


class TirecliError(Exception):
    """Base class: a failure with a one-line message for the user."""

    exit_code = 1


class RunError(TirecliError):
    """A run failed (numerical failure, a check failing under ``--strict``): exit code 1."""

    exit_code = 1


class Interrupted(TirecliError):
    """Ctrl-C during a run; the message says what was kept (``interrupted: previous results in DIR
    kept``): exit code 130."""

    exit_code = 130


class UsageError(TirecliError):
    """Bad command-line usage or input that the user must fix: exit code 2."""

    exit_code = 2


@dataclass(frozen=True)
class Problem:
    """One problem found in an input file.

    Attributes
    ----------
    file : str
        File the value came from (or ``"<command line>"`` for ``--set`` overrides).
    line : int or None
        1-based line in that file, when known.
    key : str
        Dotted key path, e.g. ``tire.sigma0`` or ``sweep.models[1].lambda``.
    message : str
        What is wrong and what was expected.
    """

    file: str
    line: int | None
    key: str
    message: str

    def __str__(self) -> str:
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        key = _short_key(self.key)
        return f"{where}: {key}: {self.message}" if key else f"{where}: {self.message}"


def _short_key(key: str) -> str:
    """A key path with each part cut to the token limit (a key is input too)."""
    if len(key) <= TOKEN_LIMIT:
        return clip(key, TOKEN_LIMIT)
    return ".".join(clip(part, TOKEN_LIMIT) for part in str(key).split("."))


class ConfigError(UsageError):
    """One or more problems in a YAML config, a parameter set or a data file: exit code 2.

    ``str(err)`` gives one line per problem.
    """

    def __init__(self, problems: list[Problem] | Problem):
        if isinstance(problems, Problem):
            problems = [problems]
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class DataError(UsageError):
    """A data file (CSV) that cannot be used: missing column, NaN, too few rows: exit code 2."""


#: Libraries that tirecli imports only where a feature needs them (import name -> the distribution to
#: install and the extra of tirecli that brings it, None for a dependency of the default install).
OPTIONAL = {
    "dask": ("dask[distributed]", "campaign"),
    "distributed": ("dask[distributed]", "campaign"),
    "pyarrow": ("pyarrow", None),
    "SALib": ("SALib", None),
    "asammdf": ("asammdf", "mdf"),
}


class MissingDependency(UsageError):
    """A library that a feature needs is not installed (or does not import): exit code 2, with the
    command that installs it."""


def missing_dependency(module: str, what: str, reason: str = "is not installed") -> MissingDependency:
    """The error of ``what`` (e.g. ``--scheduler``) needing library ``module`` (an import name of
    :data:`OPTIONAL`), which ``reason``: one line naming how to install it, from a checkout of tirecli
    (``pip install '.[EXTRA]'``) or from the package index (``pip install 'tirecli[EXTRA]'``)."""
    top = module.split(".")[0]
    dist, extra = OPTIONAL.get(top, (top, None))
    name = dist.split("[")[0]
    if extra:
        how = f"pip install '.[{extra}]' in a checkout of tirecli, or pip install 'tirecli[{extra}]'"
    else:
        how = f"a dependency of tirecli: pip install '{dist}' (or install tirecli again: pip install . in its checkout)"
    return MissingDependency(f"{what} needs {name}, which {reason}: {how}")


def require(module: str, what: str):
    """Import ``module`` and return it, or raise :func:`missing_dependency` naming ``what`` needs it.
    Called before any work, so that a missing library fails a run at its start."""
    import importlib

    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is not None and exc.name.split(".")[0] != module.split(".")[0]:
            raise missing_dependency(module, what, f"does not import (it needs {exc.name})") from None
        raise missing_dependency(module, what) from None
    except ImportError as exc:
        raise missing_dependency(module, what, f"does not import ({clip(str(exc), 120)})") from None


def error_lines(exc: BaseException) -> list[str]:
    """The lines printed for an error (each then prefixed with ``error: ``): one per problem, at most
    :data:`MAX_PROBLEM_LINES` (then a count of the rest), each a clean line."""
    problems = getattr(exc, "problems", None)
    lines = [str(p) for p in problems] if problems else (str(exc).splitlines() or [""])
    if len(lines) > MAX_PROBLEM_LINES:
        rest = len(lines) - (MAX_PROBLEM_LINES - 1)
        lines = lines[:MAX_PROBLEM_LINES - 1] + [f"... and {rest} more problem(s) of the same input"]
    return [clean_line(line) for line in lines]
