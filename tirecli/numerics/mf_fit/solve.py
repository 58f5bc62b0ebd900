"""Least squares of one fit step, the coefficients its Jacobian cannot tell apart, and the intervals.

Residuals are ``r_i = sqrt(w_i) (model_i - data_i) / scale`` (``w_i`` the point weight, ``scale`` the
largest measured |value| of the channel in the stage, so residuals are fractions of the peak), and the
cost is ``C = 1/2 sum rho(r_i^2)`` with scipy's losses (``linear``: ``rho(z) = z``; ``soft_l1``,
``huber``, ``cauchy``, ``arctan`` with ``f_scale``, exactly as ``scipy.optimize.least_squares``).

**Solver.** :func:`levenberg_marquardt` is a bounded trust-region Levenberg-Marquardt method as MINPACK's
(More's column scaling and radius control; bounds by projection, the coefficients held on a bound
left out of the step) on the normal equations, solved through the eigen-decomposition of the
column-scaled ``J^T J`` (once per Jacobian, reused while the radius changes): with thousands of points
and tens of coefficients every matrix it factors is p x p, where scipy's ``least_squares`` factors the
n x p Jacobian (an SVD per iteration, slow with threaded BLAS on a busy machine). Robust losses scale
the Jacobian and the residuals as scipy does (Triggs et al. 2000).
``solver="scipy"`` runs ``scipy.optimize.least_squares`` (``trf``) instead, for comparison. The
Jacobian is a forward difference of the stage model (:func:`fd_jacobian`).

**Identifiability at the optimum.** The Jacobian columns, each scaled to unit length, are taken in the
stage's order (nominal coefficients first) and kept while a column keeps a component of at least
``tol`` (default 1e-4) outside the span of the columns kept before it. A column below that (zero: the
coefficient has no effect on these data; tiny: it acts as a combination of others) is not identified.

**Intervals.** With ``J`` the Jacobian of the residuals at the optimum (for a robust loss, scaled by the
loss), ``n`` points and ``p`` identified coefficients: ``cov = s^2 (J^T J)^-1`` with
``s^2 = 2 C / (n - p)`` (for the plain loss the sum of squared residuals over ``n - p``), standard errors
``sqrt(diag cov)``, 95 % intervals ``value +- t_{0.975, n-p} se``, correlations ``cov_ij / (se_i se_j)``.
A coefficient on a bound gets no interval and is left out of ``J``.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

_EPS = np.finfo(float).eps


class Residuals:
    """``sqrt(w) (model(values) - y) / scale`` as a function of the free coefficients; counts evaluations."""

    def __init__(self, model, names, fixed: dict, y, w, scale):
        self.model, self.names, self.fixed = model, list(names), dict(fixed)
        self.y, self.sw, self.scale = y, np.sqrt(w), float(scale)
        self.nfev = 0

    def values(self, x) -> dict:
        v = dict(self.fixed)
        v.update(zip(self.names, (float(a) for a in x)))
        return v

    def __call__(self, x):
        self.nfev += 1
        r = (self.model(self.values(x)) - self.y) * (self.sw / self.scale)
        return np.where(np.isfinite(r), r, 1e6)  # a trial point where the model overflows: a huge residual


def fd_jacobian(fun, x, f0, lower, upper, typical):
    """Forward-difference Jacobian of ``fun`` at ``x`` (``f0 = fun(x)``): step ``1.5e-8 max(|x_j|, typ_j)``,
    taken backwards where the forward step would cross the upper bound."""
    J = np.empty((f0.size, x.size))
    for j in range(x.size):
        h = 1.4901161193847656e-08 * max(abs(x[j]), typical[j])
        if x[j] + h > upper[j]:
            h = -h
        xh = x.copy()
        xh[j] = x[j] + h
        J[:, j] = (fun(xh) - f0) / (xh[j] - x[j])
    return J


# --------------------------------------------------------------------------- losses (scipy's definitions)


def _rho(loss: str, z):
    """``(rho, rho', rho'')`` of a loss at ``z = r^2`` (unit f_scale)."""
    if loss == "linear":
        return z, np.ones_like(z), np.zeros_like(z)
    if loss == "soft_l1":
        t = 1.0 + z
        return 2.0 * (np.sqrt(t) - 1.0), 1.0 / np.sqrt(t), -0.5 * t ** -1.5
    if loss == "huber":
        big = z > 1.0
        sq = np.sqrt(np.where(big, z, 1.0))
        return (np.where(big, 2.0 * sq - 1.0, z), np.where(big, 1.0 / sq, 1.0),
                np.where(big, -0.5 / (sq * sq * sq), 0.0))
    if loss == "cauchy":
        t = 1.0 + z
        return np.log1p(z), 1.0 / t, -1.0 / t**2
    if loss == "arctan":
        t = 1.0 + z * z
        return np.arctan(z), 1.0 / t, -2.0 * z / t**2
    raise ValueError(f"unknown loss {loss!r}")


def cost(f, loss: str = "linear", f_scale: float = 1.0) -> float:
    """``1/2 sum rho(f^2)`` with ``rho`` scaled by ``f_scale`` as scipy does."""
    if loss == "linear":
        return 0.5 * float(f @ f)
    return 0.5 * f_scale**2 * float(np.sum(_rho(loss, (f / f_scale) ** 2)[0]))


def _robust(J, f, loss, f_scale):
    """Jacobian and residuals scaled for a robust loss (scipy's ``scale_for_robust_loss_function``)."""
    if loss == "linear":
        return J, f
    _, r1, r2 = _rho(loss, (f / f_scale) ** 2)
    r2 = r2 / f_scale**2
    js = r1 + 2.0 * r2 * f**2
    js = np.sqrt(np.maximum(js, _EPS))
    return J * js[:, None], f * (r1 / js)


# --------------------------------------------------------------------------- solver


def _tr_step(w, V, vg, delta):
    """The damped Gauss-Newton step in scaled coordinates, ``-V (V^T g) / (w + lam)``, with ``lam >= 0`` the
    least for which its length is at most ``delta`` (More's trust region, solved on the eigenvalues)."""
    def step(lam):
        return -(V @ (vg / (w + lam)))

    big = w > w.max() * 1e-14 if w.size else w
    gn = -(V[:, big] @ (vg[big] / w[big]))  # Gauss-Newton (pseudo-inverse on the numerically zero directions)
    if np.linalg.norm(gn) <= delta:
        return gn
    lo, hi = 0.0, max(float(np.linalg.norm(vg)) / delta, 1e-300)  # |step(hi)| <= delta
    for _ in range(60):  # bisection on log(lam): |step(lam)| decreases with lam
        mid = np.sqrt(max(lo, hi * 1e-12) * hi)
        if np.linalg.norm(step(mid)) > delta:
            lo = mid
        else:
            hi = mid
        if hi <= lo * 1.01:
            break
    return step(hi)


def levenberg_marquardt(fun, jac, x0, lower, upper, loss="linear", f_scale=1.0, tol=1e-10, max_nfev=400):
    """Minimise ``1/2 sum rho(fun(x)^2)`` within ``[lower, upper]`` (see the module docstring).

    A trust-region Levenberg-Marquardt method as MINPACK's ``lmder`` (More 1978): scaled step length at
    most ``delta`` (initially 100 times the scaled length of ``x0``), shrunk to a quarter of the step when
    the cost falls by less than a quarter of the predicted decrease, doubled when it falls by more than
    three quarters; a step is taken when the cost falls at all. ``jac(x, f)`` gives the Jacobian at ``x``
    where ``fun(x) = f``. Returns a namespace like scipy's ``OptimizeResult``: ``x``, ``cost``, ``fun``,
    ``jac`` (scaled for the loss), ``active_mask`` (-1 on the lower bound, 1 on the upper, 0 inside),
    ``nfev`` (residual evaluations), ``njev``, ``message``, ``success``.
    """
    from scipy.linalg import eigh  # numpy's eigh of a 30 x 30 matrix takes milliseconds with threaded BLAS

    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    f = fun(x)
    nfev, njev = 1, 1
    c = cost(f, loss, f_scale)
    J = jac(x, f)
    D = None
    eig = None
    delta = None
    message, success = "the most evaluations were used", False
    while nfev < max_nfev:
        if eig is None:
            Js, fs = _robust(J, f, loss, f_scale)
            A = Js.T @ Js
            g = np.einsum("ij,i->j", Js, fs)  # (numpy's own loop: a threaded BLAS gemv is slower on a busy machine)
            norms = np.sqrt(np.maximum(np.diag(A), 0.0))
            D = norms if D is None else np.maximum(D, norms)
            Ds = np.where(D > 0, D, 1.0)
            free = ~(((x <= lower) & (g > 0)) | ((x >= upper) & (g < 0)))
            gf = g[free]
            if not gf.size or np.max(np.abs(gf) / Ds[free]) <= tol * np.sqrt(max(2.0 * c, 1e-300)):
                message, success = "gradient below tolerance", True
                break
            dF = Ds[free]
            w, V = eigh(A[np.ix_(free, free)] / np.outer(dF, dF))
            eig = (np.maximum(w, 0.0), V, V.T @ (gf / dF))
            if delta is None:
                delta = 100.0 * (float(np.linalg.norm(Ds * x)) or 1.0)
        step = np.zeros_like(x)
        step[free] = _tr_step(*eig, delta) / Ds[free]
        x_new = np.clip(x + step, lower, upper)
        d = x_new - x
        dn = float(np.linalg.norm(Ds * d))
        pred = -(g @ d + 0.5 * d @ (A @ d))
        small_step = dn <= tol * (tol + float(np.linalg.norm(Ds * x)))
        if not np.any(d) or pred <= 0:
            if small_step:
                message, success = "step below tolerance", True
                break
            delta = 0.25 * (dn or delta)
            continue
        f_new = fun(x_new)
        nfev += 1
        c_new = cost(f_new, loss, f_scale)
        actual = c - c_new if np.isfinite(c_new) else -np.inf
        rho = actual / pred
        if rho < 0.25:
            delta = 0.25 * min(delta, dn)
        elif rho > 0.75:
            delta = max(delta, 2.0 * dn)
        if rho > 1e-4:
            small_cost = actual <= tol * c and pred <= tol * c
            x, f, c = x_new, f_new, c_new
            J = jac(x, f)
            njev += 1
            eig = None
            if small_cost:
                message, success = "cost change below tolerance", True
                break
            if small_step:
                message, success = "step below tolerance", True
                break
        elif small_step or delta <= 1e-300:
            message, success = "no further decrease within tolerance", True
            break
    Js, _ = _robust(J, f, loss, f_scale)
    active = np.where(x <= lower, -1, np.where(x >= upper, 1, 0))
    return SimpleNamespace(x=x, cost=c, fun=f, jac=Js, active_mask=active, nfev=nfev, njev=njev, message=message,
                           success=success)


def least_squares(res: Residuals, x0, lower, upper, typical, loss="linear", f_scale=1.0, tol=1e-10, max_nfev=400,
                  solver="lm"):
    """Fit the free coefficients of ``res``; returns ``(x, result)`` (see :func:`levenberg_marquardt`)."""
    def jac(x, f):
        return fd_jacobian(res, x, f, lower, upper, typical)

    if solver == "scipy":
        from scipy.optimize import least_squares as lsq

        r = lsq(res, np.clip(x0, lower, upper), jac=lambda x: jac(x, res(x)), bounds=(lower, upper), method="trf",
                loss=loss, f_scale=f_scale, x_scale="jac", ftol=tol, xtol=tol, gtol=tol, max_nfev=max_nfev)
        return r.x, r
    r = levenberg_marquardt(res, jac, x0, lower, upper, loss, f_scale, tol, max_nfev)
    return r.x, r


# --------------------------------------------------------------------------- identifiability, intervals


def _unit_gram(J):
    """``(C, d)``: the Gram matrix of the unit-length columns of ``J`` and the column lengths."""
    G = J.T @ J
    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    ds = np.where(d > 0, d, 1.0)
    return G / np.outer(ds, ds), d


def dependent(J, tol: float = 1e-4) -> dict:
    """Columns of ``J`` not identified, in order: index -> ``(reason, independent fraction)``. A zero column
    has no effect; a column whose unit vector keeps less than ``tol`` outside the span of the earlier kept
    columns acts as a combination of them (Gram-Schmidt in the Gram matrix)."""
    C, d = _unit_gram(J)
    out, kept = {}, []
    big = float(d.max()) if d.size else 0.0
    for j in range(J.shape[1]):
        if not np.isfinite(d[j]) or d[j] <= 1e-12 * max(big, 1e-300):
            out[j] = ("no effect on the fitted channel at these points", 0.0)
            continue
        if kept:
            cj = C[kept, j]
            r2 = 1.0 - float(cj @ np.linalg.solve(C[np.ix_(kept, kept)], cj))
        else:
            r2 = 1.0
        r = float(np.sqrt(max(r2, 0.0)))
        if r < tol:
            out[j] = ("acts on these points only as a combination of the others (Jacobian column dependent, "
                      f"{r:.1e} of it independent)", r)
            continue
        kept.append(j)
    return out


def covariance(J, c: float, n: int):
    """``(cov, s2, dof)``: ``s^2 (J^T J)^-1`` with ``s^2 = 2 c / (n - p)`` (cov None when ``n <= p`` or
    ``J^T J`` is singular)."""
    p = J.shape[1]
    dof = n - p
    if dof <= 0 or p == 0:
        return None, float("nan"), dof
    s2 = 2.0 * c / dof
    C, d = _unit_gram(J)
    if np.any(d <= 0):
        return None, s2, dof
    try:
        inv = np.linalg.inv(C)
    except np.linalg.LinAlgError:
        return None, s2, dof
    return s2 * inv / np.outer(d, d), s2, dof


def t_quantile(dof: int, q: float = 0.975) -> float:
    """Student's t quantile (``scipy.special.stdtrit``; scipy.stats is slow to import)."""
    from scipy.special import stdtrit

    return float(stdtrit(dof, q))
