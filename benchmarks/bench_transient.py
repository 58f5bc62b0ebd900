"""Benchmark: a 5 s quarter-car braking with the lumped and the distributed LuGre tire.

Run: ``python benchmarks/bench_transient.py`` (after ``pip install .``). Prints a Markdown table;
the README quotes its numbers. Scenario (docs/models/lugre_friction.md §7): Table 2 tire, OBS quarter car, v0 = 20 m/s,
brake torque ramp 0 -> 1000 N m over 0.5-2.0 s, linear release over 2.0-2.6 s, 5 s simulated.

Goals (issue 3): lumped model under 20 ms, distributed model at default resolution under 0.5 s;
a straightforward ``scipy.integrate.solve_ivp(method="Radau")`` of the same lumped equations
(:func:`tirecli.models.quarter_car.rhs`, finite-difference Jacobian) timed at equal accuracy, with
the speed-up (goal: at least 5x).

Second table (issue 12): a 1100 N m braking that locks the wheel (linear release over 2.0-2.6 s),
the lock and unlock times against an independent Radau reference with event location (rtol 1e-9,
tests/reference_quarter_car.py), and the 1 ms output grid of the 5 s braking: the cost of sampling it
from the dense output and its mu error against the reference, beside linear interpolation of the steps.

Accuracy is the largest deviation of slip and friction from a tight reference at each method's
own output points (Radau rtol 1e-11 for the lumped model; tirecli at tol 1e-7 for the distributed
one). "Equal accuracy": the loosest Radau tolerance whose slip and friction errors are both at
most tirecli's.
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

T_END = 5.0


def best_of(fn, repeat=7):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def setup():
    from tirecli.models.profiles import Change, Constant, Transitions
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("canudas2003-table2").model()
    car = load_builtin("canudas2003-obs-quarter-car").model()
    torque = Transitions(0.0, (Change(0.5, -1000.0, 1.5, "linear"), Change(2.0, 0.0, 0.6, "linear")))
    return p, car, torque, Constant(1.0)


def radau_lumped(p, car, torque, rtol):
    """The straightforward implementation: solve_ivp(Radau) on quarter_car.rhs, default FD Jacobian."""
    from scipy.integrate import solve_ivp

    from tirecli.models.lugre_lumped import LumpedTire
    from tirecli.models.quarter_car import QuarterCar, rhs

    qc = QuarterCar(tire=LumpedTire(p, "Z"), car=car)

    def f(t, x):
        return rhs(t, x, (torque.at(t), 1.0), qc)

    return solve_ivp(f, (0.0, T_END), [20.0, 20.0 / car.r, 0.0], method="Radau", rtol=rtol,
                     atol=[rtol * 1.0, rtol * 4.0, rtol * 1e-3], dense_output=True)


def lumped_outputs(p, car, torque, t, y):
    """Slip and friction along a lumped solution (FM eqs. (8)-(9))."""
    from tirecli.conventions import slip_from_speeds
    from tirecli.models.lugre_lumped import LumpedTire
    from tirecli.models.quarter_car import QuarterCar, outputs

    qc = QuarterCar(tire=LumpedTire(p, "Z"), car=car)
    mu = np.array([outputs(tk, y[:, k], (torque.at(tk), 1.0), qc)["mu"] for k, tk in enumerate(t)])
    return slip_from_speeds(y[0], y[1], car.r), mu


def main():
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs

    p, car, torque, theta = setup()
    lumped = FrictionVariant("lumped", kappa0="Z")
    dist = FrictionVariant("distributed")

    def run_lumped():
        return runs.quarter_car(lumped, p, car, torque, theta, 20.0, 20.0 / car.r, T_END)

    def run_pde():
        return runs.quarter_car(dist, p, car, torque, theta, 20.0, 20.0 / car.r, T_END)

    run_lumped()  # warm up imports
    t_lumped, tr = best_of(run_lumped, 11)
    t_pde, trp = best_of(run_pde, 3)

    ref = radau_lumped(p, car, torque, 1e-11)
    s_ref, mu_ref = lumped_outputs(p, car, torque, tr.t, ref.sol(tr.t))
    e_s = float(np.max(np.abs(tr.out["slip"] - s_ref)))
    e_mu = float(np.max(np.abs(tr.out["mu"] - mu_ref)))

    rows = [("tirecli lumped kappa0(Z), 5 s braking (default tol 1e-3)", t_lumped, tr.stats["steps"], e_s, e_mu)]
    radau = None
    for rtol in (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 3e-7, 1e-7):
        sol = radau_lumped(p, car, torque, rtol)
        s_r, mu_r = lumped_outputs(p, car, torque, sol.t, sol.y)
        s_x, mu_x = lumped_outputs(p, car, torque, sol.t, ref.sol(sol.t))
        es, emu = float(np.max(np.abs(s_r - s_x))), float(np.max(np.abs(mu_r - mu_x)))
        if es <= e_s and emu <= e_mu:
            t_r, sol = best_of(lambda: radau_lumped(p, car, torque, rtol), 3)
            radau = (f"scipy solve_ivp Radau on quarter_car.rhs, rtol {rtol:g} (equal accuracy)", t_r, sol.t.size,
                     es, emu)
            break
    if radau is not None:
        rows.append(radau)

    # distributed: accuracy against its own tight solution
    refp = runs.quarter_car(dist, p, car, torque, theta, 20.0, 20.0 / car.r, T_END, runs.SolverOptions(tol=1e-7))
    e_sp = float(np.max(np.abs(trp.out["slip"] - np.interp(trp.t, refp.t, refp.out["slip"]))))
    e_mup = float(np.max(np.abs(trp.out["mu"] - np.interp(trp.t, refp.t, refp.out["mu"]))))
    rows.append(("tirecli distributed (exact along characteristics), 5 s braking (default tol 3e-4)", t_pde,
                 trp.stats["steps"], e_sp, e_mup))

    print(f"python {sys.version.split()[0]}, 5 s FM braking (T_max = 1000 N m), best of several runs\n")
    print("| what | wall time | steps | max abs slip error | max abs mu error |")
    print("|---|---|---|---|---|")
    for what, t, n, es, emu in rows:
        tt = f"{t * 1e3:.1f} ms" if t < 1 else f"{t:.2f} s"
        print(f"| {what} | {tt} | {n} | {es:.1e} | {emu:.1e} |")
    print()
    print(f"goal lumped < 20 ms: {'met' if t_lumped < 0.020 else 'MISSED'} ({t_lumped * 1e3:.1f} ms)")
    print(f"goal distributed < 0.5 s: {'met' if t_pde < 0.5 else 'MISSED'} ({t_pde:.3f} s)")
    if radau is not None:
        speedup = radau[1] / t_lumped
        print(f"speed-up over Radau at equal accuracy: {speedup:.0f}x (goal >= 5x: {'met' if speedup >= 5 else 'MISSED'})")
    else:
        print("Radau did not reach tirecli's accuracy at rtol >= 1e-7")
    events_and_dense(p, car, torque, theta, tr, ref)


def events_and_dense(p, car, torque, theta, tr, ref):
    """Lock/unlock times against the Radau event reference; the 1 ms output grid from the dense output."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from reference_quarter_car import reference_run

    from tirecli.models.profiles import Change, Transitions
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs

    lock_torque = Transitions(0.0, (Change(0.5, -1100.0, 1.5, "linear"), Change(2.0, 0.0, 0.6, "linear")))
    lumped = FrictionVariant("lumped", kappa0=2.0)
    _, _, _, ev = reference_run(p, car, 2.0, lock_torque, 2.4, 20.0, 20.0 / car.r)
    (r_lock, r_unlock), = ev["lock"]
    print("\n| lumped kappa0 2, 1100 N m braking to 2.4 s | wall time | lock time error | unlock time error |")
    print("|---|---|---|---|")
    for tol in (None, 1e-5):
        t_run, trl = best_of(lambda: runs.quarter_car(lumped, p, car, lock_torque, theta, 20.0, 20.0 / car.r, 2.4,
                                                      runs.SolverOptions(tol=tol)), 5)
        (t_lock, t_unlock), = trl.events["lock"]
        name = "default tol 1e-3" if tol is None else f"tol {tol:g}"
        print(f"| {name} | {t_run * 1e3:.1f} ms | {abs(t_lock - r_lock):.1e} s | {abs(t_unlock - r_unlock):.1e} s |")

    grid = np.arange(0.0, T_END + 1e-12, 1e-3)
    grid = grid[grid <= tr.t[-1]]
    t_s, (_, O) = best_of(lambda: tr.sample(grid), 3)
    _, mu_ref = lumped_outputs(p, car, torque, grid, ref.sol(grid))
    e_dense = float(np.max(np.abs(O["mu"] - mu_ref)))
    e_lin = float(np.max(np.abs(np.interp(grid, tr.t, tr.out["mu"]) - mu_ref)))
    print(f"\n1 ms output grid of the 5 s lumped braking ({grid.size} points, {tr.t.size} steps): sampled from the "
          f"dense output in {t_s * 1e3:.0f} ms; max |mu error| {e_dense:.1e} (linear interpolation of the steps: "
          f"{e_lin:.1e})")


if __name__ == "__main__":
    main()
