"""Benchmark: tirecli at scale (issue 15): large sweeps, many-case simulations, ``mf eval`` of many
rows, and campaigns (``tirecli campaign``).

Run: ``python benchmarks/bench_scale.py [--only sweep,simulate,mf,campaign] [--repeat N] [--points N]
[--scaling-points N] [--skip-serial] [--skip-dask] [--skip-figures]`` (after ``pip install '.[campaign]'``).
Prints Markdown tables; the README quotes their numbers. Every number is the real command in a
subprocess, with the machine's load average beside it.

Sections:

- ``sweep``: a 10^6-point LuGre sweep (distributed model, uniform load; 100 000 slips x 10 speeds) with
  ``--format csv`` and ``--format parquet``. Targets: under 3 s wall and 300 MB peak.
- ``simulate``: one config of 100 lumped-LuGre emergency brakings (cases with different kappa0 and
  brake torques, 6 s, output every 1 ms), and the same with 50 cases (memory flat in the cases).
  Target: under 5 s.
- ``mf``: ``tirecli mf eval`` of a 10^6-row points CSV (built-in MF 6.1 tyre). Target: under 2.5 s.
- ``campaign``: below.

Campaign scenario: a Monte Carlo campaign of lumped-LuGre emergency brakings (FM Table 2 tyre, kappa0(Z),
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


SWEEP = """study: sweep
title: "10^6-point sweep"
tire: canudas2003-table1
sweep:
  slip: {start: -1, stop: 1, num: 100000}
  speeds: [5, 10, 15, 20, 25, 30, 35, 40, 45, 50]
  models: [distributed]
"""


def simulate_config(cases: int) -> str:
    """A simulate config of ``cases`` lumped brakings (kappa0 1.5 or Z, peak torques 600-1200 N m)."""
    rows = [f"  - {{model: lumped, kappa0: {'Z' if i % 2 else 1.5}, label: c{i:03d}, input: {{brake_torque: "
            f"{{initial: 0, changes: [{{at: 0.1, duration: 0.3, to: {600 + 600 * i // max(cases - 1, 1)}, "
            f"shape: linear}}]}}}}}}" for i in range(cases)]
    return BASE.split("cases:")[0].replace("emergency braking from 20 m/s, lumped kappa0(Z)",
                                          f"{cases} emergency brakings") + "cases:\n" + "\n".join(rows) + "\n"


def write_points(path: Path, n: int) -> None:
    """A points CSV of ``n`` rows (kappa, alpha, gamma, fz), seeded."""
    import numpy as np

    rng = np.random.default_rng(1)
    cols = [np.round(rng.uniform(-0.3, 0.3, n), 6), np.round(rng.uniform(-0.2, 0.2, n), 6),
            np.round(rng.uniform(-0.05, 0.05, n), 6), np.round(rng.uniform(2000, 6000, n), 1)]
    with path.open("w") as fh:
        fh.write("kappa,alpha,gamma,fz\n")
        for lo in range(0, n, 100_000):
            fh.write("".join(f"{a!r},{b!r},{c!r},{d!r}\n" for a, b, c, d in zip(*(x[lo:lo + 100_000].tolist() for x in cols))))


def measured(cmd: list[str]) -> tuple[float, float, float]:
    """``(wall [s], peak resident memory [MB], CPU [s])`` of the command run to its end (exit 0 required)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"failed ({proc.returncode}): {' '.join(cmd)}")
    return wall, usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime


def cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "tirecli.cli.main", "--quiet", *args]


def scale_sections(only: set, repeat: int) -> list[tuple]:
    """Rows ``(what, wall, peak MB, CPU, target, load average)`` of the sweep, simulate and mf sections (best
    wall time of ``repeat`` runs)."""
    rows = []

    def best(label, target, cmd):
        load = os.getloadavg()[0]
        runs = [measured(cmd) for _ in range(repeat)]
        wall, cpu = min((r[0], r[2]) for r in runs)
        rows.append((label, wall, max(r[1] for r in runs), cpu, target, load))
        print(f"  {label}: {wall:.2f} s, {rows[-1][2]:.0f} MB, CPU {cpu:.2f} s (load {load:.1f})", file=sys.stderr)

    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        if "sweep" in only:
            (d / "sweep.yaml").write_text(SWEEP)
            for fmt in ("csv", "parquet"):
                best(f"`sweep` 10^6 points, `--format {fmt}`", "< 3 s, < 300 MB",
                     cli("sweep", str(d / "sweep.yaml"), "--out", str(d / f"sweep-{fmt}"), "--format", fmt))
        if "simulate" in only:
            for n in (50, 100):
                (d / f"sim{n}.yaml").write_text(simulate_config(n))
                best(f"`simulate` {n} brakings in one config", "< 5 s (100), memory flat",
                     cli("simulate", str(d / f"sim{n}.yaml"), "--out", str(d / f"sim{n}")))
        if "mf" in only:
            write_points(d / "points.csv", 1_000_000)
            best("`mf eval` 10^6 rows", "< 2.5 s",
                 cli("mf", "eval", "pacejka2006-205-60r15", "--points", str(d / "points.csv"), "--out", str(d / "mf.csv")))
    return rows


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


SECTIONS = ("sweep", "simulate", "mf", "campaign")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", default=",".join(SECTIONS), help=f"sections to run, comma-separated ({', '.join(SECTIONS)})")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each sweep/simulate/mf command (best wall time)")
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--scaling-points", type=int, default=None,
                    help="points of the 1-worker and Dask runs [default: --points, the same campaign]")
    ap.add_argument("--skip-serial", action="store_true")
    ap.add_argument("--skip-dask", action="store_true")
    ap.add_argument("--skip-figures", action="store_true")
    args = ap.parse_args()
    only = {s.strip() for s in args.only.split(",") if s.strip()}
    unknown = only - set(SECTIONS)
    if unknown:
        ap.error(f"--only: unknown section(s) {', '.join(sorted(unknown))} (choose from {', '.join(SECTIONS)})")
    print(f"load average before: {os.getloadavg()[0]:.2f} (2 cores; above ~0.5 the numbers are not comparable)")
    rows = scale_sections(only, args.repeat)
    if rows:
        print()
        print("| command | wall [s] | peak RSS [MB] | CPU [s] | target | load average |")
        print("|---|---:|---:|---:|---|---:|")
        for label, wall, mb, cpu, target, load in rows:
            print(f"| {label} | {wall:.2f} | {mb:.0f} | {cpu:.2f} | {target} | {load:.1f} |")
        print()
    if "campaign" in only:
        campaign(args)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


def campaign(args) -> None:
    """The campaign section (see the module doc)."""
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


if __name__ == "__main__":
    main()
