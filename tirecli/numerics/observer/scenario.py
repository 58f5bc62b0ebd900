"""One plant/observer run (:class:`Scenario`), its record (:class:`Trajectory`); the fixed scheme's time grid.

The types every method of :mod:`tirecli.numerics.observer` shares; :func:`time_grid` and :func:`step_profiles` are the
grid and the inputs on it of the fixed-step scheme (:func:`tirecli.numerics.observer.fast.simulate_fast`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from tirecli.conventions import theta_obs_from_fm

#: Steps after t = 0 and each breakpoint are graded down to step/2^GRADING.
GRADING = 4


@dataclass(frozen=True)
class Scenario:
    """One plant/observer run.

    Attributes
    ----------
    duration : float
        Simulated time [s].
    torque : callable
        ``u(t)`` wheel torque [N m] (> 0 drives), vectorized (:mod:`tirecli.models.profiles`).
    theta_fm : callable
        ``theta_fm(t)`` road adhesion in the canonical FM convention [-], vectorized.
    v0 : float
        Initial vehicle speed [m/s].
    omega0 : float
        Initial wheel speed [rad/s].
    z0 : float
        Initial bristle deflection [m].
    v_hat0 : float
        Initial speed estimate [m/s].
    z_hat0 : float
        Initial deflection estimate [m].
    theta_hat0 : float
        Initial adhesion estimate in the OBS convention [-].
    breakpoints : tuple
        Times [s] where ``torque`` or ``theta_fm`` may jump or kink (grid points of the fast scheme).
    """

    duration: float
    torque: Callable
    theta_fm: Callable
    v0: float
    omega0: float
    z0: float = 0.0
    v_hat0: float | None = None
    z_hat0: float = 0.0
    theta_hat0: float = 1.0
    breakpoints: tuple = ()

    @property
    def vhat0(self) -> float:
        return self.v0 if self.v_hat0 is None else self.v_hat0


@dataclass
class Trajectory:
    """Recorded run: plant, measurement and observer, on the output grid ``t``.

    ``theta`` and ``theta_hat`` are in the OBS convention (``theta_obs = 1/theta_fm``).
    """

    t: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    z: np.ndarray
    y: np.ndarray           # measured wheel speed [rad/s]
    v_hat: np.ndarray
    z_hat: np.ndarray
    theta_hat: np.ndarray
    y_tilde: np.ndarray     # output error y - C x_hat [rad/s]
    theta: np.ndarray
    torque: np.ndarray
    method: str = "fast"
    info: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- time grid


def time_grid(duration: float, step: float, breakpoints=(), samples=(), grading: int = GRADING) -> np.ndarray:
    """Grid on ``[0, duration]`` of steps ``<= step`` containing every breakpoint and sampling instant.

    After ``t = 0`` and each breakpoint the steps are graded (``step 2^-k``, k = ``grading`` .. 1) to
    resolve the fast plant transient a jump of the inputs starts. Points closer than ``1e-9 step`` to
    an existing point are merged (no sliver steps).
    """
    n = max(int(math.ceil(duration / step - 1e-9)), 1)
    starts = [0.0] + [b for b in breakpoints if 0.0 < b < duration]
    graded = [b + step * 2.0 ** -k for b in starts for k in range(1, grading + 1)]
    pts = np.concatenate([np.linspace(0.0, duration, n + 1), starts, graded, np.asarray(samples, dtype=float)])
    pts = np.unique(pts[(pts >= 0.0) & (pts <= duration)])
    keep = np.concatenate([[True], np.diff(pts) > 1e-9 * step])
    pts = pts[keep]
    pts[-1] = duration
    return pts


def step_profiles(scenario: Scenario, grid: np.ndarray):
    """Torque and ``theta_obs`` at each step's start (right limit), end (left limit) and midpoint."""
    t0, t1 = grid[:-1], grid[1:]
    eps = 1e-9 * np.maximum(1.0, np.abs(t1))
    tm = 0.5 * (t0 + t1)
    u = scenario.torque
    th = lambda t: theta_obs_from_fm(scenario.theta_fm(t))  # noqa: E731
    return (np.asarray(u(t0), float), np.asarray(u(t1 - eps), float), np.asarray(th(t0), float),
            np.asarray(th(t1 - eps), float), np.asarray(th(tm), float))
