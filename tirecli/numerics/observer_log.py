"""The observer alone, driven by a measured log: no simulated plant.

:func:`observe_log` integrates the observer of OBS Theorem 1 (:func:`tirecli.observers.observer.rhs`, four
states ``eta_hat, chi_hat, z_hat, theta_hat``) with the log's wheel speed ``y`` [rad/s] and wheel torque
``u`` [N m] held constant from one sample to the next (zero-order hold: the value of sample ``k`` applies on
``[t_k, t_{k+1})``). Every sample is an input jump, so the adaptive solver restarts at each one (LSODA,
guarded against its stall in the non-stiff mode as in :mod:`tirecli.numerics.observer.adaptive`); the
states are returned at the sample times, right after each sample is taken.

The model it integrates is :func:`tirecli.observers.observer.rhs` itself (nothing inlined).
"""
from __future__ import annotations

import numpy as np

from tirecli.errors import RunError
from tirecli.numerics.observer.adaptive import _lsoda_guarded, scalar_rhs, state_scales
from tirecli.numerics.observer.scenario import Scenario, Trajectory
from tirecli.numerics.solver_guard import WorkGuard, failure_message, quiet
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant

class _Held:
    """A torque held constant over a sample interval [N m] (scalar ``at`` for the inlined right-hand side)."""

    def __init__(self, value: float):
        self.value = value

    def at(self, t) -> float:
        return self.value

    def __call__(self, t):
        return np.full(np.shape(t), self.value) if np.ndim(t) else self.value


_ONE = _Held(1.0)   # adhesion of the placeholder plant (not read by the observer part)


#: Right-hand-side evaluations a sample interval costs, about (LSODA restarting after an input jump: 209 a
#: sample on examples/obs-log.yaml); the work estimate of a log run (:mod:`tirecli.studies.observe.work`).
CALLS_PER_SAMPLE = 200


def observe_log(plant: ObserverPlant, gains: ObserverGains, t, y, u, v_hat0: float, z_hat0: float = 0.0,
                theta_hat0: float = 1.0, rtol: float = 1e-7, atol=None, h_max: float | None = None,
                max_work: float | None = None) -> Trajectory:
    """Run the observer on sampled, held wheel speed and torque.

    Parameters
    ----------
    plant, gains : ObserverPlant, ObserverGains
        The design plant and the gains of OBS (14).
    t : array_like, shape (n,)
        Sample times [s], strictly increasing.
    y : array_like, shape (n,)
        Measured wheel speed [rad/s] at ``t``.
    u : array_like, shape (n,)
        Wheel torque [N m] at ``t`` (> 0 drives).
    v_hat0, z_hat0, theta_hat0 : float
        Initial estimates: speed [m/s], bristle deflection [m], adhesion (OBS convention) [-].
    rtol, atol, h_max : float
        Tolerances of LSODA (``atol`` None: ``rtol`` times the state scales) and its largest step [s].
    max_work : float or None
        Most weighted evaluations (:class:`~tirecli.numerics.solver_guard.WorkGuard`; default the budget).

    Returns
    -------
    Trajectory
        On the sample times: ``y`` and ``omega`` the measured wheel speed, ``torque`` the held torque, the
        estimates; ``v``, ``z`` and ``theta`` are NaN (no plant: the caller fills a measured ``v``).
    """
    t, y, u = (np.asarray(a, dtype=float) for a in (t, y, u))
    c = plant.car
    # the observer part of the inlined plant + observer right-hand side (parity with observer.rhs:
    # tests/test_model_parity.py); its plant states are placeholders that the observer part does not read
    atol_v = rtol * state_scales(plant)[3:7] if atol is None else atol
    X = np.array([c.r * c.m * v_hat0 + c.J * y[0], c.J * y[0] + plant.P * z_hat0, z_hat0, theta_hat0])
    out = np.empty((len(t), 4))
    out[0] = X
    guard = WorkGuard("lsoda", float(t[0]), float(t[-1]), max_work)
    kw = dict(rtol=rtol, atol=atol_v, **({"max_step": h_max} if h_max else {}))
    nfev, stalled = 0, 0
    for k in range(len(t) - 1):
        a, b = float(t[k]), float(t[k + 1])
        yk = float(y[k])
        pad = [c.r * yk, yk, 0.0]
        # the observer part of the inlined plant + observer right-hand side (parity with observer.rhs:
        # tests/test_model_parity.py), the torque held; its plant states are placeholders it does not read
        full = scalar_rhs(plant, gains, Scenario(duration=b, torque=_Held(float(u[k])), theta_fm=_ONE, v0=0.0,
                                                 omega0=0.0))
        fun = guard.wrap(lambda _t, x, yk=yk, pad=pad: full(_t, pad + list(x), yk)[3:])
        with quiet() as caught:
            sol, spent = _lsoda_guarded(fun, a, b, X, h_max, dict(kw, t_eval=[b]), on_redo=lambda: guard.use("bdf"))
            guard.use("lsoda")
        if sol.status < 0 or not np.all(np.isfinite(sol.y)):
            raise RunError(failure_message("lsoda", a, caught, sol.message if sol.status < 0 else
                                           "the state stopped being finite", True))
        nfev += sol.nfev + spent
        stalled += bool(spent)
        X = sol.y[:, -1].copy()
        out[k + 1] = X
    eta, chi, zh, thh = out.T
    nan = np.full(len(t), np.nan)
    info = {"method": "lsoda", "rtol": rtol, "atol": "rtol x state scales" if atol is None else atol,
            "h_max_s": h_max, "segments": len(t) - 1, "rhs_calls": int(nfev), "hold": "zero-order"}
    if stalled:
        info["lsoda_stall"] = f"LSODA stalled on {stalled} sample interval(s); each was redone with BDF"
    return Trajectory(t=t, v=nan, omega=y, z=nan.copy(), y=y, v_hat=plant.speed_from_eta(eta, y), z_hat=zh,
                      theta_hat=thh, y_tilde=y - (chi - plant.P * zh) / c.J, theta=nan.copy(), torque=u,
                      method=f"lsoda on the log's samples (rtol {rtol:g}, zero-order hold)", info=info)
