"""Magic Formula figures: pure-slip families, camber, combined slip, the LuGre comparison, one
overview card per built-in tyre and one card per golden-data block (docs/models/magic_formula_tyre.md).

Curves are drawn in ISO-W (§2.2): a positive slip angle gives a negative side force and, at
small angles, a positive aligning moment. The comparison with LuGre uses ``|mu|`` against
``|s|`` (the LuGre slip of :mod:`tirecli.conventions`), so signs do not matter there.
"""
from __future__ import annotations

import numpy as np

from tirecli.figures.registry import register
from tirecli.figures.style import COLORS, LINESTYLES, finish, new_figure

ISO = " (ISO-W)"


def require_mf(result, fid: str, frame: str = "sweep", column: str = "family", what: str | None = None) -> None:
    """A UsageError unless ``result`` holds the Magic Formula frame this figure draws."""
    from tirecli.errors import UsageError

    df = result.data.get(frame)
    if df is None or column not in df.columns:
        need = what or "a Magic Formula sweep (a 'sweep' config whose tire: is a Magic Formula tyre)"
        raise UsageError(f"figure {fid!r} draws {need}, not this '{result.study}' run (see 'tirecli figures list')")


def _fam(df, family):
    return df[df["family"] == family]


def _by(df, key):
    for i, (val, d) in enumerate(df.groupby(key, sort=True)):
        yield i, val, d


def _plot_family(ax, df, family, x, y, key, label_fmt):
    d = _fam(df, family)
    for i, val, g in _by(d, key):
        g = g.sort_values(x)
        ax.plot(g[x], g[y], color=COLORS[i % len(COLORS)], ls=LINESTYLES[(i // len(COLORS)) % len(LINESTYLES)],
                label=label_fmt.format(val))


def _title(result, what):
    name = result.parameter_sets["tire"].name
    return f"{what}: {name} ({result.meta.get('convention', 'mfeval')})"


def draw_fx_kappa(ax, result):
    """Fx [N] against kappa [-], one curve per load (family ``fx-kappa``)."""
    _plot_family(ax, result.data["sweep"], "fx-kappa", "kappa", "fx", "fz", "Fz = {:g} N")
    finish(ax, "longitudinal slip kappa [-]", "Fx [N]" + ISO, _title(result, "Fx vs kappa"))


def draw_fy_alpha(ax, result):
    """Fy [N] against alpha [rad], one curve per load (family ``fy-alpha``)."""
    _plot_family(ax, result.data["sweep"], "fy-alpha", "alpha", "fy", "fz", "Fz = {:g} N")
    # ISO-W: Fy > 0 for alpha < 0, so the lower left stays free of curves
    finish(ax, "slip angle alpha [rad]", "Fy [N]" + ISO, _title(result, "Fy vs alpha"), loc="lower left")


def draw_mz_alpha(ax, result):
    """Mz [N m] against alpha [rad], one curve per load (family ``fy-alpha``)."""
    _plot_family(ax, result.data["sweep"], "fy-alpha", "alpha", "mz", "fz", "Fz = {:g} N")
    finish(ax, "slip angle alpha [rad]", "Mz [N m]" + ISO, _title(result, "Mz vs alpha"))


def draw_camber(axes, result):
    """Fy [N] and Mz [N m] against alpha [rad], one curve per camber [rad] (family ``camber``)."""
    df = result.data["sweep"]
    fz = _fam(df, "camber")["fz"].iloc[0] if len(_fam(df, "camber")) else float("nan")
    for k, (ax, y, lab) in enumerate(zip(axes, ("fy", "mz"), ("Fy [N]", "Mz [N m]"))):
        _plot_family(ax, df, "camber", "alpha", y, "gamma", "{:g}")
        # one narrow legend (the values under a title) for both panels, in the lower left of Fy (ISO-W: Fy > 0
        # for alpha < 0; the Mz curves fill every corner)
        finish(ax, "slip angle alpha [rad]", lab + ISO,
               f"camber family at Fz = {fz:g} N" + (" (legend at left)" if k else ""), legend=not k, loc="lower left",
               legend_title="camber gamma [rad]")


def draw_combined(axes, result):
    """Fy against Fx [N]: kappa swept at fixed alpha (left), alpha swept at fixed kappa (right)."""
    df = result.data["sweep"]
    a, b = axes
    d = _fam(df, "combined-alpha")
    for i, val, g in _by(d, "alpha"):
        g = g.sort_values("kappa")
        a.plot(g["fx"], g["fy"], color=COLORS[i % len(COLORS)], label=f"alpha = {val:g} rad\n(kappa swept)")
    finish(a, "Fx [N]" + ISO, "Fy [N]" + ISO, "combined slip: fixed alpha", outside=True)
    d = _fam(df, "combined-kappa")
    for i, val, g in _by(d, "kappa"):
        g = g.sort_values("alpha")
        b.plot(g["fx"], g["fy"], color=COLORS[i % len(COLORS)], label=f"kappa = {val:g}\n(alpha swept)")
    finish(b, "Fx [N]" + ISO, "Fy [N]" + ISO, "combined slip: fixed kappa", outside=True)


def _figure_of(fid, draw, ncols=1):
    """A figure function drawing ``draw(ax_or_axes, result)`` on one panel or a row of ``ncols``."""

    def fig(result):
        require_mf(result, fid)
        f, axes = new_figure(ncols=ncols, width=6.4 if ncols == 1 else 11.0, height=4.2)
        draw(axes, result)
        return f

    return fig


for _id, _title_text, _caption, _draw, _ncols in (
    ("mf-fx-kappa", "Magic Formula Fx vs kappa at several loads",
     "Longitudinal force against the practical slip kappa (ISO-W, > 0 driving) at alpha = gamma = 0, one curve "
     "per load.", draw_fx_kappa, 1),
    ("mf-fy-alpha", "Magic Formula Fy vs alpha at several loads",
     "Lateral force against the slip angle at kappa = gamma = 0, one curve per load; ISO-W signs (alpha > 0 gives "
     "Fy < 0).", draw_fy_alpha, 1),
    ("mf-mz-alpha", "Magic Formula Mz vs alpha at several loads",
     "Aligning moment (combined-slip formula of docs/models/magic_formula_tyre.md §6.3 at kappa = 0) against the slip angle, one curve per load; "
     "ISO-W signs.", draw_mz_alpha, 1),
    ("mf-camber", "Magic Formula camber family",
     "Fy and Mz against the slip angle for several inclination angles at one load (kappa = 0).", draw_camber, 2),
    ("mf-combined", "Magic Formula combined slip (Fx-Fy)",
     "Fy against Fx under combined slip at one load: kappa swept at fixed slip angles (left) and alpha swept at "
     "fixed slips (right); the weighting functions G_xa, G_yk of docs/models/magic_formula_tyre.md §6.", draw_combined, 2),
):
    register(_id, paper="generic", label="MF sweep", title=_title_text, caption=_caption)(_figure_of(_id, _draw, _ncols))


# --------------------------------------------------------------------------- LuGre vs MF


@register(
    "mf-lugre-compare", paper="MF", label="LuGre vs MF", study="mf-lugre-compare", order=5,
    title="Steady-state LuGre (FM Table 1) and a Magic Formula tyre on one |mu| - |s| plot",
    caption="Braking and driving friction |mu| = |F|/F_n against the slip |s| (s = vr / max(v, r omega), "
            "tirecli.conventions): the distributed LuGre steady state (uniform load, FM Table 1, held speed) "
            "and the Magic Formula pure longitudinal force Fx/Fz at one load on the same slip grid (kappa = "
            "kappa_from_slip(s)). The built-in comparison turns input clipping off (limits: false), since the "
            "file's KPUMAX would flatten the driving branch; with limits on, the title says so. "
            "The Magic Formula curve does not depend on speed; LuGre's falls with speed (Stribeck). The legend "
            "states each LuGre curve's gap to the Magic Formula curve of its direction (largest |mu| difference, "
            "the |s| where it occurs, RMS over the drawn points; also run.json facts gap.*): the two models are "
            "different tyres on different data, so the gap measures how far apart they are, not an error.",
    paper_shows="No paper figure: the comparison the MCPS paper makes between a dynamic friction model and the "
                "Magic Formula, drawn with the tyres available here (docs/models/magic_formula_tyre.md §16).",
)
def fig_lugre_compare(result):
    """|mu| [-] against |s| [-]: the Magic Formula ``compare`` family and the LuGre frame."""
    require_mf(result, "mf-lugre-compare", "lugre", "mu", "a Magic Formula sweep with a 'compare:' block")
    fig, ax = new_figure()
    d = _fam(result.data["sweep"], "compare")
    name = result.parameter_sets["tire"].name
    for i, (direction, sel) in enumerate((("braking", d["kappa"] <= 0), ("driving", d["kappa"] >= 0))):
        g = d[sel].assign(s=np.abs(d["slip"]), m=np.abs(d["mu_x"])).sort_values("s")
        ax.plot(g["s"], g["m"], color=COLORS[0], ls=LINESTYLES[i],
                label=f"Magic Formula {name}, Fz = {g['fz'].iloc[0]:g} N ({direction})")
    lu = result.data["lugre"]
    lname = result.parameter_sets["lugre"].name
    for i, direction in enumerate(("braking", "driving")):
        g = lu[lu["direction"] == direction]
        g = g.assign(s=np.abs(g["slip"]), m=np.abs(g["mu"])).sort_values("s")
        if len(g):
            gap = (result.meta.get("facts") or {}).get("gap", {}).get(direction)
            note = (f"\n  gap to MF: max {gap['max']:.3f} at |s| = {gap['at']:.3g}, RMS {gap['rms']:.3f}"
                    if gap else "")
            ax.plot(g["s"], g["m"], color=COLORS[1], ls=LINESTYLES[i],
                    label=f"LuGre {lname}, {g['speed'].iloc[0]:g} m/s ({direction}){note}")
    title = "LuGre and Magic Formula steady states"
    if result.meta.get("limits", True):
        title += "\n(Magic Formula inputs clipped to the file's ranges: limits on)"
    finish(ax, "slip |s| [-]", "friction |mu| = |F|/F_n [-]", title)
    ax.set_xlim(0, 1)
    ax.set_ylim(bottom=0)
    return fig


# --------------------------------------------------------------------------- built-in tyre cards


def draw_overview(result):
    """Six panels: Fx-kappa, Fy-alpha, Mz-alpha at several loads; camber Fy, Mz; combined Fx-Fy."""
    require_mf(result, "mf-tire-*")
    fig, axes = new_figure(ncols=3, nrows=2, width=12.5, height=7.6)
    draw_fx_kappa(axes[0, 0], result)
    draw_fy_alpha(axes[0, 1], result)
    draw_mz_alpha(axes[0, 2], result)
    draw_camber(axes[1, :2], result)
    d = _fam(result.data["sweep"], "combined-alpha")
    ax = axes[1, 2]
    for i, val, g in _by(d, "alpha"):
        g = g.sort_values("kappa")
        ax.plot(g["fx"], g["fy"], color=COLORS[i % len(COLORS)], label=f"alpha = {val:g} rad")
    finish(ax, "Fx [N]" + ISO, "Fy [N]" + ISO, "combined slip, kappa swept", outside=True)
    for a in axes.ravel():
        a.title.set_fontsize(9)
    return fig


def _register_tire_cards():
    from tirecli.parameters.mf import BUILTIN_TIRES

    for i, (name, meta) in enumerate(sorted(BUILTIN_TIRES.items())):
        register(
            f"mf-tire-{name}", paper="MF", label=f"built-in tyre {name}", study=f"mf-sweep-{name}", order=20 + i,
            title=f"Sweeps of the built-in tyre {name}",
            caption=f"{meta['title']}. Fx against kappa, Fy and Mz against alpha at 0.5, 1 and 1.5 x FNOMIN; Fy and "
                    "Mz for a camber family; combined-slip Fx-Fy at fixed slip angles (mfeval convention, ISO-W). "
                    f"Source: {meta['citation']}; licence {meta['licence']}.",
            paper_shows="Reference facts instead of a paper figure: the slopes at zero slip equal the stiffnesses "
                        "K_xk and K_ya, the curves pass through (-S_H, S_V), outputs are finite"
                        + (", and the derived values of docs/models/magic_formula_tyre.md §15.5." if name == "pacejka2006-205-60r15" else "."),
        )(draw_overview)


_register_tire_cards()


# --------------------------------------------------------------------------- golden-data cards


def _golden_block(result, block):
    df = result.data["golden"]
    return df[df["block"] == block]


def _draw_golden(block):
    from tirecli.studies.mf_golden import OUTPUTS, TOLERANCE

    def draw(result):
        require_mf(result, f"mf-golden-{block}", "golden", "block", "the golden-data study (built-in config mf-golden)")
        d = _golden_block(result, block)
        fig, ax = new_figure(width=7.0, height=3.8)
        x = d["row"].to_numpy()
        for i, c in enumerate(OUTPUTS):
            r = np.abs(d[f"{c}_residual"].to_numpy())
            ax.semilogy(x + (i - 2) * 0.08, np.maximum(r, 1e-16), "o", ms=4, color=COLORS[i % len(COLORS)],
                        label=c.replace("f", "F").replace("m", "M"))
        ax.axhline(TOLERANCE, color="k", ls="--", lw=1, label=f"tolerance {TOLERANCE:g}")
        ax.set_ylim(1e-17, 1e-2)  # two decades above the tolerance line hold the legend, clear of the points
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        finish(ax, f"row number [-] in {block}.csv (docs/models/magic_formula_tyre.md §15.4)", "|tirecli - golden| [N, N m] (zero shown at 1e-16)",
               f"golden rows {block}: {result.meta.get('convention')} convention", ncol=6, loc="upper center")
        return fig

    return draw


def _register_golden_cards():
    from tirecli.studies.mf_golden import BLOCK_TITLES, GOLDEN

    for i, block in enumerate(GOLDEN):
        register(
            f"mf-golden-{block.replace('_', '-')}", paper="MF", label=f"golden data {block}", study="mf-golden",
            order=10 + i, title=f"Golden rows, {BLOCK_TITLES[block]}",
            caption=f"The rows of {block}.csv quoted in docs/models/magic_formula_tyre.md §15.4 (Pacejka 2006 Table A3.1 tyre, teasit "
                    "magic-formula-tyre-library under GNU Octave, via KMoula30/outlap), evaluated with the teasit "
                    "convention: absolute residual of every output per row against the 1e-6 print precision.",
            paper_shows="The public MF 6.1 golden values (docs/models/magic_formula_tyre.md §15.1-15.4): Fx, Fy, Mz, Mx, My printed to 1e-6.",
        )(_draw_golden(block))


_register_golden_cards()
