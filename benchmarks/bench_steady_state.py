"""Benchmark: LuGre steady state over 10^6 (slip, v) points, and `tirecli sweep` per example.

Run: ``python benchmarks/bench_steady_state.py`` (after ``pip install .``). Prints a Markdown
table; the README quotes its numbers. Goals (issue 2): the uniform-load steady state over 10^6
points in under 0.1 s on a 2-core machine, also given as a ratio to a bare numpy ``exp`` over
the same array (the practical floor); ``tirecli sweep`` on each example under 2 s wall,
start-up included. Also the root-found peaks of 1000 curves (issue 12), which every sweep computes.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def best_of(fn, repeat=7):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def steady_state(n=1_000_000):
    from tirecli.conventions import speeds_from_slip
    from tirecli.models.lugre import mu_ss_lumped, mu_ss_uniform
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("canudas2003-table1").model()
    rng = np.random.default_rng(0)
    s = -rng.uniform(0, 1, n)
    v, rw = speeds_from_slip(s, rng.uniform(1, 30, n))
    vr = rw - v
    t_model = best_of(lambda: mu_ss_uniform(vr, rw, p))
    t_lumped = best_of(lambda: mu_ss_lumped(vr, rw, p, "Z"))
    t_exp = best_of(lambda: np.exp(vr))
    return [
        ("uniform-load steady state (FM eq. 4), 10^6 points", t_model, t_model / t_exp),
        ("lumped steady state with kappa0(Z) (FM eq. 10), 10^6 points", t_lumped, t_lumped / t_exp),
        ("numpy exp over the same array (floor)", t_exp, 1.0),
    ] + peaks(p)


def peaks(p, n=1000):
    """Root-found peaks (slip to 1e-12) of n braking curves at held speeds 1-30 m/s."""
    from tirecli.models.steady_peaks import curve_peaks
    from tirecli.models.variants import FrictionVariant

    speeds = np.linspace(1.0, 30.0, n)
    t_u = best_of(lambda: curve_peaks(FrictionVariant(), p, speeds), repeat=3)
    t_p = best_of(lambda: curve_peaks(FrictionVariant(load="parabolic"), p, speeds), repeat=3)
    return [(f"root-found peaks of {n} curves, uniform load (FM eq. 4)", t_u, None),
            (f"root-found peaks of {n} curves, parabolic load (quadrature)", t_p, None)]


def import_floor():
    """Wall time of a bare interpreter importing numpy, pandas and matplotlib (start-up floor)."""
    walls = []
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import numpy, pandas, matplotlib.figure"], check=True)
        walls.append(time.perf_counter() - t0)
    return [("python -c 'import numpy, pandas, matplotlib.figure' (start-up floor)", min(walls), None)]


def cli_sweeps():
    exe = shutil.which("tirecli") or f"{sys.executable} -m tirecli.cli.main"
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for cfg in sorted((ROOT / "examples").glob("*.yaml")):
            if "study: sweep" not in cfg.read_text():
                continue
            cmd = exe.split() + ["--quiet", "sweep", str(cfg), "--out", str(Path(tmp) / cfg.stem)]
            walls = []
            for _ in range(3):
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True)
                walls.append(time.perf_counter() - t0)
            rows.append((f"tirecli sweep examples/{cfg.name}", min(walls), None))
    return rows


def main():
    rows = steady_state() + import_floor() + cli_sweeps()
    print("| what | time | ratio to numpy exp |")
    print("|---|---|---|")
    for what, t, ratio in rows:
        r = f"{ratio:.1f}x" if ratio is not None else ""
        print(f"| {what} | {t * 1e3:.1f} ms | {r} |" if t < 1 else f"| {what} | {t:.2f} s | {r} |")


if __name__ == "__main__":
    main()
