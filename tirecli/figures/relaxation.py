"""The relaxation comparison (study ``relaxation``): the transient Magic Formula, MCPS and the distributed
LuGre tire after a slip-ratio step and a slip-angle step, each normalised by its own steady state, against
the rolled distance; the 63 % and 95 % distances marked on the curves and tabulated on the card."""
from __future__ import annotations

import math

import numpy as np

from tirecli.figures.registry import Table, register, with_table
from tirecli.figures.style import COLORS, LINESTYLES, finish, new_figure, suptitle

DEG = math.pi / 180.0
#: Model label in the study's frames -> (legend label, colour, line style).
MODELS = {
    "mf": ("transient Magic Formula", COLORS[0], LINESTYLES[0]),
    "mcps-rigid": ("MCPS, solid carcass", COLORS[1], LINESTYLES[1]),
    "mcps-complete": ("MCPS, complete carcass", COLORS[2], LINESTYLES[2]),
    "lugre": ("LuGre, distributed", COLORS[3], LINESTYLES[3]),
}
#: Rolled distance of the zoomed panels [m].
ZOOM = 0.4


def _require(result):
    from tirecli.errors import UsageError

    if result.study != "relaxation":
        raise UsageError("figure 'relaxation-compare' draws a 'relaxation' run (see 'tirecli figures list')")


def _fmt(v, unit=" m") -> str:
    """A distance, or "not reached"."""
    return "not reached" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.3g}{unit}"


def _marks(ax, s, ratio, f, color):
    """Filled markers where the response first reaches 63.2 % (circle) and 95 % (square); open markers
    where it settles within 1 +- 36.8 % / 5 % when that is later (a response that starts above the level
    or overshoots)."""
    for key, mk in (("63", "o"), ("95", "s")):
        first, settled = f[f"s{key}_m"], f[f"s{key}_settled_m"]
        if first:
            ax.plot([first], [np.interp(first, s, ratio)], marker=mk, color=color, ms=5, ls="none", zorder=5)
        if settled and (first is None or settled > first + 1e-9):
            ax.plot([settled], [np.interp(settled, s, ratio)], marker=mk, mfc="white", mec=color, ms=5, ls="none",
                    zorder=5)


def _table(result) -> Table:
    facts = result.meta["facts"]
    rows = []
    for step, name in (("kappa", "Fx, slip-ratio step"), ("alpha", "Fy, slip-angle step")):
        for model, f in facts[step].items():
            gap = "" if model == "mf" else (f"{_fmt(f['gap_s63_m'])} / {_fmt(f['gap_s95_m'])}; "
                                            f"max {f['gap_max']:.3f} at {f['gap_at_m']:.3g} m, RMS {f['gap_rms']:.3f}")
            rows.append([name, MODELS[model][0], f"{f['steady_N']:.5g}", _fmt(f["s63_m"]), _fmt(f["s95_m"]),
                         f"{_fmt(f['s63_settled_m'])} / {_fmt(f['s95_settled_m'])}", f"{f['peak_ratio']:.3f}", gap])
    mf = result.meta["mf"]
    notes = [f"Magic Formula {mf['name']}: relaxation lengths sigma_kappa = {facts['kappa']['mf']['sigma_m']:.4g} m, "
             f"sigma_alpha = {facts['alpha']['mf']['sigma_m']:.4g} m from {mf['sigma_note']} "
             "(docs/models/magic_formula_tyre.md §17.2).",
             "First: where the normalised force first reaches 63.2 % or 95 %; settled: from where on it stays within "
             "36.8 % or 5 % of its steady state. Gaps: distance minus the Magic Formula's (63 % / 95 %), and the "
             "largest and RMS difference of the normalised forces over the drawn distance."]
    return Table(columns=["step", "model", "steady force [N]", "63 % [m]", "95 % [m]", "settled 63 / 95 % [m]",
                          "peak / steady [-]", "gap to the Magic Formula [m; -]"], rows=rows, notes=notes)


def _caption(result=None) -> str:
    base = ("After a step of the slip ratio (top two panels: Fx) and of the slip angle (bottom two: Fy) at constant "
            "speed and load, each model's force normalised by its own steady state, (F - F_start)/(F_steady - F_start), "
            "against the distance rolled by the wheel centre; the second panel of each step zooms into the first "
            f"{ZOOM:g} m. Filled markers: first 63.2 % (circle) and 95 % (square); open markers: where the response "
            "settles within 36.8 % / 5 % when that is later. Grey dashes: the Magic Formula's slip state, the first-order "
            "lag 1 - exp(-s/sigma). The distributed LuGre tire is longitudinal only (docs/models/magic_formula_tyre.md §18.1).")
    if result is None or result.study != "relaxation":
        return base
    f = result.meta["facts"]
    k, a = f["kappa"], f["alpha"]
    parts = [f"Here the transient Magic Formula reaches 95 % of Fx at {_fmt(k['mf']['s95_m'], ' m')} and of Fy at "
             f"{_fmt(a['mf']['s95_m'], ' m')}"]
    for model in ("mcps-rigid", "mcps-complete"):
        if model in k:
            parts.append(f"{MODELS[model][0]} at {_fmt(k[model]['s95_m'])} and {_fmt(a[model]['s95_m'])}")
    text = base + " " + "; ".join(parts) + "."
    if "lugre" in k:
        lg = k["lugre"]
        text += (f" LuGre starts at {lg['start_ratio']:.2f} of its steady state at once (its damping terms "
                 f"(sigma1 + sigma2) vr), peaks at {lg['peak_ratio']:.2f} and is steady after one patch transit "
                 f"({lg['transit_m']:.3g} m); it settles within 5 % at {_fmt(lg['s95_settled_m'])}.")
    return text


@register(
    "relaxation-compare", paper="MF", label="relaxation", study="relaxation", order=900,
    title="Relaxation side by side: transient Magic Formula, MCPS and LuGre after a slip step",
    caption=_caption,
    paper_shows="No paper figure: the comparison users make most, the force building up over the rolled distance "
                "after a slip step.",
)
def draw_relaxation_compare(result):
    _require(result)
    df = result.data["relaxation"]
    facts, sc = result.meta["facts"], result.meta["scenario"]
    fig, axes = new_figure(nrows=4, width=5.6, height=10.8)
    reach = max((f["s95_settled_m"] or 0.0) for st in facts.values() for f in st.values())
    smax = min(float(df["s"].max()), max(1.15 * reach, 2 * ZOOM))
    titles = {"kappa": f"slip-ratio step kappa = {sc['kappa']:g}: Fx", "alpha": f"slip-angle step alpha = "
              f"{sc['alpha_rad'] / DEG:.3g} deg: Fy"}
    for row, step in enumerate(("kappa", "alpha")):
        g = df[df["step"] == step]
        for col, (ax, right) in enumerate(((axes[2 * row], smax), (axes[2 * row + 1], ZOOM))):
            for model in facts[step]:
                h = g[g["model"] == model]
                lab, color, ls = MODELS[model]
                s, ratio = h["s"].to_numpy(), h["ratio"].to_numpy()
                ax.plot(s, ratio, color=color, ls=ls, lw=1.5, label=lab)
                _marks(ax, s, ratio, facts[step][model], color)
                if model == "mf":
                    ax.plot(s, h["slip_state"].to_numpy() / (sc["kappa"] if step == "kappa" else sc["alpha_rad"]),
                            color="0.55", ls=(0, (2, 2)), lw=0.9, label="first-order lag 1 - exp(-s/sigma)")
            for lev in (1.0 - math.exp(-1.0), 0.95, 1.0, 1.05):
                ax.axhline(lev, color="#777777", lw=0.6, ls=":")
            ax.set_xlim(0, right)
            top = max(1.1, 1.05 * float(g["ratio"].max()))
            ax.set_ylim(min(-0.05, float(g["ratio"].min()) - 0.05), top)
            finish(ax, "rolled distance s [m]", "(F - F0)/(F_steady - F0) [-]",
                   titles[step] + ("" if col == 0 else f" (first {ZOOM:g} m)"), legend=False)
    h, lab = axes[0].get_legend_handles_labels()
    fig.legend(h, lab, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    mf = result.meta["mf"]
    suptitle(fig, f"{sc['speed_m_per_s']:g} m/s, {sc['fz_N']:g} N; Magic Formula {mf['name']}")
    return with_table(fig, _table(result))


__all__ = ["draw_relaxation_compare", "MODELS"]
