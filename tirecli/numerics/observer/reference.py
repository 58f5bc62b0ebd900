"""The plant + observer system composed from the models' right-hand sides, and the Radau reference run.

:func:`full_rhs` is the system built from :func:`tirecli.models.quarter_car.rhs` and
:func:`tirecli.observers.observer.rhs` (the straightforward form the benchmark once timed);
:func:`simulate_reference` is :func:`tirecli.numerics.observer.adaptive.simulate_adaptive` with the reference
Radau settings of docs/models/observer_model.md §7.
"""
from __future__ import annotations

import numpy as np

from tirecli.numerics.observer.adaptive import simulate_adaptive
from tirecli.numerics.observer.scenario import Scenario, Trajectory
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant
from tirecli.observers.measurement import Sensor


def full_rhs(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario):
    """``f(t, X, y)`` of plant + observer composed from the models, ``X = (v, omega, z, eta_hat, chi_hat, z_hat,
    theta_hat[, angle])``.

    Plant: :func:`tirecli.models.quarter_car.rhs` with ``QuarterCar(LumpedTire(plant.tire), plant.car,
    sigma2_in_wheel=False)`` (OBS (3)-(5); the scenario's adhesion ``theta_fm``); observer:
    :func:`tirecli.observers.observer.rhs` driven by the held measured wheel speed ``y`` [rad/s] (``None``:
    the ideal ``y = omega``); the wheel angle ``angle' = omega`` [rad] when ``X`` has an eighth state. The
    straightforward formulation, which :func:`tirecli.numerics.observer.adaptive.scalar_rhs` inlines (parity:
    tests/test_model_parity.py).
    """
    from tirecli.models import quarter_car
    from tirecli.models.lugre_lumped import LumpedTire
    from tirecli.observers import observer

    qc = quarter_car.QuarterCar(tire=LumpedTire(plant.tire), car=plant.car, sigma2_in_wheel=False)
    obs = observer.Observer(plant, gains)
    u_of = getattr(scenario.torque, "at", scenario.torque)  # scalar evaluation without numpy overhead
    th_of = getattr(scenario.theta_fm, "at", scenario.theta_fm)

    def f(t, X, y=None):
        u = float(u_of(t))
        parts = [quarter_car.rhs(t, X[:3], (u, float(th_of(t))), qc),
                 observer.rhs(t, X[3:7], (X[1] if y is None else y, u), obs)]
        if len(X) > 7:
            parts.append([X[1]])
        return np.concatenate(parts)

    return f


def simulate_reference(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario, sensor: Sensor | None = None,
                       rtol: float = 1e-8, atol=None, max_step: float | None = 5e-3, output_dt: float = 1e-3,
                       method: str = "radau") -> Trajectory:
    """Radau on the full system, split at breakpoints and samples (rtol 1e-8, max step 5 ms: docs/models/observer_model.md §7).

    :func:`simulate_adaptive` with the reference settings of docs/models/observer_model.md §7.
    """
    return simulate_adaptive(plant, gains, scenario, sensor, method=method, rtol=rtol, atol=atol, h_max=max_step,
                             output_dt=output_dt)
