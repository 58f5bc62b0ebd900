"""The work of an observer run, estimated before it starts, and gains no adaptive solver can integrate.

An observe run's cost depends on the method that will run (``solver.method``, or what ``auto`` picks:
:func:`planned_method`), on the measurement (an adaptive method restarts at every sample) and on the gains
(the adaptation loop can ring: :mod:`tirecli.observers.envelope`). :func:`work_terms` gives the solver
work in **evaluations of the model at LSODA's cost** (a Radau evaluation costs 2.4 of them, a BDF one 3.3:
:data:`tirecli.numerics.solver_guard.CALL_WORK`), so that one sample budget (:mod:`tirecli.limits`) bounds
the time of every method alike (a million such evaluations take 25-70 s):

- **restarts** (adaptive methods): one at every measurement sample and input breakpoint, each costing
  :data:`RESTART_WORK` (measured on the OBS noise scenario at 1 and 10 kHz: LSODA 94-138 evaluations a
  restart, Radau 134-210, BDF 83-113);
- **ringing**: an adaptation loop with damping ratio below :data:`ZETA_RING` rings at ``omega_a`` for as
  long as the tyre works near its knee; an error-controlled method follows it with
  :data:`STEPS_PER_PERIOD` steps (:data:`EVALS_PER_STEP` evaluations each) a period over the run (OBS
  Fig. 2 with LSODA: ``gamma = 1e12``, ``zeta = 0.043``, ends after 16,000 evaluations; ``gamma = 2e12``,
  ``zeta = 0.030``, had made 183,000 by 7 s of 20 s; ``gamma = 1e13``, ``zeta = 0.014``, 250,000 by 12 s);
- **inputs** (adaptive methods): the same per period of a formula input's fastest oscillation.

The fixed scheme's grid is counted by the study (its recorded times); when the gains make its slow
block too fast for the step (``h rho > 0.5``), ``auto`` will fall back to LSODA, which is then estimated.

:func:`injection_problem`: the output injection ``K_eff = (k1, k2, k3 - alpha (1 + theta))`` multiplies
the rounding noise of the output error ``y~ = y - C x_hat`` (``eps |omega|``, a difference of numbers of the
size of the wheel speed) into the estimates' derivatives; over a step of :data:`H_REF` that noise must stay
below each estimate's tolerance, or no adaptive method converges (LSODA: "repeated convergence
failures"). The bound is ``|K_eff,i| eps |omega| H_REF <= atol_i + rtol scale_i``: on OBS Fig. 2 at rtol
1e-7, ``alpha <= 3e6``; measured: 3e6 runs, 6e6 and 1e7 fail (Radau and BDF slow down 10-20x there). A
torque that spins the wheel up raises ``|omega|`` and with it the noise: then the torque is at fault.

At run time :func:`tirecli.numerics.observer.adaptive.simulate_adaptive` counts the same work
(:class:`tirecli.numerics.solver_guard.WorkGuard`) and stops a run that passes the budget.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.conventions import theta_obs_from_fm
from tirecli.observers.envelope import Envelope, adaptation_loop, operating_envelope

#: Work of one restart of an adaptive method [evaluations of LSODA's cost] (module doc: the evaluations
#: measured a restart, times :data:`~tirecli.numerics.solver_guard.CALL_WORK`).
RESTART_WORK = {"lsoda": 120.0, "radau": 400.0, "bdf": 330.0}
#: An adaptation loop rings (must be followed by the steps) below this damping ratio.
ZETA_RING = 0.02
#: Steps per period of an oscillation an error-controlled method follows, and evaluations per step (LSODA: 2.7).
STEPS_PER_PERIOD, EVALS_PER_STEP = 10, 2.7
#: The step over which the injected rounding noise must stay within the tolerance [s] (the adaptive
#: methods' 1 ms output grid; their steps on the OBS scenarios are of this size).
H_REF = 1e-3
#: Relative rounding error of a double.
EPS = float(np.finfo(float).eps)
#: Names of the injection components (what :func:`injection_problem` blames).
INJECTED = ("eta_hat", "chi_hat", "z_hat")


#: Points of the grid a scenario's torque and adhesion are sampled on for its envelope (plus its breakpoints).
ENVELOPE_POINTS = 2001


def scenario_envelope(plant, scenario) -> Envelope:
    """The :class:`~tirecli.observers.envelope.Envelope` of a scenario (its torque and adhesion sampled over the run)."""
    T = float(scenario.duration)
    t = np.unique(np.concatenate([np.linspace(0.0, T, ENVELOPE_POINTS),
                                  [b for b in scenario.breakpoints if 0.0 <= b <= T]]))
    with np.errstate(all="ignore"):
        u = np.asarray(scenario.torque(t), dtype=float)
        th = np.asarray(theta_obs_from_fm(scenario.theta_fm(t)), dtype=float)
    th = np.append(th, float(scenario.theta_hat0))
    return operating_envelope(plant, scenario.v0, t, u, th[np.isfinite(th)])


def planned_method(plant, gains, scenario, sensor, opts, env: Envelope) -> tuple[str, str]:
    """The method a run will use, and why: ``solver.method``, or ``auto``'s choice
    (:func:`tirecli.numerics.observer.method.choose_method`), with the fall-back to LSODA that ``auto``
    makes when the fixed scheme's slow block is too fast for its step at the operating point."""
    from tirecli.numerics.observer.method import BLOCK_RATE_LIMIT, choose_method, slow_rate

    if opts.method != "auto":
        return opts.method, "solver.method"
    method, why = choose_method(plant, gains, scenario, sensor, opts)
    if method != "fixed":
        return method, why
    wa, zeta = adaptation_loop(plant, gains, env.phi, scenario.theta_hat0)
    lam = float(plant.fast_rate(gains, scenario.theta_hat0))
    rho = wa * wa / lam + slow_rate(plant, gains, scenario.theta_hat0) if zeta >= 1.0 else math.inf
    h = min(opts.step, 0.5 * sensor.period) if not sensor.ideal else opts.step
    if h * rho > BLOCK_RATE_LIMIT:
        return "lsoda", f"the fixed step x slow-block rate {h * rho:.3g} > {BLOCK_RATE_LIMIT:g} at the operating point"
    return method, why


def work_terms(plant, gains, scenario, sensor, opts, env: Envelope, profiles=()) -> list[tuple[str, float, str]]:
    """The solver work of one run before it starts: ``(kind, steps, what)`` with ``kind`` ``restarts``,
    ``ringing`` or ``inputs`` (module doc); ``profiles``: the input profiles (torque, adhesion) whose
    oscillations an adaptive method follows. Empty for the fixed scheme (its grid is the study's count)."""
    method, _ = planned_method(plant, gains, scenario, sensor, opts, env)
    if method == "fixed":
        return []
    T = float(scenario.duration)
    out = []
    samples = 0 if sensor.ideal else math.floor(T * sensor.rate + 1e-9) + 1
    restarts = samples + len(scenario.breakpoints) + 1
    per = RESTART_WORK.get(method, RESTART_WORK["bdf"])
    out.append(("restarts", restarts * per,
                f"the {method} solver's {restarts:,} restarts (one at each measurement sample and input breakpoint, "
                f"~{per:g} model evaluations of LSODA's cost each)"))
    wa, zeta = adaptation_loop(plant, gains, env.phi, scenario.theta_hat0)
    if zeta < ZETA_RING:
        wd = wa * math.sqrt(max(1.0 - zeta * zeta, 0.0))
        cause = (f"the torque (up to {env.torque_max:.3g} N m, the tyre transmits {env.capacity:.3g}) spins the wheel "
                 f"to |v_r| ~ {env.vr:.3g} m/s" if env.spin else f"the tyre near its knee, |v_r| ~ {env.vr:.3g} m/s")
        out.append(("ringing", T * wd / (2.0 * math.pi) * STEPS_PER_PERIOD * EVALS_PER_STEP,
                    f"the steps to follow the adaptation loop's ringing at {wd:.3g} rad/s (damping ratio {zeta:.2g}, "
                    f"gamma = {gains.gamma:g}, |phi| ~ {env.phi:.3g} m/s: {cause}; {STEPS_PER_PERIOD} steps a period "
                    f"over {T:g} s)"))
    hz = max((float(p.frequency(T)) for p in profiles if hasattr(p, "frequency")), default=0.0)
    if hz > 0.0:
        out.append(("inputs", T * hz * STEPS_PER_PERIOD * EVALS_PER_STEP,
                    f"the steps to follow the inputs' oscillation at up to {hz:.3g} Hz ({STEPS_PER_PERIOD} a period "
                    f"over {T:g} s)"))
    return out


def injection_problem(plant, gains, scenario, sensor, opts, env: Envelope, given=()) -> tuple[str, str] | None:
    """``(key, message)`` when an adaptive run cannot converge because the output injection amplifies rounding
    noise beyond the tolerance (module doc), with ``key`` the input at fault: the gain (``k1``, ``k2``, ``k3``,
    ``alpha``) when the user gave it (``given``: the gains the config sets), else what made a usual gain too
    much: ``torque`` (it spins the wheel up), ``rtol`` (tighter than the default), ``theta`` (an adhesion that
    makes ``alpha (1 + theta)`` or the knee's slip speed extreme), ``v0`` (the speed), else the gain. None when
    the run is fine or will use the fixed scheme (which takes the fast layer in closed form)."""
    from dataclasses import replace

    from tirecli.numerics.observer.method import DEFAULT_RTOL

    method, _ = planned_method(plant, gains, scenario, sensor, opts, env)
    if method == "fixed":
        return None
    r, v0 = plant.car.r, abs(scenario.v0)
    omega = (v0 + env.vr) / r
    bad = _injection(plant, gains, opts, env.theta_max, omega, method)
    if bad is None or bad[0] in given:
        return bad
    tail = (f"the observer's output injection then amplifies the rounding noise of the wheel speed ({omega:.3g} rad/s) "
            f"beyond the tolerance of solver.rtol {opts.rtol:g}, and no adaptive solver converges")
    if env.spin and _injection(plant, gains, opts, env.theta_max, (v0 + env.knee) / r, method) is None:
        return "torque", (f"up to {env.torque_max:g} N m is far more than the tyre transmits ({env.capacity:.3g} N m): "
                          f"the wheel would spin up to |v_r| ~ {env.vr:.3g} m/s; {tail}; give a torque the tyre can transmit")
    if opts.rtol < DEFAULT_RTOL and _injection(plant, gains, replace(opts, rtol=DEFAULT_RTOL), env.theta_max, omega,
                                               method) is None:
        return "rtol", (f"{opts.rtol:g} is tighter than the rounding noise the observer's output injection puts into the "
                        f"estimates at {omega:.3g} rad/s allows (no adaptive solver converges); use {DEFAULT_RTOL:g} "
                        "(the default) or looser")
    if env.theta_max > 1.0 and _injection(plant, gains, opts, 1.0, omega, method) is None or env.vr > v0:
        return "theta", (f"theta_obs from {env.theta_min:.3g} to {env.theta_max:.3g} (OBS convention) is beyond the "
                         f"model's range: {tail}")
    if v0 > 1.0 and _injection(plant, gains, opts, env.theta_max, (1.0 + env.vr / v0) / r, method) is None:
        return "v0", f"{v0:g} m/s turns the wheel at {omega:.3g} rad/s: {tail}"
    return bad


def _injection(plant, gains, opts, theta_max: float, omega: float, method: str) -> tuple[str, str] | None:
    """The first injection component whose rounding noise at wheel speed ``omega`` [rad/s] exceeds its tolerance."""
    from tirecli.numerics.observer.adaptive import state_scales

    noise = EPS * omega * H_REF
    scales = state_scales(plant)[3:6]
    k3_alpha = gains.alpha * (1.0 + theta_max)
    k_eff = (gains.k1, gains.k2, gains.k3 - k3_alpha)
    for i, (k, scale) in enumerate(zip(k_eff, scales)):
        atol = opts.rtol * scale if opts.atol is None else float(opts.atol)
        tol = atol + opts.rtol * scale
        if abs(k) * noise <= tol:
            continue
        room = tol / noise
        if i == 2 and abs(k3_alpha) >= abs(gains.k3):
            name, value, most = "alpha", gains.alpha, max(room - abs(gains.k3), 0.0) / (1.0 + theta_max)
        else:
            name = ("k1", "k2", "k3")[i]
            value, most = getattr(gains, name), room
        return name, (f"{value:g} is more than an adaptive solver can integrate in double precision: it injects "
                      f"the rounding noise of the measured wheel speed ({EPS:.1e} x {omega:.3g} rad/s) into "
                      f"{INJECTED[i]} beyond the tolerance of solver.rtol {opts.rtol:g} (the {method} run would not "
                      f"converge); here |{name}| may be at most about {most:.2g}: use a smaller {name} or a looser "
                      "solver.rtol")
    return None
