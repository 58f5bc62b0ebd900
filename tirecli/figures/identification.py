"""Identification figures: samples and fitted steady state, transient fit of sigma1; FM Fig. 6 and Table 2."""
from __future__ import annotations

import numpy as np

from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, figure, finish, new_figure, readable_3d, synthetic_mark
from tirecli.figures.transient import SYN, require


def _label(result, fig):
    if result.synthetic:
        synthetic_mark(fig, SYN)


def _surface_mu(p, s_abs, v):
    from tirecli.models.lugre import mu_ss_uniform

    return np.abs(mu_ss_uniform(-v * s_abs, v * (1.0 - s_abs), p))


def _fm(result):
    """The FM-procedure (stages 1-2) parameter set of a fit result."""
    return result.payload.get("fitted_fm", result.payload["fitted"])


def _dist(result):
    """The stage-3 (distributed model) FitResult, or None."""
    return result.payload.get("distributed")


@register("fit-steady", paper="generic", label="fit", title="Steady-state fit: samples and model",
          caption="|mu| against |s| of the samples used by the steady-state fit (coloured by vehicle speed) and the fitted "
                  "FM eq. (4) at the minimum, middle and maximum sample speed (stage 1 of the FM procedure; the "
                  "distributed-model fit is in fm-fig6 and fit-transient); below, the residuals mu_model - mu of all "
                  "samples (grey: not used: outside the window or |s| below the threshold).")
def draw_fit_steady(result):
    require(result, "fit", "fit-steady")
    d = result.data["samples"]
    p = _fm(result)
    used = d["used"].to_numpy() > 0
    fig, (a, b) = new_figure(nrows=2, width=7.0, height=7.0, height_ratios=(2.2, 1))
    sc = a.scatter(np.abs(d["s"][used]), np.abs(d["mu"][used]), c=d["v"][used], s=9, cmap="viridis", label="samples used")
    fig.colorbar(sc, ax=a, label="v [m/s]")
    smax = float(np.abs(d["s"]).max()) * 1.15 or 0.3
    ss = np.linspace(0, smax, 300)
    vs = d["v"][used]
    for k, v in enumerate(sorted({float(vs.min()), float(vs.median()), float(vs.max())})):
        a.plot(ss, _surface_mu(p, ss, v), color=COLORS[(k + 1) % len(COLORS)], lw=1.2, label=f"fit, v = {v:.1f} m/s")
    finish(a, "slip |s| [-]", "|mu| [-]", result.meta.get("title") or "Steady-state fit", loc="lower right")
    b.plot(d["t"][~used], d["residual"][~used], ".", color="0.7", ms=3, label="not used")
    b.plot(d["t"][used], d["residual"][used], ".", color=COLORS[0], ms=3, label="used")
    finish(b, "time t [s]", "mu_model - mu [-]")
    _label(result, fig)
    return fig


@register("fit-transient", paper="generic", label="fit", title="Transient fits: sigma1, and the distributed model",
          caption="Measured mu(t) and the tire model driven by the measured v(t), s(t): the FM procedure's model (stage 2: "
                  "the steady-state parameters with sigma1 fitted to mu(t); default lumped kappa0(Z)) and, with model: "
                  "distributed, the distributed model with all parameters fitted to mu(t) at once (stage 3); dashed: the "
                  "steady state FM eq. (4) at the same (s, v), which misses the lag of the bristle dynamics. Below, "
                  "model - data. In stage 2 sigma1 also absorbs what the chosen transient model gets wrong: on the "
                  "synthetic braking #2 (truth: distributed model, sigma1 = 1 s/m) the lumped kappa0(Z) model returns "
                  "about 1.24 s/m even with the Table 2 steady state; stage 3 has no such model error.")
def draw_fit_transient(result):
    require(result, "fit", "fit-transient")
    tr = result.data.get("transient")
    dd = result.data.get("distributed")
    fig, (a, b) = new_figure(nrows=2, width=7.0, height=6.0, sharex=True, height_ratios=(2.2, 1))
    if tr is None and dd is None:
        a.text(0.5, 0.5, "sigma1 not fitted (fit.sigma1: false)", ha="center", va="center", transform=a.transAxes)
        return fig
    data = tr if tr is not None else dd
    a.plot(data["t"], data["mu"], ".", color="0.5", ms=3, label="data")
    if tr is not None:
        s1 = result.payload["sigma1"]
        a.plot(tr["t"], tr["mu_model"], color=COLORS[0], lw=1.3,
               label=f"FM procedure, sigma1 = {s1.estimate['sigma1']:.3g} +/- {s1.se['sigma1']:.2g} s/m")
        a.plot(tr["t"], tr["mu_steady"], "--", color=COLORS[1], lw=1.0, label="steady state (FM eq. 4)")
        b.plot(tr["t"], tr["residual"], color=COLORS[0], lw=1.0, label="FM procedure")
    if dd is not None:
        f = _dist(result)
        lab = f"distributed model, all fitted (RMS {f.residual_rms:.2g})"
        a.plot(dd["t"], dd["mu_model"], color=COLORS[2], lw=1.1, ls="-.", label=lab)
        b.plot(dd["t"], dd["residual"], color=COLORS[2], lw=1.0, ls="-.", label="distributed model")
    # the legend below the panels: measured data may run through any corner of the friction panel
    finish(a, "", "mu [-]", result.meta.get("title") or "Transient fit", legend=False)
    handles, labels = a.get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    finish(b, "time t [s]", "model - data [-]", legend=dd is not None and tr is not None, loc="upper right")
    _label(result, fig)
    return fig


# --------------------------------------------------------------------------- FM Fig. 6

def _caption_fig6(result):
    f = _dist(result) if result is not None else None
    base = ("SYNTHETIC data: the noise-free 100 Hz samples of braking #2 of Fig. 4 (distributed model, Table 2) with "
            "t <= 2.6 s and |s| > 0.005 (post-release samples dropped), and the steady-state surface FM eq. (4) "
            "(alpha = 2, L = 0.2 m) fitted to them by bounded least squares from Table 1 starting values (FM procedure"
            + (", panel (c)" if f is not None else "") + "). sigma0 and mu_s are well determined; mu_c and v_s are poorly determined (correlated, and the "
            "samples stop at the force peak), so the transient bias of ~2e-3 RMS moves them far from Table 2 - an "
            "independent fit reports the same effect (mu_c 1.17, v_s 3.7 on its data, docs/models/lugre_friction.md §10); beyond the sampled slips the fitted surface is an "
            "extrapolation.")
    if f is None:
        return base + " See Table 2 for the estimates with 95% intervals (which cover the residual scatter, not the bias)."
    from tirecli.studies.fit import TABLE2

    e = f.estimate
    outside = [k for k in f.names if k in TABLE2 and not f.ci_low[k] <= TABLE2[k] <= f.ci_high[k]]
    lvl = int(round(100 * f.confidence))
    cover = (f"Table 2 lies inside all {lvl}% intervals of this fit" if not outside
             else f"Table 2 lies outside the {lvl}% intervals of {', '.join(outside)}")
    return (base + " (a) and (b): the surface of the distributed-model fit in 3-D and as a map from above, with the "
            "samples; (c): the FM procedure's fit; (d): the fit with the distributed model in the least-squares loop (all "
            f"six parameters to mu(t) of the whole braking, the model driven by the sampled v(t), r omega(t)): mu_c = {e.get('mu_c', float('nan')):.3g}, "
            f"v_s = {e.get('v_s', float('nan')):.3g} m/s, residual RMS {f.residual_rms:.2g}. It removes the model bias: "
            f"{cover}. What is left of the residual is the data's own numerical error (the generating run's tolerance "
            "and the 100 Hz sampling of the fast wheel transients), to which mu_c and v_s remain sensitive (wide "
            "intervals); on data consistent to 1e-7 the same fit returns Table 2 to 1e-4 (tests). See Table 2.")


@register(
    "fm-fig6", paper="FM", label="Fig. 6", study="fm-fig6", order=61,
    title="(mu, s, v) samples of braking #2 and the identified steady-state surfaces (synthetic data)",
    caption=_caption_fig6,
    paper_shows="3-D plot of the measured (mu, s, v) samples of braking #2 (points) and the identified steady-state "
                "surface (alpha = 2).",
)
def draw_fm_fig6(result):
    require(result, "fit", "fm-fig6")
    d = result.data["samples"]
    used = d["used"].to_numpy() > 0
    p_fm = _fm(result)
    f = _dist(result)
    panels = [(p_fm, "FM procedure: steady-state fit (stage 1)")]
    if f is not None:
        panels.append((result.payload["fitted"], "distributed model in the loop (stage 3)"))
    s_abs, v, m = np.abs(d["s"][used]), d["v"][used], np.abs(d["mu"][used])
    ss = np.linspace(0.0, 0.3, 61)
    vv = np.linspace(float(v.min()), float(v.max()), 41)
    S, V = np.meshgrid(ss, vv)
    p3, name3 = panels[-1][0], ("distributed-model fit" if f is not None else "FM procedure's fit")
    M = _surface_mu(p3, S, V)
    # two rows that fit a page: the paper's 3-D view and the same surface as a map (top), the fitted
    # curves of each fit against the samples (bottom); one legend and one speed scale for the figure.
    # A fixed layout: the constrained engine measures the 3-D panel's ticks at length (seconds per figure).
    fig = figure(figsize=(10.0, 8.6))
    a = fig.add_axes((0.0, 0.53, 0.47, 0.40), projection="3d")
    a.plot_surface(S, V, M, cmap="viridis", alpha=0.55, linewidth=0, rasterized=True)
    a.scatter(s_abs, v, m, color=COLORS[1], s=6, depthshade=False)
    a.set_xlabel("slip |s| [-]", fontsize=9)
    a.set_ylabel("speed v [m/s]", fontsize=9)
    a.zaxis.set_rotate_label(False)
    a.set_zlabel("|mu| [-]", rotation=90, fontsize=9)
    readable_3d(a)
    a.view_init(elev=22, azim=-50)
    a.set_title(f"(a) samples and the {name3}'s surface", fontsize=10)
    c = fig.add_axes((0.57, 0.565, 0.28, 0.345))
    filled = c.contourf(S, V, M, levels=np.arange(0.0, float(M.max()) + 0.1, 0.1), cmap="viridis", alpha=0.85)
    lines = c.contour(S, V, M, levels=filled.levels[2::2], colors="#FFFFFF", linewidths=0.6)
    c.clabel(lines, fmt="%.1f", fontsize=7)
    fig.colorbar(filled, cax=fig.add_axes((0.87, 0.565, 0.013, 0.345)), label="|mu| of the surface [-]")
    c.plot(s_abs, v, ".", color=COLORS[1], ms=3, label="synthetic samples (|s|, v) of braking #2")
    finish(c, "slip |s| [-]", "speed v [m/s]", "(b) the same surface from above: |mu| over (|s|, v)", legend=False)
    axes = []
    lefts = (0.07, 0.5) if len(panels) == 2 else (0.285,)
    for i, ((p, title), x0) in enumerate(zip(panels, lefts)):
        b = fig.add_axes((x0, 0.12, 0.35, 0.33), sharey=axes[0] if axes else None)
        axes.append(b)
        sc = b.scatter(s_abs, m, c=v, s=8, cmap="viridis")
        for k, vk in enumerate((float(v.max()), 0.5 * (float(v.min()) + float(v.max())), float(v.min()))):
            b.plot(ss, _surface_mu(p, ss, vk), color=COLORS[k], lw=1.2, label=f"fit, v = {vk:.1f} m/s")
            b.plot(ss, _surface_mu(result.payload["table2"], ss, vk), color=COLORS[k], lw=0.8, ls=":",
                   label=f"Table 2, v = {vk:.1f} m/s")
        b.set_xlim(0, 0.3)
        b.set_ylim(bottom=0)
        finish(b, "slip |s| [-]", "|mu| [-]" if i == 0 else "", f"({'cd'[i]}) {title}:\nfit (solid), Table 2 (dotted)",
               legend=False)
    fig.colorbar(sc, cax=fig.add_axes((lefts[-1] + 0.37, 0.12, 0.013, 0.33)), label="sample speed v [m/s]")
    handles, labels = axes[0].get_legend_handles_labels()
    handles += c.get_legend_handles_labels()[0]
    labels += c.get_legend_handles_labels()[1]
    fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=4, fontsize=8, frameon=False,
               markerscale=2)
    synthetic_mark(fig, SYN)
    return fig


def _deviations(f) -> tuple[str, list]:
    """``"sigma0 -0.11 %, ..."`` (relative to Table 2; sigma2 absolute) and the parameters whose interval holds Table 2."""
    from tirecli.studies.fit import TABLE2

    parts, inside = [], []
    for k in f.names:
        if k not in TABLE2:
            continue
        ref = TABLE2[k]
        parts.append(f"{k} {f.estimate[k] - ref:+.2g} s/m" if ref == 0.0 else f"{k} {100 * (f.estimate[k] / ref - 1):+.2g} %")
        if f.ci_low[k] <= ref <= f.ci_high[k]:
            inside.append(k)
    return ", ".join(parts), inside


def _caption_table2(result):
    base = ("FM Table 2 (the paper's identification from measured braking #2; here also the generating values of the "
            "SYNTHETIC braking #2) beside tirecli's fits of that braking: estimate and 95% confidence interval. FM "
            "procedure: the steady state FM eq. (4) fitted to the samples, then sigma1 from the transient with the lumped "
            "kappa0(Z) model, which is not the distributed truth, so sigma1 is biased too. The checks fit exact "
            "steady-state samples of Table 2 and must return it.")
    f = _dist(result) if result is not None else None
    if f is None:
        return base
    dev, inside = _deviations(f)
    return (base + " Distributed model: all parameters fitted at once to mu(t) with the distributed model (the truth's "
            "model) in the least-squares loop, starting from the FM procedure's values. Here it deviates from Table 2 "
            f"by {dev}; Table 2 lies inside the interval of {', '.join(inside) or 'none'}. The intervals come from the "
            f"residual (RMS {f.residual_rms:.2g}), which on noise-free synthetic samples is not noise but the data's "
            "own numerical error (the generating run's tolerance, the 100 Hz sampling of fast wheel transients); mu_c "
            "and v_s, nearly interchangeable below the force peak, are the most sensitive to it. With mu consistent "
            "with the sampled kinematics to 1e-7 (an independent solver) the distributed fit returns Table 2 to 1e-4 "
            "(tests).")


@register(
    "fm-table2", paper="FM", label="Table 2", study="fm-fig6", order=60,
    title="Identified parameters: FM Table 2 beside tirecli's fits (synthetic braking #2)",
    caption=_caption_table2,
    paper_shows="Table 2: sigma0 = 178 1/m, sigma1 = 1 (printed '1/m', a unit typo: s/m), sigma2 = 0, mu_c = 0.8, "
                "mu_s = 1.5, v_s = 5.5 m/s.",
)
def draw_fm_table2(result):
    from tirecli.studies.fit import TABLE2

    require(result, "fit", "fm-table2")
    par = result.data["parameters"]
    if "fit" not in par.columns:
        par = par.assign(fit="FM 4.3")
    fm = par[par["fit"] != "distributed"].set_index("parameter")
    di = par[par["fit"] == "distributed"].set_index("parameter")
    p_fm, p = _fm(result), result.payload["fitted"]
    has_dist = len(di) > 0

    def cells(frame, k, pset):
        if k in frame.index:
            f = frame.loc[k]
            flag = " (on a bound)" if bool(f["at_bound"]) else ""
            return [f"{f['estimate']:.4g}", f"[{f['ci_low']:.4g}, {f['ci_high']:.4g}]{flag}"]
        return [f"{getattr(pset, k):.4g}", "fixed (not identified)"]

    rows = []
    for k, ref in TABLE2.items():
        unit = {"sigma0": "1/m", "sigma1": "s/m", "sigma2": "s/m", "v_s": "m/s", "L": "m"}.get(k, "-")
        row = [k, f"{ref:g}"] + cells(fm, k, p_fm) + (cells(di, k, p) if has_dist else []) + [unit]
        rows.append(row)
    st = result.payload["steady"]
    lvl = int(round(100 * st.confidence))
    columns = ["parameter", "FM Table 2", "FM procedure", f"FM procedure {lvl}% CI"]
    if has_dist:
        columns += ["distributed model", f"distributed model {lvl}% CI"]
    columns.append("unit")
    notes = [f"Data: {result.meta['data']['source']} ({result.meta['data']['used_steady']} samples in the steady-state "
             f"fit); SYNTHETIC." if result.synthetic else f"Data: {result.meta['data']['source']}.",
             f"FM procedure: steady-state residual RMS {st.residual_rms:.2e}"
             + (f", transient (sigma1) residual RMS {result.payload['sigma1'].residual_rms:.2e}"
                if result.payload.get("sigma1") is not None else "")
             + "; correlation matrix in data/correlation.csv.",
             "The FM procedure's intervals reflect the residual scatter only: the systematic transient bias of braking "
             "samples moves the poorly determined mu_c and v_s far outside them (an independent fit of its own synthetic "
             "data: mu_c 1.17, v_s 3.7). A fit of exact steady-state samples returns Table 2 (checks)."]
    if has_dist:
        f = _dist(result)
        corr = ""
        if "mu_c" in f.names and "v_s" in f.names:
            corr = f" (mu_c and v_s: {f.corr[f.names.index('mu_c'), f.names.index('v_s')]:.4f})"
        notes.append(f"Distributed model: {f.n} samples of mu(t), residual RMS {f.residual_rms:.2e}, {f.nfev} model "
                     f"evaluations and {f.extra.get('njev', 0)} Jacobians in "
                     f"{f.extra.get('wall_time_s', float('nan')):.2f} s; correlation matrix in "
                     f"data/correlation_distributed.csv{corr}." + (" On synthetic data its residual is the data's own "
                     "numerical error rather than noise, so its intervals are indicative only." if result.synthetic
                                                                  else ""))
    notes.append("FM Table 2 prints the unit of sigma1 as 1/m; it is s/m (docs/models/lugre_friction.md §6).")
    return Table(columns=columns, rows=rows, notes=notes)
