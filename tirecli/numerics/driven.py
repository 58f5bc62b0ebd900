"""The distributed LuGre tire driven by prescribed kinematics, vectorised over time (docs/models/lugre_friction.md §3.1-3.2, §8).

**Model it implements:** :func:`tirecli.models.lugre_pde.rhs` / :func:`~tirecli.models.lugre_pde.outputs`
with ``DistributedTire(p, red)`` and the input ``(vr, r omega, theta)`` of the drive, the tracked deflections
``z_points`` from the grid's own characteristics (:meth:`GridModel.solve` returns the state, its rates and
``z_points`` at the nodes). Parity to 1e-12: tests/test_model_parity.py.

Open loop (the tire alone, ``v(t)`` [m/s] and ``r omega(t)`` [m/s] given, adhesion ``theta = 1``)
the coefficient of the PDE (FM eq. (1))::

    dz/dt + |r omega| dz/dzeta = vr - b(t) z,    b = sigma0 |vr| / (theta g(vr))

depends only on the drive and the parameters, never on the state. The exact reduction of
:mod:`tirecli.models.lugre_pde` (``Y``, ``Phi = int b``, ``X = int |r omega|``, the patch
integrals ``S_j``) is then a chain of scalar *linear* ODEs ``dx/dt = f(t) - lambda(t) x``:

    dY/dt   = vr - b Y                                                    (point model, Y(0) = 0)
    dS_j/dt = A_j vr - b S_j - (|r omega|/L) (Bc_j z(u_{p_j} L, t) - sum_l D_jl S_l)
    z(zeta, t) = Y(t) - exp(Phi(tau) - Phi(t)) Y(tau),   X(tau) = X(t) - zeta   (characteristics)

(``D`` lower triangular, so the ``S_j`` follow one another) and FM eq. (2) gives
``mu = sigma0 w.S + sigma1 w.dS/dt + sigma2 vr``. Each linear ODE is solved on a fixed time grid by
an exponential integrator: over a step ``[t_n, t_n + h]``, with ``u = t_{n+1} - s``,

    x_{n+1} = e^{-beta_n} x_n + int_0^h exp(-lambda_{n+1} u + lambda' u^2/2) f(t_{n+1} - u) du,
    beta_n = h (lambda_n + lambda_{n+1})/2,   lambda' = (lambda_{n+1} - lambda_n)/h,

with ``f`` linear over the step and ``exp(lambda' u^2/2) ~ 1 + lambda' u^2/2``: the integral is a
combination of the moments ``m_k(A) = int_0^1 s^k e^{-A s} ds`` (``A = h lambda_{n+1}``, k = 0..3).
It is unconditionally stable in the stiff bristle rate ``b``, second order in the step, and keeps
the stiff limit exact (``x_{n+1} -> f_{n+1}/lambda_{n+1}``; a step-averaged rate would leave a
first-order error there). The recurrence is evaluated without a loop over steps (cumulative sums in
blocks short enough that ``exp(int lambda)`` cannot overflow). The deflections at the tracked points
come from the grid values by cubic Hermite interpolation in time (the rates ``dY/dt``, ``b``,
``|r omega|`` are known at every node; ``tau`` from one Newton step on the Hermite ``X``), as in
:mod:`tirecli.numerics.characteristics`. Everything broadcasts over a leading axis of parameter
sets, so a finite-difference Jacobian of the identification (:mod:`tirecli.numerics.identify`) costs
one call.

:class:`DrivenDistributed` solves on two grids (``m`` and ``2 m`` steps per sample interval) and
extrapolates (Richardson) the sample values. The kinematics enter only through their values on the
grid: :func:`drive_from_samples` builds it from measured samples (cubic spline through them, or
linear), so the samples are grid nodes. Elements in the patch at the first sample start undeflected
(``z(zeta, t_0) = 0``); after one patch transit (``X >= L``) the solution no longer depends on that
assumption. Measured accuracy at 100 Hz samples, ``m = 4``, against ``solve_ivp`` (DOP853, rtol
1e-12) with adaptive quadrature over the patch (tests/test_fit_distributed.py): max ``|mu|`` error
6e-7 (uniform load), 1e-7 (exponential), 6e-5 (parabolic: three coupled patch moments).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.models.lugre import mu_of_deflection
from tirecli.models.lugre_pde import PatchReduction, patch_reduction

#: Largest increase of ``int lambda dt`` inside one block of the cumulative-sum recurrence
#: (``exp(600)`` ~ 1e260 stays finite in double precision).
_BLOCK_EXPONENT = 600.0
#: Default number of grid steps per sample interval (coarse grid of the extrapolation).
DEFAULT_SUBSTEPS = 4


@dataclass(frozen=True)
class Drive:
    """Prescribed kinematics on a time grid.

    Attributes
    ----------
    t : ndarray
        Grid times [s], increasing, from the first sample.
    v, romega : ndarray
        Vehicle speed and wheel circumferential speed ``r omega`` [m/s] at the grid times.
    X : ndarray
        Travelled length ``int_0^t |r omega| dt`` [m] at the grid times.
    samples : ndarray of int
        Grid indices of the samples (where the model is compared with data).
    """

    t: np.ndarray
    v: np.ndarray
    romega: np.ndarray
    X: np.ndarray
    samples: np.ndarray

    @property
    def vr(self) -> np.ndarray:
        """Relative velocity ``r omega - v`` [m/s] at the grid times."""
        return self.romega - self.v


def drive_on_grid(t, v, romega, samples=None, X=None) -> Drive:
    """A :class:`Drive` from kinematics already on a grid (``X`` by the trapezoid rule unless given)."""
    t, v, romega = (np.asarray(a, dtype=float) for a in (t, v, romega))
    if X is None:
        c = np.abs(romega)
        X = np.concatenate(([0.0], np.cumsum(0.5 * (c[1:] + c[:-1]) * np.diff(t))))
    idx = np.arange(len(t)) if samples is None else np.asarray(samples, dtype=int)
    return Drive(t, v, romega, np.asarray(X, dtype=float), idx)


def drive_from_samples(t, v, romega, substeps: int = DEFAULT_SUBSTEPS, interpolation: str = "cubic") -> Drive:
    """The drive through measured samples: ``substeps`` grid steps per sample interval.

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing (the grid starts at ``t[0]``; times are kept as given).
    v, romega : array_like
        Vehicle speed and ``r omega`` [m/s] at the samples.
    interpolation : str
        ``cubic`` (not-a-knot cubic spline through the samples; ``X`` its exact integral) or
        ``linear`` (``X`` by the trapezoid rule, exact for it).
    """
    t, v, romega = (np.asarray(a, dtype=float) for a in (t, v, romega))
    m = int(substeps)
    frac = np.arange(m) / m
    tg = np.append((t[:-1, None] + np.diff(t)[:, None] * frac[None, :]).ravel(), t[-1])
    idx = np.arange(len(t)) * m
    tg[idx] = t
    if interpolation == "linear" or len(t) < 4:
        vg, rg = np.interp(tg, t, v), np.interp(tg, t, romega)
        d = drive_on_grid(tg, vg, rg, idx)
        return d
    from scipy.interpolate import CubicSpline

    sv, sr = CubicSpline(t, v), CubicSpline(t, romega)
    vg, rg = sv(tg), sr(tg)
    vg[idx], rg[idx] = v, romega
    if np.all(romega >= 0.0) and np.all(rg >= 0.0):
        X = sr.antiderivative()(tg)
        X -= X[0]
        return Drive(tg, vg, rg, X, idx)
    return drive_on_grid(tg, vg, rg, idx)


# --------------------------------------------------------------------------- linear recurrences


#: Taylor coefficients of ``m_k(A) = int_0^1 s^k e^(-A s) ds = sum_j (-A)^j / (j! (k + j + 1))``, ``k = 0..3``.
_SERIES = [np.array([(-1.0) ** j / (math.factorial(j) * (k + j + 1)) for j in range(9)]) for k in range(4)]
#: Below this ``A`` the moments come from their Taylor series (9 terms: error < 1e-15), above it from
#: the upward recurrence (error amplification at most 3!/A^3 ~ 6e3 at the threshold: < 1e-12).
_A_SERIES = 0.1


def _moments(A):
    """``m_k(A) = int_0^1 s^k e^(-A s) ds`` for ``k = 0..3`` (A >= 0; Taylor series for small ``A``)."""
    small = A < _A_SERIES
    As = np.where(small, 1.0, A)
    e = np.exp(-As)
    r = 1.0 / As
    m = [-np.expm1(-As) * r]
    for k in range(1, 4):
        m.append((k * m[-1] - e) * r)
    if small.any():
        a = A[small]
        for k in range(4):
            c = _SERIES[k]
            acc = np.full_like(a, c[-1])
            for cj in c[-2::-1]:
                acc = acc * a + cj
            m[k][small] = acc
    return m


class LinearODE:
    """Solver of ``dx/dt = f(t) - lambda(t) x``, ``x(t_0) = 0``, on a grid, for a fixed rate ``lambda`` (module doc).

    The weights (which depend on the rate only) are computed once; :meth:`solve` then takes any
    source ``f``. Leading axes of ``rate`` (and of the sources) are independent problems.

    Parameters
    ----------
    h : ndarray, shape (N-1,)
        Grid steps [s].
    rate : ndarray, shape (..., N)
        ``lambda`` [1/s] (>= 0) at the grid nodes.

    Attributes
    ----------
    Lam : ndarray, shape (..., N)
        ``int_0^t lambda`` (trapezoid rule): the exponent the integrator uses.
    """

    def __init__(self, h, rate):
        beta = 0.5 * h * (rate[..., 1:] + rate[..., :-1])
        A = h * rate[..., 1:]
        cq = 0.5 * h * (rate[..., 1:] - rate[..., :-1])
        m0, m1, m2, m3 = _moments(A)
        # x_{n+1} = e^-beta_n x_n + h (w1_n f_{n+1} + w0_n f_n): kernel exp(-lambda_{n+1} u) (1 + c u^2/h^2), f linear
        self.w1 = h * (m0 + cq * m2 - m1 - cq * m3)
        self.w0 = h * (m1 + cq * m3)
        self.Lam = np.concatenate((np.zeros(rate.shape[:-1] + (1,)), np.cumsum(beta, axis=-1)), axis=-1)
        N = rate.shape[-1]
        self.shape = rate.shape
        # blocks of steps in which exp(int lambda) stays finite (module doc); the exponents are taken
        # from the end of a block's first step, so a single step may be as stiff as it likes
        flat = self.Lam.reshape(-1, N)
        self.blocks = []
        start = 0
        while start < N - 1:
            ends = [int(np.searchsorted(row, row[start + 1] + _BLOCK_EXPONENT, side="right")) - 1 for row in flat]
            end = max(min(min(ends), N - 1), start + 1)
            ref = self.Lam[..., start + 1:start + 2]
            up = np.exp(self.Lam[..., start + 1:end + 1] - ref)                       # e^0 .. e^600
            down = np.exp(ref - self.Lam[..., start + 1:end + 1])
            decay = np.exp(self.Lam[..., start:start + 1] - self.Lam[..., start + 1:end + 1])
            self.blocks.append((start, end, up, down, decay))
            start = end

    def solve(self, source):
        """``x`` at the grid nodes for the source ``f`` (shape broadcastable to the rate's)."""
        source = np.broadcast_to(source, self.shape)
        g = self.w1 * source[..., 1:] + self.w0 * source[..., :-1]
        x = np.empty(self.shape)
        x[..., 0] = 0.0
        x0 = np.zeros(self.shape[:-1])
        for start, end, up, down, decay in self.blocks:
            x[..., start + 1:end + 1] = decay * x0[..., None] + down * np.cumsum(g[..., start:end] * up, axis=-1)
            x0 = x[..., end]
        return x


def linear_ode(h, rate, source):
    """Solve ``dx/dt = f(t) - lambda(t) x``, ``x(t_0) = 0`` on a grid: ``(x, int_0^t lambda)`` (:class:`LinearODE`)."""
    ode = LinearODE(h, rate)
    return ode.solve(source), ode.Lam


# --------------------------------------------------------------------------- characteristics lookups


@dataclass(frozen=True)
class _Lookup:
    """Where (between which nodes, at which fraction) the element now at ``u L`` entered: parameter-free."""

    k: np.ndarray        # left node of the bracketing step
    s: np.ndarray        # fraction in the step (Hermite coordinate)
    inside: np.ndarray   # False: the element was in the patch at t = 0 (z = Y(t) there)
    dt: np.ndarray       # step length [s]


def _lookup(drive: Drive, zeta: float) -> _Lookup:
    """Entry step of the element at ``zeta`` [m] behind the leading edge, for every grid node."""
    X, t = drive.X, drive.t
    c = np.abs(drive.romega)
    target = X - zeta
    inside = target > 0.0
    k = np.clip(np.searchsorted(X, target, side="right") - 1, 0, len(X) - 2)
    dt = t[k + 1] - t[k]
    dXs = X[k + 1] - X[k]
    ok = dXs > 0.0
    s = np.where(ok, (target - X[k]) / np.where(ok, dXs, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    # one Newton step on the Hermite X(s) (X is nearly linear in a step)
    a0, a1 = dt * c[k], dt * c[k + 1]
    s2, s3 = s * s, s * s * s
    Xs = (2 * s3 - 3 * s2 + 1) * X[k] + (s3 - 2 * s2 + s) * a0 + (-2 * s3 + 3 * s2) * X[k + 1] + (s3 - s2) * a1
    dXds = (6 * s2 - 6 * s) * (X[k] - X[k + 1]) + (3 * s2 - 4 * s + 1) * a0 + (3 * s2 - 2 * s) * a1
    good = ok & (dXds > 0.0)
    s = np.where(good, np.clip(s - (Xs - target) / np.where(good, dXds, 1.0), 0.0, 1.0), s)
    return _Lookup(k, s, inside, dt)


def _hermite(lk: _Lookup, y, dy):
    """Cubic Hermite value of ``y`` (rates ``dy``; leading axes broadcast) at the lookup points."""
    s = lk.s
    s2, s3 = s * s, s * s * s
    k = lk.k
    return ((2 * s3 - 3 * s2 + 1) * y[..., k] + (s3 - 2 * s2 + s) * lk.dt * dy[..., k]
            + (-2 * s3 + 3 * s2) * y[..., k + 1] + (s3 - s2) * lk.dt * dy[..., k + 1])


# --------------------------------------------------------------------------- the model


class GridModel:
    """The distributed LuGre tire (any load of :func:`~tirecli.models.lugre_pde.patch_reduction`) on one grid:
    the exponential-integrator kernel of :func:`tirecli.models.lugre_pde.rhs` (module doc).

    Parameters
    ----------
    drive : Drive
        The kinematics on the grid.
    L : float
        Contact-patch length [m] (fixed: the characteristics lookups depend on it).
    red : PatchReduction or None
        Load reduction (default uniform).
    """

    def __init__(self, drive: Drive, L: float, red: PatchReduction | None = None):
        self.drive = drive
        self.L = float(L)
        self.red = red if red is not None else patch_reduction("uniform")
        self.h = np.diff(drive.t)
        self.vr = drive.vr
        self.cL = np.abs(drive.romega) / self.L
        self.avr = np.abs(self.vr)
        self.lookups = [_lookup(drive, float(u) * self.L) for u in self.red.points]

    def solve(self, sigma0, mu_c, mu_s, v_s, alpha, theta: float = 1.0) -> dict:
        """Grid solution for parameter values: arrays of shape ``(P,)`` (``P`` parameter sets) or scalars.

        Returns ``zbar`` (load-weighted mean deflection ``w.S`` [m]) and ``zdot`` (its rate
        [m/s]), each of shape ``(P, N)``; ``mu = sigma0 zbar + sigma1 zdot + sigma2 vr`` (FM eq. (2)). Also the
        reduced state at the nodes, ``Y`` [m], ``Phi`` [-] and the list ``S`` [m] (``X`` is ``drive.X``), its
        rates ``dY`` [m/s], ``b`` [1/s] and ``dS`` [m/s] (:func:`tirecli.models.lugre_pde.rhs` at the nodes, with
        ``|r omega|`` for ``X``) and the tracked deflections ``z_points`` [m] (one array per point), each ``(P, N)``.
        """
        col = [np.atleast_1d(np.asarray(a, dtype=float))[:, None] for a in (sigma0, mu_c, mu_s, v_s, alpha)]
        s0, mc, ms, vs, al = np.broadcast_arrays(*col)
        e = np.exp(-np.power(self.avr[None, :] / vs, al))
        b = s0 * self.avr[None, :] / (theta * (mc + (ms - mc) * e))       # sigma0 |vr| / (theta g)
        vr = np.broadcast_to(self.vr, b.shape)
        ode_b = LinearODE(self.h, b)
        Y, Phi = ode_b.solve(vr), ode_b.Lam
        dY = vr - b * Y
        zp = []
        for lk in self.lookups:
            Pt = _hermite(lk, Phi, b)
            Yt = _hermite(lk, Y, dY)
            G = np.exp(np.minimum(Pt - Phi, 0.0))
            zp.append(np.where(lk.inside, Y - G * Yt, Y))
        red, cL = self.red, self.cL
        S, dS = [], []
        for j in range(red.size):
            f = red.A[j] * vr - cL * red.Bc[j] * zp[int(red.p[j])]
            for ll in range(j):
                if red.D[j, ll] != 0.0:
                    f = f + cL * red.D[j, ll] * S[ll]
            rate = b - cL * red.D[j, j]                 # D_jj <= 0: transport out of the state's interval
            x = (ode_b if red.D[j, j] == 0.0 else LinearODE(self.h, rate)).solve(f)
            S.append(x)
            dS.append(f - rate * x)
        zbar = sum(w * x for w, x in zip(red.w, S))
        zdot = sum(w * x for w, x in zip(red.w, dS))
        return {"zbar": zbar, "zdot": zdot, "Y": Y, "Phi": Phi, "S": S, "dY": dY, "b": b, "dS": dS, "z_points": zp}


class DrivenDistributed:
    """The distributed LuGre tire driven by sampled kinematics, at the samples (module doc).

    Two grids (``substeps`` and ``2 substeps`` steps per sample interval) and Richardson
    extrapolation ``(4 x_fine - x_coarse)/3`` of the sample values: the second-order error of the
    exponential integrator cancels (measured: max error 6e-7 in mu at 100 Hz samples and
    ``substeps = 4`` on a braking-like drive; tests/test_driven.py).

    Parameters
    ----------
    t, v, romega : array_like
        Sample times [s] (increasing), vehicle speed and ``r omega`` [m/s].
    L : float
        Contact-patch length [m].
    red : PatchReduction or None
        Load reduction (default uniform, FM eq. (3)).
    substeps : int
        Grid steps per sample interval of the coarse grid.
    interpolation : str
        ``cubic`` or ``linear`` (:func:`drive_from_samples`).
    """

    def __init__(self, t, v, romega, L: float, red: PatchReduction | None = None, substeps: int = 4,
                 interpolation: str = "cubic"):
        self.grids = [GridModel(drive_from_samples(t, v, romega, m, interpolation), L, red)
                      for m in (int(substeps), 2 * int(substeps))]
        self.vr = np.asarray(romega, dtype=float) - np.asarray(v, dtype=float)
        self.L = float(L)

    def states(self, sigma0, mu_c, mu_s, v_s, alpha, theta: float = 1.0):
        """``(zbar [m], zdot [m/s])`` at the samples, shape ``(P, n)`` (parameters as :meth:`GridModel.solve`)."""
        out = []
        for g in self.grids:
            sol = g.solve(sigma0, mu_c, mu_s, v_s, alpha, theta)
            idx = g.drive.samples
            out.append((sol["zbar"][:, idx], sol["zdot"][:, idx]))
        (z1, d1), (z2, d2) = out
        return (4.0 * z2 - z1) / 3.0, (4.0 * d2 - d1) / 3.0

    def mu(self, p, theta: float = 1.0) -> np.ndarray:
        """``mu`` [-] at the samples (FM eq. (2)) for a :class:`~tirecli.models.lugre.LuGreParams`.

        Its ``L`` must be ``self.L`` (the lookups were built for it).
        """
        z, zd = self.states(p.sigma0, p.mu_c, p.mu_s, p.v_s, p.alpha, theta)
        return mu_of_deflection(z[0], zd[0], self.vr, p)
