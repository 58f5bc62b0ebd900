"""Plant + observer with an adaptive scipy method (:func:`simulate_adaptive`).

:func:`simulate_adaptive` integrates the full 7-state system (plant ``(v, omega, z)``, observer
OBS (14); :func:`scalar_rhs`) with ``scipy.integrate.solve_ivp``, split at every breakpoint and sample; a
segment where LSODA stalls in its non-stiff mode is redone with BDF (:func:`_lsoda_guarded`).

**Models the kernel implements:** :func:`scalar_rhs` inlines :func:`tirecli.numerics.observer.reference.full_rhs`.
Parity to 1e-12: tests/test_model_parity.py.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.conventions import theta_obs_from_fm
from tirecli.errors import RunError
from tirecli.numerics.observer.scenario import Scenario, Trajectory
from tirecli.numerics.solver_guard import WorkGuard, failure_message, quiet
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant
from tirecli.observers.measurement import Sensor

#: ``solve_ivp`` names of the adaptive methods.
SCIPY_METHODS = {"lsoda": "LSODA", "radau": "Radau", "bdf": "BDF", "dop853": "DOP853"}


def state_scales(plant: ObserverPlant) -> np.ndarray:
    """Typical sizes of ``X = (v, omega, z, eta_hat, chi_hat, z_hat, theta_hat, angle)``.

    1 m/s, 1 rad/s, 1 mm, ``r m`` (eta for 1 m/s), ``J`` (chi for 1 rad/s), 1 mm, 1, 1 rad: the
    default absolute tolerance is ``rtol`` times these (the relative test takes over above them).
    """
    c = plant.car
    return np.array([1.0, 1.0, 1e-3, c.r * c.m, c.J, 1e-3, 1.0, 1.0])


def scalar_rhs(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario):
    """``f(t, X, y)`` of plant + observer with scalar arithmetic (what the adaptive methods integrate).

    **Models it implements:** :func:`tirecli.numerics.observer.reference.full_rhs`, i.e.
    :func:`tirecli.models.quarter_car.rhs` (lumped tire, ``sigma2_in_wheel=False``) and
    :func:`tirecli.observers.observer.rhs`, inlined; parity to 1e-12 for the ideal and the held measurement, with
    and without the wheel angle: tests/test_model_parity.py.

    ``X = (v, omega, z, eta_hat, chi_hat, z_hat, theta_hat[, angle])``; ``y`` is the held measured
    wheel speed [rad/s] (``None``: the ideal ``y = omega``). Plant, OBS (3)-(5) with ``vr = r omega - v``:

    ``z' = vr - theta_obs sigma0 |vr|/g(vr) z - kappa r |omega| z``, ``F = F_n (sigma0 z + sigma1 z' + sigma2 vr)``,
    ``m v' = F``, ``J omega' = -r (F - F_n sigma2 vr) - sigma_w omega + u``;

    observer, OBS (14) in explicit form (docs/models/observer_model.md §3), ``y~ = y - (chi_hat - P z_hat)/J``; the
    wheel angle ``angle' = omega`` [rad] is an eighth state when ``X`` has one (encoder models).
    """
    tire, car, g = plant.tire, plant.car, gains
    r, m, J, Fn = car.r, car.m, car.J, car.F_n
    s0, s1, s2, sw = tire.sigma0, tire.sigma1, tire.sigma2, tire.sigma_w
    muc, dmu, ivs, al_g = tire.mu_c, tire.mu_s - tire.mu_c, 1.0 / tire.v_s, tire.alpha
    unit_alpha = al_g == 1.0
    kr = plant.kappa * r
    irm = 1.0 / (r * m)
    c = plant.c_eta
    E1, _, E3 = (float(e) for e in plant.E)
    P, Q = plant.P, plant.Q
    k1, k2, k3, gam, alp = g.k1, g.k2, g.k3, g.gamma, g.alpha
    u_of = getattr(scenario.torque, "at", scenario.torque)   # scalar evaluations without numpy overhead
    th_fm = getattr(scenario.theta_fm, "at", scenario.theta_fm)
    exp_, fabs = math.exp, math.fabs

    def aphi_of(vr):
        avr = fabs(vr)
        if unit_alpha:
            return s0 * avr / (muc + dmu * exp_(-avr * ivs))
        return s0 * avr / (muc + dmu * exp_(-((avr * ivs) ** al_g)))

    def f(t, X, y=None):
        v, w, z, eh, ch, zh, thh = X[0], X[1], X[2], X[3], X[4], X[5], X[6]
        u = float(u_of(t))
        th = 1.0 / float(th_fm(t))
        vr = r * w - v
        zd = vr - (th * aphi_of(vr) + kr * fabs(w)) * z
        F = Fn * (s0 * z + s1 * zd + s2 * vr)
        ym = w if y is None else y
        yt = ym - (ch - P * zh) / J
        vrh = r * ym - (eh - J * ym) * irm
        phh = aphi_of(vrh) * zh
        out = [F / m, (-r * (F - Fn * s2 * vr) - sw * w + u) / J, zd,
               -c * eh + E1 * ym + u + k1 * yt,
               -Q * zh - sw * ym + u + k2 * yt,
               -eh * irm + E3 * ym - thh * phh - kr * fabs(ym) * zh - alp * (1.0 + thh) * yt + k3 * yt,
               gam * yt * (phh + alp * yt)]
        if len(X) > 7:
            out.append(w)
        return np.array(out)

    return f


def simulate_adaptive(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario, sensor: Sensor | None = None,
                      method: str = "lsoda", rtol: float = 1e-6, atol=None, h_max: float | None = None,
                      output_dt: float = 1e-3, rhs=None, max_work: float | None = None) -> Trajectory:
    """Integrate plant + observer with an adaptive ``solve_ivp`` method (LSODA, Radau, BDF, DOP853).

    The run is split at every profile breakpoint and every sampling instant: the solver stops
    there and restarts with the new held measurement, never stepping across an input jump.
    Encoder models integrate the wheel angle as an eighth state; the tooth edges the ``period``
    method times are root-found on the solver's interpolant (to 1e-12 s).

    Parameters
    ----------
    method : str
        ``lsoda``, ``radau``, ``bdf`` or ``dop853`` (explicit: only for non-stiff gains).
    rtol : float
        Relative tolerance.
    atol : float, array or None
        Absolute tolerance; ``None``: ``rtol`` times :func:`state_scales`.
    h_max : float or None
        Largest step [s] (``None``: unlimited).
    output_dt : float
        Output grid [s] (at most half the sampling period; plus every segment start, the right
        limit after a jump), from the solver's interpolant.
    rhs : callable or None
        ``f(t, X, y)`` to integrate instead of :func:`scalar_rhs` (tests).
    max_work : float or None
        Most right-hand-side evaluations, weighted by the method's cost (:class:`~tirecli.numerics.solver_guard.WorkGuard`;
        default: the sample budget). A failure of the method, or work past the limit, is a RunError of one line
        (no library warning reaches the user).
    """
    from scipy.integrate import solve_ivp

    sensor = sensor or Sensor()
    name = SCIPY_METHODS.get(method.lower(), method)
    f = rhs or scalar_rhs(plant, gains, scenario)
    encoder = sensor.teeth is not None
    nx = 8 if encoder else 7
    atol_v = rtol * state_scales(plant)[:nx] if atol is None else atol
    samples = sensor.sample_times(scenario.duration)
    T = scenario.duration
    cuts = np.unique(np.concatenate([[0.0, T], [b for b in scenario.breakpoints if 0 < b < T], samples]))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-12 * max(T, 1.0)])]
    cuts[-1] = T
    sample_set = set(np.round(samples, 12).tolist())
    sampler = None if sensor.ideal else sensor.sampler(len(samples), scenario.omega0)
    y_hold = scenario.omega0 if sampler is None else sampler.sample(0.0, scenario.omega0)
    c = plant.car
    X = np.array([scenario.v0, scenario.omega0, scenario.z0, c.r * c.m * scenario.vhat0 + c.J * y_hold,
                  c.J * y_hold + plant.P * scenario.z_hat0, scenario.z_hat0, scenario.theta_hat0, 0.0][:nx])
    if not sensor.ideal:
        output_dt = min(output_dt, 0.5 * sensor.period)  # mid-sample states on the grid (held value unambiguous)
    n_out = max(int(round(T / output_dt)), 1)
    t_out = np.linspace(0.0, T, n_out + 1)
    ts, Xs, ys = [], [], []
    nfev = 0
    stalled = []
    kw = {"max_step": h_max} if h_max else {}
    guard = WorkGuard(method, 0.0, T, max_work)
    for a, b in zip(cuts[:-1], cuts[1:]):
        if sampler is not None and a > 0 and round(a, 12) in sample_set:
            y_hold = sampler.sample(a, X[1])
        yy = None if sampler is None else y_hold
        te = t_out[(t_out >= a) & (t_out < b)]
        if len(te) == 0 or te[0] > a:
            te = np.concatenate([[a], te])
        fun = guard.wrap(lambda t, x, yy=yy: f(t, x, yy))
        opts = dict(rtol=rtol, atol=atol_v, t_eval=np.append(te, b), dense_output=encoder, **kw)
        with quiet() as caught:
            if name == "LSODA":
                sol, spent = _lsoda_guarded(fun, a, b, X, h_max, opts, on_redo=lambda: guard.use("bdf"))
                guard.use(method)
                if spent:
                    stalled.append(round(float(a), 9))
                    nfev += spent
            else:
                sol = solve_ivp(fun, (a, b), X, method=name, **opts)
        if sol.status < 0 or not np.all(np.isfinite(sol.y)):
            raise RunError(failure_message(method, a, caught, sol.message if sol.status < 0 else
                                           "the state stopped being finite", not sensor.ideal))
        nfev += sol.nfev
        if encoder:
            sampler.advance_angle(float(sol.y[7, -1]), lambda ang, s=sol.sol, lo_=a, hi=b: _edge_time(s, ang, lo_, hi))
        ts.append(sol.t[:-1])
        Xs.append(sol.y[:, :-1])
        ys.append(np.full(len(sol.t) - 1, np.nan if sampler is None else y_hold))
        X = sol.y[:, -1].copy()
    ts.append([T])
    Xs.append(X[:, None])
    ys.append([np.nan if sampler is None else y_hold])
    t = np.concatenate(ts)
    Y = np.concatenate(Xs, axis=1)
    y = np.concatenate(ys)
    y = np.where(np.isnan(y), Y[1], y)
    v, omega, z, eh, ch, zh, thh = Y[:7]
    info = {"method": method, "rtol": rtol, "atol": "rtol x state scales" if atol is None else atol,
            "h_max_s": h_max, "segments": len(cuts) - 1, "rhs_calls": int(nfev)}
    label = f"{method} (rtol {rtol:g})"
    if stalled:
        info["lsoda_stalled_segments_start_s"] = stalled
        info["lsoda_stall"] = (f"LSODA stayed in its non-stiff mode on {len(stalled)} segment(s) (first at t = "
                               f"{stalled[0]:.6g} s); each was redone with BDF")
        label = f"{method} (rtol {rtol:g}; {len(stalled)} segment(s) by BDF)"
    return Trajectory(t=t, v=v, omega=omega, z=z, y=y, v_hat=plant.speed_from_eta(eh, y), z_hat=zh, theta_hat=thh,
                      y_tilde=y - (ch - plant.P * zh) / plant.car.J, theta=theta_obs_from_fm(scenario.theta_fm(t)),
                      torque=np.asarray(scenario.torque(t), float), method=label, info=info)


#: LSODA counts as stalled when a window of this many right-hand-side calls advances the solution by
#: less than the window over :data:`LSODA_STALL_RATE` (2 ms).
LSODA_STALL_CALLS = 2000
#: Calls per simulated second [1/s] of a stalled LSODA, at least (or four per ``h_max``, if more). Its
#: normal work on the built-in runs is at most about 450 calls per segment start and 2000 per
#: simulated second (rtol 1e-10); stalled it makes about ``lambda_f/0.6`` calls per second, 6.5e6
#: for the OBS gains.
LSODA_STALL_RATE = 1e6


class _Stalled(Exception):
    """LSODA stalled on a segment (:func:`_lsoda_guarded`)."""


def _lsoda_guarded(fun, a: float, b: float, X, h_max, opts: dict, on_redo=None):
    """``solve_ivp`` with LSODA on ``[a, b]``, redone with BDF when LSODA stalls: ``(sol, calls spent in vain)``.

    LSODA starts every segment in its non-stiff (Adams) mode and switches to BDF on an estimate of
    the Lipschitz constant that it forms from the corrector's convergence rate. When the corrector
    converges in one iteration at every step (the fast observer mode, ``lambda_f`` about 4e6 1/s,
    sits below the tolerance) that estimate is never formed: LSODA stays in Adams at order 1 with
    the step its stability allows, ``h`` about ``0.6/lambda_f`` (1.5e-7 s), and a 1 s segment costs
    7e6 calls (the theta-known case of the speed-error study: 7.2e6 calls, 100 s). When
    :data:`LSODA_STALL_CALLS` calls in a row advance the solution (the latest time LSODA asked
    for) by less than ``LSODA_STALL_CALLS / LSODA_STALL_RATE``, the segment is redone with BDF
    (same tolerances and output times; ``on_redo()`` is called first).
    """
    from scipy.integrate import solve_ivp

    window = LSODA_STALL_CALLS
    least = window / max(LSODA_STALL_RATE, 4.0 / h_max if h_max else 0.0)   # [s] a window must advance
    calls = 0
    t_far = t_mark = a

    def counted(t, x):
        nonlocal calls, t_far, t_mark
        calls += 1
        if t > t_far:
            t_far = t
        if calls % window == 0:
            if t_far - t_mark < least:
                raise _Stalled
            t_mark = t_far
        return fun(t, x)

    try:
        return solve_ivp(counted, (a, b), X, method="LSODA", **opts), 0
    except _Stalled:
        if on_redo is not None:
            on_redo()
        return solve_ivp(fun, (a, b), X, method="BDF", **opts), calls


def _edge_time(sol, angle, lo, hi):
    """Time in ``[lo, hi]`` where the interpolated wheel angle ``sol(t)[7]`` reaches ``angle`` (1e-12 s)."""
    from scipy.optimize import brentq

    fa = sol(lo)[7] - angle
    fb = sol(hi)[7] - angle
    if fa >= 0.0:
        return lo
    if fb <= 0.0:
        return hi
    return brentq(lambda t: sol(t)[7] - angle, lo, hi, xtol=1e-12, rtol=1e-15)
