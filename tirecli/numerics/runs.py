"""Entry points of the transient runs: the quarter car driven by a torque, or the tire driven by kinematics.

Both pick the stepper of the model variant (:class:`~tirecli.models.variants.FrictionVariant`):
lumped (:mod:`tirecli.numerics.lumped`) or distributed (:mod:`tirecli.numerics.characteristics`),
and integrate with :func:`tirecli.numerics.ros2.integrate`.
"""
from __future__ import annotations

import bisect
import copy
import threading
from collections import OrderedDict
from dataclasses import dataclass, replace

import numpy as np

from tirecli.conventions import slip_from_speeds
from tirecli.models.lugre import LuGreParams
from tirecli.models.lugre_pde import patch_reduction
from tirecli.models.profiles import Constant
from tirecli.models.variants import FrictionVariant
from tirecli.models.vehicle import QuarterCarParams
from tirecli.numerics.ros2 import PRESCRIBED, Trajectory, integrate

#: Default local error tolerance per model (m/s for speeds, friction units for the tire states).
#: Measured on the FM braking: lumped 1e-3 gives max |dmu| 6e-4 (in the first milliseconds),
#: |ds| 6e-5; distributed 3e-4 gives |dmu| 3e-4, |ds| 2e-4 and constant-slip runs settle within
#: 1e-5 of FM eq. (4) (benchmarks/bench_transient.py, tests/test_transient_numerics.py).
DEFAULT_TOL = {"lumped": 1e-3, "distributed": 3e-4}


@dataclass(frozen=True)
class SolverOptions:
    """Time-stepping options.

    Attributes
    ----------
    tol : float or None
        Local error tolerance (None: :data:`DEFAULT_TOL` of the model).
    h_max : float
        Largest step [s].
    v_stop : float
        Stop speed [m/s] of coupled runs (module doc of :mod:`tirecli.numerics.ros2`).
    """

    tol: float | None = None
    h_max: float = 0.05
    v_stop: float = 0.1

    def tol_for(self, variant: FrictionVariant) -> float:
        return self.tol if self.tol is not None else DEFAULT_TOL[variant.model]


def _stepper(variant, p, car, torque, theta, v_of_t=None, omega_of_t=None, tol=1e-3):
    if variant.model == "lumped":
        from tirecli.numerics.lumped import LumpedStepper

        return LumpedStepper(p, car, variant.lumped_kappa0(p), torque, theta, v_of_t, omega_of_t, tol)
    from tirecli.numerics.characteristics import CharacteristicsStepper

    red = patch_reduction(variant.load, variant.lam, variant.u, variant.f)
    return CharacteristicsStepper(p, car, red, torque, theta, v_of_t, omega_of_t, tol)


def _initial_state(variant, stepper, v0, omega0):
    return [float(v0), float(omega0)] + [0.0] * (len(stepper.y_names) - 2)


def quarter_car(variant: FrictionVariant, p: LuGreParams, car: QuarterCarParams, torque, theta,
                v0: float, omega0: float, t_end: float, options: SolverOptions = SolverOptions(),
                sample_times=(), reuse: bool = False) -> Trajectory:
    """Quarter-car run (docs/models/lugre_friction.md §7) from ``z = 0`` at ``(v0 [m/s], omega0 [rad/s])`` to ``t_end`` [s].

    ``torque`` and ``theta`` are profiles (:mod:`tirecli.models.profiles`): the signed wheel
    torque ``u`` [N m] (its braking part cannot reverse the wheel) and the adhesion (FM
    convention). The run stops early when ``v`` falls to ``options.v_stop``. ``sample_times``
    [s] become step ends, so the solution is exact (not interpolated) there. ``reuse``: keep the run
    (read-only) and return the kept one to a later call with the same inputs (:data:`MEMO_RUNS`).
    """
    key = None if not reuse else _memo_key(variant, p, car, torque, theta, float(v0), float(omega0), float(t_end),
                                           options, tuple(float(x) for x in sample_times))
    memo = _memo()
    if key is not None and key in memo:
        memo.move_to_end(key)
        return _shared(memo[key])
    tol = options.tol_for(variant)
    st = _stepper(variant, p, car, torque.at, theta.at, tol=tol)
    tr = integrate(st, _initial_state(variant, st, v0, omega0), 0.0, t_end,
                   tuple(torque.breakpoints(t_end)) + tuple(theta.breakpoints(t_end)) + tuple(sample_times), tol=tol,
                   h_max=options.h_max, v_stop=options.v_stop)
    tr = _finish(tr, car)
    if key is None:
        return tr
    _freeze(tr)
    memo[key] = tr
    while len(memo) > MEMO_RUNS:
        memo.popitem(last=False)
    return _shared(tr)


#: Coupled runs kept for reuse in a process (per thread, least recently used dropped first). The
#: built-in brakings are shared by several studies: braking #2 of fm-fig4 is the data of fm-fig6, and
#: the brakings of fm-fig7 and fm-fig8 are those of fm-fig4, so a report solves each of them once.
MEMO_RUNS = 8
_LOCAL = threading.local()


def _memo() -> OrderedDict:
    memo = getattr(_LOCAL, "runs", None)
    if memo is None:
        memo = _LOCAL.runs = OrderedDict()
    return memo


def _memo_key(*parts):
    """The key of a run: its inputs (frozen dataclasses and profiles, compared by value) and the sample
    budget in force; ``None`` when an input is not hashable (the run is not kept)."""
    from tirecli.limits import max_samples

    key = parts + (max_samples(),)
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _freeze(tr: Trajectory) -> None:
    """Make a kept run's arrays read-only (it is shared: a caller writing into it would change it for the next);
    its dense-output samples are then kept too (``sample_cache``)."""
    for a in (tr.t, tr.y, tr.dy, tr.dy_left, tr.modes, *tr.out.values()):
        if isinstance(a, np.ndarray):
            a.flags.writeable = False
    tr.sample_cache = {}


def _shared(tr: Trajectory) -> Trajectory:
    """A kept run for one caller: its own ``out``, ``events`` and ``stats`` containers, the (read-only) arrays shared."""
    return replace(tr, out=dict(tr.out), events=copy.deepcopy(tr.events), stats=dict(tr.stats))


def open_loop(variant: FrictionVariant, p: LuGreParams, car: QuarterCarParams, v_profile, omega_profile, theta,
              t_end: float, options: SolverOptions = SolverOptions()) -> Trajectory:
    """The tire alone driven by prescribed ``v(t)`` [m/s] and ``omega(t)`` [rad/s] (FM Figs. 7-8), from ``z = 0``."""
    tol = options.tol_for(variant)
    zero = Constant(0.0)
    st = _stepper(variant, p, car, zero.at, theta.at, v_profile.at, omega_profile.at, tol=tol)
    bps = tuple(v_profile.breakpoints(t_end)) + tuple(omega_profile.breakpoints(t_end)) + tuple(theta.breakpoints(t_end))
    tr = integrate(st, _initial_state(variant, st, v_profile.at(0.0), omega_profile.at(0.0)), 0.0, t_end, bps,
                   tol=tol, h_max=options.h_max, prescribed=True)
    tr.out["torque"][:] = np.nan
    tr.out["brake_torque"][:] = np.nan
    return _finish(tr, car)


class HermiteProfile:
    """Cubic Hermite profile through ``(t_i, y_i)`` with slopes: the dense output of a run.

    ``dy`` are the slopes each interval starts with (right limits), ``dy_left`` those each ends
    with (left limits; default ``dy``): they differ at the run's breakpoints and events, where the
    profile has a kink. Has the profile interface of :mod:`tirecli.models.profiles` (``__call__``,
    ``at``, ``breakpoints``, ``record``); constant outside ``[t_0, t_n]``. It is smooth (C^1) between
    the given ``breakpoints`` (the kinks of the run's inputs and its events), so a run it drives
    need not stop at every node.
    """

    def __init__(self, t, y, dy, source: str = "", breakpoints=(), dy_left=None):
        self.t = [float(x) for x in t]
        self.y = [float(x) for x in y]
        self.dy = [float(x) for x in dy]
        self.dyl = self.dy if dy_left is None else [float(x) for x in dy_left]
        self.source = source
        self._bps = tuple(float(b) for b in breakpoints)

    def at(self, t: float) -> float:
        tt = self.t
        if t <= tt[0]:
            return self.y[0]
        if t >= tt[-1]:
            return self.y[-1]
        i = bisect.bisect_right(tt, t) - 1
        h = tt[i + 1] - tt[i]
        s = (t - tt[i]) / h
        s2 = s * s
        s3 = s2 * s
        return ((2 * s3 - 3 * s2 + 1) * self.y[i] + (s3 - 2 * s2 + s) * h * self.dy[i]
                + (-2 * s3 + 3 * s2) * self.y[i + 1] + (s3 - s2) * h * self.dyl[i + 1])

    def __call__(self, t):
        if np.ndim(t):
            return np.array([self.at(float(x)) for x in np.ravel(t)]).reshape(np.shape(t))
        return self.at(float(t))

    def breakpoints(self, t_end: float | None = None) -> tuple:
        return self._bps

    def record(self) -> dict:
        return {"kind": "run", "source": self.source, "points": len(self.t)}


def kinematics_of(tr: Trajectory, source: str = "", breakpoints=()):
    """Profiles ``(v(t) [m/s], omega(t) [rad/s])`` of a coupled run (its dense output, cubic Hermite), to drive another model.

    ``breakpoints``: the kinks of the run's inputs (and any times the driven run must hit exactly);
    wheel lock/unlock times are added.
    """
    bps = tuple(breakpoints) + tuple(t for pair in tr.events["lock"] for t in pair if t is not None)
    return (HermiteProfile(tr.t, tr.y[:, 0], tr.dy[:, 0], source, bps, tr.dy_left[:, 0]),
            HermiteProfile(tr.t, tr.y[:, 1], tr.dy[:, 1], source, bps, tr.dy_left[:, 1]))


def distance_at(tr: Trajectory, tq) -> np.ndarray:
    """Travelled distance [m] at ``tq`` [s]: the exact integral of the dense output of ``v`` (a coupled
    run); for an open-loop run (``v`` prescribed) the trapezoid rule over its steps, interpolated."""
    tq = np.atleast_1d(np.asarray(tq, dtype=float))
    if tr.modes is not None and np.all(tr.modes == PRESCRIBED):
        v = tr.y[:, 0]
        cum = np.concatenate(([0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(tr.t))))
        return np.interp(tq, tr.t, cum)
    return tr.distance_at(tq)


def _finish(tr: Trajectory, car: QuarterCarParams) -> Trajectory:
    v, omega = tr.y[:, 0], tr.y[:, 1]
    tr.out["slip"] = slip_from_speeds(v, omega, car.r)
    tr.out["romega"] = car.r * omega
    if "zbar" not in tr.out:
        tr.out["zbar"] = tr.y[:, 2].copy()
    tr.out["distance"] = distance_at(tr, tr.t)
    return tr


#: Steps a run takes at least per switch (jump or kink) of an input, where it restarts with a small step, and
#: per period of an input's fastest oscillation (measured on the lumped model at tol 1e-3: 12-15 steps per
#: switch of a 1 kHz square wave, 12-30 per period of a 1-5 kHz sine; fewer would not resolve them).
STEPS_PER_SWITCH, STEPS_PER_PERIOD = 10, 10


def input_steps(profile, t_end: float) -> tuple[float, int, float]:
    """``(steps, switches, hz)``: the steps a run over ``[0, t_end]`` [s] must take at least to follow the input
    ``profile`` (:data:`STEPS_PER_SWITCH` per breakpoint, :data:`STEPS_PER_PERIOD` per period of its fastest
    oscillation, ``hz`` [Hz], when it has one: a formula's sines and cosines), before the run starts."""
    switches = len(profile.breakpoints(t_end))
    frequency = getattr(profile, "frequency", None)
    hz = float(frequency(t_end)) if frequency is not None else 0.0
    return STEPS_PER_SWITCH * switches + STEPS_PER_PERIOD * hz * float(t_end), switches, hz
