"""Ctrl-C in the middle of a report that runs its studies in a process pool (issue 14): the previous
report stays byte-identical (its cache may have gained entries), and no staging, lock or worker
process is left."""
from __future__ import annotations

import json
import os
import signal
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from harness import BASE_CMD, run, snapshot

#: fm-fig4 and fm-fig7 (two transient studies of a few seconds each) run in two workers; fm-fig1-left is quick.
ONLY = ["--only", "fm-fig1-left", "--only", "fm-fig4", "--only", "fm-fig7"]


def _report_files(out: Path) -> dict:
    return snapshot(out)


def _children(pid: int) -> list[int]:
    try:
        return [int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def test_ctrl_c_during_a_parallel_report_keeps_the_previous_report(tmp_path):
    out = tmp_path / "rep"
    r = run(["report", "--out", out, "--quiet", "--only", "fm-fig1-left", "--jobs", "1"], timeout=120)
    assert r.code == 0, r.err
    before = _report_files(out)
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.Popen(BASE_CMD + ["report", "--out", str(out), "--jobs", "2", "--no-cache", *ONLY],
                            cwd=tmp_path, env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    workers = []
    try:
        t0 = time.monotonic()
        while len(workers) < 2:  # both workers started: the studies are running
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() - t0 < 60, "no worker processes appeared"
            workers = _children(proc.pid)
            time.sleep(0.05)
        time.sleep(0.5)
        os.killpg(proc.pid, signal.SIGINT)  # as a terminal does: to the report and its workers (one group)
        code = proc.wait(timeout=60)
    finally:
        proc.kill()
    err = proc.stderr.read()
    assert (code, err) == (130, f"error: interrupted: previous results in {out} kept\n")
    assert _report_files(out) == before
    assert sorted(os.listdir(tmp_path)) == ["rep"]  # no staging, no lock
    time.sleep(0.5)
    assert all(not Path(f"/proc/{pid}").exists() or "zombie" in Path(f"/proc/{pid}/status").read_text()
               for pid in workers), "a worker outlived the report"
    assert json.loads((out / "summary.json").read_text())["study_cached"] == {"fm-fig1-left": False}


@pytest.fixture(scope="module")
def cached_report(tmp_path_factory) -> Path:
    """A cache holding the entry of fm-fig1-left (its study files and its figure's card)."""
    d = tmp_path_factory.mktemp("cached")
    r = run(["report", "--out", d / "rep", "--cache", d / "cache", "--quiet", "--only", "fm-fig1-left", "--jobs", "1"],
            timeout=120)
    assert r.code == 0, r.err
    return d


@pytest.mark.parametrize("damage, what", [("fifo", "manifest.json"), ("fifo", "fm-fig1-left.png"),
                                          ("dev-zero", "sweep.csv"), ("link-out", "card.json")])
def test_a_cache_entry_that_is_no_regular_file_is_recomputed(cached_report, tmp_path, damage, what):
    """A cache entry's file replaced by a FIFO (a read would wait for a writer for ever), a link to /dev/zero (a read
    would never end) or a link out of the cache (to a file with the very bytes the entry expects) is a miss: the study
    runs again (as for a damaged entry), within the time limit, and the entry is rewritten."""
    cache = tmp_path / "cache"
    shutil.copytree(cached_report / "cache", cache)
    target = next(cache.glob(f"v1/fm-fig1-left/*/**/{what}"))
    outside = tmp_path / "outside"
    outside.write_bytes(target.read_bytes())
    target.unlink()
    {"fifo": lambda: os.mkfifo(target), "dev-zero": lambda: os.symlink("/dev/zero", target),
     "link-out": lambda: os.symlink(outside, target)}[damage]()
    r = run(["report", "--out", tmp_path / "rep", "--cache", cache, "--quiet", "--only", "fm-fig1-left", "--jobs", "1"],
            timeout=60)
    assert r.code == 0, r.err
    cached = json.loads((tmp_path / "rep" / "summary.json").read_text())["study_cached"]
    assert cached == {"fm-fig1-left": False}
    assert next(cache.glob(f"v1/fm-fig1-left/*/**/{what}")).is_file() and not target.is_symlink()
