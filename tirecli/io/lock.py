"""The lock of an output target: one tirecli run at a time writes into a directory or file.

A staged run (:mod:`tirecli.io.staging`) holds a lock file ``.NAME.tirecli-lock`` beside the target for
the whole run: a second run into the same target is refused naming the process that holds it. The lock is
an advisory ``flock`` on that file, which the kernel releases when its process ends, so a lock file left by
a killed run is stale and taken over; the file holds the holder's pid, host, start time and command (one
JSON line).
"""
from __future__ import annotations

import contextlib
import json
import os
import socket
import sys
import time
from pathlib import Path

from tirecli.errors import UsageError

LOCK = "tirecli-lock"

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None


def _try_lock(fd: int) -> bool:
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        else:  # pragma: no cover - Windows: lock the first byte
            import msvcrt

            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    except OSError:
        return False
    return True


def _holder(fd: int) -> str:
    """Who holds a lock: ``pid N on HOST, started TIME: COMMAND`` from its lock file."""
    for _ in range(20):  # the holder writes its record just after taking the lock
        try:
            os.lseek(fd, 0, os.SEEK_SET)
            info = json.loads(os.read(fd, 4096).decode("utf-8"))
            started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(float(info["started"])))
            command = str(info.get("command", ""))
            command = command if len(command) <= 80 else command[:77] + "..."
            return f"pid {int(info['pid'])} on {info.get('host', '?')}, started {started}: {command}"
        except (OSError, ValueError, KeyError, TypeError):
            time.sleep(0.05)
    return "a process whose lock record cannot be read"


class _Lock:
    """An exclusive, non-blocking lock on ``path`` for the output ``target``; UsageError when a live
    process holds it. The lock file is removed on release."""

    def __init__(self, path: Path, target: Path):
        self.path, self.target, self.fd = path, target, -1

    def __enter__(self) -> _Lock:
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise UsageError(f"--out {self.target}: cannot create the lock file {self.path} "
                                 f"({exc.strerror})") from None
            if not _try_lock(fd):
                who = _holder(fd)
                os.close(fd)
                raise UsageError(f"--out {self.target}: in use by another tirecli run ({who}); "
                                 "wait for it to finish or choose another --out")
            try:  # the holder before us may have removed the file after we opened it: lock the new one
                same = os.path.samestat(os.fstat(fd), os.stat(self.path))
            except OSError:
                same = False
            if same:
                break
            os.close(fd)
        else:  # pragma: no cover - another process keeps replacing the lock file
            raise UsageError(f"--out {self.target}: cannot take the lock {self.path}")
        record = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time(),
                  "command": "tirecli " + " ".join(sys.argv[1:])}
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, (json.dumps(record) + "\n").encode("utf-8"))
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        os.close(self.fd)
