"""Plant + observer in one simulation: a structured fixed-step scheme, adaptive scipy methods, ``auto``.

:func:`simulate` runs the method of ``solver:`` (:class:`SolverOptions`): ``fixed``
(:func:`simulate_fast`), ``lsoda``/``radau``/``bdf`` (:func:`simulate_adaptive`, split at every
breakpoint and sample; a segment where LSODA stalls in its non-stiff mode is redone with BDF) or
``auto`` (:func:`choose_method`: LSODA for the ideal measurement, the fixed scheme for a sampled one
when ``lambda_f``, ``h rho_slow`` and ``h rho_block`` allow it).

The coupled system (docs/models/observer_model.md §1-§3) is stiff twice over: the plant's wheel/bristle modes reach
-2.5e3 1/s and the observer's output-error mode ``lambda_f = C K_eff`` is about -3.9e6 1/s for the
OBS gains. :func:`simulate_fast` exploits the structure:

1. **Plant** in OBS coordinates ``(eta, chi, z)`` (OBS (19)-(22)): the stiff pair ``(chi, z)`` is
   linear once the bristle decay ``a = theta_obs sigma0 |vr|/g + kappa r |omega|`` is frozen, and
   is advanced with its exact 2x2 matrix exponential and phi-functions (forcing affine in time);
   ``a`` is taken at the step's trapezoid mean from a predictor (the previous step's exponential),
   its variation inside the step enters as an affine forcing ``-(a(t) - a_mean) z(t)`` (this keeps
   the fast bristle component stiffly accurate); ``eta`` (slow) by the trapezoidal rule.
2. **Observer** by singular perturbation of its fast mode: on the slow manifold
   ``y~ = (y_m' - C F(x_hat, y_m)) / lambda_f`` (error ``O(rate/lambda_f)``, about 1e-3 relative),
   which leaves ``chi_hat`` with the constant rate ``sigma0/sigma1`` (exact exponential) and
   ``eta_hat``, ``theta_hat`` non-stiff (linearly implicit trapezoid). The observer is integrated in
   error coordinates ``eta~ = eta - eta_hat``, ``chi~ = chi - chi_hat`` so that the plant's
   truncation error is not mistaken by the high-gain adaptation (``gamma = 2e5``) for a model
   mismatch; an exact initial state therefore stays exact.
3. **Sampled measurements** (zero-order hold) jump at sampling instants; the fast layer that
   follows each jump ``Delta`` (width ``1/lambda_f``) is applied in closed form:
   ``x_hat += K_eff Delta/lambda_f`` and ``theta_hat`` gains ``gamma (phi_hat Delta + alpha Delta^2/2)/lambda_f``.

:func:`simulate_adaptive` integrates the full 7-state system (plant ``(v, omega, z)``, observer
OBS (14); :func:`scalar_rhs`) with ``scipy.integrate.solve_ivp``; :func:`simulate_reference` is it
with the reference Radau settings of docs/models/observer_model.md §7. :func:`full_rhs` is the same system built from
the models' right-hand sides, :func:`tirecli.models.quarter_car.rhs` and :func:`tirecli.observers.observer.rhs`
(the straightforward form the benchmark once timed).

**Models the kernels implement:** :func:`scalar_rhs` inlines :func:`full_rhs`; :func:`simulate_fast` inlines
:func:`tirecli.observers.plant.rhs` and :func:`tirecli.observers.observer.rhs` through :func:`fast_model`.
Parity to 1e-12: tests/test_model_parity.py.
"""
from __future__ import annotations

import cmath
import math
from dataclasses import dataclass, field
from operator import attrgetter
from types import SimpleNamespace
from typing import Callable

import numpy as np

from tirecli.conventions import theta_obs_from_fm
from tirecli.errors import RunError
from tirecli.numerics.solver_guard import WorkGuard, failure_message, quiet
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant
from tirecli.observers.measurement import Sensor

#: Default fixed step of the fast scheme [s] (accuracy: see tests/test_observer_numerics.py).
DEFAULT_STEP = 2.5e-3
#: The singular-perturbation reduction needs a fast observer mode well above the plant's rates.
MIN_FAST_RATE = 1e5
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


def _expo2(m11, m12, m21, m22, h):
    """``phi_k(h M)``, k = 0, 1, 2, of a real 2x2 matrix as 12 floats (row-major E, P1, P2).

    ``phi_0 = exp``, ``phi_1(x) = (e^x - 1)/x``, ``phi_2(x) = (e^x - 1 - x)/x^2``, evaluated by the
    Newton form ``f(hM) = f(l2) I + f[l1, l2] (hM - l2 I)`` on the eigenvalues ``l1, l2`` of ``hM``
    (nearly repeated real eigenvalues are split by 1e-7 relative; complex ones use ``cmath``).
    """
    a, b, c, d = h * m11, h * m12, h * m21, h * m22
    half = 0.5 * (a + d)
    disc = half * half - (a * d - b * c)
    if disc >= 0.0:
        sq = math.sqrt(disc)
        tiny = 1e-7 * (1.0 + abs(half))
        if sq < tiny:
            sq = tiny
        l1, l2 = half + sq, half - sq
        e1, f11, f21 = _phis(l1)
        e2, f12, f22 = _phis(l2)
    else:
        sq = cmath.sqrt(disc)
        l1, l2 = half + sq, half - sq
        e1, f11, f21 = _phis_c(l1)
        e2, f12, f22 = _phis_c(l2)
    inv = 0.5 / sq
    d0, d1, d2 = (e1 - e2) * inv, (f11 - f12) * inv, (f21 - f22) * inv
    A, D = a - l2, d - l2
    out = (e2 + d0 * A, d0 * b, d0 * c, e2 + d0 * D,
           f12 + d1 * A, d1 * b, d1 * c, f12 + d1 * D,
           f22 + d2 * A, d2 * b, d2 * c, f22 + d2 * D)
    return out if disc >= 0.0 else tuple(x.real for x in out)


def _phis(x):
    """``(phi_0, phi_1, phi_2)(x)`` of a real ``x``, accurate near 0."""
    if -1e-3 < x < 1e-3:
        return math.exp(x), 1.0 + x * (0.5 + x * (1.0 / 6.0 + x / 24.0)), 0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x / 120.0))
    e = math.exp(x)
    p1 = (e - 1.0) / x
    return e, p1, (p1 - 1.0) / x


def _phis_c(x):
    """``(phi_0, phi_1, phi_2)(x)`` of a complex ``x``."""
    if abs(x) < 1e-3:
        return cmath.exp(x), 1.0 + x * (0.5 + x * (1.0 / 6.0 + x / 24.0)), 0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x / 120.0))
    e = cmath.exp(x)
    p1 = (e - 1.0) / x
    return e, p1, (p1 - 1.0) / x


def _profiles(scenario: Scenario, grid: np.ndarray):
    """Torque and ``theta_obs`` at each step's start (right limit), end (left limit) and midpoint."""
    t0, t1 = grid[:-1], grid[1:]
    eps = 1e-9 * np.maximum(1.0, np.abs(t1))
    tm = 0.5 * (t0 + t1)
    u = scenario.torque
    th = lambda t: theta_obs_from_fm(scenario.theta_fm(t))  # noqa: E731
    return (np.asarray(u(t0), float), np.asarray(u(t1 - eps), float), np.asarray(th(t0), float),
            np.asarray(th(t1 - eps), float), np.asarray(th(tm), float))


# --------------------------------------------------------------------------- fast scheme


class StepTooLarge(RunError):
    """The fixed step times the slow observer block's fastest rate exceeded the limit at time ``t``."""

    def __init__(self, t: float, h_rate: float, limit: float):
        self.t, self.h_rate, self.limit = t, h_rate, limit
        super().__init__(f"the fixed step is too large at t = {t:.4g} s: step x fastest rate = {h_rate:.3g} "
                         f"> {limit:g}; use a smaller solver.step or an adaptive method (solver.method: lsoda)")


#: The constants and functions of :func:`fast_model` that :func:`simulate_fast` binds as locals.
FAST_NAMES = tuple("r J rm irm kr c E1 P rho m11 m12 m21 m22c k1 k2 k3 gam alp lam0 lamb swmrj PJ PrmJ fabs aphi_of daphi_of oeval ydot".split())


def fast_model(plant: ObserverPlant, gains: ObserverGains) -> SimpleNamespace:
    """The plant and observer as :func:`simulate_fast` inlines them: constants and scalar functions (module doc).

    **Models it implements:** :func:`tirecli.observers.plant.rhs` (OBS coordinates) and
    :func:`tirecli.observers.observer.rhs` on its slow manifold. The plant's ``eta' = -c eta + E1 omega + u``
    and the stiff pair ``(chi, z)' = M(a) (chi, z) + (u, -eta/(r m))`` with
    ``M(a) = [[m11, m12], [m21, m22c - a]]``, ``a = theta_obs aphi_of(vr) + kr |omega|``; ``ydot``: the
    plant's ``omega' = C x'``; ``oeval``: the observer's output error on its slow manifold, where
    ``C x_hat' = y_m'`` (``y~' = 0``), with ``z_hat``, ``v_hat``. Parity to 1e-12:
    tests/test_model_parity.py.
    """
    tire, car, g = plant.tire, plant.car, gains
    r, m, J = car.r, car.m, car.J
    s0, sw = tire.sigma0, tire.sigma_w
    muc, dmu, ivs, al_g = tire.mu_c, tire.mu_s - tire.mu_c, 1.0 / tire.v_s, tire.alpha
    unit_alpha = al_g == 1.0
    kr = plant.kappa * r
    rm = r * m
    irm = 1.0 / rm
    c = plant.c_eta
    E1, _, E3 = (float(e) for e in plant.E)
    P, Q = plant.P, plant.Q
    iP = 1.0 / P
    rho = Q / P
    m11, m12, m21 = -sw / J, -Q + sw * P / J, E3 / J
    m22c = -E3 * P / J
    k1, k2, k3, gam, alp = g.k1, g.k2, g.k3, g.gamma, g.alpha
    lam0 = (k2 - P * k3 + P * alp) / J  # lambda_f = lam0 + lamb * theta_hat
    lamb = P * alp / J
    swmrj = sw - rho * J                # chi~ forcing per unit measurement error
    NJ = (sw + P * E3) / J              # C (F(x, y) - F(x_hat, y_m)) per unit measurement error
    PJ, QJ, PrmJ = P / J, Q / J, P * irm / J
    exp_, fabs = math.exp, math.fabs

    def aphi_of(vr):
        """``sigma0 |vr| / g(vr)`` [1/s]."""
        avr = fabs(vr)
        if unit_alpha:
            return s0 * avr / (muc + dmu * exp_(-avr * ivs))
        return s0 * avr / (muc + dmu * exp_(-((avr * ivs) ** al_g)))

    def daphi_of(vr):
        """``d(sigma0 |vr|/g)/d vr`` [1/m] (its magnitude; the sign does not enter the rate)."""
        avr = fabs(vr)
        x = avr * ivs
        e = exp_(-x) if unit_alpha else exp_(-(x ** al_g))
        gg = muc + dmu * e
        dg = -dmu * e * ivs * (1.0 if unit_alpha else al_g * x ** (al_g - 1.0) if x > 0 else 0.0)
        return s0 * (gg - avr * dg) / (gg * gg)

    def oeval(et, ct, thh, eta, z, w, thpz, nv, ydiff):
        """Observer on the slow manifold: ``(y~, phi_hat, z_hat, v_hat)``; ``thpz = theta phi`` of the plant.

        ``y~ = (y_m' - y' + C (F(x, y) - F(x_hat, y_m))) / lambda_f`` (module doc), written with the
        errors ``eta~ = et``, ``chi~ = ct``, ``n = y_m - y = nv`` and ``z~ = (chi~ + J n)/P``.
        """
        ym = w + nv
        zt = (ct + J * nv) * iP
        zh = z - zt
        vh = (eta - et - J * ym) * irm
        phh = aphi_of(r * ym - vh) * zh
        yt = ((ydiff + NJ * nv - QJ * zt + PrmJ * et + PJ * (thpz - thh * phh + kr * (fabs(w) * z - fabs(ym) * zh)))
              / (lam0 + lamb * thh))
        return yt, phh, zh, vh

    def ydot(z_, w_, vr_, a_, u_):
        """Plant wheel acceleration ``omega'`` [rad/s^2] (OBS (4))."""
        return (-Q * z_ - P * (vr_ - a_ * z_) - sw * w_ + u_) / J

    return SimpleNamespace(**{n: v for n, v in locals().items() if n not in ("plant", "gains", "tire", "car", "g")})


def simulate_fast(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario, sensor: Sensor | None = None,
                  step: float = DEFAULT_STEP, record_every: int = 1, rate_limit: float = math.inf) -> Trajectory:
    """Simulate plant and observer with the structured fixed-step scheme (module doc).

    Parameters
    ----------
    plant : ObserverPlant
        Tire and quarter-car parameters (lumped LuGre, constant ``kappa``, OBS ``sigma2`` placement).
    gains : ObserverGains
        ``k1, k2, k3, gamma, alpha`` of OBS (14).
    scenario : Scenario
        Profiles and initial states.
    sensor : Sensor or None
        Measurement model (``None``: ideal).
    step : float
        Largest step [s]; sampling instants and profile breakpoints are added to the grid.
    record_every : int
        Keep every n-th grid point in the returned trajectory (the last one always).
    rate_limit : float
        Largest ``h rho`` allowed, ``rho`` [1/s] the spectral radius of the Jacobian of the slow
        observer block ``(eta~, theta_hat)`` (what the linearly implicit trapezoid integrates; its
        error grows like ``(h rho)^2``); :class:`StepTooLarge` is raised at the first step above
        it. The largest ``h rho`` of the run is returned in ``info["max_step_x_rate"]``.

    Raises
    ------
    RunError
        When the observer's fast mode is too slow for the reduction (``lambda_f < 1e5 1/s``; use an
        adaptive method), becomes unstable, or the state stops being finite; :class:`StepTooLarge`
        when ``h rho`` exceeds ``rate_limit``.
    """
    sensor = sensor or Sensor()
    lam_min = plant.fast_rate(gains, scenario.theta_hat0)
    if not lam_min >= MIN_FAST_RATE:
        raise RunError(f"the observer's fast output-error mode (lambda_f = {lam_min:.3g} 1/s) is too slow for the "
                       f"fast scheme's singular-perturbation reduction (needs >= {MIN_FAST_RATE:g} 1/s); "
                       "use an adaptive method (solver.method: lsoda)")
    samples = sensor.sample_times(scenario.duration)
    # sampled: at least one grid point inside each hold interval (mid-sample states on the grid)
    grid = time_grid(scenario.duration, min(step, 0.5 * sensor.period) if not sensor.ideal else step,
                     scenario.breakpoints, samples)
    u0a, u1a, th0a, th1a, thma = _profiles(scenario, grid)
    # a profile jumps at grid point n when its right limit differs from the left limit
    jump = np.zeros(len(u0a), dtype=bool)
    jump[1:] = ((np.abs(u0a[1:] - u1a[:-1]) > 1e-7 * (1.0 + np.abs(u0a[1:])))
                | (np.abs(th0a[1:] - th1a[:-1]) > 1e-7 * (1.0 + np.abs(th0a[1:]))))
    jumps = set(np.flatnonzero(jump).tolist())
    U0, U1, TH0, TH1, THM = (a.tolist() for a in (u0a, u1a, th0a, th1a, thma))
    T = grid.tolist()
    N = len(T) - 1
    # sampling instants -> grid indices
    sample_at = {}
    if not sensor.ideal:
        idx = np.searchsorted(grid, samples - 1e-9 * step)
        sample_at = {int(i): k for k, i in enumerate(idx) if i > 0}  # t = 0 is sampled at the start
    ideal = sensor.ideal
    sampler = None if ideal else sensor.sampler(len(samples), scenario.omega0)

    # ---- constants and model functions (locals for speed)
    (r, J, rm, irm, kr, c, E1, P, rho, m11, m12, m21, m22c, k1, k2, k3, gam, alp, lam0, lamb, swmrj, PJ, PrmJ,
     fabs, aphi_of, daphi_of, oeval, ydot) = attrgetter(*FAST_NAMES)(fast_model(plant, gains))

    # ---- initial state
    eta, chi, z = (float(a) for a in plant.to_obs_coords(scenario.v0, scenario.omega0, scenario.z0))
    w = float(scenario.omega0)
    v = float(scenario.v0)
    vr = r * w - v
    aphi = aphi_of(vr)
    th = TH0[0]
    a_n = th * aphi + kr * fabs(w)
    ym = sampler.sample(0.0, w) if sampler is not None else w
    nv = ym - w
    # the observer starts from the measured wheel speed, y_hat(0) = y_m(0)
    et = rm * (scenario.v0 - scenario.vhat0) - J * nv
    ct = P * (scenario.z0 - scenario.z_hat0) - J * nv
    thh = float(scenario.theta_hat0)
    yd = 0.0 if ideal else ydot(z, w, vr, a_n, U0[0])
    ydiff = 0.0 if ideal else -yd
    yt, phh, zh, vh = oeval(et, ct, thh, eta, z, w, th * aphi * z, nv, ydiff)

    max_hr, t_max_hr = 0.0, 0.0
    rec = [(T[0], v, w, z, ym, vh, zh, thh, yt, th, U0[0])]
    rec_append = rec.append
    Ep = None
    h_prev = -1.0
    EXPR = P1R = P2R = 0.0
    n0 = n1 = ydiff1 = 0.0
    for n in range(N):
        t0 = T[n]
        t1 = T[n + 1]
        h = t1 - t0
        if abs(h - h_prev) > 1e-9 * h:
            EXPR, P1R, P2R = _phis(-rho * h)
            Ep = None
            h_prev = h
        u0, u1, thm, th1 = U0[n], U1[n], THM[n], TH1[n]
        if n in jumps:
            # a profile jumps at t0: derivatives from the right
            th = TH0[n]
            a_n = th * aphi + kr * fabs(w)
            Ep = None
            if not ideal:
                yd = ydot(z, w, vr, a_n, u0)
                ydiff = -yd
            yt, phh, zh, vh = oeval(et, ct, thh, eta, z, w, th * aphi * z, nv, ydiff)
        if n in sample_at:
            ynew = sampler.sample(t0, w)
            delta = ynew - ym
            if delta != 0.0:
                # fast layer after a measurement jump, in closed form (module doc)
                lam = lam0 + lamb * thh
                zh_after = zh + (k3 - alp * (1.0 + thh)) * delta / lam
                rhs = gam * (aphi_of(r * ynew - vh) * 0.5 * (zh + zh_after) * delta + 0.5 * alp * delta * delta)
                dth = 2.0 * rhs / (lam + math.sqrt(max(lam * lam + 2.0 * lamb * rhs, 0.0)))
                iy = delta / (lam + 0.5 * lamb * dth)
                et -= k1 * iy
                ct -= k2 * iy
                thh += dth
            ym = ynew
            nv = ym - w
            yt, phh, zh, vh = oeval(et, ct, thh, eta, z, w, th * aphi * z, nv, ydiff)
        lam = lam0 + lamb * thh
        jth = -gam * phh * phh * PJ / lam      # d theta_hat'/d theta_hat
        jet = -c - k1 * PrmJ / lam             # d eta~'/d eta~
        # fastest rate of the slow observer block (eta~, theta_hat): spectral radius of its Jacobian
        vrh = r * ym - vh
        dy_e = (PrmJ - PJ * thh * zh * daphi_of(vrh) * irm) / lam       # d y~/d eta~
        dy_t = (-PJ * phh - lamb * yt) / lam                            # d y~/d theta_hat
        w2 = phh + 2.0 * alp * yt
        j11, j12 = -c - k1 * dy_e, -k1 * dy_t
        j21, j22 = gam * (dy_e * w2 + yt * zh * daphi_of(vrh) * irm), gam * dy_t * w2
        tr2 = 0.5 * (j11 + j22)
        dsc = tr2 * tr2 - (j11 * j22 - j12 * j21)
        rate = fabs(tr2) + math.sqrt(dsc) if dsc >= 0.0 else math.sqrt(tr2 * tr2 - dsc)
        if rate * h > max_hr:
            max_hr = rate * h
            t_max_hr = t0
            if max_hr > rate_limit:
                raise StepTooLarge(t0, max_hr, rate_limit)

        # ---------------- plant: predictor with the previous step's exponential
        if Ep is None:
            Ep = _expo2(m11, m12, m21, m22c - a_n, h)
        e11, e12, e21, e22, p11, p12, p21, p22, q11, q12, q21, q22 = Ep
        etad = -c * eta + E1 * w + u0
        ga = h * u0
        gb = -h * eta * irm
        ha = h * (u1 - u0)
        hb = -h * h * etad * irm
        chip = e11 * chi + e12 * z + p11 * ga + p12 * gb + q11 * ha + q12 * hb
        zp = e21 * chi + e22 * z + p21 * ga + p22 * gb + q21 * ha + q22 * hb
        etap = eta + h * etad
        wp = (chip - P * zp) / J
        vrp = r * wp - (etap - J * wp) * irm
        # ---------------- corrector: trapezoid mean of a; its variation enters as a forcing
        a0 = thm * aphi + kr * fabs(w)
        ap = thm * aphi_of(vrp) + kr * fabs(wp)
        Ep = _expo2(m11, m12, m21, m22c - 0.5 * (a0 + ap), h)
        e11, e12, e21, e22, p11, p12, p21, p22, q11, q12, q21, q22 = Ep
        da = 0.5 * (ap - a0)
        g0 = da * z
        eta1 = eta + 0.5 * h * (etad - c * etap + E1 * wp + u1)
        gb = h * (g0 - eta * irm)
        hb = h * (-(eta1 - eta) * irm - da * zp - g0)
        chi1 = e11 * chi + e12 * z + p11 * ga + p12 * gb + q11 * ha + q12 * hb
        z1 = e21 * chi + e22 * z + p21 * ga + p22 * gb + q21 * ha + q22 * hb
        w1 = (chi1 - P * z1) / J
        eta1 = (eta + 0.5 * h * (etad + E1 * w1 + u1)) / (1.0 + 0.5 * c * h)
        v1 = (eta1 - J * w1) * irm
        vr1 = r * w1 - v1
        aphi1 = aphi_of(vr1)
        thpz1 = th1 * aphi1 * z1
        if not ideal:
            if sampler is not None:
                sampler.advance(t0, t1, w, w1)
            a1 = th1 * aphi1 + kr * fabs(w1)
            yd = ydot(z1, w1, vr1, a1, u1)
            ydiff1 = -yd
            n0, n1 = nv, ym - w1
        else:
            a1 = 0.0

        # ---------------- observer (error coordinates): linearly implicit Euler predictor
        etd0 = -c * et - E1 * n0 - k1 * yt
        thd0 = gam * yt * (phh + alp * yt)
        etp = et + h * etd0 / (1.0 - h * jet)
        thp = thh + h * thd0 / (1.0 - h * jth)
        b0 = swmrj * n0 - k2 * yt
        bs = swmrj * (n1 - n0)
        ctp = EXPR * ct + h * (P1R * b0 + P2R * bs)
        ytp, phhp, _, _ = oeval(etp, ctp, thp, eta1, z1, w1, thpz1, n1, ydiff1)
        # ---------------- linearly implicit trapezoid corrector
        etd1 = -c * etp - E1 * n1 - k1 * ytp
        thd1 = gam * ytp * (phhp + alp * ytp)
        et = (et + 0.5 * h * (etd0 + etd1 - jet * etp)) / (1.0 - 0.5 * h * jet)
        thh = (thh + 0.5 * h * (thd0 + thd1 - jth * thp)) / (1.0 - 0.5 * h * jth)
        ct = EXPR * ct + h * (P1R * b0 + P2R * (bs - k2 * (ytp - yt)))

        eta, chi, z, w, v, vr, aphi, th, nv, ydiff = eta1, chi1, z1, w1, v1, vr1, aphi1, th1, n1, ydiff1
        if ideal:
            a_n = th * aphi + kr * fabs(w)
        else:
            a_n = a1
        yt, phh, zh, vh = oeval(et, ct, thh, eta, z, w, thpz1, nv, ydiff)
        if (n + 1) % record_every == 0 or n + 1 == N:
            rec_append((t1, v, w, z, w if ideal else ym, vh, zh, thh, yt, th, u1))
            if not (lam0 + lamb * thh > 0.1 * MIN_FAST_RATE and math.isfinite(thh + et + z)):
                raise RunError(f"observer diverged at t = {t1:.4g} s (theta_hat = {thh:.4g}, fast-mode rate "
                               f"{lam0 + lamb * thh:.3g} 1/s): the gains do not keep it stable in this scenario")
    arr = np.array(rec)
    return Trajectory(t=arr[:, 0], v=arr[:, 1], omega=arr[:, 2], z=arr[:, 3], y=arr[:, 4], v_hat=arr[:, 5],
                      z_hat=arr[:, 6], theta_hat=arr[:, 7], y_tilde=arr[:, 8], theta=arr[:, 9], torque=arr[:, 10],
                      method=f"fixed (step {step * 1e3:g} ms)",
                      info={"method": "fixed", "steps": N, "step_s": step, "grid_points": N + 1,
                            "fast_rate_1_s": float(plant.fast_rate(gains, thh)), "max_step_x_rate": max_hr,
                            "max_step_x_rate_at_s": t_max_hr})


# --------------------------------------------------------------------------- reference


def full_rhs(plant: ObserverPlant, gains: ObserverGains, scenario: Scenario):
    """``f(t, X, y)`` of plant + observer composed from the models, ``X = (v, omega, z, eta_hat, chi_hat, z_hat,
    theta_hat[, angle])``.

    Plant: :func:`tirecli.models.quarter_car.rhs` with ``QuarterCar(LumpedTire(plant.tire), plant.car,
    sigma2_in_wheel=False)`` (OBS (3)-(5); the scenario's adhesion ``theta_fm``); observer:
    :func:`tirecli.observers.observer.rhs` driven by the held measured wheel speed ``y`` [rad/s] (``None``:
    the ideal ``y = omega``); the wheel angle ``angle' = omega`` [rad] when ``X`` has an eighth state. The
    straightforward formulation, which :func:`scalar_rhs` inlines (parity: tests/test_model_parity.py).
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


# --------------------------------------------------------------------------- adaptive (scipy)

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

    **Models it implements:** :func:`full_rhs`, i.e. :func:`tirecli.models.quarter_car.rhs` (lumped tire,
    ``sigma2_in_wheel=False``) and :func:`tirecli.observers.observer.rhs`, inlined; parity to 1e-12 for the
    ideal and the held measurement, with and without the wheel angle: tests/test_model_parity.py.

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


# --------------------------------------------------------------------------- method choice

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
        Absolute tolerance (``None``: ``rtol`` times :func:`state_scales`).
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
      in the non-stiff mode (:func:`_lsoda_guarded`: such a segment is redone with BDF);
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
