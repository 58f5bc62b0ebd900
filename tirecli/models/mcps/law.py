"""Friction laws of the MCPS tire model: anisotropic Coulomb and Dahl-type differential laws.

Sorine & Szymanski, *A New Dynamic Multi-D.O.F. Tire-Model* (IFAC CTS 2000) [MCPS], eqs. (1)-(9);
tirecli's documentation: ``docs/models/mcps_tire.md`` §2-§4. Pure functions on numpy arrays, SI units.

Sign convention (stated once for the MCPS package): the friction operator's output ``f`` [N]
(``m`` [N m]) is what a slider transmits **to the road**, so ``f . du >= 0`` in steady sliding,
where ``du`` is the velocity [m/s] (or, for the exact steps, the displacement [m]) of the slider
base relative to the road, in slider-frame components. The road's reaction on the tire is
``-f``, ``-m``; the tire forces of :mod:`tirecli.models.mcps.tire` are road on tire (ISO-W).

**Model shape** (python-control): :func:`rhs` and :func:`outputs` with the state
``x = (F^1_x, F^1_y, .., M^1, ..)`` [N, N m] (:func:`split_state`), the input
``u = (du_x, du_y, dpsi, omega)`` (:class:`LawInput`) and the parameters ``p`` a :class:`DahlLaw`; the
kernels (:func:`step`, :mod:`tirecli.numerics.mcps_transient`) keep the states as ``F (..., nb, 2)``,
``M (..., nbz)`` and :func:`output`.

A *law* holds, per branch ``k`` of the state and per component ``j`` (x, y):

    dF^k_j/dt = h^k_j du_j - |F_k du| g^k_j F^k_j  (- Omega_s (Omega_2 F^k)_j with the frame term)
    f = sum_k sigma_k F^k

- first order (MCPS eq. 4, the 2-D Dahl model): one branch, ``h = K``, ``g = K / F_k^2``;
- second order with overshoot (MCPS eqs. 5-6): two branches, ``h^1 = beta K``,
  ``g^1 = beta K / (alpha F_k^2)``, ``h^2 = (beta - 1) K``, ``g^2 = (beta - 1) K / ((alpha - 1) F_k^2)``,
  ``sigma = (+1, -1)``. With ``alpha = beta`` it reduces exactly to the first-order law.

The torsion (MCPS eqs. 7-8) is an uncoupled 1-D law of the same type in the slider spin
``dpsi_s`` [rad/s] with ``S_z``, ``M_kz``, ``alpha_z``, ``beta_z``.

For inputs that are constant over a step (straight displacement increment, constant frame rate)
the equations are linear with constant coefficients and :func:`step` solves them **exactly**
(2 x 2 matrix exponential in closed form). Every right-hand side is homogeneous of degree 1 in
the rates (rate independence), so a step depends on the increments only, never on the time.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class DahlLaw:
    """A Dahl-type friction law (first or second order) with its torsional part.

    Attributes
    ----------
    h : ndarray, shape (nb, 2)
        Input gains per branch and component [N/m] (per unit patch length: [N/m^2]).
    g : ndarray, shape (nb, 2)
        Relaxation gains per branch and component: ``g = h / (level * F_k)`` [1/(N m)]
        (per length: [1/N]); the sliding measure ``|F_k du|`` multiplies them.
    sigma : ndarray, shape (nb,)
        Output weights (``f = sum sigma_k F^k``): ``(1,)`` first order, ``(1, -1)`` second order.
    Fk : ndarray, shape (2,)
        Coulomb levels along x and y [N] (per length [N/m]), MCPS eq. (2).
    hz, gz, sigz : ndarray, shape (nbz,)
        The torsional branches: gains [N m/rad], relaxation gains [1/rad] (the measure is ``|dpsi|``), weights.
    Mkz : float
        Torsional sliding torque [N m] (per length [N m/m]), MCPS eq. (8).
    """

    h: np.ndarray
    g: np.ndarray
    sigma: np.ndarray
    Fk: np.ndarray
    hz: np.ndarray
    gz: np.ndarray
    sigz: np.ndarray
    Mkz: float

    @property
    def nb(self) -> int:
        return len(self.sigma)

    @property
    def nbz(self) -> int:
        return len(self.sigz)

    @property
    def K(self) -> np.ndarray:
        """Small-deformation stiffness ``sum sigma_k h^k`` [N/m] (from rest ``df = K du``)."""
        return np.einsum("k,kj->j", self.sigma, self.h)

    @property
    def Sz(self) -> float:
        """Small-rotation torsional stiffness [N m/rad]."""
        return float(np.dot(self.sigz, self.hz))


def _branches(K, F, alpha, beta, per_level=True):
    """``(h, g, sigma)`` of the second-order law (MCPS eqs. 5-8) for stiffness ``K``, level ``F``,
    overshoot factors ``alpha``, ``beta`` (arrays over the components, all > 1).

    For forces the relaxation measure ``|F_k du|`` carries one factor ``F_k``, so
    ``g = beta K/(alpha F_k^2)`` (eq. 5); for the torsion it is ``|dpsi|`` and
    ``g = beta S_z/(alpha M_kz)`` (eq. 7) (``per_level=False``).
    """
    K, F, alpha, beta = (np.atleast_1d(np.asarray(x, dtype=float)) for x in (K, F, alpha, beta))
    lev = F * F if per_level else F
    h = np.stack([beta * K, (beta - 1.0) * K])
    g = np.stack([beta * K / (alpha * lev), (beta - 1.0) * K / ((alpha - 1.0) * lev)])
    return h, g, np.array([1.0, -1.0])


def second_order(K, Fk, alpha, beta, Sz, Mkz, alpha_z, beta_z) -> DahlLaw:
    """The second-order law with overshoot (MCPS eqs. 5-6) and its torsion (eqs. 7-8).

    Parameters
    ----------
    K : array_like, shape (2,)
        Small-deformation stiffness along x, y [N/m] (per length [N/m^2]).
    Fk : array_like, shape (2,)
        Coulomb levels along x, y [N] (per length [N/m]).
    alpha, beta : array_like, shape (2,)
        Overshoot factors along x, y [-], each > 1 (overshoot iff alpha > beta).
    Sz : float
        Torsional stiffness [N m/rad] (per length [N m/(rad m)]).
    Mkz : float
        Torsional sliding torque [N m] (per length [N m/m]).
    alpha_z, beta_z : float
        Torsional overshoot factors [-], > 1.
    """
    h, g, sig = _branches(K, Fk, alpha, beta)
    hz, gz, sigz = _branches(Sz, Mkz, alpha_z, beta_z, per_level=False)
    return DahlLaw(h=h, g=g, sigma=sig, Fk=np.asarray(Fk, dtype=float), hz=hz[:, 0], gz=gz[:, 0],
                   sigz=sigz, Mkz=float(Mkz))


def first_order(K, Fk, Sz, Mkz) -> DahlLaw:
    """The first-order 2-D Dahl law (MCPS eq. 4): ``K^-1 df/dt + |F_k du| F_k^-2 f = du``, with a
    first-order torsion of the same type (``S_z^-1 dm/dt + |dpsi| M_kz^-1 m = dpsi``).

    Parameters
    ----------
    K : array_like, shape (2,)
        Small-deformation stiffness along x, y [N/m] (per length [N/m^2]).
    Fk : array_like, shape (2,)
        Coulomb levels along x, y [N] (per length [N/m]).
    Sz : float
        Torsional stiffness [N m/rad] (per length [N m/(rad m)]).
    Mkz : float
        Torsional sliding torque [N m] (per length [N m/m]).
    """
    K = np.asarray(K, dtype=float)
    Fk = np.asarray(Fk, dtype=float)
    return DahlLaw(h=K[None, :], g=(K / Fk**2)[None, :], sigma=np.array([1.0]), Fk=Fk,
                   hz=np.array([float(Sz)]), gz=np.array([float(Sz) / float(Mkz)]),
                   sigz=np.array([1.0]), Mkz=float(Mkz))


def coulomb(du, Fk):
    """Anisotropic Coulomb friction force [N] for a sliding velocity ``du`` [m/s] (MCPS eq. 2).

    ``f = F_k^2 du / |F_k du|`` (maximal dissipation on the ellipse ``|F_k^-1 f| <= 1``); not
    collinear with ``du`` unless ``du`` is along a principal axis or ``F_k`` is isotropic. At
    ``du = 0`` the force is set-valued; this returns 0 there.

    Parameters
    ----------
    du : array_like, shape (..., 2)
        Sliding velocity of the slider relative to the road [m/s].
    Fk : array_like, shape (2,)
        Friction levels along x and y [N].
    """
    du = np.asarray(du, dtype=float)
    Fk = np.asarray(Fk, dtype=float)
    n = np.hypot(Fk[0] * du[..., 0], Fk[1] * du[..., 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(n[..., None] > 0, Fk**2 * du / n[..., None], 0.0)
    return out


def output(F, M, law: DahlLaw):
    """Friction force ``f`` [N] (shape ``(..., 2)``) and torque ``m`` [N m]: ``f = C_xy F``, ``m = C_z M`` (MCPS eqs. 5, 7).

    :func:`outputs` in the kernels' layout of the states (:func:`split_state`).

    Parameters
    ----------
    F : array_like, shape (..., nb, 2)
        Force states [N].
    M : array_like, shape (..., nbz)
        Torque states [N m].
    law : DahlLaw
        The friction law (gains, levels; per unit patch length for a patch).
    """
    f = np.einsum("k,...kj->...j", law.sigma, F)
    m = np.einsum("k,...k->...", law.sigz, M)
    return f, m


def sliding_measure(du, Fk):
    """``|F_k du|`` [N m/s] (or [N m] for a displacement), the rate that drives relaxation (MCPS eqs. 4-9).

    Parameters
    ----------
    du : array_like, shape (..., 2)
        Slider base velocity relative to the road [m/s] (or displacement [m]).
    Fk : array_like, shape (2,)
        Coulomb levels along x, y [N].
    """
    du = np.asarray(du, dtype=float)
    return np.hypot(Fk[0] * du[..., 0], Fk[1] * du[..., 1])


class LawInput(NamedTuple):
    """Input of a friction law (:func:`rhs`).

    Attributes
    ----------
    du_x, du_y : array_like
        Velocity of the slider base relative to the road, slider-frame components [m/s] (for the exact
        :func:`step`: the displacement over the step [m]).
    dpsi : array_like
        Slider spin [rad/s] (drives the torsion).
    omega : array_like
        Rotation rate of the slider frame relative to the road [rad/s]: the frame term
        ``-Omega_s Omega_hat F`` (docs/models/mcps_tire.md §4); 0 leaves it out.
    """

    du_x: object
    du_y: object
    dpsi: object
    omega: object = 0.0


def split_state(x, law: DahlLaw):
    """The law's state ``x`` in the layout of the kernels (MCPS eq. 9's states ``F^k``, ``M^k``).

    ``x`` (shape ``(2 nb + nbz, ...)``: ``F^1_x, F^1_y, .., F^nb_x, F^nb_y, M^1 .. M^nbz``) becomes ``F`` [N],
    shape ``(..., nb, 2)``, and ``M`` [N m], shape ``(..., nbz)``.

    Parameters
    ----------
    x : array_like, shape (2 nb + nbz, ...)
        Force states [N] then torque states [N m].
    law : DahlLaw
        The friction law (gains, levels; per unit patch length for a patch).
    """
    x = np.asarray(x, dtype=float)
    nb = law.nb
    F = np.moveaxis(x[:2 * nb].reshape((nb, 2) + x.shape[1:]), (0, 1), (-2, -1))
    return F, np.moveaxis(x[2 * nb:], 0, -1)


def join_state(F, M) -> np.ndarray:
    """The inverse of :func:`split_state`: ``x`` of shape ``(2 nb + nbz, ...)`` (MCPS eq. 9's states).

    Parameters
    ----------
    F : array_like, shape (..., nb, 2)
        Force states [N].
    M : array_like, shape (..., nbz)
        Torque states [N m].
    """
    F, M = np.asarray(F, dtype=float), np.asarray(M, dtype=float)
    lead = F.shape[:-2]
    return np.concatenate([np.moveaxis(F, (-2, -1), (0, 1)).reshape((-1,) + lead), np.moveaxis(M, -1, 0)])


def rhs(t, x, u, p: DahlLaw):
    """Time derivative of the law's states (MCPS eq. 9 with the frame-rotation term; module doc).

    ``dF^k/dt = h^k du - |F_k du| g^k F^k - Omega_s (F^k_y, -F^k_x)`` per branch ``k`` (components
    x, y), ``dM^k/dt = h_z^k dpsi - |dpsi| g_z^k M^k``. Rate independent: homogeneous of degree 1 in ``u``.

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (2 nb + nbz, ...)
        Force states [N] then torque states [N m] (:func:`split_state`).
    u : sequence
        ``(du_x [m/s], du_y [m/s], dpsi [rad/s], omega [rad/s])`` (:class:`LawInput`).
    p : DahlLaw

    Returns
    -------
    ndarray, shape (2 nb + nbz, ...)
        ``dF/dt`` [N/s] and ``dM/dt`` [N m/s] in the layout of ``x``.
    """
    F, M = split_state(x, p)
    du = np.stack(np.broadcast_arrays(np.asarray(u[0], dtype=float), np.asarray(u[1], dtype=float)), axis=-1)
    n = sliding_measure(du, p.Fk)[..., None, None]
    dF = p.h * du[..., None, :] - n * p.g * F
    w = np.asarray(u[3], dtype=float)
    if np.any(w != 0.0):
        w = w[..., None]
        dF = dF + np.stack([w * F[..., 1], -w * F[..., 0]], axis=-1)
    dpsi = np.asarray(u[2], dtype=float)[..., None]
    dM = p.hz * dpsi - np.abs(dpsi) * p.gz * M
    return join_state(dF, dM)


def outputs(t, x, u, p: DahlLaw) -> dict:
    """Friction the slider transmits to the road at state ``x`` (arguments as :func:`rhs`; MCPS eqs. 5, 7).

    Returns
    -------
    dict
        ``f_x``, ``f_y`` [N]: ``f = sum_k sigma_k F^k``; ``m`` [N m]: ``sum_k sigma_z^k M^k``.
    """
    f, m = output(*split_state(x, p), p)
    return {"f_x": f[..., 0], "f_y": f[..., 1], "m": m}


def _exp_factors(m, d, w):
    """``e^-m cosh(r)`` and ``e^-m sinh(r)/r`` with ``r^2 = d^2 - w^2`` (``cos``, ``sin(r)/r`` when
    negative), without overflow (``r <= m`` when real, since ``|d| <= m``) or cancellation."""
    D = d * d - w * w
    r = np.sqrt(np.abs(D))
    real = D > 0
    small = r < 1e-4
    rs = np.where(small, 1.0, r)
    em = np.exp(-m)
    ep = np.exp(np.minimum(r - m, 0.0))
    en = np.exp(-r - m)
    ch = np.where(real, 0.5 * (ep + en), em * np.cos(r))
    sh = np.where(small, em * (1.0 + D / 6.0 + D * D / 120.0),
                  np.where(real, 0.5 * (ep - en) / rs, em * np.sin(r) / rs))
    return ch, sh


def step(F, M, du, dpsi, dtheta, law: DahlLaw):
    """Exact update of the states over one step with constant rates (MCPS eq. 9, frame term given
    by its increment): the exact flow of :func:`rhs` over a unit time with the input
    ``(du_x, du_y, dpsi, dtheta)`` (rate independence), in the kernels' layout (:func:`split_state`).
    Parity with :func:`rhs` to 1e-12: tests/test_model_parity.py.

    Parameters
    ----------
    F : ndarray, shape (..., nb, 2)
        Force states at the start [N].
    M : ndarray, shape (..., nbz)
        Torque states at the start [N m].
    du : array_like, shape (..., 2)
        Displacement of the slider base relative to the road over the step, slider frame [m]
        (velocity times step); a straight segment.
    dpsi : array_like, shape (...)
        Slider rotation over the step [rad] (drives the torsion).
    dtheta : array_like, shape (...)
        Rotation of the slider frame relative to the road over the step [rad] (the frame term;
        0 switches it off).
    law : DahlLaw
        The friction law.

    Returns
    -------
    F, M : the states at the end of the step.

    Notes
    -----
    Per branch the force state obeys ``F' = b - A F`` over a unit step with ``b = h du`` and
    ``A = [[p, -w], [w, q]]`` (``p = n g_x``, ``q = n g_y``, ``n = |F_k du|``, ``w = dtheta``):
    ``F(1) = F* + exp(-A)(F - F*)``, ``F* = A^-1 b``, with the closed-form 2 x 2 exponential
    ``exp(-A) = e^-m (cosh r I - sinh(r)/r N)``, ``m = (p + q)/2``, ``N = A - m I``,
    ``r^2 = ((p - q)/2)^2 - w^2`` (cos/sin when negative). Exact for any step length; no stiffness
    limit.
    """
    du = np.asarray(du, dtype=float)
    dtheta = np.asarray(dtheta, dtype=float)
    dpsi = np.asarray(dpsi, dtype=float)
    n = sliding_measure(du, law.Fk)[..., None]                 # (..., 1)
    p = n * law.g[:, 0]                                        # (..., nb)
    q = n * law.g[:, 1]
    w = np.broadcast_to(dtheta[..., None], p.shape)
    bx = law.h[:, 0] * du[..., None, 0]
    by = law.h[:, 1] * du[..., None, 1]
    det = p * q + w * w
    moving = det > 0
    safe = np.where(moving, det, 1.0)
    sx = np.where(moving, (q * bx + w * by) / safe, 0.0)       # F* = A^-1 b
    sy = np.where(moving, (-w * bx + p * by) / safe, 0.0)
    ce, se = _exp_factors(0.5 * (p + q), 0.5 * (p - q), w)
    d = 0.5 * (p - q)
    ex = F[..., 0] - sx
    ey = F[..., 1] - sy
    # exp(-A) e = e^-m [c e - s N e], N = [[d, -w], [w, -d]]
    nx = ce * ex - se * (d * ex - w * ey)
    ny = ce * ey - se * (w * ex - d * ey)
    Fn = np.stack([np.where(moving, sx + nx, F[..., 0]), np.where(moving, sy + ny, F[..., 1])], axis=-1)
    a = np.abs(dpsi)[..., None]
    Ms = np.sign(dpsi)[..., None] * law.hz / law.gz
    Mn = np.where(a > 0, Ms + (M - Ms) * np.exp(-law.gz * a), M)
    return Fn, Mn


def path_rates(alpha, beta, K, Fk):
    """Decay rates [1/m] of the two branches along a monotone 1-D path (MCPS eqs. 5-6; docs/models/mcps_tire.md §3.2):
    ``a = beta K/(alpha F_k)``, ``b = (beta - 1) K/((alpha - 1) F_k)``.

    Parameters
    ----------
    alpha, beta : float or array_like
        Overshoot factors [-] (> 1).
    K : float or array_like
        Stiffness [N/m].
    Fk : float or array_like
        Coulomb level [N].
    """
    return beta * K / (alpha * Fk), (beta - 1.0) * K / ((alpha - 1.0) * Fk)


def path_response(p, alpha, beta, K, Fk):
    """1-D response of the second-order law, monotone from rest, as a fraction of ``F_k``
    (docs/models/mcps_tire.md §3.2): ``g(p) = 1 + (alpha - 1) e^{-b p} - alpha e^{-a p}``,
    ``a = beta K/(alpha F_k)``, ``b = (beta - 1) K/((alpha - 1) F_k)``.

    Parameters
    ----------
    p : array_like
        Path travelled since rest [m].
    alpha, beta : float
        Overshoot factors [-] (> 1).
    K : float
        Stiffness [N/m].
    Fk : float
        Coulomb level [N].
    """
    p = np.asarray(p, dtype=float)
    a, b = path_rates(alpha, beta, K, Fk)
    return 1.0 + (alpha - 1.0) * np.exp(-b * p) - alpha * np.exp(-a * p)


def overshoot_peak(alpha, beta, K=1.0, Fk=1.0):
    """Peak of :func:`path_response`: ``(p*, g(p*))`` with ``p* = ln(beta/(beta-1))/(a - b)`` [m]
    (MCPS eqs. 5-6; docs/models/mcps_tire.md §3.2); ``(inf, 1)`` when there is no overshoot (``alpha <= beta``).

    Parameters
    ----------
    alpha, beta : float
        Overshoot factors [-] (> 1).
    K : float
        Stiffness [N/m].
    Fk : float
        Coulomb level [N].
    """
    if alpha <= beta:
        return float("inf"), 1.0
    a, b = path_rates(alpha, beta, K, Fk)
    p = np.log(beta / (beta - 1.0)) / (a - b)
    return float(p), float(path_response(p, alpha, beta, K, Fk))


__all__ = ["DahlLaw", "LawInput", "second_order", "first_order", "coulomb", "rhs", "outputs", "output",
           "split_state", "join_state", "step", "sliding_measure", "path_rates", "path_response", "overshoot_peak"]
