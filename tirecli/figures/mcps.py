"""MCPS figures (Sorine & Szymanski 2000): Figs. 3-5 and 7-11, the relaxation run, the calibration
and the parameter table (``docs/models/mcps_tire.md``).

Forces are computed in ISO-W, road on tire (:mod:`tirecli.models.mcps.tire`). The paper-style signs
are applied here, at the plotting step only (docs/models/mcps_tire.md §1): side force ``-Fy`` and
aligning torque ``+Mz`` against the slip angle ``alpha_s`` (equivalently ``Fy`` against
``-alpha_s``, the paper's "-delta" axis of Fig. 8); Fig. 10 draws the same ordinates against
``Fx``; Fig. 11 draws magnitudes. Slip angles are drawn in degrees, slips in percent.

Their reference checks (model checks against closed forms and linear stiffnesses, reference checks
against docs/models/mcps_tire.md §11) are in :mod:`tirecli.studies.checks.mcps`.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, LINESTYLES, MAX_COLUMNS, direct_labels, finish, new_figure, suptitle

DEG = math.pi / 180.0


def require(result, study: str, fid: str, family: str | None = None) -> None:
    """A UsageError unless ``result`` is a ``study`` run (holding ``family`` for stationary figures)."""
    from tirecli.errors import UsageError

    if result.study != study:
        raise UsageError(f"figure {fid!r} draws an '{study}' run, not a '{result.study}' run (see 'tirecli figures list')")
    if family is not None and family not in set(result.data["stationary"]["family"]):
        raise UsageError(f"figure {fid!r} draws the '{family}' family: add '{family}:' to the config")


def _reference(result) -> bool:
    from tirecli.studies.mcps.common import reference_tire

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
            "drawn): -Fy (top row) and Mz (bottom row) against Fx, paper-style signs, one column per model (shared "
            "ordinates), one colour per slip angle, named at the curve's end. The side force falls as |Fx| grows for both "
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
    return (f"Blocked wheel (V = 0, rigid belt; {_standstill_text(result)}; {_tire_text(result)}). Top: the lateral "
            "force density f_y(xi, t) of the road on the tire (ISO-W; odd in xi) as a map over the patch and time (the "
            "paper's surface seen from above; dotted: |f_y| = F'_ky); below: profiles at the yaw reversals over F'_ky "
            "(the lines of their colours on the map). Near the centre f_y grows with |xi| psi; the edges saturate "
            "first, with an overshoot on first loading (4/3 F'_ky without the frame term) and a larger one after each "
            "reversal (limit 5/3 F'_ky).")


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


@register(
    "mcps-fig7", paper="MCPS", label="Fig. 7", study="mcps-fig7-9", order=70,
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


@register(
    "mcps-fig8", paper="MCPS", label="Fig. 8", study="mcps-fig7-9", order=80,
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
    title="Stationary self-aligning torque: MCPS against the Magic Formula",
    caption=_caption_fig9,
    paper_shows="Self-aligning torque against the slip angle (axis 'delta (deg)', 0-12 deg), MCPS and PaMaF of similar shape.",
)
def draw_fig9(result):
    require(result, "mcps-stationary", "mcps-fig9", "alpha")
    return _curve_panels(result, "alpha", "alpha", lambda g: g["mz"], "slip angle alpha_s [deg]", "aligning torque Mz [N m]",
                         f"MCPS Fig. 9: stationary aligning torque, {_tire_name(result)}", x_scale=1.0 / DEG)


# --------------------------------------------------------------------------- Fig. 10


@register(
    "mcps-fig10", paper="MCPS", label="Fig. 10", study="mcps-fig10", order=100,
    title="Stationary combined slip at 4000 N: side force and aligning torque against Fx",
    caption=_caption_fig10,
    paper_shows="Lateral force vs longitudinal force and aligning torque vs longitudinal force at 4000 N for small slip "
                "angles and slips, MCPS against PaMaF: similar Fy-Fx curves, clearly different Mz-Fx curves.",
)
def draw_fig10(result):
    import textwrap

    d, fz = _first_load(result, "mcps-fig10", "combined")
    variants = _variants(d)
    # one column per model (at most MAX_COLUMNS, then a second block of rows), -Fy above Mz (the same scales
    # in every panel, so MCPS and the Magic Formula read across); one colour per slip angle, named at the
    # curve's driving end
    ncols = min(len(variants), MAX_COLUMNS)
    blocks = -(-len(variants) // ncols)
    fig, axes = new_figure(nrows=2 * blocks, ncols=ncols, width=3.7 * ncols + 0.6, height=3.6 * 2 * blocks)
    axes = np.asarray(axes).reshape(2 * blocks, ncols)
    alphas = sorted(d["alpha"].unique(), key=abs)
    colour = {al: COLORS[i % len(COLORS)] for i, al in enumerate(alphas)}
    ends = {}
    for j, (label, sel, style) in enumerate(variants):
        a, b = axes[2 * (j // ncols), j % ncols], axes[2 * (j // ncols) + 1, j % ncols]
        for al in alphas:
            g = d[sel & (d["alpha"] == al)].sort_values("kappa")
            kw = {"color": colour[al], "ls": style["ls"], "lw": style["lw"]}
            a.plot(g["fx"], -g["fy"], **kw)
            b.plot(g["fx"], g["mz"], **kw)
            last = g.iloc[-1]
            for ax, y in ((a, -last["fy"]), (b, last["mz"])):
                ends.setdefault(ax, []).append((last["fx"], y, f"{al / DEG:.3g} deg", colour[al]))
        name = _mf_label(result) if label == "MF" else label
        finish(a, "", "side force -Fy [N]" if j % ncols == 0 else "", "\n".join(textwrap.wrap(name, 38)), legend=False)
        finish(b, "Fx [N] (< 0 braking)", "aligning torque Mz [N m]" if j % ncols == 0 else "", legend=False)
        a.tick_params(labelbottom=False)
        if j % ncols:
            a.tick_params(labelleft=False)
            b.tick_params(labelleft=False)
    for ax in axes.ravel():
        ax.set_visible(ax in ends)
    lo, hi = float(d["fx"].min()), float(d["fx"].max())
    for row in range(2):
        panels = [ax for ax in axes[row::2].ravel() if ax in ends]
        ylo = min(ax.get_ylim()[0] for ax in panels)
        yhi = max(ax.get_ylim()[1] for ax in panels)
        for ax in panels:
            ax.set_xlim(lo - 0.04 * (hi - lo), hi + 0.2 * (hi - lo))  # room right of the curves for their names
            ax.set_ylim(ylo, yhi)
            direct_labels(ax, ends[ax])
    suptitle(fig, f"MCPS Fig. 10: combined slip at {fz:g} N, {_tire_name(result)}; families at constant slip angle "
                  "alpha_s (named at their ends)")
    return fig


# --------------------------------------------------------------------------- Fig. 11


@register(
    "mcps-fig11", paper="MCPS", label="Fig. 11", study="mcps-fig11", order=110,
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


@register(
    "mcps-calibration", paper="MCPS", label="calibration", study="mcps-calibration", order=120,
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


@register(
    "mcps-fig3", paper="MCPS", label="Fig. 3", study="mcps-fig3", order=30,
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


@register(
    "mcps-fig4", paper="MCPS", label="Fig. 4", study="mcps-fig4-5", order=40,
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
    # the paper's surface f_y(xi, t) as a map over the same plane (top), the profiles at the reversals
    # below it on the same xi axis; the reversal times are lines of the profiles' colours on the map
    fig, (a, b) = new_figure(nrows=2, width=6.8, height=8.2, sharex=True, height_ratios=(1.25, 1.0))
    lim = max(float(np.abs(Z).max()), 5.0 / 3.0 * Fk / 1e3)
    mesh = a.pcolormesh(1e3 * xi, times, Z, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest", rasterized=True)
    fig.colorbar(mesh, ax=a, label="f_y [kN/m]", pad=0.02)
    a.contour(1e3 * xi, times, Z, levels=[-Fk / 1e3, Fk / 1e3], colors="#000000", linewidths=0.7, linestyles=":")
    a.plot([], [], color="#000000", lw=0.7, ls=":", label="|f_y| = F'_ky (map)")
    st = result.data["standstill"]
    ends = st.groupby("leg")["t"].max().to_numpy()
    for i, te in enumerate(ends[:4]):
        k = int(np.argmin(np.abs(times - te)))
        ps = float(st["psi"].iloc[int(np.argmin(np.abs(st["t"].to_numpy() - te)))])
        col = COLORS[i % len(COLORS)]
        a.axhline(times[k], color=col, lw=1.4)
        b.plot(1e3 * xi, Z[k] * 1e3 / Fk, color=col, lw=1.5, label=f"t = {te:.2f} s, psi = {ps:+.3g} rad")
    for lev in (4 / 3, 5 / 3):
        for s_ in (1, -1):
            b.axhline(s_ * lev, color="#777777", lw=0.7, ls=":")
    finish(a, "", "time t [s]", "f_y(xi, t), road on tire (lines: the reversals drawn below)", legend=False)
    finish(b, "patch abscissa xi [mm] (forward)", "f_y / F'_ky [-]", "profiles at the reversals (dotted: 4/3, 5/3)",
           legend=False)
    a.grid(False)
    handles = b.get_legend_handles_labels()[0] + a.get_legend_handles_labels()[0]
    labels = b.get_legend_handles_labels()[1] + a.get_legend_handles_labels()[1]
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    suptitle(fig, f"MCPS Fig. 4: lateral friction force distribution at standstill, {_tire_name(result)}")
    return fig


@register(
    "mcps-fig5", paper="MCPS", label="Fig. 5", study="mcps-fig4-5", order=50,
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


@register(
    "mcps-relaxation", paper="MCPS", label="relaxation", study="mcps-relaxation", order=130,
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

    if result.study not in ("mcps-relaxation", "mcps-stationary") or "params" not in (result.payload or {}):
        raise UsageError("figure 'mcps-fig6' draws an 'mcps-relaxation' or 'mcps-stationary' run")
    p = result.payload["params"]
    fz = result.meta.get("scenario", {}).get("fz_N") or result.meta.get("loads", [4000.0])[0]
    pa, law, cz = p.patch(fz), p.patch_law(fz), p.stiffnesses(fz)["C_z"]
    rows, coupled = [], []
    for dof, m, k, c, kp, unit_k, unit_c in (
            ("x", p.m_b, p.k_x, p.c_x, law.K[0] * pa.l, "N/m", "N s/m"),
            ("y", p.m_b, p.k_y, p.c_y, law.K[1] * pa.l, "N/m", "N s/m"),
            ("delta", p.J_b, p.k_delta, p.c_delta, cz, "N m/rad", "N m s/rad")):
        coupled.append(math.sqrt((k + kp) / m))
        rows.append([dof, f"{m:g}", f"{k:.4g} {unit_k}", f"{c:.4g} {unit_c}", f"{c / (2 * math.sqrt(k * m)):.3f}",
                     f"{math.sqrt(k / m):.1f}", f"{coupled[-1]:.1f}"])
    # the fastest rate with the patch as a spring is tirecli.numerics.mcps_transient.coupling_rate (no DOF locked)
    return Table(columns=["DOF", "mass / inertia", "stiffness", "damping", "damping ratio",
                          "natural rate on the rim [rad/s]", "with the patch as a spring [rad/s]"], rows=rows,
                 notes=[f"Tire {_tire_name(result)} at {fz:g} N; the fastest rate ({max(coupled):.0f} rad/s) sets the "
                        "transport step of the relaxation runs (docs/models/mcps_tire.md §7)."])
