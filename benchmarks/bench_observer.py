"""Benchmark: the 20 s OBS Fig. 2 plant + observer run, fast scheme against ``solve_ivp``.

Run: ``python benchmarks/bench_observer.py`` (after ``pip install .``). Prints a Markdown table.
Goal (issue 4): the 20 s Fig. 2 run in under 0.3 s of simulation wall time, with the ratio to a
straightforward ``scipy.integrate.solve_ivp`` implementation of the same coupled 7-state system
(plant by ``tirecli.models.quarter_car.rhs``, observer by OBS (14); one call over [0, 20] s)
measured in the same run. Accuracy is the largest deviation from the spec's reference
integration (Radau, rtol 1e-8, max step 5 ms, split at the profile breakpoints).
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from bench_transient import best_of  # noqa: E402 (same folder: (min time, last result) of repeated runs)

ROOT = Path(__file__).resolve().parents[1]


def setup():
    from tirecli.studies.base import builtin_config
    from tirecli.studies.observe import plan

    p = plan(builtin_config("obs-fig2"))
    return p.plant, p.cases[0].gains, p.cases[0].scenario


def straightforward(plant, gains, sc, method, rtol, atol):
    """One ``solve_ivp`` call on the full coupled system (no structure, no breakpoint splitting)."""
    from scipy.integrate import solve_ivp

    from tirecli.numerics.observer_integrator import full_rhs

    f = full_rhs(plant, gains, sc)
    c = plant.car
    x0 = [sc.v0, sc.omega0, sc.z0, c.r * c.m * sc.vhat0 + c.J * sc.omega0, c.J * sc.omega0 + plant.P * sc.z_hat0,
          sc.z_hat0, sc.theta_hat0]
    t_eval = np.arange(0.0, sc.duration + 1e-9, 0.005)
    sol = solve_ivp(f, (0.0, sc.duration), x0, method=method, rtol=rtol, atol=atol, t_eval=t_eval)
    v, w, z, eh, ch, zh, th = sol.y
    return sol.t, th, plant.speed_from_eta(eh, w) - v, sol.nfev


def deviation(t, th, dv, ref):
    both = np.arange(0.0, 20.0, 0.005)
    return (float(np.max(np.abs(np.interp(both, t, th) - np.interp(both, ref.t, ref.theta_hat)))),
            float(np.max(np.abs(np.interp(both, t, dv) - np.interp(both, ref.t, ref.v_hat - ref.v)))))


def main() -> None:
    from tirecli.numerics import observer_integrator as oi

    plant, gains, sc = setup()
    print("Reference: Radau rtol 1e-8, max step 5 ms, split at breakpoints (observer.md §7) ...", file=sys.stderr)
    t0 = time.perf_counter()
    ref = oi.simulate_reference(plant, gains, sc)
    t_ref = time.perf_counter() - t0

    rows = []
    for step in (oi.DEFAULT_STEP, 1e-3):
        t_fast, tr = best_of(lambda: oi.simulate_fast(plant, gains, sc, step=step), repeat=5)
        dth, ddv = deviation(tr.t, tr.theta_hat, tr.v_hat - tr.v, ref)
        rows.append((f"fast scheme, step {step * 1e3:g} ms (best of 5)", t_fast, dth, ddv, tr.info["steps"]))
    t_main = rows[0][1]
    for method, rtol, atol in (("Radau", 1e-3, 1e-6), ("Radau", 1e-6, 1e-9), ("BDF", 1e-6, 1e-9), ("LSODA", 1e-6, 1e-9)):
        print(f"solve_ivp {method} rtol {rtol:g} ...", file=sys.stderr)
        t1 = time.perf_counter()
        try:
            t, th, dv, nfev = straightforward(plant, gains, sc, method, rtol, atol)
            el = time.perf_counter() - t1
            dth, ddv = deviation(t, th, dv, ref)
        except Exception as exc:  # noqa: BLE001 - a failing baseline is a result too
            el, dth, ddv, nfev = time.perf_counter() - t1, float("nan"), float("nan"), f"failed: {exc}"
        rows.append((f"solve_ivp {method}, rtol {rtol:g}, atol {atol:g}", el, dth, ddv, f"{nfev} rhs calls"))
    rows.append(("reference: Radau rtol 1e-8, max step 5 ms, split at breakpoints", t_ref, 0.0, 0.0, "-"))

    print("| integration of the 20 s OBS Fig. 2 run | wall time [s] | x fast | max abs(theta_hat dev.) "
          "| max abs((v_hat - v) dev.) [m/s] | steps / work |")
    print("|---|---:|---:|---:|---:|---|")
    for name, el, dth, ddv, work in rows:
        print(f"| {name} | {el:.3f} | {el / t_main:.1f} | {dth:.1e} | {ddv:.1e} | {work} |")
    print()
    print(f"Goal: 20 s run < 0.3 s of simulation wall time: {'met' if t_main < 0.3 else 'MISSED'} "
          f"({t_main:.3f} s at the default step).")

    exe = shutil.which("tirecli")
    if exe:
        with tempfile.TemporaryDirectory() as tmp:
            t1 = time.perf_counter()
            subprocess.run([exe, "--quiet", "observe", str(ROOT / "examples" / "obs-fig2.yaml"), "--out", tmp],
                           check=True, stdout=subprocess.DEVNULL)
            print(f"`tirecli observe examples/obs-fig2.yaml` (start-up, run, CSV, PNG+SVG): "
                  f"{time.perf_counter() - t1:.2f} s wall")


if __name__ == "__main__":
    main()
