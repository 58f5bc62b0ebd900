"""An independent reference of the quarter car with the lumped LuGre tire: scipy's Radau at rtol 1e-10 on
the model's right-hand side (tirecli.models.quarter_car.rhs, not the ROS2 stepper), split at the input
breakpoints, with wheel lock, unlock and stop located by solve_ivp's event detection (docs/models/lugre_friction.md §7)."""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from tirecli.models import lugre_lumped
from tirecli.models.lugre_lumped import LumpedTire
from tirecli.models.quarter_car import QuarterCar, outputs, rhs


def reference_run(p, car, kappa0, torque, t_end, v0, omega0, v_stop=0.1, theta=1.0, rtol=1e-9, atol=1e-11,
                  max_step=1e-3):
    """``(t, y, mode, events)`` on a dense grid: ``events = {"lock": [[t_lock, t_unlock], ...], "stop": t}``.

    ``torque`` is a tirecli profile (``at``, ``breakpoints``); the brake part cannot reverse the wheel.
    """
    qc = QuarterCar(LumpedTire(p, kappa0), car)
    bps = sorted({b for b in torque.breakpoints() if 0 < b < t_end} | {t_end})

    def u_of(t):
        return (torque.at(t), theta)

    def margin(t, x):  # brake holding margin of a locked wheel: min(T_b, T_b - |r F|)
        u = torque.at(t)
        mu = outputs(t, (x[0], 0.0, x[2]), (u, theta), qc)["mu"]
        return min(-u, car.r * mu * car.F_n - u)

    def f_free(t, x):
        return rhs(t, x, u_of(t), qc)

    def f_locked(t, x):
        d = rhs(t, (x[0], 0.0, x[2]), u_of(t), qc)
        d[1] = 0.0
        return d

    def ev_lock(t, x):
        return x[1]
    ev_lock.terminal, ev_lock.direction = True, -1

    def ev_unlock(t, x):
        return margin(t, x)
    ev_unlock.terminal, ev_unlock.direction = True, -1

    def ev_stop(t, x):
        return x[0] - v_stop
    ev_stop.terminal, ev_stop.direction = True, -1

    t, x = 0.0, np.array([v0, omega0, 0.0])
    mode = "locked" if omega0 <= 0 and margin(0.0, x) >= 0 else "free"
    T, Y, M = [t], [x.copy()], [mode]
    locks, stop = ([[0.0, None]] if mode == "locked" else []), None
    seg = 0
    while t < t_end - 1e-14 and stop is None:
        while bps[seg] <= t + 1e-14:
            seg += 1
        tb = bps[seg]
        if mode == "free":
            sol = solve_ivp(f_free, (t, tb), x, method="Radau", rtol=rtol, atol=atol, events=[ev_lock, ev_stop],
                            max_step=max_step, dense_output=False)
        else:
            sol = solve_ivp(f_locked, (t, tb), x, method="Radau", rtol=rtol, atol=atol, events=[ev_unlock, ev_stop],
                            max_step=max_step)
        T += list(sol.t[1:])
        Y += list(sol.y.T[1:])
        M += [mode] * (len(sol.t) - 1)
        t, x = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:
            if len(sol.t_events[1]):        # stop
                stop = float(sol.t_events[1][0])
                break
            te = float(sol.t_events[0][0])
            if mode == "free":
                x[1] = 0.0
                if margin(te, x) >= 0:
                    mode = "locked"
                    locks.append([te, None])
            else:
                mode = "free"
                locks[-1][1] = te
        elif mode == "locked" and t < t_end - 1e-14 and margin(t, x) < 0:   # a jump of the input released it
            mode = "free"
            locks[-1][1] = t
    return np.array(T), np.array(Y), M, {"lock": locks, "stop": stop}


def reference_mu(p, car, kappa0, t, y, torque, theta=1.0):
    """Friction ``mu`` of the reference at its states ``y`` (rows ``v, omega, z``), times ``t``."""
    qc = QuarterCar(LumpedTire(p, kappa0), car)
    return np.array([outputs(tt, x, (torque.at(tt), theta), qc)["mu"] for tt, x in zip(t, y)])


def reference_open_loop(p, car, kappa0, v_of_t, omega_of_t, breakpoints, t_end, t_eval, theta=1.0, rtol=1e-10,
                        atol=1e-13):
    """The lumped tire alone driven by prescribed ``v(t)``, ``omega(t)``: ``mu`` at ``t_eval`` (solve_ivp
    DOP853 on the lumped tire's right-hand side, tirecli.models.lugre_lumped.rhs, split at the breakpoints).

    Inside a piece ``[a, b]`` the drive is read from inside it (its one-sided limits at ``a`` and ``b``: a jump
    of the drive at ``b`` belongs to the next piece); at a breakpoint itself ``mu`` is the right limit (the value
    there from the next piece on)."""
    tire = LumpedTire(p, kappa0)

    def u_of(t):
        rw = car.r * omega_of_t(t)
        return (rw - v_of_t(t), rw, theta)

    edges = [0.0] + sorted(b for b in set(breakpoints) if 0 < b < t_end) + [t_end]
    z, out = [0.0], np.full(len(t_eval), np.nan)
    t_eval = np.asarray(t_eval, dtype=float)
    for a, b in zip(edges[:-1], edges[1:]):
        b_in = np.nextafter(b, -np.inf)   # the drive's left limit at b

        def zdot(t, z, b_in=b_in):
            return lugre_lumped.rhs(t, z, u_of(min(t, b_in)), tire)
        last = b == edges[-1]
        q = (t_eval >= a) & ((t_eval <= b) if last else (t_eval < b))
        sol = solve_ivp(zdot, (a, b), z, method="DOP853", rtol=rtol, atol=atol, dense_output=True, max_step=2e-3)
        for i in np.flatnonzero(q):
            tt = float(t_eval[i])
            out[i] = float(np.squeeze(lugre_lumped.outputs(tt, sol.sol(tt), u_of(min(tt, b_in) if last else tt), tire)["mu"]))
        z = [float(sol.y[0, -1])]
    return out
