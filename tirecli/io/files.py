"""Reading input files as bytes with one clear error per failure (missing, a directory, unreadable),
and the record of every input file the process read (an output never overwrites or removes one)."""
from __future__ import annotations

import contextlib
import os
from pathlib import Path

from tirecli.errors import ConfigError, Problem


_INPUTS: set[str] = set()
_TRACKERS: list[set] = []


def note_input(path: str | Path) -> None:
    """Record that ``path`` is an input of this run (every reader of :mod:`tirecli.io` calls this)."""
    real = os.path.realpath(path)
    _INPUTS.add(real)
    for seen in _TRACKERS:
        seen.add(real)


@contextlib.contextmanager
def tracked_inputs():
    """Yield a set that collects the real paths of the input files read inside the block (a
    campaign hashes the files its base study reads into the points' identities)."""
    seen: set = set()
    _TRACKERS.append(seen)
    try:
        yield seen
    finally:
        _TRACKERS.remove(seen)


def inputs_read() -> frozenset[str]:
    """Real paths of the input files read since :func:`forget_inputs` (the start of the command)."""
    return frozenset(_INPUTS)


def forget_inputs() -> None:
    _INPUTS.clear()


def read_input_bytes(path: str | Path, expected: str) -> bytes:
    """The bytes of an input file; ``ConfigError`` (exit 2) naming the file otherwise.

    Parameters
    ----------
    expected : str
        What the file should be, for the message (e.g. ``"a YAML file"``).
    """
    path = Path(path)
    note_input(path)
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise ConfigError(Problem(str(path), None, "", "file not found")) from None
    except IsADirectoryError:
        raise ConfigError(Problem(str(path), None, "", f"is a directory, expected {expected}")) from None
    except OSError as exc:
        raise ConfigError(Problem(str(path), None, "", f"cannot read: {exc.strerror}")) from None
