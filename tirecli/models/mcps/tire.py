"""The MCPS tire: contact patch of Dahl sliders, rigid or flexible belt (Sorine & Szymanski 2000).

Axes and signs (ISO-W, stated once for MCPS; see :mod:`tirecli.models.mcps.law` for the friction
operator): ``X_W`` forward along the wheel heading, ``Y_W`` left, ``Z_W`` up, origin at the patch
centre; patch abscissa ``xi`` in ``[-l/2, l/2]`` along ``X_W`` (forward), ``d = l/2 - xi`` the
distance from the leading edge of a rolling tire. Slip as in the Magic Formula (ISO-W):
``kappa = (r omega - Vx)/|Vx|`` (> 0 driving), ``tan alpha_s = Vy/|Vx|``, path curvature
``phi = yaw_rate/Vx`` [1/m]. Tire forces ``Fx, Fy, Mz`` are **road on tire**: ``Fx > 0`` for
``kappa > 0``, ``Fy < 0`` and ``Mz > 0`` for ``alpha_s > 0``. Resultants (MCPS eq. 10):
``F = -int f dxi``, ``Mz = -int (m + c_Mz xi f_y) dxi``.

Rate independence: every stationary quantity depends on the slider velocities divided by the
transport speed ``r omega``, never on the speed itself. The stationary patch (MCPS eq. 14) of a
uniform slip is solved in closed form (:func:`stationary_uniform`); with a yaw rate the lateral
slip varies linearly along the patch and :func:`stationary_linear` integrates (14) in ``d``
(classical RK4 on each side of the point where the lateral slip vanishes, error checked in the
tests). The complete model's belt (MCPS eqs. 16-17) is :func:`belt_velocities`, :func:`wheel_forces`
and the belt's dynamics :mod:`tirecli.models.mcps.belt`; the friction law's dynamics are
:func:`tirecli.models.mcps.law.rhs`.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.models.mcps.law import DahlLaw, path_rates

#: Below this argument the closed forms switch to their power series (docs/models/mcps_tire.md §6: the aligning
#: bracket loses every digit to cancellation near z = 1e-4).
SERIES_Z = 0.05


def _series(z, coef):
    out = np.zeros_like(z)
    for c in reversed(coef):
        out = out * z + c
    return out


_F1Z = [((-1) ** (j + 1)) / math.factorial(j + 1) for j in range(1, 14)]           # f1(z)/z
_F2Z = [((-1) ** j) * j / (2.0 * math.factorial(j + 2)) for j in range(1, 14)]     # f2(z)/z


def f1z(z):
    """``f1(z)/z`` [-] with ``f1(z) = 1 - (1 - e^-z)/z``: the patch mean of ``1 - e^{-z d/l}`` (MCPS eq. 14,
    docs/models/mcps_tire.md §6); finite at 0 (1/2).

    Parameters
    ----------
    z : array_like
        ``z = |F_k s| g l`` [-], >= 0 (patch length over the relaxation length).
    """
    z = np.asarray(z, dtype=float)
    small = z < SERIES_Z
    zs = np.where(small, 1.0, z)
    direct = (1.0 + np.expm1(-zs) / zs) / zs
    return np.where(small, _series(np.where(small, z, 0.0), _F1Z), direct)


def f2z(z):
    """``f2(z)/z`` [-] with ``f2(z) = (1 - e^-z (1+z))/z^2 - (1 - e^-z)/(2z)`` (MCPS eq. 14: the first moment about
    the patch centre, docs/models/mcps_tire.md §6); series ``sum (-1)^j j z^(j-1)/(2 (j+2)!)`` below ``SERIES_Z``.

    Parameters
    ----------
    z : array_like
        ``z = |F_k s| g l`` [-], >= 0.
    """
    z = np.asarray(z, dtype=float)
    small = z < SERIES_Z
    zs = np.where(small, 1.0, z)
    em1 = -np.expm1(-zs)                   # 1 - e^-z
    direct = ((em1 - zs * np.exp(-zs)) / zs**2 - em1 / (2.0 * zs)) / zs
    return np.where(small, _series(np.where(small, z, 0.0), _F2Z), direct)


def stationary_uniform(s, spin, law: DahlLaw, l: float):
    """Patch integrals of the stationary states for a uniform slip (MCPS eq. 14, closed form).

    Parameters
    ----------
    s : array_like, shape (..., 2)
        Slider velocity over transport speed, ``du/(r omega)`` [-] (uniform along the patch).
    spin : array_like, shape (...)
        Slider spin over transport speed, ``Omega_s/(r omega)`` [1/m] (drives the torsion).
    law : DahlLaw
        The law per unit patch length (:meth:`MCPSParams.patch_law`).
    l : float
        Patch length [m].

    Returns
    -------
    f0 : ndarray, shape (..., 2)
        ``int_0^l f dd`` [N]: the friction force the patch transmits to the road.
    f1y : ndarray, shape (...)
        ``int_0^l (l/2 - d) f_y dd`` [N m]: its lateral first moment about the patch centre.
    m0 : ndarray, shape (...)
        ``int_0^l m dd`` [N m]: the torsional torque.

    Notes
    -----
    Each component obeys ``dF/dd = h s - n g F`` (``n = |F_k s|``), so with ``z = n g l``:
    ``int F = h s l^2 f1(z)/z`` and ``int (l/2-d) F = h s l^3 f2(z)/z``. No division by ``n``:
    exact also at zero slip.
    """
    s = np.asarray(s, dtype=float)
    spin = np.asarray(spin, dtype=float)
    n = np.hypot(law.Fk[0] * s[..., 0], law.Fk[1] * s[..., 1])[..., None, None]
    z = n * law.g * l                                      # (..., nb, 2)
    hs = law.h * s[..., None, :]
    I0 = hs * l * l * f1z(z)
    f0 = np.einsum("k,...kj->...j", law.sigma, I0)
    f1y = np.einsum("k,...k->...", law.sigma, hs[..., 1] * l**3 * f2z(z[..., 1]))
    zz = np.abs(spin)[..., None] * law.gz * l
    m0 = np.einsum("k,...k->...", law.sigz, law.hz * spin[..., None] * l * l * f1z(zz))
    return f0, f1y, m0


def stationary_rates(d, F, sx, sy0, phi, law: DahlLaw, l: float, frame_term: bool):
    """``dF/dd`` [N/m per m] of the force states along the stationary patch (MCPS eq. 14) with a linear lateral
    slip: the kernel :func:`stationary_linear` integrates.

    :func:`tirecli.models.mcps.law.rhs` per unit rolled distance (rate independence: the rates divided by
    ``r omega``) with the input ``(sx, sy0 + phi (l/2 - d), phi, phi if frame_term else 0)``; parity to 1e-12:
    tests/test_model_parity.py.

    Parameters
    ----------
    d : array_like, shape (P,)
        Distance from the leading edge [m].
    F : ndarray, shape (P, nb, 2)
        Force states per unit length [N/m].
    sx, sy0, phi : ndarray, shape (P,)
        Slip ``du_x/(r omega)`` [-], lateral slip at the centre [-] and ``Omega_s/(r omega)`` [1/m]
        (:func:`stationary_linear`).
    law : DahlLaw
        The law per unit patch length.
    l : float
        Patch length [m].
    frame_term : bool
        Include the frame rotation.
    """
    syd = sy0 + phi * (l / 2.0 - d)
    s = np.stack([sx, syd], axis=-1)                  # (P, 2)
    n = np.hypot(law.Fk[0] * sx, law.Fk[1] * syd)[:, None, None]
    dF = law.h * s[:, None, :] - n * law.g * F
    if frame_term:
        w = phi[:, None]
        dF = dF + np.stack([w * F[..., 1], -w * F[..., 0]], axis=-1)
    return dF


def stationary_linear(sx, sy0, phi, law: DahlLaw, l: float, frame_term: bool = False, steps: int | None = None):
    """Patch integrals of the stationary states when the lateral slip varies linearly along the patch
    (a yaw rate: MCPS eq. 14 with ``du_y(xi) = du_y(0) + Omega xi``).

    Parameters
    ----------
    sx : array_like, shape (P,)
        Longitudinal slider velocity over ``r omega`` [-] (uniform).
    sy0 : array_like, shape (P,)
        Lateral slider velocity at the patch centre over ``r omega`` [-].
    phi : array_like, shape (P,)
        ``Omega_s/(r omega)`` [1/m]: the lateral slip is ``sy0 + phi xi``; also the spin of the
        torsion and, with ``frame_term``, the rotation rate of the slider frame per unit rolled distance.
    law : DahlLaw
        The law per unit patch length (:meth:`MCPSParams.patch_law`).
    l : float
        Patch length [m].
    frame_term : bool
        Include the frame rotation (docs/models/mcps_tire.md §4).
    steps : int or None
        RK4 steps [-] on each side of the zero of the lateral slip (default: from the stiffness, at
        least 64).

    Returns
    -------
    f0, f1y, m0 : as :func:`stationary_uniform`.

    Notes
    -----
    Integrated in ``d`` with the augmented state ``(F, int F, int (l/2-d) F)``, split where the
    lateral slip vanishes (kink of ``|F_k s|``); the torsion is uniform and exact. The right-hand side
    is :func:`stationary_rates`.
    """
    sx, sy0, phi = (np.atleast_1d(np.asarray(a, dtype=float)) for a in (sx, sy0, phi))
    P = sx.shape[0]
    # zero of the lateral slip: sy0 + phi (l/2 - d) = 0 -> d0 = l/2 + sy0/phi
    with np.errstate(divide="ignore", invalid="ignore"):
        d0 = np.where(phi != 0, l / 2.0 + sy0 / np.where(phi != 0, phi, 1.0), l)
    d0 = np.clip(np.nan_to_num(d0, nan=l), 0.0, l)
    smax = np.hypot(law.Fk[0] * np.abs(sx), law.Fk[1] * (np.abs(sy0) + np.abs(phi) * l / 2.0))
    zmax = float(np.max(smax) * np.max(law.g) * l) if P else 0.0
    if steps is None:
        steps = int(min(4000, max(64, math.ceil(zmax / 0.05))))

    def rhs(d, F):
        return stationary_rates(d, F, sx, sy0, phi, law, l, frame_term)

    F = np.zeros((P, law.nb, 2))
    I0 = np.zeros_like(F)
    I1 = np.zeros_like(F)
    for a, b in ((np.zeros(P), d0), (d0, np.full(P, l))):
        L = (b - a)[:, None, None]
        hstep = L / steps
        for i in range(steps):
            d = a + (b - a) * (i / steps)
            dm = a + (b - a) * ((i + 0.5) / steps)
            de = a + (b - a) * ((i + 1.0) / steps)
            arm = lambda dd: (l / 2.0 - dd)[:, None, None]  # noqa: E731
            k1 = rhs(d, F)
            F2 = F + 0.5 * hstep * k1
            k2 = rhs(dm, F2)
            F3 = F + 0.5 * hstep * k2
            k3 = rhs(dm, F3)
            F4 = F + hstep * k3
            k4 = rhs(de, F4)
            I0 = I0 + hstep / 6.0 * (F + 2.0 * F2 + 2.0 * F3 + F4)
            I1 = I1 + hstep / 6.0 * (arm(d) * F + 2.0 * arm(dm) * (F2 + F3) + arm(de) * F4)
            F = F + hstep / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    f0 = np.einsum("k,pkj->pj", law.sigma, I0)
    f1y = np.einsum("k,pk->p", law.sigma, I1[..., 1])
    zz = np.abs(phi)[:, None] * law.gz * l
    m0 = np.einsum("k,pk->p", law.sigz, law.hz * phi[:, None] * l * l * f1z(zz))
    return f0, f1y, m0


def resultants(f0, f1y, m0, c_Mz: float):
    """Road-on-tire resultants about the patch centre from the patch integrals (MCPS eq. 10):
    ``Fx, Fy = -int f`` [N], ``Mz = -(int m + c_Mz int xi f_y)`` [N m].

    Parameters
    ----------
    f0 : array_like, shape (..., 2)
        ``int f dd`` [N] (:func:`stationary_uniform`).
    f1y : array_like
        ``int (l/2 - d) f_y dd`` [N m].
    m0 : array_like
        ``int m dd`` [N m].
    c_Mz : float
        Weight of the lever-arm torque [-].
    """
    f0 = np.asarray(f0)
    return -f0[..., 0], -f0[..., 1], -(np.asarray(m0) + c_Mz * np.asarray(f1y))


def belt_velocities(Vx, Vy, romega, yaw, q, qdot):
    """Slider velocities of the complete model in the belt frame R_A (docs/models/mcps_tire.md §7, own convention).

    Parameters
    ----------
    Vx, Vy : array_like
        Rim (wheel-centre) velocity in R_W [m/s].
    romega : array_like
        Transport speed ``r omega`` [m/s].
    yaw : array_like
        Rim yaw rate ``psi_dot`` [rad/s].
    q : array_like, shape (..., 3)
        Belt displacement ``(x, y, delta)`` relative to the rim [m, m, rad] (zeros: solid carcass).
    qdot : array_like, shape (..., 3)
        Its rates [m/s, m/s, rad/s].

    Returns
    -------
    ux : ndarray
        Longitudinal slider velocity [m/s]: ``a cos delta + b sin delta - r omega`` with
        ``a = Vx + xdot - yaw y``, ``b = Vy + ydot + yaw x``.
    uy0 : ndarray
        Lateral slider velocity at the belt centre [m/s]: ``-a sin delta + b cos delta``;
        at abscissa ``xi`` it is ``uy0 + Omega xi``.
    Omega : ndarray
        Rotation rate of the slider frame and spin of the sliders [rad/s]: ``yaw + delta_dot``.
    """
    q = np.asarray(q, dtype=float)
    qdot = np.asarray(qdot, dtype=float)
    x, y, de = q[..., 0], q[..., 1], q[..., 2]
    a = Vx + qdot[..., 0] - yaw * y
    b = Vy + qdot[..., 1] + yaw * x
    c, s = np.cos(de), np.sin(de)
    return a * c + b * s - romega, -a * s + b * c, yaw + qdot[..., 2]


def wheel_forces(FA, MA, q):
    """Patch resultants in the belt frame to the rim frame R_W (MCPS eq. 16, first-order rotation):
    ``FWx = FAx - delta FAy``, ``FWy = FAy + delta FAx``, ``MW = MA + x FAy - y FAx`` (about the rim
    centre) [N, N, N m].

    Parameters
    ----------
    FA : array_like, shape (..., 2)
        Road-on-tire force in R_A [N].
    MA : array_like
        Road-on-tire torque about the belt centre [N m].
    q : array_like, shape (..., 3)
        ``(x, y, delta)`` [m, m, rad].
    """
    FA = np.asarray(FA, dtype=float)
    q = np.asarray(q, dtype=float)
    x, y, de = q[..., 0], q[..., 1], q[..., 2]
    fx, fy = FA[..., 0], FA[..., 1]
    return fx - de * fy, fy + de * fx, MA + x * fy - y * fx


def pure_longitudinal_fx(kappa, p, fz):
    """Closed-form stationary ``Fx`` [N] of pure longitudinal slip (docs/models/mcps_tire.md §6; the same with and
    without the carcass): ``sgn(kappa) mu_x Fz [1 + (alpha_x-1)(1-e^{-bP})/(bP) - alpha_x (1-e^{-aP})/(aP)]``
    with ``P = l |kappa|/(1+kappa)`` and ``a``, ``b`` of the 1-D path response (per-length constants).

    Parameters
    ----------
    kappa : array_like
        Longitudinal slip (ISO-W) [-], > -1.
    p : MCPSParams
    fz : float
        Load [N].
    """
    kappa = np.asarray(kappa, dtype=float)
    pa = p.patch(fz)
    a, b = path_rates(p.alpha_x, p.beta_x, pa.w * p.r_x, p.mu_x * pa.P * pa.w)
    P = pa.l * np.abs(kappa) / (1.0 + kappa)

    def mean_exp(c):  # (1 - e^{-cP})/(cP), 1 at P = 0
        x = c * P
        xs = np.where(x > 0, x, 1.0)
        return np.where(x > 0, -np.expm1(-xs) / xs, 1.0)

    return np.sign(kappa) * p.mu_x * fz * (1.0 + (p.alpha_x - 1.0) * mean_exp(b) - p.alpha_x * mean_exp(a))


__all__ = ["f1z", "f2z", "stationary_uniform", "stationary_linear", "resultants", "belt_velocities",
           "wheel_forces", "stationary_rates", "pure_longitudinal_fx"]
