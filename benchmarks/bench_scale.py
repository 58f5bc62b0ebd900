"""Benchmark: campaigns at scale (``tirecli campaign``).

Run: ``python benchmarks/bench_scale.py [--points N] [--skip-serial] [--skip-dask]`` (after
``pip install '.[campaign]'``). Prints a Markdown table; the README quotes its numbers.

Scenario: a Monte Carlo campaign of lumped-LuGre emergency brakings (FM Table 2 tyre, kappa0(Z),
OBS quarter car, 20 m/s, brake torque ramped over 0.3 s to a sampled peak and held until the car
stops or 6 s), N latin-hypercube samples of the tyre's sigma0, mu_c, mu_s, the road adhesion theta
and the peak torque; outputs peak |slip|, stopping distance, final speed; a campaign check
(stopping distance <= 40 m). Each configuration runs the real command in a fresh output
directory, without figures (``figures: false``; the figures are timed separately).

Targets (issue 15): 10 000 points under 60 s on the 2-core machine; 2 workers at least 1.8x faster
than 1; a 2-worker Dask LocalCluster within 1.3x of the local pool. The machine's load average is
printed: numbers measured while other work runs are not comparable.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BASE = """study: simulate
title: "emergency braking from 20 m/s, lumped kappa0(Z)"
tire: canudas2003-table2
vehicle: canudas2003-obs-quarter-car
initial: {v: 20, slip: 0}
input:
  brake_torque: {initial: 0, changes: [{at: 0.1, duration: 0.3, to: 900, shape: linear}]}
t_end: 6
cases: [{model: lumped, kappa0: Z, label: braking}]
"""

CAMPAIGN = """campaign: braking-mc
base: base.yaml
sample:
  n: {n}
  seed: 1
  method: latin-hypercube
  tire.sigma0: {{normal: [178, 9]}}
  tire.mu_c: {{uniform: [0.7, 0.9]}}
  tire.mu_s: {{uniform: [1.35, 1.65]}}
  input.theta: {{uniform: [0.5, 1.0]}}
  input.brake_torque.changes[0].to: {{uniform: [600, 1200]}}
outputs: [peak_abs_slip, stopping_distance, v_final]
checks: [{{output: stopping_distance, max: 40}}]
figures: {figures}
"""


def run(workdir: Path, n: int, jobs: int, scheduler: str | None = None, figures: bool = False) -> tuple[float, dict]:
    camp = workdir / f"c{n}.yaml"
    camp.write_text(CAMPAIGN.format(n=n, figures="true" if figures else "false"))
    out = Path(tempfile.mkdtemp(dir=workdir))
    cmd = [sys.executable, "-m", "tirecli.cli.main", "--quiet", "campaign", str(camp), "--out", str(out / "o"), "-j", str(jobs)]
    if scheduler:
        cmd += ["--scheduler", scheduler]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    return wall, json.loads((out / "o" / "summary.json").read_text())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--scaling-points", type=int, default=2_000, help="points of the 1-vs-2-worker and Dask runs")
    ap.add_argument("--skip-serial", action="store_true")
    ap.add_argument("--skip-dask", action="store_true")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores; above ~0.5 the numbers are not comparable)")
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        (d / "base.yaml").write_text(BASE)
        rows = []
        wall, s = run(d, args.points, 2)
        rows.append((f"{args.points} points, local pool, 2 workers", wall, s))
        n = args.scaling_points
        w2, s2 = run(d, n, 2)
        rows.append((f"{n} points, local pool, 2 workers", w2, s2))
        if not args.skip_serial:
            w1, s1 = run(d, n, 1)
            rows.append((f"{n} points, 1 worker (in-process)", w1, s1))
        if not args.skip_dask:
            wd, sd = run(d, n, 2, scheduler="local")
            rows.append((f"{n} points, Dask LocalCluster, 2 workers (start-up included)", wd, sd))
        wf, sf = run(d, n, 2, figures=True)
        rows.append((f"{n} points, local pool, 2 workers, with the 7 analysis figures", wf, sf))
        print()
        print("| campaign | wall [s] | points/s | ok | failed |")
        print("|---|---:|---:|---:|---:|")
        for label, wall, s in rows:
            p = s["points"]
            print(f"| {label} | {wall:.1f} | {p['total'] / wall:.0f} | {p['ok']} | {p['failed']} |")
        print()
        if not args.skip_serial:
            print(f"2 workers vs 1: {w1 / w2:.2f}x faster (target >= 1.8x)")
        if not args.skip_dask:
            print(f"Dask LocalCluster vs local pool: {wd / w2:.2f}x the time (target <= 1.3x)")
        print(f"{args.points} points: {rows[0][1]:.1f} s (target < 60 s); batch {rows[0][2]['execution'].get('batch')} points")
        st = rows[0][2]["analysis"]["statistics"]["stopping_distance"]
        print(f"stopping distance: median {st['median']:.2f} m, p95 {st['p95']:.2f} m, max {st['max']:.2f} m")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
