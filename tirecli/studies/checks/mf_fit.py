"""Reference checks of the ``mf-fit`` figures (:mod:`tirecli.studies.mf_fit`).

With a ``reference:`` tyre (the generating tyre of SYNTHETIC data), each data-against-fit figure checks the
fitted tyre -- the written ``fitted.tir`` read back -- against that tyre, evaluated independently
(:func:`tirecli.models.magic_formula.evaluate`) over every measured sweep: at the sweep's load, inclination,
pressure and speed (and held slip angle of a combined sweep), on 101 slips over the sweep's range. The
value is the largest gap as a percentage of the reference's peak over those sweeps; the bound is the
config's tolerance (by default the issue's targets for 1 % noise: 2 % for Fx, Fy and combined slip,
5 % for Mz). The coefficient table checks that ``tirecli tir check`` finds no error in the fitted file.
"""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check

#: Figure -> (sweep kind, channels, tolerance key per channel).
FIGURE_SWEEPS = {
    "mf-fit-fx": ("pure longitudinal", (("fx", "fx"),)),
    "mf-fit-fy": ("pure lateral", (("fy", "fy"),)),
    "mf-fit-mz": ("pure lateral", (("mz", "mz"),)),
    "mf-fit-combined": ("combined", (("fx", "combined"), ("fy", "combined"), ("mz", "mz"))),
}
#: Default tolerances [% of the peak] (docs/data.md, "Fitting a Magic Formula tyre").
TOLERANCE = {"fx": 2.0, "fy": 2.0, "mz": 5.0, "combined": 2.0}
#: Slips per sweep of the comparison.
GRID = 101


def sweep_gaps(fitted, reference, frame, sweeps, kind: str, channels, convention: str = "mfeval") -> dict:
    """Largest ``|fitted - reference|`` of each channel over the sweeps of ``kind``, as % of the
    reference's largest |value| there; None for a channel without such a sweep."""
    from tirecli.models.magic_formula import evaluate

    gaps = {ch: [0.0, 0.0] for ch in channels}  # largest gap, peak
    found = False
    for s in sweeps:
        if s.kind != kind or s.rows < 2:
            continue
        rows = frame.iloc[s.start:s.stop]
        if kind == "pure lateral":
            alpha = np.linspace(rows.alpha.min(), rows.alpha.max(), GRID)
            kappa = np.zeros(GRID)
        else:
            kappa = np.linspace(rows.kappa.min(), rows.kappa.max(), GRID)
            alpha = np.full(GRID, float(np.median(rows.alpha))) if kind == "combined" else np.zeros(GRID)
        held = {k: np.full(GRID, float(np.median(rows[k]))) for k in ("gamma", "fz", "vx")}
        p = np.full(GRID, float(np.median(rows.p))) if "p" in rows and np.isfinite(rows.p).all() else None
        a = evaluate(fitted, kappa, alpha, held["gamma"], held["fz"], held["vx"], p if fitted.nominal_pressure else None,
                     outputs=tuple(channels), convention=convention)
        b = evaluate(reference, kappa, alpha, held["gamma"], held["fz"], held["vx"],
                     p if reference.nominal_pressure else None, outputs=tuple(channels), convention=convention)
        for ch in channels:
            fa, fb = np.asarray(getattr(a, ch), float), np.asarray(getattr(b, ch), float)
            gaps[ch][0] = max(gaps[ch][0], float(np.max(np.abs(fa - fb))))
            gaps[ch][1] = max(gaps[ch][1], float(np.max(np.abs(fb))))
        found = True
    if not found:
        return {ch: None for ch in channels}
    return {ch: 100.0 * g / peak if peak > 0 else None for ch, (g, peak) in gaps.items()}


def checks(fid: str, result) -> list[Check]:
    """The checks of figure ``fid`` of an mf-fit result (module docstring)."""
    pay = result.payload or {}
    if fid == "mf-fit-coefficients":
        errors = result.meta["facts"]["tir_check_errors"]
        return [Check("tir-check", "errors 'tirecli tir check' finds in the fitted .tir", float(errors), 0.0, 0.0,
                      "-", "tirecli tir check (docs/models/magic_formula_tyre.md §19)", bound="max")]
    if fid not in FIGURE_SWEEPS or pay.get("reference") is None:
        return []
    kind, pairs = FIGURE_SWEEPS[fid]
    frame = result.data["fit"]
    have = [(ch, tol) for ch, tol in pairs if ch in frame.columns]
    gaps = sweep_gaps(pay["tire"], pay["reference"], frame, pay["sweeps"], kind, [ch for ch, _ in have],
                      pay.get("convention", "mfeval"))
    tol = {**TOLERANCE, **(pay.get("tolerance") or {})}
    out = []
    for ch, key in have:
        if gaps[ch] is None:
            continue
        out.append(Check(f"{ch}-{kind.split()[-1]}-vs-reference",
                         f"largest |fitted - reference| {ch} over the {kind} sweeps, % of the peak",
                         gaps[ch], 0.0, float(tol[key]), "%",
                         f"the tyre {pay['reference_label']} evaluated at the sweeps' conditions (the generating "
                         "tyre of the SYNTHETIC data)", bound="max"))
    return out


__all__ = ["checks", "sweep_gaps", "FIGURE_SWEEPS", "TOLERANCE"]
