"""Benchmark: campaigns at scale (``tirecli campaign``).

Run: ``python benchmarks/bench_scale.py [--points N] [--scaling-points N] [--skip-serial] [--skip-dask]
[--skip-figures]`` (after ``pip install '.[campaign]'``). Prints a Markdown table; the README quotes its
numbers.

Scenario: a Monte Carlo campaign of lumped-LuGre emergency brakings (FM Table 2 tyre, kappa0(Z),
OBS quarter car, 20 m/s, brake torque ramped over 0.3 s to a sampled peak and held until the car
stops or 6 s), N latin-hypercube samples of the tyre's sigma0, mu_c, mu_s, the road adhesion theta
and the peak torque; outputs peak |slip|, stopping distance, final speed; a campaign check
(stopping distance <= 40 m). Each configuration runs the real command in a fresh output
directory, without figures (``figures: false``; the figures are timed separately).

Targets (issue 15): 10 000 points under 60 s on the 2-core machine; 2 workers at least 1.8x faster
than 1; a 2-worker Dask LocalCluster within 1.3x of the local pool (the same campaign). The machine's
load average is printed: wall times measured while other work runs are not comparable, so the CPU
time (user + system) of the command and of its workers is printed too, and an idle-core estimate
from them (:func:`critical_cpu`).
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


#: Runs the command and writes its CPU times (this process, and its worker processes once they have
#: ended: the pool's, or the Dask nannies' and workers') as JSON to the file named by TIRECLI_BENCH_CPU.
_WRAP = """
import atexit, json, os, resource, sys
pid = os.getpid()
def _cpu():
    if os.getpid() != pid:
        return
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(os.environ["TIRECLI_BENCH_CPU"], "w") as fh:
        json.dump({"parent": s.ru_utime + s.ru_stime, "workers": c.ru_utime + c.ru_stime}, fh)
atexit.register(_cpu)
from tirecli.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def run(workdir: Path, n: int, jobs: int, scheduler: str | None = None, figures: bool = False) -> dict:
    """One campaign through the real command: ``{"wall", "parent", "workers", "load", "summary"}`` (seconds;
    ``parent``/``workers``: CPU time, user + system, of the command's own process and of its workers)."""
    camp = workdir / f"c{n}.yaml"
    camp.write_text(CAMPAIGN.format(n=n, figures="true" if figures else "false"))
    out = Path(tempfile.mkdtemp(dir=workdir))
    cmd = [sys.executable, "-c", _WRAP, "--quiet", "campaign", str(camp), "--out", str(out / "o"), "-j", str(jobs)]
    if scheduler:
        cmd += ["--scheduler", scheduler]
    load = os.getloadavg()[0]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, env={**os.environ, "TIRECLI_BENCH_CPU": str(out / "cpu.json")})
    wall = time.perf_counter() - t0
    cpu = json.loads((out / "cpu.json").read_text())
    return {"wall": wall, **cpu, "load": max(load, os.getloadavg()[0]),
            "summary": json.loads((out / "o" / "summary.json").read_text())}


def critical_cpu(r: dict) -> float:
    """The wall time the run would take on idle cores, from its CPU times: the command's own work is
    serial (start-up, design, checks, results) and the workers' is shared evenly between them."""
    return r["parent"] + r["workers"] / max(r["summary"]["execution"]["workers"], 1)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--scaling-points", type=int, default=None,
                    help="points of the 1-worker and Dask runs [default: --points, the same campaign]")
    ap.add_argument("--skip-serial", action="store_true")
    ap.add_argument("--skip-dask", action="store_true")
    ap.add_argument("--skip-figures", action="store_true")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores; above ~0.5 the wall times are not comparable:"
          " compare the CPU columns)")
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        (d / "base.yaml").write_text(BASE)
        rows = {}
        n = args.scaling_points or args.points
        rows["pool"] = (f"{args.points} points, local pool, 2 workers", run(d, args.points, 2))
        if n != args.points:
            rows["pool-n"] = (f"{n} points, local pool, 2 workers", run(d, n, 2))
        pool = rows.get("pool-n", rows["pool"])[1]
        if not args.skip_serial:
            rows["serial"] = (f"{n} points, 1 worker (in-process)", run(d, n, 1))
        if not args.skip_dask:
            rows["dask"] = (f"{n} points, Dask LocalCluster, 2 workers (start-up included)", run(d, n, 2, scheduler="local"))
        if not args.skip_figures:
            nf = min(n, 2000)
            rows["figures"] = (f"{nf} points, local pool, 2 workers, with the 7 analysis figures", run(d, nf, 2, figures=True))
        print()
        print("| campaign | wall [s] | CPU: command [s] | CPU: workers [s] | idle-core estimate [s] | points/s | ok | failed | load |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for label, r in rows.values():
            p = r["summary"]["points"]
            print(f"| {label} | {r['wall']:.1f} | {r['parent']:.1f} | {r['workers']:.1f} | {critical_cpu(r):.1f} | "
                  f"{p['total'] / r['wall']:.0f} | {p['ok']} | {p['failed']} | {r['load']:.1f} |")
        print()
        print("idle-core estimate: the command's CPU time plus the workers' divided by their number (serial work"
              " and evenly shared batches; a loaded machine inflates CPU times a little, not this ratio)")
        if not args.skip_serial:
            s = rows["serial"][1]
            print(f"2 workers vs 1: {s['wall'] / pool['wall']:.2f}x faster by wall time, "
                  f"{critical_cpu(s) / critical_cpu(pool):.2f}x by the idle-core estimate (target >= 1.8x)")
        if not args.skip_dask:
            k = rows["dask"][1]
            print(f"Dask LocalCluster vs local pool: {k['wall'] / pool['wall']:.2f}x the time by wall, "
                  f"{critical_cpu(k) / critical_cpu(pool):.2f}x by the idle-core estimate (target <= 1.3x)")
        first = rows["pool"][1]
        print(f"{args.points} points: {first['wall']:.1f} s wall, {critical_cpu(first):.1f} s idle-core estimate "
              f"(target < 60 s); batch {first['summary']['execution'].get('batch')} points")
        st = first["summary"]["analysis"]["statistics"]["stopping_distance"]
        print(f"stopping distance: median {st['median']:.2f} m, p95 {st['p95']:.2f} m, max {st['max']:.2f} m")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
