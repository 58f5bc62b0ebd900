"""Options and results of a Magic Formula fit (plain data for studies, reports and the CLI)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.models.magic_formula.tire import MFTire

LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")


@dataclass(frozen=True)
class FitOptions:
    """Options of :func:`~tirecli.numerics.mf_fit.fit_mf`.

    Attributes
    ----------
    parts : tuple of str
        Parts of the fit to run, among ``longitudinal``, ``lateral``, ``aligning``, ``combined``.
    bounds : dict
        Coefficient -> ``(low, high)``, replacing the defaults (:data:`~.stages.DEFAULT_BOUNDS`; every other
        coefficient is free).
    fix : frozenset of str
        Coefficients kept at their start values.
    weights : dict
        Channel (``fx``, ``fy``, ``mz``) -> weight multiplying its squared residuals; 0 leaves the channel
        out (its stages are skipped). A ``weight`` column of the data weights single points.
    loss : str
        ``linear`` (least squares) or a robust loss of scipy's ``least_squares``: ``soft_l1``, ``huber``,
        ``cauchy``, ``arctan``.
    f_scale : float
        Residual size where a robust loss starts to discount a point, as a fraction of the channel's peak
        (0.02: residuals beyond 2 % of the peak count less).
    convention : str
        Magic Formula convention of the evaluation (``mfeval`` as ``tirecli mf eval``, or ``teasit``).
    alpha_tol, kappa_tol : float
        ``|alpha| <= alpha_tol`` [rad] is pure longitudinal, ``|kappa| <= kappa_tol`` [-] pure lateral.
    load_tol : float
        Loads within ``load_tol * FNOMIN`` of each other are one load level.
    camber_tol : float
        Inclinations within this [rad] are one level.
    pressure_tol : float
        Pressures within this [Pa] are one level.
    ranges : str
        ``data``: the fitted tyre's input ranges (FZMIN..FZMAX, KPUMIN..KPUMAX, ALPMIN..ALPMAX,
        CAMMIN..CAMMAX, PRESMIN..PRESMAX) become those of the data (widened to hold the nominal point);
        ``start``: the start tyre's ranges stay (points outside are clipped, as ``mf eval`` would).
    min_points : int
        Fewest points a stage needs.
    tol : float
        Tolerance of the final least-squares step of a stage (ftol, xtol, gtol).
    collinearity : float
        Smallest independent fraction of a Jacobian column for its coefficient to count as identified.
    max_nfev : int
        Most residual evaluations of one least-squares step.
    step_points : int
        Steps on more points than this first fit an evenly strided subsample of that size (the steps
        before a stage's last one fit only the subsample; the last one then fits every point).
    solver : str
        ``lm`` (tirecli's bounded Levenberg-Marquardt on the normal equations, the default) or ``scipy``
        (``scipy.optimize.least_squares``, trust-region reflective).
    """

    parts: tuple = ("longitudinal", "lateral", "aligning", "combined")
    bounds: dict = field(default_factory=dict)
    fix: frozenset = frozenset()
    weights: dict = field(default_factory=dict)
    loss: str = "linear"
    f_scale: float = 0.02
    convention: str = "mfeval"
    alpha_tol: float = math.radians(0.25)
    kappa_tol: float = 0.005
    load_tol: float = 0.1
    camber_tol: float = math.radians(0.25)
    pressure_tol: float = 5000.0
    ranges: str = "data"
    min_points: int = 10
    tol: float = 1e-8
    collinearity: float = 1e-4
    max_nfev: int = 400
    solver: str = "lm"
    step_points: int = 4000


@dataclass
class CoefficientFit:
    """One row of the coefficient table.

    ``stderr``, ``low``, ``high`` are None when no interval is claimed (not identified, at a bound).
    ``reason`` says why a coefficient was not identified (empty when it was). ``fitted_in`` names the
    stage whose last step gave the value and interval (a later stage may fit a coefficient again).
    """

    name: str
    stage: str
    group: str
    start: float
    value: float
    stderr: float | None = None
    low: float | None = None
    high: float | None = None
    identified: bool = False
    at_bound: bool = False
    reason: str = ""
    fitted_in: str = ""

    def as_dict(self) -> dict:
        return {"name": self.name, "stage": self.stage, "group": self.group, "start": self.start,
                "fitted": self.value, "stderr": self.stderr, "ci95_low": self.low, "ci95_high": self.high,
                "identified": self.identified, "at_bound": self.at_bound, "reason": self.reason,
                "fitted_in": self.fitted_in}


@dataclass
class StepReport:
    """One least-squares step of a stage (a coefficient group on its data)."""

    group: str
    points: int
    coefficients: list
    rms: float
    nfev: int
    message: str = ""


@dataclass
class StageReport:
    """A stage of the fit: what it did or why it was skipped.

    ``rms_start`` and ``rms_fit`` [N or N m] are the root mean square of ``model - data`` over the
    stage's points with the coefficients on entering the stage and after it (the optimiser's own view;
    the independent check evaluates the written ``.tir``); ``peak`` is the largest measured |value|.
    """

    name: str
    title: str
    channel: str
    status: str  # "fitted" | "skipped"
    reason: str = ""
    points: int = 0
    data: str = ""
    rms_start: float = float("nan")
    rms_fit: float = float("nan")
    peak: float = float("nan")
    nfev: int = 0
    seconds: float = 0.0
    steps: list = field(default_factory=list)
    s2: float = float("nan")
    dof: int = 0

    def as_dict(self) -> dict:
        return {"stage": self.name, "title": self.title, "channel": self.channel, "status": self.status,
                "reason": self.reason, "points": self.points, "rms_start": self.rms_start,
                "rms_fit": self.rms_fit, "peak": self.peak, "rms_fit_pct_peak": 100 * self.rms_fit / self.peak
                if self.peak and np.isfinite(self.peak) else float("nan"), "nfev": self.nfev,
                "seconds": self.seconds, "data": self.data}


@dataclass
class FitResult:
    """What :func:`~tirecli.numerics.mf_fit.fit_mf` returns.

    Attributes
    ----------
    start : MFTire
        The start tyre (as given).
    tire : MFTire
        The fitted tyre: the start tyre with the fitted coefficients and the fit's ranges.
    coefficients : list of CoefficientFit
        Every coefficient of the stages that ran or were skipped, in stage order.
    correlations : list of tuple
        ``(name_a, name_b, r)``: the strongest correlations between identified coefficients of one stage
        (``|r|`` descending; coefficients of different stages are fitted apart: no correlation claimed).
    stages : list of StageReport
    ranges : dict
        Range keys (``FZMIN``, ...) -> values written to the fitted tyre (empty for ``ranges='start'``).
    notes : list of str
        Assumptions and substitutions made (defaulted data columns, start values moved into bounds or away
        from a value with no gradient).
    options : FitOptions
    data : str
        What the data held (points per sweep, levels).
    sweeps : dict
        ``longitudinal``, ``lateral``, ``combined`` -> boolean mask over the data's rows (a free-rolling
        point at zero slip angle is in the first two).
    """

    start: MFTire
    tire: MFTire
    coefficients: list
    correlations: list
    stages: list
    ranges: dict
    notes: list
    options: FitOptions
    data: str = ""
    seconds: float = 0.0
    sweeps: dict = field(default_factory=dict)

    @property
    def values(self) -> dict:
        """Coefficient -> fitted value (start value when not identified), every coefficient of the table."""
        return {c.name: c.value for c in self.coefficients}

    @property
    def changed(self) -> dict:
        """Coefficient -> fitted value of the identified coefficients."""
        return {c.name: c.value for c in self.coefficients if c.identified}

    @property
    def unidentified(self) -> dict:
        """Coefficient -> why it stayed at its start value."""
        return {c.name: c.reason for c in self.coefficients if not c.identified}

    @property
    def fitted_stages(self) -> list[str]:
        return [s.name for s in self.stages if s.status == "fitted"]

    def coefficient_frame(self):
        """The coefficient table as a DataFrame (name, stage, group, start, fitted, stderr, ci95_low,
        ci95_high, identified, at_bound, reason)."""
        import pandas as pd

        return pd.DataFrame([c.as_dict() for c in self.coefficients])

    def correlation_frame(self):
        import pandas as pd

        return pd.DataFrame(self.correlations, columns=["a", "b", "r"])

    def stage_frame(self):
        import pandas as pd

        return pd.DataFrame([s.as_dict() for s in self.stages])
