"""Parameter identification of the LuGre tire (FM §4.3; docs/models/lugre_friction.md §8), no I/O.

Stage 1 — steady state: bounded nonlinear least squares (``scipy.optimize.least_squares``, trust
region reflective) of the uniform-load steady state FM eq. (4) to samples ``(s_i, v_i, mu_i)``::

    min_p  sum_i (mu_ss(s_i, v_i; p) - mu_i)^2,   p within bounds, mu_c <= mu_s

with ``r omega_i = v_i (1 + s_i)`` when braking (``v_i / (1 - s_i)`` when driving). When both
``mu_c`` and ``mu_s`` are free the solver works with ``(mu_c, mu_s - mu_c >= 0)``, which keeps
``mu_c <= mu_s``; results are reported for ``mu_s``.

Stage 2 — ``sigma1`` from the transient: the tire model (default lumped ``kappa0(Z)``) driven
open loop by the measured ``v(t)``, ``s(t)`` gives ``z(t)``, ``dz/dt(t)`` that do not depend on
``sigma1`` (it only enters FM eq. (9)), so ``mu = sigma0 z + sigma1 dz/dt + sigma2 vr`` is linear
in ``sigma1``: a one-parameter linear least squares with its exact standard error.

Statistics (both stages): residual variance ``s^2 = RSS/(n - p)``, covariance ``s^2 (J^T J)^-1``
(linearised at the optimum), standard errors, Student-t confidence intervals, correlation matrix;
parameters ending on a bound are flagged (their intervals are then only indicative).

Identifiability: data that do not determine a parameter (samples all at one operating point, a
parameter the data do not reach) make the Jacobian rank-deficient, and ``s^2 (J^T J)^-1`` then claims
nothing true (40 identical rows fitted exactly: every standard error 0). :func:`identifiability` takes the
singular values of the Jacobian with unit columns; a direction whose singular value is below
:data:`IDENTIFIABLE_RTOL` of the largest is not determined by the data, and a parameter with more than
:data:`NULL_SHARE` of its unit vector in those directions is *not identifiable*: it gets no standard error
and no interval (NaN), and is named (``FitResult.unidentifiable``); the other parameters' covariance is
the pseudo-inverse's (exact for what the data determine). A fit that identifies nothing is refused.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from tirecli.models.lugre import LuGreParams, mu_ss_uniform

#: Parameters of the steady-state fit and their default bounds (SI units).
STEADY_PARAMETERS = ("sigma0", "sigma2", "mu_c", "mu_s", "v_s", "alpha")
DEFAULT_BOUNDS = {
    "sigma0": (1.0, 5000.0), "sigma2": (0.0, 0.1), "mu_c": (0.01, 3.0), "mu_s": (0.01, 3.0),
    "v_s": (0.05, 50.0), "alpha": (0.25, 4.0), "sigma1": (0.0, 100.0),
}
#: Singular values of the unit-column Jacobian below this share of the largest span directions the data do not
#: determine (finite-difference noise is about 1e-10 of a column; the shipped fits' smallest share is 2e-5).
IDENTIFIABLE_RTOL = 1e-8
#: A parameter is not identifiable when more than this share of its unit vector lies in those directions.
NULL_SHARE = 0.01
UNITS = {"sigma0": "1/m", "sigma1": "s/m", "sigma2": "s/m", "mu_c": "-", "mu_s": "-", "v_s": "m/s", "alpha": "-",
         "L": "m"}


@dataclass
class FitResult:
    """Estimates with their uncertainty.

    Attributes
    ----------
    names : list
        Fitted parameters (public names).
    estimate, se, ci_low, ci_high : dict
        Value, standard error and confidence interval per parameter (SI units).
    corr : ndarray
        Correlation matrix (order of ``names``).
    cov : ndarray
        Covariance matrix.
    at_bound : dict
        Parameter -> True when the estimate lies on a bound.
    residual_rms : float
        RMS of ``mu_model - mu`` [-].
    n, dof : int
        Number of samples and degrees of freedom ``n - p``.
    confidence : float
        Level of the intervals.
    cond : float
        Condition number of ``J^T J`` (large: poorly determined combinations).
    success : bool
    message : str
    nfev : int
    """

    names: list
    estimate: dict
    se: dict
    ci_low: dict
    ci_high: dict
    corr: np.ndarray
    cov: np.ndarray
    at_bound: dict
    residual_rms: float
    n: int
    dof: int
    confidence: float
    cond: float = float("nan")
    success: bool = True
    message: str = ""
    nfev: int = 0
    extra: dict = field(default_factory=dict)
    unidentifiable: list = field(default_factory=list)
    rank: int | None = None

    def failure(self) -> str | None:
        """Why this is not a fitted result (None when it is): the optimiser did not converge, a
        residual, estimate or standard error is not finite (data the model cannot reach), or every
        fitted parameter ended on a bound (the optimum lies outside the admissible region: the model
        cannot represent the data). Such a result must not be written as a fitted set."""
        vals = np.array([self.residual_rms] + [self.estimate[k] for k in self.names], dtype=float)
        if not np.all(np.isfinite(vals)):
            return "the residuals or estimates are not finite (the data are beyond what the model can reach)"
        if self.names and set(self.unidentifiable) >= set(self.names):
            return self.identifiability_text()
        if not self.success:
            return f"the optimiser stopped without converging ({self.message.rstrip('.')})"
        se = np.array([self.se[k] for k in self.names if k not in self.unidentifiable], dtype=float)
        if np.any(np.isnan(se)):
            return "the covariance of the estimates is not finite"
        if len(self.names) > 1 and all(self.at_bound.get(k, False) for k in self.names):
            return (f"every fitted parameter ended on a bound ({', '.join(self.names)}): the model cannot represent "
                    "the data within the bounds")
        return None

    def identifiability_text(self) -> str:
        """What the data do not determine, in words (empty when they determine every parameter)."""
        if not self.unidentifiable:
            return ""
        which = ", ".join(self.unidentifiable)
        scope = "any of the fitted parameters" if set(self.unidentifiable) >= set(self.names) else which
        return (f"the data cannot identify {scope} ({which}: the fit's Jacobian has rank {self.rank} of "
                f"{len(self.names)}; e.g. every sample at one operating point)")

    def record(self) -> dict:
        extra = {"unidentifiable": list(self.unidentifiable), "jacobian_rank": self.rank} if self.unidentifiable else {}
        return extra | {
            "parameters": {k: {"estimate": self.estimate[k], "se": self.se[k], "ci": [self.ci_low[k], self.ci_high[k]],
                               "unit": UNITS.get(k, "-"), "at_bound": self.at_bound[k]} for k in self.names},
            "correlation": {"order": list(self.names), "matrix": np.round(self.corr, 6).tolist()},
            "residual_rms": self.residual_rms, "n": self.n, "dof": self.dof, "confidence": self.confidence,
            "cond_JTJ": self.cond, "success": self.success, "message": self.message, "nfev": self.nfev, **self.extra,
        }


def _rms(resid) -> float:
    """RMS of the residuals (inf when they overflow: no warning, :meth:`FitResult.failure` reports it)."""
    with np.errstate(all="ignore"):
        return float(np.sqrt(np.mean(np.square(np.asarray(resid, dtype=float)))))


def romega_of(s, v):
    """Wheel circumferential speed ``r omega`` [m/s] from slip ``s`` [-] and vehicle speed ``v`` [m/s] (docs/models/lugre_friction.md §1)."""
    s, v = np.asarray(s, dtype=float), np.asarray(v, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s <= 0.0, v * (1.0 + s), v / (1.0 - s))


def identifiability(J, names) -> tuple[list, int]:
    """``(names not identifiable, rank)`` of a fit's Jacobian ``J`` (module doc): singular values of ``J`` with unit
    columns below :data:`IDENTIFIABLE_RTOL` of the largest span the directions the data do not determine; a
    parameter with more than :data:`NULL_SHARE` of its unit vector there (or a zero column) is not identifiable."""
    J = np.asarray(J, dtype=float)
    p = J.shape[1]
    with np.errstate(all="ignore"):
        norms = np.linalg.norm(J, axis=0)
        ok = np.isfinite(norms) & (norms > 0)
        if not np.all(np.isfinite(J[:, ok])):
            return [], p      # not finite: FitResult.failure reports it
        Js = J[:, ok] / norms[ok]
    share = np.ones(p)
    rank = 0
    if Js.size:
        _, sv, Vt = np.linalg.svd(Js, full_matrices=True)
        rank = int(np.sum(sv > IDENTIFIABLE_RTOL * sv[0])) if sv.size and sv[0] > 0 else 0
        null = Vt[rank:]
        share[ok] = np.sum(null * null, axis=0) if null.size else 0.0
    return [k for k, sh in zip(names, share) if sh > NULL_SHARE], rank


def _stats(J, resid, names, estimate, lo, hi, confidence):
    """Covariance, standard errors, intervals and correlations of a least-squares fit; no standard error or
    interval (NaN) for a parameter the data do not identify (:func:`identifiability`)."""
    from scipy.special import stdtrit  # Student-t quantile (scipy.stats costs 0.6 s to import)

    n, p = J.shape
    unident, rank = identifiability(J, names)
    dof = max(n - p, 1)
    with np.errstate(all="ignore"):  # data beyond the model's reach: inf/NaN, reported by FitResult.failure
        s2 = float(resid @ resid) / dof
        JTJ = J.T @ J
        if not (np.isfinite(s2) and np.all(np.isfinite(JTJ))):
            cond, cov = float("inf"), np.full((p, p), np.nan)
        else:
            try:
                cond = float(np.linalg.cond(JTJ))
                cov = s2 * np.linalg.inv(JTJ) if np.isfinite(cond) and cond < 1e15 else s2 * np.linalg.pinv(JTJ)
            except np.linalg.LinAlgError:
                cond, cov = float("inf"), s2 * np.linalg.pinv(JTJ)
    if unident:   # what the data determine: the pseudo-inverse's covariance (unit columns); nothing for the rest
        with np.errstate(all="ignore"):
            ns = np.linalg.norm(J, axis=0)
            ns = np.where(np.isfinite(ns) & (ns > 0), ns, 1.0)
            if np.isfinite(s2) and np.all(np.isfinite(J)):
                Jp = np.linalg.pinv(J / ns, rcond=IDENTIFIABLE_RTOL)
                cov = s2 * (Jp @ Jp.T) / np.outer(ns, ns)
        bad = [names.index(k) for k in unident]
        cov[bad, :] = np.nan
        cov[:, bad] = np.nan
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    se[np.isnan(np.diag(cov))] = np.nan
    tq = float(stdtrit(dof, 0.5 + confidence / 2.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(se, se)
    corr = np.where(np.outer(se, se) > 0, corr, np.nan)
    est = np.array([estimate[k] for k in names])
    span = np.array([hi[k] - lo[k] for k in names])
    # on (or, for mu_s = mu_c + d_mu, beyond: the split coordinates bound d_mu, not mu_s) a bound
    at_bound = {k: bool(min(estimate[k] - lo[k], hi[k] - estimate[k]) <= 1e-6 * max(s_, 1e-12))
                for k, s_ in zip(names, span)}
    # Wald intervals, clipped to the bounds (a parameter on a bound has no interval beyond it)
    low = np.where(np.isnan(se), np.nan, np.maximum(est - tq * se, [lo[k] for k in names]))
    high = np.where(np.isnan(se), np.nan, np.minimum(est + tq * se, [hi[k] for k in names]))
    return dict(cov=cov, se=dict(zip(names, se)), ci_low=dict(zip(names, low)),
                ci_high=dict(zip(names, high)), corr=corr, at_bound=at_bound, dof=dof, cond=cond,
                unidentifiable=unident, rank=rank)


class _Space:
    """Bounded internal coordinates of a fit (module doc): ``(mu_c, d_mu = mu_s - mu_c >= 0)`` when both are free.

    ``public(xi)`` maps internal values to a ``{name: value}`` dict of the free parameters;
    ``T`` is ``d public / d internal`` (Jacobians: ``J_internal = J_public @ T``).
    """

    def __init__(self, free, start: LuGreParams, bounds: dict | None, initial: dict | None, order, pad=1e-9):
        self.free = [k for k in order if k in free]
        lo = {k: DEFAULT_BOUNDS[k][0] for k in DEFAULT_BOUNDS}
        hi = {k: DEFAULT_BOUNDS[k][1] for k in DEFAULT_BOUNDS}
        for k, (a, b) in (bounds or {}).items():
            lo[k], hi[k] = float(a), float(b)
        self.x0 = {k: float((initial or {}).get(k, getattr(start, k))) for k in self.free}
        self.split = split = "mu_c" in self.free and "mu_s" in self.free
        self.inames = ["d_mu" if (split and k == "mu_s") else k for k in self.free]
        ilo = {**lo, "d_mu": 0.0}
        ihi = {**hi, "d_mu": hi["mu_s"] - lo["mu_c"]}
        if not split and "mu_c" in self.free:
            ihi["mu_c"] = min(hi["mu_c"], start.mu_s)      # mu_c <= fixed mu_s
        if not split and "mu_s" in self.free:
            ilo["mu_s"] = max(lo["mu_s"], start.mu_c)      # mu_s >= fixed mu_c
        x0 = self.x0
        xi0 = [x0["mu_s"] - x0["mu_c"] if k == "d_mu" else x0[k] for k in self.inames]
        self.lb = np.array([ilo[k] for k in self.inames])
        self.ub = np.array([ihi[k] for k in self.inames])
        pad = pad * (self.ub - self.lb)
        self.xi0 = np.clip(xi0, self.lb + pad, self.ub - pad)
        self.plo = {k: (lo[k] if k != "mu_s" or split else ilo["mu_s"]) for k in self.free}
        self.phi = {k: (hi[k] if k != "mu_c" or split else ihi["mu_c"]) for k in self.free}
        T = np.eye(len(self.inames))
        if split:
            T[self.free.index("mu_s"), self.inames.index("mu_c")] = 1.0   # d mu_s / d mu_c
        self.T = T

    def public(self, xi) -> dict:
        d = dict(zip(self.inames, (float(x) for x in xi)))
        if self.split:
            d["mu_s"] = d["mu_c"] + d.pop("d_mu")
        return {k: d[k] for k in self.free}

    def snap(self, x):
        """Estimates resting on a bound, snapped onto it."""
        lb, ub = self.lb, self.ub
        x = np.where(np.abs(x - lb) <= 1e-12 * (ub - lb), lb, x)
        return np.where(np.abs(ub - x) <= 1e-12 * (ub - lb), ub, x)

    def result(self, Jp, resid, xi, confidence, n, sol, extra=None) -> "FitResult":
        """A :class:`FitResult` from the public Jacobian and residuals at the optimum ``xi``."""
        pub = self.public(xi)
        st = _stats(Jp, resid, self.free, pub, self.plo, self.phi, confidence)
        if self.split:  # the constraint mu_c <= mu_s is the bound d_mu >= 0
            dm = pub["mu_s"] - pub["mu_c"]
            if dm <= 1e-9 * max(1.0, pub["mu_s"]):
                st["at_bound"]["mu_s"] = st["at_bound"]["mu_c"] = True
        return FitResult(names=self.free, estimate=pub, se=st["se"], ci_low=st["ci_low"], ci_high=st["ci_high"],
                         corr=st["corr"], cov=st["cov"], at_bound=st["at_bound"],
                         residual_rms=_rms(resid), n=n, dof=st["dof"],
                         confidence=confidence, cond=st["cond"], success=bool(sol.success), message=str(sol.message),
                         nfev=int(sol.nfev), extra={"start": dict(self.x0), **(extra or {})},
                         unidentifiable=st["unidentifiable"], rank=st["rank"])


def fit_steady_state(s, v, mu, start: LuGreParams, free=("sigma0", "sigma2", "mu_c", "mu_s", "v_s"),
                     bounds: dict | None = None, initial: dict | None = None, confidence: float = 0.95):
    """Stage 1 (module doc): fit FM eq. (4) to samples; returns ``(FitResult, fitted LuGreParams)``.

    Parameters
    ----------
    s, v, mu : array_like
        Slip [-], vehicle speed [m/s] and friction ``F/F_n`` [-] samples.
    start : LuGreParams
        Fixed values (``L``, ``alpha`` unless free, ...) and default starting values.
    free : sequence of str
        Parameters to fit, among :data:`STEADY_PARAMETERS`.
    bounds, initial : dict or None
        Per-parameter ``(low, high)`` and starting values (override the defaults / ``start``).
    """
    from scipy.optimize import least_squares

    s, v, mu = (np.asarray(a, dtype=float) for a in (s, v, mu))
    rw = romega_of(s, v)
    vr = rw - v
    sp = _Space(free, start, bounds, initial, STEADY_PARAMETERS)

    def model(xi):
        return replace(start, **sp.public(xi))

    def resid(xi):
        return mu_ss_uniform(vr, rw, model(xi)) - mu

    with np.errstate(all="ignore"):  # overflow on data beyond the model's reach: FitResult.failure says so
        sol = least_squares(resid, sp.xi0, bounds=(sp.lb, sp.ub), jac="3-point", x_scale="jac", method="trf",
                            xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=2000)
    x = sp.snap(sol.x)
    # Jacobian in public coordinates (mu_c, mu_s independent): J_internal = J_public @ T
    Jp = sol.jac @ np.linalg.inv(sp.T)
    res = sp.result(Jp, sol.fun, x, confidence, len(mu), sol)
    return res, model(x)


#: Parameters of the transient fit with the distributed model in the loop (:func:`fit_distributed`).
DISTRIBUTED_PARAMETERS = ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "alpha")
#: Relative finite-difference step of the Jacobian columns of the nonlinear parameters (central differences).
FD_STEP = 1e-6


def fit_distributed(t, v, romega, mu, start: LuGreParams, free=("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s"),
                    bounds: dict | None = None, initial: dict | None = None, confidence: float = 0.95,
                    use=None, red=None, substeps: int = 4, interpolation: str = "cubic"):
    """Stage 3: all transient parameters by least squares of ``mu(t)`` with the distributed model in the loop.

    The distributed LuGre tire (FM eqs. (1)-(2), load ``red``; default uniform) is driven open loop
    by the measured ``v(t)``, ``r omega(t)`` from ``z = 0`` at the first sample
    (:class:`tirecli.numerics.driven.DrivenDistributed`) and::

        min_p  sum_{i in use} (mu_model(t_i; p) - mu_i)^2,   p within bounds, mu_c <= mu_s

    by ``scipy.optimize.least_squares`` (dogbox trust region, start values moved 1e-3 of their
    range inside the bounds). Jacobian: exact columns for
    ``sigma1`` and ``sigma2`` (``mu`` is linear in them: ``dz/dt`` and ``vr``), central differences
    for the others, all parameter sets of one Jacobian in one vectorised model call. Statistics as
    the steady-state fit (module doc).

    Parameters
    ----------
    t, v, romega, mu : array_like
        Sample times [s] (increasing), speed [m/s], ``r omega`` [m/s] and friction [-].
    start : LuGreParams
        Starting values (and the fixed ``L``, ``alpha`` unless free, ...).
    free : sequence of str
        Among :data:`DISTRIBUTED_PARAMETERS`.
    use : array_like of bool or None
        Samples compared (all by default); the others still drive the model.
    Returns
    -------
    (FitResult, LuGreParams, dict)
        The fit, the fitted set and ``{"mu_model", "zbar", "zdot"}`` at every sample.
    """
    from scipy.optimize import least_squares

    from tirecli.numerics.driven import DrivenDistributed

    t, v, romega, mu = (np.asarray(a, dtype=float) for a in (t, v, romega, mu))
    use = np.ones(len(t), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    model = DrivenDistributed(t, v, romega, start.L, red, substeps, interpolation)
    vr = model.vr
    # starting values a little inside the bounds: the dogbox method cannot leave a start on a bound
    sp = _Space(free, start, bounds, initial, DISTRIBUTED_PARAMETERS, pad=1e-3)
    nonlin = [k for k in ("sigma0", "mu_c", "mu_s", "v_s", "alpha") if k in sp.free]
    base = start.as_dict()
    cache = {}

    def rows(pub_list):
        """``(mu, zbar, zdot)`` at the samples for a list of public parameter dicts (one model call)."""
        cols = {k: np.array([{**base, **pp}[k] for pp in pub_list]) for k in
                ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "alpha")}
        z, zd = model.states(cols["sigma0"], cols["mu_c"], cols["mu_s"], cols["v_s"], cols["alpha"])
        m = cols["sigma0"][:, None] * z + cols["sigma1"][:, None] * zd + cols["sigma2"][:, None] * vr[None, :]
        return m, z, zd

    def fun(xi):
        key = np.asarray(xi).tobytes()
        if key not in cache:
            cache.clear()
            m, z, zd = rows([sp.public(xi)])
            cache[key] = (m[0], z[0], zd[0])
        return cache[key][0][use] - mu[use]

    def jac_public(xi):
        pub = sp.public(xi)
        steps, sets = [], []
        for k in nonlin:
            hk = FD_STEP * max(abs(pub[k]), 1e-3)
            steps.append(hk)
            sets += [{**pub, k: pub[k] + hk}, {**pub, k: pub[k] - hk}]
        J = np.empty((int(use.sum()), len(sp.free)))
        if sets:
            m, _, _ = rows(sets)
            for i, (k, hk) in enumerate(zip(nonlin, steps)):
                J[:, sp.free.index(k)] = (m[2 * i] - m[2 * i + 1])[use] / (2.0 * hk)
        fun(xi)
        _, z, zd = cache[np.asarray(xi).tobytes()]
        if "sigma1" in sp.free:
            J[:, sp.free.index("sigma1")] = zd[use]
        if "sigma2" in sp.free:
            J[:, sp.free.index("sigma2")] = vr[use]
        return J

    # dogbox: on this ill-conditioned problem (mu_c, v_s correlated) 3-4x fewer iterations than trf, same optimum
    with np.errstate(all="ignore"):
        sol = least_squares(fun, sp.xi0, jac=lambda xi: jac_public(xi) @ sp.T, bounds=(sp.lb, sp.ub), x_scale="jac",
                            method="dogbox", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200)
    x = sp.snap(sol.x)
    resid = fun(x)
    res = sp.result(jac_public(x), resid, x, confidence, int(use.sum()), sol,
                    extra={"njev": int(sol.njev or 0), "substeps": int(substeps), "interpolation": interpolation})
    p = replace(start, **sp.public(x))
    m, z, zd = cache[np.asarray(x).tobytes()]
    return res, p, {"mu_model": m, "zbar": z, "zdot": zd}


def fit_sigma1(mu, z, zdot, vr, p: LuGreParams, bounds=(0.0, 100.0), confidence: float = 0.95) -> FitResult:
    """Stage 2 (module doc): ``sigma1`` [s/m] by linear least squares of ``mu - sigma0 z - sigma2 vr = sigma1 dz/dt``.

    ``z`` [m], ``zdot`` [m/s], ``vr`` [m/s] come from the tire model driven by the measured kinematics.
    """
    mu, z, zdot, vr = (np.asarray(a, dtype=float) for a in (mu, z, zdot, vr))
    with np.errstate(all="ignore"):
        y = mu - p.sigma0 * z - p.sigma2 * vr
        den = float(zdot @ zdot)
        s1 = float(zdot @ y) / den if den > 0 else 0.0
        s1 = min(max(s1, bounds[0]), bounds[1]) if np.isfinite(s1) else s1
        resid = s1 * zdot - y
    st = _stats(zdot[:, None], resid, ["sigma1"], {"sigma1": s1}, {"sigma1": bounds[0]}, {"sigma1": bounds[1]},
                confidence)
    return FitResult(names=["sigma1"], estimate={"sigma1": s1}, se=st["se"], ci_low=st["ci_low"],
                     ci_high=st["ci_high"], corr=st["corr"], cov=st["cov"], at_bound=st["at_bound"],
                     residual_rms=_rms(resid), n=len(mu), dof=st["dof"],
                     confidence=confidence, cond=st["cond"], success=den > 0,
                     message="linear least squares" if den > 0 else "dz/dt is zero: sigma1 is not identifiable",
                     nfev=1, unidentifiable=st["unidentifiable"], rank=st["rank"])
