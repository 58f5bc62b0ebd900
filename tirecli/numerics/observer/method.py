"""The method of ``solver:`` (:class:`SolverOptions`), the choice of ``auto`` and the entry point :func:`simulate`.

:func:`simulate` runs the method of ``solver:`` (:class:`SolverOptions`): ``fixed``
(:func:`~tirecli.numerics.observer.fast.simulate_fast`), ``lsoda``/``radau``/``bdf``
(:func:`~tirecli.numerics.observer.adaptive.simulate_adaptive`, split at every
breakpoint and sample; a segment where LSODA stalls in its non-stiff mode is redone with BDF) or
``auto`` (:func:`choose_method`: LSODA for the ideal measurement, the fixed scheme for a sampled one
when ``lambda_f``, ``h rho_slow`` and ``h rho_block`` allow it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from tirecli.errors import RunError
from tirecli.numerics.observer.adaptive import simulate_adaptive
from tirecli.numerics.observer.fast import DEFAULT_STEP, MIN_FAST_RATE, StepTooLarge, simulate_fast
from tirecli.numerics.observer.scenario import Scenario, Trajectory
from tirecli.numerics.solver_guard import failure_message, quiet
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant
from tirecli.observers.measurement import Sensor

#: Methods of ``solver.method``.
METHODS = ("auto", "fixed", "lsoda", "radau", "bdf")
#: Default relative tolerance of the adaptive methods (LSODA: 6e-6 in theta_hat on the Fig. 2 run).
DEFAULT_RTOL = 1e-7
#: ``auto`` keeps the fixed step only while ``h rho_block`` stays below this (module doc of :func:`choose_method`).
BLOCK_RATE_LIMIT = 0.5
#: ... and when ``h rho_slow`` is below this.
SLOW_RATE_LIMIT = 1e-3


@dataclass(frozen=True)
class SolverOptions:
    """``solver:`` of an observe config.

    Attributes
    ----------
    method : str
        ``auto`` (default), ``fixed``, ``lsoda``, ``radau`` or ``bdf``.
    rtol : float
        Relative tolerance of the adaptive methods [-].
    atol : float or None
        Absolute tolerance (``None``: ``rtol`` times :func:`~tirecli.numerics.observer.adaptive.state_scales`).
    step : float
        Largest step of the fixed scheme [s].
    h_max : float or None
        Largest step of the adaptive methods [s] (``None``: unlimited).
    """

    method: str = "auto"
    rtol: float = DEFAULT_RTOL
    atol: float | None = None
    step: float = DEFAULT_STEP
    h_max: float | None = None


def slow_rate(plant: ObserverPlant, gains: ObserverGains, theta_hat: float = 1.0) -> float:
    """Rate ``rho_slow = c_eta + k1 P/(r m J lambda_f)`` [1/s] of the speed-error mode on the slow manifold.

    The singular-perturbation form of the slow pole of docs/models/observer_model.md §6 (``k1/(r m |k3|)`` for
    ``alpha = 0``): 0.0294 1/s for the OBS gains, 11.4 1/s for ``k1 = 1e6``.
    """
    lam = float(plant.fast_rate(gains, theta_hat))
    c = plant.car
    return plant.c_eta + abs(gains.k1) * plant.P / (c.r * c.m * c.J * lam) if lam > 0 else math.inf


def choose_method(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario, sensor: Sensor | None,
                  opts: SolverOptions) -> tuple[str, str]:
    """The method ``auto`` runs, and why: ``("fixed" | "lsoda", reason)``.

    Measured on this project's benchmark (benchmarks/bench_observer.py):

    - with the ideal measurement LSODA on the full system is faster than the fixed scheme at
      every accuracy (about as fast as the 5 ms step for its 3e-4 in theta_hat, 8x faster at 5e-6),
      and it follows stiff gains, where the fixed scheme does not: LSODA, guarded against its stall
      in the non-stiff mode (:func:`~tirecli.numerics.observer.adaptive._lsoda_guarded`: such a segment is
      redone with BDF);
    - with a sampled measurement every sample is an input jump an adaptive method must restart
      at (about 90 rhs calls, 2.5 ms each time: 2.5 s per simulated second at 1 kHz), while the
      fixed scheme takes the fast layer after a jump in closed form (0.02 s per simulated second):
      the fixed scheme when it is stable and accurate for the gains at hand, else LSODA.

    The fixed scheme is stable and accurate when (i) the observer's fast mode
    ``lambda_f = C K_eff`` is at least 1e5 1/s (its singular-perturbation reduction), (ii)
    ``h rho_slow <= 1e-3`` (:func:`slow_rate`: the trapezoid integrates the speed-error block with
    the plant's transients, up to 1e3 1/s and not resolved by the step, as forcing; with
    ``k1 = 1e6`` and a 3 m/s start error ``h rho_slow = 0.029`` gave a v_hat error of 0.2 m/s) and
    (iii) ``h rho_block <= 0.5`` along the run (checked at every step by :func:`simulate_fast`,
    which then hands over to LSODA).
    """
    sensor = sensor or Sensor()
    if sensor.ideal:
        return "lsoda", ("ideal measurement: LSODA is faster than the fixed step at equal accuracy (a segment where "
                         "it stalls in its non-stiff mode is redone with BDF)")
    lam = float(plant.fast_rate(gains, scenario.theta_hat0))
    if not lam >= MIN_FAST_RATE:
        return "lsoda", (f"observer fast mode lambda_f = {lam:.3g} 1/s < {MIN_FAST_RATE:g} 1/s: the fixed scheme's "
                         "reduction does not apply")
    h = min(opts.step, 0.5 * sensor.period)
    hs = h * slow_rate(plant, gains, scenario.theta_hat0)
    if hs > SLOW_RATE_LIMIT:
        return "lsoda", (f"step x slow-mode rate = {hs:.3g} > {SLOW_RATE_LIMIT:g}: the fixed step is inaccurate "
                         "for these gains")
    return "fixed", (f"sampled measurement ({sensor.rate:g} Hz): the fixed scheme's closed-form fast layers avoid "
                     f"a restart per sample; step x slow-mode rate = {hs:.2g}")


def simulate(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario, sensor: Sensor | None = None,
             opts: SolverOptions | None = None, output_dt: float = 1e-3) -> Trajectory:
    """Simulate plant + observer with the method of ``opts`` (``auto``: :func:`choose_method`).

    ``info["chosen_because"]`` says why ``auto`` chose its method; a fixed run that hits
    ``h rho_block > 0.5`` is redone with LSODA (``info["fallback"]``).
    """
    opts = opts or SolverOptions()
    method = opts.method
    reason = None
    if method == "auto":
        method, reason = choose_method(plant, gains, scenario, sensor, opts)
    if method == "fixed":
        try:
            with quiet():
                tr = simulate_fast(plant, gains, scenario, sensor, step=opts.step,
                                   rate_limit=BLOCK_RATE_LIMIT if reason else math.inf)
        except (ArithmeticError, ValueError) as exc:   # math.exp overflow, a square root of a negative number
            raise RunError(failure_message("fixed", 0.0, detail=f"{type(exc).__name__}: {exc}",
                                           sampled=not (sensor or Sensor()).ideal)) from None
        except StepTooLarge as exc:
            tr = simulate_adaptive(plant, gains, scenario, sensor, method="lsoda", rtol=opts.rtol, atol=opts.atol,
                                   h_max=opts.h_max, output_dt=output_dt)
            tr.info["fallback"] = f"fixed step left at t = {exc.t:.4g} s (step x rate = {exc.h_rate:.3g} > {exc.limit:g})"
            reason = f"{reason}; {tr.info['fallback']}: LSODA"
    else:
        tr = simulate_adaptive(plant, gains, scenario, sensor, method=method, rtol=opts.rtol, atol=opts.atol,
                               h_max=opts.h_max, output_dt=output_dt)
    if reason:
        tr.method = f"auto: {tr.method}"
        tr.info["chosen_because"] = reason
    return tr
