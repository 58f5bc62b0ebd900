"""Independent tight reference of the distributed LuGre tire driven open loop (FM eqs. (1)-(2)).

Shares no code with :mod:`tirecli.numerics.driven`: ``Y``, ``Phi = int b`` and ``X = int |r omega|``
by ``scipy.integrate.solve_ivp`` (DOP853, rtol 1e-12 by default) with dense output; then, at each
requested time, load-weighted patch integrals of the characteristics solution
``z(zeta, t) = Y(t) - exp(Phi(tau) - Phi(t)) Y(tau)`` (``X(tau) = X(t) - zeta``; ``z = Y(t)`` for the
elements in the patch at t = 0) by adaptive quadrature over the entry times ``s``
(``u = (X(t) - X(s))/L``, ``du = |r omega(s)| ds / L``)::

    int_0^1 q(u) z du = Y(t) int_0^1 q - (1/L) int_{tau_1}^{t} q(u(s)) exp(Phi(s) - Phi(t)) Y(s) |r omega(s)| ds

(``tau_1``: entry time of the element now at the trailing edge, 0 while X(t) < L), with ``q`` the
load density ``w`` (unit mass) for ``zbar_w`` and its derivative ``w'`` for the transport term of
the patch-integrated PDE::

    d zbar_w / dt = vr - b zbar_w - (|r omega|/L) (w(1) z(L, t) - int_0^1 w' z du)

and ``mu = sigma0 zbar_w + sigma1 d zbar_w/dt + sigma2 vr`` (FM eq. (2)). Defaults: uniform load.
"""
from __future__ import annotations

import numpy as np


def reference_mu(v_of, romega_of, p, times, w=None, dw=None, rtol=1e-12, breakpoints=()):
    """``mu`` [-] at ``times`` [s] for the drive ``v_of(t)``, ``romega_of(t)`` [m/s] (callables).

    ``w(u)``, ``dw(u)``: load density per unit ``u = zeta/L`` with unit mass and its derivative
    (continuous on [0, 1]); default uniform. ``breakpoints`` [s]: times where the drive jumps or has a kink;
    the ODEs are solved piece by piece between them (inside a piece the drive is read from inside it, its
    one-sided limits at the ends) and the patch quadrature is split there. At a breakpoint itself ``mu`` is
    the right limit.
    """
    import bisect

    from scipy.integrate import quad, solve_ivp
    from scipy.optimize import brentq

    w = w or (lambda u: 1.0)
    dw = dw or (lambda u: 0.0)
    times = np.asarray(times, dtype=float)

    def rates(t):
        vr = romega_of(t) - v_of(t)
        g = p.mu_c + (p.mu_s - p.mu_c) * np.exp(-np.abs(vr / p.v_s) ** p.alpha)
        return vr, p.sigma0 * np.abs(vr) / g, np.abs(romega_of(t))

    t_end = float(times[-1])
    edges = [0.0] + sorted(float(b) for b in set(breakpoints) if 0.0 < b < t_end) + [t_end]
    pieces, y0 = [], [0.0, 0.0, 0.0]
    for a, b in zip(edges[:-1], edges[1:]):
        b_in = np.nextafter(b, -np.inf)   # the drive's left limit at b

        def rhs(t, y, b_in=b_in):
            vr, b_, c = rates(min(t, b_in))
            return [vr - b_ * y[0], b_, c]

        sol = solve_ivp(rhs, (a, b), y0, method="DOP853", rtol=rtol, atol=[1e-16, 1e-12, 1e-12], dense_output=True)
        pieces.append(sol.sol)
        y0 = list(sol.y[:, -1])

    def d(s):
        return pieces[min(max(bisect.bisect_right(edges, s) - 1, 0), len(pieces) - 1)](s)
    mass_dw = w(1.0) - w(0.0)
    out = []
    for t in times:
        Y, Phi, X = d(t)
        vr, b, c = rates(t if t < t_end else np.nextafter(t_end, -np.inf))
        if X > p.L:
            tau = brentq(lambda s: d(s)[2] - (X - p.L), 0.0, t, xtol=1e-15, rtol=1e-15)
            Yt, Pt, _ = d(tau)
            zL = Y - np.exp(Pt - Phi) * Yt
        else:
            tau, zL = 0.0, Y

        def moment(q):
            if t <= tau:
                return 0.0

            def f(s):
                Ys, Ps, Xs = d(s)
                return q((X - Xs) / p.L) * np.exp(Ps - Phi) * Ys * abs(romega_of(s))

            kinks = [e for e in edges[1:-1] if tau < e < t]
            return quad(f, tau, t, epsabs=1e-16, epsrel=1e-13, limit=400, points=kinks or None)[0] / p.L

        zbar = Y - moment(w)
        int_dw_z = Y * mass_dw - moment(dw)
        zdot = vr - b * zbar - c / p.L * (w(1.0) * zL - int_dw_z)
        out.append(p.sigma0 * zbar + p.sigma1 * zdot + p.sigma2 * vr)
    return np.array(out)
