"""Benchmark: ``tirecli report`` cold, from the cache, after one changed parameter; ``tirecli --help``.

Run: ``python benchmarks/bench_report.py [--jobs N] [--only NAME ...]`` from a checkout. The script
copies the package (with ``docs/``) into a temporary folder and runs that copy through
``python -m tirecli`` in a subprocess, so it can change a parameter without touching the checkout:

1. cold: a new output folder, no cache (every study runs, every figure is drawn);
2. cached: the same folder again, nothing changed (every study from the cache);
3. one changed parameter: ``PDX1`` (peak friction) of the built-in tyre ``chrono-185-80r14``,
   which two studies read (the MF-LuGre comparison and that tyre's sweeps): only they run;
4. ``tirecli --help`` (the start-up floor).

Goals (issue 14): cold under 10 s on the 2-core machine, cached under 3 s, ``--help`` under 0.3 s.
Wall times grow on a loaded machine: the load average before each run is printed beside it, and
the CPU time (user + system, the report's worker processes included), which grows much less.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TYRE = "chrono-185-80r14"


def load() -> str:
    return "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def run(pkg: Path, args: list[str]) -> tuple[float, str, float]:
    """Wall time [s], the load average before, and the CPU time [s] (user + system, with the
    report's worker processes) of ``tirecli ARGS``."""
    env = dict(os.environ, PYTHONPATH=str(pkg), MPLBACKEND="Agg")
    before = load()
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "tirecli", *args], env=env, capture_output=True, text=True,
                          cwd=pkg)  # not the checkout: ``-m`` imports from the working directory first
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"tirecli {' '.join(args)} failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, before, after.ru_utime + after.ru_stime - ru.ru_utime - ru.ru_stime


def ran(out: Path) -> str:
    summary = json.loads((out / "summary.json").read_text())
    cached = summary["study_cached"]
    return f"{sum(not c for c in cached.values())} of {len(cached)} studies ran, {summary['n_figures']} figures"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=None, help="--jobs of the report (default: every core)")
    ap.add_argument("--only", action="append", default=[], help="--only of the report (repeatable)")
    ap.add_argument("--repeat", type=int, default=3, help="runs of the quick cases (the best is shown)")
    opts = ap.parse_args()
    extra = [a for name in opts.only for a in ("--only", name)]
    if opts.jobs:
        extra += ["--jobs", str(opts.jobs)]
    rows = []
    with tempfile.TemporaryDirectory(prefix="tirecli-bench-report-") as tmp:
        pkg, out = Path(tmp) / "pkg", Path(tmp) / "report"
        shutil.copytree(ROOT / "tirecli", pkg / "tirecli", ignore=shutil.ignore_patterns("__pycache__"))
        shutil.copytree(ROOT / "docs", pkg / "docs")
        run(pkg, ["--version"])  # compile the copy's bytecode outside the timings
        where = subprocess.run([sys.executable, "-c", "import tirecli; print(tirecli.__file__)"], cwd=pkg, text=True,
                               env=dict(os.environ, PYTHONPATH=str(pkg)), capture_output=True).stdout
        assert where.startswith(str(pkg)), f"the copy is not the package imported: {where}"
        report = ["report", "--out", str(out), "--quiet", *extra]

        rows.append(("cold: new folder, no cache", *run(pkg, report), ran(out)))

        best = min((run(pkg, report) for _ in range(opts.repeat)), key=lambda r: r[0])
        rows.append(("cached: nothing changed", *best, ran(out)))

        tir = pkg / "tirecli" / "parameters" / "data" / f"{TYRE}.tir"
        text = tir.read_text()
        assert "PDX1                     = 1.09 " in text
        tir.write_text(text.replace("PDX1                     = 1.09 ", "PDX1                     = 1.10 ", 1))
        rows.append((f"one changed parameter (PDX1 of {TYRE})", *run(pkg, report), ran(out)))

        best = min((run(pkg, ["--help"]) for _ in range(max(opts.repeat, 5))), key=lambda r: r[0])
        rows.append(("`tirecli --help`", *best, ""))

    print(f"\n`python benchmarks/bench_report.py{' ' + ' '.join(sys.argv[1:]) if sys.argv[1:] else ''}` "
          f"({os.cpu_count()} cores, Python {sys.version.split()[0]}):\n")
    print("| what | wall [s] | CPU [s] | load average before (1, 5, 15 min) | work |")
    print("|---|---|---|---|---|")
    for what, wall, before, cpu, work in rows:
        print(f"| {what} | {wall:.2f} | {cpu:.2f} | {before} | {work} |")
    goals = [("cold < 10 s", rows[0][1] < 10), ("cached < 3 s", rows[1][1] < 3), ("--help < 0.3 s", rows[3][1] < 0.3)]
    print("\nGoals: " + ", ".join(f"{g} ({'met' if ok else 'NOT met'})" for g, ok in goals))


if __name__ == "__main__":
    main()
