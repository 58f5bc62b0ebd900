"""Run the real ``tirecli`` in a subprocess and check the error contract (issue 13).

Every robustness test goes through :func:`run`: the installed console script (or ``python -m
tirecli.cli.main`` when there is none), a wall-clock limit, stdout/stderr captured. The contract
for an input at fault: exit 2, exactly one line on stderr starting with ``error:``, no traceback,
no file content beyond the offending token; outputs that existed before are byte-identical after.

:func:`run_warm` runs a command the same way in a process forked from a warm ``tirecli``
(:mod:`forkserver`: the imports done once), for the corpus of many short commands; set
``TIRECLI_ROBUSTNESS_SCRIPT=1`` to run those through the console script too.
"""
from __future__ import annotations

import atexit
import hashlib
import json
import os
import queue
import re
import select
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

#: The console script next to this interpreter (a venv's bin/), else the module.
_SCRIPT = Path(sys.executable).with_name("tirecli")
BASE_CMD = [str(_SCRIPT)] if _SCRIPT.exists() else [sys.executable, "-m", "tirecli.cli.main"]


@dataclass
class Result:
    code: int
    out: str
    err: str
    elapsed: float

    @property
    def lines(self) -> list[str]:
        return [ln for ln in self.err.splitlines() if ln.strip()]


def _env(env=None) -> dict:
    e = dict(os.environ)
    e.setdefault("MPLBACKEND", "Agg")
    e["COLUMNS"] = "200"
    if env:
        e.update(env)
    return e


def run(args, cwd=None, timeout: float = 20.0, env=None, stdin=None) -> Result:
    """Run ``tirecli ARGS`` and return its exit code, output and wall time; a run over ``timeout`` s fails the
    test (the process group is killed: nothing may hang)."""
    e = _env(env)
    t0 = time.perf_counter()
    try:
        p = subprocess.run(BASE_CMD + [str(a) for a in args], cwd=cwd, env=e, capture_output=True, text=True,
                           timeout=timeout, stdin=subprocess.DEVNULL if stdin is None else stdin)
    except subprocess.TimeoutExpired as exc:
        raise AssertionError(f"tirecli {' '.join(map(str, args))} did not finish within {timeout} s") from exc
    return Result(p.returncode, p.stdout, p.stderr, time.perf_counter() - t0)


class ForkServer:
    """One :mod:`forkserver` process: a warm ``tirecli`` that runs each command in a forked child."""

    def __init__(self):
        env = _env({"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"})
        self.proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name("forkserver.py"))],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                     env=env, text=True, bufsize=1)
        self.tmp = tempfile.mkdtemp(prefix="tirecli-forkserver-")
        self._answer(120.0)  # {"ready": true} once the imports are done

    def _answer(self, timeout: float) -> dict:
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        line = self.proc.stdout.readline() if ready else ""
        if not line:
            self.close()
            raise AssertionError("the fork server did not answer")
        return json.loads(line)

    def run(self, args, cwd, timeout: float, env=None) -> Result:
        out, err = os.path.join(self.tmp, "out"), os.path.join(self.tmp, "err")
        for p in (out, err):
            open(p, "wb").close()
        req = {"args": [str(a) for a in args], "cwd": str(cwd or os.getcwd()), "env": _env(env),
               "timeout": timeout, "out": out, "err": err}
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        ans = self._answer(timeout + 60.0)
        if ans["timed_out"]:
            raise AssertionError(f"tirecli {' '.join(map(str, args))} did not finish within {timeout} s")
        with open(out, encoding="utf-8", errors="replace") as fo, open(err, encoding="utf-8", errors="replace") as fe:
            return Result(ans["code"], fo.read(), fe.read(), ans["elapsed"])

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.stdin.close()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        shutil.rmtree(self.tmp, ignore_errors=True)


_SERVERS: queue.Queue = queue.Queue()
_STARTED: list = []
_START_LOCK = threading.Lock()


def run_warm(args, cwd=None, timeout: float = 20.0, env=None, servers: int = 2) -> Result:
    """:func:`run`, in a child forked from a warm ``tirecli`` (:mod:`forkserver`); thread-safe, up to ``servers``
    commands at once. ``TIRECLI_ROBUSTNESS_SCRIPT=1`` runs the console script instead."""
    if os.environ.get("TIRECLI_ROBUSTNESS_SCRIPT"):
        return run(args, cwd=cwd, timeout=timeout, env=env)
    with _START_LOCK:
        if len(_STARTED) < servers and _SERVERS.empty():
            server = ForkServer()
            _STARTED.append(server)
            _SERVERS.put(server)
    server = _SERVERS.get()
    try:
        return server.run(args, cwd, timeout, env)
    finally:
        _SERVERS.put(server)


@atexit.register
def _stop_servers() -> None:
    for server in _STARTED:
        server.close()


def assert_clean_error(r: Result, code: int = 2, pattern: str | None = None, max_seconds: float | None = None) -> None:
    """Exit ``code``, one ``error:`` line on stderr (no traceback), matching ``pattern`` (regex, case-insensitive)."""
    assert "Traceback" not in r.err and "Traceback" not in r.out, r.err[-2000:]
    assert r.code == code, f"exit {r.code}, expected {code}; stderr: {r.err[-800:]}"
    lines = [ln for ln in r.lines if not ln.startswith("warning:")]
    assert len(lines) == 1 and lines[0].startswith("error:"), f"expected one 'error:' line, got: {r.err[-800:]!r}"
    if pattern is not None:
        assert re.search(pattern, lines[0], re.I), f"{lines[0]!r} does not match {pattern!r}"
    if max_seconds is not None:
        assert r.elapsed < max_seconds, f"took {r.elapsed:.1f} s (limit {max_seconds} s)"


def snapshot(directory) -> dict:
    """``{relative path: sha256}`` of every file under ``directory`` (empty if it does not exist)."""
    d = Path(directory)
    if not d.exists():
        return {}
    return {str(p.relative_to(d)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(d.rglob("*")) if p.is_file()}


def assert_unchanged(before: dict, directory) -> None:
    after = snapshot(directory)
    assert after == before, f"{directory} changed: {sorted(set(after.items()) ^ set(before.items()))[:6]}"


def assert_no_leak(r: Result, secret: str) -> None:
    """No line of ``secret`` (a file's content) appears in the output beyond an 80-character token."""
    for ln in secret.splitlines():
        ln = ln.strip()
        if len(ln) > 80:
            assert ln not in r.out and ln not in r.err, "a file's content was printed"


def copy_example(name: str, dest) -> Path:
    """Copy ``examples/NAME`` to ``dest`` and return the copy."""
    src = Path(__file__).resolve().parents[2] / "examples" / name
    dst = Path(dest) / src.name
    shutil.copyfile(src, dst)
    return dst
