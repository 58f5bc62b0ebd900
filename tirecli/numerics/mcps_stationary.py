"""Stationary MCPS tire: the patch (MCPS eq. 14) and the belt fixed point of the complete model (eq. 18).

For a slip ``(kappa, alpha_s, phi)`` any forward speed gives the same answer (rate independence);
the computation takes ``Vx = V`` (default 1 m/s), ``Vy = V tan alpha_s``, ``r omega = V (1 + kappa)``,
``yaw = phi V``. The solid carcass evaluates the stationary patch once (closed form, or RK4 in
``d`` with a yaw rate). The complete model solves, for the belt displacement ``q = (x, y, delta)``,

    G(Q) = (k_x x - FWx(q), k_y y - FWy(q), k_delta delta - MW(q)) / Fz = 0,   Q = (k_x x, k_y y, k_delta delta)

by Newton's method vectorized over all points (forward-difference Jacobian, backtracking on
``|G|``), from the solid-carcass solution, until ``max |G| < tol`` (default 1e-10, forces to
about 1e-6 N); points that do not converge are retried one by one with MINPACK's hybrid method
(``scipy.optimize.root(method="hybr")``). Points that still fail are reported, never returned
as numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from tirecli.models.mcps import tire as T

#: Convergence tolerance of the fixed point (18) on ``max |G|`` (docs/models/mcps_tire.md §7).
TOL = 1e-10


@dataclass
class Stationary:
    """Stationary solutions at a set of points (arrays of one shape).

    Attributes
    ----------
    fx, fy, mz : ndarray
        Road-on-tire forces and aligning torque in R_W [N, N, N m] (ISO-W).
    x, y, delta : ndarray
        Belt displacement relative to the rim [m, m, rad] (0 for the solid carcass).
    residual : ndarray
        ``max |G|`` at the solution (0 for the solid carcass).
    iterations : int
        Newton iterations used (the largest over the points).
    converged : ndarray of bool
    Q : ndarray, shape (P, 3), or None
        ``(k_x x, k_y y, k_delta delta)`` [N, N, N m] (a warm start for nearby solutions).
    """

    fx: np.ndarray
    fy: np.ndarray
    mz: np.ndarray
    x: np.ndarray
    y: np.ndarray
    delta: np.ndarray
    residual: np.ndarray
    iterations: int
    converged: np.ndarray
    Q: np.ndarray | None = None


def patch_forces(p, fz, kappa, alpha, phi, q, frame_term=False, steps=None, speed=1.0):
    """Stationary patch resultants in the belt frame for trial belt displacements ``q`` (P, 3).

    ``speed`` [m/s] is the forward speed ``Vx`` of the evaluation (the result does not depend on it).
    Returns ``(FA (P, 2), MA (P,))`` [N, N m]: road on tire, about the belt centre.
    """
    pa = p.patch(fz)
    law = p.patch_law(fz)
    kappa, alpha, phi = (np.asarray(a, dtype=float) for a in (kappa, alpha, phi))
    romega = speed * (1.0 + kappa)
    ux, uy0, Om = T.belt_velocities(speed, speed * np.tan(alpha), romega, phi * speed, q, np.zeros_like(q))
    sx, sy0, spin = ux / romega, uy0 / romega, Om / romega
    P = kappa.shape[0]
    fx = np.empty(P)
    fy = np.empty(P)
    mz = np.empty(P)
    flat = spin == 0
    if flat.any():
        s = np.stack([sx[flat], sy0[flat]], axis=-1)
        r = T.resultants(*T.stationary_uniform(s, spin[flat], law, pa.l), p.c_Mz)
        fx[flat], fy[flat], mz[flat] = r
    if (~flat).any():
        k = ~flat
        r = T.resultants(*T.stationary_linear(sx[k], sy0[k], spin[k], law, pa.l, frame_term, steps), p.c_Mz)
        fx[k], fy[k], mz[k] = r
    return np.stack([fx, fy], axis=-1), mz


def _residual(p, fz, kappa, alpha, phi, Q, kvec, frame_term, steps, speed=1.0):
    q = Q / kvec
    FA, MA = patch_forces(p, fz, kappa, alpha, phi, q, frame_term, steps, speed)
    FW = np.stack(T.wheel_forces(FA, MA, q), axis=-1)
    return (Q - FW) / fz, FW


def solve(p, fz: float, kappa, alpha, phi, carcass: str = "complete", frame_term: bool = False,
          tol: float = TOL, max_iter: int = 60, steps: int | None = None, locked=(), start=None,
          speed: float = 1.0) -> Stationary:
    """Stationary forces at the points ``(kappa, alpha, phi)`` (broadcast 1-D arrays).

    Parameters
    ----------
    p : MCPSParams
    fz : float
        Load [N].
    kappa : array_like
        Longitudinal slip (ISO-W) [-], > -1.
    alpha : array_like
        Slip angle [rad], |alpha| < pi/2.
    phi : array_like
        Path curvature ``yaw/Vx`` [1/m].
    carcass : {"complete", "rigid"}
        The complete model (belt fixed point, MCPS eq. 18) or the solid carcass (eq. 14).
    frame_term : bool
        Frame-rotation term in the stationary patch (default off, docs/models/mcps_tire.md §4; acts only with a yaw rate).
    tol : float
        Tolerance on ``max |G|`` (scaled by ``fz``).
    locked : iterable of int
        Belt DOFs held at zero (0: x, 1: y, 2: delta); their equations drop out.
    start : array_like, shape (P, 3), or None
        Initial ``Q = (k_x x, k_y y, k_delta delta)`` [N, N, N m] (default: the solid-carcass
        solution); a nearby solution (e.g. of the previous parameters in a fit) saves iterations.
    speed : float
        Forward speed of the evaluation [m/s] (rate independence: any value gives the same forces).
    """
    kappa, alpha, phi = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in (kappa, alpha, phi)))
    kappa, alpha, phi = (np.ascontiguousarray(a).ravel() for a in (kappa, alpha, phi))
    if not speed > 0:
        raise ValueError(f"speed must be > 0 (got {speed}); the stationary forces do not depend on it")
    if np.any(kappa <= -1.0) or np.any(np.abs(alpha) >= np.pi / 2):
        raise ValueError("kappa must be > -1 (the tread moves forwards) and |alpha| < pi/2")
    P = kappa.size
    zeros = np.zeros((P, 3))
    FA, MA = patch_forces(p, fz, kappa, alpha, phi, zeros, frame_term, steps, speed)
    if carcass == "rigid":
        z = np.zeros(P)
        return Stationary(FA[:, 0], FA[:, 1], MA, z, z.copy(), z.copy(), z.copy(), 0, np.ones(P, dtype=bool))
    kvec = np.array([p.k_x, p.k_y, p.k_delta])
    free = np.array([j for j in range(3) if j not in set(locked)], dtype=int)
    Q = np.stack([FA[:, 0], FA[:, 1], MA], axis=-1)            # rigid solution: q0 = F/k
    if start is not None:
        Q = np.array(np.broadcast_to(np.asarray(start, dtype=float), Q.shape))
    Q[:, [j for j in range(3) if j not in free]] = 0.0

    def residual(kq, aq, cq, Qq):
        G_, FW_ = _residual(p, fz, kq, aq, cq, Qq, kvec, frame_term, steps, speed)
        return G_[:, free], FW_

    G, FW = residual(kappa, alpha, phi, Q)
    err = np.max(np.abs(G), axis=1) if free.size else np.zeros(P)
    it = 0
    active = err >= tol
    while active.any() and it < max_iter:
        it += 1
        idx = np.flatnonzero(active)
        Qa, Ga = Q[idx], G[idx]
        args = (kappa[idx], alpha[idx], phi[idx])
        J = np.empty((idx.size, free.size, free.size))
        for c, j in enumerate(free):
            h = 1e-7 * np.maximum(np.abs(Qa[:, j]), 1e-3 * fz)
            Qh = Qa.copy()
            Qh[:, j] += h
            Gh, _ = residual(*args, Qh)
            J[:, :, c] = (Gh - Ga) / h[:, None]
        try:
            dQ = -np.linalg.solve(J, Ga[..., None])[..., 0]
        except np.linalg.LinAlgError:
            dQ = -np.einsum("pij,pj->pi", np.linalg.pinv(J), Ga)
        lam = np.ones(idx.size)
        e0 = err[idx]
        for _ in range(12):  # backtracking: accept the step when |G| decreases
            Qn = Qa.copy()
            Qn[:, free] += lam[:, None] * dQ
            Gn, FWn = residual(*args, Qn)
            en = np.max(np.abs(Gn), axis=1)
            ok = (en < e0) | ~np.isfinite(e0)
            if ok.all():
                break
            lam = np.where(ok, lam, 0.5 * lam)
        good = np.isfinite(en)
        Q[idx[good]] = Qn[good]
        G[idx[good]] = Gn[good]
        FW[idx[good]] = FWn[good]
        err[idx[good]] = en[good]
        stalled = np.zeros(P, dtype=bool)
        stalled[idx] = ~good | (lam < 2.0**-11)
        active = (err >= tol) & ~stalled
    bad = np.flatnonzero(~(err < tol))
    for i in bad:  # one at a time with MINPACK's hybrid method
        args = (kappa[i:i + 1], alpha[i:i + 1], phi[i:i + 1])
        def full(Qf, i=i):
            Qv = Q[i:i + 1].copy()
            Qv[0, free] = Qf
            return Qv

        sol = root(lambda Qf: residual(*args, full(Qf))[0][0], Q[i, free], method="hybr", options={"xtol": 1e-14})
        Gi, FWi = residual(*args, full(sol.x))
        ei = float(np.max(np.abs(Gi)))
        if np.isfinite(ei) and ei < err[i]:
            Q[i], FW[i], err[i] = full(sol.x)[0], FWi[0], ei
    q = Q / kvec
    return Stationary(FW[:, 0], FW[:, 1], FW[:, 2], q[:, 0], q[:, 1], q[:, 2], err, it, err < tol, Q)


def solve_sideslip(p, fz: float, alpha, tol: float = TOL, max_iter: int = 50, start=None) -> Stationary:
    """The complete model in pure side slip (``kappa = 0``, no yaw): the fixed point (18) reduced to the twist.

    Without yaw the belt translations ``x, y`` do not enter the slider velocities (docs/models/mcps_tire.md
    §7): for a trial twist ``delta`` the patch forces ``FA``, ``MA`` are fixed, ``x = FWx/k_x`` and
    ``y = FWy/k_y`` follow explicitly from (16), and (18) reduces to one equation per point,
    ``g(delta) = (k_delta delta - MA - x FA_y + y FA_x)/Fz = 0``, solved by Newton's method with a
    forward-difference slope (step as :func:`solve`), vectorized, halving a step until ``|g|`` decreases.
    Same model and tolerance as :func:`solve` (``carcass="complete"``, no frame term; parity in the
    tests), about twice as fast: the calibration's evaluations use it.

    Parameters
    ----------
    p : MCPSParams
    fz : float
        Load [N].
    alpha : array_like
        Slip angles [rad], ``|alpha| < pi/2``.
    tol : float
        Tolerance on ``|g|`` (the ``max |G|`` of :func:`solve`).
    start : array_like or None
        Initial ``Q = (k_x x, k_y y, k_delta delta)`` (only the twist is used; default: the
        solid-carcass torque, as :func:`solve`).

    Returns
    -------
    Stationary
        Points that do not converge within ``max_iter`` are flagged (``converged`` False), never
        returned as numbers silently.
    """
    alpha = np.ascontiguousarray(np.atleast_1d(np.asarray(alpha, dtype=float))).ravel()
    if np.any(np.abs(alpha) >= np.pi / 2):
        raise ValueError("|alpha| must be < pi/2")
    P = alpha.size
    pa = p.patch(fz)
    law = p.patch_law(fz)
    ta = np.tan(alpha)
    kd = p.k_delta

    def state(de):
        c, s = np.cos(de), np.sin(de)
        sl = np.stack([c + ta * s - 1.0, -s + ta * c], axis=-1)
        fx, fy, ma = T.resultants(*T.stationary_uniform(sl, np.zeros(P), law, pa.l), p.c_Mz)
        fwx, fwy = fx - de * fy, fy + de * fx
        x, y = fwx / p.k_x, fwy / p.k_y
        mw = ma + x * fy - y * fx
        return (kd * de - mw) / fz, fwx, fwy, mw, x, y

    if start is None:
        de = state(np.zeros(P))[3] / kd
    else:
        de = np.array(np.broadcast_to(np.asarray(start, dtype=float), (P, 3))[:, 2]) / kd
    G, fwx, fwy, mw, x, y = state(de)
    err = np.abs(G)
    it = 0
    active = err >= tol
    while active.any() and it < max_iter:
        it += 1
        idx = np.flatnonzero(active)
        d0 = de[idx]
        h = 1e-7 * np.maximum(np.abs(kd * d0), 1e-3 * fz) / kd
        full = de.copy()
        full[idx] = d0 + h
        Gh = state(full)[0][idx]
        slope = (Gh - G[idx]) / h
        step = np.where(slope != 0, -G[idx] / np.where(slope != 0, slope, 1.0), 0.0)
        lam = np.ones(idx.size)
        for _ in range(12):
            trial = de.copy()
            trial[idx] = d0 + lam * step
            out = state(trial)
            en = np.abs(out[0][idx])
            ok = (en < err[idx]) | ~np.isfinite(err[idx])
            if ok.all():
                break
            lam = np.where(ok, lam, 0.5 * lam)
        good = np.isfinite(en) & ok
        sel = idx[good]
        de[sel] = trial[sel]
        for arr, new in zip((G, fwx, fwy, mw, x, y), out):
            arr[sel] = new[sel]
        err[sel] = en[good]
        stalled = np.zeros(P, dtype=bool)
        stalled[idx[~good]] = True
        active = (err >= tol) & ~stalled
    Q = np.stack([p.k_x * x, p.k_y * y, kd * de], axis=-1)
    return Stationary(fwx, fwy, mw, x, y, de, err, it, err < tol, Q)


__all__ = ["Stationary", "solve", "solve_sideslip", "patch_forces", "TOL"]
