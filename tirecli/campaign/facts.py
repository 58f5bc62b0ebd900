"""One point of a campaign: run its study with the studies' pure functions and pick facts by name.

No figures are drawn and no file is written: a lumped braking takes milliseconds, and the
campaign's cost must be its runs. The facts of each study, by name (``NAME[LABEL]`` for the case
``LABEL`` of a study with several cases; the plain ``NAME`` too when there is one case):

* ``simulate`` (quarter-car runs): ``peak_abs_slip, t_peak_abs_slip, min_slip, t_min_slip,
  peak_abs_mu, t_peak_abs_mu, stop_time, stopping_distance, distance, v_final, t_final,
  locked_at_end, wheel_locks, first_lock_time, steps, rejected_steps, end`` (the ``events`` of
  ``run.json``; a run that does not stop has no ``stop_time`` nor ``stopping_distance``: empty);
* ``observe``: ``convergence_time`` (settling time of theta_hat after the first adhesion change),
  ``rms_theta_error, max_theta_error`` (over the run, zero crossings of v_r excluded),
  ``max_abs_v_error, final_v_error, excitation_share, theta_hat_final``;
* every other study: its ``facts`` in ``run.json`` (``meta.facts``), flattened: ``mu_peak`` of a
  sweep with one curve (``mu_peak[i]`` for curve ``i`` of data/peaks.csv), ``fy`` of an ``mf-eval``
  point, the MCPS studies' facts, and the stationary MCPS stiffnesses (``C_kappa[4000 N]``).
"""
from __future__ import annotations

import contextlib
import signal
import threading
import time
import traceback

import numpy as np

#: The numeric facts of a simulate case (see the module doc), in order.
SIMULATE_FACTS = ("peak_abs_slip", "t_peak_abs_slip", "min_slip", "t_min_slip", "peak_abs_mu", "t_peak_abs_mu",
                  "stop_time", "stopping_distance", "distance", "v_final", "t_final", "locked_at_end", "wheel_locks",
                  "first_lock_time", "steps", "rejected_steps", "end")
OBSERVE_FACTS = ("convergence_time", "rms_theta_error", "max_theta_error", "max_abs_v_error", "final_v_error",
                 "excitation_share", "theta_hat_final")
#: The unit of each fact of a study (``-``: dimensionless; :func:`fact_unit`); the facts of other
#: studies take theirs from a unit suffix of the name (:data:`UNIT_SUFFIXES`), else none is known.
FACT_UNITS = {
    "simulate": {"peak_abs_slip": "-", "t_peak_abs_slip": "s", "min_slip": "-", "t_min_slip": "s", "peak_abs_mu": "-",
                 "t_peak_abs_mu": "s", "stop_time": "s", "stopping_distance": "m", "distance": "m", "v_final": "m/s",
                 "t_final": "s", "locked_at_end": "-", "wheel_locks": "-", "first_lock_time": "s", "steps": "-",
                 "rejected_steps": "-"},
    "observe": {"convergence_time": "s", "rms_theta_error": "-", "max_theta_error": "-", "max_abs_v_error": "m/s",
                "final_v_error": "m/s", "excitation_share": "-", "theta_hat_final": "-"},
    "sweep": {"slip_peak": "-", "mu_peak": "-", "mu_slide": "-"},
    "mf-eval": {"fx": "N", "fy": "N", "mz": "N m", "mx": "N m", "my": "N m"},
}
#: Unit suffixes of fact names in ``run.json`` (``last_period_max_force_N``), longest first.
UNIT_SUFFIXES = (("_Nm_per_rad", "N m/rad"), ("_N_per_m", "N/m"), ("_1_s", "1/s"), ("_Nm", "N m"), ("_N", "N"),
                 ("_rad", "rad"), ("_J", "J"), ("_m", "m"), ("_s", "s"))


def fact_unit(study: str, name: str) -> str | None:
    """The unit of fact ``name`` (``NAME[LABEL]`` too) of a ``study`` run; None when unknown."""
    base = name.split("[", 1)[0]
    if study in FACT_UNITS:
        return FACT_UNITS[study].get(base)
    return next((unit for suffix, unit in UNIT_SUFFIXES if base.endswith(suffix)), None)


#: The frame kept per point with ``keep: timeseries`` (default: the study's first frame).
PRIMARY_FRAME = {"simulate": "timeseries", "observe": "observer"}


def _scalar(v):
    """A fact as a float (None -> NaN, booleans -> 0/1) or a text; None for a non-scalar."""
    if v is None:
        return float("nan")
    if isinstance(v, (bool, np.bool_)):
        return float(v)
    if isinstance(v, (int, float, np.integer, np.floating)):
        return float(v)
    if isinstance(v, str):
        return v
    return None


def _named(per_case: dict) -> dict:
    """``{LABEL: {NAME: value}}`` -> ``{NAME[LABEL]: value}``, and ``NAME`` alone for a single case."""
    out = {}
    for label, facts in per_case.items():
        out.update({f"{k}[{label}]": v for k, v in facts.items()})
    if len(per_case) == 1:
        out.update(next(iter(per_case.values())))
    return out


def _wanted_base(wanted) -> set | None:
    """The base names (``NAME`` of ``NAME[LABEL]``) asked for; None for all."""
    if wanted is None:
        return None
    return {w.split("[", 1)[0] for w in wanted}


def flatten(facts, prefix: str = "") -> dict:
    """Scalar facts of a nested ``meta.facts``: ``{a: 1, b: {x: 2}, rows: [{y: 3}, {y: 4}]}`` ->
    ``{a: 1, x[b]: 2, y[0]: 3, y[1]: 4}`` (``y`` alone when the list has one row)."""
    out = {}
    if isinstance(facts, dict):
        for k, v in facts.items():
            s = _scalar(v)
            if s is not None:
                out[f"{k}{prefix}"] = s
            elif isinstance(v, dict):
                out.update(flatten(v, f"[{k}]" if not prefix else f"{prefix[:-1]}, {k}]"))
            elif isinstance(v, list) and v and all(isinstance(r, dict) for r in v):
                if len(v) == 1:
                    out.update(flatten(v[0], prefix))
                else:
                    for i, r in enumerate(v):
                        out.update(flatten(r, f"[{i}]" if not prefix else f"{prefix[:-1]}, {i}]"))
    return out


def _simulate(config, wanted, keep):
    from tirecli.studies import simulate as sim

    checked, tire, vehicle, cases = sim.plan(config)
    p, car = tire.model(), vehicle.model()
    t_end = checked["t_end"]
    meas = checked["measurement"]
    trs = sim.run_cases(cases, p, car, t_end, sim._sample_times(meas, t_end))
    base = _wanted_base(wanted)
    which = None if base is None else set(base) | {"wheel_lock"}
    per_case = {}
    for c in cases:
        ev = sim._events(trs[c.label], c, car.r, which)
        locks = ev.get("wheel_lock", [])
        row = {k: _scalar(ev[k]) for k in SIMULATE_FACTS if k in ev}
        row["wheel_locks"] = float(len(locks))
        row["first_lock_time"] = float(locks[0][0]) if locks else float("nan")
        per_case[c.label] = {k: v for k, v in row.items() if base is None or k in base}
    frame = None
    if keep:
        import pandas as pd

        gain = (checked["input"] or {}).get("pressure_gain") or sim.DEFAULT_PRESSURE_GAIN
        frame = pd.concat([sim._frame(trs[c.label], c, checked["output"]["dt"], car.r, gain) for c in cases],
                          ignore_index=True)
    return _named(per_case), frame


def _observe_facts(result) -> dict:
    per_case = {}
    for run in result.meta["runs"]:
        m = run["metrics"]
        settle = [s["time"] for s in m["settling"]]
        per_case[run["label"]] = {
            "convergence_time": float("nan") if not settle or settle[0] is None else float(settle[0]),
            "rms_theta_error": _scalar(m["all_excl_crossings"]["rms_excl"]),
            "max_theta_error": _scalar(m["all_excl_crossings"]["max_excl"]),
            "max_abs_v_error": _scalar(m["max_abs_v_error"]), "final_v_error": _scalar(m["final_v_error"]),
            "excitation_share": _scalar(m["excitation_share"]), "theta_hat_final": _scalar(m["theta_hat_final"]),
        }
    return _named(per_case)


def study_facts(result) -> dict:
    """Every scalar fact of a study result, by name (module doc)."""
    if result.study == "observe":
        return _observe_facts(result)
    facts = flatten(result.meta.get("facts") or {})
    if result.study == "mcps-stationary":
        facts.update(flatten({"stiffness": result.meta.get("stiffnesses") or {}}))
    return facts


class UnknownFact(KeyError):
    """An output name that is not a fact of the run (``fact``)."""

    def __init__(self, message: str, fact: str):
        super().__init__(message)
        self.fact = fact

    def __str__(self) -> str:  # the message itself (a KeyError's str() is its repr, in quotes)
        return str(self.args[0])


def run_point(config, wanted=None, keep: bool = False) -> tuple[dict, object]:
    """Run one point's study: ``(facts, frame or None)``; ``wanted`` the fact names needed (None: all)."""
    from tirecli.studies.base import run_study, study_name

    if study_name(config) == "simulate":
        facts, frame = _simulate(config, wanted, keep)
    else:
        result = run_study(config)
        facts = study_facts(result)
        frame = None
        if keep and result.data:
            name = PRIMARY_FRAME.get(result.study, next(iter(result.data)))
            frame = result.data[name]
    if wanted is not None:
        missing = [w for w in wanted if w not in facts]
        if missing:
            import difflib

            facts = run_point(config)[0]  # every fact, to name them

            hint = difflib.get_close_matches(missing[0], list(facts), n=1)
            raise UnknownFact(f"no fact named {missing[0]!r}" + (f"; did you mean {hint[0]!r}?" if hint else "")
                           + f" (facts of this run: {', '.join(list(facts)[:30])}{' ...' if len(facts) > 30 else ''})", missing[0])
        facts = {w: facts[w] for w in wanted}
    return facts, frame


def error_text(exc: BaseException) -> str:
    """One line for a failed point: the message of a tirecli error, else the type and message."""
    from tirecli.errors import TirecliError

    msg = str(exc).strip().splitlines()
    text = msg[0] if msg else ""
    if isinstance(exc, (TirecliError, PointTimeout, UnknownFact)):
        return text or type(exc).__name__
    if isinstance(exc, KeyError):
        text = str(exc.args[0]) if exc.args else text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class PointTimeout(Exception):
    """A point ran longer than the campaign's ``timeout``."""


@contextlib.contextmanager
def _time_limit(seconds):
    """Raise :class:`PointTimeout` in the block after ``seconds`` of wall time (an interval timer:
    only in a process's main thread, so not on Dask workers, which run tasks in threads)."""
    if not seconds or threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return

    def expire(signum, frame):
        raise PointTimeout(f"timeout: the point ran longer than {seconds:g} s (campaign timeout:)")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def run_batch(payload, batch) -> list:
    """Run the points of ``batch`` (``[(index, id, overrides), ...]``) of a campaign whose shared part
    is ``payload`` (``{"base", "fixed", "outputs", "keep"}``); a record per point, a failure recorded
    with its error (the campaign goes on)."""
    from tirecli.campaign.spec import point_config

    out = []
    for index, pid, overrides in batch:
        t0 = time.perf_counter()
        rec = {"point": index, "id": pid, "status": "ok", "error": "", "facts": {}, "frame": None}
        try:
            with _time_limit(payload.get("timeout")):
                cfg = point_config(payload["base"], payload["fixed"] + overrides)
                rec["facts"], rec["frame"] = run_point(cfg, payload["outputs"], payload["keep"])
        except Exception as exc:  # noqa: BLE001 - a failing point is recorded, the campaign goes on
            rec.update(status="failed", error=error_text(exc), trace=traceback.format_exc(limit=6),
                       unknown=getattr(exc, "fact", None))
        rec["seconds"] = time.perf_counter() - t0
        out.append(rec)
    return out


def column_units(campaign, study: str) -> dict:
    """``{column: unit}`` of the results' varied inputs of ``campaign`` (a
    :class:`~tirecli.campaign.spec.Campaign`; units from the base study's config schema and parameter
    sets) and outputs (:func:`fact_unit`) whose unit is known."""
    from tirecli.parameters.kinds import unit_at
    from tirecli.studies.base import SPECS, load_study

    load_study(study)
    units = {}
    if study in SPECS:
        units.update({k: unit_at(SPECS[study], campaign.overrides[k][0]) for k in campaign.design.keys})
    units.update({o: fact_unit(study, o) for o in campaign.outputs})
    return {k: u for k, u in units.items() if u}


__all__ = ["UnknownFact", "run_point", "run_batch", "column_units", "study_facts", "flatten", "SIMULATE_FACTS", "OBSERVE_FACTS", "error_text",
           "FACT_UNITS", "fact_unit"]
