"""Fitting Magic Formula 6.1 coefficients to measured points (``tirecli mf fit``'s engine).

- :func:`fit_mf` -- the staged fit (pure longitudinal, pure lateral, aligning torque, combined slip),
  :func:`plan_fit` / :func:`run_fit` -- the same in two parts (check and plan; run);
- :class:`FitOptions` -- bounds, fixed coefficients, weights, robust loss, tolerances, ranges;
- :class:`FitResult` -- fitted tyre, coefficient table with 95 % intervals, correlations, stage reports;
- :mod:`.stages` (which coefficients, in which order, identified by which data), :mod:`.data` (checks,
  sweeps, levels), :mod:`.model` (a stage's model values), :mod:`.solve` (least squares, identifiability,
  intervals), :mod:`.synthetic` (SYNTHETIC rig data from a tyre, seeded).

Documentation: docs/models/magic_formula_tyre.md, "Fitting a .tir to measurements".
"""
from tirecli.numerics.mf_fit.fit import FitPlan, fit_mf, plan_fit, run_fit
from tirecli.numerics.mf_fit.result import CoefficientFit, FitOptions, FitResult, StageReport
from tirecli.numerics.mf_fit.stages import FIT_COEFFICIENTS, STAGES

__all__ = ["fit_mf", "plan_fit", "run_fit", "FitPlan", "FitOptions", "FitResult", "CoefficientFit", "StageReport",
           "FIT_COEFFICIENTS", "STAGES"]
