"""MCPS figures (Sorine & Szymanski 2000): Figs. 3-5 and 7-11, the relaxation run, the calibration
and the parameter table, with the reference checks of ``docs/models/mcps_tire.md``.

Forces are computed in ISO-W, road on tire (:mod:`tirecli.models.mcps.tire`). The paper-style signs
are applied here, at the plotting step only (docs/models/mcps_tire.md §1): side force ``-Fy`` and
aligning torque ``+Mz`` against the slip angle ``alpha_s`` (equivalently ``Fy`` against
``-alpha_s``, the paper's "-delta" axis of Fig. 8); Fig. 10 draws the same ordinates against
``Fx``; Fig. 11 draws magnitudes. Slip angles are drawn in degrees, slips in percent.

Reference checks come in two kinds: *model* checks (the computed curves against the closed forms and
linear stiffnesses of the same parameters: valid for any parameter set) and *reference* checks (the
reference numbers of docs/models/mcps_tire.md §11 for the default set ``sorine2000-mcps`` and the paper's scenario; skipped when the
set or the scenario differs).
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, LINESTYLES, finish, new_figure
from tirecli.studies.base import Check

DOC = "docs/models/mcps_tire.md"
DEG = math.pi / 180.0


def require(result, study: str, fid: str, family: str | None = None) -> None:
    """A UsageError unless ``result`` is a ``study`` run (holding ``family`` for stationary figures)."""
    from tirecli.errors import UsageError

    if result.study != study:
        raise UsageError(f"figure {fid!r} draws an '{study}' run, not a '{result.study}' run (see 'tirecli figures list')")
    if family is not None and family not in set(result.data["stationary"]["family"]):
        raise UsageError(f"figure {fid!r} draws the '{family}' family: add '{family}:' to the config")


def _reference(result) -> bool:
    from tirecli.studies.mcps import reference_tire

    return reference_tire(result.parameter_sets["tire"])


def _tire_name(result) -> str:
    return result.parameter_sets["tire"].label


# --------------------------------------------------------------------------- stationary curves


def _variants(df):
    """The curves of a stationary frame: ``(label, selection, style)`` for MCPS (each carcass,
    calibrated) and the Magic Formula."""
    out = []
    for (model, carcass, cal), _ in df.groupby(["model", "carcass", "calibrated"], sort=False):
        sel = (df["model"] == model) & (df["carcass"] == carcass) & (df["calibrated"] == cal)
        if model == "mf":
            style = {"color": "#000000", "ls": "-", "lw": 1.4}
            label = "MF"
        elif cal:
            style = {"color": COLORS[2], "ls": "-.", "lw": 1.4}
            label = f"MCPS calibrated ({carcass})"
        elif carcass == "complete":
            style = {"color": COLORS[0], "ls": "-", "lw": 1.6}
            label = "MCPS complete model"
        else:
            style = {"color": COLORS[1], "ls": "--", "lw": 1.3}
            label = "MCPS solid carcass"
        out.append((label, sel, style))
    return out


def _legend_below(fig, ax, ncol=3):
    """One legend for the figure, below the panels (never over the curves)."""
    h, lab = ax.get_legend_handles_labels()
    if h:
        fig.legend(h, lab, loc="outside lower center", ncol=ncol, fontsize=8, frameon=False)


def _mf_label(result) -> str:
    return result.meta["mf"]["label"]


def _curve_panels(result, family, x_col, y_fn, xlabel, ylabel, title, x_scale=1.0):
    """One panel per load (three per row), one legend below the panels."""
    df = result.data["stationary"]
    d = df[df["family"] == family]
    loads = sorted(d["fz"].unique())
    ncols = min(len(loads), 3)
    nrows = -(-len(loads) // 3)
    fig, axes = new_figure(ncols=ncols, nrows=nrows, width=6.4 if ncols == 1 else 4.2 * ncols, height=4.0 + 3.2 * (nrows - 1))
    axes = np.atleast_1d(axes).ravel()
    for ax, fz in zip(axes, loads):
        dl = d[d["fz"] == fz]
        for label, sel, style in _variants(dl):
            g = dl[sel].sort_values(x_col)
            ax.plot(g[x_col] * x_scale, y_fn(g), label=_mf_label(result) if label == "MF" else label, **style)
        finish(ax, xlabel, ylabel, f"Fz = {fz:g} N" if len(loads) > 1 else None, legend=False)
    for ax in axes[len(loads):]:
        ax.set_visible(False)
    _legend_below(fig, axes[0], ncol=2)
    fig.suptitle(title, fontsize=10)
    return fig


def _first_load(result, fid, family):
    """The rows of ``family`` at the run's first load (figures drawn at one load): ``(frame, fz)``."""
    require(result, "mcps-stationary", fid, family)
    df = result.data["stationary"]
    d = df[df["family"] == family]
    fz = sorted(d["fz"].unique())[0]
    return d[d["fz"] == fz], fz


def _solve(p, fz, kappa, alpha, phi, carcass="complete"):
    from tirecli.numerics.mcps_stationary import solve

    return solve(p, fz, kappa, alpha, phi, carcass=carcass, tol=1e-12)


def _slope(p, fz, which, axis, carcass="complete", e=1e-5):
    """Derivative at zero of output ``which`` (fx, fy, mz) along ``axis`` (0: kappa, 1: alpha, 2: phi),
    from two small steps with Richardson extrapolation (error O(e^2))."""
    pts = np.zeros((3, 2))
    pts[axis] = (e, 2 * e)
    st = _solve(p, fz, pts[0], pts[1], pts[2], carcass)
    v = getattr(st, which)
    return float(2.0 * v[0] / e - v[1] / (2.0 * e))


def _load_present(result, fz) -> bool:
    return any(abs(f - fz) < 1e-9 for f in result.meta["loads"])


def _carcasses(result) -> list:
    return result.meta["carcass"]



# --------------------------------------------------------------------------- captions (describe the run at hand)


def _loads_text(result, default="4000 N") -> str:
    if result is None:
        return default
    loads = result.meta.get("loads") or [result.meta.get("scenario", {}).get("fz_N", 4000.0)]
    return ", ".join(f"{f:g}" for f in loads) + " N"


def _mf_text(result) -> str:
    """What the Magic Formula side of a stationary run is."""
    mf = (result.meta.get("mf") or {}) if result is not None else {"kind": "tir", "name": "externdata-205-60r15"}
    if mf.get("kind") == "none":
        return "no Magic Formula tyre (mf: none)"
    if mf.get("kind") == "simple":
        return ("the simple-form Magic Formula with fixed B, C, D, E [assumed] (combined slip by the normalised-slip "
                "method)")
    name = mf.get("name", "")
    if name == "externdata-205-60r15":
        return ("a real Magic Formula tyre, the ExternData sample MF 6.1 205/60R15 at 4000 N (a stand-in: the paper's "
                "165/65R14 data are not public), steady state, camber 0, input limits off")
    return f"the Magic Formula tyre {name} (steady state, camber 0, input limits off)"


def _models_text(result) -> str:
    """The MCPS curves of a stationary run."""
    if result is None:
        carc, cal = ["complete", "rigid"], True
    else:
        carc, cal = result.meta.get("carcass", ["complete"]), bool(result.meta.get("calibration"))
    parts = []
    if "complete" in carc:
        parts.append("the complete model (belt fixed point, MCPS eq. 18)")
    if "rigid" in carc:
        parts.append("the solid carcass (eq. 14)")
    if cal:
        parts.append("MCPS with its rubber parameters calibrated to the Magic Formula curves (docs/models/mcps_tire.md §8)")
    return ", ".join(parts)


def _tire_text(result) -> str:
    if result is None or _reference(result):
        return "the default tire sorine2000-mcps [every value assumed: the paper prints none]"
    return f"the tire {_tire_name(result)}"


def _caption_fig7(result):
    return (f"Fx against the longitudinal slip kappa (ISO-W, road on tire) at {_loads_text(result)}, alpha = 0: MCPS with "
            f"{_tire_text(result)}, {_models_text(result)}; and {_mf_text(result)}. In pure longitudinal slip the complete "
            "model and the solid carcass coincide exactly. With the default tire MCPS rises more slowly than a Magic "
            "Formula and is still rising at 12 %; calibration narrows the gap but cannot close it (a patch mean of a Dahl "
            "response bends over more slowly). Equations and choices: docs/models/mcps_tire.md.")


def _caption_fig8(result):
    return (f"Side force -Fy against the slip angle alpha_s at {_loads_text(result)}, kappa = 0. Paper-style signs: the "
            "ISO-W side force Fy is negated (a positive slip angle gives a negative ISO Fy), the aligning torque is drawn "
            f"as computed. MCPS with {_tire_text(result)}: {_models_text(result)}; and {_mf_text(result)}. The belt twist "
            "lowers the cornering stiffness of the complete model below the solid carcass's (eq. 20; 36 910 against "
            "44 590 N/rad for the default tire at 4000 N).")


def _caption_fig9(result):
    return (f"Aligning torque Mz (ISO-W, not negated) against the slip angle at {_loads_text(result)}, kappa = 0: rise, "
            "peak at a moderate angle, decline as the patch slides and the pneumatic trail collapses. MCPS with "
            f"{_tire_text(result)}: {_models_text(result)} (c_Mz fitted last); and {_mf_text(result)} (Mz of its "
            "combined-slip formula at kappa = 0). The twist lowers the aligning stiffness (eq. 20).")


def _caption_fig10(result):
    if result is None or result.payload is None or "checked" not in result.payload:
        fam = "alpha_s = 1, 2, 4 deg with kappa swept from -0.1 (braking) to +0.1 (driving)"
    else:
        comb = result.payload["checked"]["combined"] or {"alpha": [], "kappa": [0.0]}
        al = ", ".join(f"{a / DEG:.3g}" for a in comb["alpha"])
        fam = f"alpha_s = {al} deg with kappa swept from {min(comb['kappa']):g} to {max(comb['kappa']):g}"
    return (f"Families at constant slip angle, {fam} [assumed scenario], at {_loads_text(result)} (the first load is "
            "drawn): -Fy (left) and Mz (right) against Fx, paper-style signs. The side force falls as |Fx| grows for both "
            "models. The aligning torque differs: in MCPS (complete model) braking drives Mz towards 0 while driving keeps "
            "it large, through the belt offsets in MW = MA + x FAy - y FAx (eq. 16); the solid carcass gives a nearly "
            f"symmetric curve. Magic Formula side: {_mf_text(result)}; its combined-slip rules do not describe this "
            "influence of Fx on Mz.")


def _caption_fig11(result):
    return (f"|Fy| (left) and |Mz| (right) produced by path curvature alone (Vy = 0, Vx = r omega, yaw rate = phi Vx; "
            f"both negative in ISO for phi > 0, magnitudes drawn [assumed]) at {_loads_text(result, '2000 N')} (the first "
            f"load is drawn). MCPS with {_tire_text(result)}: {_models_text(result)}, the lateral slip varying along "
            "the patch, frame-rotation term off: nearly linear; the belt twist raises |Fy| and lowers |Mz|. A Magic "
            "Formula without turn slip has no curvature input: its response is zero (its constant output at zero slip, a "
            "conicity/ply-steer offset, is not a curvature response and is given in the legend).")


def _caption_fig3(result):
    if result is None:
        vals = "U = 1 cm^2 under the 4000 N patch pressure: K = 5000 N/m, F_k = 19.8 N, S_z = 0.35 N m/rad, M_kz = 0.187 N m"
        motion, periods = "A = 8 F_k/K, Psi = 8 M_kz/S_z", "T = 2 s (solid, exact increments) and T = 0.5 s (dashed, eq. 9 integrated in time)"
        frame = "off"
    else:
        f, sc = result.meta["facts"], result.meta["scenario"]
        vals = (f"U = {result.payload['params'].U:g} m^2 under {f['pressure_Pa'] / 1e3:.4g} kPa: K = {f['K_N_per_m']:.4g} N/m, "
                f"F_k = {f['Fk_N']:.4g} N, S_z = {f['Sz_Nm_per_rad']:.4g} N m/rad, M_kz = {f['Mkz_Nm']:.4g} N m")
        motion = f"A = {1e3 * f['amplitude_m']:.4g} mm, Psi = {f['rotation_rad']:.4g} rad"
        per = sc["periods_s"]
        periods = f"T = {per[0]:g} s (solid, exact increments)" + (
            f" and T = {per[1]:g} s (dashed, eq. 9 integrated in time)" if len(per) > 1 else "")
        frame = "on" if sc["frame_term"] else "off"
    return (f"One slider ({vals}; {_tire_text(result)}) driven by u_x = A sin(2 pi t/T), psi = Psi sin(2 pi t/T), "
            f"{motion} [assumed scenario], frame-rotation term {frame}. Force and torque are what the slider transmits to "
            "the road (MCPS eq. 9). Initial slope K (S_z), overshoot above the Coulomb level on first loading (4/3 F_k "
            f"with alpha = 3, beta = 1.5) and more after each reversal (limit 5/3 F_k), then the Coulomb level. {periods}: "
            "coinciding loops show that the law is rate independent.")


def _standstill_text(result):
    if result is None:
        return "4000 N, |yaw rate| = 1 rad/s, psi = 0 -> +0.45 -> -0.45 -> +0.45 rad [assumed amplitude], frame-rotation term on"
    sc = result.meta["scenario"]
    A = sc["amplitude_rad"]
    return (f"{sc['fz_N']:g} N, |yaw rate| = {sc['yaw_rate_rad_per_s']:g} rad/s, psi = 0 -> +{A:.3g} -> -{A:.3g} rad, "
            f"{sc['cycles']} cycle(s)" + (" [assumed amplitude: the scan's '-45 <= psi <= 45' read as +-0.45 rad]"
                                           if abs(A - 0.45) < 1e-8 else "")
            + f", frame-rotation term {'on' if sc['frame_term'] else 'off'}")


def _caption_fig4(result):
    return (f"Blocked wheel (V = 0, rigid belt; {_standstill_text(result)}; {_tire_text(result)}). Left: the lateral "
            "force density f_y(xi, t) of the road on the tire (ISO-W; odd in xi); right: profiles at the yaw reversals "
            "over F'_ky. Near the centre f_y grows with |xi| psi; the edges saturate first, with an overshoot on first "
            "loading (4/3 F'_ky without the frame term) and a larger one after each reversal (limit 5/3 F'_ky).")


def _caption_fig5(result):
    return (f"Mz (road on tire, ISO) against the yaw angle psi for the Fig. 4 motion ({_standstill_text(result)}; "
            f"{_tire_text(result)}). Linear start with slope -C_z (eq. 11, dashed), saturation towards -sgn(yaw rate) times "
            "the asymptotic torque (dotted: with the frame term; dash-dot: eq. 12, without it) with overshoot, a larger "
            "overshoot after each reversal, and a loop that settles to a periodic one within a few cycles (the first is not "
            "symmetric). The Magic Formula has no torque at standstill. The scan's torque ticks suggest the paper's tire "
            "gives about half the torques of the default tire.")


def _caption_relaxation(result):
    if result is None:
        scen, cases = "at 20 m/s, Vy steps to Vx tan(1 deg)", "the solid carcass, the complete model, and the complete model with the twist locked"
    else:
        sc = result.meta["scenario"]
        scen = f"at {sc['speed_m_per_s']:g} m/s, Vy steps to Vx tan({sc['alpha_rad'] / DEG:.3g} deg) ({sc['fz_N']:g} N)"
        cases = ", ".join(c["label"] for c in result.meta["cases"])
    return (f"From free rolling {scen} at t = 0 [assumed scenario]; Fy/Fy_inf (left) and Mz (right) against the rolled "
            f"distance, frame-rotation term on; cases: {cases}; {_tire_text(result)}. The solid carcass is exact by "
            "characteristics and steady after one patch length. With the default tire at 20 m/s and 1 deg the complete "
            "model is not monotone (about 72 % at 0.08 m, a dip to about 25 % near 0.19 m, then a slow rise, 95 % near "
            "0.78 m): the dip is the lateral belt mode y, it stays with the twist locked (63 % first reached at 0.309 m) "
            "and vanishes when y is locked. Transport by Lagrangian tread elements (CFL = 1), second order. The Magic "
            "Formula, a stationary model, cannot give this build-up.")


# --------------------------------------------------------------------------- Fig. 7


def _fig7_checks(result):
    from tirecli.models.mcps.tire import pure_longitudinal_fx

    p = result.payload["params"]
    df = result.data["stationary"]
    out = []
    for fz in result.meta["loads"]:
        sti = p.stiffnesses(fz)
        out.append(Check(f"slope-{fz:g}", f"dFx/dkappa at kappa = 0, Fz = {fz:g} N, over D_xsigma = w r_x l^2/2",
                         _slope(p, fz, "fx", 0, _carcasses(result)[0]) / sti["D_xsigma"], 1.0, 1e-6, "-",
                         f"{DOC} §6 (stiffness table)"))
        k = np.array([0.01, 0.05, 0.1, 0.12])
        st = _solve(p, fz, k, 0 * k, 0 * k, _carcasses(result)[0])
        dev = float(np.max(np.abs(st.fx - pure_longitudinal_fx(k, p, fz))))
        out.append(Check(f"closed-form-{fz:g}", f"max |Fx - closed form| at kappa = 0.01-0.12, Fz = {fz:g} N",
                         dev, 0.0, 1e-6, "N", f"{DOC} §6 (pure longitudinal closed form)"))
    d = df[(df["family"] == "kappa") & (df["model"] == "mcps") & (~df["calibrated"])]
    if set(d["carcass"]) >= {"complete", "rigid"}:
        a = d[d["carcass"] == "complete"]["fx"].to_numpy()
        b = d[d["carcass"] == "rigid"]["fx"].to_numpy()
        out.append(Check("carcass-invariant", "max |Fx(complete) - Fx(solid carcass)| in pure longitudinal slip",
                         float(np.max(np.abs(a - b))), 0.0, 1e-6, "N", f"{DOC} §7 (the carcass does not act)"))
    if _reference(result) and _load_present(result, 4000.0):
        st = _solve(p, 4000.0, [0.01, 0.05, 0.1, 0.12], [0.0] * 4, [0.0] * 4)
        for kv, ref, v in zip((0.01, 0.05, 0.1, 0.12), (586.79, 2177.23, 3176.78, 3410.85), st.fx):
            out.append(Check(f"fx-{kv:g}", f"MCPS Fx at kappa = {kv:g}, 4000 N", float(v), ref, 0.01, "N", f"{DOC} §6 checks"))
    return out


@register(
    "mcps-fig7", paper="MCPS", label="Fig. 7", study="mcps-fig7-9", order=70, checks=_fig7_checks,
    title="Stationary longitudinal force: MCPS against the Magic Formula",
    caption=_caption_fig7,
    paper_shows="Fx against the slip (ticks up to about 12, likely %) for a 165/65R14 tire, MCPS and 'PaMaF': two "
                "very similar curves from the origin, bending over.",
)
def draw_fig7(result):
    require(result, "mcps-stationary", "mcps-fig7", "kappa")
    return _curve_panels(result, "kappa", "kappa", lambda g: g["fx"], "longitudinal slip kappa [%]", "Fx [N]",
                         f"MCPS Fig. 7: stationary Fx, {_tire_name(result)}", x_scale=100.0)


# --------------------------------------------------------------------------- Figs. 8, 9


def _alpha_ref_checks(result, what):
    p = result.payload["params"]
    out = []
    carc = _carcasses(result)
    for fz in result.meta["loads"]:
        sti = p.stiffnesses(fz)
        for c in carc:
            if what == "fy":
                ref = sti["D_yalphaF"] if c == "complete" else sti["D_yalpha"]
                name = "D_yalphaF (eq. 20)" if c == "complete" else "D_yalpha"
                out.append(Check(f"stiffness-{c}-{fz:g}", f"-dFy/dalpha at alpha = 0, {c} carcass, Fz = {fz:g} N, over {name}",
                                 -_slope(p, fz, "fy", 1, c) / ref, 1.0, 1e-6, "-", f"{DOC} §6-§7"))
            else:
                ref = sti["D_zalphaF"] if c == "complete" else sti["D_zalpha"]
                name = "D_zalphaF (eq. 20)" if c == "complete" else "D_zalpha"
                out.append(Check(f"stiffness-{c}-{fz:g}", f"dMz/dalpha at alpha = 0, {c} carcass, Fz = {fz:g} N, over {name}",
                                 _slope(p, fz, "mz", 1, c) / ref, 1.0, 1e-6, "-", f"{DOC} §6-§7"))
    if _reference(result) and _load_present(result, 4000.0):
        degs = [1, 2, 4, 12]
        refs = {"fy": (606.95, 1141.54, 2009.78, 3600.32), "mz": (13.585, 24.416, 38.859, 41.811)}[what]
        st = _solve(p, 4000.0, [0.0] * 4, [d * DEG for d in degs], [0.0] * 4)
        vals = -st.fy if what == "fy" else st.mz
        for d, ref, v in zip(degs, refs, vals):
            out.append(Check(f"{what}-{d}deg", f"complete model {'-Fy' if what == 'fy' else 'Mz'} at {d} deg, 4000 N",
                             float(v), ref, 0.01 if what == "fy" else 0.001, "N" if what == "fy" else "N m",
                             f"{DOC} §7 checks"))
        if "rigid" in carc:
            st = _solve(p, 4000.0, [0.0] * 2, [4 * DEG, 12 * DEG], [0.0] * 2, "rigid")
            vals = -st.fy if what == "fy" else st.mz
            refs = (2177.39, 3634.41) if what == "fy" else (41.379, 41.65)
            for d, ref, v in zip((4, 12), refs, vals):
                out.append(Check(f"rigid-{what}-{d}deg", f"solid carcass {'-Fy' if what == 'fy' else 'Mz'} at {d} deg, 4000 N",
                                 float(v), ref, 0.01, "N" if what == "fy" else "N m", f"{DOC} §11 (Figs. 8-9)"))
        if what == "mz":
            from scipy.optimize import minimize_scalar

            r = minimize_scalar(lambda a: -_solve(p, 4000.0, [0.0], [a * DEG], [0.0]).mz[0], bounds=(5.0, 10.0),
                                method="bounded", options={"xatol": 1e-6})
            out.append(Check("mz-peak", "peak Mz of the complete model, 4000 N", float(-r.fun), 47.28, 0.01, "N m",
                             f"{DOC} §11 (Fig. 9)"))
            out.append(Check("mz-peak-angle", "slip angle of the peak Mz", float(r.x), 7.78, 0.01, "deg",
                             f"{DOC} §11 (Fig. 9)"))
    return out


@register(
    "mcps-fig8", paper="MCPS", label="Fig. 8", study="mcps-fig7-9", order=80,
    checks=lambda r: _alpha_ref_checks(r, "fy"),
    title="Stationary lateral force: MCPS against the Magic Formula",
    caption=_caption_fig8,
    paper_shows="Lateral force against the slip angle (axis '-delta (deg)', 0-12 deg), MCPS and PaMaF nearly coincident: "
                "linear start, curvature, saturation.",
)
def draw_fig8(result):
    require(result, "mcps-stationary", "mcps-fig8", "alpha")
    return _curve_panels(result, "alpha", "alpha", lambda g: -g["fy"], "slip angle alpha_s [deg]",
                         "side force -Fy [N] (ISO Fy negated)", f"MCPS Fig. 8: stationary side force, {_tire_name(result)}",
                         x_scale=1.0 / DEG)


@register(
    "mcps-fig9", paper="MCPS", label="Fig. 9", study="mcps-fig7-9", order=90,
    checks=lambda r: _alpha_ref_checks(r, "mz"),
    title="Stationary self-aligning torque: MCPS against the Magic Formula",
    caption=_caption_fig9,
    paper_shows="Self-aligning torque against the slip angle (axis 'delta (deg)', 0-12 deg), MCPS and PaMaF of similar shape.",
)
def draw_fig9(result):
    require(result, "mcps-stationary", "mcps-fig9", "alpha")
    return _curve_panels(result, "alpha", "alpha", lambda g: g["mz"], "slip angle alpha_s [deg]", "aligning torque Mz [N m]",
                         f"MCPS Fig. 9: stationary aligning torque, {_tire_name(result)}", x_scale=1.0 / DEG)


# --------------------------------------------------------------------------- Fig. 10


def _fig10_checks(result):
    p = result.payload["params"]
    df = result.data["stationary"]
    out = []
    d = df[(df["family"] == "combined") & (df["model"] == "mcps") & (df["carcass"] == "complete") & (~df["calibrated"])]
    for (fz, a), g in d.groupby(["fz", "alpha"]):
        if a == 0:
            continue
        g = g.sort_values("kappa")
        brake = g[g["kappa"] < 0]
        drive = g[g["kappa"] > 0]
        if len(brake) and len(drive):
            out.append(Check(f"asymmetry-{fz:g}-{a / DEG:.3g}deg",
                             f"|Mz| largest on the driving side (alpha = {a / DEG:.3g} deg, Fz = {fz:g} N): "
                             "max |Mz| driving over max |Mz| braking, at least 1",
                             float(drive["mz"].abs().max() / max(brake["mz"].abs().max(), 1e-12)), 1.0, 0.0, "-",
                             f"{DOC} §11 (Fig. 10)", bound="min"))
    if _reference(result) and _load_present(result, 4000.0):
        k = [-0.05, 0.0, 0.05, 0.0]
        a = [4 * DEG, 4 * DEG, 4 * DEG, 2 * DEG]
        st = _solve(p, 4000.0, k, a, [0.0] * 4)
        refs = [(-1911.33, -1990.82, 17.54), (-6.22, -2009.78, 38.86), (1858.81, -1723.95, 47.15), (-2.68, -1141.54, 24.42)]
        for i, (kv, av, ref) in enumerate(zip(k, a, refs)):
            for name, v, rv in zip(("fx", "fy", "mz"), (st.fx[i], st.fy[i], st.mz[i]), ref):
                out.append(Check(f"{name}-a{av / DEG:.0f}-k{kv:g}", f"complete model {name} at alpha = {av / DEG:.0f} deg, "
                                 f"kappa = {kv:g}, 4000 N (ISO; the reference's alpha = -{av / DEG:.0f} deg mirrored)",
                                 float(v), rv, 0.01, "N m" if name == "mz" else "N", f"{DOC} §11 (Fig. 10)"))
    return out


@register(
    "mcps-fig10", paper="MCPS", label="Fig. 10", study="mcps-fig10", order=100, checks=_fig10_checks,
    title="Stationary combined slip at 4000 N: side force and aligning torque against Fx",
    caption=_caption_fig10,
    paper_shows="Lateral force vs longitudinal force and aligning torque vs longitudinal force at 4000 N for small slip "
                "angles and slips, MCPS against PaMaF: similar Fy-Fx curves, clearly different Mz-Fx curves.",
)
def draw_fig10(result):
    d, fz = _first_load(result, "mcps-fig10", "combined")
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.6)
    alphas = sorted(d["alpha"].unique(), key=abs)
    for label, sel, style in _variants(d):
        ls = style["ls"] if label != "MF" else ":"
        for i, al in enumerate(alphas):
            g = d[sel & (d["alpha"] == al)].sort_values("kappa")
            lab = f"{label if label != 'MF' else _mf_label(result)}, alpha_s = {al / DEG:.3g} deg"
            kw = {"color": COLORS[i % len(COLORS)], "ls": ls, "lw": style["lw"]}
            a.plot(g["fx"], -g["fy"], label=lab, **kw)
            b.plot(g["fx"], g["mz"], **kw)
    finish(a, "Fx [N] (< 0 braking)", "side force -Fy [N]", "side force against Fx", legend=False)
    finish(b, "Fx [N] (< 0 braking)", "aligning torque Mz [N m]", "aligning torque against Fx", legend=False)
    h, lab = a.get_legend_handles_labels()
    fig.legend(h, lab, loc="outside lower center", ncol=3, fontsize=7, frameon=False)
    fig.suptitle(f"MCPS Fig. 10: combined slip at {fz:g} N, {_tire_name(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- Fig. 11


def _fig11_checks(result):
    p = result.payload["params"]
    out = []
    for fz in result.meta["loads"]:
        sti = p.stiffnesses(fz)
        for c in _carcasses(result):
            kf, kz = ("D_yphiF", "D_zphiF") if c == "complete" else ("D_yphi", "D_zphi")
            out.append(Check(f"fy-slope-{c}-{fz:g}", f"-dFy/dphi at phi = 0, {c} carcass, Fz = {fz:g} N, over the linear "
                             f"theory {kf}", -_slope(p, fz, "fy", 2, c, 1e-4) / sti[kf], 1.0, 1e-5, "-", f"{DOC} §6-§7"))
            out.append(Check(f"mz-slope-{c}-{fz:g}", f"-dMz/dphi at phi = 0, {c} carcass, Fz = {fz:g} N, over the linear "
                             f"theory {kz}", -_slope(p, fz, "mz", 2, c, 1e-4) / sti[kz], 1.0, 1e-5, "-", f"{DOC} §6-§7"))
    if _reference(result) and _load_present(result, 2000.0):
        sti = p.stiffnesses(2000.0)
        out.append(Check("D_yphi-2000", "curvature force stiffness of the solid carcass at 2000 N", sti["D_yphi"], 367.8,
                         0.1, "N m", f"{DOC} §11 (Fig. 11)"))
        out.append(Check("D_zphi-2000", "curvature torque stiffness of the solid carcass at 2000 N", sti["D_zphi"], 31.40,
                         0.01, "N m^2", f"{DOC} §11 (Fig. 11)"))
        st = _solve(p, 2000.0, [0.0], [0.0], [0.1], "rigid")
        out.append(Check("rigid-fy-0.1", "solid carcass Fy at phi = 0.1 1/m, 2000 N", float(st.fy[0]), -36.23, 0.01, "N",
                         f"{DOC} §11 (Fig. 11)"))
        out.append(Check("rigid-mz-0.1", "solid carcass Mz at phi = 0.1 1/m, 2000 N", float(st.mz[0]), -3.076, 0.001,
                         "N m", f"{DOC} §11 (Fig. 11)"))
    return out


@register(
    "mcps-fig11", paper="MCPS", label="Fig. 11", study="mcps-fig11", order=110, checks=_fig11_checks,
    title="Stationary curvature (yaw-rate) response at 2000 N",
    caption=_caption_fig11,
    paper_shows="Lateral force and self-aligning torque against the path curvature (ticks about 0-0.1 1/m) at 2000 N; "
                "PaMaF gives no such response.",
)
def draw_fig11(result):
    d, fz = _first_load(result, "mcps-fig11", "curvature")
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.4)
    for label, sel, style in _variants(d):
        g = d[sel].sort_values("phi")
        fy, mz = g["fy"].to_numpy(), g["mz"].to_numpy()
        if label == "MF":  # no curvature input: its response is zero; its zero-slip offset is not a response
            label = (f"{_mf_label(result)}: no curvature input, response 0\n(its offset at zero slip, Fy = {fy[0]:+.4g} N, "
                     f"Mz = {mz[0]:+.4g} N m, is not drawn)")
            fy, mz = fy - fy[0], mz - mz[0]
        a.plot(g["phi"], np.abs(fy), label=label, **style)
        b.plot(g["phi"], np.abs(mz), label=label, **style)
    finish(a, "path curvature phi [1/m]", "|Fy| [N]", "lateral force", legend=False)
    finish(b, "path curvature phi [1/m]", "|Mz| [N m]", "aligning torque", legend=False)
    _legend_below(fig, a, ncol=3)
    fig.suptitle(f"MCPS Fig. 11: curvature response at {fz:g} N, {_tire_name(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- calibration


def _calibration_checks(result):
    cal = result.meta.get("calibration")
    if not cal:
        return []
    out = []
    for g, r in cal["groups"].items():
        out.append(Check(f"{g}-improves", f"calibration of {g} does not raise the max gap to the Magic Formula "
                         "(after over before, at most 1)", r["max_gap"] / max(r["max_gap_before"], 1e-12), 1.0, 0.0, "-",
                         f"{DOC} §8", bound="max"))
    mf = result.meta["mf"]
    if mf["kind"] == "simple" and _reference(result) and "fx" in cal["groups"] and abs(cal["load"] - 4000.0) < 1e-9:
        r = cal["groups"]["fx"]
        out.append(Check("fx-max-gap", "max Fx gap after calibration against the simple-form fallback (at most 150 N; "
                         "about 120 N expected)", r["max_gap"], 150.0, 0.0, "N", f"{DOC} §11 (Fig. 7)", bound="max"))
        out.append(Check("mu_x-at-bound", "mu_x ends at its bound (1 = yes)", float(r["at_bound"]["mu_x"]), 1.0, 0.0, "-",
                         f"{DOC} §8"))
        out.append(Check("alpha_x-at-bound", "alpha_x ends at its bound (1 = yes)", float(r["at_bound"]["alpha_x"]), 1.0,
                         0.0, "-", f"{DOC} §8"))
    return out


@register(
    "mcps-calibration", paper="MCPS", label="calibration", study="mcps-calibration", order=120,
    checks=_calibration_checks,
    title="Calibration of the MCPS rubber parameters to a Magic Formula tyre",
    caption="Bounded least squares (docs/models/mcps_tire.md §8, procedure assumed): (r_x, mu_x, alpha_x, beta_x) on the Magic "
            "Formula Fx(kappa) at 40 slips in (0, 0.12], then (r_y, mu_y, alpha_y, beta_y) on Fy(alpha) over (0, 12 deg] "
            "(complete model), then c_Mz on Mz. The built-in study calibrates against the simple-form Magic Formula "
            "fallback (assumed B, C, D, E): mu_x and alpha_x end at their bounds and a gap of about 120 N (3 % of Fz) "
            "remains. A parameter at its bound is flagged; the fitted set is written as calibrated.yaml.",
    paper_shows="No paper figure: the paper states MCPS 'represents very well' the stationary curves of the Magic Formula; "
                "this card measures how well with the assumed parameters.",
)
def draw_calibration(result):
    from tirecli.errors import UsageError

    require(result, "mcps-stationary", "mcps-calibration")
    cal = result.meta.get("calibration")
    if not cal:
        raise UsageError("figure 'mcps-calibration' draws a run with 'calibrate: true'")
    rows = []
    for g, r in cal["groups"].items():
        for n, v in r["parameters"].items():
            lo, hi = r["bounds"][n]
            rows.append([g, n, f"{r['start'][n]:.6g}", f"{v:.6g}", f"[{lo:g}, {hi:g}]", "AT BOUND" if r["at_bound"][n] else ""])
        stage = "" if abs(r["max_gap_stage"] - r["max_gap"]) < 1e-6 * max(1.0, r["max_gap"]) else \
            f"{r['max_gap_stage']:.4g} right after this fit; c_Mz (fitted later) changes the belt twist"
        rows.append([g, f"max gap [{r['unit']}]", f"{r['max_gap_before']:.4g}", f"{r['max_gap']:.4g}", "", stage])
        rows.append([g, f"rms gap [{r['unit']}]", f"{r['rms_gap_before']:.4g}", f"{r['rms_gap']:.4g}", "", ""])
    return Table(columns=["fit", "parameter", "before", "final", "bounds", "status"], rows=rows,
                 notes=[f"Target: {cal['target']} at {cal['load']:g} N; model: MCPS {cal['carcass']} carcass; "
                        f"fits on {cal['grid']['kappa'][2]} points each."])


@register(
    "mcps-table", paper="MCPS", label="parameters", study="mcps-fig7-9", order=1,
    title="Default MCPS tire (all values assumed)",
    caption="The built-in set sorine2000-mcps: the paper gives the model's structure but no parameter values, so every "
            "value is a documented default (a 165/65R14-like passenger tire, docs/models/mcps_tire.md §9), overridable with "
            "--set tire.NAME=VALUE.",
    paper_shows="No parameter table: the MCPS paper prints no values.",
)
def draw_table(result):
    from tirecli.figures.steady import parameter_table

    return parameter_table(result.parameter_sets["tire"])


# --------------------------------------------------------------------------- Fig. 3 (slider)


def _fig3_checks(result):
    from tirecli.models.mcps.law import overshoot_peak

    f = result.meta["facts"]
    p = result.payload["params"]
    sc = result.meta["scenario"]
    out = []
    pk_path, pk = overshoot_peak(p.alpha_x, p.beta_x, f["K_N_per_m"], f["Fk_N"])
    if math.isfinite(pk_path) and f["amplitude_m"] > pk_path and not sc["frame_term"]:  # 1-D: no frame rotation
        out.append(Check("peak-closed-form", "first-loading force peak over the closed form g_max F_k", f["first_peak_force_N"] / (pk * f["Fk_N"]),
                         1.0, 1e-5, "-", f"{DOC} §3.2"))
    if "rate_independence_max_diff_N" in f:
        out.append(Check("rate-independence", "max |f(T) - f(T')| at equal phase (exact increments at T, time "
                         "integration at T')", f["rate_independence_max_diff_N"], 0.0, 1e-6, "N",
                         f"{DOC} §3.2 (rate independence)"))
    default = not sc["frame_term"] and abs(sc["pressure_Pa"] - 4000.0 / (0.13 * 0.14)) < 1e-6 and \
        abs(f["amplitude_m"] - 8 * f["Fk_N"] / f["K_N_per_m"]) < 1e-12
    if _reference(result) and default:
        out += [
            Check("peak-force", "first-loading force peak (4/3 F_k)", f["first_peak_force_N"], 26.37, 0.01, "N", f"{DOC} §11 (Fig. 3)"),
            Check("peak-path", "path of the force peak (4.394 F_k/K)", 1e3 * f["first_peak_path_m"], 17.38, 0.02, "mm", f"{DOC} §11 (Fig. 3)"),
            Check("peak-torque", "first-loading torque peak (4/3 M_kz)", f["first_peak_torque_Nm"], 0.2491, 1e-4, "N m", f"{DOC} §11 (Fig. 3)"),
            Check("peak-angle", "angle of the torque peak", f["first_peak_angle_rad"], 2.3455, 0.005, "rad", f"{DOC} §11 (Fig. 3)"),
            Check("last-max", "largest force of the last period", f["last_period_max_force_N"], 32.50, 0.01, "N", f"{DOC} §11 (Fig. 3)"),
            Check("last-min", "smallest force of the last period", f["last_period_min_force_N"], -32.50, 0.01, "N", f"{DOC} §11 (Fig. 3)"),
        ]
    return out


@register(
    "mcps-fig3", paper="MCPS", label="Fig. 3", study="mcps-fig3", order=30, checks=_fig3_checks,
    title="Rubber slider: friction force and torsional torque loops",
    caption=_caption_fig3,
    paper_shows="Friction force and torque of one rubber slider: hysteresis loops with overshoot (no scales legible).",
)
def draw_fig3(result):
    require(result, "mcps-slider", "mcps-fig3")
    df = result.data["slider"]
    f = result.meta["facts"]
    periods = result.payload["periods"]
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.4)
    for i, T in enumerate(periods):
        g = df[df["period"] == T]
        kw = {"color": COLORS[i], "ls": LINESTYLES[i % len(LINESTYLES)], "lw": 1.5 if i == 0 else 1.1}
        a.plot(1e3 * g["ux"], g["fx"], label=f"T = {T:g} s", **kw)
        b.plot(g["psi"], g["m"], label=f"T = {T:g} s", **kw)
    for ax, lev, lim in ((a, f["Fk_N"], f["reversal_limit_force_N"]), (b, f["Mkz_Nm"], None)):
        for s_ in (1, -1):
            ax.axhline(s_ * lev, color="#777777", lw=0.8, ls=":")
            if lim:
                ax.axhline(s_ * lim, color="#B00020", lw=0.6, ls=":")
    # one legend (the periods are the same in both panels), in the torque panel: the force panel's free corner
    # holds the red limit line
    finish(a, "displacement u_x [mm]", "friction force f_x [N]", "force (dotted: +-F_k; red: limit 5/3 F_k)",
           legend=False)
    finish(b, "rotation psi [rad]", "friction torque m [N m]", "torque (dotted: +-M_kz)")
    fig.suptitle(f"MCPS Fig. 3: one rubber slider, {_tire_name(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- Figs. 4-5 (standstill)


def _fig4_checks(result):
    f = result.meta["facts"]
    pay = result.payload
    fyg = pay["fy_grid"]
    odd = float(np.max(np.abs(fyg + fyg[:, ::-1])) / f["Fky_per_length_N_per_m"])
    out = [Check("odd", "max |f_y(xi) + f_y(-xi)| over F'_ky (the distribution is odd in xi)", odd, 0.0, 1e-9, "-",
                 f"{DOC} §11 (Fig. 4)")]
    sc = result.meta["scenario"]
    if _reference(result) and abs(sc["fz_N"] - 4000.0) < 1e-9 and sc["frame_term"]:
        out.append(Check("Fky", "F'_ky = mu_y P w", f["Fky_per_length_N_per_m"], 24286.0, 1.0, "N/m", f"{DOC} §11 (Fig. 4)"))
        out.append(Check("first-loading", "max |f_y|/F'_ky on first loading (4/3 without the frame term; the turning "
                         "frame lowers it to 1.327)", f["max_fy_first_loading_over_Fky"], 1.327, 0.002, "-",
                         f"{DOC} §11 (Fig. 4)"))
        A = sc["amplitude_rad"]
        ref = 1.59 if abs(A - 0.45) < 1e-8 else (1.63 if abs(A - math.pi / 4) < 1e-8 else None)
        if ref is not None:
            out.append(Check("first-cycle", f"max |f_y|/F'_ky over the first cycle (A = {sc['amplitude_rad']:.4g} rad)",
                             f["max_fy_first_cycle_over_Fky"], ref, 0.01, "-", f"{DOC} §11 (Fig. 4)"))
    return out


@register(
    "mcps-fig4", paper="MCPS", label="Fig. 4", study="mcps-fig4-5", order=40, checks=_fig4_checks,
    title="Lateral friction force distribution over the patch at standstill",
    caption=_caption_fig4,
    paper_shows="Surface plot of the lateral friction-force distribution over the patch against time, V = 0, |yaw rate| = "
                "1 rad/s.",
)
def draw_fig4(result):
    require(result, "mcps-standstill", "mcps-fig4")
    df = result.data["patch"]
    f = result.meta["facts"]
    Fk = f["Fky_per_length_N_per_m"]
    times = np.unique(df["t"].to_numpy())
    xi = np.unique(df["xi"].to_numpy())
    Z = df.sort_values(["t", "xi"])["fy"].to_numpy().reshape(times.size, xi.size) / 1e3
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11.0, 4.8))  # fixed layout: the constrained engine is slow with 3-D axes
    fig.subplots_adjust(left=0.02, right=0.98, bottom=0.2, top=0.88, wspace=0.12)
    ax3 = fig.add_subplot(1, 2, 1, projection="3d")
    X, Tm = np.meshgrid(1e3 * xi, times)
    ax3.plot_surface(X, Tm, Z, cmap="coolwarm", linewidth=0, antialiased=True, rcount=36, ccount=27, rasterized=True)
    ax3.set_xlabel("xi [mm]", fontsize=8)
    ax3.set_ylabel("t [s]", fontsize=8)
    ax3.set_zlabel("f_y [kN/m]", fontsize=8)
    ax3.tick_params(labelsize=7)
    ax3.view_init(elev=25, azim=-60)
    ax3.set_title("f_y(xi, t), road on tire", fontsize=10)
    ax = fig.add_subplot(1, 2, 2)
    ax.set_position([0.56, 0.2, 0.42, 0.66])
    st = result.data["standstill"]
    ends = st.groupby("leg")["t"].max().to_numpy()
    for i, te in enumerate(ends[:4]):
        k = int(np.argmin(np.abs(times - te)))
        ps = float(st["psi"].iloc[int(np.argmin(np.abs(st["t"].to_numpy() - te)))])
        ax.plot(1e3 * xi, Z[k] * 1e3 / Fk, color=COLORS[i % len(COLORS)], label=f"t = {te:.2f} s, psi = {ps:+.3g} rad")
    for lev in (4 / 3, 5 / 3):
        for s_ in (1, -1):
            ax.axhline(s_ * lev, color="#777777", lw=0.7, ls=":")
    finish(ax, "patch abscissa xi [mm] (forward)", "f_y / F'_ky [-]", "profiles at the reversals (dotted: 4/3, 5/3)",
           legend=False)
    _legend_below(fig, ax, ncol=2)
    fig.suptitle(f"MCPS Fig. 4: lateral friction force distribution at standstill, {_tire_name(result)}", fontsize=10)
    return fig


def _fig5_checks(result):
    f = result.meta["facts"]
    sc = result.meta["scenario"]
    out = [
        Check("C_z-secant", "secant yaw stiffness after 1 mrad over C_z of eq. (11)",
              f["C_z_secant_1mrad_Nm_per_rad"] / f["C_z_eq11_Nm_per_rad"], 1.0, 0.005, "-", f"{DOC} §5"),
        Check("Mz_inf-eq12", "asymptotic sliding torque without the frame term over eq. (12)",
              f["Mz_inf_no_frame_term_Nm"] / f["Mz_inf_eq12_Nm"], 1.0, 1e-9, "-", f"{DOC} §5"),
    ]
    if _reference(result) and abs(sc["fz_N"] - 4000.0) < 1e-9:
        on = sc["frame_term"]
        out += [
            Check("C_z", "small yaw stiffness C_z, eq. (11)", f["C_z_eq11_Nm_per_rad"], 1937.54, 0.01, "N m/rad", f"{DOC} §5"),
            Check("C_z-secant-value", "secant after 1 mrad from rest", f["C_z_secant_1mrad_Nm_per_rad"], 1932.08, 0.01,
                  "N m/rad", f"{DOC} §5"),
            Check("Mz_inf", "asymptotic torque, eq. (12)", f["Mz_inf_eq12_Nm"], 229.5, 0.001, "N m", f"{DOC} §5"),
            Check("Mz_inf-frame", "asymptotic torque with the frame term", f["Mz_inf_frame_term_Nm"], 249.995, 0.001, "N m",
                  f"{DOC} §5"),
        ]
        refs = (-18.837, -84.294, -147.330) if on else (-18.837, -84.311, -147.434)
        for (k, v), ref in zip(f["first_loading_mz_Nm"].items(), refs):
            out.append(Check(f"first-{k.split()[0]}", f"Mz on first loading at psi = {k}", v, ref, 0.001, "N m", f"{DOC} §5"))
        A = sc["amplitude_rad"]
        if on and abs(A - 0.45) < 1e-8:
            out += [Check("mz-minus-A", "Mz at psi = -0.45 rad (end of the second leg)", f["mz_at_minus_A_Nm"], 301.92, 0.01,
                          "N m", f"{DOC} §11 (Fig. 5)"),
                    Check("max-mz", "max |Mz| over the first cycle", f["max_abs_mz_first_cycle_Nm"], 329.28, 0.01, "N m",
                          f"{DOC} §11 (Fig. 5)"),
                    Check("max-mz-psi", "yaw angle of the max |Mz| (last leg)", f["psi_of_max_abs_mz_rad"], 0.14, 0.01, "rad",
                          f"{DOC} §11 (Fig. 5)")]
        if on and abs(A - math.pi / 4) < 1e-8:
            out += [Check("mz-minus-A", "Mz at psi = -pi/4", f["mz_at_minus_A_Nm"], 265.16, 0.01, "N m", f"{DOC} §11 (Fig. 5)"),
                    Check("max-mz", "max |Mz| over the first cycle", f["max_abs_mz_first_cycle_Nm"], 347.26, 0.01, "N m",
                          f"{DOC} §11 (Fig. 5)"),
                    Check("max-mz-psi", "yaw angle of the max |Mz|", f["psi_of_max_abs_mz_rad"], -0.23, 0.01, "rad",
                          f"{DOC} §11 (Fig. 5)")]
    if "loop_energy_previous_cycle_J" in f:
        out.append(Check("periodic", "energy of the last cycle over the previous one (the loop settles)",
                         f["loop_energy_last_cycle_J"] / f["loop_energy_previous_cycle_J"], 1.0, 0.02, "-",
                         f"{DOC} §11 (Fig. 5)"))
    return out


@register(
    "mcps-fig5", paper="MCPS", label="Fig. 5", study="mcps-fig4-5", order=50, checks=_fig5_checks,
    title="Tire torsional torque at standstill: Mz against the yaw angle",
    caption=_caption_fig5,
    paper_shows="Torsional torque against the yaw angle (rad, ticks -0.4 to 0.4): a hysteresis loop.",
)
def draw_fig5(result):
    require(result, "mcps-standstill", "mcps-fig5")
    st = result.data["standstill"]
    f = result.meta["facts"]
    fig, ax = new_figure(width=6.8, height=4.6)
    for c, g in st.groupby("cycle"):
        lo = g.index[0] - 1 if g.index[0] > 0 else g.index[0]
        g = st.loc[lo:g.index[-1]]
        ax.plot(g["psi"], g["mz"], color=COLORS[int(c) % len(COLORS)], lw=1.4,
                label="first loading" if c == 0 else f"cycle {int(c)}")
    A = result.meta["scenario"]["amplitude_rad"]
    ps = np.linspace(-0.15 * A, 0.15 * A, 3)
    ax.plot(ps, -f["C_z_eq11_Nm_per_rad"] * ps, color="#000000", ls="--", lw=0.9, label="slope -C_z (eq. 11)")
    for s_ in (1, -1):
        ax.axhline(s_ * f["Mz_inf_frame_term_Nm"], color="#777777", ls=":", lw=0.9)
        ax.axhline(s_ * f["Mz_inf_eq12_Nm"], color="#777777", ls="-.", lw=0.7)
    ax.plot([], [], color="#777777", ls=":", lw=0.9, label="+-asymptotic torque, frame term on")
    ax.plot([], [], color="#777777", ls="-.", lw=0.7, label="+-eq. (12), frame term off")
    finish(ax, "yaw angle psi [rad]", "aligning torque Mz [N m] (ISO, road on tire)",
           f"MCPS Fig. 5: torque at standstill, {_tire_name(result)}", legend=False)
    _legend_below(fig, ax, ncol=3)
    return fig


# --------------------------------------------------------------------------- relaxation


def _relaxation_checks(result):
    from tirecli.numerics.mcps_transient import rigid_relaxation_exact

    df = result.data["relaxation"]
    p = result.payload["params"]
    sc = result.meta["scenario"]
    out = []
    for case in result.meta["cases"]:
        lab = case["label"]
        f = result.meta["facts"][lab]
        g = df[df["case"] == lab]
        if case["carcass"] == "rigid":
            fy, _ = rigid_relaxation_exact(p, sc["fz_N"], sc["alpha_rad"], g["s"].to_numpy())
            out.append(Check(f"exact-{lab}", "max |Fy - exact characteristic solution| of the solid carcass",
                             float(np.max(np.abs(g["fy"].to_numpy() - fy))), 0.0, 0.05, "N", f"{DOC} §7"))
    ref = _reference(result) and abs(sc["fz_N"] - 4000.0) < 1e-9 and abs(sc["alpha_rad"] - DEG) < 1e-8 and sc["frame_term"]
    if ref:
        for case in result.meta["cases"]:
            lab, f = case["label"], result.meta["facts"][case["label"]]
            if case["carcass"] == "rigid":
                for k, r in (("s63_first_m", 0.051685), ("s95_first_m", 0.106260), ("s99_first_m", 0.124713)):
                    out.append(Check(f"{lab}-{k[1:3]}", f"solid carcass: rolled distance to {k[1:3]} % of Fy_inf", f[k] or float("nan"),
                                     r, 2e-4, "m", f"{DOC} §7 (exact by characteristics)"))
            elif abs(sc["speed_m_per_s"] - 20.0) < 1e-9 and not case["locked"]:
                g = df[df["case"] == lab]
                s, ratio = g["s"].to_numpy(), g["ratio"].to_numpy()
                early = s <= 0.13
                i = int(np.argmax(ratio[early]))
                dip = (s > 0.1) & (s < 0.3)
                j = int(np.argmin(ratio[dip]))
                if sc["distance_m"] >= 4.0:
                    out.append(Check(f"{lab}-steady", f"|Fy - Fy_inf| after {sc['distance_m']:g} m: the long-time transient "
                                     "tends to the stationary solution (MCPS eq. 18)", abs(f["final_fy_minus_fy_inf_N"]), 0.0,
                                     0.01, "N", f"{DOC} §7"))
                out += [Check(f"{lab}-hump", "first maximum of Fy/Fy_inf (belt modes), about 72 %", float(ratio[early][i]),
                              0.72, 0.01, "-", f"{DOC} §7"),
                        Check(f"{lab}-hump-s", "rolled distance of the first maximum", float(s[early][i]), 0.08, 0.01, "m", f"{DOC} §7"),
                        Check(f"{lab}-dip", "the dip of Fy/Fy_inf after it, about 25 %", float(ratio[dip][j]), 0.25, 0.01, "-", f"{DOC} §7"),
                        Check(f"{lab}-dip-s", "rolled distance of the dip", float(s[dip][j]), 0.19, 0.01, "m", f"{DOC} §7"),
                        Check(f"{lab}-95", "first rolled distance to 95 %", f["s95_first_m"] or float("nan"), 0.78, 0.01, "m", f"{DOC} §7")]
            elif abs(sc["speed_m_per_s"] - 20.0) < 1e-9 and case["locked"] == ["delta"]:
                out += [Check(f"{lab}-63", "twist locked: rolled distance to 63 %", f["s63_first_m"] or float("nan"), 0.309, 0.002,
                              "m", f"{DOC} §7"),
                        Check(f"{lab}-95", "twist locked: rolled distance to 95 %", f["s95_first_m"] or float("nan"), 0.933, 0.002,
                              "m", f"{DOC} §7")]
    return out


@register(
    "mcps-relaxation", paper="MCPS", label="relaxation", study="mcps-relaxation", order=130, checks=_relaxation_checks,
    title="Relaxation: side-force build-up over the rolled distance after a 1 deg slip-angle step",
    caption=_caption_relaxation,
    paper_shows="No paper figure: the paper states that MCPS reproduces relaxation-length behaviour.",
)
def draw_relaxation(result):
    require(result, "mcps-relaxation", "mcps-relaxation")
    df = result.data["relaxation"]
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.4)
    for i, case in enumerate(result.meta["cases"]):
        lab = case["label"]
        g = df[df["case"] == lab]
        kw = {"color": COLORS[i % len(COLORS)], "ls": LINESTYLES[i % len(LINESTYLES)], "lw": 1.4}
        a.plot(g["s"], g["ratio"], label=lab, **kw)
        b.plot(g["s"], g["mz"], label=lab, **kw)
        f = result.meta["facts"][lab]
        for k, mk in (("s63_first_m", "o"), ("s95_first_m", "s")):
            if f[k] is not None:
                a.plot([f[k]], [float(k[1:3]) / 100.0], marker=mk, color=kw["color"], ms=4, ls="none")
    for lev in (0.63, 0.95, 1.0):
        a.axhline(lev, color="#777777", lw=0.7, ls=":")
    sc = result.meta["scenario"]
    smax = min(float(df["s"].max()), 1.5)
    for ax in (a, b):
        ax.set_xlim(0, smax)
    finish(a, "rolled distance s [m]", "Fy / Fy_inf [-]", "side force (markers: first 63 % and 95 %)", legend=False)
    finish(b, "rolled distance s [m]", "Mz [N m] (ISO)", "aligning torque", legend=False)
    _legend_below(fig, a, ncol=4)
    fig.suptitle(f"MCPS relaxation: alpha = {sc['alpha_rad'] / DEG:.3g} deg at {sc['speed_m_per_s']:g} m/s, "
                 f"{_tire_name(result)}", fontsize=10)
    return fig


__all__ = ["require"]


# --------------------------------------------------------------------------- schematics (Figs. 1, 2, 6) as tables


@register(
    "mcps-fig1-2", paper="MCPS", label="Figs. 1-2", study="mcps-fig4-5", order=10,
    title="Rubber slider and contact patch: geometry and the quantities of the model",
    caption="The paper's Figs. 1 and 2 are drawings (a slider of area U with its frame R_D; the patch of length l and "
            "width w in the tire frame R_W with the rim's translation V and yaw rate). tirecli lists what they define, "
            "with the values of the run's tire at its load: patch, pressure, the slider of Fig. 3 and the per-length "
            "constants of the blocked-wheel model (docs/models/mcps_tire.md §1, §4, §5).",
    paper_shows="Fig. 1: rubber slider geometry and referential; Fig. 2: contact patch geometry and tire referential "
                "(schematics, no data).",
)
def draw_geometry(result):
    from tirecli.errors import UsageError

    if "params" not in (result.payload or {}) or "patch" not in (result.payload or {}):
        raise UsageError("figure 'mcps-fig1-2' draws an 'mcps-standstill' run (see 'tirecli figures list')")
    p, pa, law = result.payload["params"], result.payload["patch"], result.payload["law"]
    sl = p.slider_law(pa.P)
    rows = [
        ["F_z", f"{pa.fz:g}", "N", "vertical load"],
        ["l", f"{pa.l:.4g}", "m", "patch length along X_W (l_ref (F_z/fz_ref)^l_exponent)"],
        ["w", f"{pa.w:.4g}", "m", "patch width along Y_W"],
        ["P", f"{pa.P:.5g}", "Pa", "uniform contact pressure F_z/(w l)"],
        ["U", f"{p.U:.3g}", "m^2", "area of the slider of Fig. 3 (frame R_D)"],
        ["K_x, K_y", f"{sl.K[0]:.5g}, {sl.K[1]:.5g}", "N/m", "slider stiffness U r"],
        ["F_kx, F_ky", f"{sl.Fk[0]:.5g}, {sl.Fk[1]:.5g}", "N", "slider Coulomb levels P U mu"],
        ["S_z, M_kz", f"{sl.Sz:.4g}, {sl.Mkz:.4g}", "N m/rad, N m", "slider torsional stiffness and sliding torque"],
        ["K'_x, K'_y", f"{law.K[0]:.5g}, {law.K[1]:.5g}", "N/m^2", "patch stiffness per length w r"],
        ["F'_kx, F'_ky", f"{law.Fk[0]:.5g}, {law.Fk[1]:.5g}", "N/m", "patch Coulomb levels per length mu P w"],
        ["S'_z, M'_kz", f"{law.Sz:.5g}, {law.Mkz:.5g}", "N m/rad/m, N m/m", "torsion of a strip per length (eq. 11-12)"],
    ]
    return Table(columns=["symbol", "value", "unit", "meaning"], rows=rows,
                 notes=[f"Tire {_tire_name(result)}; ISO-W axes: X_W forward, Y_W left, Z_W up, origin at the patch centre."])


@register(
    "mcps-fig6", paper="MCPS", label="Fig. 6", study="mcps-relaxation", order=60,
    title="System with carcass flexibility: the belt's degrees of freedom",
    caption="The paper's Fig. 6 is a drawing of the belt on the rim: translations x, y and twist delta, each on a spring "
            "and a damper (MCPS eqs. 16-17). tirecli lists them with the run's values, the belt's natural frequencies "
            "on its springs alone and with the tread elements acting as springs to the road, and the damping ratios "
            "(docs/models/mcps_tire.md §7).",
    paper_shows="Fig. 6: the system with carcass flexibility (schematic, no data).",
)
def draw_belt(result):
    from tirecli.errors import UsageError
    from tirecli.numerics.mcps_transient import coupling_rate

    if result.study not in ("mcps-relaxation", "mcps-stationary") or "params" not in (result.payload or {}):
        raise UsageError("figure 'mcps-fig6' draws an 'mcps-relaxation' or 'mcps-stationary' run")
    p = result.payload["params"]
    fz = result.meta.get("scenario", {}).get("fz_N") or result.meta.get("loads", [4000.0])[0]
    pa, law, cz = p.patch(fz), p.patch_law(fz), p.stiffnesses(fz)["C_z"]
    rows = []
    for dof, m, k, c, kp, unit_k, unit_c in (
            ("x", p.m_b, p.k_x, p.c_x, law.K[0] * pa.l, "N/m", "N s/m"),
            ("y", p.m_b, p.k_y, p.c_y, law.K[1] * pa.l, "N/m", "N s/m"),
            ("delta", p.J_b, p.k_delta, p.c_delta, cz, "N m/rad", "N m s/rad")):
        rows.append([dof, f"{m:g}", f"{k:.4g} {unit_k}", f"{c:.4g} {unit_c}", f"{c / (2 * math.sqrt(k * m)):.3f}",
                     f"{math.sqrt(k / m):.1f}", f"{math.sqrt((k + kp) / m):.1f}"])
    return Table(columns=["DOF", "mass / inertia", "stiffness", "damping", "damping ratio",
                          "natural rate on the rim [rad/s]", "with the patch as a spring [rad/s]"], rows=rows,
                 notes=[f"Tire {_tire_name(result)} at {fz:g} N; the fastest rate ({coupling_rate(p, fz):.0f} rad/s) sets the "
                        "transport step of the relaxation runs (docs/models/mcps_tire.md §7)."])
