"""The gaps of the stationary MCPS curves to the Magic Formula curves drawn beside them (MCPS Figs. 7-11).

Every comparison figure states, for each MCPS curve (each carcass, the calibrated set), its gap to the
Magic Formula curve drawn in the same panel (:func:`tirecli.numerics.gaps.curve_gap`): the largest
absolute gap, where it occurs, and the RMS over the drawn points. The points are those the figure draws
(:func:`drawn`), each model's own ISO-W output at them (road on tire; the paper's plotting signs change
only the axes, never one model's curve):

- Fig. 7: ``Fx`` against ``kappa`` at ``alpha = 0``;
- Fig. 8: ``Fy`` against ``-alpha`` at ``kappa = 0``, the points with ``alpha <= 0`` (the paper's "-delta"
  axis: a positive side force), all points when the run has fewer than two of them;
- Fig. 9: ``Mz`` against ``alpha``, the points with ``alpha >= 0`` (all when fewer than two);
- Fig. 10: ``Fy`` and ``Mz`` against ``Fx`` per slip angle (each model against its own ``Fx``: the MCPS
  curve is interpolated onto the Magic Formula's ``Fx``; points outside its range are skipped);
- Fig. 11: ``|Fy|`` and ``|Mz|`` against the curvature; the Magic Formula line is drawn at 0 (no
  curvature input; its zero-slip offset is not a curvature response), so the gap is the MCPS response.
"""
from __future__ import annotations

import numpy as np

from tirecli.studies.mcps.common import DEG

#: Figure id -> (family, quantities): the curves each comparison figure draws.
FIGURES = {"mcps-fig7": ("kappa", ("fx",)), "mcps-fig8": ("alpha", ("fy",)), "mcps-fig9": ("alpha", ("mz",)),
           "mcps-fig10": ("combined", ("fy", "mz")), "mcps-fig11": ("curvature", ("fy", "mz"))}
#: Abscissa of each figure's gap (``at``): column and unit suffix of the fact names.
ABSCISSA = {"mcps-fig7": ("kappa", "kappa"), "mcps-fig8": ("alpha", "rad"), "mcps-fig9": ("alpha", "rad"),
            "mcps-fig10": ("fx", "fx_N"), "mcps-fig11": ("phi", "per_m")}
UNITS = {"fx": "N", "fy": "N", "mz": "Nm"}


def drawn(d, fid: str):
    """The rows of a family frame that figure ``fid`` draws (Fig. 8: ``alpha <= 0``; Fig. 9: ``alpha >= 0``;
    every row when fewer than two qualify, or for the other figures)."""
    if fid in ("mcps-fig8", "mcps-fig9"):
        keep = d["alpha"] <= 0 if fid == "mcps-fig8" else d["alpha"] >= 0
        if d.loc[keep, "alpha"].nunique() >= 2:
            return d[keep]
    return d


def variant(row_model: str, carcass: str, calibrated: bool) -> str:
    """The name of a curve: ``mf``, ``complete``, ``rigid`` or ``calibrated``."""
    return "mf" if row_model == "mf" else ("calibrated" if calibrated else carcass)


def _gap_dict(g, q: str, xs: str) -> dict:
    u = UNITS[q]
    out = {f"{q}_max_{u}": g.max, f"{q}_at_{xs}": g.at, f"{q}_rms_{u}": g.rms, f"{q}_max_rel": g.max_rel,
           f"{q}_rms_rel": g.rms_rel, f"{q}_points": g.points, f"{q}_skipped": g.skipped}
    if g.peak == 0:  # a reference line at 0 (Fig. 11): no relative gap
        del out[f"{q}_max_rel"], out[f"{q}_rms_rel"]
    return out


def stationary_gaps(df) -> dict:
    """``{figure id: {"F N": {curve: {fact: value}}}}`` for every comparison figure whose family the frame
    holds and every MCPS curve with a Magic Formula curve beside it (Fig. 10: one more level per slip
    angle, ``"alpha X deg"``). Facts: ``{q}_max_{unit}``, ``{q}_at_{abscissa}``, ``{q}_rms_{unit}``,
    ``{q}_max_rel``, ``{q}_rms_rel`` (over the Magic Formula's peak magnitude), ``{q}_points``,
    ``{q}_skipped``. Empty when there is no Magic Formula side."""
    from tirecli.numerics.gaps import curve_gap

    out = {}
    if not (df["model"] == "mf").any():
        return out
    for fid, (family, qs) in FIGURES.items():
        fam = df[df["family"] == family]
        if fam.empty:
            continue
        col, xs = ABSCISSA[fid]
        per_load = {}
        for fz, dl in fam.groupby("fz", sort=True):
            dl = drawn(dl, fid)
            mf = dl[dl["model"] == "mf"]
            curves = {}
            for (model, carcass, cal), g in dl[dl["model"] == "mcps"].groupby(["model", "carcass", "calibrated"], sort=False):
                name = variant(model, carcass, bool(cal))
                if fid == "mcps-fig10":
                    per_alpha = {}
                    for a, ga in g.groupby("alpha", sort=True):
                        ga, ma = ga.sort_values("kappa"), mf[mf["alpha"] == a].sort_values("kappa")
                        facts = {}
                        for q in qs:
                            try:
                                gap = curve_gap(ma["fx"], ga[q], ma[q], model_x=ga["fx"])
                            except ValueError:  # an MCPS Fx that is not monotone in kappa: no interpolation
                                continue
                            facts.update(_gap_dict(gap, q, xs))
                        per_alpha[f"alpha {a / DEG:.3g} deg"] = facts
                    curves[name] = per_alpha
                    continue
                x = g.sort_values(col)
                m = mf.sort_values(col)
                facts = {}
                for q in qs:
                    if fid == "mcps-fig11":  # magnitudes; the Magic Formula line is 0 (its offset is not drawn)
                        mod, ref = np.abs(x[q].to_numpy()), np.zeros(len(m))
                    else:
                        mod, ref = x[q].to_numpy(), m[q].to_numpy()
                    facts.update(_gap_dict(curve_gap(m[col], mod, ref), q, xs))
                curves[name] = facts
            if curves:
                per_load[f"{fz:g} N"] = curves
        if per_load:
            out[fid] = per_load
    return out


def mz_features(df) -> dict:
    """``{"F N": {curve: {"peak_Nm", "peak_rad", "sign_change_rad"}}}`` of the aligning torque Fig. 9 draws:
    the sampled peak of ``|Mz|`` refined by a parabola through its neighbours, and the first slip angle after
    the peak where ``Mz`` changes sign (linear interpolation between the bracketing points; None when it
    keeps its sign to the end of the drawn range)."""
    from tirecli.studies.mcps.common import refine_peak

    out = {}
    fam = df[df["family"] == "alpha"]
    for fz, dl in fam.groupby("fz", sort=True):
        dl = drawn(dl, "mcps-fig9")
        per = {}
        for (model, carcass, cal), g in dl.groupby(["model", "carcass", "calibrated"], sort=False):
            g = g.sort_values("alpha")
            a, mz = g["alpha"].to_numpy(), g["mz"].to_numpy()
            i = int(np.argmax(np.abs(mz)))
            pa, pm = refine_peak(a, mz, i)
            change = None
            for j in range(i, mz.size - 1):
                if np.sign(mz[j + 1]) != np.sign(mz[i]):
                    change = float(a[j] + (a[j + 1] - a[j]) * mz[j] / (mz[j] - mz[j + 1]))
                    break
            per[variant(model, carcass, bool(cal))] = {"peak_Nm": pm, "peak_rad": pa, "sign_change_rad": change}
        out[f"{fz:g} N"] = per
    return out


def calibration_grids(fams) -> dict:
    """The drawn grids the calibration fits on: ``kappa`` (Fig. 7), ``alpha`` (the ``Mz`` of Fig. 9) and
    ``alpha_fy`` (the ``Fy`` of Fig. 8), from the run's families; Figs. 7-9's default grids for a family
    the run does not draw."""
    import pandas as pd

    kap = next((np.unique(f[1]) for f in fams if f[0] == "kappa"), np.linspace(0.0, 0.12, 49))
    alp = next((np.unique(f[2]) for f in fams if f[0] == "alpha"), np.linspace(-12 * DEG, 12 * DEG, 97))
    d = pd.DataFrame({"alpha": alp})
    return {"kappa": kap, "alpha": np.sort(drawn(d, "mcps-fig9")["alpha"].to_numpy()),
            "alpha_fy": np.sort(drawn(d, "mcps-fig8")["alpha"].to_numpy())}


__all__ = ["FIGURES", "drawn", "variant", "stationary_gaps", "mz_features", "calibration_grids"]
