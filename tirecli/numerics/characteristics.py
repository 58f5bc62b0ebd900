"""ROS2 stepper of the quarter car with the distributed LuGre tire, exact along characteristics.

**Model it implements:** :func:`tirecli.models.quarter_car.rhs` / :func:`~tirecli.models.quarter_car.outputs`
with ``QuarterCar(DistributedTire(p, red), car)`` for the free wheel, the same with ``domega/dt = 0`` for the
locked wheel, and :func:`tirecli.models.lugre_pde.rhs` for the tire alone (prescribed ``v``, ``omega``); the
model's input ``z_points`` (the tracked deflections) is read from the stepper's :class:`History`. Inlined as
scalar Python in :meth:`CharacteristicsStepper._eval` and :meth:`CharacteristicsStepper._eval1`. Parity to
1e-12: tests/test_model_parity.py.

See :mod:`tirecli.models.lugre_pde` for the reduction: state
``y = (v, omega, Y, Phi, X, S_0 .. S_{K-1})`` with::

    dY/dt = vr - b Y,   dPhi/dt = b,   dX/dt = |r omega|,
    dS/dt = A vr - b S - (|r omega|/L) (Bc * z(points)[p] - D @ S),
    mu = sigma0 w.S + sigma1 w.dS/dt + sigma2 vr,   m dv/dt = mu F_n,   J domega/dt = -r mu F_n - sigma_w omega + u

and ``z(u_i, t) = Y(t) - exp(Phi(tau_i) - Phi(t)) Y(tau_i)``, ``X(tau_i) = X(t) - u_i L``, read
from the history of accepted steps by cubic Hermite interpolation (the derivatives ``|r omega|``,
``b`` and ``vr - b Y`` are known at every stored step), so the history adds O(h^4) per lookup and
the solver stays second order in the step (the characteristics' spacing).

Jacobian (for the W-method ROS2 of :mod:`tirecli.numerics.ros2`): exact, including the columns of
``Phi`` and ``X`` (through the entry times ``tau_i``: ``dW/dX = G vr(tau)/|r omega(tau)|``, the
entry slope). Dropping only one of them is worse than dropping both: in steady rolling their
effects cancel, and a one-sided Jacobian leaves an O(h) drift. The tire block is lower triangular (``Y``, ``Phi``, ``X`` feed the ``S_j``, which feed later ``S_l``), so a
step solves it by forward substitution and a 2 x 2 system for the wheel and vehicle. Keeping the
trailing-edge coupling ``dS/dY = -(|r omega|/L) Bc`` matters: without it the W-matrix disagrees
with the vehicle rows in the stiff wheel direction and the error estimate degrades to O(h).
"""
from __future__ import annotations

import bisect
import math
from operator import mul

import numpy as np

from tirecli.models.lugre import LuGreParams
from tirecli.models.lugre_pde import PatchReduction
from tirecli.models.vehicle import QuarterCarParams
from tirecli.numerics.ros2 import GAMMA, LOCKED, PRESCRIBED, just_before


#: Weight of the error estimate of ``Phi``: it enters only through differences over one patch
#: transit, and its first-order embedded estimate overstates the (second-order) error of a
#: quadrature of the smooth ``b(t)``; 0.1 leaves the results unchanged (measured) with ~30 % fewer steps.
PHI_WEIGHT = 0.1
#: ``jac`` value of :meth:`CharacteristicsStepper._eval` asking for the outputs without the Jacobian.
OUTPUTS = "outputs"


def _vehicle_wheel(rv, rw, m_r, ghFm, ghrFJ, a11, a12, a21, a22, det, locked):
    """``(k_v, k_w)`` of a W-solve once the tire block is eliminated: the 2 x 2 system of the vehicle and the
    wheel with right-hand side ``(rv + gh Fm m_r, rw - gh rFJ m_r)`` (``m_r``: the friction coefficient's part
    from the tire block; ``a``, ``det``: the system's matrix and determinant); ``k_w = 0`` for a locked wheel."""
    b1 = rv + ghFm * m_r
    b2 = rw - ghrFJ * m_r
    if locked:
        return b1 / a11, 0.0
    return (b1 * a22 - a12 * b2) / det, (a11 * b2 - a21 * b1) / det


class History:
    """The characteristic history: time, travelled length ``X``, ``Phi``, ``Y`` and their rates.

    Each point has the rates the step from it starts with (``dX``, ``dPhi``, ``dY``: right limits) and those
    the step to it ends with (``lX``, ``lPhi``, ``lY``: left limits). They differ where the drive or the
    adhesion jumps (a breakpoint: ``vr``, ``|r omega|`` and ``b`` jump there), and the Hermite interpolant of a
    step takes each end's slope from inside the step: interpolating with the slopes after a jump would
    misplace the elements that entered just before it, by up to one step's worth of the jump.
    Plain lists (appending and bisecting them is cheaper than numpy for one point per step).
    """

    _LISTS = ("t", "X", "Phi", "Y", "dX", "dPhi", "dY", "lX", "lPhi", "lY")

    def __init__(self):
        for name in self._LISTS:
            setattr(self, name, [])

    def put(self, t, X, Phi, Y, dX, dPhi, dY, left=None):
        """Append a point, or replace the last one if it has the same time. ``left``: the left-limit rates
        ``(dX, dPhi, dY)`` at ``t`` when they differ from the right-limit ones (a breakpoint)."""
        if self.t and self.t[-1] >= t:
            for name in self._LISTS:
                getattr(self, name).pop()
        lX, lPhi, lY = (dX, dPhi, dY) if left is None else left
        for name, x in zip(self._LISTS, (t, X, Phi, Y, dX, dPhi, dY, lX, lPhi, lY)):
            getattr(self, name).append(x)

    def arrays(self) -> dict:
        return {k: np.array(getattr(self, k)) for k in self._LISTS}

    def truncate(self, t: float) -> None:
        """Drop the points after ``t`` (a step that is taken back)."""
        while self.t and self.t[-1] > t:
            for name in self._LISTS:
                getattr(self, name).pop()

    def lookup(self, target, now):
        """``(Phi(tau), Y(tau), vr(tau)/|r omega(tau)|)`` where ``X(tau) = target``, ``tau`` in ``[0, t_now]``.

        ``now = (t, X, Phi, Y, dX, dPhi, dY)`` is the current (stage) state. Inside the stored
        history: cubic Hermite in time on the bracketing interval, ``tau`` from one Newton step on
        the Hermite ``X(tau)``; past the last stored point, the current state is the right end.
        ``target <= 0``: an element initially in the patch (``Phi = Y = 0`` at ``tau = 0``). The
        third value is the entry slope ``dz/dzeta`` factor: ``d/dX [e^(Phi(tau)) Y(tau)] =
        e^(Phi(tau)) vr(tau)/|r omega(tau)|`` (0 when the wheel was at rest).
        """
        if target <= 0.0 or not self.t:
            return 0.0, 0.0, 0.0
        Xh = self.X
        k = bisect.bisect_right(Xh, target) - 1
        n = len(Xh)
        if k < 0:
            k = 0
        t0, X0, P0, Y0, dX0, dP0, dY0 = (self.t[k], Xh[k], self.Phi[k], self.Y[k], self.dX[k], self.dPhi[k],
                                         self.dY[k])
        if k >= n - 1:
            t1, X1, P1, Y1, dX1, dP1, dY1 = now
        else:
            k1 = k + 1
            t1, X1, P1, Y1, dX1, dP1, dY1 = (self.t[k1], Xh[k1], self.Phi[k1], self.Y[k1], self.lX[k1],
                                             self.lPhi[k1], self.lY[k1])
        dt = t1 - t0
        dXs = X1 - X0
        if dXs <= 0.0 or dt <= 0.0:
            return P0, Y0, 0.0
        s = (target - X0) / dXs
        s = 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)
        # one Newton step on the Hermite X(s) (X is nearly linear: |r omega| changes little over a step)
        a0, a1 = dt * dX0, dt * dX1
        s2 = s * s
        s3 = s2 * s
        Xs = (2 * s3 - 3 * s2 + 1) * X0 + (s3 - 2 * s2 + s) * a0 + (-2 * s3 + 3 * s2) * X1 + (s3 - s2) * a1
        dXds = (6 * s2 - 6 * s) * (X0 - X1) + (3 * s2 - 4 * s + 1) * a0 + (3 * s2 - 2 * s) * a1
        if dXds > 0.0:
            s -= (Xs - target) / dXds
            s = 0.0 if s < 0.0 else (1.0 if s > 1.0 else s)
            s2 = s * s
            s3 = s2 * s
        h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, -2 * s3 + 3 * s2, s3 - s2
        Yt = h00 * Y0 + h10 * dt * dY0 + h01 * Y1 + h11 * dt * dY1
        ct = dX0 + s * (dX1 - dX0)
        vrt = dY0 + s * (dY1 - dY0) + (dP0 + s * (dP1 - dP0)) * Yt   # vr = dY/dt + b Y
        return h00 * P0 + h10 * dt * dP0 + h01 * P1 + h11 * dt * dP1, Yt, (vrt / ct if ct > 1e-9 else 0.0)


class CharacteristicsStepper:
    """Quarter car (or tire alone) with the distributed LuGre tire (module doc).

    Parameters as :class:`tirecli.numerics.lumped.LumpedStepper`, with ``red`` the
    :class:`~tirecli.models.lugre_pde.PatchReduction` of the normal-load density. Scalar Python
    with loops over the few tire states; with one (the uniform and exponential loads) the right-hand
    side and the step are :meth:`_eval1` and :meth:`_attempt1`, the same arithmetic without the loops
    (bit for bit the same runs, in about 60 % of the time).
    """

    out_names = ("vr", "mu", "zbar", "zdot", "torque", "brake_torque", "theta", "kappa0", "locked", "z_trailing",
                 "dv", "domega")

    def __init__(self, p: LuGreParams, car: QuarterCarParams, red: PatchReduction, torque, theta,
                 v_of_t=None, omega_of_t=None, tol: float = 1e-4):
        self.p, self.car, self.red = p, car, red
        self.U, self.TH = torque, theta
        self.V, self.W = v_of_t, omega_of_t
        self.tol = tol
        K = red.size
        self.K = K
        self.y_names = ("v", "omega", "Y", "Phi", "X") + tuple(f"S{j}" for j in range(K))
        self.hist = History()
        s0 = p.sigma0
        # error weights (1/tol in the units of each state): speeds in m/s, deflections in friction
        # units (sigma0 z), Phi dimensionless, X relative to L; the patch states S_j no less than by their effect
        # on the friction, |d mu/dS_j| (``mu_q`` of the Jacobian: sigma0 w_j - sigma1 (b w_j - ...), many times
        # sigma0 w_j when the bristles are stiff, sigma1 b >> sigma0: sliding or a locked wheel; lumped.py)
        scale = [1.0, car.r, s0, PHI_WEIGHT, 1.0 / p.L] + [s0 * max(1.0, abs(float(x))) for x in red.w]
        self.iscale = [x / tol for x in scale]
        self.itol = 1.0 / tol
        self.points = [float(x) * p.L for x in red.points]
        self.pidx = [int(i) for i in red.p]
        self.A = [float(x) for x in red.A]
        self.Bc = [float(x) for x in red.Bc]
        self.w = [float(x) for x in red.w]
        self.Drows = [[(l, float(red.D[j, l])) for l in range(K) if red.D[j, l] != 0.0] for j in range(K)]
        self.Ddiag = [float(red.D[j, j]) for j in range(K)]
        self.DTw = [float(x) for x in red.D.T @ red.w]
        self.wBc = [a * b for a, b in zip(self.w, self.Bc)]
        self.sum_wBc = sum(self.wBc)
        self.uniform = red.uniform
        self._cache = [None, 0.0, 1.0]
        self._left = None   # (t, dX, dPhi, dY): left-limit rates at a breakpoint t, for the history point there
        if K == 1 and len(self.points) == 1:  # one tire state, one tracked point (uniform load): no loops
            self._eval, self.attempt = self._eval1, self._attempt1

    # ------------------------------------------------------------------ inputs

    def inputs(self, t):
        c = self._cache
        if t == c[0]:
            return c[1], c[2]
        u, th = self.U(t), self.TH(t)
        c[0], c[1], c[2] = t, u, th
        return u, th

    # ------------------------------------------------------------------ model

    def _slip(self, v, w, th):
        """The slip terms at vehicle speed ``v`` [m/s], wheel speed ``w`` [rad/s] and adhesion ``th``:
        ``c = |r omega|``, ``vr = r omega - v`` [m/s], ``qa = (|vr|/v_s)^alpha``, ``e = exp(-qa)``,
        ``g = th (mu_c + (mu_s - mu_c) e)`` and the bristle rate ``b = sigma0 |vr| / g`` [1/s]."""
        p, r = self.p, self.car.r
        c = r * w if w >= 0.0 else -r * w
        vr = r * w - v
        avr = vr if vr >= 0.0 else -vr
        qa = avr / p.v_s
        if p.alpha != 1.0:
            qa = qa * qa if p.alpha == 2.0 else qa ** p.alpha
        e = math.exp(-qa)
        g = th * (p.mu_c + (p.mu_s - p.mu_c) * e)
        return c, vr, qa, e, g, p.sigma0 * avr / g

    def _forces(self, zw, zwd, vr, w, u, mode):
        """``(mu, F, dv/dt, domega/dt)`` from the weighted deflection ``zw`` and its rate ``zwd``:
        ``mu = sigma0 zw + sigma1 zwd + sigma2 vr``, ``F = mu F_n`` [N], ``m dv/dt = F``,
        ``J domega/dt = -r F - sigma_w omega + u`` (0 for a locked wheel; both 0 when prescribed)."""
        p, car = self.p, self.car
        mu = p.sigma0 * zw + p.sigma1 * zwd + p.sigma2 * vr
        F = mu * car.F_n
        if mode == PRESCRIBED:
            return mu, F, 0.0, 0.0
        return mu, F, F / car.m, 0.0 if mode == LOCKED else (-car.r * F - p.sigma_w * w + u) / car.J

    def _eval(self, t, y, u, th, mode, jac):
        """Right-hand side at one state; with ``jac``: ``(f, Jacobian pieces, outputs)``, with ``jac`` =
        :data:`OUTPUTS`: ``(f, None, outputs)`` (what the dense output needs, without the Jacobian)."""
        p, car = self.p, self.car
        r, L = car.r, p.L
        v, w, Y, Phi, X = y[0], y[1], y[2], y[3], y[4]
        S = y[5:]
        K = self.K
        c, vr, qa, e, g, b = self._slip(v, w, th)
        dY = vr - b * Y
        now = (t, X, Phi, Y, c, b, dY)
        lookup = self.hist.lookup
        Wp, zp, dWX = [], [], []
        for d in self.points:
            Pt, Yt, slope = lookup(X - d, now)
            ex = Pt - Phi
            G = math.exp(ex if ex < 0.0 else 0.0)
            Wi = G * Yt
            Wp.append(Wi)
            zp.append(Y - Wi)
            dWX.append(G * slope)
        cL = c / L
        A, Bc, pidx, Drows = self.A, self.Bc, self.pidx, self.Drows
        trans = [Bc[j] * zp[pidx[j]] - sum([val * S[l] for l, val in Drows[j]]) for j in range(K)]
        dS = [A[j] * vr - b * S[j] - cL * trans[j] for j in range(K)]
        wv = self.w
        zw = sum(map(mul, wv, S))
        zwd = sum(map(mul, wv, dS))
        mu, F, fv, fw = self._forces(zw, zwd, vr, w, u, mode)
        f = [fv, fw, dY, b, c] + dS
        if not jac:
            return f
        zL = zp[-1]
        k0 = zL / zw if (self.uniform and zw != 0.0) else math.nan
        out = (vr, mu, zw, zwd, u, th, k0, zL, F)
        if jac is OUTPUTS:
            return f, None, out
        sg = 1.0 if vr > 0.0 else (-1.0 if vr < 0.0 else 0.0)
        dbdvr = (p.sigma0 * sg / g) * (1.0 + th * (p.mu_s - p.mu_c) * e * p.alpha * qa / g)
        dbdth = -b / th
        ws = 1.0 if w >= 0.0 else -1.0
        # tire-state rows (Y, Phi, X, S_j): partials in vr, c = |r omega| and theta, and the diagonal
        q_vr = [1.0 - Y * dbdvr, dbdvr, 0.0] + [A[j] - S[j] * dbdvr for j in range(K)]
        q_c = [0.0, 0.0, 1.0] + [-trans[j] / L for j in range(K)]
        q_th = [-Y * dbdth, dbdth, 0.0] + [-S[j] * dbdth for j in range(K)]
        diag = [-b, 0.0, 0.0] + [-b + cL * dd for dd in self.Ddiag]
        Jqv = [-x for x in q_vr]
        Jqw = [r * (a + ws * cc) for a, cc in zip(q_vr, q_c)]
        # couplings of S_j to Y, Phi (through the tracked deflections) and to earlier S_l (D is
        # strictly lower triangular off its diagonal): the tire block is lower triangular
        SY = [-cL * Bc[j] for j in range(K)]
        SPhi = [-cL * Bc[j] * Wp[pidx[j]] for j in range(K)]
        SX = [cL * Bc[j] * dWX[pidx[j]] for j in range(K)]
        SS = [[(l, cL * val) for l, val in Drows[j] if l != j] for j in range(K)]
        s1 = p.sigma1
        wd_vr = sum(map(mul, wv, q_vr[3:]))
        wd_c = sum(map(mul, wv, q_c[3:]))
        wd_th = sum(map(mul, wv, q_th[3:]))
        wBc = self.wBc
        mu_q = [-s1 * cL * self.sum_wBc, -s1 * cL * sum([wBc[j] * Wp[pidx[j]] for j in range(K)]),
                s1 * cL * sum([wBc[j] * dWX[pidx[j]] for j in range(K)])] + \
               [p.sigma0 * wv[j] + s1 * (-b * wv[j] + cL * self.DTw[j]) for j in range(K)]
        mu_v = -(s1 * wd_vr + p.sigma2)
        mu_w = r * (s1 * (wd_vr + ws * wd_c) + p.sigma2)
        mu_th = s1 * wd_th
        return f, (Jqv, Jqw, q_th, diag, SY, SPhi, SX, SS, mu_q, mu_v, mu_w, mu_th), out

    def _eval1(self, t, y, u, th, mode, jac):
        """:meth:`_eval` for one tire state and one tracked point (``K = 1``): the same operations in the
        same order on scalars (the same values to the last bit), without the loops over the states."""
        p, car = self.p, self.car
        r, L = car.r, p.L
        v, w, Y, Phi, X, S0 = y
        c, vr, qa, e, g, b = self._slip(v, w, th)
        dY = vr - b * Y
        Pt, Yt, slope = self.hist.lookup(X - self.points[0], (t, X, Phi, Y, c, b, dY))
        ex = Pt - Phi
        G = math.exp(ex if ex < 0.0 else 0.0)
        Wp0 = G * Yt
        zp0 = Y - Wp0
        cL = c / L
        Bc0 = self.Bc[0]
        d00 = self.Ddiag[0]
        trans0 = Bc0 * zp0 - (0.0 + d00 * S0 if d00 != 0.0 else 0)  # the general sum over D's row
        dS0 = self.A[0] * vr - b * S0 - cL * trans0
        w0 = self.w[0]
        zw = 0.0 + w0 * S0
        zwd = 0.0 + w0 * dS0
        mu, F, fv, fw = self._forces(zw, zwd, vr, w, u, mode)
        f = [fv, fw, dY, b, c, dS0]
        if not jac:
            return f
        k0 = zp0 / zw if (self.uniform and zw != 0.0) else math.nan
        out = (vr, mu, zw, zwd, u, th, k0, zp0, F)
        if jac is OUTPUTS:
            return f, None, out
        dWX0 = G * slope
        A0 = self.A[0]
        sg = 1.0 if vr > 0.0 else (-1.0 if vr < 0.0 else 0.0)
        dbdvr = (p.sigma0 * sg / g) * (1.0 + th * (p.mu_s - p.mu_c) * e * p.alpha * qa / g)
        dbdth = -b / th
        ws = 1.0 if w >= 0.0 else -1.0
        q_vr = [1.0 - Y * dbdvr, dbdvr, 0.0, A0 - S0 * dbdvr]
        q_c = [0.0, 0.0, 1.0, -trans0 / L]
        q_th = [-Y * dbdth, dbdth, 0.0, -S0 * dbdth]
        diag = [-b, 0.0, 0.0, -b + cL * d00]
        Jqv = [-x for x in q_vr]
        Jqw = [r * (a + ws * cc) for a, cc in zip(q_vr, q_c)]
        s1 = p.sigma1
        wBc0 = self.wBc[0]
        mu_q = [-s1 * cL * self.sum_wBc, -s1 * cL * (0.0 + wBc0 * Wp0), s1 * cL * (0.0 + wBc0 * dWX0),
                p.sigma0 * w0 + s1 * (-b * w0 + cL * self.DTw[0])]
        mu_v = -(s1 * (0.0 + w0 * q_vr[3]) + p.sigma2)
        mu_w = r * (s1 * ((0.0 + w0 * q_vr[3]) + ws * (0.0 + w0 * q_c[3])) + p.sigma2)
        mu_th = s1 * (0.0 + w0 * q_th[3])
        return f, (Jqv, Jqw, q_th, diag, [-cL * Bc0], [-cL * Bc0 * Wp0], [cL * Bc0 * dWX0], [[]], mu_q, mu_v,
                   mu_w, mu_th), out

    # ------------------------------------------------------------------ stepper API

    def start(self, t, y, mode):
        E = self.peek(t, y, mode)
        t, y, u, th, mode, f = E[:6]
        left = self._left   # kept while the run restarts at this time (a released wheel: start again, free)
        left = left[1:] if left is not None and abs(left[0] - t) <= 1e-12 * max(1.0, abs(t)) else None
        self.hist.put(t, y[4], y[3], y[2], f[4], f[3], f[2], left)
        return E

    def peek(self, t, y, mode, jac=True):
        """``start`` without recording ``(t, y)`` in the history (a step from a point of a finished run);
        ``jac=OUTPUTS``: a record without the Jacobian (for :meth:`outputs`, not for a step)."""
        y = [float(x) for x in y]
        u, th = self.inputs(t)
        if mode == PRESCRIBED:
            y[0], y[1] = self.V(t), self.W(t)
        f, J, out = self._eval(t, y, u, th, mode, jac)
        return (t, y, u, th, mode, f, J, out)

    def attempt(self, E, h, left=False):
        t, y, u0, th0, mode, f, (Jqv, Jqw, q_th, diag, SY, SPhi, SX, SS, mu_q, mu_v, mu_w, mu_th), out = E
        car = self.car
        J, Fm, rFJ = car.J, car.F_n / car.m, car.r * car.F_n / car.J
        K = self.K
        t1 = t + h
        tl = just_before(t1, h) if left else t1   # a step ending on a breakpoint: the left limits there (lumped.py)
        u1, th1 = (self.U(tl), self.TH(tl)) if left else self.inputs(t1)
        ud, thd = (u1 - u0) / h, (th1 - th0) / h
        gh = GAMMA * h
        nq = len(diag)
        dq = [1.0 / (1.0 - gh * d) for d in diag]
        ftq = [x * thd for x in q_th]

        def tire(rq):
            """Forward substitution through the lower-triangular tire block: k_q = base_q + cv_q kv + cw_q kw."""
            base = [rq[0] * dq[0], rq[1], rq[2]]
            for j in range(K):
                acc = rq[3 + j] + gh * (SY[j] * base[0] + SPhi[j] * base[1] + SX[j] * base[2])
                for l, val in SS[j]:
                    acc += gh * val * base[3 + l]
                base.append(acc * dq[3 + j])
            return base

        # coefficients of kv, kw in k_q (independent of the right-hand side)
        cv = [gh * Jqv[0] * dq[0], gh * Jqv[1], gh * Jqv[2]]
        cw = [gh * Jqw[0] * dq[0], gh * Jqw[1], gh * Jqw[2]]
        for j in range(K):
            av = gh * (Jqv[3 + j] + SY[j] * cv[0] + SPhi[j] * cv[1] + SX[j] * cv[2])
            aw = gh * (Jqw[3 + j] + SY[j] * cw[0] + SPhi[j] * cw[1] + SX[j] * cw[2])
            for l, val in SS[j]:
                av += gh * val * cv[3 + l]
                aw += gh * val * cw[3 + l]
            cv.append(av * dq[3 + j])
            cw.append(aw * dq[3 + j])
        if mode == PRESCRIBED:
            # v, omega: pseudo-states with the secant slopes as right-hand side, no Jacobian row
            ftv = ftw = 0.0
            f = [(self.V(tl) - y[0]) / h, (self.W(tl) - y[1]) / h] + f[2:]

            def solve(rv, rw, rq):
                base = tire(rq)
                return rv, rw, [base[i] + cv[i] * rv + cw[i] * rw for i in range(nq)]
        else:
            ftv, ftw = Fm * mu_th * thd, -rFJ * mu_th * thd + ud / J
            Jvv, Jvw = Fm * mu_v, Fm * mu_w
            Jwv, Jww = -rFJ * mu_v, -rFJ * mu_w - self.p.sigma_w / J
            sv_ = sum(map(mul, mu_q, cv))
            sw_ = sum(map(mul, mu_q, cw))
            a11 = 1.0 - gh * Jvv - gh * Fm * sv_
            a12 = -gh * Jvw - gh * Fm * sw_
            a21 = -gh * Jwv + gh * rFJ * sv_
            a22 = 1.0 - gh * Jww + gh * rFJ * sw_
            det = a11 * a22 - a12 * a21
            locked = mode == LOCKED

            def solve(rv, rw, rq):
                base = tire(rq)
                kv, kw = _vehicle_wheel(rv, rw, sum(map(mul, mu_q, base)), gh * Fm, gh * rFJ, a11, a12, a21, a22, det,
                                        locked)
                return kv, kw, [base[i] + cv[i] * kv + cw[i] * kw for i in range(nq)]
        k1v, k1w, k1q = solve(f[0] + gh * ftv, f[1] + gh * ftw, [f[2 + i] + gh * ftq[i] for i in range(nq)])
        y2 = [y[0] + h * k1v, y[1] + h * k1w] + [y[2 + i] + h * k1q[i] for i in range(nq)]
        f2 = self._eval(t1, y2, u1, th1, mode, False)
        if mode == PRESCRIBED:
            f2[0], f2[1] = f[0], f[1]
        k2v, k2w, k2q = solve(f2[0] - 2.0 * k1v - gh * ftv, f2[1] - 2.0 * k1w - gh * ftw,
                              [f2[2 + i] - 2.0 * k1q[i] - gh * ftq[i] for i in range(nq)])
        sc = self.iscale
        it = self.itol
        err = max(abs(k1v + k2v) * sc[0], abs(k1w + k2w) * sc[1],
                  max(abs(k1q[i] + k2q[i]) * sc[2 + i] for i in range(3)),
                  max(abs(k1q[i] + k2q[i]) * max(sc[2 + i], abs(mu_q[i]) * it) for i in range(3, nq)))
        y_new = [y[0] + h * (1.5 * k1v + 0.5 * k2v), y[1] + h * (1.5 * k1w + 0.5 * k2w)] + \
                [y[2 + i] + h * (1.5 * k1q[i] + 0.5 * k2q[i]) for i in range(nq)]
        if mode == PRESCRIBED and left:   # the kinematics at t1 as the next step starts (right limits)
            y_new[0], y_new[1] = self.V(t1), self.W(t1)
        return y_new, 0.5 * h * err

    def _attempt1(self, E, h, left=False):
        """:meth:`attempt` for one tire state (``K = 1``, see :meth:`_eval1`): the same operations in the
        same order on scalars (the same step to the last bit)."""
        t, y, u0, th0, mode, f, (Jqv, Jqw, q_th, diag, SY, SPhi, SX, SS, mu_q, mu_v, mu_w, mu_th), out = E
        car = self.car
        J, Fm, rFJ = car.J, car.F_n / car.m, car.r * car.F_n / car.J
        t1 = t + h
        tl = just_before(t1, h) if left else t1   # a step ending on a breakpoint: the left limits there (lumped.py)
        u1, th1 = (self.U(tl), self.TH(tl)) if left else self.inputs(t1)
        ud, thd = (u1 - u0) / h, (th1 - th0) / h
        gh = GAMMA * h
        dq0, dq3 = 1.0 / (1.0 - gh * diag[0]), 1.0 / (1.0 - gh * diag[3])
        ft0, ft1, ft2, ft3 = q_th[0] * thd, q_th[1] * thd, q_th[2] * thd, q_th[3] * thd
        sy, sphi, sx = SY[0], SPhi[0], SX[0]
        # coefficients of kv, kw in k_q (the tire block solved by forward substitution)
        cv0, cv1, cv2 = gh * Jqv[0] * dq0, gh * Jqv[1], gh * Jqv[2]
        cw0, cw1, cw2 = gh * Jqw[0] * dq0, gh * Jqw[1], gh * Jqw[2]
        cv3 = gh * (Jqv[3] + sy * cv0 + sphi * cv1 + sx * cv2) * dq3
        cw3 = gh * (Jqw[3] + sy * cw0 + sphi * cw1 + sx * cw2) * dq3
        prescribed, locked = mode == PRESCRIBED, mode == LOCKED
        if prescribed:
            ftv = ftw = 0.0
            f = [(self.V(tl) - y[0]) / h, (self.W(tl) - y[1]) / h] + f[2:]
        else:
            mq0, mq1, mq2, mq3 = mu_q
            ftv, ftw = Fm * mu_th * thd, -rFJ * mu_th * thd + ud / J
            Jvv, Jvw = Fm * mu_v, Fm * mu_w
            Jwv, Jww = -rFJ * mu_v, -rFJ * mu_w - self.p.sigma_w / J
            sv_ = 0.0 + mq0 * cv0 + mq1 * cv1 + mq2 * cv2 + mq3 * cv3
            sw_ = 0.0 + mq0 * cw0 + mq1 * cw1 + mq2 * cw2 + mq3 * cw3
            a11 = 1.0 - gh * Jvv - gh * Fm * sv_
            a12 = -gh * Jvw - gh * Fm * sw_
            a21 = -gh * Jwv + gh * rFJ * sv_
            a22 = 1.0 - gh * Jww + gh * rFJ * sw_
            det = a11 * a22 - a12 * a21

        def solve(rv, rw, r0, r1, r2, r3):
            b0 = r0 * dq0
            b3 = (r3 + gh * (sy * b0 + sphi * r1 + sx * r2)) * dq3
            if prescribed:
                kv, kw = rv, rw
            else:
                kv, kw = _vehicle_wheel(rv, rw, 0.0 + mq0 * b0 + mq1 * r1 + mq2 * r2 + mq3 * b3, gh * Fm, gh * rFJ,
                                        a11, a12, a21, a22, det, locked)
            return (kv, kw, b0 + cv0 * kv + cw0 * kw, r1 + cv1 * kv + cw1 * kw, r2 + cv2 * kv + cw2 * kw,
                    b3 + cv3 * kv + cw3 * kw)

        v0, w0, Y0, P0, X0, S0 = y
        k1v, k1w, k10, k11, k12, k13 = solve(f[0] + gh * ftv, f[1] + gh * ftw, f[2] + gh * ft0, f[3] + gh * ft1,
                                             f[4] + gh * ft2, f[5] + gh * ft3)
        y2 = [v0 + h * k1v, w0 + h * k1w, Y0 + h * k10, P0 + h * k11, X0 + h * k12, S0 + h * k13]
        f2 = self._eval1(t1, y2, u1, th1, mode, False)
        if prescribed:
            f2[0], f2[1] = f[0], f[1]
        k2v, k2w, k20, k21, k22, k23 = solve(f2[0] - 2.0 * k1v - gh * ftv, f2[1] - 2.0 * k1w - gh * ftw,
                                             f2[2] - 2.0 * k10 - gh * ft0, f2[3] - 2.0 * k11 - gh * ft1,
                                             f2[4] - 2.0 * k12 - gh * ft2, f2[5] - 2.0 * k13 - gh * ft3)
        sc = self.iscale
        w3 = abs(mu_q[3]) * self.itol
        err = max(abs(k1v + k2v) * sc[0], abs(k1w + k2w) * sc[1],
                  max(abs(k10 + k20) * sc[2], abs(k11 + k21) * sc[3], abs(k12 + k22) * sc[4],
                      abs(k13 + k23) * (w3 if w3 > sc[5] else sc[5])))
        y_new = [v0 + h * (1.5 * k1v + 0.5 * k2v), w0 + h * (1.5 * k1w + 0.5 * k2w), Y0 + h * (1.5 * k10 + 0.5 * k20),
                 P0 + h * (1.5 * k11 + 0.5 * k21), X0 + h * (1.5 * k12 + 0.5 * k22), S0 + h * (1.5 * k13 + 0.5 * k23)]
        if prescribed and left:
            y_new[0], y_new[1] = self.V(t1), self.W(t1)
        return y_new, 0.5 * h * err

    def holds(self, E):
        u, F = E[2], E[7][-1]
        return u < 0.0 and -self.car.r * F <= -u

    # ------------------------------------------------------------------ dense output and events

    @staticmethod
    def _left_of(t):
        return just_before(t, max(abs(t), 1e-3))

    def _inputs_at(self, t, left):
        if not left:
            return self.inputs(t)
        tl = self._left_of(t)
        return self.U(tl), self.TH(tl)

    @staticmethod
    def deriv(E) -> list:
        """The right-hand side of a ``start`` record."""
        return list(E[5])

    def rhs_at(self, t, y, mode, left=False):
        """Right-hand side at ``(t, y)`` (``left``: the inputs' and prescribed kinematics' left limits). The
        history is not changed, but the left-limit rates of ``X``, ``Phi``, ``Y`` are kept for the history
        point at ``t`` that the next :meth:`start` records (the integrator asks for them when a step ends on
        a breakpoint, before the next step starts there)."""
        u, th = self._inputs_at(t, left)
        y = [float(x) for x in y]
        if mode == PRESCRIBED:
            tk = self._left_of(t) if left else t
            y[0], y[1] = self.V(tk), self.W(tk)
        f = self._eval(t, y, u, th, mode, False)
        if left:
            self._left = (t, f[4], f[3], f[2])
        return f

    def lock_margin(self, t, y, left=False):
        """``min(T_b, T_b - |r F|)`` at ``(t, y)`` with the wheel locked (>= 0 while the brake holds)."""
        u, th = self._inputs_at(t, left)
        y = [float(x) for x in y]
        y[1] = 0.0
        F = self._eval(t, y, u, th, LOCKED, OUTPUTS)[2][-1]
        return min(-u, self.car.r * F - u)

    def evaluate(self, t, y, mode):
        """``(state, outputs)`` at ``(t, y)`` in ``mode``, without touching the history."""
        E = self.peek(t, y, mode, OUTPUTS)
        return E[1], self.outputs(E)

    def rollback(self, t: float) -> None:
        """Forget the history after ``t`` (a step that is taken back)."""
        self.hist.truncate(t)

    def outputs(self, E):
        t, y, u, th, mode, f, J, out = E
        vr, mu, zw, zwd, u, th, k0, zL, F = out
        tb = -u if u < 0.0 else 0.0
        if mode == LOCKED:
            u = self.car.r * F
        return (vr, mu, zw, zwd, u, tb, th, k0, 1.0 if mode == LOCKED else 0.0, zL, f[0], f[1])
