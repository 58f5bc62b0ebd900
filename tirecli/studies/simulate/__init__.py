"""Transient runs: the quarter car braking/driving with lumped or distributed LuGre tires, and the tire alone.

Config (``tirecli simulate CONFIG``)::

    study: simulate
    tire: canudas2003-table2                 # LuGre set (name, file, or {set: ..., overrides})
    vehicle: canudas2003-obs-quarter-car     # quarter-car set (default) [assumed for FM, docs/models/lugre_friction.md §7]
    initial: {v: 20, slip: 0}                # or {v: 20, omega: 80}; the bristles start undeformed
    input:                                   # exactly one of torque / brake_torque / pressure
      brake_torque: {initial: 0, changes: [{at: 0.5, duration: 1.5, to: 1000, shape: linear},
                                           {at: 2.0, duration: 0.6, to: 0, shape: linear}]}
      # torque: PROFILE         signed wheel torque [N m] (> 0 drives, < 0 brakes)
      # pressure: PROFILE       brake pressure [bar], brake torque = pressure_gain * pressure
      pressure_gain: 20                      # [N m/bar] (docs/models/lugre_friction.md §10, FM Fig. 4) [assumed]
      theta: 1.0                             # adhesion profile, FM convention unless theta_convention: obs
    t_end: 5.0                               # [s]
    stop: {v_min: 0.1}                       # the run ends when v falls to v_min [m/s]
    solver: {tol: null, h_max: 0.05}         # null: 1e-3 lumped, 3e-4 distributed
    cases:                                   # model variants, run side by side
      - {model: lumped, kappa0: 1}
      - {model: lumped, kappa0: Z}
      - {model: distributed, load: uniform, label: PDE}
      - {model: lumped, kappa0: 2, drive: {case: PDE}}          # open loop, driven by another case
      - {model: lumped, kappa0: Z, drive: {csv: run.csv, map: {slip: s}}}   # ... by measured t, v, s
      - {model: distributed, drive: {v: 20, slip: {expr: "-0.1*(t > 0.01)"}}}   # ... by formulas
    open_loop: {models: [{model: lumped, kappa0: 1}]}   # every model driven by every coupled case
    measurement: {rate: 100, noise: {speed: 0.05, pressure: 0.5}, seed: 2003}  # synthetic samples
    output: {dt: 0.001}                      # time step of data/timeseries.csv (0: solver steps)

A case may override ``input``, ``initial`` and ``solver``. Profiles are those of
:mod:`tirecli.models.profiles` (number, table, transitions, CSV, formula). Brake torque never turns
the wheel backwards: the wheel locks and stays locked while the brake can hold the tire torque
(docs/models/lugre_friction.md §7). Frames: ``timeseries`` (``case, mode, t, v, omega, romega, slip, vr, mu, torque,
brake_torque, pressure, theta, zbar, zdot, kappa0, locked, distance``), ``events`` (one row per
case) and, with ``measurement``, ``measured`` / ``measured_clean`` (synthetic samples ``t, pressure,
torque, v, romega, s, mu`` with and without noise).
"""
from __future__ import annotations

from tirecli.studies.facts import named, scalar, wanted_base
from tirecli.studies.registry import register
from tirecli.studies.simulate.planning import Case, plan
from tirecli.studies.simulate.running import case_events, case_frame, run, run_cases, sample_times
from tirecli.studies.simulate.spec import DEFAULT_PRESSURE_GAIN, SPEC
from tirecli.studies.study import Lazy, Study

#: The facts of each case (``NAME[LABEL]``; ``NAME`` too with one case), in order: the ``events`` of
#: ``run.json`` (a run that does not stop has no ``stop_time`` nor ``stopping_distance``: NaN), the
#: number of wheel locks and the start of the first.
FACTS = ("peak_abs_slip", "t_peak_abs_slip", "min_slip", "t_min_slip", "peak_abs_mu", "t_peak_abs_mu",
         "stop_time", "stopping_distance", "distance", "v_final", "t_final", "locked_at_end", "wheel_locks",
         "first_lock_time", "steps", "rejected_steps", "end")
FACT_UNITS = {"peak_abs_slip": "-", "t_peak_abs_slip": "s", "min_slip": "-", "t_min_slip": "s", "peak_abs_mu": "-",
              "t_peak_abs_mu": "s", "stop_time": "s", "stopping_distance": "m", "distance": "m", "v_final": "m/s",
              "t_final": "s", "locked_at_end": "-", "wheel_locks": "-", "first_lock_time": "s", "steps": "-",
              "rejected_steps": "-"}


def case_facts(ev: dict, base: set | None = None) -> dict:
    """The facts of one case from its events (:func:`~tirecli.studies.simulate.running.case_events`); only the
    names in ``base`` when given."""
    locks = ev.get("wheel_lock", [])
    row = {k: scalar(ev[k]) for k in FACTS if k in ev}
    row["wheel_locks"] = float(len(locks))
    row["first_lock_time"] = float(locks[0][0]) if locks else float("nan")
    return {k: v for k, v in row.items() if base is None or k in base}


def facts(result) -> dict:
    """Every fact of a simulate result, by case (:data:`FACTS`)."""
    return named({ev["case"]: case_facts(ev) for ev in result.meta["events"]})


def point(plan_, wanted=None, keep: bool = False):
    """A campaign's point: the cases run and the facts ``wanted`` found (only the extrema they need are
    root-found), no time series unless ``keep``: ``(facts, timeseries frame or None)``."""
    checked, cases = plan_.checked, plan_.detail
    p, car = plan_.sets["tire"].model(), plan_.sets["vehicle"].model()
    t_end = checked["t_end"]
    trs = run_cases(cases, p, car, t_end, sample_times(checked["measurement"], t_end))
    base = wanted_base(wanted)
    which = None if base is None else set(base) | {"wheel_lock"}
    per_case = {c.label: case_facts(case_events(trs[c.label], c, car.r, which), base) for c in cases}
    frame = None
    if keep:
        import pandas as pd

        gain = (checked["input"] or {}).get("pressure_gain") or DEFAULT_PRESSURE_GAIN
        frame = pd.concat([case_frame(trs[c.label], c, checked["output"]["dt"], car.r, gain) for c in cases],
                          ignore_index=True)
    return named(per_case), frame


def summary(result) -> list[str]:
    """One line per case: peak |slip| and |mu|, wheel locks, the stop (or the speed at the end)."""
    lines = []
    for ev in result.meta.get("events", []):
        locks = ", ".join(f"{a:.4f}-{b:.4f} s" if b is not None else f"from {a:.4f} s" for a, b in ev["wheel_lock"]) or "none"
        stop = f"stop at {ev['stop_time']:.3f} s after {ev['stopping_distance']:.2f} m" if ev["stop_time"] is not None \
            else f"v = {ev['v_final']:.3g} m/s at {ev['t_final']:.3g} s"
        lines.append(f"  {ev['case']}: peak |s| {ev['peak_abs_slip']:.4f} at {ev['t_peak_abs_slip']:.3f} s, "
                     f"peak |mu| {ev['peak_abs_mu']:.4f}, wheel lock: {locks}, {stop}")
    return lines


_CHECKS = "tirecli.studies.checks.transient"

STUDY = register(Study(
    name="simulate", command="simulate", spec=SPEC, plan=plan, run=run,
    figures=("transient-histories", "transient-mu-slip", "transient-overlay"),
    checks={"fm-fig4": Lazy(_CHECKS, "fig4_checks"), "fm-fig7": Lazy(_CHECKS, "fig7_checks"),
            "fm-fig8": Lazy(_CHECKS, "fig8_checks")},
    facts=facts, fact_units=FACT_UNITS, summary=summary, primary_frame="timeseries", point=point,
    group="shared-runs",  # the FM brakings are solved once per report worker (tirecli.numerics.runs)
))

__all__ = ["STUDY", "SPEC", "Case", "plan", "run", "run_cases", "facts", "point", "summary", "FACTS", "FACT_UNITS"]
