"""Identification of the LuGre parameters from braking data (FM §4.3; docs/models/lugre_friction.md §8).

Config (``tirecli fit CONFIG``)::

    study: fit
    tire: canudas2003-table1        # starting values and fixed parameters (L; alpha unless fitted)
    data:
      csv: braking.csv              # columns t [s], v [m/s], s [-] (or romega [m/s]), mu [-]
      # file: braking.tdx           # ... or measured data (.csv, .parquet, .tdx, .mf4) through tirecli.io.readers:
      #                             # t, vx, s | kappa | romega | omega (x re), mu | fx/fz, brake_pressure | torque
      # units: {brake_pressure: bar}  # data.file: units of its columns; convention: iso|sae|adapted-iso; rate (MDF)
      # simulate: fm-fig4           # ... or the samples of a simulate config (built-in name or file)
      # frame: measured             # which of its frames (measured, measured_clean)
      # cases: ["braking #2"]       # run only these cases of it
      map: {slip_ratio: s}          # rename file columns {FILE_COLUMN: NAME}
      where: {braking: 2}           # keep rows whose column equals the value
      window: {start: 0, end: 2.6}  # [s], steady-state fit only (post-release samples are biased)
      min_abs_slip: 0.005           # steady-state fit only
    fit:
      parameters: [sigma0, sigma2, mu_c, mu_s, v_s]   # add alpha to fit the Stribeck exponent
      initial: {sigma0: 150}        # default: the tire set
      bounds: {v_s: [0.5, 20]}      # default: identify.DEFAULT_BOUNDS
      confidence: 0.95
      sigma1: {model: {model: lumped, kappa0: Z}, bounds: [0, 100]}   # or false
      model: lumped                 # default: the FM procedure (stages 1-2) only
      # model: distributed          # ... then stage 3, or with options:
      # model: {model: distributed, load: uniform, window: {start: 0.05}, substeps: 4, interpolation: cubic}
      method: fm                    # or output-error: then the quarter car simulated from the brake input,
      # output_error: {parameters: [...], model: distributed, input: pressure, pressure_gain: 20, window: ...}
      name: fitted-braking          # name of the fitted set
    figures: [fit-steady, fit-transient]

Stage 1 fits FM eq. (4) to the ``(s, v, mu)`` samples; stage 2 fits ``sigma1`` to ``mu(t)`` with
the tire model driven by the measured ``v(t)``, ``s(t)`` over the whole selection (see
:mod:`tirecli.numerics.identify`). With ``model: distributed``, stage 3 starts from their result
and fits the parameters of ``fit.parameters`` and ``sigma1`` (unless ``sigma1: false``) together
to ``mu(t)`` with the distributed model (FM eqs. (1)-(2), uniform load unless ``load`` says
otherwise) driven open loop by the measured ``v(t)``, ``r omega(t)`` in the least-squares loop
(:func:`tirecli.numerics.identify.fit_distributed`): no lumped approximation biases the estimates.
The model starts undeflected at the first sample; ``window`` selects the samples compared (earlier
samples still drive it). Output: ``fitted.yaml`` (the last stage's set), a parameter set every
command accepts (``tire: {set: fitted.yaml}``), and frames ``parameters`` (column ``fit``:
``FM 4.3`` for stages 1-2, ``distributed`` for stage 3), ``correlation``, ``samples``,
``transient`` and, with stage 3, ``distributed`` and ``correlation_distributed``.

With ``method: output-error`` a last stage (:mod:`tirecli.studies.fit.output_error`) starts from the previous
one's values and fits the coupled quarter car, simulated from the measured brake input, to the measured ``v``,
``r omega`` and ``mu`` (:func:`tirecli.numerics.identify_oe.fit_output_error`; docs/models/lugre_friction.md §8):
frames ``output_error`` and ``correlation_output_error``, rows ``output-error`` in ``parameters``, its values in
``fitted.yaml``; parameters the data do not determine are named and get no interval.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from tirecli.studies.fit.fitting import FIT_DISTRIBUTED, FIT_FM, TABLE2, plan, run
from tirecli.studies.fit.spec import SPEC
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Study


def overrides_for(data: str | None, maps: list[str] | None, config: str | Path | None = None) -> list[str]:
    """``--set`` overrides from ``tirecli fit --data FILE --map FILE_COLUMN=NAME``: a ``.csv`` is ``data.csv`` (the
    fit's own columns), a measured-data file (``.parquet``, ``.tdx``, ``.mf4``) ``data.file``, any other name
    ``data.csv`` (whose reader names what is wrong with it).

    ``--data`` is relative to the current directory and ``data.csv`` to the config's: a relative
    ``--data`` is kept as written when the two are the same (messages and run.json name the file as
    the user typed it), else made absolute."""
    out = []
    if data:
        same_dir = config is not None and os.path.abspath(os.path.dirname(os.fspath(config)) or ".") == os.getcwd()
        given = data if (same_dir and not os.path.isabs(data)) else os.path.abspath(data)
        from tirecli.io.readers import SUFFIXES

        measured = os.path.splitext(given)[1].lower() in set(SUFFIXES) - {".csv"}
        key, other = ("file", "csv") if measured else ("csv", "file")
        out += [f"data.{key}={json.dumps(given)}", f"data.{other}=null", "data.simulate=null"]
    if maps:
        mapping = {}
        for m in maps:
            if "=" not in m:
                from tirecli.errors import UsageError

                raise UsageError(f"--map {m!r}: expected FILE_COLUMN=NAME, e.g. --map slip_ratio=s")
            a, _, b = m.partition("=")
            mapping[a.strip()] = b.strip()
        out.append(f"data.map={json.dumps(mapping)}")
    return out


#: Headings of the fits in the summary, by the ``fit`` column of frame ``parameters``.
_HEADINGS = {"FM 4.3": "FM procedure (steady state, then sigma1):",
             "distributed": "distributed model (all at once, model in the loop):",
             "output-error": "output error (the coupled quarter car simulated from the brake input):"}


def summary(result) -> list[str]:
    """The estimates with their standard errors and intervals, per fit, and the residual RMS; parameters the
    data do not determine are named."""
    df = result.data["parameters"]
    meta = result.meta
    several = df["fit"].nunique() > 1
    lines = []
    for fit_name, rows in df.groupby("fit", sort=False):
        if several:
            lines.append(_HEADINGS.get(fit_name, f"{fit_name}:"))
        for _, r in rows.iterrows():
            flag = " (on a bound)" if r["at_bound"] else ""
            if not r.get("identified", True) or r["se"] != r["se"]:  # not identified, or no interval (NaN)
                lines.append(f"  {r['parameter']:7s} {r['estimate']:12.6g} {r['unit']:4s} NOT IDENTIFIED by these data (no interval)")
                continue
            lines.append(f"  {r['parameter']:7s} {r['estimate']:12.6g} +/- {r['se']:.3g} {r['unit']:4s} "
                         f"CI [{r['ci_low']:.6g}, {r['ci_high']:.6g}]{flag}")
        if fit_name == FIT_FM:
            lines.append(f"  residual RMS (steady state): {meta['steady_state']['residual_rms']:.3g}")
        elif fit_name == FIT_DISTRIBUTED:
            lines.append(f"  residual RMS of mu(t): {meta['distributed']['residual_rms']:.3g} "
                         f"({meta['distributed']['samples_used']} samples)")
        else:
            oe = meta["output_error"]
            rms = ", ".join(f"{c} {x:.3g}" for c, x in oe["channel_rms"].items())
            lines.append(f"  residual RMS: {rms} ({oe['samples_used']} samples, input {oe['input']}; "
                         f"{oe['runs']} runs, {oe['wall_time_s']:.1f} s)")
            if oe["not_identifiable"]:
                lines.append(f"  not identifiable from these data: {', '.join(oe['not_identifiable'])}")
    return lines


_CHECKS = "tirecli.studies.checks.identification"

STUDY = register(Study(
    name="fit", command="fit", spec=SPEC, plan=plan, run=run, figures=("fit-steady", "fit-transient"),
    checks={"fm-fig6": Lazy(_CHECKS, "fig6_checks"), "fm-table2": Lazy(_CHECKS, "table2_checks")},
    summary=summary, group="shared-runs",  # its data may be a simulate run the report keeps (fm-fig6 reads fm-fig4's)
    files=("fitted.yaml",),
))

__all__ = ["STUDY", "SPEC", "plan", "run", "summary", "overrides_for", "TABLE2", "FIT_FM", "FIT_DISTRIBUTED"]
