"""Benchmark: identification with the distributed model in the loop (``tirecli fit``, ``fit.model: distributed``).

Run: ``python benchmarks/bench_fit.py`` (after ``pip install .``). Prints a Markdown table; the README
quotes its numbers.

Scenario: a 3.5 s braking below the force peak like FM's braking #2 (prescribed smooth kinematics,
slip to about -0.19, speed 20 -> 6 m/s), Table 2 tire, 351 samples at 100 Hz. The reference ``mu(t)``
comes from an independent solver (tests/driven_reference.py: DOP853 at rtol 1e-12 plus adaptive
quadrature over the patch).

Rows:

- one evaluation of the open-loop distributed model at the samples: tirecli's vectorised solution
  (:class:`tirecli.numerics.driven.DrivenDistributed`) and, for comparison, the ROS2 characteristics
  stepper of ``simulate`` (:func:`tirecli.numerics.runs.open_loop`) at the loosest tolerance that
  reaches the same accuracy (or its tightest tried), with the speed-up;
- the distributed-model fit of all six parameters from the FM procedure's biased start values
  (mu_c 1.41, v_s 1.50, sigma1 1.27) on the noise-free reference data: wall time, model evaluations,
  largest relative error of the generating parameters;
- the whole ``tirecli fit examples/fm-fig6.yaml`` (synthetic braking #2 of FM Fig. 4, figures
  included) with ``model: distributed`` (as shipped) and with ``model: lumped``, and its stage-3 time.

Goals (issue 12, item 8): the fm-fig6 example stays within a few seconds (under 6 s wall on the 2-core
development machine, start-up and four figures included) and the distributed-model stage takes under 1 s.
"""
from __future__ import annotations

import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

START = {"sigma0": 179.58, "sigma1": 1.2666, "sigma2": 0.0, "mu_c": 1.4078, "mu_s": 1.5045, "v_s": 1.498}


def braking_v(t):
    return 20.0 - 4.0 * t + 0.3 * np.sin(2.0 * t)


def braking_rw(t):
    return braking_v(t) * (1.0 - 0.18 * np.sin(np.pi * t / 3.5) ** 2 * (1.0 + 0.1 * np.sin(4.0 * t)))


def best_of(fn, repeat=5):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def stepper_mu(p, car, t, tol):
    """mu at the samples from the ROS2 characteristics stepper driven open loop by the same kinematics."""
    from tirecli.models.profiles import Constant
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs

    tf = np.linspace(0.0, t[-1], 3501)
    eps = 1e-6
    dv = (braking_v(tf + eps) - braking_v(tf - eps)) / (2 * eps)
    drw = (braking_rw(tf + eps) - braking_rw(tf - eps)) / (2 * eps)
    vp = runs.HermiteProfile(tf, braking_v(tf), dv)
    wp = runs.HermiteProfile(tf, braking_rw(tf) / car.r, drw / car.r)
    opts = runs.SolverOptions(tol=tol)
    tr = runs.open_loop(FrictionVariant("distributed"), p, car, vp, wp, Constant(1.0), float(t[-1]), opts)
    return np.interp(t, tr.t, tr.out["mu"]), tr.stats["steps"]


def main():
    from driven_reference import reference_mu

    from tirecli.numerics.driven import DrivenDistributed
    from tirecli.numerics.identify import fit_distributed
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("canudas2003-table2").model()
    car = load_builtin("canudas2003-obs-quarter-car").model()
    t = np.round(np.arange(351) * 0.01, 10)
    v, rw = braking_v(t), braking_rw(t)
    mu_ref = reference_mu(braking_v, braking_rw, p, t)

    model = DrivenDistributed(t, v, rw, p.L)
    t_model, mu = best_of(lambda: model.mu(p), 7)
    e_model = float(np.max(np.abs(mu - mu_ref)))
    rows = [("tirecli vectorised distributed model, one evaluation (351 samples, substeps 4 + 8)", t_model, "-",
             f"{e_model:.1e}")]
    stepper = None
    for tol in (1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7):
        m, steps = stepper_mu(p, car, t, tol)
        e = float(np.max(np.abs(m - mu_ref)))
        stepper = (tol, steps, e)
        if e <= e_model:
            break
    tol, steps, e = stepper
    t_step, _ = best_of(lambda: stepper_mu(p, car, t, tol), 3)
    reached = "equal accuracy" if e <= e_model else "its tightest tried"
    rows.append((f"ROS2 characteristics stepper (simulate's), open loop, tol {tol:g} ({reached}), {steps} steps",
                 t_step, "-", f"{e:.1e}"))

    start = replace(p, **START)
    t_fit, (res, _, _) = best_of(lambda: fit_distributed(t, v, rw, mu_ref, start), 3)
    worst = max(abs(res.estimate[k] / getattr(p, k) - 1) for k in ("sigma0", "sigma1", "mu_c", "mu_s", "v_s"))
    rows.append(("distributed-model fit of 6 parameters from the FM procedure's start, noise-free reference data",
                 t_fit, str(res.nfev), f"max rel. parameter error {worst:.1e}"))

    import json
    import tempfile

    out = Path(tempfile.mkdtemp(prefix="bench-fit-"))

    import resource

    def cli(*extra):
        """(wall, CPU) seconds of one run in a fresh interpreter."""
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "tirecli.cli.main", "--quiet", "fit", str(ROOT / "examples" / "fm-fig6.yaml"),
                        "--out", str(out), *extra], check=True, stdout=subprocess.DEVNULL)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        return time.perf_counter() - t0, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)

    lumped = [cli("--set", "fit.model=lumped") for _ in range(3)]
    dist = [cli() for _ in range(3)]
    t_lumped, c_lumped = min(x[0] for x in lumped), min(x[1] for x in lumped)
    t_dist, c_dist = min(x[0] for x in dist), min(x[1] for x in dist)
    run = json.loads((out / "run.json").read_text())
    stage3 = run["meta"]["distributed"]["wall_time_s"]
    rows.append((f"tirecli fit examples/fm-fig6.yaml (model: distributed, as shipped; figures included; CPU "
                 f"{c_dist:.2f} s)", t_dist, str(run["meta"]["distributed"]["nfev"]), f"stage 3 alone {stage3:.2f} s"))
    rows.append((f"the same with --set fit.model=lumped (FM procedure only; CPU {c_lumped:.2f} s)", t_lumped, "-", "-"))

    print(f"python {sys.version.split()[0]}, best of several runs\n")
    print("| what | wall time | model evaluations | accuracy |")
    print("|---|---|---|---|")
    for what, tt, n, acc in rows:
        ts = f"{tt * 1e3:.1f} ms" if tt < 1 else f"{tt:.2f} s"
        print(f"| {what} | {ts} | {n} | {acc} |")
    print()
    print(f"speed-up of one model evaluation over the stepper: {t_step / t_model:.0f}x")
    print(f"goal fm-fig6 example under 6 s: {'met' if t_dist < 6.0 else 'MISSED'} ({t_dist:.2f} s wall, "
          f"{c_dist:.2f} s CPU; +{c_dist - c_lumped:.2f} s CPU over the FM procedure alone)")
    print(f"goal distributed-model stage under 1 s: {'met' if stage3 < 1.0 else 'MISSED'} ({stage3:.2f} s)")


if __name__ == "__main__":
    main()
