"""``mcps-standstill`` (``tirecli simulate``): a blocked wheel yawing back and forth at standstill (MCPS Figs. 4-5)."""
from __future__ import annotations

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Bool, Map, Num, Raw, collect
from tirecli.errors import ConfigError
from tirecli.limits import Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mcps.common import (BYTES_PER_ROW, MAX_PATCH_ROWS, MAX_SLIDER_STEPS, MAX_STEPS, meta_summary,
                                         refine_peak, tire_set)
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

STANDSTILL = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="vertical load"),
    "amplitude": Num(unit="rad", gt=0, le=6.3, default=0.45, doc="yaw amplitude A of the cycle 0 -> A -> -A -> A"),
    "yaw_rate": Num(unit="rad/s", gt=0, le=1e4, default=1.0, doc="|yaw rate| (the response does not depend on it)"),
    "cycles": Num(unit="-", integer=True, ge=1, le=20, default=2, doc="full yaw cycles after the first quarter"),
    "frame_term": Bool(default=True, doc="rotate the slider states with the wheel (docs/models/mcps_tire.md §4: on)"),
    "nodes": Num(unit="-", integer=True, ge=2, le=200, default=24, doc="Gauss nodes per half patch (resultants)"),
    "grid": Num(unit="-", integer=True, ge=3, le=1001, default=81, doc="points of the lateral force distribution (data/patch.csv)"),
    "samples": Num(unit="-", integer=True, ge=20, le=20_000, default=400, doc="samples per yaw leg of 2 A"),
    "patch_samples": Num(unit="-", integer=True, ge=4, le=2000, default=40, doc="times per leg of 2 A in data/patch.csv"),
})


def plan(config: Config) -> Plan:
    """Check an ``mcps-standstill`` config completely (set ``tire``; detail the MCPS parameters)."""
    checked, ps = collect(lambda: config.checked(STANDSTILL), lambda: tire_set(config))
    legs = 0.5 + 2 * int(checked["cycles"])
    steps = legs * int(checked["samples"])
    sliders = 2 * int(checked["nodes"]) + int(checked["grid"])
    rows = legs * int(checked["patch_samples"]) * int(checked["grid"])
    cap, slider_cap = compute_cap(MAX_STEPS), compute_cap(MAX_SLIDER_STEPS)
    if steps > cap or steps * sliders > slider_cap:
        raise ConfigError(config.origins.problem(("samples",), f"{steps:.0f} steps of {sliders} sliders exceed the budget "
                                                               f"({cap:.0f} steps, {slider_cap:.0e} slider-steps): "
                                                               "fewer samples, cycles, nodes or grid points " + cap_hint()))
    row_cap = compute_cap(MAX_PATCH_ROWS)
    if rows > row_cap:
        raise ConfigError(config.origins.problem(("patch_samples",), f"data/patch.csv would hold {rows:.0f} rows (budget "
                                                                     f"{row_cap:.0f}): fewer patch_samples or grid points " + cap_hint()))
    est = (Estimate().add(steps, (("samples",), ("cycles",)), f"data/standstill.csv ({steps:,.0f} steps)", BYTES_PER_ROW)
           .add(rows, (("patch_samples",), ("grid",), ("cycles",)), f"data/patch.csv ({rows:,.0f} rows)", BYTES_PER_ROW))
    est.check(config.origins)
    return Plan("mcps-standstill", config, checked, {"tire": ps}, est, ps.model())


def run(plan_: Plan, progress=None) -> StudyResult:
    """Blocked wheel yawing back and forth at standstill (MCPS §3.1, Figs. 4-5)."""
    from tirecli.numerics.mcps_transient import (asymptotic_standstill_torque, gauss_patch, simulate_standstill,
                                                 triangle_yaw)

    import pandas as pd  # once the config is checked: a refused run fails at once

    config, checked, ps, p = plan_.config, plan_.checked, plan_.sets["tire"], plan_.detail
    fz = checked["fz"]
    pa = p.patch(fz)
    law = p.patch_law(fz)
    A, rate, cyc = checked["amplitude"], checked["yaw_rate"], int(checked["cycles"])
    frame = checked["frame_term"]
    if progress is not None:
        progress.start(3, "standstill")
    t, psi, leg = triangle_yaw(A, rate, cyc, int(checked["samples"]))
    xi_q, w_q = gauss_patch(pa.l, int(checked["nodes"]))
    xi_g = np.linspace(-pa.l / 2.0, pa.l / 2.0, int(checked["grid"]))
    r = simulate_standstill(law, p.c_Mz, t, psi, xi_q, w_q, xi_g, frame)
    if progress is not None:
        progress.advance(1)
    cycle = np.where(leg == 0, 0, (leg + 1) // 2)  # leg 0: first quarter; legs 1, 2 cycle 1; 3, 4 cycle 2 ...
    st = pd.DataFrame({"t": t, "psi": psi, "leg": leg, "cycle": cycle, "mz": r["mz"], "fx": r["fx"], "fy": r["fy"]})
    every = max(1, int(round(int(checked["samples"]) / int(checked["patch_samples"]))))
    keep = np.arange(0, t.size, every)
    if keep[-1] != t.size - 1:
        keep = np.append(keep, t.size - 1)
    fy_tire = -r["fy_grid"]  # the road's force density on the tire (ISO-W), like every tire force of the run
    patch = pd.DataFrame({"t": np.repeat(t[keep], xi_g.size), "psi": np.repeat(psi[keep], xi_g.size),
                          "xi": np.tile(xi_g, keep.size), "fy": fy_tire[keep].ravel()})
    # facts: small-yaw stiffness (exact step of 1 mrad from rest) and first-loading torques
    probe = np.array([0.0, 1e-3, 0.01, 0.05, 0.1])
    pr = simulate_standstill(law, p.c_Mz, probe / rate, probe, xi_q, w_q, (), frame)
    sti = p.stiffnesses(fz)
    mz = r["mz"]
    facts = {
        "C_z_eq11_Nm_per_rad": sti["C_z"], "C_z_secant_1mrad_Nm_per_rad": float(-pr["mz"][1] / 1e-3),
        "C_z_with_belt_twist_Nm_per_rad": sti["C_zF"],
        "first_loading_mz_Nm": {f"{x:g} rad": float(v) for x, v in zip(probe[2:], pr["mz"][2:])},
        "Mz_inf_eq12_Nm": sti["Mz_inf"],
        "Mz_inf_frame_term_Nm": asymptotic_standstill_torque(law, pa.l, p.c_Mz, True),
        "Mz_inf_no_frame_term_Nm": asymptotic_standstill_torque(law, pa.l, p.c_Mz, False),
        "Fky_per_length_N_per_m": float(law.Fk[1]),
    }
    end2 = np.flatnonzero(leg == 1)  # legs: 0 (0 -> A), 1 (A -> -A), 2 (-A -> A), ...
    if end2.size:
        facts["mz_at_minus_A_Nm"] = float(mz[end2[-1]])
    first = cycle <= 1
    i = int(np.argmax(np.abs(mz[first])))
    ps_, mz_ = refine_peak(psi[first], np.abs(mz[first]), i) if 0 < i < first.sum() - 1 else (psi[i], abs(mz[i]))
    facts["max_abs_mz_first_cycle_Nm"] = float(mz_)
    facts["psi_of_max_abs_mz_rad"] = float(ps_)
    facts["leg_of_max_abs_mz"] = int(leg[first][i])
    fyg = np.abs(r["fy_grid"])
    facts["max_fy_first_loading_over_Fky"] = float(fyg[leg == 0].max() / law.Fk[1])
    facts["max_fy_first_cycle_over_Fky"] = float(fyg[first].max() / law.Fk[1])
    last = cycle == cyc
    # the last full cycle: from the start of its first leg (the end of the previous cycle)
    lo = np.flatnonzero(last)[0] - 1
    seg = slice(lo, None)
    facts["loop_energy_last_cycle_J"] = float(-np.trapezoid(mz[seg], psi[seg]))
    prev = cycle == cyc - 1
    if cyc >= 2 and prev.any():
        lo2 = np.flatnonzero(prev)[0] - 1
        hi2 = np.flatnonzero(prev)[-1] + 1
        facts["loop_energy_previous_cycle_J"] = float(-np.trapezoid(mz[lo2:hi2], psi[lo2:hi2]))
    if progress is not None:
        progress.advance(2)
        progress.close()
    lines = [f"C_z = {facts['C_z_eq11_Nm_per_rad']:.6g} N m/rad (eq. 11; secant after 1 mrad "
             f"{facts['C_z_secant_1mrad_Nm_per_rad']:.6g}); asymptotic torque {facts['Mz_inf_eq12_Nm']:.6g} N m "
             f"(eq. 12), {facts['Mz_inf_frame_term_Nm']:.6g} N m with the frame term",
             f"yaw cycle +-{A:g} rad: Mz = {facts.get('mz_at_minus_A_Nm', float('nan')):.5g} N m at psi = -A; max |Mz| "
             f"{facts['max_abs_mz_first_cycle_Nm']:.5g} N m at psi = {facts['psi_of_max_abs_mz_rad']:.3g} rad; "
             f"energy of the last cycle {facts['loop_energy_last_cycle_J']:.4g} J"]
    return StudyResult(
        study="mcps-standstill", config=config, parameter_sets={"tire": ps},
        data={"standstill": st, "patch": patch},
        meta={"title": checked["title"] or "MCPS blocked wheel at standstill: patch forces and torsional torque",
              "scenario": {"amplitude_rad": A, "yaw_rate_rad_per_s": rate, "cycles": cyc,
                           "path": "psi triangular 0 -> +A -> -A -> +A ...", "frame_term": frame, "fz_N": fz,
                           "patch": {"l_m": pa.l, "w_m": pa.w, "P_Pa": pa.P},
                           "quadrature": f"Gauss-Legendre, {checked['nodes']} nodes per half patch"},
              "signs": "mz, fx, fy and patch.csv fy: road on tire (ISO-W, eq. 10); patch.csv fy is a force per unit "
                       "patch length [N/m]",
              "assumed": [f"yaw amplitude {A:g} rad (the scan's '-45 <= psi <= 45' read as +-0.45 rad: its decimal points are "
                          "lost and the figure's axis is in rad, ticks -0.4 to 0.4)"]
              if abs(A - 0.45) < 1e-12 else [],
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-fig4", "mcps-fig5"],
        payload={"params": p, "law": law, "patch": pa, "xi_grid": xi_g, "fy_grid": fy_tire, "t": t, "psi": psi},
    )


_CHECKS = "tirecli.studies.checks.mcps"

STUDY = register(Study(
    name="mcps-standstill", command="simulate", spec=STANDSTILL, plan=plan, run=run, figures=("mcps-fig4", "mcps-fig5"),
    checks={"mcps-fig4": Lazy(_CHECKS, "fig4_checks"), "mcps-fig5": Lazy(_CHECKS, "fig5_checks")},
    summary=meta_summary,
))

__all__ = ["STUDY", "STANDSTILL", "plan", "run"]
