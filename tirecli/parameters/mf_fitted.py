"""The fitted ``.tir`` of a Magic Formula fit, and the fit judged by evaluating that file again.

:func:`fitted_document` takes the start tyre's document (a ``.tir`` file or a built-in tyre, read by
:mod:`tirecli.io.tir`) and the fitted coefficients (a :class:`~tirecli.numerics.mf_fit.FitResult`, or
anything with its ``coefficients``, ``ranges``, ``stages`` and ``data``) and returns a new document:
every identified coefficient replaced (in the file's own units), the input ranges of the fit, every
other key, table and dimension as in the start tyre, and a comment block naming the fit, the data and
the coefficients that stayed at their start values (with why). The start tyre must be MF 6.1 or 6.2.

:func:`check_fitted` reads such a text back (:func:`tirecli.io.tir.parse_tir`,
:func:`tirecli.parameters.mf.tire_data`), evaluates it at every measured point with
:func:`tirecli.models.magic_formula.evaluate` (combined slip, as ``tirecli mf eval``), and tabulates data,
fit and residual per point and their RMS and largest gap per channel and sweep: the goodness of fit of
the file a user gets, not the optimiser's view.
"""
from __future__ import annotations

import copy
import textwrap
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import UsageError
from tirecli.io import tir as tirio
from tirecli.models.magic_formula import evaluate
from tirecli.models.magic_formula.check import check_coefficients
from tirecli.parameters import mf as mfp
from tirecli.parameters.mf_catalogue import CATALOGUE, SECTION_ORDER, descriptions

#: Significant digits of the fitted values written (far below any interval; the file reads back to 1e-12).
DIGITS = 12

_RANGE_SECTIONS = {"FZMIN": "VERTICAL_FORCE_RANGE", "FZMAX": "VERTICAL_FORCE_RANGE",
                   "KPUMIN": "LONG_SLIP_RANGE", "KPUMAX": "LONG_SLIP_RANGE",
                   "ALPMIN": "SLIP_ANGLE_RANGE", "ALPMAX": "SLIP_ANGLE_RANGE",
                   "CAMMIN": "INCLINATION_ANGLE_RANGE", "CAMMAX": "INCLINATION_ANGLE_RANGE",
                   "PRESMIN": "INFLATION_PRESSURE_RANGE", "PRESMAX": "INFLATION_PRESSURE_RANGE"}


def check_start(doc: tirio.TirDocument) -> mfp.TireData:
    """The start tyre's checked data; UsageError (one line) when it is not MF 6.1 / 6.2."""
    td = mfp.tire_data(doc)
    if td.version not in ("6.1", "6.2"):
        what = {"5.2": "MF 5.2 / PAC2002", "pac89": "PAC89"}.get(td.version, td.version)
        raise UsageError(f"{doc.file}: the start tyre is {what} (from {td.version_source}): a fit writes MF 6.1 "
                         "coefficients (pressure terms, PKY5-PKY7, QDZ10-11, RBX3, RBY4, ...) that its equations do "
                         "not have; start from an MF 6.1 or 6.2 .tir")
    return td


def _ascii(text: str) -> str:
    return "".join(ch if 32 <= ord(ch) < 127 else "?" for ch in str(text))


def _comment_lines(result, start_label: str, data_label: str) -> list[str]:
    fitted = [c.name for c in result.coefficients if c.identified]
    kept: dict = {}
    for c in result.coefficients:
        if not c.identified:
            kept.setdefault(c.reason.split(" (")[0], []).append(c.name)
    done = [s.name for s in result.stages if s.status == "fitted"]
    lines = ["Fitted by tirecli (mf fit): Magic Formula 6.1 coefficients fitted to measured points, stage by "
             "stage (pure longitudinal, pure lateral, aligning torque, combined slip).",
             f"Data: {data_label or 'not named'} ({result.data}).",
             f"Start tyre: {start_label}; dimensions and every coefficient not listed as fitted are the start tyre's.",
             f"Stages fitted: {', '.join(done) or 'none'}.",
             f"Fitted ({len(fitted)}): {' '.join(fitted) or 'none'}."]
    if kept:
        lines.append(f"Kept at the start values ({sum(len(v) for v in kept.values())}), by reason:")
        lines += [f"- {why}: {' '.join(names)}" for why, names in kept.items()]
    if result.ranges:
        lines.append("Input ranges from the data: " + ", ".join(f"{k} {v:.6g}" for k, v in result.ranges.items()) + ".")
    out = []
    for line in lines:
        out += textwrap.wrap(_ascii(line), 96, subsequent_indent="  ", break_long_words=True) or [""]
    return ["! " + x for x in out]


def _put(doc: tirio.TirDocument, key: str, value: float) -> None:
    """Set ``key`` in the document: where it is written, else in its catalogue section (created in the
    usual order when the file has none)."""
    found = doc.find(key)
    if found:
        found[0][1].value = value
        return
    sect = _RANGE_SECTIONS.get(key) or CATALOGUE[key].section
    if sect not in doc.sections:
        rank = {name: i for i, name in enumerate(SECTION_ORDER)}
        new = tirio.TirSection(name=sect, line=0)
        items = list(doc.sections.items())
        pos = next((i for i, (name, _) in enumerate(items) if rank.get(name, -1) > rank.get(sect, len(rank))),
                   len(items))
        items.insert(pos, (sect, new))
        doc.sections = dict(items)
    doc.sections[sect].entries[key] = tirio.TirEntry(value=value, line=0, comment="")


def fitted_document(start_doc: tirio.TirDocument, result, *, data_label: str = "", start_label: str = "",
                    file: str = "fitted.tir") -> tirio.TirDocument:
    """The fitted tyre as a ``.tir`` document (see the module docstring).

    Parameters
    ----------
    start_doc : TirDocument
        The start tyre's document (MF 6.1 or 6.2; UsageError otherwise).
    result : FitResult
        The fit (its identified coefficients and ranges are written).
    data_label : str
        The data's name for the comment (file names, or a SYNTHETIC label).
    start_label : str
        The start tyre's name for the comment (default: the document's file).
    file : str
        Name of the new document in messages.
    """
    td = check_start(start_doc)
    doc = copy.deepcopy(start_doc)
    doc.file = file
    doc.warnings = []
    fac = td.factors
    for c in result.coefficients:
        if c.identified:
            v = float(f"{c.value:.{DIGITS}g}") / mfp.dim_factor(CATALOGUE[c.name].dim, fac)
            _put(doc, c.name, v)
    for key, v in result.ranges.items():
        _put(doc, key, float(f"{v:.{DIGITS}g}") / mfp.dim_factor(CATALOGUE[key].dim, fac))
    doc.preamble = _comment_lines(result, start_label or start_doc.file, data_label) + (
        ["! The start tyre's header:"] + list(start_doc.preamble) if start_doc.preamble else [])
    return doc


def fitted_text(start_doc: tirio.TirDocument, result, **kw) -> str:
    """The ``.tir`` text of :func:`fitted_document` (inline descriptions from the catalogue)."""
    return tirio.format_tir(fitted_document(start_doc, result, **kw), descriptions())


# --------------------------------------------------------------------------- the independent check


@dataclass
class FittedCheck:
    """The fitted ``.tir`` read back and evaluated at the measured points.

    Attributes
    ----------
    tire : MFTire
        The tyre read back from the text.
    frame : pandas.DataFrame
        One row per point: ``sweep``, the inputs, and per measured channel ``CH`` (data), ``CH_fit``,
        ``CH_res`` (fit - data); ``run``, ``mx``, ``my`` when given.
    table : pandas.DataFrame
        Per channel and sweep: ``points``, ``rms``, ``max_abs`` (largest |residual|), ``peak`` (largest
        |data|), ``rms_pct``, ``max_pct`` (of the peak) and ``worst_row`` (row of the largest gap).
    findings : list
        ``tirecli tir check``'s findings on the read-back tyre (errors and warnings).
    warnings : list
        The reader's warnings.
    """

    tire: object
    frame: object
    table: object
    findings: list = field(default_factory=list)
    warnings: list = field(default_factory=list)


def check_fitted(text: str, data, sweeps: dict, *, convention: str = "mfeval", file: str = "fitted.tir") -> FittedCheck:
    """Read a fitted ``.tir`` text back and evaluate it at every point of ``data``.

    Parameters
    ----------
    text : str
        The fitted ``.tir`` (:func:`fitted_text`).
    data : pandas.DataFrame
        The measured points (columns as for the fit).
    sweeps : dict
        Sweep name -> boolean mask over the rows (``FitResult.sweeps``); a point takes the first sweep
        whose mask holds it.
    convention : str
        Evaluation convention (the fit's).
    """
    import pandas as pd

    td = mfp.tire_data(tirio.parse_tir(text, file))
    tire = td.tire()
    cols = {str(c).lower(): c for c in data.columns}
    n = len(data)

    def col(name, default):
        return np.asarray(data[cols[name]], dtype=float) if name in cols else default

    x = {"kappa": col("kappa", None), "alpha": col("alpha", None), "gamma": col("gamma", np.zeros(n)),
         "fz": col("fz", None), "vx": col("vx", np.full(n, tire.reference_speed or np.nan)),
         "p": col("p", np.full(n, tire.default_pressure or np.nan))}
    chans = [c for c in ("fx", "fy", "mz") if c in cols]
    res = evaluate(tire, x["kappa"], x["alpha"], x["gamma"], x["fz"], x["vx"],
                   x["p"] if tire.nominal_pressure else None, outputs=tuple(chans), convention=convention)
    label = np.full(n, "other", dtype=object)
    for name in reversed(list(sweeps)):
        label[np.asarray(sweeps[name], dtype=bool)] = name
    frame = pd.DataFrame({"sweep": label, **x})
    for extra in ("run", "mx", "my"):
        if extra in cols:
            frame[extra] = np.asarray(data[cols[extra]])
    rows = []
    for ch in chans:
        y = col(ch, None)
        fit = np.asarray(getattr(res, ch), dtype=float)
        frame[ch], frame[ch + "_fit"], frame[ch + "_res"] = y, fit, fit - y
        for sw in list(sweeps) + ["all"]:
            m = np.isfinite(y) & (np.ones(n, bool) if sw == "all" else (label == sw))
            if not m.any():
                continue
            r = (fit - y)[m]
            peak = float(np.max(np.abs(y[m])))
            i = int(np.argmax(np.abs(r)))
            rms = float(np.sqrt(np.mean(r * r)))
            rows.append({"channel": ch, "sweep": sw, "points": int(m.sum()), "rms": rms,
                         "max_abs": float(abs(r[i])), "peak": peak, "rms_pct": 100 * rms / peak if peak else np.nan,
                         "max_pct": 100 * abs(r[i]) / peak if peak else np.nan,
                         "worst_row": int(np.flatnonzero(m)[i])})
    findings = check_coefficients(tire)
    return FittedCheck(tire=tire, frame=frame, table=pd.DataFrame(rows), findings=findings,
                       warnings=[str(w) for w in td.warnings])
