"""Observer study: estimate road adhesion and vehicle speed from the wheel speed (OBS Fig. 2).

Config (``tirecli observe CONFIG``)::

    study: observe
    tire: canudas2003-table1              # lumped LuGre, constant kappa = kappa0/L (OBS: 10 1/m)
    vehicle: canudas2003-obs-quarter-car
    observer: canudas2003-obs-gains       # k1, k2, k3, gamma, alpha (kind: observer)
    scenario:
      duration: 20                        # [s]
      theta_convention: obs               # values of theta below: obs (1 dry, > 1 less grip) or fm
      theta: {initial: 1, changes: [{at: 5, to: 1.6667, shape: step}, ...]}
      torque: {initial: 350, changes: [{at: 7, duration: 1, to: -250}, ...]}   # [N m]
      v0: 20                              # [m/s]
      slip0: 0                            # initial slip (0: pure rolling)
      z0: 0                               # initial bristle deflection [m]
      assumed: "why these scenario values are assumed"    # flagged in every output
    estimate: {v_error: 0, z: 0, theta: 1}               # observer's initial state
    measurement: {rate: 1000, noise: {std: 0.01, seed: 1}, encoder: {teeth: 48, method: period}}
    solver: {method: auto, rtol: 1.0e-7, step: 0.0025}   # auto | fixed | lsoda | radau | bdf
    metrics: {phases: [0, 5, 10, 15, 20], crossing_margin: 0.5, settle_tolerance: 0.05,
              excitation_threshold: 0.05, min_excitation: 0.5}
    cases:                                # optional variants, each overriding parts of the above
      - {label: "+0.1 m/s", estimate: {v_error: 0.1}}
      - {label: "theta known", observer: {gamma: 0}, theta: 1}
    gain_study: {gain: gamma, values: [5.0e4, 1.0e5, 2.0e5]}   # optional, instead of cases
    output: {dt: 0.01}                    # CSV sampling [s]
    figures: [obs-fig2]

Frames: ``observer`` (long format: ``case, t, theta, theta_hat`` (OBS convention),
``theta_fm, theta_hat_fm, v, v_hat, omega, omega_meas, vr, vr_hat, slip, z, z_hat, torque``) and
``metrics`` (per case and phase). Warnings (observability, gain/SPR conditions, excitation,
forward motion) are listed in ``meta["warnings"]``.
"""
from __future__ import annotations

from tirecli.studies.facts import named, scalar
from tirecli.studies.observe.planning import Case, Observe, plan
from tirecli.studies.observe.running import design_record, run, simulate_case
from tirecli.studies.observe.spec import SPEC
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Line, Study

#: Units of the facts of each case (``NAME[LABEL]``; ``NAME`` too with one case).
FACT_UNITS = {"convergence_time": "s", "rms_v_error": "m/s", "max_abs_v_error_at_s": "s", "v_hat_final": "m/s", "rms_theta_error": "-", "max_theta_error": "-", "max_abs_v_error": "m/s",
              "final_v_error": "m/s", "excitation_share": "-", "theta_hat_final": "-"}


def facts(result) -> dict:
    """Per case: ``convergence_time`` (settling time of theta_hat after the first adhesion change),
    ``rms_theta_error, max_theta_error`` (over the run, zero crossings of v_r excluded),
    ``max_abs_v_error, final_v_error, excitation_share, theta_hat_final``."""
    if "log" in result.meta:
        from tirecli.studies.observe.log import facts as log_facts

        return log_facts(result)
    per_case = {}
    for run_ in result.meta["runs"]:
        m = run_["metrics"]
        settle = [s["time"] for s in m["settling"]]
        per_case[run_["label"]] = {
            "convergence_time": float("nan") if not settle or settle[0] is None else float(settle[0]),
            "rms_theta_error": scalar(m["all_excl_crossings"]["rms_excl"]),
            "max_theta_error": scalar(m["all_excl_crossings"]["max_excl"]),
            "max_abs_v_error": scalar(m["max_abs_v_error"]), "final_v_error": scalar(m["final_v_error"]),
            "excitation_share": scalar(m["excitation_share"]), "theta_hat_final": scalar(m["theta_hat_final"]),
        }
    return named(per_case)


def _fmt(x, spec=".4g") -> str:
    return "-" if x is None or x != x else format(x, spec)


def metrics_table(result) -> list[str]:
    """Lines of the metrics table of an observe result (per case: phases, settling, speed, excitation)."""
    lines = []
    for rec in result.meta["runs"]:
        m = rec["metrics"]
        lines.append(f"case {rec['label']!r} ({rec['integrator']}):")
        lines.append(f"  {'phase [s]':<14}{'rms':>10}{'max':>10}{'rms excl':>10}{'max excl':>10}   |theta_hat - theta|, OBS convention")
        for k, ph in enumerate(m["phases"] + [m["all_excl_crossings"]]):
            name = f"{ph['start']:g}-{ph['end']:g}"
            if k == len(m["phases"]):
                name = f"all {name}"     # the whole run, not one more phase
            lines.append(f"  {name:<14}{_fmt(ph['rms']):>10}{_fmt(ph['max']):>10}{_fmt(ph['rms_excl']):>10}{_fmt(ph['max_excl']):>10}")
        cr = ", ".join(f"{t:.3f}" for t in m["crossings_s"]) or "none"
        lines.append(f"  v_r zero crossings [s]: {cr} (excluded: +-{result.meta['metric_settings']['crossing_margin']:g} s)")
        tol = result.meta["metric_settings"]["settle_tolerance"]
        for s in m["settling"]:
            # t = 0 is listed when the estimate starts off (theta_hat(0) != theta(0) or a speed error)
            when = "from the start (initial estimate off)" if s["at"] == 0 else f"change at {s['at']:g} s"
            lines.append(f"  {when}: " + (f"|theta_hat - theta| stays >= {tol:g} to the end of the run"
                                          if s["time"] is None else
                                          f"|theta_hat - theta| < {tol:g} after {s['time']:.3f} s"))
        lines.append(f"  max |v_hat - v| = {m['max_abs_v_error']:.3g} m/s; excitation |v_r| > "
                     f"{result.meta['metric_settings']['excitation_threshold']:g} m/s: {100 * m['excitation_share']:.1f}% of the time; "
                     f"slip in [{m['slip_range'][0]:.4f}, {m['slip_range'][1]:.4f}]")
    return lines


def summary(result) -> list:
    """The metrics table, the scenario's assumptions (notes) and the design or excitation warnings."""
    if "log" in result.meta:
        from tirecli.studies.observe.log import summary as log_summary

        return log_summary(result)
    return (metrics_table(result) + [Line(f"assumed: {a}", "note") for a in result.meta.get("assumed", [])]
            + [Line(w, "warning") for w in result.meta.get("warnings", [])])


_CHECKS = "tirecli.studies.checks.observer"

STUDY = register(Study(
    name="observe", command="observe", spec=SPEC, plan=plan, run=run, figures=("obs-fig2",),
    checks={"obs-fig2": Lazy(_CHECKS, "fig2_checks"), "obs-speed-error": Lazy(_CHECKS, "speed_error_checks"),
            "obs-gain-study": Lazy(_CHECKS, "gain_checks")},
    facts=facts, fact_units=FACT_UNITS, summary=summary, primary_frame="observer",
))

__all__ = ["STUDY", "SPEC", "Case", "Observe", "plan", "run", "simulate_case", "design_record", "facts", "metrics_table",
           "FACT_UNITS"]
