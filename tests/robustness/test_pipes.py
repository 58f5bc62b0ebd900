"""A closed output pipe (issue 24, item 13): ``tirecli params list | head -1`` ends quietly.

The reader of tirecli's output may go away before it has read everything (``head -1``). Then the rest
of the output is dropped, nothing is printed on stderr, the command finishes its work and exits with its
own code: 0 when all went well (the choice documented in :mod:`tirecli.cli.main`).
"""
from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

from harness import BASE_CMD, _env

ROOT = Path(__file__).resolve().parents[2]


def _to_closed_pipe(args, cwd) -> subprocess.CompletedProcess:
    """Run tirecli with stdout a real pipe whose reading end is already closed: its first write fails (EPIPE)."""
    r, w = os.pipe()
    os.close(r)
    try:
        return subprocess.run(BASE_CMD + [str(a) for a in args], stdout=w, stderr=subprocess.PIPE, text=True,
                              cwd=cwd, env=_env(), stdin=subprocess.DEVNULL, timeout=120)
    finally:
        os.close(w)


@pytest.mark.parametrize("args", [["params", "list"], ["--help"], ["figures", "list"]], ids=" ".join)
def test_a_closed_pipe_ends_the_listing_quietly(tmp_path, args):
    p = _to_closed_pipe(args, tmp_path)
    assert (p.returncode, p.stderr) == (0, "")


def test_a_run_whose_reader_left_still_writes_its_results(tmp_path):
    """The run's output lines go nowhere, its results are written all the same, and its exit code is its own."""
    p = _to_closed_pipe(["sweep", ROOT / "examples" / "fm-fig1-left.yaml", "--out", "o"], tmp_path)
    assert (p.returncode, p.stderr) == (0, "")
    assert (tmp_path / "o" / "run.json").is_file() and (tmp_path / "o" / "data" / "sweep.csv").is_file()


def test_head_reads_the_first_line(tmp_path):
    """Through a shell pipeline into head (with pipefail, so tirecli's own exit code counts)."""
    cmd = " ".join(f"'{a}'" for a in BASE_CMD) + " params list | head -1"
    p = subprocess.run(["bash", "-c", f"set -o pipefail; {cmd}"], capture_output=True, text=True, cwd=tmp_path,
                       env=_env(), timeout=120)
    assert p.returncode == 0 and p.stderr == "" and len(p.stdout.splitlines()) == 1
