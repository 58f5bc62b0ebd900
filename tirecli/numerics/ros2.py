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

Modes of the wheel (docs/models/lugre_friction.md §7): *free* (quarter car), *locked* (``omega = 0`` held while the
brake torque can balance the tire torque ``|r F| <= T_b``; brake torque never drives the wheel
backwards; at ``omega = 0`` the wheel sticks, Filippov-style: it is released only when the free
wheel's speed rises, see :func:`integrate`) and *prescribed* (open loop: ``v(t)``, ``omega(t)``
given, only the tire states integrate). **Stop condition:** a run ends at ``t_end``, or when the vehicle speed falls to
``v_stop`` (the quarter car has no model of a vehicle at rest; LuGre itself stays defined at
``v = 0``: no division by zero anywhere).

**Dense output:** between its steps a run is evaluated by the integrator's own step from the last
recorded point to the time asked (outputs, extrema, the CSV grid); events (wheel lock, unlock,
stop) are root-found on that same one-step map, so the run ends a step exactly at each event.

A stepper (see :mod:`tirecli.numerics.lumped`, :mod:`tirecli.numerics.characteristics`) provides
``start(t, y, mode) -> E`` (right-hand side, Jacobian and outputs at ``(t, y)``),
``attempt(E, h, left) -> (y_new, err)`` (``left``: the step ends on a breakpoint, use the
inputs' left limits there), ``holds(E)`` (locked wheel stays locked), ``outputs(E)``,
the names ``y_names``/``out_names`` and ``car`` (the quarter car: its radius scales the wheel speed's
error tolerance). This module holds no model equations: the steppers are the kernels, and each names the
model ``rhs`` it implements (:func:`tirecli.models.quarter_car.rhs`).
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import RunError
from tirecli.numerics.roots import EVENT_TOL, event_step, hermite, minimize


class StepUnderflow(RunError):
    """The step size fell below the time resolution at ``t`` [s] (the run cannot go on)."""

    def __init__(self, message: str, t: float):
        super().__init__(message)
        self.t = t


#: ROS2 parameter gamma = 1 + 1/sqrt(2) (L-stable).
GAMMA = 1.0 + 1.0 / math.sqrt(2.0)

FREE, LOCKED, PRESCRIBED = 0, 1, 2




def just_before(t: float, h: float) -> float:
    """A time inside the step of length ``h`` [s] that ends at ``t`` [s], so close to ``t`` that every input there is
    its left limit at ``t`` (to ``1e-9`` of the step times its slope): where a step that ends on a breakpoint reads
    the inputs and the prescribed kinematics, so that a jump there belongs to the next step. Strictly before ``t``
    even when ``1e-9 h`` is below the resolution of ``t``."""
    return min(t - 1e-9 * h, math.nextafter(t, -math.inf))


@dataclass
class Trajectory:
    """A solution on the accepted steps, with its dense output.

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
        ``reason`` (why the run ended); event times located on the dense output to ``EVENT_TOL``.
    stats : dict
        Accepted/rejected steps, smallest/largest step.
    dy, dy_left : ndarray
        Time derivatives of the states at each time: the right limit (the slope the next step
        starts with) and the left limit (the slope the previous step ends with); they differ at
        breakpoints of the inputs and at events.
    modes : ndarray of int
        Wheel mode of the step that starts at each time (FREE, LOCKED, PRESCRIBED).
    evaluate : callable or None
        ``evaluate(t, y, mode) -> (state, outputs)`` of the stepper (no side effects).
    advance : callable or None
        ``advance(t_k, y_k, mode, dt) -> y``: the integrator's step of length ``dt`` from a recorded
        point, the dense output of :meth:`sample` (and the map events are root-found on).
    dense : callable or None
        ``dense(t_k, y_k, modes_k, dt) -> (states, outputs) or None``: ``advance`` followed by ``evaluate`` at
        many points at once (arrays over the points; the stepper's ``dense``), the same values to rounding;
        :meth:`sample` uses it for the times inside the run (None: one ``advance`` per time).
    sample_cache : dict or None
        Results of :meth:`sample` by output times, for a run that is no longer changed (its arrays
        read-only: a run kept for reuse, :mod:`tirecli.numerics.runs`); shared by its copies.
    """

    t: np.ndarray
    y: np.ndarray
    out: dict
    events: dict
    stats: dict
    y_names: tuple = field(default_factory=tuple)
    dy: np.ndarray | None = None
    dy_left: np.ndarray | None = None
    modes: np.ndarray | None = None
    evaluate: object = None
    out_names: tuple = field(default_factory=tuple)
    advance: object = None
    sample_cache: dict | None = field(default=None, repr=False, compare=False)
    dense: object = field(default=None, repr=False, compare=False)

    def state(self, name: str) -> np.ndarray:
        return self.y[:, self.y_names.index(name)]

    def step_index(self, tq) -> np.ndarray:
        """Index ``k`` of the step ``[t_k, t_k+1]`` holding each time of ``tq`` (clipped to the run)."""
        k = np.searchsorted(self.t, np.asarray(tq, dtype=float), side="right") - 1
        return np.clip(k, 0, max(len(self.t) - 2, 0))

    def states_at(self, tq):
        """States at the times ``tq`` [s], shape ``(len(tq), n_states)``: the cubic Hermite interpolant of
        each step through its end values and end slopes (the right-hand side at the step's start, right
        limit, and at its end, left limit). Exact at the steps' ends, C^1 except where the inputs or the
        wheel's mode change (breakpoints, events: step ends). Fourth-order for the smooth speeds ``v``,
        ``omega`` (distance, driving profiles); :meth:`sample` gives all states and outputs from the
        integrator's own step instead.
        """
        tq = np.atleast_1d(np.asarray(tq, dtype=float))
        if len(self.t) < 2:
            return np.repeat(self.y[:1], tq.size, axis=0)
        k = self.step_index(tq)
        h = (self.t[k + 1] - self.t[k])[:, None]
        th = np.clip((tq - self.t[k]) / h[:, 0], 0.0, 1.0)[:, None]
        args = (th, h, self.y[k], self.y[k + 1], self.dy[k], self.dy_left[k + 1])
        return hermite(*args)

    def _dense(self, k: int, tt: float) -> list:
        """State at ``tt`` inside step ``k``: the integrator's step from ``t_k`` of length ``tt - t_k``
        (``advance``), or the Hermite interpolant when the run has no ``advance``."""
        if self.advance is None or tt <= self.t[0] or tt >= self.t[-1]:
            return list(self.states_at([tt])[0])
        return list(self.advance(float(self.t[k]), self.y[k].tolist(), int(self.modes[k]), tt - float(self.t[k])))

    def _recorded(self) -> np.ndarray:
        """The recorded outputs as one array ``(len(t), len(out_names))`` (built once)."""
        rec = self.__dict__.get("_rec")
        if rec is None or rec.shape[0] != len(self.t):
            rec = np.array([self.out[n] for n in self.out_names]).T if self.out_names else np.empty((len(self.t), 0))
            self.__dict__["_rec"] = rec
        return rec

    def sample(self, tq, keep: bool = True) -> tuple:
        """States and outputs at the times ``tq`` [s] from the dense output: ``(states, {name: array})``.

        Between steps, the states are the integrator's own step from the last recorded point to the
        time asked (``advance``: damped like the steps in the stiff bristle directions, where a
        polynomial through the end slopes would amplify the step's error by the decay rate times the
        step) and the outputs are the model's at those states; at a recorded time the recorded values
        are returned exactly. ``keep=False``: the result is not kept in :attr:`sample_cache` (a
        sampling done once, such as each case of a run streamed to disk: memory stays flat).
        """
        tq = np.atleast_1d(np.asarray(tq, dtype=float))
        cache, key = (self.sample_cache if keep else None), None
        if cache is not None:
            key = tq.tobytes()
            if key in cache:
                Y, outs = cache[key]
                return Y.copy(), {n: outs[:, i].copy() for i, n in enumerate(self.out_names)}
        Y = np.empty((tq.size, self.y.shape[1]))
        outs = np.empty((tq.size, len(self.out_names)))
        k = self.step_index(tq)
        last = len(self.t) - 1
        rec = self._recorded()
        # a recorded time (within 1e-12 s): the recorded values
        k1 = np.minimum(k + 1, last)
        j = np.where(np.abs(tq - self.t[k]) <= 1e-12, k, np.where(np.abs(tq - self.t[k1]) <= 1e-12, k1, -1))
        hit = j >= 0
        Y[hit], outs[hit] = self.y[j[hit]], rec[j[hit]]
        todo = np.flatnonzero(~hit)
        if self.dense is not None and self.advance is not None and todo.size:
            # inside the run: the integrator's step from each point's step start, all points at once
            inner = todo[(tq[todo] > self.t[0]) & (tq[todo] < self.t[-1])]
            kk = k[inner]
            got = self.dense(self.t[kk], self.y[kk], self.modes[kk], tq[inner] - self.t[kk]) if inner.size else None
            if got is not None:
                Y[inner], outs[inner] = got
                todo = np.setdiff1d(todo, inner, assume_unique=True)
        for i in todo:
            tt = tq[i]
            kk = int(k[i])
            yi = self._dense(kk, float(tt))
            y_eff, outs[i] = self.evaluate(float(tt), yi, int(self.modes[kk]))
            Y[i] = yi
            Y[i, :2] = y_eff[:2]
        if key is not None:
            while len(cache) >= SAMPLE_CACHE_SIZE:
                cache.pop(next(iter(cache)))
            cache[key] = (Y.copy(), outs.copy())
        return Y, {n: outs[:, i] for i, n in enumerate(self.out_names)}

    def _sample_one(self, tt: float) -> tuple:
        """:meth:`sample` at one time ``tt``, without the array set-up: ``(state, outputs row)``
        (the same values; the root-finding of :meth:`extremum` calls it many times)."""
        y, outs = self._sample_plain(tt)
        return np.asarray(y, dtype=float), np.asarray(outs, dtype=float)

    def _sample_plain(self, tt: float) -> tuple:
        """:meth:`_sample_one` as plain sequences of floats (no arrays made)."""
        t = self.t
        last = len(t) - 1
        k = min(max(bisect.bisect_right(self._tlist(), tt) - 1, 0), max(last - 1, 0))
        for j in (k, min(k + 1, last)):
            if abs(tt - t[j]) <= 1e-12:
                return self.y[j], self._recorded()[j]
        yi = self._dense(k, float(tt))
        y_eff, outs = self.evaluate(float(tt), yi, int(self.modes[k]))
        return [float(y_eff[0]), float(y_eff[1]), *(float(x) for x in yi[2:])], outs

    def _tlist(self) -> list:
        """The times as a list (built once), for bisection."""
        tl = self.__dict__.get("_tl")
        if tl is None or len(tl) != len(self.t):
            tl = self.t.tolist()
            self.__dict__["_tl"] = tl
        return tl

    def extremum(self, fn, which: str = "max", scalar=None) -> tuple:
        """``(t*, value)`` of the largest (``max``) or smallest (``min``) value of ``fn(t, y, outputs)``
        over the run, root-found on the dense output (bounded Brent search in the steps around the
        best recorded time, to 1e-12 s; value accurate to about 1e-10 of its scale).

        ``fn(t, state, outputs_dict) -> float`` is evaluated on recorded points (vectorised over
        arrays) and on interpolated points (scalars). ``scalar(t, state, outputs)``, when given, is
        the same function of one time on plain floats (``state`` a sequence in ``y_names`` order,
        ``outputs`` one in ``out_names`` order) and must return the same values: the search then
        makes no arrays (several times faster).
        """
        sign = 1.0 if which == "max" else -1.0
        vals = sign * np.asarray(fn(self.t, self.y, self.out), dtype=float)
        i = int(np.nanargmax(vals))
        best_t, best_v = float(self.t[i]), float(vals[i])

        def at(tt):
            if scalar is not None:
                return float(sign * float(scalar(tt, *self._sample_plain(tt))))
            y, o = self._sample_one(tt)
            return float(sign * fn(np.array([tt]), y[None, :], {n: o[j:j + 1] for j, n in enumerate(self.out_names)})[0])

        for k in (i - 1, i):  # the steps on each side of the best recorded point
            if k < 0 or k >= len(self.t) - 1:
                continue
            a, b = float(self.t[k]), float(self.t[k + 1])
            if b - a <= 0:
                continue
            x, fx = minimize(lambda x: -at(x), a, b, xtol=1e-12 * max(1.0, b))
            if -fx > best_v:
                best_t, best_v = float(x), float(-fx)
        return best_t, sign * best_v

    def distance_at(self, tq) -> np.ndarray:
        """Travelled distance [m] at the times ``tq``: the exact integral of the Hermite interpolant of ``v`` (:meth:`states_at`)."""
        tq = np.atleast_1d(np.asarray(tq, dtype=float))
        t, v = self.t, self.y[:, 0]
        if len(t) < 2:
            return np.zeros(tq.size)
        h = np.diff(t)
        f0, f1 = self.dy[:-1, 0], self.dy_left[1:, 0]
        full = h * (0.5 * (v[:-1] + v[1:]) + h * (f0 - f1) / 12.0)   # integral of the cubic over a step
        cum = np.concatenate(([0.0], np.cumsum(full)))
        k = self.step_index(tq)
        hk = h[k]
        th = np.clip((tq - t[k]) / hk, 0.0, 1.0)
        t2, t3, t4 = th ** 2, th ** 3, th ** 4
        part = hk * ((t4 / 2 - t3 + th) * v[k] + (t4 / 4 - 2 * t3 / 3 + t2 / 2) * hk * f0[k]
                     + (-t4 / 2 + t3) * v[k + 1] + (t4 / 4 - t3 / 3) * hk * f1[k])
        return cum[k] + part


#: Output grids whose :meth:`Trajectory.sample` results a kept run holds (the time series and the measured samples).
SAMPLE_CACHE_SIZE = 4


def merge_breakpoints(t0: float, t_end: float, *lists) -> list:
    """Sorted times in ``(t0, t_end)`` from several lists, followed by ``t_end``."""
    eps = 1e-12 * max(1.0, abs(t_end))
    pts = sorted({float(b) for lst in lists for b in lst if t0 + eps < b < t_end - eps})
    return pts + [float(t_end)]


def integrate(stepper, y0, t0: float, t_end: float, breakpoints=(), tol: float = 1e-4,
              h_max: float = 5e-3, h0: float = 1e-4, v_stop: float = 0.1, prescribed: bool = False,
              max_steps: int | None = None) -> Trajectory:
    """Integrate from ``(t0, y0)`` to ``t_end`` with adaptive ROS2 steps (module doc).

    Parameters
    ----------
    stepper : object
        Provides ``start``, ``attempt``, ``holds``, ``outputs``, ``deriv``, ``rhs_at``,
        ``lock_margin``, ``evaluate``, ``rollback``, ``y_names``, ``out_names``.
    y0 : sequence of float
        Initial state; ``y0[0]`` is the vehicle speed ``v`` [m/s], ``y0[1]`` the wheel speed
        ``omega`` [rad/s].
    breakpoints : sequence of float
        Times [s] where inputs have kinks or jumps: integration breakpoints (a step ends there and
        the next starts there with the inputs' right limits; no step straddles one).
    tol : float
        Local error tolerance per step, in m/s for speeds and in friction units for the
        bristle states [-].
    h_max, h0 : float
        Largest and first step [s].
    v_stop : float
        Stop speed [m/s]: the run ends when ``v`` falls to it (quarter car only).
    prescribed : bool
        Open loop: the stepper's kinematics are prescribed (no wheel lock, no stop).
    max_steps : int or None
        Most steps stored (default: the sample budget, :func:`tirecli.limits.max_samples`): a run
        that needs more stops with a RunError instead of filling the memory.

    Notes
    -----
    Events are located on the step where they occur by root finding on the integrator's own
    solution: Brent's method on the length ``h`` of that step (the ROS2 step from the same start is a
    smooth function of ``h``), to ``EVENT_TOL``; the step then ends exactly there. Wheel lock:
    ``omega`` reaching 0 with the wheel free; unlock: the brake's holding margin
    ``min(T_b, T_b - |r F|)`` reaching 0 with the wheel locked (at a breakpoint, with the inputs' left
    limits first: a jump of the input releases the wheel exactly at the breakpoint); stop: ``v``
    reaching ``v_stop``.

    Sticking (Filippov): with ``omega = 0`` the free wheel's ``J domega/dt`` equals minus the holding
    margin, so the wheel really leaves only where the margin crosses 0 downwards. A free step from
    ``omega = 0`` (just released, or at rest) that ends with ``omega < 0`` locks where ``omega`` comes
    back to 0 after rising above the wheel speed's error tolerance ``tol / r``; if it never does (the
    wheel would turn backwards at once: the margin is 0 to rounding but rising, as after a crossing
    located on a step whose restart relaxes the bristles), the wheel stays locked at that time and the
    next step is taken locked without the holding test there; its unlock is then the margin's crossing
    after it has risen (or the step's end). Every mode change thus comes with a step of positive length:
    no zero-length lock/unlock cycles.
    """
    from tirecli.limits import OPTION, max_samples

    budget = max_steps is None
    max_steps = max_samples() if budget else max_steps
    bps = merge_breakpoints(t0, t_end, breakpoints)
    eps_t = 1e-12 * max(1.0, abs(t_end))
    omega_floor = tol / stepper.car.r if not prescribed else 0.0   # [rad/s] the wheel speed's error tolerance
    t = float(t0)
    y = list(map(float, y0))
    mode = PRESCRIBED if prescribed else FREE
    if mode == FREE and y[1] <= 0.0:
        y[1] = 0.0
        if stepper.holds(stepper.start(t, y, LOCKED)):
            mode = LOCKED
    locks: list = [[t, None]] if mode == LOCKED else []
    rec_t, rec_y, rec_o, rec_f, rec_fl, rec_m = [], [], [], [], [], []
    h = min(h0, h_max)
    ib = 0
    n_acc = n_rej = 0
    stop_t = None
    reason = "t_end"
    start, attempt, outputs, deriv = stepper.start, stepper.attempt, stepper.outputs, stepper.deriv
    f_left = None          # slope at the current time as the end of the previous step (None: same as the next start's)
    prev = None            # (t, y, E, mode) of the last accepted step's start
    sticks = False         # the wheel sticks at t: the next step is locked without the holding test at t
    while True:
        E = start(t, y, mode)
        if mode == LOCKED and not sticks and not stepper.holds(E):
            # The brake no longer holds at t. If it already failed within the last (locked) step,
            # locate the crossing of the holding margin on that step's dense output and redo the step to it
            # (a step that started sticking, margin ~ 0-: the crossing after the margin's rise).
            fl = f_left if f_left is not None else deriv(E)
            if prev is not None and prev[3] == LOCKED and stepper.lock_margin(t, y, True) < 0.0:
                tp, yp, Ep, _ = prev
                gp = stepper.lock_margin(tp, yp)
                gt = stepper.lock_margin(t, y, True)
                if gt < 0.0:
                    stepper.rollback(tp)
                    hs, ys = event_step(attempt, Ep, tp, t - tp, stepper.lock_margin, gp, gt, True,
                                         0.0 if gp < 0.0 else None)
                    if eps_t < hs < t - tp - 1e-12:
                        ys[1] = 0.0
                        t, y = tp + hs, ys
                        fl = stepper.rhs_at(t, y, LOCKED)
                    else:
                        start(t, y, LOCKED)   # no earlier crossing: the history holds t again
            f_left = fl
            mode = FREE
            locks[-1][1] = t
            E = start(t, y, mode)
        sticks = False
        rec_t.append(t)
        rec_y.append(list(y))
        rec_o.append(outputs(E))
        rec_f.append(deriv(E))
        rec_fl.append(f_left if f_left is not None else rec_f[-1])
        rec_m.append(mode)
        f_left = None
        if stop_t is not None or t >= t_end - eps_t:
            break
        if n_acc >= max_steps:
            why = f"the sample budget; raise it with {OPTION}, or loosen the tolerance" if budget else "tolerance too tight?"
            raise RunError(f"time integration stopped after {max_steps:,} steps at t = {t:.6g} s ({why})")
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
                    raise StepUnderflow(f"time step underflow at t = {t:.6g} s (state {list(y)})", t)
                continue
            break
        n_acc += 1
        step_mode = mode
        if at_bp:  # the slope this step ends with: the inputs' left limits at the breakpoint
            f_left = stepper.rhs_at(t + hh, y_new, step_mode, True)
        if mode == FREE and y_new[1] < 0.0:
            # the wheel would turn backwards: lock where omega reaches 0 (docs/models/lugre_friction.md §7);
            # from omega = 0 (just unlocked, or at rest): where omega comes back to 0 after rising above
            # the error tolerance (a smaller excursion is the locked wheel to the solution's accuracy)
            hs, ys = event_step(attempt, E, t, hh, lambda tt, yy: yy[1], y[1], y_new[1], at_bp,
                                 omega_floor if y[1] == 0.0 else None)
            if hs <= 1e-12:
                # The wheel leaves omega = 0 backwards (it sticks: Filippov): lock here and take the next step
                # locked whatever the holding margin says at t (it is 0 to rounding, rising: the margin has
                # just been root-found, or the free rolling would reverse the wheel); the unlock is the margin's
                # next downward crossing. Record this time again, locked.
                fl_prev = rec_fl[-1]
                for lst in (rec_t, rec_y, rec_o, rec_f, rec_fl, rec_m):
                    lst.pop()
                y = list(y)
                y[1] = 0.0
                mode = LOCKED
                if locks and locks[-1][1] == t:
                    locks[-1][1] = None       # the unlock at t did not happen: the lock goes on
                else:
                    locks.append([t, None])
                f_left = fl_prev
                sticks = True
                continue
            end_bp = at_bp and hs >= hh
            hh, y_new = hs, ys
            f_left = stepper.rhs_at(t + hh, y_new, FREE, end_bp)
            y_new[1] = 0.0
            forced = True
            mode = LOCKED
            locks.append([t + hh, None])
        if step_mode != PRESCRIBED and y_new[0] <= v_stop and hh > 0:
            hs, ys = event_step(attempt, E, t, hh, lambda tt, yy: yy[0] - v_stop, y[0] - v_stop, y_new[0] - v_stop,
                                 at_bp and t + hh >= tb)
            if 0.0 < hs < hh - 1e-12:
                hh, y_new = hs, ys
                f_left = stepper.rhs_at(t + hh, y_new, step_mode)
            y_new[0] = v_stop if v_stop > 0 else max(y_new[0], 0.0)
            y_new[1] = max(y_new[1], 0.0)
            stop_t = t + hh
            reason = "stop"
        prev = (t, list(y), E, step_mode)
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
        y_names=tuple(stepper.y_names), dy=np.array(rec_f, dtype=float), dy_left=np.array(rec_fl, dtype=float),
        modes=np.array(rec_m, dtype=int), evaluate=stepper.evaluate, out_names=tuple(stepper.out_names),
        advance=_advance_of(stepper), dense=getattr(stepper, "dense", None),
    )


def _advance_of(stepper):
    """The dense output of a run: ``advance(t_k, y_k, mode, dt)`` is the integrator's own step of length
    ``dt`` from a recorded point (the one-step map that events are root-found on). Unlike a polynomial
    through the step's end slopes it is damped like the steps in the stiff bristle directions, so the
    outputs between steps are as accurate as at the steps."""
    peek = getattr(stepper, "peek", stepper.start)
    attempt = stepper.attempt
    last = [None, None]   # the start record of the last step used (several output times share a step)

    def advance(t, y, mode, dt):
        if last[0] != (t, mode):
            last[0], last[1] = (t, mode), peek(t, y, mode)
        y_new = list(attempt(last[1], dt, False)[0])
        if mode == LOCKED or (mode == FREE and y_new[1] < 0.0):
            y_new[1] = 0.0     # within the event tolerance of a lock: the wheel does not turn backwards
        return y_new

    return advance
