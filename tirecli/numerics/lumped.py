"""ROS2 stepper of the quarter car with the averaged lumped LuGre tire (FM eqs. (8)-(10); docs/models/lugre_friction.md §4, §7).

**Model it implements:** :func:`tirecli.models.quarter_car.rhs` / :func:`~tirecli.models.quarter_car.outputs`
with ``QuarterCar(LumpedTire(p, kappa0), car)`` (``sigma2_in_wheel=True``, FM's form) for the free wheel,
the same with ``domega/dt = 0`` for the locked wheel, and :func:`tirecli.models.lugre_lumped.rhs` for the
tire alone (prescribed ``v``, ``omega``); inlined as scalar Python (``core``/``rhs``) and again on numpy
arrays for the dense output (``dense``). Parity to 1e-12: tests/test_model_parity.py.

State ``y = (v [m/s], omega [rad/s], z [m])``::

    dz/dt = vr - a z,      a = sigma0 |vr| / (theta g(vr)) + kappa0 |r omega| / L
    mu = sigma0 z + sigma1 dz/dt + sigma2 vr,      F = mu F_n
    m dv/dt = F,           J domega/dt = -r F - sigma_w omega + u

with ``kappa0`` a constant or ``kappa0(Z)`` of FM eq. (10) (then ``a`` depends on ``x = L/Z``).
The steps are plain scalar Python (a 5 s braking takes a few hundred steps; numpy calls would
cost more than the arithmetic); the dense output at thousands of output times repeats the same
arithmetic on numpy arrays over the times (``dense``). The Jacobian is exact, including ``d a/d vr``: in sliding the
bristle rate barely responds to ``vr`` (``1 - z da/dvr ~ 0``), and a frozen-``a`` Jacobian would
over-damp the wheel mode. At ``vr = 0`` the derivative of ``|vr|`` is taken as 0; at
``r omega = 0`` the ``kappa`` term vanishes (no division by ``omega`` anywhere).
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.models.lugre import LuGreParams
from tirecli.models.vehicle import QuarterCarParams
from tirecli.numerics.ros2 import GAMMA, LOCKED, PRESCRIBED, just_before

_X_SERIES = 1e-4


def kappa0_and_slope(x: float) -> tuple[float, float]:
    """``kappa0(x)`` of FM eq. (10) and ``d kappa0/dx`` at one ``x = L/Z >= 0`` [-] (scalar form of
    :func:`tirecli.models.lugre.kappa0_of_x` with its slope, for the stepper's exact Jacobian).

    ``kappa0 = (1 - e^-x)/h(x)``, ``h = 1 - (1 - e^-x)/x``; series ``2 - x/3 + x^2/18`` near 0,
    ``kappa0 -> 1`` for ``x -> inf``.
    """
    if x < _X_SERIES:
        return 2.0 - x / 3.0 + x * x / 18.0, -1.0 / 3.0 + x / 9.0
    if x > 1e12:
        return 1.0, 0.0
    E = math.exp(-x)
    q = -math.expm1(-x)
    hx = 1.0 - q / x
    hp = (q - x * E) / (x * x)
    return q / hx, (E * hx - q * hp) / (hx * hx)


class LumpedStepper:
    """Quarter car (or tire alone, prescribed ``v``, ``omega``) with the lumped LuGre tire: the ROS2 kernel of
    :func:`tirecli.models.quarter_car.rhs` (module doc).

    Parameters
    ----------
    p : LuGreParams
        Tire (``sigma_w`` of the wheel bearing included).
    car : QuarterCarParams
        Radius, quarter mass, wheel inertia, normal load.
    kappa0 : float or "Z"
        Constant lumped coefficient or ``"Z"`` for FM eq. (10).
    torque : callable
        ``torque(t) -> u`` [N m], signed wheel torque (> 0 drives, < 0 brakes); the braking part
        ``T_b = max(-u, 0)`` cannot turn the wheel backwards.
    theta : callable
        ``theta(t)`` [-], adhesion in the FM convention (``g -> theta g``).
    v_of_t, omega_of_t : callable or None
        Prescribed vehicle and wheel speeds [m/s], [rad/s] (open loop).
    tol : float
        Error tolerance (m/s for speeds, friction units for ``z``).
    """

    y_names = ("v", "omega", "z")
    out_names = ("vr", "mu", "zdot", "torque", "brake_torque", "theta", "kappa0", "locked", "dv", "domega")

    def __init__(self, p: LuGreParams, car: QuarterCarParams, kappa0, torque, theta,
                 v_of_t=None, omega_of_t=None, tol: float = 1e-4):
        self.p, self.car = p, car
        self.kappa0 = kappa0
        self.torque, self.theta = torque, theta
        self.v_of_t, self.omega_of_t = v_of_t, omega_of_t
        self.tol = tol
        self._build()

    def _build(self):  # noqa: C901 - one closure per hot function, constants bound as cells
        p, car = self.p, self.car
        s0, s1, s2 = p.sigma0, p.sigma1, p.sigma2
        mc, dmu, vs, L, al = p.mu_c, p.mu_s - p.mu_c, p.v_s, p.L, p.alpha
        sw = p.sigma_w
        r, m, J, Fn = car.r, car.m, car.J, car.F_n
        Fm, rFJ = Fn / m, r * Fn / J
        zmode = self.kappa0 == "Z"
        K0 = 2.0 if zmode else float(self.kappa0)
        U0, TH0 = self.torque, self.theta
        cache = [None, 0.0, 1.0]  # (t, u, theta) of the last evaluation: a step's end is the next start

        def inputs(t):
            if t == cache[0]:
                return cache[1], cache[2]
            u, th = U0(t), TH0(t)
            cache[0], cache[1], cache[2] = t, u, th
            return u, th
        V, W = self.v_of_t, self.omega_of_t
        exp, expm1 = math.exp, math.expm1
        # error scales: speeds in m/s; z by its effect on the friction, |d mu/dz| = |sigma0 - sigma1 a| (no less
        # than sigma0): with the bristles stiff (sigma1 a >> sigma0, sliding or locked) an error of z shows in mu
        # through sigma1 dz/dt = sigma1 (vr - a z) many times larger than through sigma0 z
        iv, iw, iz, is1 = 1.0 / self.tol, r / self.tol, s0 / self.tol, s1 / self.tol

        def core(v, w, z, th):
            """a, da/dvr-factors and friction at one state (shared by the stage evaluations)."""
            c = r * w if w > 0.0 else -r * w
            vr = r * w - v
            avr = vr if vr > 0.0 else -vr
            qa = avr / vs
            if al != 1.0:
                qa = qa * qa if al == 2.0 else qa ** al
            e = exp(-qa)
            g = th * (mc + dmu * e)
            b = s0 * avr / g
            if zmode and c > 0.0:
                x = b * L / c
                if x < _X_SERIES:
                    k0, k0p = 2.0 - x / 3.0 + x * x / 18.0, -1.0 / 3.0 + x / 9.0
                elif x > 1e12:
                    k0, k0p = 1.0, 0.0
                else:  # kappa0_and_slope, inlined
                    E = exp(-x)
                    q = -expm1(-x)
                    hx = 1.0 - q / x
                    k0 = q / hx
                    k0p = (E * hx - q * (q - x * E) / (x * x)) / (hx * hx)
            else:
                x, k0, k0p = 0.0, (1.0 if zmode else K0), 0.0
            a = b + k0 * c / L
            zd = vr - a * z
            mu = s0 * z + s1 * zd + s2 * vr
            return c, vr, avr, qa, e, g, b, x, k0, k0p, a, zd, mu

        def rhs(t, v, w, z, u, th, mode):
            c, vr, avr, qa, e, g, b, x, k0, k0p, a, zd, mu = core(v, w, z, th)
            F = mu * Fn
            if mode == PRESCRIBED:
                return 0.0, 0.0, zd
            fw = 0.0 if mode == LOCKED else (-r * F - sw * w + u) / J
            return F / m, fw, zd

        def start(t, y, mode):
            v, w, z = y
            u, th = inputs(t)
            if mode == PRESCRIBED:
                v, w = V(t), W(t)
            c, vr, avr, qa, e, g, b, x, k0, k0p, a, zd, mu = core(v, w, z, th)
            F = mu * Fn
            sg = 1.0 if vr > 0.0 else (-1.0 if vr < 0.0 else 0.0)
            dbdvr = (s0 * sg / g) * (1.0 + th * dmu * e * al * qa / g)
            if zmode:
                dadb = 1.0 + k0p
                dadc = (k0 - x * k0p) / L
            else:
                dadb, dadc = 1.0, k0 / L
            dzvr = 1.0 - z * dbdvr * dadb
            dzc = -z * dadc
            dzth = z * (b / th) * dadb          # -z da/dtheta, da/dtheta = -(b/theta) da/db
            ws = 1.0 if w >= 0.0 else -1.0
            Jzv, Jzw, Jzz = -dzvr, r * (dzvr + ws * dzc), -a
            dmv = -(s1 * dzvr + s2)
            dmw = r * (s1 * (dzvr + ws * dzc) + s2)
            dmz = s0 - s1 * a
            dmth = s1 * dzth
            if mode == PRESCRIBED:
                fv = fw = 0.0
            else:
                fv = F / m
                fw = 0.0 if mode == LOCKED else (-r * F - sw * w + u) / J
            jac = (Fm * dmv, Fm * dmw, Fm * dmz, -rFJ * dmv, -rFJ * dmw - sw / J, -rFJ * dmz,
                   Jzv, Jzw, Jzz, Fm * dmth, -rFJ * dmth, dzth)
            return (t, v, w, z, u, th, mode, fv, fw, zd, jac, vr, mu, F, k0)

        def attempt(E, h, left=False):
            t, v, w, z, u0, th0, mode, fv, fw, fz, jac, *_ = E
            Jvv, Jvw, Jvz, Jwv, Jww, Jwz, Jzv, Jzw, Jzz, Jvth, Jwth, Jzth = jac
            t1 = t + h
            # a step ending on a breakpoint sees the inputs' left limits there (steps in u, theta, and in the
            # prescribed kinematics: a jump belongs to the next step, which starts with the right limits)
            tl = just_before(t1, h) if left else t1
            u1, th1 = (U0(tl), TH0(tl)) if left else inputs(t1)
            ud, thd = (u1 - u0) / h, (th1 - th0) / h
            gh = GAMMA * h
            ftv, ftw, ftz = Jvth * thd, (Jwth * thd + ud / J), Jzth * thd
            dz = 1.0 - gh * Jzz
            cz = gh / dz
            if mode == PRESCRIBED:
                # v, omega are pseudo-states with the secant slopes as right-hand side and no
                # Jacobian row: k1 = slope, k2 = -slope (their ROS2 update is then exact)
                fv = (V(tl) - v) / h
                fw = (W(tl) - w) / h

                def solve(rv, rw, rz):
                    return rv, rw, (rz + gh * (Jzv * rv + Jzw * rw)) / dz
                ftv = ftw = 0.0
            else:
                # eliminate z: kz = (rz + gh (Jzv kv + Jzw kw)) / dz
                a11 = 1.0 - gh * Jvv - gh * Jvz * cz * Jzv
                a12 = -gh * Jvw - gh * Jvz * cz * Jzw
                if mode == LOCKED:
                    def solve(rv, rw, rz):
                        kv = (rv + gh * Jvz * rz / dz) / a11
                        return kv, 0.0, (rz + gh * Jzv * kv) / dz
                else:
                    a21 = -gh * Jwv - gh * Jwz * cz * Jzv
                    a22 = 1.0 - gh * Jww - gh * Jwz * cz * Jzw
                    det = a11 * a22 - a12 * a21

                    def solve(rv, rw, rz):
                        b1 = rv + gh * Jvz * rz / dz
                        b2 = rw + gh * Jwz * rz / dz
                        kv = (b1 * a22 - a12 * b2) / det
                        kw = (a11 * b2 - a21 * b1) / det
                        return kv, kw, (rz + gh * (Jzv * kv + Jzw * kw)) / dz
            k1v, k1w, k1z = solve(fv + gh * ftv, fw + gh * ftw, fz + gh * ftz)
            f2v, f2w, f2z = rhs(t1, v + h * k1v, w + h * k1w, z + h * k1z, u1, th1, mode)
            if mode == PRESCRIBED:
                f2v, f2w = fv, fw
            k2v, k2w, k2z = solve(f2v - 2.0 * k1v - gh * ftv, f2w - 2.0 * k1w - gh * ftw,
                                  f2z - 2.0 * k1z - gh * ftz)
            ev = abs(k1v + k2v) * iv
            ew = abs(k1w + k2w) * iw
            wz = iz + is1 * Jzz                 # (sigma0 - sigma1 a) / tol
            ez = abs(k1z + k2z) * (wz if wz > iz else (-wz if -wz > iz else iz))
            err = 0.5 * h * max(ev, ew, ez)
            z1 = z + h * (1.5 * k1z + 0.5 * k2z)
            if mode == PRESCRIBED and left:   # the kinematics at t1 as the next step starts (right limits)
                return [V(t1), W(t1), z1], err
            return [v + h * (1.5 * k1v + 0.5 * k2v), w + h * (1.5 * k1w + 0.5 * k2w), z1], err

        def holds(E):
            # locked wheel: the brake holds while the tire torque -r F does not exceed T_b
            u, F = E[4], E[13]
            return u < 0.0 and -r * F <= -u

        def left_of(t):
            return just_before(t, max(abs(t), 1e-3))

        def left_inputs(t):
            tl = left_of(t)
            return U0(tl), TH0(tl)

        def rhs_at(t, y, mode, left=False):
            """Right-hand side at ``(t, y)`` (``left``: the inputs' and prescribed kinematics' left limits at ``t``)."""
            u, th = left_inputs(t) if left else inputs(t)
            v, w, z = y
            if mode == PRESCRIBED:
                tk = left_of(t) if left else t
                v, w = V(tk), W(tk)
            return list(rhs(t, v, w, z, u, th, mode))

        def lock_margin(t, y, left=False):
            """How far the brake holds a locked wheel at ``(t, y)``: ``min(T_b, T_b - |r F|)``
            (>= 0 while it holds, with ``T_b = -u``); ``left``: the inputs' left limits."""
            u, th = left_inputs(t) if left else inputs(t)
            mu = core(y[0], 0.0, y[2], th)[-1]
            return min(-u, r * mu * Fn - u)

        def evaluate(t, y, mode):
            """``(state, outputs)`` at ``(t, y)`` in ``mode`` (prescribed kinematics replace v, omega)."""
            E = start(t, y, mode)
            return [E[1], E[2], E[3]], tuple(outputs(E))

        def outputs(E):
            t, v, w, z, u, th, mode, fv, fw, zd, jac, vr, mu, F, k0 = E
            tb = -u if u < 0.0 else 0.0
            if mode == LOCKED:
                u = r * F  # brake reaction torque holding the wheel
            return (vr, mu, zd, u, tb, th, k0, 1.0 if mode == LOCKED else 0.0, fv, fw)

        self.start, self.attempt, self.holds, self.outputs = start, attempt, holds, outputs
        self.rhs_at, self.lock_margin, self.evaluate = rhs_at, lock_margin, evaluate
        self.dense = self._build_dense(U0, TH0, zmode, K0)

    def _build_dense(self, U0, TH0, zmode, K0):  # noqa: C901 - the scalar start/attempt/evaluate over arrays
        """``dense(t0, Y0, modes, dt) -> (Y, outputs) or None``: the dense output of :meth:`Trajectory.sample
        <tirecli.numerics.ros2.Trajectory.sample>` at many points at once. Point ``i`` is the ROS2 step of length
        ``dt[i] > 0`` from the recorded point ``(t0[i], Y0[i])`` of wheel mode ``modes[i]`` (``start`` there, then
        ``attempt`` without left limits, omega clamped at 0 like ``advance``), followed by ``evaluate`` at its
        end: the same arithmetic as the scalar functions, on numpy arrays (equal to rounding). ``Y``: states
        ``(n, 3)``; ``outputs``: ``(n, len(out_names))``. None when a point is in the prescribed mode (open
        loop: the caller takes the scalar path)."""
        p, car = self.p, self.car
        s0, s1, s2 = p.sigma0, p.sigma1, p.sigma2
        mc, dmu, vs, L, al = p.mu_c, p.mu_s - p.mu_c, p.v_s, p.L, p.alpha
        sw = p.sigma_w
        r, m, J, Fn = car.r, car.m, car.J, car.F_n
        Fm, rFJ = Fn / m, r * Fn / J
        u_vec, th_vec = _vectorised(U0), _vectorised(TH0)

        def core(v, w, z, th):
            c = np.abs(r * w)
            vr = r * w - v
            avr = np.abs(vr)
            qa = avr / vs
            if al != 1.0:
                qa = qa * qa if al == 2.0 else qa ** al
            e = np.exp(-qa)
            g = th * (mc + dmu * e)
            b = s0 * avr / g
            if zmode:
                pos = c > 0.0
                x = np.where(pos, b * L / np.where(pos, c, 1.0), 0.0)
                xs = np.maximum(x, _X_SERIES)
                E = np.exp(-xs)
                q = -np.expm1(-xs)
                hx = 1.0 - q / xs
                k0 = np.where(x < _X_SERIES, 2.0 - x / 3.0 + x * x / 18.0, np.where(x > 1e12, 1.0, q / hx))
                k0p = np.where(x < _X_SERIES, -1.0 / 3.0 + x / 9.0,
                               np.where(x > 1e12, 0.0, (E * hx - q * (q - xs * E) / (xs * xs)) / (hx * hx)))
                k0 = np.where(pos, k0, 1.0)
                k0p = np.where(pos, k0p, 0.0)
            else:
                x, k0, k0p = np.zeros_like(v), np.full_like(v, K0), np.zeros_like(v)
            a = b + k0 * c / L
            zd = vr - a * z
            mu = s0 * z + s1 * zd + s2 * vr
            return c, vr, avr, qa, e, g, b, x, k0, k0p, a, zd, mu

        def start(v, w, z, u, th, locked):
            c, vr, avr, qa, e, g, b, x, k0, k0p, a, zd, mu = core(v, w, z, th)
            F = mu * Fn
            sg = np.sign(vr)
            dbdvr = (s0 * sg / g) * (1.0 + th * dmu * e * al * qa / g)
            if zmode:
                dadb = 1.0 + k0p
                dadc = (k0 - x * k0p) / L
            else:
                dadb, dadc = 1.0, k0 / L
            dzvr = 1.0 - z * dbdvr * dadb
            dzc = -z * dadc
            dzth = z * (b / th) * dadb
            ws = np.where(w >= 0.0, 1.0, -1.0)
            dmv = -(s1 * dzvr + s2)
            dmw = r * (s1 * (dzvr + ws * dzc) + s2)
            dmz = s0 - s1 * a
            dmth = s1 * dzth
            fv = F / m
            fw = np.where(locked, 0.0, (-r * F - sw * w + u) / J)
            jac = (Fm * dmv, Fm * dmw, Fm * dmz, -rFJ * dmv, -rFJ * dmw - sw / J, -rFJ * dmz,
                   -dzvr, r * (dzvr + ws * dzc), -a, Fm * dmth, -rFJ * dmth, dzth)
            return fv, fw, zd, jac, vr, mu, F, k0

        def dense(t0, Y0, modes, dt):
            if np.any(modes == PRESCRIBED):
                return None
            locked = modes == LOCKED
            t0 = np.asarray(t0, dtype=float)
            v, w, z = (np.asarray(Y0[:, i], dtype=float) for i in range(3))
            # inputs at the steps' starts: the scalar functions (right limits at breakpoints), once per step
            starts, inv = np.unique(t0, return_inverse=True)
            u0 = np.array([U0(float(tt)) for tt in starts])[inv]
            th0 = np.array([TH0(float(tt)) for tt in starts])[inv]
            fv, fw, fz, jac, *_ = start(v, w, z, u0, th0, locked)
            Jvv, Jvw, Jvz, Jwv, Jww, Jwz, Jzv, Jzw, Jzz, Jvth, Jwth, Jzth = jac
            h = np.asarray(dt, dtype=float)
            t1 = t0 + h
            u1, th1 = u_vec(t1), th_vec(t1)
            ud, thd = (u1 - u0) / h, (th1 - th0) / h
            gh = GAMMA * h
            ftv, ftw, ftz = Jvth * thd, (Jwth * thd + ud / J), Jzth * thd
            dz = 1.0 - gh * Jzz
            cz = gh / dz
            a11 = 1.0 - gh * Jvv - gh * Jvz * cz * Jzv
            a12 = -gh * Jvw - gh * Jvz * cz * Jzw
            a21 = -gh * Jwv - gh * Jwz * cz * Jzv
            a22 = 1.0 - gh * Jww - gh * Jwz * cz * Jzw
            det = a11 * a22 - a12 * a21

            def solve(rv, rw, rz):
                b1 = rv + gh * Jvz * rz / dz
                b2 = rw + gh * Jwz * rz / dz
                kv = np.where(locked, b1 / a11, (b1 * a22 - a12 * b2) / det)
                kw = np.where(locked, 0.0, (a11 * b2 - a21 * b1) / det)
                kz = np.where(locked, (rz + gh * Jzv * kv) / dz, (rz + gh * (Jzv * kv + Jzw * kw)) / dz)
                return kv, kw, kz

            k1v, k1w, k1z = solve(fv + gh * ftv, fw + gh * ftw, fz + gh * ftz)
            f2v, f2w, f2z, *_ = start(v + h * k1v, w + h * k1w, z + h * k1z, u1, th1, locked)
            k2v, k2w, k2z = solve(f2v - 2.0 * k1v - gh * ftv, f2w - 2.0 * k1w - gh * ftw, f2z - 2.0 * k1z - gh * ftz)
            Y = np.empty((h.size, 3))
            Y[:, 0] = v + h * (1.5 * k1v + 0.5 * k2v)
            Y[:, 1] = w + h * (1.5 * k1w + 0.5 * k2w)
            Y[:, 2] = z + h * (1.5 * k1z + 0.5 * k2z)
            Y[locked | (Y[:, 1] < 0.0), 1] = 0.0   # as advance: the wheel does not turn backwards
            fv, fw, zd, _, vr, mu, F, k0 = start(Y[:, 0], Y[:, 1], Y[:, 2], u1, th1, locked)
            out = np.column_stack((vr, mu, zd, np.where(locked, r * F, u1), np.where(u1 < 0.0, -u1, 0.0), th1, k0,
                                   locked.astype(float), fv, fw))
            return Y, out

        def guarded(t0, Y0, modes, dt):
            with np.errstate(all="ignore"):
                return dense(t0, Y0, modes, dt)

        return guarded

    @staticmethod
    def deriv(E) -> list:
        """The right-hand side ``(dv, domega, dz)`` of a ``start`` record."""
        return [E[7], E[8], E[9]]

    def rollback(self, t: float) -> None:
        """Forget everything after ``t`` (nothing to forget: the lumped tire has no history)."""


def _vectorised(fn):
    """``fn(t)`` over an array of times for an input profile's ``at`` (scalar): the profile's own array
    evaluation for the profiles whose ``at`` and array forms agree to rounding away from their breakpoints
    (constants, tables, level changes; the dense output's times lie strictly inside steps, and every
    breakpoint is a step end), else one scalar call per time."""
    from tirecli.models.profiles import Constant, Table, Transitions

    owner = getattr(fn, "__self__", None)
    if isinstance(owner, (Constant, Table, Transitions)) and getattr(fn, "__name__", "") == "at":
        return lambda t: np.asarray(owner(np.asarray(t, dtype=float)), dtype=float)
    return lambda t: np.array([fn(float(x)) for x in np.asarray(t, dtype=float)], dtype=float)
