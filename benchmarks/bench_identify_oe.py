"""Benchmark: output-error identification (``tirecli.numerics.identify_oe``) against the driven fit.

Run: ``python benchmarks/bench_identify_oe.py`` (after ``pip install .``; about 6.5 min). Prints Markdown
tables; the numbers below are from its run on the 2-core development machine (load average 3.7).

Data: SYNTHETIC 100 Hz samples of coupled distributed-model brakings made by the simulate study (its
``measured_clean`` and ``measured`` frames; solver tol 1e-6; noise 0.05 m/s on the speeds, 0.5 bar on the
pressure, none on mu, seed 2003), FM Table 2:

- ``lock``: sigma1 = 1.15 s/m, brake pressure 0 -> 55 bar (1100 N m) over 0.5-2.0 s, released over
  2.0-2.6 s, 3.5 s: the wheel locks at 1.993 s and is released at 2.174 s;
- ``braking #2``: FM Fig. 4's braking #2 (sigma1 = 1 s/m, 1000 N m, no lock), the data of FM Fig. 6.

Rows: the equation-error fit with the distributed model driven by the interpolated samples
(``identify.fit_distributed``, from Table 1 with alpha = 2) and the output-error fit started from its
result (noise-free) or from the steady-state fit of FM eq. (4) to the samples (noisy); relative errors of
the generating values, wall time and simulator runs. Noisy rows: the input is the config's pressure
profile, or the noisy pressure samples (linear between them: an input error), v0 fitted, samples from
0.05 s compared; the 95 % intervals and whether they cover the truth.

Measured (2026-11-28; relative errors, sigma2 absolute as its truth is 0):

- lock, noise-free, output error from the driven fit: 5 free: worst 2.9e-5 (sigma0 177.995), sigma1
  1.15000 (+9.1e-7); 27.9 s, 55 runs. 6 free: the same five, sigma2 6.2e-13; 86.0 s, 197 runs. The driven
  fit: 5 free worst 3.7e-2 (v_s), sigma1 +1.1e-3; 6 free sigma1 -8.5e-2, mu_c -1.2e-1.
- braking #2 (no lock, slip down to -0.18, below the force peak), noise-free: output error 5 free:
  sigma0 +1.4e-4, mu_s -4.9e-4, sigma1 -5.1e-3, but mu_c -2.7e-1 and v_s +1.6e-1 (64 s, 232 runs), at a
  residual no larger than the truth's (mu RMS 4.9e-6 against 4.6e-6, the simulator's accuracy): below the
  peak the data do not separate mu_c from v_s (docs/models/lugre_friction.md §8, *Identifiability*).
- lock, noisy, config profile as input: every 95 % interval covers (worst error 8.2e-4, sigma0
  178.145 [177.968, 178.323]); 37.5 s, 140 runs; estimated scales v 0.0505, r omega 0.0535 m/s.
  Noisy pressure samples as input (an input error): sigma0 -2.4e-2, mu_c +1.1e-2, mu_s +9.4e-3, and
  their intervals miss (sigma1, v_s, v0 covered); 86.8 s, 137 runs.
"""
from __future__ import annotations

import os
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

FIVE = ("sigma0", "sigma1", "mu_c", "mu_s", "v_s")
SIX = ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s")
GAIN = 20.0


def main():
    from test_identify_output_error import braking, columns, steady_start

    from tirecli.models.profiles import Table
    from tirecli.numerics import identify
    from tirecli.numerics.identify_oe import fit_output_error, torque_from_samples
    from tirecli.parameters.sets import load_builtin

    table1 = replace(load_builtin("canudas2003-table1").model(), alpha=2.0, sigma2=0.0)
    car = load_builtin("canudas2003-obs-quarter-car").model()
    table2 = load_builtin("canudas2003-table2").model()
    cases = {
        "lock": (replace(table2, sigma1=1.15), 55.0,
                 braking("{model: distributed, label: lock}", "{t: [0, 0.5, 2.0, 2.6], value: [0, 0, 55, 0]}", 3.5)),
    }
    # FM Fig. 4's braking #2 (the data of FM Fig. 6): Table 2 as it is
    from tirecli.config.loader import config_from_text
    from tirecli.studies import simulate

    text = (ROOT / "tirecli" / "studies" / "configs" / "fm-fig4.yaml").read_text()
    sim = config_from_text(text, "<fm-fig4>")
    sim.data["cases"] = [c for c in sim.data["cases"] if isinstance(c, dict) and c.get("label") == "braking #2"]
    sim.data["measurement"]["cases"] = ["braking #2"]
    sim.data["measurement"]["record_starts"] = [97]
    cases["braking #2"] = (table2, 50.0, simulate.run(simulate.plan(sim)))

    def rel(est, truth, k):
        return (est[k] - getattr(truth, k)) / getattr(truth, k) if getattr(truth, k) else est[k] - getattr(truth, k)

    def row(name, est, truth, names, wall, runs, extra=""):
        cells = " | ".join(f"{est[k]:.6g} ({rel(est, truth, k):+.1e})" if k in est else "-" for k in names)
        return f"| {name} | {cells} | {wall:.1f} | {runs} |{extra}"

    print(f"load average at start: {os.getloadavg()[0]:.1f} (2 cores)\n")
    for label, (truth, pmax, res) in cases.items():
        d = columns(res.data["measured_clean"])
        t = d["t"]
        print(f"### {label}: noise-free (truth {', '.join(f'{k} {getattr(truth, k):g}' for k in SIX)})\n")
        names = SIX
        print("| fit | " + " | ".join(names) + " | wall [s] | runs |")
        print("|---|" + "---|" * (len(names) + 2))
        for free in (FIVE, SIX):
            w0 = time.perf_counter()
            dr, p_dr, _ = identify.fit_distributed(t, d["v"], d["romega"], d["mu"], table1, free, use=t >= 0.05)
            print(row(f"driven (equation error), {len(free)} free", dr.estimate, truth, names,
                      time.perf_counter() - w0, dr.nfev))
            w0 = time.perf_counter()
            oe, _, _ = fit_output_error(t, torque_from_samples(t, -GAIN * d["pressure"]), p_dr, car, v=d["v"],
                                        romega=d["romega"], mu=d["mu"], free=free)
            print(row(f"output error, {len(free)} free", oe.estimate, truth, names, time.perf_counter() - w0,
                      oe.extra["runs"]))
        print()
    truth, pmax, res = cases["lock"]
    d = columns(res.data["measured"])
    t = d["t"]
    start = steady_start(d, table1)
    names = FIVE + ("v0",)
    truth_v0 = {**{k: getattr(truth, k) for k in FIVE}, "v0": 20.0}
    print("### lock: noisy (speeds 0.05 m/s, pressure 0.5 bar), v0 fitted, samples from 0.05 s\n")
    print("| input | " + " | ".join(names) + " | wall [s] | runs |")
    print("|---|" + "---|" * (len(names) + 2))
    for how, prof in (("config profile", Table((0.0, 0.5, 2.0, 2.6), (0.0, 0.0, -GAIN * pmax, 0.0))),
                      ("noisy pressure samples", torque_from_samples(t, -GAIN * d["pressure"]))):
        w0 = time.perf_counter()
        oe, _, _ = fit_output_error(t, prof, start, car, v=d["v"], romega=d["romega"], mu=d["mu"], free=names,
                                    use=t >= 0.05)
        wall = time.perf_counter() - w0
        cells = " | ".join(f"{oe.estimate[k]:.6g} ({(oe.estimate[k] - truth_v0[k]) / truth_v0[k]:+.1e}) "
                           f"[{oe.ci_low[k]:.6g}, {oe.ci_high[k]:.6g}] "
                           f"{'covers' if oe.ci_low[k] <= truth_v0[k] <= oe.ci_high[k] else 'MISSES'}" for k in names)
        print(f"| {how} | {cells} | {wall:.1f} | {oe.extra['runs']} |")
        print(f"|  scales | {oe.extra['scales']} | | |")


if __name__ == "__main__":
    main()
