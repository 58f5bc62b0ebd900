"""Events on a step's dense output: the cubic Hermite interpolant and the root and extremum finders the
ROS2 integration (:mod:`tirecli.numerics.ros2`) uses to end a step exactly at a wheel lock, an unlock or
the stop, and to locate extrema of its outputs. Plain Python: no scipy import on the event path.
"""
from __future__ import annotations

#: Events are located to this tolerance [s] on the step's dense output.
EVENT_TOL = 1e-9


def hermite(s, h, y0, y1, f0, f1):
    """Cubic Hermite interpolant at ``s = (t - t0)/h`` in [0, 1] of a step of length ``h`` [s] with end
    values ``y0``, ``y1`` and end slopes ``f0`` (right limit at the start), ``f1`` (left limit at the end)."""
    s2 = s * s
    s3 = s2 * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * f0 + (-2 * s3 + 3 * s2) * y1
            + (s3 - s2) * h * f1)


def root(g, a, b, ga=None, gb=None, tol=EVENT_TOL):
    """A zero of ``g`` on ``[a, b]`` where it changes sign: regula falsi with the Illinois modification
    and bisection safeguard (superlinear, bracketing), to ``tol``. Plain Python: no scipy import on the
    simulate path. Returns, of the points evaluated in the final bracket (its ends included, ``a`` as
    given excluded: the zero is sought after it), the one where ``|g|`` is smallest."""
    ga = g(a) if ga is None else ga
    gb = g(b) if gb is None else gb
    if ga == 0.0:
        return a
    if gb == 0.0 or ga * gb > 0.0:
        return b
    g_raw, a0 = g, a
    seen = {a: ga, b: gb}

    def g(x):
        seen[x] = gx = g_raw(x)
        return gx
    side = 0
    for _ in range(200):
        if b - a <= tol:
            break
        c = b - gb * (b - a) / (gb - ga)
        if not a < c < b:
            c = 0.5 * (a + b)
        # at least tol/2 inside the bracket (Brent's rule): a secant point a rounding error away from an end
        # (an end value ~0, e.g. an event just located) would evaluate g at rounding noise
        c = min(max(c, a + 0.5 * tol), b - 0.5 * tol)
        gc = g(c)
        if gc == 0.0:
            return c
        if gc * gb < 0.0:
            a, ga = b, gb
            b, gb = c, gc
            side = 0
        else:
            b, gb = c, gc
            if side == -1:
                ga *= 0.5       # Illinois: halve the stale end's value
            side = -1
        if a > b:
            a, b, ga, gb = b, a, gb, ga
        if abs(b - a) > 0.5 * abs(c - a) + tol and side == -1 and _ > 40:
            m = 0.5 * (a + b)   # slow progress: bisect
            gm = g(m)
            if gm * ga < 0.0:
                b, gb = m, gm
            else:
                a, ga = m, gm
    inside = [x for x in seen if a <= x <= b and x != a0]
    return min(inside, key=lambda x: abs(seen[x])) if inside else 0.5 * (a + b)


def minimize(f, a, b, xtol=1e-12, maxiter=200):
    """Minimum of ``f`` on ``[a, b]``: Brent's method (golden section with parabolic steps). Plain Python."""
    cg = 0.3819660112501051
    x = w = v = a + cg * (b - a)
    fx = fw = fv = f(x)
    d = e = 0.0
    for _ in range(maxiter):
        m = 0.5 * (a + b)
        tol1 = xtol + 1e-12 * abs(x)
        tol2 = 2.0 * tol1
        if abs(x - m) <= tol2 - 0.5 * (b - a):
            break
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p_ = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p_ = -p_
            q = abs(q)
            if abs(p_) < abs(0.5 * q * e) and q * (a - x) < p_ < q * (b - x):
                e, d = d, p_ / q
                u = x + d
                if u - a < tol2 or b - u < tol2:
                    d = tol1 if x < m else -tol1
            else:
                e = (b - x) if x < m else (a - x)
                d = cg * e
        else:
            e = (b - x) if x < m else (a - x)
            d = cg * e
        u = x + (d if abs(d) >= tol1 else (tol1 if d > 0 else -tol1))
        fu = f(u)
        if fu <= fx:
            if u < x:
                b = x
            else:
                a = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x, fx


def return_root(gh, H, gH, floor=0.0, tol=EVENT_TOL):
    """Zero of ``gh`` on ``(0, H]`` where it comes back down through 0 after rising from ``gh(0) ~ 0``
    (the step starts on the event surface, ``gh(H) = gH < 0``): the largest of the probes ``gh(H 2^-k)``
    (k = 1, 2, ... down to ``tol``) brackets the zero with ``H``; 0.0 when no probe exceeds ``floor``
    (``gh`` leaves 0 downwards, or rises by less than the solution's resolution ``floor`` before it
    comes back: the event is at the step's start)."""
    best, g_best = 0.0, 0.0
    h = H
    while h > 2.0 * tol:
        h *= 0.5
        g = gh(h)
        if g > g_best:
            best, g_best = h, g
    if g_best <= floor:
        return 0.0
    return root(gh, best, H, g_best, gH, tol)


def event_step(attempt, E, t, H, g, g0, gH, left_end=False, on_surface=None):
    """Length ``h`` in ``(0, H]`` of the step from ``E`` (at ``t``) that ends on the event ``g(t + h, y(h)) = 0``,
    with ``y(h)`` the ROS2 step of length ``h`` (the integrator's own one-step map, smooth in ``h``):
    Brent's method to ``EVENT_TOL``. ``g0``, ``gH``: the event function at both ends (a sign change).
    ``on_surface``: None, or the step starts on the event surface (``g0`` zero up to rounding) and the
    zero sought is where ``g`` comes back to 0 after rising above ``on_surface`` (:func:`return_root`);
    ``h = 0`` when it does not. Returns ``(h, y(h))``."""
    def gh(h):
        return g(t + h, attempt(E, h, left_end and h >= H)[0])

    h = root(gh, 0.0, H, g0, gH) if on_surface is None else return_root(gh, H, gH, on_surface)
    if h <= 0.0:
        return 0.0, None
    return h, attempt(E, h, left_end and h >= H)[0]
