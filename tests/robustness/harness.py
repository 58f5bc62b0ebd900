"""Run the real ``tirecli`` in a subprocess and check the error contract (issue 13).

Every robustness test goes through :func:`run`: the installed console script (or ``python -m
tirecli.cli.main`` when there is none), a wall-clock limit, stdout/stderr captured. The contract
for an input at fault: exit 2, exactly one line on stderr starting with ``error:``, no traceback,
no file content beyond the offending token; outputs that existed before are byte-identical after.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
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


def run(args, cwd=None, timeout: float = 20.0, env=None, stdin=None) -> Result:
    """Run ``tirecli ARGS`` and return its exit code, output and wall time; a run over ``timeout`` s fails the
    test (the process group is killed: nothing may hang)."""
    e = dict(os.environ)
    e.setdefault("MPLBACKEND", "Agg")
    e["COLUMNS"] = "200"
    if env:
        e.update(env)
    t0 = time.perf_counter()
    try:
        p = subprocess.run(BASE_CMD + [str(a) for a in args], cwd=cwd, env=e, capture_output=True, text=True,
                           timeout=timeout, stdin=subprocess.DEVNULL if stdin is None else stdin)
    except subprocess.TimeoutExpired as exc:
        raise AssertionError(f"tirecli {' '.join(map(str, args))} did not finish within {timeout} s") from exc
    return Result(p.returncode, p.stdout, p.stderr, time.perf_counter() - t0)


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
