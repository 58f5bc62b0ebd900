"""Steady-state friction figures: FM Fig. 1, OBS Fig. 1, FM Fig. 6 surface, FM Table 1, generic sweeps."""
from __future__ import annotations

import numpy as np

from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, LINESTYLES, figure, finish, legend_room, new_figure, readable_3d
from tirecli.studies.sweep_curves import curve, curve_peak, first_model

#: Caption sentence of the peak markers.
PEAK_CAPTION = (" Circles: each curve's peak, root-found on the model (not the grid), value in the legend "
                "(data/peaks.csv).")


def curve_groups(df, keys) -> list:
    """The distinct ``keys`` tuples of a sweep frame's rows, in order of first appearance (as
    ``df.groupby(keys, sort=False).groups``): taken at the rows where a key changes (a sweep's rows run
    curve by curve), so a large sweep is not hashed row by row."""
    change = np.zeros(len(df), dtype=bool)
    change[:1] = True
    for k in keys:
        col = df[k]
        change[1:] |= (col.to_numpy()[1:] != col.to_numpy()[:-1]) if col.dtype.kind == "f" else \
            col.ne(col.shift()).to_numpy(dtype=bool)[1:]
    starts = df.loc[change, keys]
    return list(dict.fromkeys(tuple(row) for row in starts.itertuples(index=False, name=None)))


#: Points drawn of one curve at most (a figure is about 800 pixels wide); denser curves are thinned.
_MAX_DRAWN = 4000


def drawn(s, mu):
    """``(s, mu)`` thinned to about :data:`_MAX_DRAWN` points for drawing (every k-th point, the last
    and the largest ``mu`` kept); the curve's data and peak are not changed."""
    n = len(s)
    if n <= _MAX_DRAWN:
        return s, mu
    keep = np.zeros(n, dtype=bool)
    keep[::-(-n // _MAX_DRAWN)] = True
    keep[[n - 1, int(np.argmax(mu))]] = True
    return s[keep], mu[keep]


def peak_text(pk) -> str:
    """``peak 1.055 at |s| = 0.212`` (legend text of a curve's peak; empty without one)."""
    if pk is None or not np.isfinite(pk[0]):
        return ""
    return f"peak {pk[1]:.4f} at |s| = {pk[0]:.3f}"


def mark_peak(ax, pk, color, xmax=1.0, **kw):
    """A marker at a curve's root-found peak ``pk = (|s|, |mu|, ...)`` when it lies in ``[0, xmax]``."""
    if pk is None or not np.isfinite(pk[0]) or pk[0] > xmax + 1e-12:
        return
    style = {"marker": "o", "ms": 5, "mfc": "white", "mew": 1.3, "ls": "none", "zorder": 4} | kw
    ax.plot([pk[0]], [pk[1]], color=color, **style)


def peak_handle():
    """Legend entry of the peak markers."""
    from matplotlib.lines import Line2D

    return Line2D([], [], marker="o", ms=5, mfc="white", mew=1.3, color="0.3", ls="none",
                  label="peak of each curve (root-found, data/peaks.csv)")


def _with_peak_legend(ax, below: bool = False, **kw):
    """The curves' legend with the peak marker's entry; ``below``: under the axes, off the curves."""
    handles, labels = ax.get_legend_handles_labels()
    h = peak_handle()
    if below:
        ax.figure.legend(handles + [h], labels + [h.get_label()], fontsize=8, loc="outside lower center", ncol=2,
                         frameon=False, **kw)
    else:
        ax.legend(handles + [h], labels + [h.get_label()], fontsize=8, **kw)


def _tire_label(result) -> str:
    """The tire set a figure draws, with its changed parameters (``canudas2003-table1 (sigma0 changed)``)."""
    return result.parameter_sets["tire"].label


# --------------------------------------------------------------------------- generic


def _legend_label(parts: dict, varying: set) -> str:
    names = {"model": "{}", "speed": "v = {:g} m/s", "theta": "theta = {:g}"}
    return ", ".join(names[k].format(v) for k, v in parts.items() if k in varying) or "mu"


@register("sweep-mu-slip", paper="generic", label="sweep", title="Friction vs slip",
          caption="Steady-state |mu| against |s| for every model, speed and adhesion of the sweep; "
                  "braking solid, driving dashed. The held speed is v when braking and r*omega when driving. "
                  "Circles: each curve's peak, root-found on the model (not the grid); with few curves the legend "
                  "gives its value (every peak is in data/peaks.csv).")
def draw_sweep_mu_slip(result):
    df = result.data["sweep"]
    keys = ["model", "speed", "theta"]
    groups = curve_groups(df, keys)
    varying = [k for i, k in enumerate(keys) if len({g[i] for g in groups}) > 1]
    title = result.meta.get("title") or "Steady-state friction"
    if len(groups) * df["direction"].nunique() > _FEW_CURVES:  # legend entries
        return _sweep_many_curves(result, df, groups, varying, title)
    fig, ax = new_figure()
    for i, (model, speed, theta) in enumerate(groups):
        for direction, ls in (("braking", "-"), ("driving", "--")):
            s, mu = curve(df, model, speed, theta, direction)
            if len(s) == 0:
                continue
            lab = _legend_label({"model": model, "speed": speed, "theta": theta}, set(varying))
            if df["direction"].nunique() > 1:
                lab += f" ({direction})"
            pk = curve_peak(result, model, speed, theta, direction)
            if peak_text(pk):
                lab += f": {peak_text(pk)}"
            ax.plot(*drawn(s, mu), ls, color=COLORS[i % len(COLORS)], label=lab)
            mark_peak(ax, pk, COLORS[i % len(COLORS)], xmax=s.max())
    finish(ax, "slip |s| [-]", "friction |mu| = |F|/F_n [-]", title, legend=False)
    _with_peak_legend(ax)
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    return fig


#: Above this many curves (model, speed, theta, direction) the generic sweep figure draws a panel per
#: direction and colours by a colour map (with a colour bar) instead of listing every curve in a legend.
_FEW_CURVES = 8
_KEY_LABELS = {"speed": "held speed [m/s]", "theta": "theta (FM convention) [-]", "model": "model"}


def _sweep_many_curves(result, df, groups, varying, title):
    """The generic sweep figure for many curves: one panel per direction, colour = the key with the
    most values (colour bar), line style = the other varying keys (a short legend)."""
    import matplotlib as mpl

    directions = [d for d in ("braking", "driving") if (df["direction"] == d).any()]
    numeric = [k for k in ("speed", "theta") if k in varying]
    c_key = max(numeric, key=lambda k: df[k].nunique()) if numeric else "model"
    others = [k for k in varying if k != c_key]
    fig, axes = new_figure(ncols=len(directions), width=5.2 * len(directions) + 1.2, sharey=True)
    axes = np.atleast_1d(axes)
    if c_key == "model":
        cvals = list(dict.fromkeys(g[0] for g in groups))
        colour = ({v: COLORS[i] for i, v in enumerate(cvals)} if len(cvals) <= len(COLORS) else
                  {v: mpl.colormaps["viridis"](i / max(len(cvals) - 1, 1)) for i, v in enumerate(cvals)})
        norm = None
    else:
        cvals = sorted({g[keys_index(c_key)] for g in groups})
        norm = mpl.colors.Normalize(vmin=min(cvals), vmax=max(cvals))
        colour = {v: mpl.colormaps["viridis"](norm(v)) for v in cvals}
    combos = list(dict.fromkeys(tuple(g[keys_index(k)] for k in others) for g in groups))
    style = {c: _DASHES[i % len(_DASHES)] for i, c in enumerate(combos)}
    for ax, direction in zip(axes, directions):
        for g in groups:
            s, mu = curve(df, *g, direction)
            if len(s):
                ax.plot(*drawn(s, mu), ls=style[tuple(g[keys_index(k)] for k in others)], lw=1.0,
                        color=colour[g[keys_index(c_key)]])
                mark_peak(ax, curve_peak(result, *g, direction), colour[g[keys_index(c_key)]], xmax=s.max(),
                          ms=3.5, mew=1.0)
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        finish(ax, "slip |s| [-]", "friction |mu| = |F|/F_n [-]" if ax is axes[0] else "",
               f"{title} ({direction})" if len(directions) > 1 else title, legend=False)
    pk_handle = peak_handle()
    if others and len(combos) > 1:
        shown = combos[: len(_DASHES)]
        handles = [mpl.lines.Line2D([], [], color="0.3", ls=style[c]) for c in shown]
        labels = [_legend_label(dict(zip(others, c)), set(others)) for c in shown]
        if len(combos) > len(shown):
            handles.append(mpl.lines.Line2D([], [], color="none"))
            labels.append(f"... {len(combos) - len(shown)} more, styles repeat (see data/sweep.csv)")
        axes[0].legend([pk_handle] + handles, [pk_handle.get_label()] + labels, fontsize=7, loc="lower right")
    elif norm is not None:
        axes[0].legend([pk_handle], [pk_handle.get_label()], fontsize=7, loc="lower right")
    if norm is not None:
        fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=list(axes), label=_KEY_LABELS[c_key])
    else:
        handles = [mpl.lines.Line2D([], [], color=colour[v]) for v in cvals[:10]]
        labels = list(cvals[:10])
        if len(cvals) > 10:
            handles.append(mpl.lines.Line2D([], [], color="none"))
            labels.append(f"... {len(cvals) - 10} more (see data/sweep.csv)")
        if not (others and len(combos) > 1):
            handles.append(pk_handle)
            labels.append(pk_handle.get_label())
        axes[-1].legend(handles, labels, fontsize=7)
    return fig


#: Line styles of the generic many-curves figure: eight distinct dash patterns.
_DASHES = ["-", "--", "-.", ":", (0, (5, 1)), (0, (1, 3)), (0, (8, 2, 1, 2, 1, 2)), (0, (3, 3))]


def keys_index(key: str) -> int:
    """Position of ``key`` in the (model, speed, theta) group tuples of the generic sweep figure."""
    return ("model", "speed", "theta").index(key)


def _surface(result, title):
    df = result.data["sweep"]
    model = first_model(df)
    theta = df["theta"].iloc[0]
    d = df[(df["model"] == model) & np.isclose(df["theta"], theta) & (df["direction"] == "braking")]
    piv = d.assign(s=np.abs(d["slip"]), m=np.abs(d["mu"])).pivot_table(index="speed", columns="s", values="m")
    if min(piv.shape) < 2:
        from tirecli.errors import UsageError

        raise UsageError("a friction surface needs braking slips and at least two speeds in the sweep "
                         f"(this one has {piv.shape[0]} speed(s) and {piv.shape[1]} braking slip(s))")
    S, V = np.meshgrid(piv.columns.to_numpy(), piv.index.to_numpy())
    fig = figure(figsize=(6.6, 5.0))
    ax = fig.add_subplot(projection="3d")
    ax.plot_surface(S, V, piv.to_numpy(), cmap="viridis", linewidth=0, antialiased=True, alpha=0.9)
    ridge = []
    for v in piv.index:
        pk = curve_peak(result, model, v, theta)
        if pk is not None and np.isfinite(pk[0]) and pk[0] <= S.max() + 1e-12:
            ridge.append(pk + (v,))
    if ridge:  # the peak of each speed's curve, where it lies inside the swept slips
        ps, pm, _, pv = np.array(ridge).T
        ax.plot(ps, pv, pm, "o-", color="#D55E00", ms=3, lw=1.2, zorder=5,
                label=f"peak |mu| at each speed (root-found; {pm.min():.4g}-{pm.max():.4g})")
        ax.legend(fontsize=8, loc="upper right")
    ax.set_xlabel("slip |s| [-]")
    ax.set_ylabel("speed v [m/s]")
    ax.zaxis.set_rotate_label(False)
    ax.set_zlabel("|mu| [-]", rotation=90)
    readable_3d(ax, fontsize=9)
    ax.set_title(title, fontsize=10)
    ax.view_init(elev=22, azim=-50)
    fig.subplots_adjust(left=0.02, right=0.95, bottom=0.05, top=0.93)
    return fig


@register("sweep-surface", paper="generic", label="sweep", title="Friction surface over slip and speed",
          caption="Steady-state |mu| over |s| and the held speed (braking) for the first model and adhesion of the sweep; "
                  "the line marks each speed's root-found peak where it lies in the swept slips (data/peaks.csv).")
def draw_sweep_surface(result):
    return _surface(result, result.meta.get("title") or "Steady-state friction surface")


# --------------------------------------------------------------------------- FM Fig. 1


def _theta_label(theta_fm, convention):
    return f"theta_obs = {1.0 / theta_fm:.3g}" if convention == "obs" else f"theta = {theta_fm:g}"


def _with_peak(label, pk):
    text = peak_text(pk)
    return f"{label}: {text}" if text else label


def _draw_speed_family(ax, result, model, theta=1.0, dashed_model=None, dashed_speed=20.0):
    """Curves at every speed of the sweep, each with its root-found peak (marker, value in the legend)."""
    df = result.data["sweep"]
    speeds = sorted(df["speed"].unique())
    for i, v in enumerate(speeds):
        s, mu = curve(df, model, v, theta)
        pk = curve_peak(result, model, v, theta)
        ax.plot(s, mu, color=COLORS[i % len(COLORS)], label=_with_peak(f"v = {v:g} m/s ({v * 3.6:.0f} km/h)", pk))
        mark_peak(ax, pk, COLORS[i % len(COLORS)], xmax=s.max() if len(s) else 0.0)
    if dashed_model is not None:
        s, mu = curve(df, dashed_model, dashed_speed, theta)
        pk = curve_peak(result, dashed_model, dashed_speed, theta)
        ax.plot(s, mu, "k--", lw=1.2, label=_with_peak(f"{dashed_model}, v = {dashed_speed:g} m/s", pk))
        mark_peak(ax, pk, "k", xmax=s.max() if len(s) else 0.0)
    ax.set_xlim(0, 1)
    ax.set_ylim(bottom=0)


def _draw_theta_family(ax, result, model, speed, convention):
    """Curves at every adhesion of the sweep at one speed, each with its root-found peak."""
    df = result.data["sweep"]
    thetas = sorted(df["theta"].unique(), reverse=True)
    for i, th in enumerate(thetas):
        s, mu = curve(df, model, speed, th)
        pk = curve_peak(result, model, speed, th)
        ax.plot(s, mu, color=COLORS[i % len(COLORS)], ls=LINESTYLES[i % len(LINESTYLES)],
                label=_with_peak(_theta_label(th, convention), pk))
        mark_peak(ax, pk, COLORS[i % len(COLORS)], xmax=s.max() if len(s) else 0.0)
    ax.set_xlim(0, 1)
    ax.set_ylim(bottom=0)


@register(
    "fm-fig1-left", paper="FM", label="Fig. 1 (left)", study="fm-fig1-left", order=10,
    title="Steady-state friction vs slip at several vehicle speeds",
    caption="Distributed LuGre model, uniform normal load (FM eq. 4), braking at constant vehicle speed "
            "v = 5-30 m/s, Table 1 parameters with the Stribeck exponent alpha = 1 [assumed]. All curves share "
            "the initial slope sigma0 L/2 + sigma2 v; peak height and peak slip fall as v grows." + PEAK_CAPTION,
    paper_shows="|mu| against |s| in [0, 1] for several vehicle speeds (braking, uniform load, Table 1): a common "
                "linear rise, a peak that is lower and earlier at higher speed, then a decay towards the sliding level.",
)
def draw_fm_fig1_left(result):
    df = result.data["sweep"]
    fig, ax = new_figure()
    _draw_speed_family(ax, result, first_model(df))
    finish(ax, "slip |s| [-]", "friction |mu| = |F|/F_n [-]",
           f"FM Fig. 1 (left): braking, uniform load, {_tire_label(result)}", legend=False)
    _with_peak_legend(ax)
    return fig


@register(
    "fm-fig1-right", paper="FM", label="Fig. 1 (right)", study="fm-fig1-right", order=11,
    title="Steady-state friction vs slip for several road adhesions at 72 km/h",
    caption="Distributed LuGre model, uniform load, braking at v = 20 m/s, Table 1 (alpha = 1 [assumed]), "
            "adhesion theta = 1, 0.8, 0.6, 0.4 in the FM convention (g -> theta g) [assumed values]. Lower "
            "adhesion lowers peak and sliding level and moves the peak to smaller slip; the initial slope is unchanged."
            + PEAK_CAPTION,
    paper_shows="|mu| against |s| at v = 20 m/s = 72 km/h for several road conditions theta: same initial slope, "
                "lower peaks and plateaus for lower adhesion.",
)
def draw_fm_fig1_right(result):
    df = result.data["sweep"]
    fig, ax = new_figure()
    _draw_theta_family(ax, result, first_model(df), 20.0, "fm")
    finish(ax, "slip |s| [-]", "friction |mu| = |F|/F_n [-]",
           f"FM Fig. 1 (right): v = 20 m/s, adhesion theta (FM convention), {_tire_label(result)}", legend=False)
    _with_peak_legend(ax, below=True)  # the low-adhesion plateaus leave no free corner
    return fig


# --------------------------------------------------------------------------- OBS Fig. 1


@register(
    "obs-fig1", paper="OBS", label="Fig. 1 (a), (b)", study="obs-fig1", order=10,
    title="Steady-state friction curves of the observer paper",
    caption="(a) Distributed LuGre model, uniform load, braking, OBS Fig. 1 parameters (= FM Table 1, alpha = 1 "
            "[assumed]) at v = 5-30 m/s [assumed speeds]; dashed: the lumped model with kappa = 10 1/m (kappa0 = 2) at "
            "20 m/s, which peaks lower and later. (b) Adhesion theta in the OBS convention (theta_obs = 1/theta_fm: "
            "1 dry, larger = less grip) at v = 20 m/s [assumed values]." + PEAK_CAPTION,
    paper_shows="Fig. 1(a): mu against slip for several vehicle speeds; Fig. 1(b): for several road conditions theta "
                "(OBS convention, theta > 1 less grip). Same figure as FM Fig. 1.",
)
def draw_obs_fig1(result):
    df = result.data["sweep"]
    models = list(dict.fromkeys(df["model"]))
    fig, (a, b) = new_figure(ncols=2, width=11.0, height=4.2)
    _draw_speed_family(a, result, models[0], 1.0, dashed_model=models[1] if len(models) > 1 else None)
    finish(a, "slip |s| [-]", "friction |mu| [-]", "(a) several speeds, theta_obs = 1", legend=False)
    _with_peak_legend(a)
    _draw_theta_family(b, result, models[0], 20.0, "obs")
    finish(b, "slip |s| [-]", "friction |mu| [-]", "(b) several road conditions, v = 20 m/s", legend=False)
    b.set_ylim(bottom=0)
    legend_room(b, 0.5, "top")  # the plateaus of the road conditions fill the lower right
    _with_peak_legend(b, loc="upper right")
    fig.suptitle(f"OBS Fig. 1: {_tire_label(result)}", fontsize=10)
    return fig


# --------------------------------------------------------------------------- FM Fig. 6 surface


@register(
    "fm-fig6-surface", paper="FM", label="Fig. 6 (model surface)", study="fm-fig6-surface", order=60,
    title="Identified steady-state surface |mu|(|s|, v), Table 2",
    caption="Steady state of the distributed model with uniform load (equivalently lumped with kappa0(Z)) for the "
            "Table 2 parameters, alpha = 2, over |s| in [0, 0.3] and v = 5-25 m/s: rising in |s|, flattening, lower at "
            "higher speed; the line marks the root-found peak at each speed (data/peaks.csv). The measured samples of "
            "the paper are replaced by synthetic ones in the identification study.",
    paper_shows="3-D plot of the measured (mu, s, v) samples of braking #2 and the identified steady-state surface (alpha = 2).",
)
def draw_fm_fig6_surface(result):
    tire = result.parameter_sets["tire"]
    return _surface(result, f"FM Fig. 6: steady-state surface, {tire.label}, alpha = {tire.values['alpha']:g}")


# --------------------------------------------------------------------------- FM Table 1


def parameter_table(ps) -> Table:
    """A :class:`Table` of a parameter set with units, sources and assumed values flagged."""
    rows = []
    for r in ps.rows():
        flag = f"ASSUMED: {r['assumed']}" if r["assumed"] else (r["note"] or "")
        rows.append([r["name"], f"{r['value']:g}", r["unit"], r["meaning"], r["equation"], flag])
    return Table(columns=["parameter", "value", "unit", "meaning", "equation", "status"], rows=rows,
                 notes=[f"Set {ps.name}: {ps.citation}"])


@register(
    "fm-table1", paper="FM", label="Table 1", study="fm-fig1-left", order=1,
    title="Parameters used for Fig. 1",
    caption="FM Table 1 as used by tirecli; sigma1 and the Stribeck exponent are not printed in the paper and are "
            "flagged as assumed defaults (overridable with --set tire.NAME=VALUE).",
    paper_shows="Table 1: sigma0 = 181.54 1/m, sigma2 = 0.0018 s/m, mu_c = 0.8, mu_s = 1.55, v_s = 6.57 m/s, L = 0.2 m.",
)
def draw_fm_table1(result):
    return parameter_table(result.parameter_sets["tire"])
