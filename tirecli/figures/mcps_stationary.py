"""MCPS Figs. 7-11 and the calibration card (Sorine & Szymanski 2000): the stationary MCPS tire against the
Magic Formula tyre drawn beside it (``docs/models/mcps_tire.md`` §8).

Every curve is a model's own ISO-W output (road on tire); the paper's style changes only the axes
(docs/models/mcps_tire.md §1): Fig. 8 draws ``Fy`` against ``-alpha_s`` at ``alpha_s <= 0`` (the paper's
"-delta" axis, a positive side force), Fig. 9 ``Mz`` against ``alpha_s`` at ``alpha_s >= 0``; no curve is
mirrored, so an asymmetric tyre shows its real offset. Fig. 10 draws ``-Fy`` and ``Mz`` against ``Fx`` at
``alpha_s > 0``; Fig. 11 magnitudes. Each MCPS curve's legend states its gap to the Magic Formula curve
(:mod:`tirecli.studies.mcps.gaps`, ``meta["gaps"]`` of the run). Their checks are in
:mod:`tirecli.studies.checks.mcps`.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.figures.mcps_common import legend_below, loads_text, default_tire, tire_name, tire_text, require
from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, MAX_COLUMNS, direct_labels, finish, new_figure, suptitle

DEG = math.pi / 180.0

# --------------------------------------------------------------------------- stationary curves


def _variants(df):
    """The curves of a stationary frame: ``(key, label, selection, style)`` for MCPS (each carcass,
    calibrated) and the Magic Formula; ``key`` names the curve in ``meta["gaps"]``."""
    from tirecli.studies.mcps.gaps import variant

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
        out.append((variant(model, carcass, bool(cal)), label, sel, style))
    return out


def _mf_label(result) -> str:
    return result.meta["mf"]["label"]


#: How a gap's abscissa is written, per figure.
_AT = {"mcps-fig7": lambda v: f"kappa {100 * v:.3g} %", "mcps-fig8": lambda v: f"{-v / DEG + 0.0:.3g} deg",
       "mcps-fig9": lambda v: f"{v / DEG:.3g} deg", "mcps-fig10": lambda v: f"Fx {v:.0f} N",
       "mcps-fig11": lambda v: f"{v:.3g} 1/m"}


def gap_text(f: dict, q: str, fid: str) -> str:
    """``max 1168 N at kappa 6.25 %, RMS 922 N`` of quantity ``q`` in one curve's gap facts."""
    from tirecli.studies.mcps.gaps import ABSCISSA, UNITS

    u = UNITS[q]
    unit = "N m" if u == "Nm" else "N"
    fmt = (lambda v: f"{v:.3g}") if q == "mz" or fid == "mcps-fig11" else (lambda v: f"{v:.0f}")
    return (f"max {fmt(f[f'{q}_max_{u}'])} {unit} at {_AT[fid](f[f'{q}_at_{ABSCISSA[fid][1]}'])}, "
            f"RMS {fmt(f[f'{q}_rms_{u}'])} {unit}")


def _gaps_of(result, fid, fz) -> dict:
    return ((result.meta.get("gaps") or {}).get(fid) or {}).get(f"{fz:g} N") or {}


def _curve_panels(result, fid, x_col, y_fn, xlabel, ylabel, title, x_fn=lambda x: x):
    """One panel per load (three per row), one legend below the panels; each MCPS curve's label (one load)
    or a note in its panel (several loads) states its gap to the Magic Formula curve."""
    from tirecli.studies.mcps.gaps import FIGURES, drawn

    family, (q,) = FIGURES[fid]
    df = result.data["stationary"]
    d = df[df["family"] == family]
    loads = sorted(d["fz"].unique())
    ncols = min(len(loads), 3)
    nrows = -(-len(loads) // 3)
    fig, axes = new_figure(ncols=ncols, nrows=nrows, width=6.8 if ncols == 1 else 4.2 * ncols, height=4.4 + 3.4 * (nrows - 1))
    axes = np.atleast_1d(axes).ravel()
    for ax, fz in zip(axes, loads):
        dl = drawn(d[d["fz"] == fz], fid)
        gaps = _gaps_of(result, fid, fz)
        notes = []
        for key, label, sel, style in _variants(dl):
            g = dl[sel].sort_values(x_col)
            if key == "mf":
                label = _mf_label(result)
            elif key in gaps:
                notes.append(f"{label}: {gap_text(gaps[key], q, fid)}")
                if len(loads) == 1:
                    label = f"{label}; gap to MF: {gap_text(gaps[key], q, fid)}"
            ax.plot(x_fn(g[x_col].to_numpy()), y_fn(g), label=label, **style)
        finish(ax, xlabel, ylabel, f"Fz = {fz:g} N" if len(loads) > 1 else None, legend=False)
        if len(loads) > 1 and notes:
            ax.text(0.02, 0.02, "gap to MF:\n" + "\n".join(notes), transform=ax.transAxes, fontsize=6.5, va="bottom")
    for ax in axes[len(loads):]:
        ax.set_visible(False)
    legend_below(fig, axes[0], ncol=1 if len(loads) == 1 else 2)
    fig.suptitle(title, fontsize=10)
    return fig, axes


def _first_load(result, fid, family):
    """The rows of ``family`` at the run's first load (figures drawn at one load): ``(frame, fz)``."""
    require(result, "mcps-stationary", fid, family)
    df = result.data["stationary"]
    d = df[df["family"] == family]
    fz = sorted(d["fz"].unique())[0]
    return d[d["fz"] == fz], fz


# --------------------------------------------------------------------------- captions (describe the run at hand)

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


_NAMES = {"complete": "complete model", "rigid": "solid carcass", "calibrated": "calibrated MCPS"}


def _gaps_sentence(result, fid) -> str:
    """The stated gaps of a figure, in words (every load, every MCPS curve)."""
    from tirecli.studies.mcps.gaps import FIGURES

    gaps = (result.meta.get("gaps") or {}).get(fid) if result is not None else None
    if not gaps:
        return ("Each MCPS curve's legend states its gap to the Magic Formula curve: the largest absolute gap, where, "
                "and the RMS over the drawn points (run.json meta.gaps).")
    parts = []
    for load, curves in gaps.items():
        for key, f in curves.items():
            if fid == "mcps-fig10":
                for al, fa in f.items():
                    parts.append(f"{_NAMES.get(key, key)} at {load}, {al}: " + "; ".join(
                        f"{'-Fy' if q == 'fy' else 'Mz'} {gap_text(fa, q, fid)}" for q in FIGURES[fid][1]
                        if f"{q}_points" in fa))
            else:
                parts.append(f"{_NAMES.get(key, key)} at {load}: " + "; ".join(
                    f"{q.capitalize() if fid != 'mcps-fig11' else '|' + q.capitalize() + '|'} {gap_text(f, q, fid)}"
                    for q in FIGURES[fid][1]))
    return "Gaps to the Magic Formula curve over the drawn points: " + "; ".join(parts) + "."


def _cal_text(result) -> str:
    cal = result.meta.get("calibration") if result is not None else None
    if not cal:
        return ""
    bounds = ", ".join(f"{n} at its {cal['fitted'][n]['at_bound']} bound {cal['fitted'][n][cal['fitted'][n]['at_bound']]:g}"
                       for n in cal["at_bound"])
    return (f" The calibrated curve is the set of the calibration card (mcps-calibration, fitted to this tyre at "
            f"{cal['load']:g} N on the drawn points" + (f"; {bounds}" if bounds else "") + ").")


def _caption_fig7(result):
    return (f"Fx against the longitudinal slip kappa (ISO-W, road on tire) at {loads_text(result)}, alpha = 0: MCPS with "
            f"{tire_text(result)}, {_models_text(result)}; and {_mf_text(result)}. In pure longitudinal slip the complete "
            f"model and the solid carcass coincide exactly. {_gaps_sentence(result, 'mcps-fig7')} The default tire's "
            "slip stiffness (63 700 N) is below the stand-in's (86 750 N) and MCPS is still rising at 12 %; the "
            "calibrated set trades a slip stiffness 30 % too high against a level that bends over too slowly, since a "
            "patch mean of a Dahl response cannot bend over as sharply as a Magic Formula curve (docs/models/mcps_tire.md "
            f"§8).{_cal_text(result)}")


def _caption_fig8(result):
    return (f"Side force Fy against -alpha_s at {loads_text(result)}, kappa = 0, in the paper's style: its axis "
            "'-delta' is -alpha_s, so each model's own ISO-W Fy is drawn at the negative slip angles (alpha_s <= 0), where "
            "it is positive; no curve is mirrored, so an asymmetric tyre shows its real offset (the stand-in gives "
            f"Fy = +69.9 N at zero slip, MCPS exactly 0). MCPS with {tire_text(result)}: {_models_text(result)}; and "
            f"{_mf_text(result)}. {_gaps_sentence(result, 'mcps-fig8')} The belt twist lowers the cornering stiffness "
            "of the complete model below the solid carcass's (eq. 20; 36 910 against 44 590 N/rad for the default tire "
            f"at 4000 N; the stand-in has 53 330 N/rad).{_cal_text(result)}")


def _caption_fig9(result):
    feats = ((result.meta.get("mz_features") or {}) if result is not None else {})
    peaks = ""
    if feats:
        load, per = next(iter(feats.items()))
        txt = []
        for key, f in per.items():
            name = "Magic Formula" if key == "mf" else _NAMES.get(key, key)
            sc = (f", changes sign at {f['sign_change_rad'] / DEG:.2f} deg" if f["sign_change_rad"] is not None
                  else ", keeps its sign over the drawn range")
            txt.append(f"{name} {f['peak_Nm']:.3g} N m at {f['peak_rad'] / DEG:.2f} deg{sc}")
        peaks = f" Peaks at {load} (markers): " + "; ".join(txt) + "."
    return (f"Aligning torque Mz (ISO-W, not negated) against the slip angle alpha_s >= 0 (the paper's 'delta') at "
            f"{loads_text(result)}, kappa = 0. MCPS with {tire_text(result)}: {_models_text(result)}; and "
            f"{_mf_text(result)} (Mz of its combined-slip formula at kappa = 0). {_gaps_sentence(result, 'mcps-fig9')}"
            f"{peaks} The shapes differ: the Magic Formula's trail function (QCZ1 > 1) and residual torque make its Mz "
            "change sign inside the drawn range (dotted line); MCPS has neither, its torque is the lever-arm moment of "
            "a force distribution under a uniform, centred pressure, which turns negative only late and shallow through "
            "the overshoot of the friction law, so the largest gap is past the Magic Formula's sign change. The twist "
            f"lowers the aligning stiffness (eq. 20).{_cal_text(result)}")


def _caption_fig10(result):
    if result is None or result.payload is None or "checked" not in result.payload:
        fam = "alpha_s = 1, 2, 4 deg with kappa swept from -0.1 (braking) to +0.1 (driving)"
    else:
        comb = result.payload["checked"]["combined"] or {"alpha": [], "kappa": [0.0]}
        al = ", ".join(f"{a / DEG:.3g}" for a in comb["alpha"])
        fam = f"alpha_s = {al} deg with kappa swept from {min(comb['kappa']):g} to {max(comb['kappa']):g}"
    return (f"Families at constant slip angle, {fam} [assumed scenario], at {loads_text(result)} (the first load is "
            "drawn): -Fy (top row) and Mz (bottom row) against Fx, paper-style signs, one column per model (shared "
            "ordinates), one colour per slip angle, named at the curve's end. The side force falls as |Fx| grows for both "
            "models. The aligning torque differs: in MCPS (complete model) braking drives Mz towards 0 while driving keeps "
            "it large, through the belt offsets in MW = MA + x FAy - y FAx (eq. 16); the solid carcass gives a nearly "
            f"symmetric curve. Magic Formula side: {_mf_text(result)}; its combined-slip rules do not describe this "
            f"influence of Fx on Mz. {_gaps_sentence(result, 'mcps-fig10')}")


def _caption_fig11(result):
    return (f"|Fy| (left) and |Mz| (right) produced by path curvature alone (Vy = 0, Vx = r omega, yaw rate = phi Vx; "
            f"both negative in ISO for phi > 0, magnitudes drawn [assumed]) at {loads_text(result, '2000 N')} (the first "
            f"load is drawn). MCPS with {tire_text(result)}: {_models_text(result)}, the lateral slip varying along "
            "the patch, frame-rotation term off: nearly linear; the belt twist raises |Fy| and lowers |Mz|. A Magic "
            "Formula without turn slip has no curvature input: its response is zero (its constant output at zero slip, a "
            "conicity/ply-steer offset, is not a curvature response and is given in the legend). "
            f"{_gaps_sentence(result, 'mcps-fig11')}")



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
    return _curve_panels(result, "mcps-fig7", "kappa", lambda g: g["fx"], "longitudinal slip kappa [%]",
                         "Fx [N] (ISO-W, road on tire)", f"MCPS Fig. 7: stationary Fx, {tire_name(result)}",
                         x_fn=lambda x: 100.0 * x)[0]


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
    fig, axes = _curve_panels(result, "mcps-fig8", "alpha", lambda g: g["fy"], "slip angle -alpha_s [deg] (the paper's -delta)",
                              "side force Fy [N] (ISO-W, road on tire)",
                              f"MCPS Fig. 8: stationary side force, {tire_name(result)}", x_fn=lambda x: -x / DEG)
    for ax in axes:
        if ax.get_visible():
            ax.axhline(0.0, color="#999999", lw=0.6)
    return fig


@register(
    "mcps-fig9", paper="MCPS", label="Fig. 9", study="mcps-fig7-9", order=90,
    title="Stationary self-aligning torque: MCPS against the Magic Formula",
    caption=_caption_fig9,
    paper_shows="Self-aligning torque against the slip angle (axis 'delta (deg)', 0-12 deg), MCPS and PaMaF of similar shape.",
)
def draw_fig9(result):
    require(result, "mcps-stationary", "mcps-fig9", "alpha")
    fig, axes = _curve_panels(result, "mcps-fig9", "alpha", lambda g: g["mz"], "slip angle alpha_s [deg] (the paper's delta)",
                              "aligning torque Mz [N m] (ISO-W, road on tire)",
                              f"MCPS Fig. 9: stationary aligning torque, {tire_name(result)}", x_fn=lambda x: x / DEG)
    d = result.data["stationary"]
    loads = sorted(d[d["family"] == "alpha"]["fz"].unique())
    feats = result.meta.get("mz_features") or {}
    for ax, fz in zip(axes, loads):  # the peaks (markers) and the Magic Formula's sign change MCPS cannot follow
        ax.axhline(0.0, color="#999999", lw=0.6)
        for key, label, sel, style in _variants(d[(d["family"] == "alpha") & (d["fz"] == fz)]):
            f = (feats.get(f"{fz:g} N") or {}).get(key)
            if not f:
                continue
            ax.plot([f["peak_rad"] / DEG], [f["peak_Nm"]], marker="o", ms=4.5, color=style["color"], ls="none")
            if key == "mf" and f["sign_change_rad"] is not None:
                x0 = f["sign_change_rad"] / DEG
                ax.axvline(x0, color="#000000", lw=0.8, ls=":")
                ax.annotate(f"MF Mz changes sign at {x0:.2f} deg:\nMCPS cannot follow (no residual torque,\n"
                            "uniform pressure: no negative trail)", xy=(x0, 0.0), xytext=(0.04, 0.06),
                            textcoords="axes fraction", ha="left", va="bottom", fontsize=7,
                            arrowprops={"arrowstyle": "->", "lw": 0.6, "color": "#444444"})
    axes[0].plot([], [], marker="o", ms=4.5, color="#555555", ls="none", label="peak of each curve")
    for lg in fig.legends:
        lg.remove()
    legend_below(fig, axes[0], ncol=1 if len(loads) == 1 else 2)
    return fig


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
    gaps = _gaps_of(result, "mcps-fig10", fz)
    for j, (key, label, sel, style) in enumerate(variants):
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
        worst = {}
        for q in ("fy", "mz"):  # the largest gap over the slip angles, against the Magic Formula column
            rows = [(fa[f"{q}_max_{'Nm' if q == 'mz' else 'N'}"], al, fa) for al, fa in (gaps.get(key) or {}).items()
                    if f"{q}_points" in fa]
            if rows:
                worst[q] = max(rows, key=lambda r: r[0])
        sub = {q: f"\ngap to MF: max {w[0]:.3g} {'N m' if q == 'mz' else 'N'} ({w[1]}, Fx {w[2][q + '_at_fx_N']:.0f} N)"
               for q, w in worst.items()}
        finish(a, "", "side force -Fy [N] (ISO Fy negated)" if j % ncols == 0 else "",
               "\n".join(textwrap.wrap(name, 38)) + sub.get("fy", ""), legend=False)
        finish(b, "Fx [N] (< 0 braking)", "aligning torque Mz [N m]" if j % ncols == 0 else "", sub.get("mz", "")[1:] or None,
               legend=False)
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
    suptitle(fig, f"MCPS Fig. 10: combined slip at {fz:g} N, {tire_name(result)}; families at constant slip angle "
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
    gaps = _gaps_of(result, "mcps-fig11", fz)
    for key, label, sel, style in _variants(d):
        g = d[sel].sort_values("phi")
        if key in gaps:
            label = (f"{label}; gap to the MF line: |Fy| {gap_text(gaps[key], 'fy', 'mcps-fig11')},\n"
                     f"|Mz| {gap_text(gaps[key], 'mz', 'mcps-fig11')}")
        fy, mz = g["fy"].to_numpy(), g["mz"].to_numpy()
        if key == "mf":  # no curvature input: its response is zero; its zero-slip offset is not a response
            label = (f"{_mf_label(result)}: no curvature input, response 0\n(its offset at zero slip, Fy = {fy[0]:+.4g} N, "
                     f"Mz = {mz[0]:+.4g} N m, is not drawn)")
            fy, mz = fy - fy[0], mz - mz[0]
        a.plot(g["phi"], np.abs(fy), label=label, **style)
        b.plot(g["phi"], np.abs(mz), label=label, **style)
    finish(a, "path curvature phi [1/m]", "|Fy| [N]", "lateral force", legend=False)
    finish(b, "path curvature phi [1/m]", "|Mz| [N m]", "aligning torque", legend=False)
    legend_below(fig, a, ncol=1)
    fig.suptitle(f"MCPS Fig. 11: curvature response at {fz:g} N, {tire_name(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- calibration


def _caption_calibration(result):
    cal = result.meta.get("calibration") if result is not None else None
    text = ("One calibration, to the Magic Formula tyre drawn beside MCPS, on the drawn points (docs/models/mcps_tire.md "
            "§8, procedure assumed): bounded least squares of (r_x, mu_x, alpha_x, beta_x) on Fx(kappa) of Fig. 7, then one "
            "joint fit of (r_y, mu_y, alpha_y, beta_y, c_Mz, k_delta) on Fy of Fig. 8 (alpha_s <= 0) and Mz of Fig. 9 "
            "(alpha_s >= 0, weight 0.1, up to the Magic Formula's sign change of Mz): the trail factor c_Mz and the belt "
            "twist k_delta shape Mz. Each model's own output, never a mirrored curve. The calibrated curves of Figs. 7-10 "
            "are this set; it is written as calibrated.yaml. Targets: Fx and Fy within 5 % of the Magic Formula peak, "
            "the Mz peak within 1 deg.")
    if not cal:
        return text
    g = cal["gaps"]["calibrated"]
    pk = cal["peaks"]
    dpk = (pk["calibrated"]["alpha"] - pk["mf"]["alpha"]) / DEG

    def ok(c):
        return "met" if g[c]["max_rel"] <= 0.05 else "NOT met"

    bounds = "; ".join(f"{n} = {cal['fitted'][n]['value']:.4g} at its {cal['fitted'][n]['at_bound']} bound "
                       f"({cal['fitted'][n]['bound_source']})" for n in cal["at_bound"]) or "none"
    sc = cal["sign_change"]
    sign = ""
    if sc.get("mf") is not None:
        beyond = sc.get("beyond") or {}
        sign = (f" The Magic Formula's Mz changes sign at {sc['mf'] / DEG:.2f} deg; the calibrated MCPS "
                + (f"at {sc['calibrated'] / DEG:.2f} deg" if sc.get("calibrated") is not None else
                   "keeps its sign over the drawn range")
                + (f", and the Mz gap past the sign change reaches {beyond['max']:.3g} N m (RMS {beyond['rms']:.3g} N m)"
                   if beyond else "") + ": MCPS has no residual torque and a uniform, centred pressure, so it cannot "
                "follow this (docs/models/mcps_tire.md §8).")
    return (text + f" Result against {cal['target']} at {cal['load']:g} N: Fx {g['fx']['max']:.4g} N "
            f"({100 * g['fx']['max_rel']:.2f} % of the peak, target {ok('fx')}); Fy {g['fy']['max']:.4g} N "
            f"({100 * g['fy']['max_rel']:.2f} %, target {ok('fy')}); Mz {g['mz']['max']:.4g} N m "
            f"({100 * g['mz']['max_rel']:.1f} % of its peak); Mz peak {pk['calibrated']['mz']:.4g} N m at "
            f"{pk['calibrated']['alpha'] / DEG:.2f} deg against the Magic Formula's {pk['mf']['mz']:.4g} N m at "
            f"{pk['mf']['alpha'] / DEG:.2f} deg ({dpk:+.2f} deg, target {'met' if abs(dpk) <= 1 else 'NOT met'}). "
            f"Parameters at a bound: {bounds}.{sign}")


@register(
    "mcps-calibration", paper="MCPS", label="calibration", study="mcps-calibration", order=120,
    title="Calibration of MCPS to the Magic Formula tyre drawn beside it",
    caption=_caption_calibration,
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
    for n, f in cal["fitted"].items():
        near = min(f["value"] - f["lower"], f["upper"] - f["value"]) <= 1e-3 * (f["upper"] - f["lower"])
        status = (f"AT {f['at_bound'].upper()} BOUND ({f['bound_source']})" if f["at_bound"] else
                  "within 0.1 % of its bound range" if near else "")
        rows.append(["parameter", n, f"{f['start']:.6g}", f"{f['value']:.6g}", f"[{f['lower']:g}, {f['upper']:g}]", status])
    unit = {"fx": "N", "fy": "N", "mz": "N m"}
    where = {"fx": lambda v: f"kappa {100 * v:.3g} %", "fy": lambda v: f"alpha {v / DEG + 0.0:.3g} deg",
             "mz": lambda v: f"alpha {v / DEG:.3g} deg"}
    for c in ("fx", "fy", "mz"):
        a, b = cal["gaps"]["start"][c], cal["gaps"]["calibrated"][c]
        rows.append(["gap", f"{c} max [{unit[c]}]", f"{a['max']:.4g} ({where[c](a['at'])})",
                     f"{b['max']:.4g} ({where[c](b['at'])})", "", f"{100 * b['max_rel']:.3g} % of the MF peak {b['peak']:.4g}"])
        rows.append(["gap", f"{c} RMS [{unit[c]}]", f"{a['rms']:.4g}", f"{b['rms']:.4g}", "", f"{100 * b['rms_rel']:.3g} %"])
    pk, sc = cal["peaks"], cal["sign_change"]
    rows.append(["Mz peak", "MF", "", f"{pk['mf']['mz']:.4g} N m at {pk['mf']['alpha'] / DEG:.2f} deg", "", ""])
    rows.append(["Mz peak", "MCPS", f"{pk['start']['mz']:.4g} N m at {pk['start']['alpha'] / DEG:.2f} deg",
                 f"{pk['calibrated']['mz']:.4g} N m at {pk['calibrated']['alpha'] / DEG:.2f} deg", "",
                 f"{(pk['calibrated']['alpha'] - pk['mf']['alpha']) / DEG:+.2f} deg from the MF peak"])

    def fmt(v):
        return "none in the drawn range" if v is None else f"{v / DEG:.2f} deg"

    rows.append(["Mz sign change", "MCPS", fmt(sc.get("start")), fmt(sc.get("calibrated")), "",
                 f"MF: {fmt(sc.get('mf'))}; Mz fitted up to {sc['fitted_up_to'] / DEG:.2f} deg"])
    g = cal["grids"]
    return Table(columns=["what", "name", "default (start)", "calibrated", "bounds", "status"], rows=rows,
                 notes=[f"Target: {cal['target']} at {cal['load']:g} N; model: MCPS {cal['carcass']} carcass; drawn points: "
                        f"kappa {g['kappa']['start']:g}..{g['kappa']['stop']:g} ({g['kappa']['points']}), Fy at alpha "
                        f"{g['alpha_fy']['start'] / DEG:.3g}..{g['alpha_fy']['stop'] / DEG:.3g} deg ({g['alpha_fy']['points']}), "
                        f"Mz at alpha {g['alpha']['start'] / DEG:.3g}..{g['alpha']['stop'] / DEG:.3g} deg ({g['alpha']['points']}); "
                        "gaps are MCPS minus the Magic Formula, each model's own ISO-W output."])
