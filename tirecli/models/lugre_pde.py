"""Distributed LuGre tire (FM eqs. (1)-(2)) solved exactly along characteristics.

PDE (docs/models/lugre_friction.md §3.1), ``zeta`` from the leading edge, ``u = zeta/L``::

    dz/dt + |r omega| dz/dzeta = vr - b(t) z,    b = sigma0 |vr| / (theta g(vr)),    z(0, t) = 0

The source ``vr - b z`` does not depend on ``zeta``: every tread element obeys the same linear ODE
and elements differ only by their entry time. With ``Y(t)`` the point-model solution from
``Y(0) = 0`` (``dY/dt = vr - b Y``), ``Phi(t) = int_0^t b`` and the travelled length
``X(t) = int_0^t |r omega|``, the element at ``zeta`` entered at ``tau`` with
``X(tau) = X(t) - zeta`` and (variation of constants)

    z(zeta, t) = Y(t) - exp(Phi(tau) - Phi(t)) Y(tau)        (tau clipped at 0, where Y = 0)

which also holds for the elements initially in the patch when ``z(zeta, 0) = 0`` (the default and
only supported initial state). The force (FM eq. (2)) needs load-weighted integrals of ``z`` and
``dz/dt``. Weighting the PDE by ``phi(u)`` and integrating by parts over ``[0, u_i]``::

    d/dt int_0^{u_i} phi z du = (int_0^{u_i} phi) vr - b (...) - (|r omega|/L) [phi(u_i) z(u_i, t) - int_0^{u_i} phi' z du]

closes exactly for ``phi`` = powers of ``u`` (``phi' = k u^(k-1)``) and ``phi = e^(-lambda u)``
(``phi' = -lambda phi``). So every load of :mod:`tirecli.models.variants` — uniform, exponential,
parabolic and piecewise-linear tabulated — reduces *exactly* to a few ODE states (:class:`PatchReduction`)
driven by the deflections ``z(u_i, t)`` at a few tracked points, which come from the stored history
of ``(X, Phi, Y)``. No spatial grid: the only discretisation is the time step (the characteristics'
spacing) and the history interpolation, both second order. Uniform load: one state (the mean
deflection, FM eq. (7)) and one tracked point (the trailing edge): ``dzbar/dt = vr - b zbar -
(|r omega|/L) z(L, t)``, the lumped model (8) with the exact trailing-edge term in place of
``kappa |r omega| zbar``.

**Model shape** (python-control, pure, vectorized with the state axis first): :func:`rhs` and
:func:`outputs` of :class:`DistributedTire` with the state ``x = (Y, Phi, X, S_0 .. S_{K-1})``, the input
``u = (vr, r omega, theta, z_points)`` (:class:`DistributedInput`; ``z_points`` from the history, see
there) and the outputs ``mu``, ``zbar``, ``zdot``, ``z_trailing``, ``kappa0``. Fast kernels that inline
it: :class:`tirecli.numerics.characteristics.CharacteristicsStepper` (quarter car) and
:class:`tirecli.numerics.driven.GridModel` (prescribed kinematics); parity: tests/test_model_parity.py.

:func:`upwind_steady_mu` is the first-order upwind discretisation of docs/models/lugre_friction.md §3.3, kept as
a reference for the convergence figures.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from tirecli.models.lugre import LuGreParams, mu_of_deflection, stribeck


@dataclass(frozen=True)
class PatchReduction:
    """Exact finite set of patch integrals for one normal-load density (module doc).

    States ``S_j = int_0^{u_{p_j}} phi_j(u) z(u, t) du`` [m] obey::

        dS/dt = A vr - b S - (|r omega|/L) (Bc * z(points)[p] - D @ S)

    Attributes
    ----------
    points : ndarray
        Tracked positions ``u_i = zeta_i/L`` in ``(0, 1]`` (always contains 1, the trailing edge).
    p : ndarray of int
        Index into ``points`` for each state.
    A : ndarray
        ``int_0^{u_p} phi_j du`` [-].
    Bc : ndarray
        ``phi_j(u_p)`` [-].
    D : ndarray
        ``phi_j' = sum_l D_jl phi_l`` on the state's interval (``K x K``).
    w : ndarray
        Force weights: load-weighted mean deflection ``zbar_w = int w z du = w @ S`` [m] for the
        density ``w`` per unit ``u`` normalised to unit mass (``f_n = F_n w / L``).
    uniform : bool
        True for the uniform load (then ``S = [zbar]``).
    """

    points: np.ndarray
    p: np.ndarray
    A: np.ndarray
    Bc: np.ndarray
    D: np.ndarray
    w: np.ndarray
    uniform: bool = False

    @property
    def size(self) -> int:
        return len(self.A)


def _powers(points, orders) -> tuple:
    """States ``int_0^{u_i} u^k z du`` for each point and each order ``k`` in ``orders``."""
    idx = {}
    p, A, Bc = [], [], []
    for i, ui in enumerate(points):
        for k in orders:
            idx[(i, k)] = len(p)
            p.append(i)
            A.append(ui ** (k + 1) / (k + 1))
            Bc.append(ui ** k)
    D = np.zeros((len(p), len(p)))
    for (i, k), j in idx.items():
        if k > 0:
            D[j, idx[(i, k - 1)]] = k  # d/du u^k = k u^(k-1)
    return idx, np.array(p), np.array(A, dtype=float), np.array(Bc, dtype=float), D


def patch_reduction(load: str, lam: float = 0.0, u=None, f=None) -> PatchReduction:
    """The :class:`PatchReduction` of a normal-load density (FM eqs. (1)-(3), (5); docs/models/lugre_friction.md §3.2).

    Parameters
    ----------
    load : str
        ``uniform`` (FM eq. (3)), ``exponential`` (FM eq. (5), decay ``lam``), ``parabolic``
        (``6 u (1 - u)``) or ``tabulated`` (samples ``f`` at positions ``u = zeta/L``, linear in
        between, zero outside, normalised to unit mass).
    lam : float
        Exponential load decay ``lambda`` [-] (below 1e-9: the uniform load).
    u : array_like or None
        Tabulated load: sample positions ``zeta/L`` [-], increasing.
    f : array_like or None
        Tabulated load: the density at them [any unit: normalised].
    """
    one = np.array([1.0])
    if load == "uniform" or (load == "exponential" and lam < 1e-9):
        return PatchReduction(one, np.array([0]), one.copy(), one.copy(), np.zeros((1, 1)), one.copy(), uniform=True)
    if load == "exponential":
        A = -np.expm1(-lam) / lam
        return PatchReduction(one, np.array([0]), np.array([A]), np.array([np.exp(-lam)]),
                              np.array([[-lam]]), np.array([1.0 / A]))
    if load == "parabolic":
        _, p, A, Bc, D = _powers([1.0], (0, 1, 2))
        return PatchReduction(one, p, A, Bc, D, np.array([0.0, 6.0, -6.0]))
    if load == "tabulated":
        us = np.asarray(u, dtype=float)
        fs = np.asarray(f, dtype=float)
        mass = np.trapezoid(fs, us)
        knots = np.union1d(np.clip(us, 0.0, 1.0), [0.0, 1.0])
        points = knots[knots > 0.0]
        idx, p, A, Bc, D = _powers(points, (0, 1))
        w = np.zeros(len(p))
        for a, b in zip(knots[:-1], knots[1:]):
            if b <= us[0] or a >= us[-1] or b <= a:
                continue  # zero density outside the samples
            fa, fb = np.interp([a, b], us, fs) / mass
            beta = (fb - fa) / (b - a)
            alpha = fa - beta * a
            ib = int(np.searchsorted(points, b))
            w[idx[(ib, 0)]] += alpha
            w[idx[(ib, 1)]] += beta
            if a > 0.0:
                ia = int(np.searchsorted(points, a))
                w[idx[(ia, 0)]] -= alpha
                w[idx[(ia, 1)]] -= beta
        return PatchReduction(points, p, A, Bc, D, w)
    raise ValueError(f"unknown load {load!r}")


@dataclass(frozen=True)
class DistributedTire:
    """Parameters of the distributed LuGre tire in its exact reduction (module doc).

    Attributes
    ----------
    params : LuGreParams
        Friction parameters (``sigma0`` [1/m], ``sigma1``, ``sigma2`` [s/m], ``mu_c``, ``mu_s`` [-],
        ``v_s`` [m/s], ``L`` [m], ``alpha`` [-]; ``sigma_w`` is the wheel's).
    red : PatchReduction
        The normal-load density's reduction (:func:`patch_reduction`; default uniform, FM eq. (3)).
    """

    params: LuGreParams
    red: PatchReduction = field(default_factory=lambda: patch_reduction("uniform"))


class DistributedInput(NamedTuple):
    """Input of the distributed tire (:func:`rhs`).

    Attributes
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s].
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    theta : array_like
        Road adhesion [-], FM convention (``g -> theta g``).
    z_points : array_like, shape (len(red.points), ...)
        Bristle deflections ``z(u_i L, t)`` [m] at the tracked points ``u_i = red.points`` (the last one
        the trailing edge). The characteristics give them from the *history* of ``(X, Phi, Y)``
        (:func:`deflection`): they are an input here because they depend on the state's past, not on
        its present value.
    """

    vr: object
    romega: object
    theta: object
    z_points: object


def _column(a, nd: int) -> np.ndarray:
    """A per-state vector as a column against ``nd`` trailing axes."""
    return np.asarray(a, dtype=float).reshape((-1,) + (1,) * nd)


def rhs(t, x, u, p: DistributedTire):
    """Right-hand side of the exact reduction of FM eq. (1) (module doc; docs/models/lugre_friction.md §3.1-3.2).

    ``dY/dt = vr - b Y``, ``dPhi/dt = b``, ``dX/dt = |r omega|`` and
    ``dS/dt = A vr - b S - (|r omega|/L) (Bc z(points)[p] - D S)`` with ``b = sigma0 |vr| / (theta g(vr))``.

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (3 + K, ...)
        State ``(Y [m], Phi [-], X [m], S_0 .. S_{K-1} [m])``: the point-model deflection from rest, the
        integrated bristle rate ``int b dt``, the travelled length ``int |r omega| dt`` and the patch
        integrals of :class:`PatchReduction` (``K = p.red.size``).
    u : sequence
        ``(vr [m/s], romega [m/s], theta [-], z_points [m])`` (:class:`DistributedInput`).
    p : DistributedTire

    Returns
    -------
    ndarray, shape (3 + K, ...)
        ``(dY/dt [m/s], b [1/s], |r omega| [m/s], dS/dt [m/s])``.
    """
    tire, red = p.params, p.red
    x = np.asarray(x, dtype=float)
    vr = np.asarray(u[0], dtype=float)
    c = np.abs(np.asarray(u[1], dtype=float))
    zp = np.asarray(u[3], dtype=float)
    shape = np.broadcast_shapes(x.shape[1:], vr.shape, c.shape, np.shape(u[2]), zp.shape[1:])
    nd = len(shape)
    Y, S = x[0], x[3:]
    b = tire.sigma0 * np.abs(vr) / stribeck(vr, tire, u[2])
    trans = _column(red.Bc, nd) * zp[red.p] - np.tensordot(red.D, S, axes=1)
    dS = _column(red.A, nd) * vr - b * S - (c / tire.L) * trans
    return np.concatenate([np.broadcast_to(a, shape)[None] for a in (vr - b * Y, b, c)]
                          + [np.broadcast_to(dS, (red.size,) + shape)])


def friction(x, dx, u, p: DistributedTire):
    """Normalised friction ``mu = sigma0 zbar + sigma1 dzbar/dt + sigma2 vr`` [-] (FM eq. (2)).

    ``zbar = w . S`` is the load-weighted mean deflection [m]. What a coupled model
    (:mod:`tirecli.models.quarter_car`) needs from the tire without evaluating :func:`rhs` twice.

    Parameters
    ----------
    x : array_like, shape (3 + K, ...)
        State ``(Y [m], Phi [-], X [m], S_0 .. S_{K-1} [m])``.
    dx : array_like, shape (3 + K, ...)
        Its rate (:func:`rhs`) [m/s, 1/s, m/s, m/s].
    u : sequence
        ``(vr [m/s], romega [m/s], theta [-], z_points [m])`` (:class:`DistributedInput`).
    p : DistributedTire
    """
    w, dx = p.red.w, np.asarray(dx, dtype=float)
    x = np.broadcast_to(np.asarray(x, dtype=float), dx.shape)
    return mu_of_deflection(np.tensordot(w, x[3:], axes=1), np.tensordot(w, dx[3:], axes=1), u[0], p.params)


def outputs(t, x, u, p: DistributedTire) -> dict:
    """Outputs of the distributed tire at state ``x`` and input ``u`` (arguments as :func:`rhs`).

    Returns
    -------
    dict
        ``mu`` [-]: normalised friction (FM eq. (2)); ``zbar`` [m]: load-weighted mean deflection
        ``w . S``; ``zdot`` [m/s]: its rate; ``z_trailing`` [m]: the deflection at the trailing edge;
        ``kappa0`` [-]: the equivalent lumped coefficient ``z_trailing / zbar`` (uniform load: FM eq. (8)
        with the exact trailing-edge term, module doc), NaN for other loads or ``zbar = 0``.
    """
    dx = rhs(t, x, u, p)
    w = p.red.w
    zbar = np.tensordot(w, np.broadcast_to(np.asarray(x, dtype=float), dx.shape)[3:], axes=1)
    zdot = np.tensordot(w, dx[3:], axes=1)
    zt = np.broadcast_to(np.asarray(u[3], dtype=float)[-1], zbar.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        k0 = np.where((zbar != 0.0) & p.red.uniform, zt / np.where(zbar != 0.0, zbar, 1.0), np.nan)
    return {"mu": mu_of_deflection(zbar, zdot, u[0], p.params), "zbar": zbar, "zdot": zdot, "z_trailing": zt,
            "kappa0": k0}


def deflection(zeta, Y_now, Phi_now, X_now, hist_t, hist_X, hist_Phi, hist_Y):
    """Bristle deflection ``z(zeta, t)`` [m] along the patch from the characteristic history (FM eq. (1)).

    ``z = Y(t) - exp(Phi(tau) - Phi(t)) Y(tau)`` with ``X(tau) = X(t) - zeta`` (module doc);
    history arrays are the values at earlier times (``hist_X`` nondecreasing), interpolated
    linearly. Used for profile plots; the solver uses a higher-order version.

    Parameters
    ----------
    zeta : array_like
        Distance from the leading edge [m], in ``[0, L]``.
    Y_now, Phi_now, X_now : float
        The reduced state now: point-model deflection [m], ``int b dt`` [-], travelled length [m].
    hist_t : array_like
        Earlier times [s] (unused by the interpolation in ``X``; kept with the history).
    hist_X, hist_Phi, hist_Y : array_like
        ``X`` [m], ``Phi`` [-] and ``Y`` [m] at those times.
    """
    zeta = np.asarray(zeta, dtype=float)
    target = X_now - zeta
    Xh = np.append(hist_X, X_now)
    tau_phi = np.interp(target, Xh, np.append(hist_Phi, Phi_now))
    tau_Y = np.interp(target, Xh, np.append(hist_Y, Y_now))
    inside = target > 0.0
    return np.where(inside, Y_now - np.exp(tau_phi - Phi_now) * tau_Y, Y_now)


def upwind_steady_mu(vr: float, romega: float, p: LuGreParams, cells: int, theta: float = 1.0) -> float:
    """Steady ``mu`` [-] of the first-order upwind discretisation of FM eq. (1), uniform load, ``cells`` cells.

    Cell values ``z_j`` (cell centres are not used: the upwind value is the cell's outflow value)
    solve ``|r omega| (z_j - z_{j-1})/dzeta = vr - b z_j``, ``z_0 = 0``; the force (FM eq. (2))
    is their mean, ``mu = sigma0 mean(z) + sigma2 vr``. Converges to FM eq. (4) at first order
    (docs/models/lugre_friction.md §3.3).

    Parameters
    ----------
    vr : float
        Relative velocity ``r omega - v`` [m/s].
    romega : float
        Wheel circumferential speed ``r omega`` [m/s].
    p : LuGreParams
        Tire parameters, SI units (:class:`~tirecli.models.lugre.LuGreParams`).
    cells : int
        Number of cells over the patch [-].
    theta : float
        Road adhesion [-], FM convention.
    """
    b = p.sigma0 * abs(vr) / float(stribeck(vr, p, theta))
    c = abs(romega)
    dz = p.L / cells
    if c == 0.0:
        zs = vr / b if b > 0 else 0.0
        return p.sigma0 * zs + p.sigma2 * vr
    rho = (c / dz) / (c / dz + b)        # z_j = rho z_{j-1} + (1 - rho) z_ss
    zss = vr / b if b > 0 else 0.0
    j = np.arange(1, cells + 1)
    z = zss * (1.0 - rho ** j)
    return float(p.sigma0 * z.mean() + p.sigma2 * vr)


def uniform_step_response(t, vr: float, romega: float, p: LuGreParams, theta: float = 1.0):
    """Closed-form response of the distributed tire (uniform load) to a step of ``vr`` and ``r omega`` at
    ``t = 0`` from free rolling (``z = 0`` everywhere), both constant afterwards.

    With ``b = sigma0 |vr|/(theta g(vr))`` constant, every element obeys ``dz/dt = vr - b z`` from the time it
    is in the patch: the element at ``zeta`` holds ``(vr/b)(1 - exp(-b tau))`` with its age
    ``tau = min(t, zeta/|r omega|)``. Over the patch, with ``R = |r omega|`` and ``T = L/R`` (one patch
    transit)::

        zbar = (vr/b) [R t/L + (1 - exp(-b t))(1 - R t/L - R/(b L))]          (t < T)
        zbar = (vr/b) [1 - (R/(b L))(1 - exp(-b L/R))]                         (t >= T: steady, FM eq. (4))
        dzbar/dt = vr (1 - R t/L) exp(-b t)  (t < T),  0 (t >= T)

    and ``mu = sigma0 zbar + sigma1 dzbar/dt + sigma2 vr`` (FM eq. (2)). At ``t = 0+`` the damping terms give
    ``mu = (sigma1 + sigma2) vr`` at once; from ``t = T`` on the response is exactly the steady state.

    Parameters
    ----------
    t : array_like
        Time since the step [s] (>= 0).
    vr : float
        Relative velocity ``r omega - v`` [m/s] after the step.
    romega : float
        Circumferential speed ``r omega`` [m/s] after the step (non-zero).
    p : LuGreParams
    theta : float
        Road adhesion [-].

    Returns
    -------
    (ndarray, ndarray, ndarray)
        ``mu`` [-], ``zbar`` [m], ``dzbar/dt`` [m/s] at ``t``.
    """
    t = np.asarray(t, dtype=float)
    R, L = abs(float(romega)), p.L
    if vr == 0:
        z = np.zeros_like(t)
        return z.copy(), z, z.copy()
    b = p.sigma0 * abs(vr) / float(stribeck(vr, p, theta))
    zs = vr / b
    tt = np.minimum(t, L / R)
    E = np.exp(-b * tt)
    frac = R * tt / L
    zbar = zs * (frac + (1.0 - E) * (1.0 - frac - R / (b * L)))
    zdot = vr * (1.0 - frac) * E
    return p.sigma0 * zbar + p.sigma1 * zdot + p.sigma2 * vr, zbar, zdot
