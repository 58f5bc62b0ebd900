"""``mcps-slider`` (``tirecli simulate``): one rubber slider under sinusoidal translation and rotation (MCPS Fig. 3)."""
from __future__ import annotations

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Bool, Map, Nullable, Num, Raw, collect
from tirecli.errors import ConfigError
from tirecli.limits import Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mcps.common import BYTES_PER_ROW, MAX_STEPS, meta_summary, refine_peak, tire_set
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

SLIDER = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set (the slider uses U, r, mu, alpha, beta, c_Sz, c_muz)"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="load whose patch pressure P = fz/(w l) acts on the slider"),
    "amplitude": Num(unit="m", gt=0, default=None, doc="amplitude of u_x (default 8 F_k/K)"),
    "rotation": Num(unit="rad", gt=0, default=None, doc="amplitude of psi (default 8 M_kz/S_z)"),
    "period": Num(unit="s", gt=0, le=1e6, default=2.0, doc="period T of the sinusoidal motion"),
    "periods": Num(unit="-", integer=True, ge=1, le=50, default=2, doc="number of periods"),
    "compare_period": Nullable(spec=Num(unit="s", gt=0, le=1e6), default=0.5,
                               doc="period of a second run, integrated in time, showing rate independence (null: none)"),
    "samples": Num(unit="-", integer=True, ge=16, le=100_000, default=400, doc="samples per period (rounded to a multiple of 4)"),
    "frame_term": Bool(default=False, doc="rotate the force states with the slider (docs/models/mcps_tire.md §4: off for Fig. 3)"),
})


def plan(config: Config) -> Plan:
    """Check an ``mcps-slider`` config completely (set ``tire``; detail the MCPS parameters)."""
    checked, ps = collect(lambda: config.checked(SLIDER), lambda: tire_set(config))
    steps = int(checked["periods"]) * int(checked["samples"])
    cap = compute_cap(MAX_STEPS)
    if steps > cap:
        raise ConfigError(config.origins.problem(("samples",), f"{steps} steps (periods x samples) exceed the budget "
                                                               f"of {cap:.0f}: fewer samples per period " + cap_hint()))
    runs_ = 2 if checked["compare_period"] else 1
    est = Estimate().add(runs_ * (steps + 1), (("samples",), ("periods",)),
                         f"data/slider.csv ({runs_} run(s) x {steps:,} steps)", BYTES_PER_ROW)
    est.check(config.origins)
    return Plan("mcps-slider", config, checked, {"tire": ps}, est, ps.model())


def run(plan_: Plan, progress=None) -> StudyResult:
    """One rubber slider under sinusoidal translation and rotation (MCPS Fig. 3; docs/models/mcps_tire.md §4)."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    from tirecli.numerics.mcps_transient import integrate_slider_in_time, simulate_slider

    config, checked, ps, p = plan_.config, plan_.checked, plan_.sets["tire"], plan_.detail

    P = p.patch(checked["fz"]).P
    law = p.slider_law(P)
    K, Fk = float(law.K[0]), float(law.Fk[0])
    A = checked["amplitude"] or 8.0 * Fk / K
    Psi = checked["rotation"] or 8.0 * law.Mkz / law.Sz
    nper = int(checked["periods"])
    spp = 4 * max(4, int(round(checked["samples"] / 4)))
    periods = [checked["period"]] + ([checked["compare_period"]] if checked["compare_period"] else [])
    if progress is not None:
        progress.start(len(periods), "slider")
    frames = []
    runs = {}
    phase = np.linspace(0.0, nper, nper * spp + 1)   # every run on the same phase grid
    ux = A * np.sin(2 * np.pi * phase)
    psi = Psi * np.sin(2 * np.pi * phase)
    for k, T in enumerate(periods):
        t = phase * T
        if k == 0:   # exact increments (MCPS eq. 9 between samples)
            f, m = simulate_slider(law, ux, np.zeros_like(ux), psi, checked["frame_term"])
        else:        # integrated in time (DOP853): checks the exact steps and the rate independence
            f, m = integrate_slider_in_time(law, A, Psi, T, phase, checked["frame_term"])
        runs[T] = (phase, t, ux, psi, f, m)
        frames.append(pd.DataFrame({"period": T, "method": "exact increments" if k == 0 else "time integration (DOP853)",
                                    "t": t, "ux": ux, "psi": psi, "fx": f[:, 0], "fy": f[:, 1], "m": m}))
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    phase, t, ux, psi, f, m = runs[periods[0]]
    q = phase <= 0.25 + 1e-12
    i = int(np.argmax(f[q, 0]))
    u_pk, f_pk = refine_peak(ux[q], f[q, 0], i)
    j = int(np.argmax(m[q]))
    p_pk, m_pk = refine_peak(psi[q], m[q], j)
    sec = phase >= nper - 1 - 1e-12
    facts = {
        "pressure_Pa": P, "K_N_per_m": K, "Fk_N": Fk, "Sz_Nm_per_rad": law.Sz, "Mkz_Nm": law.Mkz,
        "amplitude_m": A, "rotation_rad": Psi,
        "first_peak_force_N": f_pk, "first_peak_path_m": u_pk,
        "first_peak_torque_Nm": m_pk, "first_peak_angle_rad": p_pk,
        "last_period_max_force_N": float(f[sec, 0].max()), "last_period_min_force_N": float(f[sec, 0].min()),
        "reversal_limit_force_N": float((2 * _g_max(p.alpha_x, p.beta_x) - 1) * Fk),
    }
    if len(periods) > 1:
        other = runs[periods[1]]
        facts["rate_independence_max_diff_N"] = float(np.max(np.abs(other[4] - f)))
        facts["rate_independence_max_diff_Nm"] = float(np.max(np.abs(other[5] - m)))
    lines = [f"slider: K = {K:.5g} N/m, F_k = {Fk:.5g} N, S_z = {law.Sz:.4g} N m/rad, M_kz = {law.Mkz:.4g} N m",
             f"first loading: force peak {f_pk:.5g} N at u = {1e3 * u_pk:.4g} mm; torque peak {m_pk:.4g} N m at "
             f"{p_pk:.4g} rad; last period force in [{facts['last_period_min_force_N']:.4g}, "
             f"{facts['last_period_max_force_N']:.4g}] N"]
    if len(periods) > 1:
        lines.append(f"rate independence: T = {periods[0]:g} s (exact increments) and {periods[1]:g} s (integrated in "
                     f"time) differ by at most {facts['rate_independence_max_diff_N']:.2g} N")
    return StudyResult(
        study="mcps-slider", config=config, parameter_sets={"tire": ps}, data={"slider": pd.concat(frames, ignore_index=True)},
        meta={"title": checked["title"] or "MCPS rubber slider: friction force and torque loops",
              "scenario": {"ux": f"{A:.6g} sin(2 pi t/T) m", "psi": f"{Psi:.6g} sin(2 pi t/T) rad",
                           "periods_s": periods, "cycles": nper, "frame_term": checked["frame_term"],
                           "pressure_Pa": P},
              "signs": "fx, m: the friction force and torque the slider transmits to the road (MCPS eq. 9); "
                       "the road's reaction on the slider is the opposite",
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-fig3"],
        payload={"params": p, "law": law, "periods": periods},
    )


def _g_max(alpha, beta):
    from tirecli.models.mcps.law import overshoot_peak

    return overshoot_peak(alpha, beta)[1]


STUDY = register(Study(
    name="mcps-slider", command="simulate", spec=SLIDER, plan=plan, run=run, figures=("mcps-fig3",),
    checks={"mcps-fig3": Lazy("tirecli.studies.checks.mcps", "fig3_checks")}, summary=meta_summary,
))

__all__ = ["STUDY", "SLIDER", "plan", "run"]
