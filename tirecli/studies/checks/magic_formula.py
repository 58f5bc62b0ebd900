"""Reference checks of the Magic Formula figures: the LuGre comparison, the built-in tyre cards and the
golden-data cards (``docs/models/magic_formula_tyre.md`` §5, §13.1, §15). Their ids start with ``mf-``."""
from __future__ import annotations

import numpy as np

from tirecli.studies.base import Check


def _fam(df, family):
    return df[df["family"] == family]


def compare_checks(result):
    """Both curves start at the origin and stay finite; the Magic Formula curve's initial slope
    d|mu|/d|s| is K_xk / Fz (docs/models/magic_formula_tyre.md §5.1: slope at zero slip equals the stiffness)."""
    from tirecli.models.magic_formula.pure import pure_slip_factors

    d = _fam(result.data["sweep"], "compare")
    lu = result.data["lugre"]
    bad = float((~np.isfinite(d["mu_x"])).sum() + (~np.isfinite(lu["mu"])).sum())
    out = [Check("finite", "non-finite |mu| values on the comparison plot", bad, 0.0, 0.0, "-", "output contract")]
    t = result.payload["tire"]
    if t.family == "mf":
        fz = float(d["fz"].iloc[0])
        f = pure_slip_factors(t, fz, convention=result.payload["convention"])
        g = d.assign(s=d["slip"].abs()).sort_values("s")
        g = g[(g["kappa"] > 0) & (g["kappa"] < 0.01)]
        if len(g) >= 2:
            s0 = g.iloc[:2]
            slope = float(np.diff(s0["mu_x"])[0] / np.diff(s0["kappa"])[0])
            out.append(Check("mf-slope", "Magic Formula d(Fx/Fz)/dkappa near zero slip over K_xk/Fz", slope / (f["fx"]["K"] / fz),
                             1.0, 0.05, "-", "docs/models/magic_formula_tyre.md §5.1"))
    out += _gap_checks(result, d)
    return out


def _gap_checks(result, d) -> list:
    """The stated gaps (run.json ``facts.gap``, the legend) recomputed from the model functions: the LuGre
    steady state :func:`tirecli.models.lugre.mu_ss_uniform` at the Magic Formula's slip points and the Magic
    Formula evaluated there, not read from the frames; largest gap, where, RMS."""
    from tirecli.conventions import kappa_from_slip, speeds_from_slip
    from tirecli.models.lugre import mu_ss_uniform
    from tirecli.models.magic_formula import evaluate
    from tirecli.numerics.gaps import curve_gap

    stated = (result.meta.get("facts") or {}).get("gap") or {}
    t, p = result.payload["tire"], result.parameter_sets["lugre"].model()
    speed = float(result.data["lugre"]["speed"].iloc[0])
    fz = float(d["fz"].iloc[0])
    kw = {"convention": result.payload["convention"], "limits": result.meta.get("limits", True)}
    vx, pr = float(d["vx"].iloc[0]), float(d["p"].iloc[0])
    out = []
    for direction, sign in (("braking", -1.0), ("driving", 1.0)):
        if direction not in stated:
            out.append(Check(f"gap-{direction}", f"the {direction} gap is stated", 0.0, 1.0, 0.0, "-", "output contract"))
            continue
        s = np.unique(np.abs(d.loc[(d["kappa"] <= 0) if sign < 0 else (d["kappa"] >= 0), "slip"]))
        extra = {k: x for k, x in (("vx", vx), ("p", pr)) if np.isfinite(x)}
        ref = np.abs(evaluate(t, kappa_from_slip(sign * s), 0.0, 0.0, fz, **extra, **kw).fx) / fz
        v, romega = speeds_from_slip(sign * s, speed)
        model = np.abs(mu_ss_uniform(romega - v, romega, p))
        g = curve_gap(s, model, ref)
        got = stated[direction]
        src = "recomputed from mu_ss_uniform (docs/models/lugre_friction.md) and the Magic Formula"
        out += [Check(f"gap-{direction}-max", f"largest |mu| gap LuGre - MF, {direction}", got["max"], g.max, 1e-3, "-", src),
                Check(f"gap-{direction}-at", f"|s| of the largest gap, {direction}", got["at"], g.at, 2.5e-3, "-", src),
                Check(f"gap-{direction}-rms", f"RMS |mu| gap LuGre - MF, {direction}", got["rms"], g.rms, 1e-3, "-", src)]
    return out


def tire_checks(result):
    """Facts every Magic Formula curve of a sweep must satisfy (docs/models/magic_formula_tyre.md §5, §13.1, §15.5)."""
    from tirecli.models.magic_formula import evaluate
    from tirecli.models.magic_formula.pure import pure_slip_factors

    t = result.payload["tire"]
    df = result.data["sweep"]
    cols = ["fx", "fy", "mz", "mx", "my"]
    bad = float(sum(int((~np.isfinite(df[c])).sum()) for c in cols))
    out = [Check("finite", "non-finite outputs over the whole sweep", bad, 0.0, 0.0, "-", "output contract")]
    if t.family != "mf":
        return out
    conv = result.payload["convention"]
    fz0 = t["FNOMIN"]
    f = pure_slip_factors(t, fz0, convention=conv)
    h = 1e-7
    sh = f["fx"]["SH"]
    fx = evaluate(t, np.array([-sh - h, -sh + h, -sh]), 0.0, 0.0, fz0, convention=conv, limits=False).fx
    slope = (fx[1] - fx[0]) / (2 * h)
    out += [
        Check("kxk-slope", "dFx0/dkappa at kappa_x = 0 over K_xk (docs/models/magic_formula_tyre.md §13.1: slope BCD = K)", float(slope / f["fx"]["K"]),
              1.0, 1e-5, "-", "docs/models/magic_formula_tyre.md §5.1, §13.1"),
        Check("fx-shift", "Fx0(kappa = -S_Hx) - S_Vx [N] (docs/models/magic_formula_tyre.md §15.5)", float(fx[2] - f["fx"]["SV"]), 0.0,
              1e-9 * fz0, "N", "docs/models/magic_formula_tyre.md §15.5"),
    ]
    shy = f["fy"]["SH"]
    fy = evaluate(t, 0.0, np.array([-shy - h, -shy + h, -shy]), 0.0, fz0, convention=conv, limits=False).fy
    out += [
        Check("kya-slope", "dFy0/dalpha at alpha_y = 0 over K_ya", float((fy[1] - fy[0]) / (2 * h) / f["fy"]["K"]),
              1.0, 1e-5, "-", "docs/models/magic_formula_tyre.md §5.2, §13.1"),
        Check("fy-shift", "Fy0(alpha = -S_Hy) - S_Vy [N] (docs/models/magic_formula_tyre.md §15.5)", float(fy[2] - f["fy"]["SV"]), 0.0,
              1e-9 * fz0, "N", "docs/models/magic_formula_tyre.md §15.5"),
    ]
    if result.parameter_sets["tire"].name == "pacejka2006-205-60r15":
        for fz, mux, kxk, muy, kya in ((2000.0, 1.2285, 38204.2551, -1.0625, -26608.8700),
                                       (4000.0, 1.2100, 86040.0, -0.9900, -46009.1387)):
            g = pure_slip_factors(t, fz, convention=conv)
            out += [
                Check(f"mux-{fz:g}", f"mu_x at Fz = {fz:g} N", float(g["fx"]["mu"]), mux, 5e-5, "-", "docs/models/magic_formula_tyre.md §15.5"),
                Check(f"kxk-{fz:g}", f"K_xk at Fz = {fz:g} N", float(g["fx"]["K"]), kxk, 5e-5, "N", "docs/models/magic_formula_tyre.md §15.5"),
                Check(f"muy-{fz:g}", f"mu_y at Fz = {fz:g} N", float(g["fy"]["mu"]), muy, 5e-5, "-", "docs/models/magic_formula_tyre.md §15.5"),
                Check(f"kya-{fz:g}", f"K_ya at Fz = {fz:g} N", float(g["fy"]["K"]), kya, 5e-5, "N/rad", "docs/models/magic_formula_tyre.md §15.5"),
            ]
    return out


def golden_checks(block, result):
    """The checks of the golden-data card of ``block`` (figure ``mf-golden-BLOCK``)."""
    from tirecli.studies.mf_golden import OUTPUTS, TOLERANCE

    df = result.data["golden"]
    d = df[df["block"] == block]
    worst = max(float(np.abs(d[f"{c}_residual"]).max()) for c in OUTPUTS)
    per = {c: float(np.abs(d[f"{c}_residual"]).max()) for c in OUTPUTS}
    which = max(per, key=per.get)
    return [Check("largest-residual", f"largest |tirecli - golden| over the {len(d)} rows of {block}.csv "
                                      f"(Fx, Fy, Mz, Mx, My; largest in {which})", worst, 0.0, TOLERANCE,
                  "N or N m", "docs/models/magic_formula_tyre.md §15.4")]
