"""No worker outlives its command (issue 24, item 2): the process-pool workers of a campaign and of a report,
a Dask LocalCluster's workers and the helper process that writes a long table all end within seconds of their
parent's death, however it dies (here SIGKILL, as a CI timeout sends: no handler of the parent runs).

Linux only (the descendants are read from /proc). The deadline is generous (a worker ends within a second:
the kernel's parent-death signal, or its watch of the parent twice a second); how fast is not measured here.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from harness import BASE_CMD, _env

pytestmark = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="reads the process tree from /proc")

ROOT = Path(__file__).resolve().parents[2]
#: Seconds the workers of a killed command may take to end (they take about one).
DEADLINE = 10.0


def _children(pid: int) -> list[int]:
    out = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return out


def descendants(pid: int) -> list[int]:
    found, todo = [], [pid]
    while todo:
        for child in _children(todo.pop()):
            found.append(child)
            todo.append(child)
    return found


def running(pid: int) -> bool:
    """Whether ``pid`` is a live process (a zombie waiting for its new parent to reap it is not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def kill_and_watch(cmd, cwd, workers: int, env=None) -> list[int]:
    """Start ``cmd``, wait until it has ``workers`` descendant processes, SIGKILL it alone; returns the
    descendants still running after :data:`DEADLINE` seconds (each then killed, so that none is left)."""
    proc = subprocess.Popen([str(c) for c in cmd], cwd=cwd, env=_env(env), stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    seen: list[int] = []
    try:
        t0 = time.monotonic()
        while len(seen) < workers:
            assert proc.poll() is None, f"it ended before its workers started: {proc.stderr.read()[-800:]}"
            assert time.monotonic() - t0 < 120, "no worker processes appeared"
            seen = descendants(proc.pid)
            time.sleep(0.05)
        time.sleep(0.5)  # the workers at work
        seen = sorted(set(seen) | set(descendants(proc.pid)))
    finally:
        proc.kill()
        proc.wait()
    t0 = time.monotonic()
    while any(map(running, seen)) and time.monotonic() - t0 < DEADLINE:
        time.sleep(0.1)
    left = [pid for pid in seen if running(pid)]
    for pid in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    return left


def _campaign(tmp_path, n: int = 400) -> Path:
    text = (ROOT / "examples" / "campaign-fm-fig4-mc.yaml").read_text(encoding="utf-8")
    text = text.replace("base: fm-fig4.yaml", "base: fm-fig4").replace("\n  n: 1000\n", f"\n  n: {n}\n")
    path = tmp_path / "mc.yaml"
    path.write_text(text)
    return path


def test_the_workers_of_a_killed_campaign_end(tmp_path):
    left = kill_and_watch(BASE_CMD + ["campaign", _campaign(tmp_path), "--out", "o", "--jobs", "2"], tmp_path, 2)
    assert not left, f"worker(s) {left} outlived the campaign"


@pytest.mark.slow  # a LocalCluster takes seconds to start; Dask ends its workers itself (a guard of that)
def test_the_dask_workers_of_a_killed_campaign_end(tmp_path):
    pytest.importorskip("distributed")
    left = kill_and_watch(BASE_CMD + ["campaign", _campaign(tmp_path), "--out", "o", "--jobs", "2", "--scheduler",
                                      "local"], tmp_path, 2)
    assert not left, f"Dask worker(s) {left} outlived the campaign"


def test_the_workers_of_a_killed_report_end(tmp_path):
    cmd = BASE_CMD + ["report", "--out", "r", "--cache", "c", "--no-cache", "--jobs", "2",
                      "--only", "fm-fig4", "--only", "fm-fig7"]
    left = kill_and_watch(cmd, tmp_path, 2)
    assert not left, f"worker(s) {left} outlived the report"


HELPER = """
import time
import pandas as pd
from tirecli.io.output import SpooledFrame

def parts():  # the helper computes for ever
    while True:
        time.sleep(0.05)
        yield pd.DataFrame({"t": [0.0]})

spool = SpooledFrame(["t"])
spool.extend(parts(), background=True)
time.sleep(600)
"""


def test_the_helper_process_of_a_killed_run_ends(tmp_path):
    """The forked helper that formats a long table (:class:`tirecli.io.output.SpooledFrame`, used by simulate)."""
    left = kill_and_watch([sys.executable, "-c", HELPER], tmp_path, 1)
    assert not left, f"the helper {left} outlived its parent"


def test_a_worker_whose_parent_died_before_it_started_ends_at_once(tmp_path):
    """The parent may die between the fork and the worker's initializer: the worker notices and ends."""
    code = ("import os, sys\nfrom tirecli.parallel import die_with_parent\n"
            "die_with_parent((os.getppid() + 1, True))\nprint('still here')\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, env=_env())
    assert (p.returncode, p.stdout) == (1, "")
