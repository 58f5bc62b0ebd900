"""Benchmark: how fast tirecli refuses hostile inputs (nothing hangs, nothing exhausts memory).

Run: ``python benchmarks/bench_refusals.py [--quick]`` (after ``pip install .``). Each input goes
through the real ``tirecli`` in a subprocess; the table gives the best wall time of a few runs, the
CPU time of that run, and the exit code. Goal: every refusal in under 2 s wall, start-up included,
with exit code 2 and one line (the tests in ``tests/robustness/test_budgets.py`` check the exit code
and the line; this script measures the time). Wall times grow on a loaded machine (start-up above
all): the load average at the time is printed.
"""
from __future__ import annotations

import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
GOAL = 2.0
_SCRIPT = Path(sys.executable).with_name("tirecli")
BASE = [str(_SCRIPT)] if _SCRIPT.exists() else [sys.executable, "-m", "tirecli.cli.main"]

#: A one-case braking whose brake pressure is the formula PRESSURE.
SIMULATE = ("study: simulate\ntire: canudas2003-table2\ninitial: {v: 20, slip: 0}\n"
            "input: {pressure: {expr: 'PRESSURE'}}\nt_end: 1\ncases: [lumped]\n")


def inputs(d: Path) -> list:
    """``(what, args)`` of each hostile input, written into ``d``."""
    def write(name, text):
        (d / name).write_text(text, encoding="utf-8")
        return str(d / name)

    bomb = ['study: sweep\na0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    bomb += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    (d / "points.csv").write_text("kappa,alpha,gamma,fz\n" + "0.1,0,0,4000\n" * 2_000_000, encoding="ascii")
    for name in ("fm-fig1-left.yaml", "fm-fig4.yaml", "obs-fig2.yaml"):
        shutil.copyfile(EXAMPLES / name, d / name)
    out = ["-o", str(d / "out")]
    return [
        ("formula `9**9**9` (`params validate`)", ["params", "validate", write("f.yaml", SIMULATE.replace("PRESSURE", "9**9**9"))]),
        ("formula switching 25,000 times in a 1 s run", ["simulate", write("s.yaml", SIMULATE.replace(
            "PRESSURE", "10*(sin(2*pi*12345.6*t) > 0)"))] + out),
        ("YAML billion laughs (10^9 values, 600 bytes)", ["params", "validate", write("bomb.yaml", "\n".join(bomb) + "\n")]),
        ("YAML recursive alias", ["params", "validate", write("rec.yaml", "study: sweep\na: &a [1, *a]\n")]),
        ("YAML of 20,001 values", ["params", "validate", write("flat.yaml", "study: sweep\nx: [" + ",".join(["0.5"] * 20_001) + "]\n")]),
        ("title of 100,000 characters", ["sweep", str(d / "fm-fig1-left.yaml"), "--set", "title=" + "x" * 100_000] + out),
        ("sweep grid 10^4 x 10^4", ["sweep", str(d / "fm-fig1-left.yaml"), "--set", "sweep.slip={start: -1, stop: 0, num: 10000}",
                                     "--set", "sweep.speeds={start: 1, stop: 30, num: 10000}"] + out),
        ("simulate `output.dt: 1e-9`", ["simulate", str(d / "fm-fig4.yaml"), "--set", "output.dt=1e-9"] + out),
        ("simulate `t_end: 3600`", ["simulate", str(d / "fm-fig4.yaml"), "--set", "t_end=3600"] + out),
        ("observe `solver.step: 1e-12`", ["observe", str(d / "obs-fig2.yaml"), "--set", "solver.step=1e-12"] + out),
        ("`mf eval` of a 2,000,000-row points file", ["mf", "eval", "chrono-185-80r14", "--points", str(d / "points.csv"),
                                                      "-o", str(d / "r.csv")]),
        ("start-up floor: `tirecli --help`", ["--help"]),
    ]


def measure(args, repeat: int):
    """Best wall time of ``repeat`` runs, the CPU time of that run and its exit code."""
    best = None
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        p = subprocess.run(BASE + args, capture_output=True, text=True, timeout=600,
                           env={**os.environ, "MPLBACKEND": "Agg"})
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
        if best is None or wall < best[0]:
            best = (wall, cpu, p.returncode, len([ln for ln in p.stderr.splitlines() if ln.strip()]))
    return best


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    repeat = 1 if "--quick" in argv else 3
    print(f"load average {os.getloadavg()[0]:.1f}, best of {repeat}\n")
    print("| hostile input | wall | CPU | exit | lines |")
    print("|---|---|---|---|---|")
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for what, args in inputs(Path(tmp)):
            wall, cpu, code, lines = measure(args, repeat)
            if args != ["--help"]:
                worst = max(worst, wall)
            print(f"| {what} | {wall:.2f} s | {cpu:.2f} s | {code} | {lines} |")
    print(f"\nGoal: every refusal under {GOAL:g} s wall: {'met' if worst < GOAL else 'NOT met'} (slowest {worst:.2f} s).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
