"""Adaptive second-order Rosenbrock (ROS2) time stepping of the quarter car and the tire alone.

The method (Verwer, Spee, Blom, Hundsdorfer, SIAM J. Sci. Comput. 20, 1999) with
``gamma = 1 + 1/sqrt(2)``, ``W = I - gamma h A``::

    W k1 = f(t, y)          + gamma h f_t
    W k2 = f(t + h, y + h k1) - 2 k1 - gamma h f_t
    y(t + h) = y + h (3/2 k1 + 1/2 k2)

is L-stable and of order 2 for *any* matrix ``A`` (a W-method): the steppers use the exact
partial derivatives where stiffness lives (bristle decay ``sigma0 |vr|/g + kappa |r omega|`` of
10^3-10^4 1/s, the wheel mode through ``sigma1``) and drop weak couplings. The explicit time
derivative ``f_t`` (input slopes ``du/dt``, ``dtheta/dt``) is essential: without it the stiff
components lag a moving equilibrium by O(h) (order reduction, measured). The embedded first-order
solution ``y + h k1`` gives the error estimate ``h (k1 + k2)/2``; steps adapt to keep it below
``tol`` in physical units (m/s for speeds, friction coefficient for bristle states) and end
exactly on the inputs' breakpoints (kinks of ramps, steps), so no step straddles a kink.

Modes of the wheel (lugre.md §7): *free* (quarter car), *locked* (``omega = 0`` held while the
brake torque can balance the tire torque ``|r F| <= T_b``; brake torque never drives the wheel
backwards) and *prescribed* (open loop: ``v(t)``, ``omega(t)`` given, only the tire states
integrate). **Stop condition:** a run ends at ``t_end``, or when the vehicle speed falls to
``v_stop`` (the quarter car has no model of a vehicle at rest; LuGre itself stays defined at
``v = 0``: no division by zero anywhere).

A stepper (see :mod:`tirecli.numerics.lumped`, :mod:`tirecli.numerics.characteristics`) provides
``start(t, y, mode) -> E`` (right-hand side, Jacobian and outputs at ``(t, y)``),
``attempt(E, h, left) -> (y_new, err)`` (``left``: the step ends on a breakpoint, use the
inputs' left limits there), ``holds(E)`` (locked wheel stays locked), ``outputs(E)``
and the names ``y_names``/``out_names``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import RunError

#: ROS2 parameter gamma = 1 + 1/sqrt(2) (L-stable).
GAMMA = 1.0 + 1.0 / math.sqrt(2.0)

FREE, LOCKED, PRESCRIBED = 0, 1, 2


@dataclass
class Trajectory:
    """A solution on the accepted steps.

    Attributes
    ----------
    t : ndarray
        Times [s] (strictly increasing).
    y : ndarray
        States, shape ``(len(t), len(y_names))``.
    out : dict
        Output name -> array over ``t`` (``mu``, ``vr``, ``slip``, ``torque`` ...).
    events : dict
        ``lock`` (list of ``[t_lock, t_unlock or None]``), ``stop`` (time or None),
        ``reason`` (why the run ended).
    stats : dict
        Accepted/rejected steps, smallest/largest step.
    """

    t: np.ndarray
    y: np.ndarray
    out: dict
    events: dict
    stats: dict
    y_names: tuple = field(default_factory=tuple)

    def state(self, name: str) -> np.ndarray:
        return self.y[:, self.y_names.index(name)]


def merge_breakpoints(t0: float, t_end: float, *lists) -> list:
    """Sorted times in ``(t0, t_end)`` from several lists, followed by ``t_end``."""
    eps = 1e-12 * max(1.0, abs(t_end))
    pts = sorted({float(b) for lst in lists for b in lst if t0 + eps < b < t_end - eps})
    return pts + [float(t_end)]


def integrate(stepper, y0, t0: float, t_end: float, breakpoints=(), tol: float = 1e-4,
              h_max: float = 5e-3, h0: float = 1e-4, v_stop: float = 0.1, prescribed: bool = False,
              max_steps: int = 2_000_000) -> Trajectory:
    """Integrate from ``(t0, y0)`` to ``t_end`` with adaptive ROS2 steps (module doc).

    Parameters
    ----------
    stepper : object
        Provides ``start``, ``attempt``, ``holds``, ``outputs``, ``y_names``, ``out_names``.
    y0 : sequence of float
        Initial state; ``y0[0]`` is the vehicle speed ``v`` [m/s], ``y0[1]`` the wheel speed
        ``omega`` [rad/s].
    breakpoints : sequence of float
        Times [s] where inputs have kinks or jumps; steps end there.
    tol : float
        Local error tolerance per step, in m/s for speeds and in friction units for the
        bristle states [-].
    h_max, h0 : float
        Largest and first step [s].
    v_stop : float
        Stop speed [m/s]: the run ends when ``v`` falls to it (quarter car only).
    prescribed : bool
        Open loop: the stepper's kinematics are prescribed (no wheel lock, no stop).
    """
    bps = merge_breakpoints(t0, t_end, breakpoints)
    eps_t = 1e-12 * max(1.0, abs(t_end))
    t = float(t0)
    y = list(map(float, y0)) if not isinstance(y0, np.ndarray) else y0.astype(float).copy()
    mode = PRESCRIBED if prescribed else FREE
    if mode == FREE and y[1] <= 0.0:
        y[1] = 0.0
        if stepper.holds(stepper.start(t, y, LOCKED)):
            mode = LOCKED
    locks: list = [[t, None]] if mode == LOCKED else []
    rec_t, rec_y, rec_o = [], [], []
    h = min(h0, h_max)
    ib = 0
    n_acc = n_rej = 0
    stop_t = None
    reason = "t_end"
    start, attempt, outputs = stepper.start, stepper.attempt, stepper.outputs
    while True:
        E = start(t, y, mode)
        if mode == LOCKED and not stepper.holds(E):
            mode = FREE
            locks[-1][1] = t
            E = start(t, y, mode)
        rec_t.append(t)
        rec_y.append(y)
        rec_o.append(outputs(E))
        if stop_t is not None or t >= t_end - eps_t:
            break
        if n_acc >= max_steps:
            raise RunError(f"time integration stopped after {max_steps} steps at t = {t:.6g} s (tolerance too tight?)")
        while bps[ib] <= t + eps_t:
            ib += 1
        tb = bps[ib]
        while True:
            hh = min(h, h_max)
            at_bp = t + hh >= tb - 1e-9 * hh
            forced = at_bp and tb - t < hh  # shortened to land on a breakpoint
            if at_bp:
                hh = tb - t
            y_new, err = attempt(E, hh, at_bp)
            if not err <= 1.0:  # also catches NaN
                n_rej += 1
                h = hh * (max(0.1, 0.9 / math.sqrt(err)) if math.isfinite(err) else 0.1)
                if h < 1e-12 * max(1.0, t_end):
                    raise RunError(f"time step underflow at t = {t:.6g} s (state {list(y)})")
                continue
            if mode == FREE and y_new[1] < 0.0:
                # the wheel would turn backwards: land on omega = 0 and lock (lugre.md §7)
                frac = y[1] / (y[1] - y_new[1])
                forced = True
                if frac * hh > 1e-9:
                    y_land, err_land = attempt(E, frac * hh)
                    if err_land <= 1.0:
                        hh, y_new = frac * hh, y_land
                y_new[1] = 0.0
                mode = LOCKED
                locks.append([t + hh, None])
            break
        n_acc += 1
        if mode != PRESCRIBED and y_new[0] <= v_stop:
            frac = (y[0] - v_stop) / (y[0] - y_new[0]) if y[0] > y_new[0] else 1.0
            frac = min(max(frac, 0.0), 1.0)
            y_new = [a + frac * (b - a) for a, b in zip(y, y_new)] if not isinstance(y, np.ndarray) \
                else y + frac * (y_new - y)
            y_new[0] = min(y_new[0], v_stop) if v_stop > 0 else max(y_new[0], 0.0)
            y_new[1] = max(y_new[1], 0.0)
            hh *= frac
            stop_t = t + hh
            reason = "stop"
        t = tb if (stop_t is None and abs(t + hh - tb) <= 1e-9 * max(hh, 1e-300)) else t + hh
        y = y_new
        if hh > 0 and not (forced and err <= 1.0):  # a forced short step says nothing about the next one
            h = hh * min(3.0, max(0.2, 0.9 * max(err, 1e-12) ** -0.333))
    out = dict(zip(stepper.out_names, np.array(rec_o, dtype=float).T))
    t_arr = np.array(rec_t)
    hs = np.diff(t_arr)
    return Trajectory(
        t=t_arr, y=np.array(rec_y, dtype=float), out=out,
        events={"lock": locks, "stop": stop_t, "reason": reason},
        stats={"steps": n_acc, "rejected": n_rej, "h_min": float(hs.min()) if hs.size else 0.0,
               "h_max": float(hs.max()) if hs.size else 0.0, "tol": tol},
        y_names=tuple(stepper.y_names),
    )
