"""Benchmark: Magic Formula combined-slip Fx, Fy, Mz over 10^6 points, and `tirecli mf eval`.

Run: ``python benchmarks/bench_mf.py [--quick]`` (after ``pip install .``). Prints a Markdown
table; the README quotes its numbers. Goals (issue 6): Fx, Fy and Mz together over 10^6 points
in under 0.5 s on a 2-core machine (under 500 ns a point; the fastest public evaluator reports
about 0.9 us a point), also given as a ratio to a bare numpy ``exp`` over the same array; and
``tirecli mf eval`` on a 10^6-row CSV end to end in under 5 s.

Every input varies from point to point (random slip, slip angle, camber and load), which is the
worst case: a sweep at fixed load and camber is faster because load terms are computed once.
The tyre is mfeval's MF 6.1 sample (``mfeval-255-55r20``: every coefficient group non-zero,
pressure and camber terms included). Timing is the best of several repeats; the machine load
at the time is printed, because other processes on a shared machine slow the numbers down.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_steady_state import best_of  # noqa: E402  (the shared timing helper)

ROOT = Path(__file__).resolve().parents[1]
N = 1_000_000


def inputs(n=N, seed=0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-0.3, 0.3, n), rng.uniform(-0.2, 0.2, n), rng.uniform(-0.05, 0.05, n),
            rng.uniform(2000.0, 9000.0, n))


def evaluator(repeat):
    """Best-of-``repeat`` times of each case, the cases taken in turn (round robin) so that every
    case sees the same mix of quiet and busy moments on a shared machine."""
    from tirecli.models.magic_formula import evaluate
    from tirecli.parameters.mf import load_builtin_tire_data

    tire = load_builtin_tire_data("mfeval-255-55r20").tire()
    k, a, g, fz = inputs()
    out = ("fx", "fy", "mz")
    fz0 = tire["FNOMIN"]
    evaluate(tire, k[:1000], a[:1000], g[:1000], fz[:1000], outputs=out)  # warm-up (thread pool)
    cases = [
        ("Fx+Fy+Mz, 10^6 points, all inputs varying, default threads", lambda: evaluate(tire, k, a, g, fz, outputs=out)),
        ("same, one thread", lambda: evaluate(tire, k, a, g, fz, outputs=out, threads=1)),
        ("same, zero camber (no second Fy0 for Mz), default threads", lambda: evaluate(tire, k, a, 0.0, fz, outputs=out)),
        ("same, teasit convention, default threads",
         lambda: evaluate(tire, k, a, g, fz, outputs=out, convention="teasit")),
        ("Fx+Fy+Mz sweep at fixed load and zero camber (kappa, alpha vary)",
         lambda: evaluate(tire, k, a, 0.0, fz0, outputs=out)),
        ("all five outputs Fx, Fy, Mz, Mx, My, all inputs varying", lambda: evaluate(tire, k, a, g, fz)),
        ("numpy exp over the same array (floor)", lambda: np.exp(k)),
    ]
    best = {label: float("inf") for label, _ in cases}
    for _ in range(repeat):
        for label, fn in cases:
            best[label] = min(best[label], best_of(fn, 1))
    t_exp = best[cases[-1][0]]
    return [(label, t, t / N * 1e9, t / t_exp) for label, t in best.items()]


def cli_eval(repeat=3):
    """``tirecli mf eval`` end to end (process start, CSV read, evaluation, CSV write) on 10^6 rows."""
    import pandas as pd

    tmp = Path(tempfile.mkdtemp(prefix="tirecli-bench-mf-"))
    try:
        k, a, g, fz = inputs()
        pts = tmp / "points.csv"
        pd.DataFrame({"kappa": k, "alpha": a, "gamma": g, "fz": fz}).to_csv(pts, index=False)
        exe = shutil.which("tirecli")
        cmd = ([exe] if exe else [sys.executable, "-m", "tirecli.cli.main"]) + [
            "mf", "eval", "mfeval-255-55r20", "--points", str(pts), "--out", str(tmp / "out.csv"), "--quiet"]
        walls = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, capture_output=True)
            walls.append(time.perf_counter() - t0)
        return [("tirecli mf eval, 10^6-row CSV, end to end (start-up included)", min(walls), None, None)]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def main():
    quick = "--quick" in sys.argv
    repeat = 3 if quick else 7
    print(f"machine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} (before), "
          f"python {sys.version.split()[0]}, numpy {np.__version__}")
    rows = evaluator(repeat)
    if "--no-cli" not in sys.argv:
        rows += cli_eval(2 if quick else 3)
    print()
    print("| what | time | per point | ratio to numpy exp |")
    print("|---|---|---|---|")
    for label, t, ns, ratio in rows:
        per = f"{ns:.0f} ns" if ns is not None else ""
        rat = f"{ratio:.1f}x" if ratio is not None else ""
        print(f"| {label} | {t * 1e3:.0f} ms | {per} | {rat} |")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
