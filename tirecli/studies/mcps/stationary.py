"""``mcps-stationary`` (``tirecli compare``): the stationary MCPS tire against the Magic Formula (MCPS Figs. 7-11)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import AnyOf, Bool, Grid, ListOf, Map, Num, Raw, Str, collect
from tirecli.errors import ConfigError, RunError
from tirecli.limits import Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.mcps.common import (BYTES_PER_ROW, CARCASSES, DEG, FAMILIES, MAX_CURVATURE_POINTS,
                                         MAX_STATIONARY_POINTS, MFSide, _lin, meta_summary, mf_side, tire_set)
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

CALIBRATE = AnyOf(options=(
    Bool(),
    Map(fields={
        "load": Num(unit="N", gt=0, default=None, doc="load of the fit (default: the first fz)"),
        "mz_weight": Num(unit="-", ge=0, le=10, default=0.1,
                         doc="weight of the Mz residuals against the Fy residuals in the lateral fit"),
    }),
), default=False, what="true, false or {load, mz_weight}")

STATIONARY = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set: a name, a file, or {set: ..., overrides} (default sorine2000-mcps)"),
    "mf": Raw(default=None, doc="Magic Formula side: a built-in tyre, a .tir path, simple, none, or {tire, convention}"),
    "carcass": AnyOf(options=(Str(choices=CARCASSES), ListOf(item=Str(choices=CARCASSES), max_len=2)),
                     default="complete", what="complete, rigid, or a list of them"),
    "fz": Grid(unit="N", gt=0, default=[4000.0], doc="vertical load(s)"),
    "kappa": Grid(unit="-", gt=-1.0, le=10.0, default=None, doc="longitudinal slip of the pure-slip family (alpha = 0)"),
    "alpha": Grid(unit="rad", ge=-1.5, le=1.5, default=None, doc="slip angle of the side-slip family (kappa = 0)"),
    "combined": Map(fields={
        "alpha": Grid(unit="rad", ge=-1.5, le=1.5, doc="slip angles of the combined family"),
        "kappa": Grid(unit="-", gt=-1.0, le=10.0, doc="slips of the combined family"),
    }, default=None),
    "curvature": Grid(unit="1/m", ge=-20.0, le=20.0, default=None, doc="path curvature at kappa = alpha = 0"),
    "calibrate": CALIBRATE,
    "frame_term": Bool(default=False, doc="frame-rotation term in the stationary patch (acts only with a curvature)"),
})


def _points(checked) -> list:
    """``(family, kappa, alpha, phi)`` arrays of every family the config asks for (Figs. 7-9 grids when none)."""
    fams = []
    if not any(checked[k] is not None for k in FAMILIES):
        checked["kappa"] = _lin(0.0, 0.12, 49)
        checked["alpha"] = _lin(-12 * DEG, 12 * DEG, 97)  # Fig. 8 draws alpha <= 0, Fig. 9 alpha >= 0
    if checked["kappa"] is not None:
        k = np.asarray(checked["kappa"], dtype=float)
        fams.append(("kappa", k, np.zeros_like(k), np.zeros_like(k)))
    if checked["alpha"] is not None:
        a = np.asarray(checked["alpha"], dtype=float)
        fams.append(("alpha", np.zeros_like(a), a, np.zeros_like(a)))
    if checked["combined"] is not None:
        A, K = np.meshgrid(np.asarray(checked["combined"]["alpha"], dtype=float),
                           np.asarray(checked["combined"]["kappa"], dtype=float), indexing="ij")
        fams.append(("combined", K.ravel(), A.ravel(), np.zeros(K.size)))
    if checked["curvature"] is not None:
        c = np.asarray(checked["curvature"], dtype=float)
        fams.append(("curvature", np.zeros_like(c), np.zeros_like(c), c))
    return fams


@dataclass
class Stationary:
    """The detail of an ``mcps-stationary`` plan: the MCPS parameters, the Magic Formula side, and
    ``(family, kappa, alpha, phi)`` of each family of points."""

    params: object
    mf: MFSide
    families: list


def plan(config: Config) -> Plan:
    """Check an ``mcps-stationary`` config completely (set ``tire``; detail :class:`Stationary`)."""
    checked, tire, mf = collect(lambda: config.checked(STATIONARY), lambda: tire_set(config), lambda: mf_side(config))
    carc = checked["carcass"]
    checked["carcass"] = [carc] if isinstance(carc, str) else list(dict.fromkeys(carc))
    fams = _points(checked)
    n = sum(f[1].size for f in fams) * len(checked["fz"]) * len(checked["carcass"])
    cap = compute_cap(MAX_STATIONARY_POINTS)
    if n > cap:
        raise ConfigError(config.origins.problem((), f"{n} stationary points (slips x loads x carcasses) exceed the "
                                                     f"budget of {cap:.0f}: use coarser grids " + cap_hint()))
    est = Estimate().add(n, tuple(("combined", k) for k in ("alpha", "kappa")) + tuple((k,) for k in FAMILIES) + (("fz",),),
                         f"the stationary points ({n:,}: slips x {len(checked['fz'])} load(s) x "
                         f"{len(checked['carcass'])} carcass(es))", BYTES_PER_ROW)
    est.check(config.origins)
    nc = sum(f[1].size for f in fams if f[0] == "curvature") * len(checked["fz"]) * len(checked["carcass"])
    cap = compute_cap(MAX_CURVATURE_POINTS)
    if nc > cap:
        raise ConfigError(config.origins.problem(("curvature",), f"{nc} curvature points (x loads x carcasses) exceed "
                                                                 f"the budget of {cap:.0f} (each integrates "
                                                                 "the patch along its length): use a coarser grid " + cap_hint()))
    cal = checked["calibrate"]
    if cal is True:
        cal = {"load": None, "mz_weight": 0.1}
    checked["calibrate"] = cal or None
    if checked["calibrate"] and mf.kind == "none":
        raise ConfigError(config.origins.problem(("calibrate",), "calibration fits MCPS to the Magic Formula curves: "
                                                                 "give an 'mf:' tyre (not none)"))
    sets = {"tire": tire} if mf.ps is None else {"tire": tire, "mf": mf.ps}
    return Plan("mcps-stationary", config, checked, sets, est, Stationary(tire.model(), mf, fams))


def _solve_all(p, fz, fams, carcass, frame_term, what: str):
    """Stationary MCPS solutions of every family at one load; RunError when a fixed point fails."""
    from tirecli.numerics.mcps_stationary import solve

    k = np.concatenate([f[1] for f in fams])
    a = np.concatenate([f[2] for f in fams])
    c = np.concatenate([f[3] for f in fams])
    st = solve(p, fz, k, a, c, carcass=carcass, frame_term=frame_term)
    bad = np.flatnonzero(~st.converged | ~np.isfinite(st.fx) | ~np.isfinite(st.fy) | ~np.isfinite(st.mz))
    if bad.size:
        i = bad[0]
        raise RunError(f"{what}: the belt fixed point (MCPS eq. 18) did not converge at fz = {fz:g} N, kappa = "
                       f"{k[i]:g}, alpha = {a[i]:g} rad, curvature = {c[i]:g} 1/m (max |G| = {st.residual[i]:.3g}; "
                       f"{bad.size} point(s)); check the belt stiffnesses k_x, k_y, k_delta of 'tire:'; nothing was written")
    return st


def _rows(model, carcass, calibrated, fams, fz, fx, fy, mz, x=None, y=None, d=None) -> pd.DataFrame:
    import pandas as pd

    n = sum(f[1].size for f in fams)
    nan = np.full(n, np.nan)
    return pd.DataFrame({
        "model": model, "carcass": carcass, "calibrated": calibrated,
        "family": np.concatenate([[f[0]] * f[1].size for f in fams]) if n else np.array([], dtype=object),
        "fz": np.full(n, float(fz)),
        "kappa": np.concatenate([f[1] for f in fams]), "alpha": np.concatenate([f[2] for f in fams]),
        "phi": np.concatenate([f[3] for f in fams]),
        "fx": np.asarray(fx, dtype=float), "fy": np.asarray(fy, dtype=float), "mz": np.asarray(mz, dtype=float),
        "x": nan if x is None else x, "y": nan if y is None else y, "delta": nan if d is None else d,
    })


def calibrated_set(ps, p_cal, fitted, mf: MFSide, fz: float):
    """The calibrated parameters as a :class:`ParameterSet` and its YAML document (``calibrated.yaml``);
    ``fitted``: the names of the fitted parameters."""
    from tirecli.parameters.sets import ParameterSet

    fitted = set(fitted)
    values = {k: float(getattr(p_cal, k)) for k in ps.values}
    doc_values = {}
    for k, v in values.items():
        if k in fitted:
            doc_values[k] = {"value": v, "note": f"calibrated to {mf.name} at {fz:g} N by tirecli compare"}
        elif k in ps.assumed:
            doc_values[k] = {"value": v, "assumed": ps.assumed[k]}
        else:
            doc_values[k] = v
    name = f"{ps.name}-calibrated"
    doc = {"name": name, "kind": "mcps",
           "title": f"{ps.title} -- rubber parameters calibrated to {mf.label} at {fz:g} N",
           "citation": f"{ps.citation} Calibrated by tirecli compare (least squares on the drawn curves, "
                       "docs/models/mcps_tire.md §8).",
           "values": doc_values}
    out = ParameterSet(name=name, kind="mcps", values=values,
                       source={k: ("tirecli compare (calibrated)" if k in fitted else ps.source.get(k, "")) for k in values},
                       assumed={k: v for k, v in ps.assumed.items() if k not in fitted},
                       notes={k: f"calibrated to {mf.name} at {fz:g} N" for k in fitted},
                       title=doc["title"], citation=doc["citation"])
    return out, doc


def run(plan_: Plan, progress=None) -> StudyResult:
    """Stationary MCPS (complete and/or solid carcass) against a Magic Formula tyre (MCPS Figs. 7-11)."""
    import pandas as pd  # once the config is checked: a refused run fails at once

    from tirecli.io.yamlio import dump_yaml
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf
    from tirecli.studies.mcps.gaps import calibration_grids, mz_features, stationary_gaps

    config, checked, ps = plan_.config, plan_.checked, plan_.sets["tire"]
    p, mf, fams = plan_.detail.params, plan_.detail.mf, plan_.detail.families

    loads = [float(f) for f in checked["fz"]]
    carcasses = checked["carcass"]
    frame = checked["frame_term"]
    cal = checked["calibrate"]
    total = len(loads) * (len(carcasses) + (1 if mf.kind != "none" else 0)) + (2 if cal else 0)
    if progress is not None:
        progress.start(total, "stationary")
    frames, sets, files, facts = [], {"tire": ps}, {}, {}
    calibration = None
    p_cal = None
    if cal:  # the one calibration: to the tyre drawn, on the drawn grids (docs/models/mcps_tire.md §8)
        fzc = float(cal["load"] or loads[0])
        grids = calibration_grids(fams)
        try:
            res = calibrate_to_mf(p, fzc, lambda k, a: mf.evaluate(k, a, fzc), grids["kappa"], grids["alpha"],
                                  alpha_fy=grids["alpha_fy"], carcass=carcasses[0], mz_weight=float(cal["mz_weight"]))
        except ValueError as err:
            raise RunError(f"calibration to {mf.name} at {fzc:g} N: {err}; nothing was written (no calibrated.yaml)") from None
        if res.failure:  # never a calibrated.yaml holding start values or a fit that did not converge
            raise RunError(f"calibration to {mf.name} at {fzc:g} N failed: {res.failure}; nothing was written "
                           "(no calibrated.yaml)")
        p_cal = res.params
        calibration = {"load": fzc, "carcass": carcasses[0], "target": mf.label, "mf_name": mf.name,
                       "grids": {k: {"start": float(v[0]), "stop": float(v[-1]), "points": int(v.size)}
                                 for k, v in grids.items()}, **res.as_dict()}
        cps, doc = calibrated_set(ps, p_cal, res.fitted, mf, fzc)
        sets["calibrated"] = cps
        files["calibrated.yaml"] = dump_yaml(doc)
        if progress is not None:
            progress.advance(2)
    for fz in loads:
        for carcass in carcasses:
            st = _solve_all(p, fz, fams, carcass, frame, f"tire {ps.label}")
            frames.append(_rows("mcps", carcass, False, fams, fz, st.fx, st.fy, st.mz, st.x, st.y, st.delta))
            if progress is not None:
                progress.advance(1)
        if p_cal is not None:
            st = _solve_all(p_cal, fz, fams, carcasses[0], frame, "calibrated tire")
            frames.append(_rows("mcps", carcasses[0], True, fams, fz, st.fx, st.fy, st.mz, st.x, st.y, st.delta))
        if mf.kind != "none":
            k = np.concatenate([f[1] for f in fams])
            a = np.concatenate([f[2] for f in fams])
            fx, fy, mz = mf.evaluate(k, a, fz)
            frames.append(_rows("mf", "", False, fams, fz, fx, fy, mz))
            if progress is not None:
                progress.advance(1)
        facts[f"{fz:g} N"] = {k: float(v) for k, v in p.stiffnesses(fz).items()}
    if progress is not None:
        progress.close()
    df = pd.concat(frames, ignore_index=True)
    bad = ~np.isfinite(df[["fx", "fy", "mz"]].to_numpy()).all(axis=1)
    if bad.any():
        row = df[bad].iloc[0]
        text = (f"non-finite forces for {row['model']} at fz = {row['fz']:g} N, kappa = {row['kappa']:g}, "
                f"alpha = {row['alpha']:g} rad")
        if row["model"] == "mf" and mf.kind == "tir":  # a load the tyre cannot evaluate is the config's fault
            t = mf.model
            hi, fnom = t.coef.get("FZMAX"), t.coef.get("FNOMIN")
            if (hi is not None and row["fz"] > hi) or (fnom and row["fz"] > 10 * fnom):
                limit = f"above FZMAX = {hi:g} N" if hi is not None and row["fz"] > hi else \
                    f"{row['fz'] / fnom:.3g} x FNOMIN ({fnom:g} N)"
                raise ConfigError(config.origins.problem(("fz",), f"{text}: the load is {limit} of {mf.name}, beyond "
                                                                  "what the tyre can evaluate; nothing was written"))
        raise RunError(f"{text}; nothing was written")
    fam_names = [f[0] for f in fams]
    default_figs = []
    if "kappa" in fam_names:
        default_figs.append("mcps-fig7")
    if "alpha" in fam_names:
        default_figs += ["mcps-fig8", "mcps-fig9"]
    if "combined" in fam_names:
        default_figs.append("mcps-fig10")
    if "curvature" in fam_names:
        default_figs.append("mcps-fig11")
    if cal:
        default_figs.append("mcps-calibration")
    if mf.ps is not None:
        sets["mf"] = mf.ps
    from tirecli.models.magic_formula.inputs import describe_outside

    flags = [f"{mf.name}: {line}" for line in describe_outside(mf.outside)]
    lines = [f"stiffnesses at {fz}: D_xsigma {v['D_xsigma']:.6g} N, D_yalpha {v['D_yalpha']:.6g} N/rad "
             f"(complete model {v['D_yalphaF']:.6g}), D_zalpha {v['D_zalpha']:.6g} N m/rad (complete {v['D_zalphaF']:.6g})"
             for fz, v in facts.items()]
    if calibration:
        lines += calibration_lines(calibration)
    gaps = stationary_gaps(df)
    return StudyResult(
        study="mcps-stationary", config=config, parameter_sets=sets, data={"stationary": df},
        meta={
            "title": checked["title"] or "MCPS stationary characteristics against the Magic Formula",
            "model": "MCPS (Sorine & Szymanski 2000): stationary patch (eq. 14), complete model by the belt "
                     "fixed point (eq. 18), solid carcass by eq. (14) alone",
            "axes": "ISO-W, road on tire, SI: kappa = (r omega - Vx)/|Vx| (> 0 driving), tan(alpha) = Vy/|Vx| "
                    "(alpha > 0 gives Fy < 0, Mz > 0), phi = yaw rate/Vx [1/m]",
            "carcass": carcasses, "families": fam_names, "loads": loads, "frame_term": frame,
            "mf": mf.record(), "stiffnesses": facts, "calibration": calibration, "gaps": gaps,
            "mz_features": mz_features(df) if "alpha" in fam_names else {},
            "points": int(len(df)), "summary": lines, "mf_outside_ranges": dict(mf.outside), "flags": flags,
        },
        figures=checked["figures"] or default_figs,
        payload={"params": p, "params_calibrated": p_cal, "mf": mf, "checked": checked},
        files=files,
    )


def calibration_lines(cal: dict) -> list:
    """What a calibration gives, in words: the fitted values, the parameters at a bound (with the bound
    and its source), the gaps of the start and the calibrated set, the aligning-torque peaks."""
    unit = {"fx": "N", "fy": "N", "mz": "N m"}
    at = {"fx": lambda v: f"kappa {100 * v:.3g} %", "fy": lambda v: f"{v / DEG:.3g} deg",
          "mz": lambda v: f"{v / DEG:.3g} deg"}
    vals = ", ".join(f"{n} = {f['value']:.4g}" for n, f in cal["fitted"].items())
    out = [f"calibration to {cal['mf_name']} at {cal['load']:g} N ({cal['carcass']} carcass): {vals}"]
    for n in cal["at_bound"]:
        f = cal["fitted"][n]
        out.append(f"  {n} ends at its {f['at_bound']} bound {f[f['at_bound']]:g} ({f['bound_source']})")
    for g in ("fx", "fy", "mz"):
        a, b = cal["gaps"]["start"][g], cal["gaps"]["calibrated"][g]
        out.append(f"  {g} gap to the Magic Formula: calibrated max {b['max']:.4g} {unit[g]} at {at[g](b['at'])}, "
                   f"rms {b['rms']:.4g} ({100 * b['max_rel']:.3g} % / {100 * b['rms_rel']:.3g} % of its peak); "
                   f"default max {a['max']:.4g} at {at[g](a['at'])}, rms {a['rms']:.4g}")
    pk = cal["peaks"]
    out.append("  Mz peak: " + ", ".join(f"{k} {pk[k]['mz']:.4g} N m at {pk[k]['alpha'] / DEG:.3g} deg"
                                          for k in ("mf", "calibrated", "start") if k in pk))
    return out


def facts(result) -> dict:
    """Flat facts (units from the name suffixes): the MCPS stiffnesses at each load
    (``D_xsigma[stiffness, 4000 N]`` ...), the gaps of every comparison figure to the Magic Formula
    (``fx_max_N[gap, mcps-fig7, 4000 N, complete]``, ``fx_at_kappa[...]``, ``fx_rms_N[...]`` ...,
    :func:`tirecli.studies.mcps.gaps.stationary_gaps`) and, with a calibration, the fitted values and
    its gaps and peaks (``r_x[calibration]``, ``fy_max_N[calibration, calibrated]``, ``mz_peak_rad[calibration, mf]``)."""
    from tirecli.studies.facts import flatten

    out = flatten({"stiffness": result.meta.get("stiffnesses") or {}, "gap": result.meta.get("gaps") or {}})
    cal = result.meta.get("calibration")
    if cal:
        c = {n: f["value"] for n, f in cal["fitted"].items()}
        c.update({f"{n}_at_bound": f["at_bound"] is not None for n, f in cal["fitted"].items()})
        for s, d in cal["gaps"].items():
            c[s] = {f"{g}_{k}_{'Nm' if g == 'mz' else 'N'}": v[k] for g, v in d.items() for k in ("max", "rms")}
            c[s].update({f"{g}_at_{'kappa' if g == 'fx' else 'rad'}": v["at"] for g, v in d.items()})
        for s, v in cal["peaks"].items():
            c.setdefault(s, {}).update({"mz_peak_Nm": v["mz"], "mz_peak_rad": v["alpha"]})
        for s in ("mf", "calibrated", "start"):
            c.setdefault(s, {})["mz_sign_change_rad"] = cal["sign_change"].get(s)
        out.update(flatten({"calibration": c}))
    return out


_CHECKS = "tirecli.studies.checks.mcps"

STUDY = register(Study(
    name="mcps-stationary", command="compare", spec=STATIONARY, plan=plan, run=run,
    figures=("mcps-fig7", "mcps-fig8", "mcps-fig9"),
    checks={fid: Lazy(_CHECKS, fn) for fid, fn in (
        ("mcps-fig7", "fig7_checks"), ("mcps-fig8", "fig8_checks"), ("mcps-fig9", "fig9_checks"),
        ("mcps-fig10", "fig10_checks"), ("mcps-fig11", "fig11_checks"), ("mcps-calibration", "calibration_checks"))},
    facts=facts, summary=meta_summary, files=("calibrated.yaml",),
))

__all__ = ["STUDY", "STATIONARY", "plan", "run", "calibrated_set", "calibration_lines", "Stationary"]
