"""Reading input files as bytes with one clear error per failure (missing, a directory, unreadable)."""
from __future__ import annotations

from pathlib import Path

from tirecli.errors import ConfigError, Problem


def read_input_bytes(path: str | Path, expected: str) -> bytes:
    """The bytes of an input file; ``ConfigError`` (exit 2) naming the file otherwise.

    Parameters
    ----------
    expected : str
        What the file should be, for the message (e.g. ``"a YAML file"``).
    """
    path = Path(path)
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise ConfigError(Problem(str(path), None, "", "file not found")) from None
    except IsADirectoryError:
        raise ConfigError(Problem(str(path), None, "", f"is a directory, expected {expected}")) from None
    except OSError as exc:
        raise ConfigError(Problem(str(path), None, "", f"cannot read: {exc.strerror}")) from None
