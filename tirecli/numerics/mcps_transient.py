"""Time-domain MCPS runs: the single slider (MCPS Fig. 3), the blocked wheel at standstill
(Figs. 4-5) and the rolling tire with a solid or flexible carcass (MCPS eqs. 13 and 17).

- **Slider and standstill patch**: the inputs are straight increments between output samples
  (piecewise-linear positions, reversal points on the grid), and :func:`tirecli.models.mcps.law.step`
  integrates each increment exactly. The standstill yaw is piecewise constant in rate (triangle),
  so the standstill patch is exact at every sample; the sinusoidal slider motion is exact in 1-D
  (rate independence: a monotone segment depends on its path only).
- **Rolling tire** (transport eq. 13 with the belt eq. 17): Lagrangian tread elements moving with
  the tread at CFL = 1 (each step ``dt = dxi/(r omega)`` moves every element one cell and admits an
  unstrained one at the leading edge: transport without numerical diffusion). Over a step each
  element's slider velocity is frozen at the mid-step position and belt state and its law is
  advanced exactly per component, with the frame rotation (uniform over the patch) split half a
  step before and after (Strang); resultants by Gregory's end-corrected trapezoid rule including the
  zero state at the entry (fourth order for smooth profiles). The belt (linear springs and dampers) advances by the trapezoidal rule (A-stable) coupled
  to the patch by a predictor and ``passes - 1`` corrections. Second order in ``dxi``; the tests
  check the rate of convergence and the exact solution of the solid carcass.

**Models the kernels implement:** :func:`tirecli.models.mcps.law.rhs` (the slider, standstill and
integrated-in-time runs through :func:`tirecli.models.mcps.law.step`; the rolling patch through
:func:`patch_step`) and :func:`tirecli.models.mcps.belt.rhs` (:func:`_belt_matrices`). Parity to 1e-12:
tests/test_model_parity.py.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.models.mcps import law as L
from tirecli.models.mcps import tire as T

# --------------------------------------------------------------------------- slider (Fig. 3)


def simulate_slider(law: L.DahlLaw, ux, uy, psi, frame_term: bool = False):
    """Response of one slider to sampled base positions (MCPS eqs. 5-9), exact between samples.

    Parameters
    ----------
    law : DahlLaw
        The slider's law (:meth:`MCPSParams.slider_law`).
    ux, uy : array_like, shape (..., n)
        Base position relative to the road at the samples [m] (straight between samples); leading
        dimensions are independent runs, computed together.
    psi : array_like, shape (..., n)
        Slider rotation at the samples [rad].
    frame_term : bool
        Rotate the force states with the slider (docs/models/mcps_tire.md §4; off for Fig. 3).

    Returns
    -------
    f : ndarray, shape (..., n, 2)
        Friction force transmitted to the road [N] (road on slider: ``-f``).
    m : ndarray, shape (..., n)
        Friction torque [N m].
    """
    ux, uy, psi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (ux, uy, psi)))
    lead, n = ux.shape[:-1], ux.shape[-1]
    F = np.zeros(lead + (law.nb, 2))
    M = np.zeros(lead + (law.nbz,))
    f = np.zeros(lead + (n, 2))
    m = np.zeros(lead + (n,))
    for i in range(1, n):
        du = np.stack([ux[..., i] - ux[..., i - 1], uy[..., i] - uy[..., i - 1]], axis=-1)
        dp = psi[..., i] - psi[..., i - 1]
        F, M = L.step(F, M, du, dp, dp if frame_term else np.zeros_like(dp), law)
        f[..., i, :], m[..., i] = L.output(F, M, law)
    return f, m


def integrate_slider_in_time(law: L.DahlLaw, amplitude: float, rotation: float, period: float, phase,
                             frame_term: bool = False, rtol: float = 1e-10):
    """The slider under ``u_x = A sin(2 pi t/T)``, ``psi = Psi sin(2 pi t/T)`` integrated **in time**
    (:func:`tirecli.models.mcps.law.rhs`, MCPS eq. 9, by ``scipy.integrate.solve_ivp``, DOP853), split at the
    reversals (``|du|`` has a kink there). An independent check of :func:`simulate_slider` and of the law's rate independence: the loop
    must not depend on ``T``.

    Parameters
    ----------
    amplitude, rotation : float
        ``A`` [m], ``Psi`` [rad].
    period : float
        ``T`` [s].
    phase : array_like
        Output phases ``t/T`` [-], increasing from 0.

    Returns
    -------
    f : ndarray, shape (n, 2) [N]; m : ndarray, shape (n,) [N m] -- as :func:`simulate_slider`.
    """
    from scipy.integrate import solve_ivp

    phase = np.asarray(phase, dtype=float)
    w = 2.0 * np.pi / period
    nb, nbz = law.nb, law.nbz

    def rhs(t, x):
        c = np.cos(w * t)
        spin = rotation * w * c
        return L.rhs(t, x, (amplitude * w * c, 0.0, spin, spin if frame_term else 0.0), law)

    edges = [0.0] + [0.25 + 0.5 * k for k in range(int(np.ceil(2 * phase[-1])) + 1) if 0.25 + 0.5 * k < phase[-1]] + [phase[-1]]
    x = np.zeros(2 * nb + nbz)
    f = np.zeros((phase.size, 2))
    m = np.zeros(phase.size)
    for a, b in zip(edges[:-1], edges[1:]):
        q = (phase >= a) & (phase <= b)
        sol = solve_ivp(rhs, (a * period, b * period), x, method="DOP853", rtol=rtol, atol=rtol * 1e-3,
                        t_eval=phase[q] * period)
        if not sol.success:
            raise RuntimeError(f"time integration of the slider failed: {sol.message}")
        Fs = sol.y[:2 * nb].T.reshape(-1, nb, 2)
        f[q], m[q] = L.output(Fs, sol.y[2 * nb:].T, law)
        x = sol.y[:, -1] if sol.y.shape[1] else x
    return f, m


# --------------------------------------------------------------------------- standstill (Figs. 4-5)


def triangle_yaw(amplitude: float, rate: float, cycles: int, samples_per_leg: int):
    """Time grid and yaw angle of the standstill cycle 0 -> +A -> -A -> +A ... (docs/models/mcps_tire.md §11).

    ``cycles`` full cycles after the first quarter: legs ``0 -> A`` then ``2 cycles`` legs of
    ``2A``; every reversal lies on the grid. Returns ``(t [s], psi [rad], leg index)``.
    """
    A, w = float(amplitude), float(rate)
    ends = [A] + [(-A if k % 2 == 0 else A) for k in range(2 * int(cycles))]
    t, psi, leg = [0.0], [0.0], [0]
    t0, p0 = 0.0, 0.0
    for k, pe in enumerate(ends):
        span = abs(pe - p0)
        n = max(2, int(round(samples_per_leg * span / (2 * A))))
        tt = t0 + np.linspace(0.0, span / w, n + 1)[1:]
        t.extend(tt)
        psi.extend(p0 + (pe - p0) * (tt - t0) / (span / w))
        leg.extend([k] * n)
        t0, p0 = tt[-1], pe
    return np.array(t), np.array(psi), np.array(leg)


def gauss_patch(l: float, nodes_per_half: int):
    """Gauss-Legendre nodes and weights on ``[-l/2, 0]`` and ``[0, l/2]`` (the standstill response is
    odd in ``xi`` with a kink of ``|xi|`` at 0, so each half gets its own rule)."""
    x, w = np.polynomial.legendre.leggauss(int(nodes_per_half))
    half = l / 2.0
    xi = np.concatenate([(x - 1.0) * half / 2.0, (x + 1.0) * half / 2.0])
    wt = np.concatenate([w, w]) * half / 2.0
    return xi, wt


def simulate_standstill(law: L.DahlLaw, c_Mz: float, t, psi, xi_quad, w_quad, xi_grid=(),
                        frame_term: bool = True):
    """Blocked wheel at standstill under a yaw motion (MCPS §3.1, eqs. 10-12), exact between samples.

    Each slider at ``xi`` moves by ``(0, xi dpsi)`` and spins by ``dpsi`` (``V = 0``); with the frame
    term its force states also turn by ``dpsi``. Resultants (eq. 10) by quadrature.

    Parameters
    ----------
    law : DahlLaw
        Law per unit patch length.
    t, psi : array_like, shape (n,)
        Samples of the yaw angle [s, rad] (linear between samples).
    xi_quad, w_quad : array_like
        Quadrature nodes [m] and weights [m] over the patch (:func:`gauss_patch`).
    xi_grid : array_like
        Extra abscissae [m] where the lateral force density is recorded (e.g. a uniform grid).

    Returns
    -------
    dict with ``fx``, ``fy`` [N], ``mz`` [N m] (road on tire, shape (n,)) and ``fy_grid``
    [N/m] (shape (n, len(xi_grid))): the lateral friction force density on the road at ``xi_grid``.
    """
    t, psi = np.asarray(t, dtype=float), np.asarray(psi, dtype=float)
    xi_quad = np.asarray(xi_quad, dtype=float)
    w_quad = np.asarray(w_quad, dtype=float)
    xi_grid = np.asarray(xi_grid, dtype=float)
    xi = np.concatenate([xi_quad, xi_grid])
    nq = xi_quad.size
    S = xi.size
    F = np.zeros((S, law.nb, 2))
    M = np.zeros((S, law.nbz))
    n = t.size
    fx, fy, mz = np.zeros(n), np.zeros(n), np.zeros(n)
    fyg = np.zeros((n, xi_grid.size))
    for i in range(1, n):
        dp = psi[i] - psi[i - 1]
        du = np.stack([np.zeros(S), xi * dp], axis=-1)
        F, M = L.step(F, M, du, np.full(S, dp), np.full(S, dp if frame_term else 0.0), law)
        f, m = L.output(F, M, law)
        fx[i] = -np.dot(w_quad, f[:nq, 0])
        fy[i] = -np.dot(w_quad, f[:nq, 1])
        mz[i] = -np.dot(w_quad, m[:nq] + c_Mz * xi_quad * f[:nq, 1])
        fyg[i] = f[nq:, 1]
    return {"fx": fx, "fy": fy, "mz": mz, "fy_grid": fyg}


def asymptotic_standstill_torque(law: L.DahlLaw, l: float, c_Mz: float, frame_term: bool, nodes: int = 64) -> float:
    """``|Mz|`` [N m] after a long monotone yaw at standstill (every slider in its steady state).

    Without the frame term each slider slides at the Coulomb level: MCPS eq. (12),
    ``(mu_y Fz/4)(c_muz w + c_Mz l)``. With it the force states lag the turning frame and settle
    at ``F* = A^-1 b`` of the exact step (per unit yaw: ``p = n g_x``, ``q = n g_y``, ``w = 1``,
    ``n = F'_ky |xi|``, ``b = (0, h_y xi)``), above Coulomb near the centre (docs/models/mcps_tire.md §3.2). The
    integrand is a smooth rational function of ``xi`` on each half patch: Gauss-Legendre with
    ``nodes`` points integrates it to rounding (checked against adaptive quadrature in the tests).
    """
    xg, wg = np.polynomial.legendre.leggauss(int(nodes))
    x = (xg + 1.0) * l / 4.0                                  # nodes on [0, l/2]
    w = wg * l / 4.0
    n = law.Fk[1] * x
    p = n[:, None] * law.g[None, :, 0]
    q = n[:, None] * law.g[None, :, 1]
    by = law.h[None, :, 1] * x[:, None]
    sy = p * by / (p * q + 1.0) if frame_term else law.h[None, :, 1] / (law.g[None, :, 1] * law.Fk[1]) + 0.0 * x[:, None]
    fy = sy @ law.sigma
    m_inf = float(np.dot(law.sigz, law.hz / law.gz))
    return l * m_inf + c_Mz * 2.0 * float(np.dot(w, x * fy))


# --------------------------------------------------------------------------- rolling tire (eqs. 13, 17)


def patch_weights(N: int) -> np.ndarray:
    """Quadrature weights (in units of the cell) of the nodes 1..N of a patch of N cells whose entry
    node 0 holds the zero state: Gregory's end-corrected trapezoid rule (weights 3/8, 7/6, 23/24 at
    each end; fourth order for smooth profiles), the plain trapezoid rule below 6 cells."""
    if N < 6:
        w = np.ones(N)
        w[-1] = 0.5
        return w
    w = np.ones(N + 1)
    w[[0, -1]] = 3.0 / 8.0
    w[[1, -2]] = 7.0 / 6.0
    w[[2, -3]] = 23.0 / 24.0
    return w[1:]


@dataclass
class RollingRun:
    """A rolling-tire run sampled at every transport step.

    Attributes
    ----------
    t : ndarray
        Time [s].
    s : ndarray
        Rolled distance ``r omega t`` [m].
    fx, fy, mz : ndarray
        Road-on-tire forces and torque in R_W about the rim centre (MCPS eq. 16) [N, N, N m].
    x, y, delta : ndarray
        Belt displacement [m, m, rad].
    rim_fx, rim_fy, rim_mz : ndarray
        Forces the belt springs and dampers put on the rim ``k q + c qdot`` [N, N, N m].
    cells : int
        Patch cells.
    dt : float
        Transport step [s].
    """

    t: np.ndarray
    s: np.ndarray
    fx: np.ndarray
    fy: np.ndarray
    mz: np.ndarray
    x: np.ndarray
    y: np.ndarray
    delta: np.ndarray
    rim_fx: np.ndarray
    rim_fy: np.ndarray
    rim_mz: np.ndarray
    cells: int
    dt: float


def _belt_matrices(p, dt: float, locked):
    """Trapezoidal-rule matrices of the belt ``y' = A y + B u`` (``y = (q, qdot)``, ``u = FW``): the kernel of
    :func:`tirecli.models.mcps.belt.rhs` (``A``, ``B`` its Jacobians; the ``locked`` DOFs held at zero).
    ``y1 = Phi y0 + Gam (u0 + u1)``; parity to 1e-12: tests/test_model_parity.py."""
    A = np.zeros((6, 6))
    B = np.zeros((6, 3))
    mass = (p.m_b, p.m_b, p.J_b)
    k = (p.k_x, p.k_y, p.k_delta)
    c = (p.c_x, p.c_y, p.c_delta)
    free = [j for j in range(3) if j not in locked]
    for j in free:
        A[j, 3 + j] = 1.0
        A[3 + j, j] = -k[j] / mass[j]
        A[3 + j, 3 + j] = -c[j] / mass[j]
        B[3 + j, j] = 1.0 / mass[j]
    I = np.eye(6)
    Linv = np.linalg.inv(I - 0.5 * dt * A)
    return Linv @ (I + 0.5 * dt * A), Linv @ (0.5 * dt * B), np.array(k), np.array(c)


def coupling_rate(p, fz: float, locked=()) -> float:
    """Fastest undamped angular frequency [rad/s] of the belt on its springs and on the patch (the
    tread elements act as springs to the road): ``sqrt((K'_x l + k_x)/m_b)``, ``sqrt((K'_y l + k_y)/m_b)``,
    ``sqrt((C_z + k_delta)/J_b)`` over the free DOFs (0 when all are locked)."""
    import math

    pa = p.patch(fz)
    law = p.patch_law(fz)
    cz = p.stiffnesses(fz)["C_z"]
    w2 = [(law.K[0] * pa.l + p.k_x) / p.m_b, (law.K[1] * pa.l + p.k_y) / p.m_b, (cz + p.k_delta) / p.J_b]
    free = [w for j, w in enumerate(w2) if j not in set(locked)]
    return math.sqrt(max(free)) if free else 0.0


def cells_needed(p, fz: float, romega: float, cells: int, carcass: str = "complete", locked=(), courant: float = 0.5,
                 slip=(0.0, 0.0), per_length: float = 5.0) -> int:
    """Patch cells of a rolling run: at least ``cells``; at least ``per_length`` cells per relaxation
    length of the tread elements at the slip ``slip = du/(r omega)`` (the entry boundary layer of
    length ``1/(|F'_k s| g)`` sharpens at large slip: ``cells >= per_length z`` with ``z = |F'_k s| g l``);
    and for the flexible carcass enough that the belt's fastest mode is resolved by the transport step
    (``omega dt <= courant``, ``dt = l/(cells r omega)``)."""
    import math

    pa = p.patch(fz)
    law = p.patch_law(fz)
    z = float(np.hypot(law.Fk[0] * slip[0], law.Fk[1] * slip[1]) * np.max(law.g) * pa.l)
    n = max(int(cells), int(math.ceil(per_length * z)))
    if carcass == "rigid":
        return n
    w = coupling_rate(p, fz, locked)
    return max(n, int(math.ceil(w * pa.l / (courant * romega))))


def patch_step(S0, du, dth, Gneg, H, Fk, meas, Pn):
    """One transport step of the tread elements' friction states (module doc): the kernel of
    :func:`tirecli.models.mcps.law.rhs`.

    Each component advances by the exact flow of the law without its frame term over the step,
    ``S' = e^-P S + h du (1 - e^-P)/P`` with ``P = g |F_k du|`` (x, y) or ``g_z |dpsi|`` (torsion), between
    two half rotations by the frame increment, each the exact flow of the frame term ``-Omega_s Omega_hat F``
    (Strang splitting). Parity with :func:`tirecli.models.mcps.law.rhs` (exact flows by matrix
    exponential) to 1e-12: tests/test_model_parity.py.

    Parameters
    ----------
    S0 : ndarray, shape (3, nb, N)
        States per component (x, y [N/m], torsion [N m/m]: the law per unit patch length), branch and element.
    du : ndarray, shape (3, 1, N)
        Increments over the step: slider base displacement along x, y [m] and spin ``dpsi`` [rad].
    dth : float
        Rotation of the slider frame relative to the road over the step [rad] (0: no frame term).
    Gneg, H : ndarray, shape (3, nb, 1)
        Minus the relaxation gains and the input gains per component and branch (:class:`~tirecli.models.mcps.law.DahlLaw`).
    Fk : array_like, shape (2,)
        Coulomb levels along x, y [N/m].
    meas, Pn : ndarray, shapes (3, 1, N) and (3, nb, N)
        Work arrays (overwritten).

    Returns
    -------
    ndarray, shape (3, nb, N)
        The states at the end of the step.
    """
    if dth:                                               # the frame turns by +dth: states by -dth
        ch, sh = np.cos(0.5 * dth), np.sin(0.5 * dth)
        S0 = S0.copy()
        S0[0], S0[1] = ch * S0[0] + sh * S0[1], -sh * S0[0] + ch * S0[1]
    meas[0, 0] = np.hypot(Fk[0] * du[0, 0], Fk[1] * du[1, 0])  # |F_k du| drives x and y
    meas[1] = meas[0]
    meas[2] = np.abs(du[2])                               # |dpsi| drives the torsion
    np.multiply(Gneg, meas, out=Pn)                       # -P (minus a tiny offset: no 0/0 at rest)
    np.subtract(Pn, 1e-300, out=Pn)
    em = np.expm1(Pn)
    phi = em / Pn                                         # (1 - e^-P)/P
    em += 1.0
    S1 = em * S0 + (H * du) * phi                         # exact per component: e^-P S + h du (1-e^-P)/P
    if dth:
        S1[0], S1[1] = ch * S1[0] + sh * S1[1], -sh * S1[0] + ch * S1[1]
    return S1


def simulate_rolling(p, fz: float, Vx: float, Vy: float, romega: float, yaw: float, distance: float,
                     cells: int = 100, carcass: str = "complete", locked=(), frame_term: bool = True,
                     passes: int | None = None, progress=None) -> RollingRun:
    """The rolling tire after a step in its inputs at ``t = 0`` (MCPS eqs. 13, 16, 17).

    Before ``t = 0`` the tire rolls freely: tread elements and belt at rest. From ``t = 0`` on the rim
    moves at ``(Vx, Vy)`` [m/s], yaws at ``yaw`` [rad/s] and the tread is transported at
    ``romega`` [m/s] (> 0), all constant.

    Parameters
    ----------
    p : MCPSParams
    fz : float
        Load [N].
    distance : float
        Rolled distance to simulate [m].
    cells : int
        Patch cells (Lagrangian elements); the step is ``dt = l/(cells romega)``.
    carcass : {"complete", "rigid"}
    locked : iterable of int
        Belt DOFs held at zero (0: x, 1: y, 2: delta), e.g. ``(2,)`` for a locked twist.
    frame_term : bool
        Rotate the element states with the belt (``Omega_s = yaw + delta_dot``; docs/models/mcps_tire.md §4 default on).
    passes : int or None
        Element updates per step for the belt coupling after the predictor (default: 1 when the belt's
        fastest mode is well resolved, ``omega dt < 0.1``, else 2).
    progress : object or None
        ``start/advance/close`` reporter.
    """
    if romega <= 0:
        raise ValueError("the transport speed r omega must be > 0")
    pa = p.patch(fz)
    law = p.patch_law(fz)
    l = pa.l
    N = int(cells)
    dxi = l / N
    dt = dxi / romega
    nsteps = int(np.ceil(distance / dxi - 1e-9))
    xi_nodes = l / 2.0 - dxi * np.arange(1, N + 1)            # positions after a step
    xi_mid = xi_nodes + 0.5 * dxi                             # mid-step positions
    wts = patch_weights(N) * dxi                              # nodes 1..N; the entry node holds zero
    wxi = wts * xi_nodes
    # states stacked as S[component (x, y, torsion z), branch, element]
    G = np.concatenate([law.g.T, law.gz[None, :]])[:, :, None]      # (3, 2, 1) relaxation gains
    H = np.concatenate([law.h.T, law.hz[None, :]])[:, :, None]      # (3, 2, 1) input gains
    sig = np.stack([law.sigma, law.sigma, law.sigz])                # (3, 2) output weights
    S = np.zeros((3, 2, N))
    rigid = carcass == "rigid"
    locked = tuple(sorted(set(locked)))
    Phi, Gam, kv, cv = _belt_matrices(p, dt, locked)
    if passes is None:
        passes = 1 if coupling_rate(p, fz, locked) * dt < 0.1 else 2
    y = np.zeros(6)
    out = np.zeros((nsteps + 1, 10))
    du = np.empty((3, 1, N))
    meas = np.empty((3, 1, N))
    Pn = np.empty((3, 2, N))
    Gneg = -G

    def forces(S_, q):
        tot = np.einsum("cbn,n->cb", S_, wts)                       # patch integrals per component, branch
        line_y = sig[1] @ S_[1]
        fxa = -float(sig[0] @ tot[0])
        fya = -float(sig[1] @ tot[1])
        mza = -(float(sig[2] @ tot[2]) + p.c_Mz * float(line_y @ wxi))
        if rigid:
            return fxa, fya, mza
        return tuple(float(v) for v in T.wheel_forces((fxa, fya), mza, q))     # MCPS eq. (16)

    def advance(S0, ymid):
        ux, uy0, Om = T.belt_velocities(Vx, Vy, romega, yaw, ymid[:3], ymid[3:])   # slider velocities in R_A
        du[0] = ux * dt
        du[1] = (uy0 + Om * xi_mid) * dt
        dps = Om * dt
        du[2] = dps
        return patch_step(S0, du, dps if frame_term else 0.0, Gneg, H, law.Fk, meas, Pn)

    def record(i, f, yv):
        q, qd = yv[:3], yv[3:]
        out[i] = (i * dt, *f, *q, *(kv * q + cv * qd))

    f_now = forces(S, y[:3])
    record(0, f_now, y)
    if progress is not None:
        progress.start(nsteps, "rolling")
    every = max(1, nsteps // 100)
    for i in range(1, nsteps + 1):
        # transport: every element moves one cell, an unstrained one enters at the leading edge
        S[:, :, 1:] = S[:, :, :-1]
        S[:, :, 0] = 0.0
        if rigid:
            S = advance(S, y)
            f_now = forces(S, y[:3])
        else:
            base = Phi @ y + Gam @ np.asarray(f_now)
            y_new = base + Gam @ np.asarray(f_now)            # predictor: the force held
            for _ in range(max(1, int(passes))):
                S1 = advance(S, 0.5 * (y + y_new))
                y_new = base + Gam @ np.asarray(forces(S1, y_new[:3]))
            S, y = S1, y_new
            f_now = forces(S, y[:3])
        record(i, f_now, y)
        if progress is not None and i % every == 0:
            progress.advance(every)
    if progress is not None:
        progress.close()
    o = out
    return RollingRun(t=o[:, 0], s=o[:, 0] * romega, fx=o[:, 1], fy=o[:, 2], mz=o[:, 3], x=o[:, 4], y=o[:, 5],
                      delta=o[:, 6], rim_fx=o[:, 7], rim_fy=o[:, 8], rim_mz=o[:, 9], cells=N, dt=dt)


def rigid_step_exact(p, fz: float, sx: float, sy: float, s):
    """Exact ``Fx, Fy, Mz`` of the solid carcass after a step of the slip at ``t = 0`` from free rolling
    (characteristics, docs/models/mcps_tire.md §7): after a transport distance ``s`` the element at distance
    ``d`` from the leading edge holds the stationary state at ``min(d, s)``.

    Per component ``F(d) = tau (1 - e^{-c d})`` with ``c = g |F'_k s_vec|`` and ``tau = h s_c / c``; the
    patch integrals split at ``d = s``.

    Parameters
    ----------
    p : MCPSParams
    fz : float
        Load [N].
    sx, sy : float
        Slider displacement per unit transport distance ``(u_x, u_y)/(r omega)`` [-] of the solid carcass:
        ``sx = (Vx - r omega)/(r omega)`` (``-kappa/(1 + kappa)`` for the slip ratio ``kappa = r omega/Vx - 1``),
        ``sy = Vy/(r omega)`` (``tan alpha`` at ``kappa = 0``).
    s : array_like
        Transport distance ``r omega t`` since the step [m].

    Returns
    -------
    (ndarray, ndarray, ndarray)
        ``Fx, Fy`` [N] and ``Mz`` [N m] (road on tire, ISO-W) at ``s``.
    """
    s = np.atleast_1d(np.asarray(s, dtype=float))
    law = p.patch_law(fz)
    l = p.patch(fz).l
    n = float(np.hypot(law.Fk[0] * sx, law.Fk[1] * sy))
    se = np.clip(s, 0.0, l)[:, None]
    out, mz = [], np.zeros_like(s)
    for comp, sc in ((0, sx), (1, sy)):
        if sc == 0 or n == 0:
            out.append(np.zeros_like(s))
            continue
        c = n * law.g[:, comp]                                # (nb,)
        tau = law.h[:, comp] * sc / c
        E = np.exp(-c * se)
        # int_0^se F dd + (l - se) F(se)
        i0 = tau * (se - (1.0 - E) / c) + (l - se) * tau * (1.0 - E)
        out.append(-(i0 @ law.sigma))
        if comp == 1:
            # int_0^se (l/2 - d) F dd + F(se) int_se^l (l/2 - d) dd
            arm0 = tau * (l / 2.0 * se - se**2 / 2.0 - (l / 2.0 * (1.0 - E) / c - (1.0 - E * (1.0 + c * se)) / c**2))
            tail = (l / 2.0 * (l - se) - (l**2 - se**2) / 2.0) * tau * (1.0 - E)
            mz = -p.c_Mz * ((arm0 + tail) @ law.sigma)
    return out[0], out[1], mz


def rigid_relaxation_exact(p, fz: float, alpha: float, s):
    """Exact ``Fy, Mz`` of the solid carcass after a slip-angle step (:func:`rigid_step_exact` with
    ``sx = 0``, ``sy = tan alpha``) at the rolled distances ``s`` [m] (array)."""
    _, fy, mz = rigid_step_exact(p, fz, 0.0, float(np.tan(alpha)), s)
    return fy, mz


__all__ = ["simulate_slider", "integrate_slider_in_time", "triangle_yaw", "gauss_patch", "simulate_standstill", "coupling_rate", "cells_needed", "patch_step",
           "asymptotic_standstill_torque", "RollingRun", "simulate_rolling", "rigid_step_exact",
           "rigid_relaxation_exact"]
