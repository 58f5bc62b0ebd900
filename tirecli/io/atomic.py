"""Output safety: every file tirecli writes appears complete or not at all, and an output
directory never mixes two runs (a run's outputs as a whole: :mod:`tirecli.io.staging`).

* :func:`atomic_write` writes one file through a unique temporary file in the target's directory
  (``.NAME.tirecli-tmp-XXXXXXXX``), then ``os.replace``: a reader sees the old file or the new one,
  never a part, and two writers never share a temporary file.

A run killed with SIGKILL leaves the temporary files it was writing (named ``.NAME.tirecli-tmp-PID-XXXXXXXX``,
PID the process that made them): the next run into the same target removes them when that process is dead
(:func:`clean_temps`), the report's study cache when it next writes its timings (its lock and staging:
:mod:`tirecli.io.staging`).
"""
from __future__ import annotations

import contextlib
import functools
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

TMP = "tirecli-tmp-"


@functools.lru_cache(maxsize=1)
def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _mode(base: int) -> int:
    """``base`` (0o666 for a file, 0o777 for a directory) under the process umask, as ``open`` and
    ``mkdir`` would give (``mkstemp`` and ``mkdtemp`` create 0600 and 0700)."""
    return base & ~_umask()


def _prefix(name: str) -> str:
    return f".{name[:50]}."  # the name's head: the temporary names stay within NAME_MAX


def temp_prefix(head: str) -> str:
    """The prefix of a temporary name tirecli makes (``mkstemp``/``mkdtemp`` add 8 random characters):
    ``HEAD`` + ``tirecli-tmp-`` + this process's id, so that a leftover of a killed run is known for
    one, and known to be dead (:func:`clean_temps`)."""
    return f"{head}{TMP}{os.getpid()}-"


#: A temporary name of tirecli's (:func:`temp_prefix`): ``.NAME.tirecli-tmp-PID-XXXXXXXX`` (or, inside an output
#: directory, ``.tirecli-tmp-PID-XXXXXXXX``).
_TEMP = re.compile(r"\.(?:.*\.)?" + re.escape(TMP) + r"(\d+)-[a-z0-9_]{8}")


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this host (another user's process counts as running)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0
    return True


#: How far :func:`clean_temps` looks below a directory: levels, and entries in all (an ``--out`` given as a
#: large folder is not walked through; tirecli writes its outputs at most a few levels deep).
CLEAN_DEPTH, CLEAN_ENTRIES = 4, 20_000


def clean_temps(directory, recursive: bool = False, older_than: float = 0.0) -> list[str]:
    """Remove the temporary files and directories tirecli left in ``directory`` (and below it, ``recursive``:
    :data:`CLEAN_DEPTH` levels, :data:`CLEAN_ENTRIES` entries at most) when killed: only names of
    :func:`temp_prefix`'s form whose process is dead (and, with ``older_than``, older than that many seconds).
    Nothing else is touched, links are not followed. Returns what was removed."""
    removed = []
    stack, seen = [(Path(directory), 0)], 0
    while stack and seen < CLEAN_ENTRIES:
        d, depth = stack.pop()
        try:
            entries = list(os.scandir(d))
        except OSError:
            continue
        seen += len(entries)
        for entry in entries:
            m = _TEMP.fullmatch(entry.name)
            if m is not None and not _alive(int(m.group(1))):
                try:
                    if older_than and time.time() - entry.stat(follow_symlinks=False).st_mtime < older_than:
                        continue
                except OSError:
                    continue
                _remove(Path(entry.path))
                removed.append(entry.path)
            elif recursive and depth < CLEAN_DEPTH and entry.is_dir(follow_symlinks=False):
                stack.append((Path(entry.path), depth + 1))
    return removed


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", encoding: str = "utf-8", errors: str | None = None, newline: str | None = None):
    """Open a unique temporary file beside ``path`` for writing (text, or bytes with ``mode='wb'``);
    when the block ends it replaces ``path`` (``os.replace``). On an error or Ctrl-C it is removed
    and ``path`` is untouched."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(_prefix(path.name)), dir=path.parent)
    try:
        if "b" in mode:
            fh = os.fdopen(fd, "wb")
        else:
            fh = os.fdopen(fd, "w", encoding=encoding, errors=errors, newline=newline)
        with fh:
            yield fh
        os.chmod(tmp, _mode(0o666))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _remove(path: Path) -> None:
    """Remove a file or directory tree, quietly (a leftover is cleaned up by the next run)."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(OSError):
            path.unlink()
