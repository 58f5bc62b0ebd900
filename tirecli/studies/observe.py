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

from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.profiles import profile_from_checked, profile_problems, profile_spec
from tirecli.config.schema import ListOf, Map, Nullable, Num, Raw, Str
from tirecli.conventions import (THETA_CONVENTIONS, slip_from_speeds, theta_fm_from_obs, theta_obs_from_fm,
                                 to_theta_fm)
from tirecli.errors import ConfigError
from tirecli.limits import MAX_TITLE_CHARS
from tirecli.models.profiles import Table, Transitions
from tirecli.observers import lugre_observer as lo
from tirecli.observers import metrics as om
from tirecli.observers.measurement import METHODS, Sensor
from tirecli.studies.base import StudyResult, common_fields, register_study
from tirecli.studies.observe_work import GAINS, work_estimate

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

DEFAULT_GAINS = "canudas2003-obs-gains"
DEFAULT_VEHICLE = "canudas2003-obs-quarter-car"


def _measurement_post(v, path, ctx):
    if v["rate"] is None and (v["noise"] is not None or v["encoder"] is not None):
        ctx.fail(path, "noise and encoder quantisation need a sampling 'rate' [Hz] (the measurement is held between samples)")


MEASUREMENT = Map(fields={
    "rate": Num(unit="Hz", gt=0, default=None, doc="sampling rate with zero-order hold; omit for the ideal continuous measurement"),
    "noise": Map(fields={"std": Num(unit="rad/s", ge=0, doc="standard deviation of the Gaussian noise"),
                         "seed": Num(unit="-", integer=True, ge=0, default=0, doc="noise seed")}, default=None),
    "encoder": Map(fields={"teeth": Num(unit="-", integer=True, ge=1, doc="encoder teeth per revolution"),
                           "method": Str(choices=METHODS, default="period",
                                         doc="count: edges per sample period; period: time of the last tooth interval"),
                           "clock": Num(unit="Hz", gt=0, default=None, doc="timer that time-stamps the edges (period method)")},
                   default=None),
}, post=_measurement_post, default=None)


def _estimate(required: bool) -> Map:
    d = (lambda x: x) if required else (lambda x: None)  # noqa: E731
    return Map(fields={
        "v_error": Num(unit="m/s", default=d(0.0), doc="initial speed estimate error v_hat(0) - v(0)"),
        "z": Num(unit="m", default=d(0.0), doc="initial deflection estimate z_hat(0)"),
        "theta": Num(unit="-", gt=0, default=d(1.0), doc="initial adhesion estimate theta_hat(0) (scenario.theta_convention)"),
    }, default=None)


THETA_PROFILE = profile_spec("-", gt=0)
TORQUE_PROFILE = profile_spec("N m")

SCENARIO = Map(fields={
    "duration": Num(unit="s", gt=0, le=3600, doc="simulated time"),
    "theta_convention": Str(choices=THETA_CONVENTIONS, default="obs", doc="convention of the theta values"),
    "theta": THETA_PROFILE,
    "torque": TORQUE_PROFILE,
    "v0": Num(unit="m/s", gt=0, doc="initial vehicle speed"),
    "slip0": Num(unit="-", gt=-1, lt=1, default=0.0, doc="initial slip (0: pure rolling)"),
    "z0": Num(unit="m", default=0.0, doc="initial bristle deflection"),
    "assumed": Str(default="", doc="why the scenario values are assumed defaults (flagged in outputs)"),
})

SOLVER_METHODS = ("auto", "fixed", "lsoda", "radau", "bdf")

SOLVER = Map(fields={
    "method": Str(choices=SOLVER_METHODS, default="auto",
                  doc="auto: the fastest stable and accurate method for the gains and the measurement; fixed: the "
                      "structured fixed-step scheme; lsoda, radau, bdf: adaptive (scipy) on the full system"),
    "rtol": Num(unit="-", gt=0, lt=1, default=1e-7, doc="relative tolerance of the adaptive methods"),
    "atol": Nullable(spec=Num(unit="-", gt=0), default=None,
                doc="absolute tolerance of the adaptive methods (default: rtol times each state's typical size)"),
    "step": Num(unit="s", gt=0, le=0.05, default=2.5e-3, doc="largest step of the fixed scheme"),
    "h_max": Nullable(spec=Num(unit="s", gt=0), default=None,
                      doc="largest step of the adaptive methods (null: unlimited)"),
}, default=None)

#: Deprecated ``numerics:`` block (``fast``: the fixed scheme, ``reference``: Radau); use ``solver:``.
NUMERICS = Map(fields={
    "method": Str(choices=("fast", "reference"), default="fast",
                  doc="deprecated (use solver.method): fast = fixed, reference = radau"),
    "step": Num(unit="s", gt=0, le=0.05, default=2.5e-3, doc="deprecated (use solver.step)"),
    "rtol": Num(unit="-", gt=0, lt=1, default=1e-8, doc="deprecated (use solver.rtol)"),
}, default=None)

METRICS = Map(fields={
    "phases": ListOf(item=Num(unit="s", ge=0), min_len=2, default=None, doc="phase boundaries (default: quarters)"),
    "crossing_margin": Num(unit="s", ge=0, default=0.5, doc="excluded window around each v_r zero crossing"),
    "settle_tolerance": Num(unit="-", gt=0, default=0.05, doc="band of |theta_hat - theta| for the settling time"),
    "excitation_threshold": Num(unit="m/s", ge=0, default=0.05, doc="|v_r| counted as excitation"),
    "min_excitation": Num(unit="-", ge=0, le=1, default=0.5, doc="warn below this share of excited time"),
}, default=None)

GAIN_OVERRIDES = Map(fields={k: Num(unit="", default=None) for k in GAINS}, default=None)

CASE = Map(fields={
    "label": Str(doc="name of the case in legends and the CSV", max_len=MAX_TITLE_CHARS),
    "estimate": _estimate(required=False),
    "observer": GAIN_OVERRIDES,
    "measurement": MEASUREMENT,
    "theta": replace(THETA_PROFILE, default=None, doc="adhesion profile of this case"),
    "torque": replace(TORQUE_PROFILE, default=None, doc="torque profile of this case"),
})

GAIN_STUDY = Map(fields={
    "gain": Str(choices=GAINS, doc="the gain that varies"),
    "values": ListOf(item=Num(unit=""), min_len=2, doc="its values"),
}, default=None)

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="lugre", doc="LuGre parameter set (lumped, constant kappa0)"),
    "vehicle": Raw(kind="quarter_car", default=None, doc="quarter-car parameter set"),
    "observer": Raw(kind="observer", default=None, doc="observer gains (kind observer)"),
    "scenario": SCENARIO,
    "estimate": _estimate(required=True),
    "measurement": MEASUREMENT,
    "solver": SOLVER,
    "numerics": NUMERICS,
    "metrics": METRICS,
    "cases": ListOf(item=CASE, default=None, doc="variants of the run"),
    "gain_study": GAIN_STUDY,
    "output": Map(fields={"dt": Num(unit="s", gt=0, default=0.01, doc="CSV sampling interval")}, default=None),
})


# --------------------------------------------------------------------------- plan


@dataclass
class Case:
    """One simulation of the study."""

    label: str
    gains: lo.ObserverGains
    scenario: object          # tirecli.numerics.observer_integrator.Scenario
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
    from tirecli.numerics.observer_integrator import Scenario

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
class Plan:
    checked: dict
    tire: object
    vehicle: object
    gain_set: object
    plant: lo.ObserverPlant
    cases: list
    solver: object            # tirecli.numerics.observer_integrator.SolverOptions
    metrics: dict
    deprecated: list


def plan(config: Config) -> Plan:
    """Check an observe config completely (schema, parameter sets, profiles, cases) without running it."""
    checked = config.checked(SPEC)
    tire = config.group("tire", "lugre")
    vehicle = config.group("vehicle", "quarter_car", DEFAULT_VEHICLE)
    gain_set = config.group("observer", "observer", DEFAULT_GAINS)
    plant = lo.ObserverPlant(tire=tire.model(), car=vehicle.model())
    gains = gain_set.model()
    sc = checked["scenario"]
    est = checked["estimate"] or {"v_error": 0.0, "z": 0.0, "theta": 1.0}
    meas = checked["measurement"]
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
    _sample_estimate(checked, cases, solver, plant, config.origins).check(config.origins)   # + the solver's work
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
    return Plan(checked, tire, vehicle, gain_set, plant, cases, solver, metrics, deprecated)


#: Memory of one recorded time of a run (trajectory, frame, CSV text) and of one step of an adaptive
#: solver that is not recorded (``h_max``) [bytes].
BYTES_PER_POINT, BYTES_PER_STEP = 600, 50
#: Output grid of the adaptive methods [s] (``tirecli.numerics.observer_integrator.simulate``).
ADAPTIVE_OUTPUT_DT = 1e-3


def _sample_estimate(checked: dict, cases: list, solver, plant=None, origins=None):
    """Samples of an observe run before it starts, per case: the recorded times (the fixed scheme's grid
    of ``solver.step``, or the adaptive methods' 1 ms output grid; ``auto`` may run either), the
    measurement samples, the adaptive steps ``h_max`` forces and the CSV's ``output.dt`` grid (+ work)."""
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


# --------------------------------------------------------------------------- run


def _solver(checked: dict, config: Config):
    """``SolverOptions`` from ``solver:`` (or the deprecated ``numerics:``) and the deprecation notes."""
    from tirecli.numerics.observer_integrator import SolverOptions

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


def simulate_case(plan_: Plan, case: Case):
    """Run one case with the configured solver (``auto``: :func:`tirecli.numerics.observer_integrator.choose_method`)."""
    from tirecli.numerics import observer_integrator as oi

    return oi.simulate(plan_.plant, case.gains, case.scenario, case.sensor, plan_.solver)


def case_metrics(plant: lo.ObserverPlant, tr, case: Case, m: dict) -> dict:
    """Metrics of one run (docs/models/observer_model.md §7-§8; see :mod:`tirecli.observers.metrics`)."""
    r = plant.car.r
    vr = r * tr.omega - tr.v
    err = tr.theta_hat - tr.theta
    crossings = om.zero_crossings(tr.t, vr)
    slip = slip_from_speeds(tr.v, tr.omega, r)
    return {
        "crossings_s": crossings.tolist(),
        "phases": om.phase_errors(tr.t, err, m["phases"], crossings, m["crossing_margin"]),
        "all_excl_crossings": om.phase_errors(tr.t, err, [tr.t[0], tr.t[-1]], crossings, m["crossing_margin"])[0],
        "settling": om.settle_times(tr.t, err, case.changes, m["settle_tolerance"]),
        "max_abs_v_error": float(np.max(np.abs(tr.v_hat - tr.v))),
        "final_v_error": float(tr.v_hat[-1] - tr.v[-1]),
        "excitation_share": om.excitation_share(tr.t, vr, m["excitation_threshold"]),
        "slip_range": [float(slip.min()), float(slip.max())],
        "v_range": [float(tr.v.min()), float(tr.v.max())],
        "theta_hat_final": float(tr.theta_hat[-1]),
    }


def design_record(plant: lo.ObserverPlant, gains: lo.ObserverGains, tr=None) -> dict:
    """Design facts of a gain set (docs/models/observer_model.md §4-§6), JSON-ready."""
    obs = lo.observability(plant)
    tf = lo.transfer_function(plant, gains)
    rec = {
        "gains": gains.as_dict(),
        "observability": {"det": obs["det"], "det_closed_form": obs["det_closed_form"], "factor": obs["factor"],
                          "rank": obs["rank"]},
        "error_poles_1_s": [complex(p).real if abs(complex(p).imag) < 1e-9 * abs(p) else str(complex(p))
                            for p in lo.error_poles(plant, gains)],
        "slow_pole_estimate_1_s": lo.slow_pole_estimate(plant, gains),
        "fast_rate_1_s": float(plant.fast_rate(gains, 1.0)),
        "transfer_function": {k: tf[k] for k in ("k_c", "a1", "a0", "b2", "b1", "b0")}
        | {"re_coeffs": list(tf["re_coeffs"]), "zeros": [float(np.real(z)) for z in tf["zeros"]]},
        "conditions": [c.record() for c in lo.design_conditions(plant, gains)],
        "k3_threshold_m": plant.car.J * plant.tire.sigma0 / (plant.car.r * plant.car.F_n * plant.tire.sigma1 ** 2),
    }
    if tr is not None:
        vr = plant.car.r * tr.omega - tr.v
        lip = lo.lipschitz_sizes(plant, float(np.max(np.abs(vr))), float(np.max(np.abs(tr.omega))),
                                 float(np.max(np.abs(tr.z))))
        pm = lo.passivity_margin(plant, gains)
        theta_max = float(np.max(tr.theta))
        rec["lipschitz"] = lip | {"vr_max": float(np.max(np.abs(vr))), "omega_max": float(np.max(np.abs(tr.omega))),
                                  "z_max": float(np.max(np.abs(tr.z)))}
        rec["passivity"] = {"lambda_min_q": pm["lambda_min_q"],
                            "alpha_bound_17_m": lo.alpha_bound(pm["lambda_min_q"], theta_max, lip["L_phi"], lip["L_psi"]),
                            "note": "sufficient bound (17); OBS's alpha is a practical tuning value (docs/models/observer_model.md §6)"}
    return rec


def slow_mode(plant: lo.ObserverPlant, case: Case, tr) -> dict:
    """The slow speed-error mode of a run with theta known (adaptation off, docs/models/observer_model.md §6, §8):
    the decay rate [1/s] of ``v_hat - v`` fitted from 2 s to the end, and the largest real part [1/s] of the
    eigenvalues of the error dynamics linearised at the run's middle sample."""
    i = len(tr.t) // 2
    M = lo.linearized_error_matrix(plant, case.gains, float(tr.theta[i]), float(tr.omega[i]), float(tr.v[i]),
                                   float(tr.z[i]))
    return {"fitted_1_s": om.decay_rate(tr.t, tr.v_hat - tr.v, 2.0, tr.t[-1]),
            "linearised_1_s": float(np.max(np.linalg.eigvals(M).real))}


def _frame(plant, tr, label, dt_out) -> pd.DataFrame:
    import pandas as pd

    r = plant.car.r
    keep = _decimate(tr.t, dt_out)
    t = tr.t[keep]
    v, w, y = tr.v[keep], tr.omega[keep], tr.y[keep]
    vh = tr.v_hat[keep]
    return pd.DataFrame({
        "case": label, "t": t,
        "theta": tr.theta[keep], "theta_hat": tr.theta_hat[keep],
        "theta_fm": theta_fm_from_obs(tr.theta[keep]), "theta_hat_fm": _safe_inv(tr.theta_hat[keep]),
        "v": v, "v_hat": vh, "omega": w, "omega_meas": y,
        "vr": r * w - v, "vr_hat": r * y - vh, "slip": slip_from_speeds(v, w, r),
        "z": tr.z[keep], "z_hat": tr.z_hat[keep], "torque": tr.torque[keep],
    })


def _safe_inv(x):
    x = np.asarray(x, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(x != 0.0, 1.0 / np.where(x != 0.0, x, 1.0), np.nan)


def _decimate(t, dt):
    """Indices of ``t`` nearest to a ``dt`` grid (first and last kept)."""
    if dt <= 0 or len(t) < 3:
        return np.arange(len(t))
    target = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    idx = np.unique(np.clip(np.searchsorted(t, target - 1e-9), 0, len(t) - 1))
    return np.unique(np.concatenate([idx, [len(t) - 1]]))


def _adaptation_off(case: Case, tr) -> str:
    """What ``gamma = 0`` means for a run, in words: theta_hat is frozen at its initial value."""
    th0 = float(case.scenario.theta_hat0)
    lo_, hi_ = float(np.min(tr.theta)), float(np.max(tr.theta))
    head = (f"{case.label}: adaptation off (gamma = 0): theta_hat stays at its initial value {th0:g} "
            "(OBS convention) for the whole run and the observer estimates only v and z. ")
    if abs(hi_ - th0) <= 1e-12 * max(1.0, abs(th0)) and abs(lo_ - th0) <= 1e-12 * max(1.0, abs(th0)):
        return head + (f"Here the road's theta is {th0:g} throughout, so this is the 'theta known' observer the case "
                       "asks for; on a road whose theta differs, v_hat and z_hat would be biased. Set gamma > 0 to "
                       "estimate theta (OBS Fig. 2: gamma = 2e5).")
    return head + (f"The road's theta varies over [{lo_:g}, {hi_:g}] and theta_hat cannot follow it, so v_hat and "
                   "z_hat are biased; set gamma > 0 to estimate theta (OBS Fig. 2: gamma = 2e5).")


def _warnings(case: Case, design: dict, met: dict, m: dict, tr) -> list[str]:
    out = []
    for c in design["conditions"]:
        if c["id"] == "gamma-positive" and c["value"] == 0:
            out.append(_adaptation_off(case, tr))
        elif not c["ok"]:
            out.append(f"{case.label}: design condition '{c['id']}' fails: {c['requirement']} "
                       f"(value {c['value']:.4g}); {c['meaning']}")
    if met["excitation_share"] < m["min_excitation"]:
        out.append(f"{case.label}: excitation: |v_r| > {m['excitation_threshold']:g} m/s only "
                   f"{100 * met['excitation_share']:.0f}% of the time (< {100 * m['min_excitation']:.0f}%): theta is "
                   "not observable while v_r = 0 (A4, docs/models/observer_model.md §8)")
    if np.any(tr.v < 0) or np.any(tr.omega < 0):
        out.append(f"{case.label}: the vehicle or the wheel reverses; the model assumes forward motion")
    return out


@register_study("observe", check=plan, spec=SPEC)
def run_observe(config: Config, progress=None) -> StudyResult:
    """Run an observe config (see module doc)."""
    p = plan(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    checked = p.checked
    sc = checked["scenario"]
    dt_out = (checked["output"] or {}).get("dt", 0.01)
    frames, rows, runs, trajs, slow = [], [], [], [], {}
    warnings = list(p.deprecated)
    designs = {}
    if progress is not None:
        progress.start(len(p.cases), "observe")
    for k, case in enumerate(p.cases):
        tr = simulate_case(p, case)
        trajs.append(tr)
        key = tuple(case.gains.as_dict().values())
        if key not in designs:
            designs[key] = design_record(p.plant, case.gains, tr if k == 0 else None)
        met = case_metrics(p.plant, tr, case, p.metrics)
        if case.gains.gamma == 0:
            slow[case.label] = slow_mode(p.plant, case, tr)
        warnings += _warnings(case, designs[key], met, p.metrics, tr)
        frames.append(_frame(p.plant, tr, case.label, dt_out))
        for ph in met["phases"]:
            rows.append({"case": case.label, "phase_start": ph["start"], "phase_end": ph["end"], "rms": ph["rms"],
                         "max": ph["max"], "rms_excl_crossings": ph["rms_excl"], "max_excl_crossings": ph["max_excl"]})
        runs.append({"label": case.label, "gains": case.gains.as_dict(), "measurement": case.sensor.record(),
                     "theta_hat0_obs": case.scenario.theta_hat0, "v_hat0": case.scenario.vhat0,
                     "integrator": tr.method, "integrator_info": tr.info, "metrics": met,
                     "theta_profile": case.theta_profile.record()})
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    synthetic = any(c.sensor.synthetic for c in p.cases)
    assumed = [sc["assumed"]] if sc["assumed"] else []
    gstudy = checked["gain_study"]
    data = {"observer": pd.concat(frames, ignore_index=True), "metrics": pd.DataFrame(rows)}
    if gstudy:
        data["gain_study"] = pd.DataFrame({
            "gain": gstudy["gain"], "value": gstudy["values"],
            "settle_time_s": [_first_settle(r["metrics"]["settling"]) for r in runs],
            "rms_excl_crossings": [r["metrics"]["all_excl_crossings"]["rms_excl"] for r in runs],
            "max_abs_v_error": [r["metrics"]["max_abs_v_error"] for r in runs],
        })
    default_fig = "obs-gain-study" if gstudy else "obs-fig2"
    return StudyResult(
        study="observe",
        config=config,
        parameter_sets={"tire": p.tire, "vehicle": p.vehicle, "observer": p.gain_set},
        data=data,
        meta={
            "title": checked["title"],
            "theta_convention": "theta and theta_hat columns: OBS convention (theta multiplies sigma0 |vr|/g; 1 dry, "
                                "larger = less grip); theta_fm = 1/theta_obs (fraction of dry grip)",
            "theta_convention_input": sc["theta_convention"],
            "plant": "quarter car, lumped LuGre with constant kappa = kappa0/L = "
                     f"{p.plant.kappa:g} 1/m, sigma2 in the vehicle equation only (OBS (3)-(5))",
            "assumed": assumed,
            "solver": asdict(p.solver),
            "metric_settings": p.metrics,
            "design": list(designs.values()),
            "runs": runs,
            "warnings": warnings,
            "gain_study": gstudy,
        },
        figures=checked["figures"] or [default_fig],
        payload={"plant": p.plant, "cases": p.cases, "trajectories": trajs, "runs": runs, "designs": designs,
                 "metrics": p.metrics, "slow_mode": slow},
        synthetic=synthetic,
    )


def _first_settle(settling: list) -> float:
    """Settling time [s] after the first adhesion change (nan if it never settles)."""
    for s in settling:
        return float("nan") if s["time"] is None else s["time"]
    return float("nan")
