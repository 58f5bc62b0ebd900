"""Figures of a Magic Formula fit (study ``mf-fit``, ``tirecli mf fit``): data against the fitted tyre for
every sweep, the residuals, and the coefficient table.

The fit drawn is the written ``fitted.tir`` read back and evaluated at the data points (frame ``fit``:
``CH`` data, ``CH_fit``, ``CH_res``); the sweeps are those of :func:`tirecli.io.sweeps.find_sweeps`
(``payload["sweeps"]``). Data are markers, the fit a line through its values at the data's slips. ISO-W
axes, SI units (slip angles in degrees).
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.figures.registry import Table, register
from tirecli.figures.style import COLORS, finish, new_figure, suptitle

#: Sweeps drawn per panel at most (the rest are named in the caption's count only).
MAX_CURVES = 12
_DEG = 180.0 / math.pi
_CHANNEL = {"fx": "Fx [N]", "fy": "Fy [N]", "mz": "Mz [N m]"}


def _require(result, fid: str) -> None:
    from tirecli.errors import UsageError

    if result.study != "mf-fit":
        raise UsageError(f"figure {fid!r} draws a Magic Formula fit (tirecli mf fit), not this "
                         f"'{result.study}' run (see 'tirecli figures list')")


def _title(result, what: str) -> str:
    tag = "SYNTHETIC data" if result.synthetic else "data"
    return f"{what}: {tag} and fitted.tir (start {result.payload['start']})"


def _sweeps(result, kind: str) -> list:
    return [s for s in result.payload["sweeps"] if s.kind == kind and s.rows >= 2]


def _label(s, held_alpha: bool = False) -> str:
    parts = [f"Fz {s.fz:.0f} N"]
    if s.gamma is not None and abs(s.gamma) > 1e-4:
        parts.append(f"gamma {s.gamma * _DEG:.3g} deg")
    if s.p is not None and math.isfinite(s.p):
        parts.append(f"p {s.p / 1e5:.3g} bar")
    if held_alpha and "alpha" in s.held:
        parts.insert(0, f"alpha {s.held['alpha'] * _DEG:.3g} deg")
    return ", ".join(parts)


def _draw(ax, frame, sweeps, x: str, ch: str, scale: float = 1.0, held_alpha: bool = False) -> int:
    """Data (markers) and fit (line) of ``ch`` against ``x`` for each sweep; the number drawn."""
    n = 0
    for i, s in enumerate(sweeps[:MAX_CURVES]):
        rows = frame.iloc[s.start:s.stop]
        if ch not in rows or not np.isfinite(rows[ch]).any():
            continue
        rows = rows.sort_values(x)
        c = COLORS[i % len(COLORS)]
        ax.plot(rows[x] * scale, rows[ch], "o", ms=2.5, color=c, alpha=0.6, mec="none")
        ax.plot(rows[x] * scale, rows[ch + "_fit"], "-", lw=1.2, color=c, label=_label(s, held_alpha))
        n += 1
    return n


def _empty(ax, what: str) -> None:
    ax.text(0.5, 0.5, f"no {what} sweep in the data", ha="center", va="center", transform=ax.transAxes, color="0.4")
    ax.set_xticks([])
    ax.set_yticks([])


def _pure(result, fid: str, kind: str, x: str, ch: str, xlabel: str, scale: float, what: str):
    _require(result, fid)
    fig, ax = new_figure(width=7.0, height=4.6)
    frame = result.data["fit"]
    sweeps = _sweeps(result, kind)
    if not _draw(ax, frame, sweeps, x, ch, scale):
        _empty(ax, kind)
        return fig
    finish(ax, xlabel, _CHANNEL[ch] + " (ISO-W)", _title(result, what), outside=True,
           legend_title="markers: data; lines: fit")
    return fig


def _caption_pure(what: str):
    def caption(result) -> str:
        return (f"{what} of each sweep of the data (markers) and of the fitted tyre (lines): the written fitted.tir "
                "read back and evaluated at the data's points (combined slip, ISO-W). One colour per sweep "
                "(load, inclination, pressure); the report fits the SYNTHETIC example data "
                "(examples/data/synthetic-externdata-205-60r15.tdx) starting from another tyre.")
    return caption


@register("mf-fit-fx", paper="MF", label="fit: Fx", title="Fitted .tir: Fx against kappa", study="mf-fit-example",
          caption=_caption_pure("Longitudinal force against slip ratio"), order=60)
def fig_fx(result):
    return _pure(result, "mf-fit-fx", "pure longitudinal", "kappa", "fx", "slip ratio kappa [-]", 1.0,
                 "Fx vs kappa, pure longitudinal")


@register("mf-fit-fy", paper="MF", label="fit: Fy", title="Fitted .tir: Fy against alpha", study="mf-fit-example",
          caption=_caption_pure("Side force against slip angle"), order=61)
def fig_fy(result):
    return _pure(result, "mf-fit-fy", "pure lateral", "alpha", "fy", "slip angle alpha [deg]", _DEG,
                 "Fy vs alpha, pure lateral")


@register("mf-fit-mz", paper="MF", label="fit: Mz", title="Fitted .tir: Mz against alpha", study="mf-fit-example",
          caption=_caption_pure("Aligning moment against slip angle"), order=62)
def fig_mz(result):
    return _pure(result, "mf-fit-mz", "pure lateral", "alpha", "mz", "slip angle alpha [deg]", _DEG,
                 "Mz vs alpha, pure lateral")


@register("mf-fit-combined", paper="MF", label="fit: combined", title="Fitted .tir: combined slip",
          study="mf-fit-example", order=63,
          caption=("Combined slip: Fx, Fy and Mz against slip ratio for each combined sweep (held slip angle, load) "
                   "of the data (markers) and of the fitted tyre (lines), the written fitted.tir read back."))
def fig_combined(result):
    _require(result, "mf-fit-combined")
    fig, axes = new_figure(ncols=3, width=12.5, height=4.4)
    frame = result.data["fit"]
    sweeps = _sweeps(result, "combined")
    drawn = 0
    for ax, ch in zip(axes, ("fx", "fy", "mz")):
        if ch not in frame.columns or not _draw(ax, frame, sweeps, "kappa", ch, 1.0, held_alpha=True):
            _empty(ax, "combined")
            continue
        drawn += 1
        finish(ax, "slip ratio kappa [-]", _CHANNEL[ch] + " (ISO-W)", legend=False)
    if drawn:
        suptitle(fig, _title(result, "combined slip"))
        handles, labels = next(ax for ax in axes if ax.get_legend_handles_labels()[0]).get_legend_handles_labels()
        # below the panels: the curves fill every corner of them
        fig.legend(handles, labels, loc="outside lower center", ncol=min(len(labels), 4), fontsize=8, frameon=False,
                   title="markers: data; lines: fit", title_fontsize=8)
    return fig


@register("mf-fit-residuals", paper="MF", label="fit: residuals", title="Fitted .tir: residuals",
          study="mf-fit-example", order=64,
          caption=("Residuals of the fit (fitted.tir read back minus data) at every data point, as a percentage of "
                   "each channel's peak, against the swept slip: Fx in the pure longitudinal sweeps, Fy and Mz in "
                   "the pure lateral sweeps, all three in the combined sweeps. Noise of the data shows as scatter "
                   "without a trend; a trend along the slip is a shape the fit misses."))
def fig_residuals(result):
    _require(result, "mf-fit-residuals")
    frame = result.data["fit"]
    fig, axes = new_figure(ncols=2, nrows=2, width=10.0, height=7.0)
    panels = (("pure longitudinal", "kappa", 1.0, "slip ratio kappa [-]", ("fx",)),
              ("pure lateral", "alpha", _DEG, "slip angle alpha [deg]", ("fy", "mz")),
              ("combined", "kappa", 1.0, "slip ratio kappa [-] (combined sweeps)", ("fx", "fy", "mz")))
    shown = 0
    for ax, (kind, x, scale, xlabel, chans) in zip(axes.ravel(), panels):
        idx = np.concatenate([np.arange(s.start, s.stop) for s in _sweeps(result, kind)] or [np.empty(0, int)])
        rows = frame.iloc[idx]
        drew = False
        for j, ch in enumerate(c for c in chans if c + "_res" in frame.columns):
            peak = float(np.nanmax(np.abs(frame[ch]))) or 1.0
            r = rows[ch + "_res"] / peak * 100
            if np.isfinite(r).any():
                ax.plot(rows[x] * scale, r, ".", ms=3, color=COLORS[j], alpha=0.7, label=ch)
                drew = True
        if not drew:
            _empty(ax, kind)
            continue
        ax.axhline(0.0, color="0.3", lw=0.8)
        finish(ax, xlabel, "fit - data [% of peak]", kind, outside=True)
        shown += 1
    ax = axes.ravel()[3]
    for j, ch in enumerate(c for c in ("fx", "fy", "mz") if c + "_res" in frame.columns):
        peak = float(np.nanmax(np.abs(frame[ch]))) or 1.0
        r = frame[ch + "_res"].to_numpy() / peak * 100
        r = r[np.isfinite(r)]
        if r.size:
            ax.hist(r, bins=40, histtype="step", color=COLORS[j], label=f"{ch}: RMS {np.sqrt(np.mean(r * r)):.2f} %")
    finish(ax, "fit - data [% of peak]", "points [-]", "all points", outside=True)
    suptitle(fig, _title(result, "residuals"))
    return fig


def _fmt(x) -> str:
    return "" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.6g}"


@register("mf-fit-coefficients", paper="MF", label="fit: coefficients", title="Fitted .tir: coefficients",
          study="mf-fit-example", order=65,
          caption=("The coefficients of the fit: start and fitted value, the 95 % interval from the Jacobian at the "
                   "optimum (conditional on the earlier stages), and why a coefficient kept its start value; "
                   "the strongest correlations between coefficients fitted together are listed below the table."))
def table_coefficients(result):
    _require(result, "mf-fit-coefficients")
    df = result.data["coefficients"]
    rows = []
    for r in df.itertuples():
        interval = f"[{_fmt(r.ci95_low)}, {_fmt(r.ci95_high)}]" if r.ci95_low is not None and \
            np.isfinite(r.ci95_low) else ""
        rows.append([r.name, r.stage, _fmt(r.start), _fmt(r.fitted), interval,
                     "yes" if r.identified else "no", r.reason])
    notes = [f"{a} and {b}: r = {c:+.3f}" for a, b, c in result.payload["correlations"][:8]]
    if notes:
        notes.insert(0, "strongest correlations:")
    return Table(["coefficient", "stage", "start", "fitted", "95 % interval", "identified", "why not"], rows, notes)


__all__ = ["fig_fx", "fig_fy", "fig_mz", "fig_combined", "fig_residuals", "table_coefficients"]
