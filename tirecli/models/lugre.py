"""LuGre tire/road friction: parameters, Stribeck curve and steady states (pure, vectorized).

Implements, from Canudas-de-Wit, Tsiotras, Velenis, Basset, Gissinger, *Dynamic friction
models for road/tire longitudinal interaction* ([FM]) and Canudas-de-Wit, Petersen,
Shiriaev, *A new nonlinear observer for tire/road distributed contact friction* ([OBS]),
restated in ``docs/models/lugre_friction.md``:

- the Stribeck level ``g(vr)`` (FM, after eq. (1));
- the distributed steady state for a uniform load (FM eq. (4)), an exponential load
  (FM eq. (6) with its misprinted sign corrected) and any normal-load density (quadrature);
- ``kappa0(Z)`` of FM eq. (10) and the averaged lumped steady state (FM eqs. (8)-(9) with
  ``dz/dt = 0``) for constant ``kappa0``, ``kappa0(Z)`` and ``kappa = lambda/L``;
- the pieces of the lumped dynamics: its coefficient ``kappa``, decay rate (FM eq. (8)) and the
  friction of a deflection (FM eq. (9)). The dynamic models themselves (``rhs(t, x, u, p)``,
  ``outputs(t, x, u, p)``) are :mod:`tirecli.models.lugre_lumped` (lumped), :mod:`tirecli.models.lugre_pde`
  (distributed) and :mod:`tirecli.models.quarter_car`.

All functions take the relative velocity ``vr = r*omega - v`` and the wheel circumferential
speed ``romega = r*omega`` in m/s (signs: :mod:`tirecli.conventions`) and broadcast like numpy.
Adhesion ``theta`` is in the canonical FM convention (``g -> theta*g``).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

#: Below this value of ``x = L/Z`` series expansions replace the closed forms.
_X_SERIES = 1e-4


@dataclass(frozen=True)
class LuGreParams:
    """Parameters of the LuGre tire friction model (docs/models/lugre_friction.md §1, §6).

    Attributes
    ----------
    sigma0 : float
        Normalised rubber longitudinal stiffness [1/m] (FM eqs. (1)-(2)).
    sigma1 : float
        Normalised rubber longitudinal damping [s/m] (FM eq. (2)).
    sigma2 : float
        Normalised viscous relative damping [s/m] (FM eq. (2)).
    mu_c : float
        Normalised Coulomb friction level [-] (FM, after eq. (1)).
    mu_s : float
        Normalised static friction level [-], ``mu_s >= mu_c``.
    v_s : float
        Stribeck velocity [m/s].
    L : float
        Contact-patch length [m].
    alpha : float
        Stribeck exponent [-] (shape of ``g``; not printed for FM Table 1).
    kappa0 : float
        Constant lumped distribution coefficient ``kappa0 = kappa*L`` [-] (FM eq. (8); OBS
        ``kappa = 10 1/m`` with ``L = 0.2 m`` is ``kappa0 = 2``).
    sigma_w : float
        Rotational viscous friction of the wheel [kg m^2/s] (OBS eq. (4)).
    """

    sigma0: float
    sigma1: float
    sigma2: float
    mu_c: float
    mu_s: float
    v_s: float
    L: float
    alpha: float = 1.0
    kappa0: float = 2.0
    sigma_w: float = 1.0

    def as_dict(self) -> dict:
        return asdict(self)


def stribeck(vr, p: LuGreParams, theta=1.0):
    """Stribeck friction level ``theta*g(vr)`` [-] (FM, after eq. (1); docs/models/lugre_friction.md §2).

    ``g(vr) = mu_c + (mu_s - mu_c) exp(-|vr/v_s|^alpha)``, so ``mu_c <= g <= mu_s``.

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    a = np.abs(np.asarray(vr, dtype=float) / p.v_s)
    e = np.exp(-a) if p.alpha == 1.0 else np.exp(-(a ** p.alpha))
    return theta * (p.mu_c + (p.mu_s - p.mu_c) * e)


def stribeck_slope(a, p: LuGreParams, theta=1.0):
    """Slope ``d(theta g)/d|vr|`` [s/m] of the Stribeck level at ``|vr| = a > 0`` (FM, after eq. (1)).

    ``theta g = theta (mu_c + (mu_s - mu_c) exp(-(a/v_s)^alpha))``, so
    ``d(theta g)/da = -theta (mu_s - mu_c) (alpha/v_s) (a/v_s)^(alpha - 1) exp(-(a/v_s)^alpha)``
    (unbounded at ``a -> 0`` for ``alpha < 1``).

    Parameters
    ----------
    a : array_like
        Magnitude of the relative velocity ``|vr|`` [m/s], > 0.
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    q = np.asarray(a, dtype=float) / p.v_s
    qa = q if p.alpha == 1.0 else q ** p.alpha
    dq = np.ones_like(q) if p.alpha == 1.0 else p.alpha * q ** (p.alpha - 1.0)
    return -theta * (p.mu_s - p.mu_c) * np.exp(-qa) * dq / p.v_s


def patch_ratio(vr, romega, p: LuGreParams, theta=1.0):
    """Dimensionless patch length ``x = L/Z = sigma0 |vr| L / (theta g |r omega|)`` [-] (FM eq. (4)).

    ``Z = |r omega| theta g / (sigma0 |vr|)`` [m] is the distance a tread element travels
    before its deflection approaches the sliding value (docs/models/lugre_friction.md §3.3). ``x = inf`` for a
    locked wheel (``romega = 0``, ``vr != 0``) and 0 at ``vr = 0``.

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    vr = np.asarray(vr, dtype=float)
    g = stribeck(vr, p, theta)
    num = p.sigma0 * np.abs(vr) * p.L
    den = g * np.abs(np.asarray(romega, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore"):
        x = np.where(num == 0.0, 0.0, num / den)
    return x


def h_uniform(x):
    """Shape function ``h(x) = 1 - (1 - exp(-x))/x`` [-] of FM eq. (4) (docs/models/lugre_friction.md §3.3).

    Evaluated with ``expm1`` and the series ``x/2 - x^2/6 + x^3/24`` below ``x = 1e-4``;
    ``h(0) = 0`` and ``h(inf) = 1``.

    Parameters
    ----------
    x : array_like
        Dimensionless patch length ``x = L/Z`` [-], >= 0 (``inf``: locked wheel).
    """
    x = np.asarray(x, dtype=float)
    small = x < _X_SERIES
    xs = np.where(small, 1.0, x)
    with np.errstate(over="ignore", invalid="ignore"):
        big = 1.0 + np.expm1(-xs) / xs
    big = np.where(np.isinf(x), 1.0, big)
    xt = np.where(small, x, 0.0)
    series = xt * (0.5 - xt * (1.0 / 6.0 - xt / 24.0))
    return np.where(small, series, big)


#: Below this ``x`` the slope of ``h`` is its Taylor series (the closed form cancels).
_X_SLOPE_SERIES = 0.1


def h_uniform_slope(x):
    """Slope ``h'(x) = (1 - (1 + x) e^-x) / x^2`` [-] of the shape function of FM eq. (4).

    ``h'(0) = 1/2``, ``h' > 0`` and ``h'(x) ~ 1/x^2`` as ``x -> inf``. Below ``x = 0.1`` the
    series ``sum_{n>=1} (-1)^(n+1) n x^(n-1) / (n+1)!`` (to ``n = 12``) replaces the closed form.
    With ``s = lam + x`` it is also the slope of the exponential-load shape (FM eq. (6)), up to
    the factor ``lam/(1 - e^-lam)``.

    Parameters
    ----------
    x : array_like
        Dimensionless patch length ``x = L/Z`` [-], >= 0 (``inf``: locked wheel).
    """
    x = np.asarray(x, dtype=float)
    small = x < _X_SLOPE_SERIES
    xs = np.where(small | np.isinf(x), 1.0, x)
    with np.errstate(over="ignore", invalid="ignore"):
        big = (-np.expm1(-xs) - xs * np.exp(-xs)) / (xs * xs)
    big = np.where(np.isinf(x), 0.0, big)
    xt = np.where(small, x, 0.0)
    series = np.zeros_like(xt)
    fact = 2.0
    for n in range(1, 13):  # (n + 1)! built up term by term
        series = series + (-1.0) ** (n + 1) * n * xt ** (n - 1) / fact
        fact *= n + 2
    return np.where(small, series, big)


def kappa0_of_x(x):
    """Uniform-load lumped coefficient ``kappa0(Z)`` [-] of FM eq. (10) (docs/models/lugre_friction.md §4.2).

    ``kappa0 = (1 - exp(-x)) / h(x)`` with ``x = L/Z``; decreases from 2 (``x -> 0``) to 1
    (``x -> inf``). Series ``2 - x/3 + x^2/18 - x^3/270`` below ``x = 1e-4``.

    Parameters
    ----------
    x : array_like
        Dimensionless patch length ``x = L/Z`` [-], >= 0 (``inf``: locked wheel).
    """
    x = np.asarray(x, dtype=float)
    small = x < _X_SERIES
    xs = np.where(small, 1.0, x)
    with np.errstate(invalid="ignore"):
        big = -np.expm1(-xs) / h_uniform(xs)
    big = np.where(np.isinf(x), 1.0, big)
    xt = np.where(small, x, 0.0)
    series = 2.0 - xt / 3.0 + xt * xt / 18.0 - xt ** 3 / 270.0
    return np.where(small, series, big)


def mu_ss_uniform(vr, romega, p: LuGreParams, theta=1.0):
    """Distributed steady-state friction, uniform normal load: FM eq. (4) [-].

    ``mu = sgn(vr) theta g(vr) h(L/Z) + sigma2 vr`` with ``h`` from :func:`h_uniform`;
    ``mu = 0`` at ``vr = 0`` and the locked-wheel limit ``sgn(vr) theta g + sigma2 vr`` at
    ``romega = 0``.

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    # Written with in-place array operations: this is the hot path of every sweep
    # (benchmarks/bench_steady_state.py); it equals sgn(vr) g h(x) + sigma2 vr.
    vr, romega = np.broadcast_arrays(np.asarray(vr, dtype=float), np.asarray(romega, dtype=float))
    shape = vr.shape
    vr, romega = vr.reshape(-1), romega.reshape(-1)
    avr = np.abs(vr)
    g = avr / p.v_s
    if p.alpha != 1.0:
        np.power(g, p.alpha, out=g)
    np.negative(g, out=g)
    np.exp(g, out=g)
    g *= p.mu_s - p.mu_c
    g += p.mu_c
    g *= theta
    x = avr * (p.sigma0 * p.L)
    den = g * np.abs(romega)
    with np.errstate(divide="ignore", invalid="ignore"):
        np.divide(x, den, out=x)
        h = np.negative(x)
        np.expm1(h, out=h)
        h /= x
    h += 1.0  # h(inf) = 1 - 0 exactly
    fix = ~(x >= _X_SERIES)  # small x, and x = 0/0 at vr = 0
    if fix.any():
        h[fix] = h_uniform(np.where(avr[fix] == 0.0, 0.0, x[fix]))
    h *= g
    np.copysign(h, vr, out=h)
    h[avr == 0.0] = 0.0
    h += p.sigma2 * vr
    return h.reshape(shape)


def mu_ss_exponential(vr, romega, p: LuGreParams, lam, theta=1.0):
    """Distributed steady state, exponential load ``f_n ~ exp(-lam zeta/L)``: FM eq. (6) [-].

    FM eq. (6) with the sign of its ``k2 exp(-lam + c1 L)`` term corrected to minus
    (docs/models/lugre_friction.md §3.3, **[reconstructed]**). Written with ``x = L/Z`` it is

    ``mu = sgn(vr) theta g [1 - lam (1 - e^-(lam + x)) / ((lam + x)(1 - e^-lam))] + sigma2 vr``,

    which tends to eq. (4) as ``lam -> 0`` (evaluated in that limit for ``lam < 1e-8``).

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    lam : float or array_like
        Load decay ``lambda`` [-], ``>= 0`` (FM eq. (5)).
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    vr = np.asarray(vr, dtype=float)
    lam = np.asarray(lam, dtype=float)
    g = stribeck(vr, p, theta)
    x = patch_ratio(vr, romega, p, theta)
    lam_safe = np.where(lam < 1e-8, 1.0, lam)
    s = lam_safe + x
    with np.errstate(invalid="ignore", over="ignore"):
        # lam/(1 - e^-lam) * (1 - e^-s)/s, each factor via expm1 for accuracy
        frac = (lam_safe / -np.expm1(-lam_safe)) * (-np.expm1(-s) / s)
    frac = np.where(np.isinf(x), 0.0, frac)
    shape = np.where(lam < 1e-8, h_uniform(x), 1.0 - frac)
    return np.sign(vr) * g * shape + p.sigma2 * vr


#: Break points of the graded composite quadrature on u = zeta/L in [0, 1]: the integrand
#: 1 - exp(-x u) has a boundary layer of width 1/x at the leading edge. Half a decade apart up to
#: 0.1, then four intervals to 1: the parabolic-load shape is within 1e-15 of its closed form for
#: x up to 1e7 (one knot a decade and one interval [0.1, 1] left errors of 2e-9 at x = 30-100).
_GRADED = np.concatenate(([0.0], np.logspace(-7, -1, 13), [0.2, 0.4, 0.7, 1.0]))


def _quadrature(knots, nodes: int):
    """Composite Gauss-Legendre nodes and weights on [0, 1] over ``knots`` (sorted, with 0 and 1)."""
    gu, gw = np.polynomial.legendre.leggauss(nodes)
    gu, gw = 0.5 * (gu + 1.0), 0.5 * gw
    a, b = knots[:-1], knots[1:]
    u = (a[:, None] + (b - a)[:, None] * gu[None, :]).ravel()
    w = ((b - a)[:, None] * gw[None, :]).ravel()
    return u, w


def parabolic_density(u):
    """Parabolic normal-load density ``6 u (1 - u)`` per unit ``u = zeta/L`` [-] (docs/models/lugre_friction.md §3.2, [assumed form]).

    Integrates to 1 over ``u in [0, 1]``; ``f_n(zeta) = F_n/L * parabolic_density(zeta/L)``.

    Parameters
    ----------
    u : array_like
        Position along the patch ``u = zeta/L`` [-], 0 at the leading edge, 1 at the trailing edge.
    """
    u = np.asarray(u, dtype=float)
    return 6.0 * u * (1.0 - u)


def uniform_density(u):
    """Uniform normal-load density per unit ``u = zeta/L``: 1 [-] (FM eq. (3)).

    Parameters
    ----------
    u : array_like
        Position along the patch ``u = zeta/L`` [-], 0 at the leading edge, 1 at the trailing edge.
    """
    return np.ones_like(np.asarray(u, dtype=float))


def exponential_density(u, lam):
    """Exponential load density ``lam e^{-lam u}/(1 - e^{-lam})`` [-] per unit ``u = zeta/L`` (FM eq. (5)).

    Parameters
    ----------
    u : array_like
        Position along the patch ``u = zeta/L`` [-], 0 at the leading edge, 1 at the trailing edge.
    lam : float
        Load decay ``lambda`` [-], >= 0 (below 1e-12: the uniform density).
    """
    u = np.asarray(u, dtype=float)
    if lam < 1e-12:
        return np.ones_like(u)
    return lam * np.exp(-lam * u) / -np.expm1(-lam)


def tabulated_density(u_samples, f_samples):
    """A load density from samples ``f_n(zeta_i)`` at ``u_i = zeta_i/L``, normalised to unit mass
    (the density ``w`` of FM eq. (2); docs/models/lugre_friction.md §3.2).

    Returns a callable of ``u`` (linear interpolation; zero outside the samples).

    Parameters
    ----------
    u_samples : array_like
        Positions ``u_i = zeta_i/L`` [-], increasing.
    f_samples : array_like
        Load density at them [any unit: normalised here].
    """
    u_samples = np.asarray(u_samples, dtype=float)
    f_samples = np.asarray(f_samples, dtype=float)
    mass = np.trapezoid(f_samples, u_samples)

    def density(u):
        return np.interp(u, u_samples, f_samples, left=0.0, right=0.0) / mass

    density.knots = u_samples  # quadrature can honour the kinks
    return density


def mu_ss_density(vr, romega, p: LuGreParams, density, theta=1.0, nodes: int = 12):
    """Distributed steady state for any normal-load density, by quadrature [-] (FM eq. (2)).

    ``mu = sgn(vr) theta g [1 - int_0^1 w(u) e^{-x u} du] + sigma2 vr`` where ``w`` is the load
    density per unit ``u = zeta/L`` normalised to unit mass (``f_n = F_n w / L``) and
    ``z_ss(zeta) = sgn(vr) theta g (1 - e^{-zeta/Z}) / sigma0`` (docs/models/lugre_friction.md §3.3).

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    density : callable
        ``w(u)`` [-] on ``u in [0, 1]`` (e.g. :func:`parabolic_density`); a density built by
        :func:`tabulated_density` is integrated piecewise between its samples.
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    nodes : int
        Gauss-Legendre nodes per interval [-] of a composite rule graded towards the leading
        edge (where ``1 - e^{-x u}`` has a layer of width ``1/x``).
    """
    vr = np.asarray(vr, dtype=float)
    g = stribeck(vr, p, theta)
    x = patch_ratio(vr, romega, p, theta)
    knots = np.union1d(_GRADED, np.clip(getattr(density, "knots", np.array([])), 0.0, 1.0))
    u, w = _quadrature(knots, nodes)
    wd = w * density(u)
    xf = np.where(np.isinf(x), 0.0, x).ravel()
    shape = np.empty_like(xf)
    step = max(1, 2_000_000 // u.size)  # bound the temporary (points x nodes) array
    for i in range(0, xf.size, step):
        # sum_j w_j (1 - e^{-x u_j}) keeps full accuracy at small x
        shape[i:i + step] = -np.expm1(-np.multiply.outer(xf[i:i + step], u)) @ wd
    shape = np.where(np.isinf(x), 1.0, shape.reshape(x.shape))  # locked wheel: z = sliding value
    return np.sign(vr) * g * shape + p.sigma2 * vr


def density_shape_slope(x, density, nodes: int = 12):
    """Slope ``d/dx int_0^1 w(u) (1 - e^{-x u}) du = int_0^1 w(u) u e^{-x u} du`` [-] (FM eq. (2)).

    The derivative of the load-density shape of :func:`mu_ss_density` with respect to
    ``x = L/Z``, by the same graded composite Gauss-Legendre rule (``w`` of unit mass).

    Parameters
    ----------
    x : array_like
        Dimensionless patch length ``x = L/Z`` [-], >= 0 (``inf``: locked wheel).
    density : callable
        ``w(u)`` [-] on ``u in [0, 1]`` (:func:`mu_ss_density`).
    nodes : int
        Gauss-Legendre nodes per interval [-].
    """
    x = np.asarray(x, dtype=float)
    knots = np.union1d(_GRADED, np.clip(getattr(density, "knots", np.array([])), 0.0, 1.0))
    u, w = _quadrature(knots, nodes)
    wd = w * density(u) * u
    xf = np.where(np.isinf(x), 0.0, x).ravel()
    out = np.empty_like(xf)
    step = max(1, 2_000_000 // u.size)
    for i in range(0, xf.size, step):
        out[i:i + step] = np.exp(-np.multiply.outer(xf[i:i + step], u)) @ wd
    return np.where(np.isinf(x), 0.0, out.reshape(x.shape))


def mu_ss_lumped(vr, romega, p: LuGreParams, kappa0=None, theta=1.0):
    """Averaged lumped steady state (FM eqs. (8)-(9) with ``dz/dt = 0``) [-] (docs/models/lugre_friction.md §4.2).

    ``mu = sgn(vr) theta g x/(x + kappa0) + sigma2 vr`` with ``x = L/Z``. ``kappa0`` is
    a constant (``None`` takes ``p.kappa0``), ``lambda`` for an exponential load
    (``kappa = lambda/L``), or the string ``"Z"`` for ``kappa0(Z)`` of FM eq. (10), with which
    the lumped steady state equals eq. (4) exactly.

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    kappa0 : float, None or "Z"
        Lumped coefficient ``kappa0 = kappa L`` [-]: a constant, ``None`` for ``p.kappa0``, or ``"Z"`` for
        ``kappa0(Z)`` of FM eq. (10) at ``(vr, romega)``.
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    vr = np.asarray(vr, dtype=float)
    g = stribeck(vr, p, theta)
    x = patch_ratio(vr, romega, p, theta)
    if isinstance(kappa0, str):
        if kappa0 != "Z":
            raise ValueError(f"kappa0 must be a number or 'Z', got {kappa0!r}")
        k0 = kappa0_of_x(x)
    else:
        k0 = p.kappa0 if kappa0 is None else kappa0
    with np.errstate(divide="ignore", invalid="ignore"):
        frac = np.where(x == 0.0, 0.0, 1.0 / (1.0 + k0 / np.where(x == 0.0, 1.0, x)))
    return np.sign(vr) * g * frac + p.sigma2 * vr


def small_slip_slope(v, p: LuGreParams):
    """Braking small-slip stiffness ``d|mu|/d|s|`` at ``s -> 0``: ``sigma0 L/2 + sigma2 v`` [-].

    The slope at the origin of FM eq. (4) (docs/models/lugre_friction.md §3.3).

    Independent of ``g`` and of ``theta``.

    Parameters
    ----------
    v : array_like
        Vehicle speed [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    """
    return p.sigma0 * p.L / 2.0 + p.sigma2 * np.asarray(v, dtype=float)


def lumped_kappa(vr, romega, p: LuGreParams, kappa0=None, theta=1.0):
    """Lumped distribution coefficient ``kappa`` [1/m] = ``kappa0/L`` (FM eq. (8)).

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    kappa0 : float, None or "Z"
        Lumped coefficient ``kappa0 = kappa L`` [-]: a constant, ``None`` for ``p.kappa0``, or ``"Z"`` for
        ``kappa0(Z)`` of FM eq. (10) at ``(vr, romega)``.
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    if isinstance(kappa0, str):
        if kappa0 != "Z":
            raise ValueError(f"kappa0 must be a number or 'Z', got {kappa0!r}")
        return kappa0_of_x(patch_ratio(vr, romega, p, theta)) / p.L
    return (p.kappa0 if kappa0 is None else kappa0) / p.L


def lumped_decay_rate(vr, romega, p: LuGreParams, kappa0=None, theta=1.0):
    """Decay rate ``a = sigma0 |vr| / (theta g) + kappa |r omega|`` [1/s] of the lumped state (FM eq. (8)).

    FM eq. (8) reads ``dz/dt = vr - a z``; ``a`` reaches 1e3-1e4 1/s at large slip velocity
    (stiff). With ``vr`` and ``romega`` frozen over a step ``h`` the exact update is
    ``z(t + h) = z_ss + (z - z_ss) exp(-a h)`` with ``z_ss = vr / a`` [m].

    Parameters
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`LuGreParams`).
    kappa0 : float, None or "Z"
        Lumped coefficient ``kappa0 = kappa L`` [-]: a constant, ``None`` for ``p.kappa0``, or ``"Z"`` for
        ``kappa0(Z)`` of FM eq. (10) at ``(vr, romega)``.
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``; 1 = nominal).
    """
    vr = np.asarray(vr, dtype=float)
    return (p.sigma0 * np.abs(vr) / stribeck(vr, p, theta)
            + lumped_kappa(vr, romega, p, kappa0, theta) * np.abs(np.asarray(romega, dtype=float)))


def mu_of_deflection(z, zdot, vr, p: LuGreParams):
    """Normalised friction ``mu = sigma0 z + sigma1 dz/dt + sigma2 vr`` [-] (FM eq. (9); FM eq. (2) with
    the load-weighted mean deflection and its rate).

    Parameters
    ----------
    z : array_like
        Mean bristle deflection [m] (FM eq. (7)).
    zdot : array_like
        Its rate ``dz/dt`` [m/s].
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    p : LuGreParams
    """
    return p.sigma0 * z + p.sigma1 * zdot + p.sigma2 * np.asarray(vr, dtype=float)
