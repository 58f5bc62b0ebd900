"""Reading input files as bytes with one clear error per failure (missing, a directory, unreadable),
and the record of every input file the process read (an output never overwrites or removes one)."""
from __future__ import annotations

import os
from pathlib import Path

from tirecli.errors import ConfigError, Problem


_INPUTS: set[str] = set()


def note_input(path: str | Path) -> None:
    """Record that ``path`` is an input of this run (every reader of :mod:`tirecli.io` calls this)."""
    _INPUTS.add(os.path.realpath(path))


def inputs_read() -> frozenset[str]:
    """Real paths of the input files read since :func:`forget_inputs` (the start of the command)."""
    return frozenset(_INPUTS)


def forget_inputs() -> None:
    _INPUTS.clear()


def read_input_bytes(path: str | Path, expected: str, max_bytes: int | None = None) -> bytes:
    """The bytes of an input file; ``ConfigError`` (exit 2) naming the file otherwise.

    Parameters
    ----------
    expected : str
        What the file should be, for the message (e.g. ``"a YAML file"``).
    max_bytes : int or None
        Largest size accepted (:mod:`tirecli.limits`); never more than this is read, so a huge file or an
        endless device is refused without filling the memory.
    """
    path = Path(path)
    note_input(path)
    try:
        with path.open("rb") as fh:
            data = fh.read() if max_bytes is None else fh.read(max_bytes + 1)
        if max_bytes is not None and len(data) > max_bytes:
            raise ConfigError(Problem(str(path), None, "", too_large(path, expected, max_bytes)))
        return data
    except FileNotFoundError:
        raise ConfigError(Problem(str(path), None, "", "file not found")) from None
    except IsADirectoryError:
        raise ConfigError(Problem(str(path), None, "", f"is a directory, expected {expected}")) from None
    except OSError as exc:
        raise ConfigError(Problem(str(path), None, "", f"cannot read: {exc.strerror}")) from None


def too_large(path: Path, expected: str, max_bytes: int) -> str:
    """The message for an input file over its size cap (its size when it has one)."""
    from tirecli.limits import bytes_text

    try:
        size = path.stat().st_size
    except OSError:
        size = 0
    what = f"{bytes_text(size)[1:]}, " if size > max_bytes else ""
    return f"too large for {expected} ({what}at most {bytes_text(max_bytes)[1:]})"
