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
channel's unit), which should be its noise level: then every channel counts by its information and
the weighted residuals have unit variance. ``scales`` gives them (e.g. the logger's noise levels).
By default (``weighting="noise"``) they are estimated: stages 1-2 (below) scale each channel by its
range over the samples compared; then each channel's scale is set to the RMS of its residuals at
that optimum and stage 2 repeated, until no scale changes by more than 20 % (at most
:data:`REWEIGHTS` times; maximum likelihood with one unknown noise level per channel). A scale never
falls below ``tol_final`` (the simulator's own accuracy, in the channel's unit: its error control
works in m/s for the speeds and in friction units for the tire) nor below :data:`SCALE_FLOOR` times
the range: a channel the model reproduces to the solver's accuracy (a noise-free ``mu``) must not
take all the weight. ``"range"`` keeps the range scales. The statistics (standard errors, Student-t
intervals, correlations: :func:`tirecli.numerics.identify._stats`) come from the weighted residuals
and the Jacobian at the optimum, so they hold when the scales are right up to one common factor and
the input is exact: noise on the measured torque or pressure (errors in the input) biases the
estimates and is not in the intervals.

**Input between samples.** ``torque`` is a profile (:mod:`tirecli.models.profiles`) in the data's
time: the config's profile when the data are synthetic from a config, or
:func:`torque_from_samples` through the measured samples, ``linear`` (first-order hold, the
default) or ``zoh`` (zero-order hold, for a logger that holds its last value). While the wheel is
locked a brake transmits only the torque that holds it: the input is the brake's torque (pressure
times gain), not the transmitted one.

**Initial state.** The run starts at the first sample with undeflected bristles, ``v0`` and
``omega0`` from the first samples (or given). With noisy speeds fit ``v0`` (add ``"v0"`` to
``free``; ``omega0`` then moves with it, keeping the initial slip: a wrong initial speed shifts the
whole ``v(t)``) and compare from a few samples on (``use``): the wheel's start transient depends
on the initial slip, which a noisy first sample does not give (or fit ``"omega0"`` too).

**Jacobian.** Forward differences, each parameter moved by :attr:`OEOptions.fd_step` (1e-6) times
its magnitude (at least a hundredth of its bound range) towards the inside of its bounds, one run
per parameter. An adaptive integrator's result is a piecewise smooth function of the parameters:
smooth while its discrete decisions (a step accepted or rejected, a step shortened to end on a
sample) stay the same, with jumps of about the tolerance where one flips. A relative step of 1e-6
almost never flips one, so the difference is the derivative of the smooth piece, accurate to about
the solver's tolerance; a step of 1e-3 flips many and its truncation error is large where the
wheel runs into the lock (measured on a braking with a lock, from parameters 0.1-0.4 % off: one
Gauss-Newton step lands within 1.2e-4 of the truth with 1e-6 at ``tol`` 3e-5 and within 4e-4 at
``tol`` 1e-4, but barely moves (3.4e-3 left) with 1e-3 at ``tol`` 1e-4; at ``tol`` 3e-4 no step
size does better than 3e-3). A lock or release time moves with the parameters, but ``v``, ``omega`` and ``mu`` stay
continuous through it (only their slopes jump): a difference straddling an event is bounded and
touches the one or two samples nearest it.

**Stages.** 1: trust-region least squares (``scipy.optimize.least_squares``, ``trf``) with runs
at :attr:`OEOptions.tol` (1e-4). 2: the same from there with runs at ``tol_final`` (3e-5), the
Jacobian kept while the parameters move less than ``refresh`` (a chord method: near the optimum a
step costs one run instead of one per parameter more); the statistics use a Jacobian computed
within ``refresh`` of the final point. 3 (``weighting="noise"``): re-weighting, each followed by stage 2.

**Starting values.** With a wheel lock the cost has local minima: where the model locks and
unlocks earlier or later than the data, the speeds part for the rest of the record. Start from
estimates within a few per cent, e.g. the steady-state fit of FM eq. (4) to the ``(s, v, mu)``
samples (:func:`tirecli.numerics.identify.fit_steady_state`) or the equation-error fit with the
distributed model (:func:`tirecli.numerics.identify.fit_distributed`) on low-noise kinematics.
Measured on a SYNTHETIC braking that locks the wheel: from the steady-state fit on noisy samples
(5-10 % off) the fit reaches the optimum; from FM Table 1's values (``v_s`` 19 % off, no lock in the
model) it ends in a local minimum (``r omega`` residual 1.2 m/s RMS, ``residual_rms`` large).

**Identifiability.** The weighted Jacobian with each column scaled by its parameter's magnitude
is decomposed (SVD); singular values below :data:`RANK_RTOL` times the largest span directions the
data do not determine (the forward differences resolve about 1e-6 of a column). The parameters with
a weight above :data:`NULL_WEIGHT` in such a direction are named (``extra["not_identifiable"]``,
and in ``message``) and get no interval (NaN standard error and bounds). Weakly determined directions
pass this test: on FM's braking #2 (no lock, slip down to -0.18, below the force peak), noise-free, the fit
ends at ``mu_c`` 27 % and ``v_s`` 16 % off with a residual no larger than the truth's (the simulator's
accuracy); a braking that reaches the peak (a lock) determines them (benchmarks/bench_identify_oe.py).

**Calling it** (e.g. from the ``fit`` study as ``fit.method: output-error``; the study does the I/O,
the size check and the one-line errors)::

    from tirecli.numerics.identify_oe import fit_output_error, torque_from_samples

    # t [s], v [m/s], romega [m/s], mu [-], pressure [bar] at the samples; gain [N m/bar]
    u = torque_from_samples(t, -gain * pressure)           # signed wheel torque, < 0 brakes
    res, fitted, out = fit_output_error(t, u, start, car, v=v, romega=romega, mu=mu,
                                        free=("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s"))
    res.estimate, res.se, res.ci_low, res.ci_high        # dicts by parameter (FitResult)
    res.extra["not_identifiable"], res.extra["locks"]    # named parameters, [t_lock, t_unlock] pairs
    out["v_model"], out["romega_model"], out["mu_model"] # the fitted run at every sample (for figures)

``start`` (a :class:`LuGreParams`) should be the steady-state or the driven distributed fit (see
*Starting values*); ``car`` the :class:`QuarterCarParams`; noisy data: add ``"v0"`` to ``free`` and
pass ``use=t >= t[0] + 0.05``. ``variant=FrictionVariant(model="lumped", kappa0="Z")`` fits the lumped model.

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
from tirecli.numerics.identify import UNITS, FitResult, _Space, _rms

#: Tire parameters the output-error fit may free.
OE_PARAMETERS = ("sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s", "alpha")
#: Initial-state parameters it may free: the vehicle speed [m/s] and wheel speed [rad/s] at the first sample.
INITIAL_PARAMETERS = ("v0", "omega0")
#: The measured channels it compares, and their units.
CHANNELS = ("v", "romega", "mu")
CHANNEL_UNITS = {"v": "m/s", "romega": "m/s", "mu": "-"}
#: Units of the initial-state parameters (the tire's: :data:`tirecli.numerics.identify.UNITS`).
INITIAL_UNITS = {"v0": "m/s", "omega0": "rad/s"}
#: Channel weighting (module doc).
WEIGHTINGS = ("noise", "range")
#: Smallest estimated channel scale, relative to the channel's range over the samples compared.
SCALE_FLOOR = 1e-6
#: Most re-weightings of ``weighting="noise"`` (each followed by stage-2 iterations); they stop when no scale
#: changes by more than 20 %.
REWEIGHTS = 4
#: Singular values of the scaled Jacobian below this fraction of the largest: directions the data do not determine.
RANK_RTOL = 1e-6
#: Weight (squared component) of a parameter in an undetermined direction above which it is named.
NULL_WEIGHT = 0.05
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
        Relative forward-difference step of the Jacobians (module doc, *Jacobian*).
    ftol, xtol : float
        Stage 1 ends when an iteration lowers the cost by less than ``ftol`` of it, or moves the
        (scaled) parameters by less than ``xtol`` of their size (or after ``max_nfev`` runs of the residual).
    max_nfev : int
        Most residual runs of stage 1 (each Jacobian costs one run per free parameter more).
    tol_final : float
        Tolerance of the runs of stages 2-3 and of the statistics; also the smallest channel scale.
    final_nfev : int
        Most residual runs of each pass of stage 2.
    refresh : float
        Stage 2 recomputes its Jacobian when the parameters have moved by more than this fraction of
        their magnitude since it was computed (and at the end, for the statistics).
    h_max : float
        Largest solver step [s].
    v_stop : float
        The runs end when ``v`` falls to it [m/s] (later samples compare with the end state).
    """

    tol: float = 1e-4
    fd_step: float = 1e-6
    ftol: float = 1e-8
    xtol: float = 1e-7
    max_nfev: int = 40
    tol_final: float = 3e-5
    final_nfev: int = 4
    refresh: float = 1e-3
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

    def weights(self) -> np.ndarray:
        """``1/scale`` of each stacked residual (channels in order, their samples compared)."""
        return np.concatenate([np.full(int(u.sum()), 1.0 / self.scales[c]) for c, u in self.use.items()])

    def stacked(self, model: dict | None) -> np.ndarray:
        """Unweighted residuals ``model - data`` of every channel at its samples compared, stacked (a failed run:
        :data:`FAILED_RESIDUAL` times each channel's scale)."""
        if model is None:
            return FAILED_RESIDUAL / self.weights()
        return np.concatenate([model[c][u] - self.data[c][u] for c, u in self.use.items()])

    def residual(self, model: dict | None) -> np.ndarray:
        """Weighted residuals ``(model - data)/scale``, stacked."""
        return self.stacked(model) * self.weights()

    @property
    def n(self) -> int:
        return int(sum(int(u.sum()) for u in self.use.values()))

    def raw(self, model: dict) -> dict:
        """Unweighted residuals per channel at the samples compared."""
        return {c: model[c][u] - self.data[c][u] for c, u in self.use.items()}

    def jacobian(self, sp: _Space, xi, tol: float, step: float) -> np.ndarray:
        """Forward-difference Jacobian of the unweighted stacked residuals in the public coordinates (module doc)."""
        pub = sp.public(xi)
        base = self.stacked(self.simulate(pub, tol)[0])
        J = np.empty((base.size, len(sp.free)))
        for i, k in enumerate(sp.free):
            lo, hi = sp.plo[k], sp.phi[k]
            h = step * max(abs(pub[k]), 0.01 * (hi - lo))
            if pub[k] + h > hi:
                h = -h
            moved = self.stacked(self.simulate({**pub, k: pub[k] + h}, tol)[0])
            J[:, i] = (moved - base) / h
        return J


class _Start:
    """A parameter set with the initial speeds as further attributes (the starting values of :class:`_Space`)."""

    def __init__(self, p: LuGreParams, **initial):
        self._p = p
        self.__dict__.update(initial)

    def __getattr__(self, name):
        return getattr(self._p, name)


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


def _coarse(prob: _Problem, sp: _Space, xi, o: OEOptions):
    """Stage 1 of a problem (module doc): trust-region least squares at the loose tolerance, forward differences."""
    from scipy.optimize import least_squares

    with np.errstate(all="ignore"):
        return least_squares(lambda x: prob.residual(prob.simulate(sp.public(x), o.tol)[0]), xi,
                             jac=lambda x: (prob.jacobian(sp, x, o.tol, o.fd_step) * prob.weights()[:, None]) @ sp.T,
                             bounds=(sp.lb, sp.ub),
                             x_scale="jac", method="trf", xtol=o.xtol, ftol=o.ftol, gtol=1e-12, max_nfev=o.max_nfev)


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
    sp = _Space(free, _Start(start, v0=v0, omega0=omega0), all_bounds, initial, OE_PARAMETERS + INITIAL_PARAMETERS,
                pad=1e-6)
    spans = {k: sp.phi[k] - sp.plo[k] for k in sp.free}
    ranges = _ranges(data, masks)
    prob.scales = {c: float(scales[c]) for c in data} if scales is not None else dict(ranges)

    def moved(xa, xb) -> float:
        """Largest change of a parameter between two internal points, relative to its magnitude."""
        pa, pb = sp.public(xa), sp.public(xb)
        return max(abs(pa[k] - pb[k]) / max(abs(pb[k]), 0.01 * spans[k]) for k in sp.free)

    # stage 1: loose tolerance (module doc, *Stages*)
    sol = _coarse(prob, sp, sp.xi0, o)
    xi, nfev, njev = sol.x, sol.nfev, sol.njev or 0
    stages = {"stage1": _record(sol, prob.runs)}
    # stages 2-3: tight tolerance, the Jacobian kept while the parameters move little (a chord method)
    chord = {"x": None, "J": None}

    def jac_final(x):
        nonlocal njev
        if chord["x"] is None or moved(x, chord["x"]) > o.refresh:
            chord["J"] = prob.jacobian(sp, x, o.tol_final, o.fd_step)
            chord["x"] = np.array(x, dtype=float)
            njev += 1
        return (chord["J"] * prob.weights()[:, None]) @ sp.T

    def polish(x, name):
        nonlocal nfev, sol
        runs0 = prob.runs
        with np.errstate(all="ignore"):
            fin = least_squares(lambda z: prob.residual(prob.simulate(sp.public(z), o.tol_final)[0]), x, jac=jac_final,
                                bounds=(sp.lb, sp.ub), x_scale="jac", method="trf", xtol=1e-10, ftol=1e-8, gtol=1e-12,
                                max_nfev=o.final_nfev)
        nfev += fin.nfev
        stages[name] = _record(fin, prob.runs - runs0)
        sol = fin if fin.success or not sol.success else sol
        return fin.x

    if o.final_nfev > 0:
        xi = polish(xi, "stage2")
    if scales is None and weighting == "noise":  # each channel by its residual RMS (module doc)
        for k in range(REWEIGHTS):
            raw = prob.raw(prob.simulate(sp.public(xi), o.tol_final)[0])
            new = {c: max(_rms(r), SCALE_FLOOR * ranges[c], o.tol_final) for c, r in raw.items()}
            settled = all(abs(np.log(new[c] / prob.scales[c])) < np.log(1.2) for c in new) and k > 0
            prob.scales = new
            if settled or o.final_nfev == 0:
                break
            xi = polish(xi, f"stage3.{k + 1}")
    x = sp.snap(xi)
    pub = sp.public(x)
    model, tr = prob.simulate(pub, o.tol_final)
    resid = prob.residual(model)
    jac_final(x)
    Jp = chord["J"] * prob.weights()[:, None]
    raw = prob.raw(model) if model is not None else {c: np.full(int(u.sum()), np.nan) for c, u in masks.items()}
    locks = [[a + prob.t0, None if b is None else b + prob.t0] for a, b in tr.events["lock"]] if tr is not None else []
    named, rel = identifiability(Jp, sp.free, pub, spans)
    extra = {"method": "output-error", "channels": list(data), "scales": dict(prob.scales),
             "weighting": "given" if scales is not None else weighting,
             "channel_rms": {c: _rms(r) for c, r in raw.items()}, "weighted_rms": _rms(resid),
             "runs": prob.runs,
             "njev": int(njev), "tol": o.tol, "tol_final": o.tol_final, "jacobian_moved": moved(x, chord["x"]),
             **stages, "wall_time_s": round(time.perf_counter() - wall, 3), "locks": locks,
             "initial_state": dict(zip(("v0", "omega0"), prob.initial(pub))),
             "smallest_relative_singular_value": rel, "not_identifiable": named,
             "units": {k: INITIAL_UNITS.get(k, UNITS.get(k, "-")) for k in sp.free}}
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
