"""Planning an ``observe`` run: the config checked completely (parameter sets, profiles over the run, cases,
solver, metrics) and sized (see :mod:`tirecli.studies.observe`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.profiles import profile_from_checked, profile_problems
from tirecli.conventions import theta_obs_from_fm, to_theta_fm
from tirecli.errors import ConfigError
from tirecli.models.profiles import Table, Transitions
from tirecli.observers import lugre_observer as lo
from tirecli.observers.measurement import Sensor
from tirecli.studies.observe.spec import DEFAULT_GAINS, DEFAULT_VEHICLE, SPEC, THETA_PROFILE, TORQUE_PROFILE
from tirecli.studies.observe.work import work_estimate
from tirecli.studies.study import Plan

@dataclass
class Case:
    """One simulation of the study."""

    label: str
    gains: lo.ObserverGains
    scenario: object          # tirecli.numerics.observer.scenario.Scenario
    sensor: Sensor
    theta_profile: object
    changes: list             # start times of the adhesion changes (settling)


def profile_changes(profile) -> list[float]:
    """Start times [s] of the level changes of a profile (for the settling metric)."""
    if isinstance(profile, Transitions):
        return [c.at for c in profile.changes]
    if isinstance(profile, Table):
        t, y = profile.t, profile.y
        return [t[i - 1] if t[i] > t[i - 1] else t[i] for i in range(1, len(t)) if y[i] != y[i - 1]]
    return []


def _sensor(m: dict | None) -> Sensor:
    if not m or m.get("rate") is None:
        return Sensor()
    noise, enc = m.get("noise") or {}, m.get("encoder") or {}
    return Sensor(rate=m["rate"], noise_std=noise.get("std", 0.0), seed=noise.get("seed", 0),
                  teeth=enc.get("teeth"), method=enc.get("method", "period"), clock=enc.get("clock"))


def _theta_fm_fn(profile, convention):
    """``theta_fm(t)`` of a profile given in ``convention`` (scalar calls use the profile's fast ``at``).

    With a scalar ``at`` the function has one too, ``theta_fm.at(t)`` (a float, no numpy: what the
    adaptive integrators call at every rhs evaluation)."""
    at = getattr(profile, "at", None)
    at_fm = None
    if at is not None and convention == "obs":
        def inverse(t):
            return 1.0 / at(t)
        at_fm = inverse
    elif at is not None and convention == "fm":
        at_fm = at

    def theta_fm(t):
        if at_fm is not None and np.ndim(t) == 0:
            return at_fm(float(t))
        return to_theta_fm(profile(t), convention)
    if at_fm is not None:
        theta_fm.at = at_fm
    return theta_fm


def _make_case(label, gains, checked, theta_raw, torque_raw, est, meas, config, r) -> Case:
    from tirecli.numerics.observer.scenario import Scenario

    sc = checked["scenario"]
    base = config.base_dir
    theta_p = profile_from_checked(theta_raw, base)
    torque_p = profile_from_checked(torque_raw, base)
    conv = sc["theta_convention"]
    v0 = sc["v0"]
    s0 = sc["slip0"]
    # initial wheel speed from the slip (docs/models/lugre_friction.md §1): braking r w = v (1 + s), driving v = r w (1 - s)
    romega0 = v0 * (1.0 + s0) if s0 <= 0 else v0 / (1.0 - s0)
    theta_hat0_obs = float(theta_obs_from_fm(to_theta_fm(est["theta"], conv)))
    theta0 = float(theta_obs_from_fm(to_theta_fm(theta_p(0.0), conv)))
    changes = profile_changes(theta_p)
    if abs(theta_hat0_obs - theta0) > 1e-12 or est["v_error"] != 0.0:
        changes = [0.0] + [c for c in changes if c > 0.0]
    scenario = Scenario(duration=sc["duration"], torque=torque_p, theta_fm=_theta_fm_fn(theta_p, conv), v0=v0,
                        omega0=romega0 / r, z0=sc["z0"], v_hat0=v0 + est["v_error"], z_hat0=est["z"],
                        theta_hat0=theta_hat0_obs,
                        breakpoints=tuple(sorted(set(theta_p.breakpoints(sc["duration"]))
                                                 | set(torque_p.breakpoints(sc["duration"])))))
    return Case(label=label, gains=gains, scenario=scenario, sensor=_sensor(meas), theta_profile=theta_p,
                changes=sorted({c for c in changes if c < sc["duration"]}))


@dataclass
class Observe:
    """The detail of an observe plan."""

    plant: lo.ObserverPlant
    cases: list
    solver: object            # tirecli.numerics.observer.method.SolverOptions
    metrics: dict
    deprecated: list          # notes on deprecated keys (warnings of the run)


def plan(config: Config) -> Plan:
    """Check an observe config completely (schema, parameter sets, profiles, cases) without running it:
    sets ``tire``, ``vehicle``, ``observer``; detail :class:`Observe`."""
    checked = config.checked(SPEC)
    tire = config.group("tire", "lugre")
    vehicle = config.group("vehicle", "quarter_car", DEFAULT_VEHICLE)
    gain_set = config.group("observer", "observer", DEFAULT_GAINS)
    plant = lo.ObserverPlant(tire=tire.model(), car=vehicle.model())
    gains = gain_set.model()
    meas = checked["measurement"]
    if meas and meas["log"] is not None:   # the observer on a measured log: no plant
        from tirecli.studies.observe.log import plan_log

        solver, deprecated = _solver(checked, config)
        return plan_log(config, checked, plant, gains, {"tire": tire, "vehicle": vehicle, "observer": gain_set},
                        solver, deprecated, BYTES_PER_POINT)
    sc = checked["scenario"]
    if sc is None:
        raise ConfigError(config.origins.problem(("scenario",), "missing: a scenario (duration, theta, torque, v0) "
                                                                "or measurement.log (a measured log)"))
    est = checked["estimate"] or {"v_error": 0.0, "z": 0.0, "theta": 1.0}
    cases_raw, gstudy = checked["cases"], checked["gain_study"]
    if cases_raw and gstudy:
        raise ConfigError(config.origins.problem(("gain_study",), "use either 'cases' or 'gain_study', not both"))
    cases = []
    r = plant.car.r
    to_check = []
    if gstudy:
        for val in gstudy["values"]:
            g = gains.replace(**{gstudy["gain"]: float(val)})
            cases.append(_make_case(f"{gstudy['gain']} = {val:g}", g, checked, sc["theta"], sc["torque"], est, meas, config, r))
            to_check += [(cases[-1].theta_profile, THETA_PROFILE, ("scenario", "theta")),
                         (cases[-1].scenario.torque, TORQUE_PROFILE, ("scenario", "torque"))]
    elif cases_raw:
        labels = [c["label"] for c in cases_raw]
        if len(set(labels)) != len(labels):
            raise ConfigError(config.origins.problem(("cases",), "two cases share a label; give each a distinct 'label'"))
        for j, c in enumerate(cases_raw):
            if (c["measurement"] or {}).get("log") is not None:
                raise ConfigError(config.origins.problem(("cases", j, "measurement", "log"),
                                                         "a log is given once, at measurement.log"))
            g = gains.replace(**{k: v for k, v in (c["observer"] or {}).items() if v is not None})
            e = {**est, **{k: v for k, v in (c["estimate"] or {}).items() if v is not None}}
            cases.append(_make_case(c["label"], g, checked, c["theta"] if c["theta"] is not None else sc["theta"],
                                    c["torque"] if c["torque"] is not None else sc["torque"], e,
                                    c["measurement"] if c["measurement"] is not None else meas, config, r))
            to_check += [(cases[-1].theta_profile, THETA_PROFILE,
                          ("cases", j, "theta") if c["theta"] is not None else ("scenario", "theta")),
                         (cases[-1].scenario.torque, TORQUE_PROFILE,
                          ("cases", j, "torque") if c["torque"] is not None else ("scenario", "torque"))]
    else:
        cases.append(_make_case("nominal", gains, checked, sc["theta"], sc["torque"], est, meas, config, r))
        to_check += [(cases[-1].theta_profile, THETA_PROFILE, ("scenario", "theta")),
                     (cases[-1].scenario.torque, TORQUE_PROFILE, ("scenario", "torque"))]
    solver, deprecated = _solver(checked, config)
    _sample_estimate(checked, cases, solver).check(config.origins)   # before the checks over the run: they cost time
    # theta > 0 and a finite torque over the whole run, not only at t = 0
    problems = profile_problems(to_check, config.origins, sc["duration"], (checked["output"] or {}).get("dt", 0.01))
    if problems:
        raise ConfigError(problems)
    est = _sample_estimate(checked, cases, solver, plant, config.origins)   # + the solver's work (gains, method)
    est.check(config.origins)
    met = checked["metrics"] or {}
    dur = sc["duration"]
    metrics = {
        "phases": met.get("phases") or [dur * k / 4 for k in range(5)],
        "crossing_margin": met.get("crossing_margin", 0.5),
        "settle_tolerance": met.get("settle_tolerance", 0.05),
        "excitation_threshold": met.get("excitation_threshold", 0.05),
        "min_excitation": met.get("min_excitation", 0.5),
    }
    ph = metrics["phases"]
    if any(b <= a for a, b in zip(ph, ph[1:])) or ph[-1] > dur + 1e-9:
        raise ConfigError(config.origins.problem(("metrics", "phases"),
                                                 f"phase boundaries must increase and end by the duration ({dur:g} s)"))
    return Plan("observe", config, checked, {"tire": tire, "vehicle": vehicle, "observer": gain_set}, est,
                Observe(plant, cases, solver, metrics, deprecated))


#: Memory of one recorded time of a run (trajectory, frame, CSV text) and of one step of an adaptive
#: solver that is not recorded (``h_max``) [bytes].
BYTES_PER_POINT, BYTES_PER_STEP = 600, 50
#: Output grid of the adaptive methods [s] (``tirecli.numerics.observer.method.simulate``).
ADAPTIVE_OUTPUT_DT = 1e-3


def _sample_estimate(checked: dict, cases: list, solver, plant=None, origins=None):
    """Samples of an observe run before it starts, per case: the recorded times (the fixed scheme's grid
    of ``solver.step``, or the adaptive methods' 1 ms output grid; ``auto`` may run either), the
    measurement samples, the adaptive steps ``h_max`` forces and the CSV's ``output.dt`` grid; with the
    ``plant``, the solver's work too (:func:`tirecli.studies.observe.work.work_estimate`)."""
    from tirecli.limits import Estimate, steps

    dur = checked["scenario"]["duration"]
    dt_out = (checked["output"] or {}).get("dt", 0.01)
    points = samples = forced = 0.0
    by_rate = False   # whether a sampling rate, not the step, sets the grid of the recorded times
    for case in cases:
        rate = case.sensor.rate
        res = []
        if solver.method in ("auto", "fixed"):
            res.append(min(solver.step, 0.5 / rate) if rate else solver.step)
        if solver.method != "fixed":
            res.append(min(ADAPTIVE_OUTPUT_DT, 0.5 / rate) if rate else ADAPTIVE_OUTPUT_DT)
            forced += steps(dur, solver.h_max) if solver.h_max else 0.0
        by_rate |= bool(rate) and 0.5 / rate < min(solver.step, ADAPTIVE_OUTPUT_DT)
        points += steps(dur, min(res))
        samples += steps(dur, 1.0 / rate) if rate else 0.0
    n = len(cases)
    rate_paths = (("measurement", "rate"),) + tuple(("cases", i, "measurement", "rate") for i in range(n))
    return ((Estimate() if plant is None else work_estimate(checked, cases, solver, plant, origins))
            .add(points, (rate_paths if by_rate else (("solver", "step"), ("numerics", "step"))) + (("scenario", "duration"),),
                 f"the recorded times ({n} case(s) x {dur:g} s, solver {solver.method})", BYTES_PER_POINT)
            .add(samples, rate_paths + (("scenario", "duration"),),
                 f"the measurement samples ({n} case(s) x {dur:g} s)", BYTES_PER_POINT)
            .add(forced, (("solver", "h_max"), ("scenario", "duration")),
                 f"the solver steps h_max forces ({n} case(s) x {dur:g} s)", BYTES_PER_STEP)
            .add(n * steps(dur, dt_out), (("output", "dt"), ("scenario", "duration")),
                 f"data/observer.csv ({n} case(s) x {dur:g} s every {dt_out:g} s)", BYTES_PER_POINT))



def _solver(checked: dict, config: Config):
    """``SolverOptions`` from ``solver:`` (or the deprecated ``numerics:``) and the deprecation notes."""
    from tirecli.numerics.observer.method import SolverOptions

    sol, num = checked["solver"], checked["numerics"]
    if sol is not None and num is not None:
        raise ConfigError(config.origins.problem(("numerics",), "give 'solver' only ('numerics' is its deprecated "
                                                                "old name)"))
    if num is not None:
        opts = (SolverOptions(method="fixed", step=num["step"]) if num["method"] == "fast"
                else SolverOptions(method="radau", rtol=num["rtol"], atol=num["rtol"] * 1e-2, h_max=5e-3))
        new = ("{method: fixed, step: %g}" % opts.step if opts.method == "fixed"
               else "{method: radau, rtol: %g, atol: %g, h_max: 0.005}" % (opts.rtol, opts.atol))
        return opts, [f"'numerics' is deprecated: write solver: {new}"]
    sol = sol or {}
    return SolverOptions(**{k: v for k, v in sol.items() if v is not None}), []

