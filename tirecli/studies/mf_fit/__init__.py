"""The ``mf-fit`` study: Magic Formula 6.1 coefficients fitted to measured tyre data (``tirecli mf fit``).

Config (:mod:`.spec`), plan -- the data read, the start tyre checked, the fit's stages planned, every
problem of the inputs found before any least squares (:mod:`.planning`) -- and run -- the staged fit, the
fitted ``.tir`` and that file read back and evaluated at every point (:mod:`.running`). Outputs: the
extra file ``fitted.tir``; frames ``fit`` (data, fit and residual per point), ``coefficients`` (start and
fitted values, 95 % intervals, why a coefficient was not identified), ``correlations``, ``stages``,
``goodness`` (RMS and largest residual per channel and sweep); figures ``mf-fit-*``.
Docs: docs/data.md, "Fitting a Magic Formula tyre".
"""
from __future__ import annotations

from tirecli.studies.mf_fit.planning import plan
from tirecli.studies.mf_fit.running import FACT_UNITS, FIGURES, run, summary
from tirecli.studies.mf_fit.spec import SPEC
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Study

STUDY = register(Study(
    name="mf-fit", command="mf fit", spec=SPEC, plan=plan, run=run, figures=FIGURES,
    checks={fid: Lazy("tirecli.studies.checks.mf_fit", "checks", (fid,)) for fid in FIGURES},
    fact_units=FACT_UNITS, summary=summary, primary_frame="fit", files=("fitted.tir",),
))

__all__ = ["STUDY", "SPEC", "plan", "run", "summary"]
