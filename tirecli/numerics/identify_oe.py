"""Output-error identification of the LuGre tire: the coupled quarter car simulated from the brake torque.

The equation-error fits of :mod:`tirecli.numerics.identify` drive the tire model with the measured
``v(t)`` and ``r omega(t)``, interpolated between the samples. Through a wheel lock and its release
those kinematics have kinks (``omega`` stops, then jumps back into rolling within a few
milliseconds) that no interpolant through 100 Hz samples reproduces, and the friction the model
computes from them is biased there. The output-error fit instead simulates what was measured::

    min_p  sum_c sum_{i in use} ((y_c(t_i; p) - y_c,i) / s_c)^2,     c in {v, r omega, mu}

with ``y(t; p)`` the coupled quarter car (docs/models/lugre_friction.md §7: ``m dv/dt = mu F_n``,
``J domega/dt = -r mu F_n - sigma_w omega + u``, the lumped or distributed tire) driven by the
measured wheel torque ``u(t)`` (or brake pressure times its gain) from the state at the first
sample, with the candidate parameters ``p``. The simulator (:func:`tirecli.numerics.runs.quarter_car`:
adaptive ROS2 steps ending at every sample time, the wheel lock and its release located as
events) produces ``v``, ``r omega`` and ``mu`` itself: no interpolated kinematics enter, the lock
and the unlock happen in the model where the candidate parameters put them.

**Channels and weights.** Each channel's residual is divided by its scale ``s_c`` (in the
channel's unit), which should be its noise level: then every channel counts by its information
and the weighted residuals have unit variance. ``scales`` gives them (e.g. the logger's noise
levels); by default (:data:`WEIGHTING` ``"noise"``) they are estimated: a first fit with each
channel scaled by its range over the samples compared, then each channel's scale set to the RMS of
its residuals there (not below :data:`SCALE_FLOOR` times its range: a channel the model reproduces
to the solver's accuracy must not take all the weight) and the fit repeated (maximum likelihood
with one unknown noise level per channel). ``"range"`` keeps the range scales. The statistics
(standard errors, intervals, correlations; :func:`tirecli.numerics.identify._stats`) come from the
weighted residuals and the Jacobian at the optimum, so they assume the scales are right up to one
common factor.

**Input between samples.** ``torque`` is a profile (:mod:`tirecli.models.profiles`) in the data's
time: the config's profile when the data are synthetic from a config, or
:func:`torque_from_samples` through the measured samples, ``linear`` (first-order hold, the
default) or ``zoh`` (zero-order hold, for a logger that holds its last value).

**Initial state.** The run starts at the first sample with undeflected bristles, ``v0`` and
``omega0`` from the first samples (or given). With noisy speeds ``v0`` should be fitted (a wrong
initial speed shifts the whole ``v(t)``): add ``"v0"`` to ``free`` (then ``omega0`` moves with it,
keeping the initial slip), or ``"omega0"`` for the wheel too.

**Jacobian.** Forward differences, each parameter moved by :attr:`OEOptions.fd_step` times its
magnitude (at least a hundredth of its bound range) towards the inside of its bounds, one run per
parameter. An adaptive integrator's result is not a smooth function of the parameters: a change of
its step sequence moves it by about the tolerance, so the step must move the outputs well above the
solver's accuracy (``fd_step`` 1e-3 against ``tol`` <= 1e-4; the forward difference's own error,
``fd_step`` relative, only slows the Gauss-Newton steps). A lock or release time moves with the
parameters, but ``v``, ``omega`` and ``mu`` stay continuous through it (only their slopes jump), so
a difference straddling an event is bounded and touches the one or two samples nearest it.

**Stages.** The iterations run at the loose :attr:`OEOptions.tol` (each run a fraction of a second),
then a few Gauss-Newton iterations at the tight :attr:`OEOptions.tol_final` refine the optimum and
give the Jacobian of the statistics (a Gauss-Newton step from near the optimum converges in one or
two iterations; the tight runs cost ~5x the loose ones).

**Identifiability.** The weighted Jacobian with each column scaled by its parameter's magnitude
is decomposed (SVD); singular values below :data:`RANK_RTOL` times the largest span directions the
data do not determine. The parameters with a weight above :data:`NULL_WEIGHT` in such a direction
are named (``extra["not_identifiable"]``) and get no interval (NaN standard error and bounds).

No I/O. Public entry: :func:`fit_output_error`.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from tirecli.errors import RunError
from tirecli.models.lugre import LuGreParams
from tirecli.models.profiles import Constant, Table
from tirecli.models.variants import FrictionVariant
from tirecli.models.vehicle import QuarterCarParams
from tirecli.numerics import runs
from tirecli.numerics.identify import FitResult, _Space, _rms

#: Tire parameters the output-error fit may free.
OE_PARAMETERS = ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "alpha")
#: Initial-state parameters it may free: the vehicle speed [m/s] and wheel speed [rad/s] at the first sample.
INITIAL_PARAMETERS = ("v0", "omega0")
#: The measured channels it compares, and their units.
CHANNELS = ("v", "romega", "mu")
CHANNEL_UNITS = {"v": "m/s", "romega": "m/s", "mu": "-"}
#: Channel weighting (module doc).
WEIGHTINGS = ("noise", "range")
#: Smallest estimated channel scale, relative to the channel's range over the samples compared.
SCALE_FLOOR = 1e-6
#: Singular values of the scaled Jacobian below this fraction of the largest: directions the data do not determine.
RANK_RTOL = 1e-7
#: Weight (squared component) of a parameter in an undetermined direction above which it is named.
NULL_WEIGHT = 0.05
#: Measured slip beyond which a braked wheel is taken to run into a lock: the continuation stage ends before it.
CONTINUATION_SLIP = 0.2
#: Fewest samples compared per fitted parameter in a stage.
MIN_PER_PARAMETER = 3
#: Weighted residual of a run that failed (a step-size underflow at absurd candidate parameters): large and finite,
#: so the trust region shrinks back.
FAILED_RESIDUAL = 1e6


@dataclass(frozen=True)
class OEOptions:
    """Numerical options of :func:`fit_output_error` (module doc, *Stages*).

    Attributes
    ----------
    tol : float
        Local error tolerance of the runs of stage 1 (m/s for the speeds, friction units for the tire).
    fd_step : float
        Relative forward-difference step of the Jacobian in stage 1.
    ftol : float
        Stage 1 ends when an iteration lowers the cost by less than this fraction (or after ``max_nfev`` runs).
    max_nfev : int
        Most residual runs of stage 1 (each Jacobian costs one run per free parameter more).
    tol_final : float
        Tolerance of the runs of stage 2 and of the statistics.
    fd_step_final : float
        Relative central-difference step of the Jacobian of stage 2.
    final_nfev : int
        Most residual runs of stage 2.
    refresh : float
        Stage 2 recomputes its Jacobian when the parameters have moved by more than this fraction of
        their magnitude since it was computed (and at the end, for the statistics).
    continuation : bool
        Fit the samples before the wheel runs into a lock first (stage 0).
    h_max : float
        Largest solver step [s].
    v_stop : float
        The runs end when ``v`` falls to it [m/s] (later samples compare with the end state).
    """

    tol: float = 3e-4
    fd_step: float = 1e-3
    ftol: float = 0.25
    max_nfev: int = 30
    tol_final: float = 3e-5
    fd_step_final: float = 1e-4
    final_nfev: int = 8
    refresh: float = 1e-3
    continuation: bool = True
    h_max: float = 0.05
    v_stop: float = 0.1


class _Shifted:
    """A profile in the data's time seen from the run's time ``t - t0`` (the run starts at 0)."""

    def __init__(self, prof, t0: float):
        self.prof, self.t0 = prof, float(t0)

    def __call__(self, t):
        return self.prof(np.asarray(t, dtype=float) + self.t0) if np.ndim(t) else self.prof(t + self.t0)

    def at(self, t):
        return self.prof.at(t + self.t0)

    def breakpoints(self, t_end=None):
        return tuple(b - self.t0 for b in self.prof.breakpoints(None if t_end is None else t_end + self.t0)
                     if b > self.t0)

    def record(self):
        return {"kind": "shifted", "t0": self.t0, "of": self.prof.record()}


def torque_from_samples(t, torque, hold: str = "linear") -> Table:
    """The wheel-torque profile [N m] through measured samples (signed: < 0 brakes).

    ``hold``: ``linear`` (first-order hold: straight lines between the samples) or ``zoh`` (each sample
    held until the next). Constant before the first and after the last sample.
    """
    t, u = np.asarray(t, dtype=float), np.asarray(torque, dtype=float)
    if hold == "linear":
        return Table(tuple(t.tolist()), tuple(u.tolist()), source="samples (linear)")
    if hold != "zoh":
        raise ValueError(f"hold must be 'linear' or 'zoh', not {hold!r}")
    tt = np.repeat(t, 2)[1:]
    uu = np.repeat(u, 2)[:-1]
    return Table(tuple(tt.tolist()), tuple(uu.tolist()), source="samples (zero-order hold)")


class _Problem:
    """The simulated outputs, residuals and Jacobian of one output-error fit (module doc)."""

    def __init__(self, t, data: dict, use: dict, torque, theta, start: LuGreParams, car: QuarterCarParams,
                 variant: FrictionVariant, v0: float, omega0: float, options: OEOptions):
        self.t0 = float(t[0])
        self.tau = np.asarray(t, dtype=float) - self.t0
        self.data, self.use = data, use
        self.torque = torque if self.t0 == 0.0 else _Shifted(torque, self.t0)
        self.theta = theta if self.t0 == 0.0 else _Shifted(theta, self.t0)
        self.start, self.car, self.variant = start, car, variant
        self.v0, self.omega0 = float(v0), float(omega0)
        self.options = options
        self.scales = {c: 1.0 for c in data}
        self.runs = 0
        self.cache: dict = {}

    def initial(self, pub: dict) -> tuple:
        v0 = pub.get("v0", self.v0)
        if "omega0" in pub:
            return v0, pub["omega0"]
        return v0, self.omega0 * (v0 / self.v0 if self.v0 != 0.0 else 1.0)

    def simulate(self, pub: dict, tol: float):
        """``({channel: model values at every sample}, trajectory)`` of the run with the public values ``pub``."""
        key = (tol,) + tuple(sorted(pub.items()))
        if key in self.cache:
            return self.cache[key]
        p = replace(self.start, **{k: v for k, v in pub.items() if k in OE_PARAMETERS})
        v0, omega0 = self.initial(pub)
        o = self.options
        self.runs += 1
        try:
            tr = runs.quarter_car(self.variant, p, self.car, self.torque, self.theta, v0, omega0, float(self.tau[-1]),
                                  runs.SolverOptions(tol=tol, h_max=o.h_max, v_stop=o.v_stop), self.tau)
        except RunError:
            out = None, None
        else:
            Y, O = tr.sample(self.tau)
            out = {"v": Y[:, 0], "romega": self.car.r * Y[:, 1], "mu": np.asarray(O["mu"], dtype=float)}, tr
        if len(self.cache) > 64:
            self.cache.clear()
        self.cache[key] = out
        return out

    def residual(self, model: dict | None, scales: dict | None = None) -> np.ndarray:
        """Weighted residuals ``(model - data)/scale`` of every channel at its samples compared, stacked."""
        sc = self.scales if scales is None else scales
        if model is None:
            return np.full(self.n, FAILED_RESIDUAL)
        return np.concatenate([(model[c][u] - self.data[c][u]) / sc[c] for c, u in self.use.items()])

    @property
    def n(self) -> int:
        return int(sum(int(u.sum()) for u in self.use.values()))

    def raw(self, model: dict) -> dict:
        """Unweighted residuals per channel at the samples compared."""
        return {c: model[c][u] - self.data[c][u] for c, u in self.use.items()}

    def jacobian(self, sp: _Space, xi, tol: float, step: float, central: bool = False) -> np.ndarray:
        """Finite-difference Jacobian of the weighted residuals in the public coordinates (module doc):
        forward differences, or ``central`` ones where both sides lie within the bounds."""
        pub = sp.public(xi)
        base = self.residual(self.simulate(pub, tol)[0])
        J = np.empty((base.size, len(sp.free)))
        for i, k in enumerate(sp.free):
            lo, hi = sp.plo[k], sp.phi[k]
            h = step * max(abs(pub[k]), 0.01 * (hi - lo))
            if central and lo <= pub[k] - h and pub[k] + h <= hi:
                up = self.residual(self.simulate({**pub, k: pub[k] + h}, tol)[0])
                down = self.residual(self.simulate({**pub, k: pub[k] - h}, tol)[0])
                J[:, i] = (up - down) / (2.0 * h)
                continue
            if pub[k] + h > hi:
                h = -h
            moved = self.residual(self.simulate({**pub, k: pub[k] + h}, tol)[0])
            J[:, i] = (moved - base) / h
        return J


def _ranges(data: dict, use: dict) -> dict:
    return {c: max(float(np.ptp(data[c][u])) if u.any() else 0.0, 1e-12) for c, u in use.items()}


def identifiability(J, names, estimate: dict, spans: dict) -> tuple[list, float]:
    """``(names not identifiable, smallest relative singular value)`` of a Jacobian (module doc).

    Each column is scaled by its parameter's magnitude (at least a hundredth of its bound range ``spans``),
    so the singular values compare relative changes.
    """
    J = np.asarray(J, dtype=float)
    if J.size == 0:
        return [], float("nan")
    scale = np.array([max(abs(estimate[k]), 0.01 * spans[k]) for k in names])
    Js = J * scale[None, :]
    if not np.all(np.isfinite(Js)):
        return list(names), float("nan")
    _, s, Vt = np.linalg.svd(Js, full_matrices=False)
    if s[0] <= 0.0:
        return list(names), 0.0
    rel = s / s[0]
    weak = Vt[rel < RANK_RTOL]
    named = [k for j, k in enumerate(names) if weak.size and np.any(weak[:, j] ** 2 > NULL_WEIGHT)]
    return named, float(rel[-1])


def _channels(t, given: dict, use):
    """``(data, masks)``: the channels given (arrays over ``t``) and the samples each compares (finite ones)."""
    data = {c: np.asarray(a, dtype=float) for c, a in given.items()}
    for c, a in data.items():
        if a.shape != t.shape:
            raise ValueError(f"channel {c}: {a.size} values for {t.size} times")
    if isinstance(use, dict):
        masks = {c: np.asarray(use.get(c, np.ones(t.size, bool)), dtype=bool) for c in data}
    else:
        m = np.ones(t.size, dtype=bool) if use is None else np.asarray(use, dtype=bool)
        masks = {c: m for c in data}
    return data, {c: m & np.isfinite(data[c]) for c, m in masks.items()}


def continuation_end(t, data: dict, masks: dict, need: int) -> int | None:
    """Number of leading samples of the continuation stage (module doc, *Stages*), or None.

    The samples before the first one where the measured slip ``|r omega - v| / max(v, r omega)`` exceeds
    :data:`CONTINUATION_SLIP`, when there is one and at least ``need`` samples are compared before it.
    """
    if "v" not in data or "romega" not in data:
        return None
    v, rw = data["v"], data["romega"]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.abs(rw - v) / np.maximum(np.maximum(v, rw), 1e-9)
    deep = np.flatnonzero(np.isfinite(s) & (s > CONTINUATION_SLIP))
    if deep.size == 0:
        return None
    end = int(deep[0])
    if sum(int(m[:end].sum()) for m in masks.values()) < need:
        return None
    return end


def _coarse(prob: _Problem, sp: _Space, xi, o: OEOptions):
    """Stage 1 of a problem (module doc): trust-region least squares at the loose tolerance, forward differences."""
    from scipy.optimize import least_squares

    with np.errstate(all="ignore"):
        return least_squares(lambda x: prob.residual(prob.simulate(sp.public(x), o.tol)[0]), xi,
                             jac=lambda x: prob.jacobian(sp, x, o.tol, o.fd_step) @ sp.T, bounds=(sp.lb, sp.ub),
                             x_scale="jac", method="trf", xtol=1e-8, ftol=o.ftol, gtol=1e-12, max_nfev=o.max_nfev)


def _record(sol, runs: int) -> dict:
    return {"nfev": int(sol.nfev), "njev": int(sol.njev or 0), "runs": int(runs), "cost": float(sol.cost),
            "message": str(sol.message)}


def fit_output_error(t, torque, start: LuGreParams, car: QuarterCarParams, *, v=None, romega=None, mu=None,
                     free=("sigma0", "sigma1", "mu_c", "mu_s", "v_s"), variant: FrictionVariant | None = None,
                     theta=None, bounds: dict | None = None, initial: dict | None = None,
                     confidence: float = 0.95, use=None, scales: dict | None = None, weighting: str = "noise",
                     v0: float | None = None, omega0: float | None = None, options: OEOptions = OEOptions()):
    """Output-error fit of the LuGre parameters (module doc): the coupled quarter car from the torque against the data.

    Parameters
    ----------
    t : array_like
        Sample times [s], increasing; the run starts at ``t[0]``.
    torque : profile
        Signed wheel torque ``u(t)`` [N m] in the data's time (< 0 brakes; brake pressure times its gain,
        negated): a profile of :mod:`tirecli.models.profiles`, e.g. :func:`torque_from_samples`.
    start : LuGreParams
        Starting values and the fixed parameters (``L``, ``kappa0``, ``sigma_w``, the others not in ``free``).
    car : QuarterCarParams
        The quarter car (radius [m], mass [kg], wheel inertia [kg m^2], load [N]).
    v, romega, mu : array_like or None
        Measured vehicle speed [m/s], wheel circumferential speed ``r omega`` [m/s] and friction ``F/F_n`` [-]
        at ``t`` (None: channel not compared; NaN: sample missing). At least one.
    free : sequence of str
        Parameters to fit, among :data:`OE_PARAMETERS` and :data:`INITIAL_PARAMETERS`.
    variant : FrictionVariant or None
        The tire model (default: distributed, uniform load).
    theta : profile or None
        Road adhesion (FM convention; default 1).
    bounds, initial : dict or None
        Per-parameter ``(low, high)`` and starting values (defaults: :data:`tirecli.numerics.identify.DEFAULT_BOUNDS`
        and ``start``; ``v0`` within 20 % of its start, ``omega0`` within 50 %).
    use : array_like of bool, or dict channel -> array of bool, or None
        Samples compared (all by default); the run covers all of them.
    scales : dict or None
        Channel -> scale [channel unit] (its noise level): fixed weights, ``weighting`` ignored.
    weighting : str
        ``noise`` or ``range`` (module doc), when ``scales`` is not given.
    v0, omega0 : float or None
        Initial vehicle [m/s] and wheel [rad/s] speed (default: the first ``v`` and ``romega / r`` samples).
    options : OEOptions

    Returns
    -------
    (FitResult, LuGreParams, dict)
        The fit (``n``: the residuals compared, over all channels; ``residual_rms``: of ``mu`` when compared,
        else of the weighted residuals; ``extra``: per-channel RMS, scales, runs per stage, wall time, the
        fitted run's wheel locks, ``not_identifiable``), the fitted set, and the fitted run at every sample:
        ``t`` and the model's ``v_model``, ``romega_model``, ``mu_model``, ``locks`` (``[t_lock, t_unlock]``
        in the data's time).
    """
    from scipy.optimize import least_squares

    wall = time.perf_counter()
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2 or np.any(np.diff(t) <= 0):
        raise ValueError("t must be increasing with at least two samples")
    given = {c: a for c, a in (("v", v), ("romega", romega), ("mu", mu)) if a is not None}
    if not given:
        raise ValueError("no channel to compare: give v, romega and/or mu")
    data, masks = _channels(t, given, use)
    unknown = [k for k in free if k not in OE_PARAMETERS + INITIAL_PARAMETERS]
    if unknown:
        raise ValueError(f"unknown parameter(s) {unknown} (expected among {OE_PARAMETERS + INITIAL_PARAMETERS})")
    if weighting not in WEIGHTINGS:
        raise ValueError(f"weighting must be one of {WEIGHTINGS}")
    variant = variant or FrictionVariant(model="distributed")
    theta = theta or Constant(1.0)
    if v0 is None:
        v0 = float(data["v"][0]) if "v" in data and np.isfinite(data["v"][0]) else float("nan")
    if omega0 is None:
        omega0 = float(data["romega"][0]) / car.r if "romega" in data and np.isfinite(data["romega"][0]) else v0 / car.r
    if not (np.isfinite(v0) and np.isfinite(omega0)):
        raise ValueError("no initial state: give v0 (and omega0) when the first v sample is missing")
    o = options
    prob = _Problem(t, data, masks, torque, theta, start, car, variant, v0, omega0, o)
    all_bounds = {"v0": (0.8 * v0, 1.2 * v0 + 1e-3), "omega0": (0.5 * omega0, 1.5 * omega0 + 1e-3), **(bounds or {})}
    init = {"v0": v0, "omega0": omega0, **(initial or {})}
    sp = _Space(free, start, all_bounds, init, OE_PARAMETERS + INITIAL_PARAMETERS, pad=1e-6)
    spans = {k: sp.phi[k] - sp.plo[k] for k in sp.free}
    ranges = _ranges(data, masks)
    prob.scales = {c: float(scales[c]) for c in data} if scales is not None else dict(ranges)

    def moved(xa, xb) -> float:
        """Largest change of a parameter between two internal points, relative to its magnitude."""
        pa, pb = sp.public(xa), sp.public(xb)
        return max(abs(pa[k] - pb[k]) / max(abs(pb[k]), 0.01 * spans[k]) for k in sp.free)

    stages, xi = {}, sp.xi0
    # stage 0: the samples before the wheel runs into a lock (module doc)
    end = continuation_end(t, data, masks, MIN_PER_PARAMETER * len(sp.free) + 1) if o.continuation else None
    if end is not None:
        part = _Problem(t[:end], {c: a[:end] for c, a in data.items()}, {c: m[:end] for c, m in masks.items()},
                        torque, theta, start, car, variant, v0, omega0, o)
        part.scales = prob.scales
        sol0 = _coarse(part, sp, xi, o)
        xi = sol0.x
        stages["stage0"] = {**_record(sol0, part.runs), "samples": int(end), "t_end": float(t[end - 1])}
    # stage 1: all samples, loose tolerance
    sol = _coarse(prob, sp, xi, o)
    xi, nfev, njev = sol.x, sol.nfev, sol.njev or 0
    stages["stage1"] = _record(sol, prob.runs)
    if scales is None and weighting == "noise":  # each channel by its residual RMS (module doc)
        raw = prob.raw(prob.simulate(sp.public(xi), o.tol)[0])
        prob.scales = {c: max(_rms(r), SCALE_FLOOR * ranges[c]) for c, r in raw.items()}
    # stage 2: tight tolerance, central differences, the Jacobian kept while the parameters move little
    chord = {"x": None, "J": None}

    def jac_final(x):
        nonlocal njev
        if chord["x"] is None or moved(x, chord["x"]) > o.refresh:
            chord["J"] = prob.jacobian(sp, x, o.tol_final, o.fd_step_final, central=True)
            chord["x"] = np.array(x, dtype=float)
            njev += 1
        return chord["J"] @ sp.T

    if o.final_nfev > 0:
        runs1 = prob.runs
        with np.errstate(all="ignore"):
            fin = least_squares(lambda x: prob.residual(prob.simulate(sp.public(x), o.tol_final)[0]), xi, jac=jac_final,
                                bounds=(sp.lb, sp.ub), x_scale="jac", method="trf", xtol=1e-10, ftol=1e-8, gtol=1e-12,
                                max_nfev=o.final_nfev)
        xi, nfev = fin.x, nfev + fin.nfev
        stages["stage2"] = _record(fin, prob.runs - runs1)
        sol = fin if fin.success or not sol.success else sol
    x = sp.snap(xi)
    pub = sp.public(x)
    model, tr = prob.simulate(pub, o.tol_final)
    resid = prob.residual(model)
    jac_final(x)
    Jp = chord["J"]
    raw = prob.raw(model) if model is not None else {c: np.full(int(u.sum()), np.nan) for c, u in masks.items()}
    locks = [[a + prob.t0, None if b is None else b + prob.t0] for a, b in tr.events["lock"]] if tr is not None else []
    named, rel = identifiability(Jp, sp.free, pub, spans)
    extra = {"method": "output-error", "channels": list(data), "scales": dict(prob.scales),
             "weighting": "given" if scales is not None else weighting,
             "channel_rms": {c: _rms(r) for c, r in raw.items()}, "weighted_rms": _rms(resid),
             "runs": prob.runs + sum(s_.get("runs", 0) for k, s_ in stages.items() if k == "stage0"),
             "njev": int(njev), "tol": o.tol, "tol_final": o.tol_final, "jacobian_moved": moved(x, chord["x"]),
             **stages, "wall_time_s": round(time.perf_counter() - wall, 3), "locks": locks,
             "initial_state": dict(zip(("v0", "omega0"), prob.initial(pub))),
             "smallest_relative_singular_value": rel, "not_identifiable": named}
    res = sp.result(Jp, resid, x, confidence, prob.n, sol, extra)
    res.nfev = int(nfev)
    if "mu" in raw:
        res.residual_rms = _rms(raw["mu"])
    for k in named:  # no interval for what the data do not determine
        res.se[k] = res.ci_low[k] = res.ci_high[k] = float("nan")
    if named:
        res.message = f"{res.message.rstrip('.')}; not identifiable from these data: {', '.join(named)}"
    fitted = replace(start, **{k: val for k, val in pub.items() if k in OE_PARAMETERS})
    at_samples = {"t": t, "locks": locks}
    for c in CHANNELS:
        at_samples[f"{c}_model"] = model[c] if model is not None else np.full(t.size, np.nan)
    return res, fitted, at_samples
