"""Exceptions of tirecli and the exit codes they map to (0 ok, 1 run failure, 2 usage/config, 130 Ctrl-C).

The CLI maps these to exit codes in one place (:mod:`tirecli.cli.main`); library code raises
them and never calls ``sys.exit``.
"""
from __future__ import annotations

from dataclasses import dataclass


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
        return f"{where}: {self.key}: {self.message}" if self.key else f"{where}: {self.message}"


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
