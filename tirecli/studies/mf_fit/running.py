"""Run an ``mf-fit`` study: the staged fit, the fitted ``.tir``, and that file read back and evaluated.

The goodness of fit in the outputs is that of the written file: :func:`tirecli.parameters.mf_fitted.check_fitted`
reads the ``.tir`` text back and evaluates it at every measured point, so ``data/fit.csv`` (data, fit,
residual per point) and the RMS and largest residual per channel describe what a user gets, never the
optimiser's own residuals.
"""
from __future__ import annotations

from tirecli.studies.base import StudyResult
from tirecli.studies.study import Line, Plan

#: Default figures of a run.
FIGURES = ("mf-fit-fx", "mf-fit-fy", "mf-fit-mz", "mf-fit-combined", "mf-fit-residuals", "mf-fit-coefficients")


def _data_label(detail) -> str:
    """The data for the fitted file's header (a file that says it holds SYNTHETIC data is named so)."""
    return "; ".join(s.frame.attrs.get("label") or (f"{s.label} (SYNTHETIC data)" if s.synthetic else s.label)
                     for s in detail.sources)


def _facts(table, result, findings) -> dict:
    facts = {"points": int(sum(table[table.sweep == "all"].points.iloc[:1])) if len(table) else 0,
             "identified": len(result.changed), "unidentified": len(result.unidentified),
             "tir_check_errors": sum(f.level == "error" for f in findings), "fit_seconds": round(result.seconds, 4)}
    for row in table.itertuples():
        if row.sweep == "all":
            facts[f"rms_pct_{row.channel}"] = float(row.rms_pct)
            facts[f"max_pct_{row.channel}"] = float(row.max_pct)
    return facts


def run(plan_: Plan, progress=None) -> StudyResult:
    """Fit, write the ``.tir`` text, read it back and evaluate it at every point (module docstring)."""
    import pandas as pd

    from tirecli.io.sweeps import find_sweeps
    from tirecli.numerics.mf_fit import run_fit
    from tirecli.parameters.mf_fitted import check_fitted, fitted_text

    d = plan_.detail
    checked = plan_.checked
    result = run_fit(d.fit, progress)
    text = fitted_text(d.start_doc, result, data_label=_data_label(d), start_label=d.start_label)
    chk = check_fitted(text, d.frame, result.sweeps, convention=checked["options"]["mf_convention"])
    frame = chk.frame
    frame.insert(0, "file", d.frame["file"].to_numpy())
    sweeps = find_sweeps(d.frame)
    coefficients = result.coefficient_frame()
    correlations = result.correlation_frame()
    synthetic = any(s.synthetic for s in d.sources)
    meta = {
        "title": checked["title"] or f"Magic Formula 6.1 fit to {len(d.frame):,} points from {d.start_label}",
        "start": d.start_label, "data": [s.label for s in d.sources], "data_summary": result.data,
        "options": {k: v for k, v in checked["options"].items()},
        "stages": [s.as_dict() for s in result.stages], "notes": result.notes, "ranges": result.ranges,
        "unidentified": result.unidentified,
        "tir_check": [str(f) for f in chk.findings],
        "reference": d.reference_label or None,
        "facts": _facts(chk.table, result, chk.findings),
    }
    payload = {"sweeps": sweeps, "tire": chk.tire, "reference": d.reference, "reference_label": d.reference_label,
               "tolerance": (checked["reference"] or {}).get("tolerance") or {}, "correlations": result.correlations,
               "start": d.start_label, "convention": checked["options"]["mf_convention"]}
    data = {"fit": frame, "coefficients": coefficients, "correlations": correlations,
            "stages": result.stage_frame(), "goodness": chk.table}
    return StudyResult(study="mf-fit", config=plan_.config, parameter_sets={}, data=data, meta=meta,
                       figures=list(checked["figures"] or FIGURES), payload=payload, synthetic=synthetic,
                       files={"fitted.tir": text})


def summary(result: StudyResult) -> list:
    """The lines ``tirecli mf fit`` prints: the data and stages, the coefficients, the fit of the written file."""
    m = result.meta
    f = m["facts"]
    lines = [Line(f"mf fit: {m['data_summary']}; start tyre {m['start']}", "note")]
    for s in m["stages"]:
        if s["status"] == "fitted":
            lines.append(Line(f"  {s['title']}: {s['points']} points, RMS {s['rms_fit']:.4g} "
                              f"({s['rms_fit_pct_peak']:.3g} % of the peak)", "note"))
        else:
            lines.append(Line(f"  {s['title']}: skipped ({s['reason']})", "note"))
    lines.append(f"{f['identified']} coefficients fitted, {f['unidentified']} kept at the start values "
                 "(named with why in fitted.tir and data/coefficients.csv)")
    g = result.data["goodness"]
    parts = [f"{r.channel} RMS {r.rms_pct:.3g} % / largest {r.max_pct:.3g} %" for r in g.itertuples() if r.sweep == "all"]
    if parts:
        lines.append("fitted.tir read back, at the data points (of each channel's peak): " + ", ".join(parts))
    for text in m["tir_check"]:
        if text.startswith("error"):
            lines.append(Line(f"fitted.tir: tir check {text}", "warning"))
    return lines


#: Unit of each fact.
FACT_UNITS = {"points": "-", "identified": "-", "unidentified": "-", "tir_check_errors": "-", "fit_seconds": "s",
              **{f"{k}_pct_{ch}": "%" for k in ("rms", "max") for ch in ("fx", "fy", "mz")}}

__all__ = ["run", "summary", "FIGURES", "FACT_UNITS"]
