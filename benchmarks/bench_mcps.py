"""Benchmark: the MCPS tire (Sorine & Szymanski 2000) -- stationary curves, standstill, relaxation, examples.

Run: ``python benchmarks/bench_mcps.py`` (after ``pip install .``). Prints a Markdown table; the
README quotes its numbers. Goals (issue 11), on the 2-core machine:

- a stationary complete-model curve of 200 points (belt fixed point, MCPS eq. 18) under 0.2 s;
- the +-0.45 rad standstill study (two cycles, converged patch quadrature) under 1 s;
- a 4 m relaxation run (complete model, 1 deg at 20 m/s, 100 cells) under 1 s;
- each MCPS example end to end (start-up, study, CSV, PNG + SVG) under 3 s.

Times are the best of repeated runs (the machine's noise only ever adds time).
"""
from __future__ import annotations

import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench_transient import best_of  # noqa: E402 (same folder: (min time, last result) of repeated runs)

ROOT = Path(__file__).resolve().parents[1]


def stationary():
    from tirecli.numerics.mcps_stationary import solve
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("sorine2000-mcps").model()
    a = np.radians(np.linspace(0, 12, 200))
    k = np.linspace(-0.1, 0.1, 200)
    phi = np.linspace(0, 0.1, 200)
    rows = []
    t, r = best_of(lambda: solve(p, 4000, 0 * a, a, 0 * a))
    rows.append(("stationary complete model, 200 slip angles 0-12 deg (fixed point to 1e-10 Fz)", t, 0.2,
                 f"{r.iterations} Newton iterations"))
    t, r = best_of(lambda: solve(p, 4000, k, np.radians(4), 0 * k))
    rows.append(("stationary complete model, combined slip, 200 kappa at 4 deg", t, 0.2, f"{r.iterations} iterations"))
    t, r = best_of(lambda: solve(p, 2000, 0 * phi, 0 * phi, phi))
    rows.append(("stationary complete model, 200 curvatures (patch integrated in d)", t, None, f"{r.iterations} iterations"))
    t, r = best_of(lambda: solve(p, 4000, 0 * a, a, 0 * a, carcass="rigid"))
    rows.append(("stationary solid carcass, 200 slip angles (closed form)", t, None, ""))
    return rows


def transient():
    from tirecli.numerics.mcps_transient import simulate_rolling
    from tirecli.parameters.sets import load_builtin
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    p = load_builtin("sorine2000-mcps").model()
    rows = []
    t, _ = best_of(lambda: run_study(builtin_config("mcps-fig4-5")), 3)
    rows.append(("standstill study +-0.45 rad, two cycles (24 Gauss nodes per half, 81-point distribution)", t, 1.0,
                 "exact steps"))
    a = math.radians(1.0)
    t, run = best_of(lambda: simulate_rolling(p, 4000, 20.0, 20.0 * math.tan(a), 20.0, 0.0, 4.0, cells=100), 3)
    rows.append(("relaxation run, complete model, 1 deg, 20 m/s, 4 m, 100 cells", t, 1.0, f"{run.t.size - 1} steps"))
    t, run = best_of(lambda: simulate_rolling(p, 4000, 20.0, 20.0 * math.tan(a), 20.0, 0.0, 4.0, cells=100,
                                              carcass="rigid"), 3)
    rows.append(("relaxation run, solid carcass, same", t, None, f"{run.t.size - 1} steps"))
    return rows


def examples():
    exe = shutil.which("tirecli") or f"{sys.executable} -m tirecli.cli.main"
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for cfg in sorted((ROOT / "examples").glob("mcps-*.yaml")):
            command = "compare" if "mcps-stationary" in cfg.read_text() else "simulate"
            cmd = exe.split() + ["--quiet", command, str(cfg), "--out", str(Path(tmp) / cfg.stem)]
            walls = []
            for _ in range(3):
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True)
                walls.append(time.perf_counter() - t0)
            rows.append((f"`tirecli {command} examples/{cfg.name}`", min(walls), 3.0, "end to end"))
    return rows


def main():
    rows = stationary() + transient() + examples()
    print("| what | time | goal | note |")
    print("|---|---|---|---|")
    for what, t, goal, note in rows:
        tt = f"{t * 1e3:.1f} ms" if t < 1 else f"{t:.2f} s"
        g = "" if goal is None else (f"< {goal:g} s " + ("(met)" if t < goal else "(NOT met)"))
        print(f"| {what} | {tt} | {g} | {note} |")


if __name__ == "__main__":
    main()
