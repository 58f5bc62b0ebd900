"""The analysis figures of a campaign (:mod:`tirecli.campaign.analysis`); never saves.

``campaign_figures(...)`` returns ``{name: Figure}``:

* grids: ``grid-OUTPUT`` (the output against each grid key: mean over the other keys, min-max band,
  the one-at-a-time view) and ``interaction-OUTPUT`` (each pair of grid keys: the output against
  the first, one line per value of the second);
* samples: ``distribution-OUTPUT`` (histogram and empirical CDF), ``scatter-OUTPUT`` (against each
  sampled input), ``tornado`` (Spearman rank correlation of every output with every input) and,
  with ``method: saltelli``, ``sobol`` (first- and total-order indices with 95 % intervals).
"""
from __future__ import annotations

import itertools
import re

import numpy as np
import pandas as pd

from tirecli.figures.style import COLORS, finish, new_figure, suptitle

#: Figures per kind are drawn for at most this many outputs (the first ones listed).
MAX_OUTPUTS = 12


def safe_name(text: str) -> str:
    """A file name for an output or key: ``stopping_distance[braking #1]`` -> ``stopping_distance-braking-1``."""
    return re.sub(r"[^A-Za-z0-9_.=-]+", "-", text).strip("-") or "output"


def _label(name: str, units: dict, what: str = "") -> str:
    """An axis label: ``distance [m]``, ``distance (mean) [m]`` with ``what``; the bare name when the unit is unknown."""
    unit = units.get(name)
    return f"{name}{what}" + (f" [{unit}]" if unit else "")


def _positions(values: pd.Series):
    """x positions of a key's values: the numbers, or 0..k-1 with the values as tick labels."""
    if pd.api.types.is_numeric_dtype(values):
        return values.to_numpy(dtype=float), None
    cats = list(dict.fromkeys(values.tolist()))
    return np.array([cats.index(v) for v in values], dtype=float), cats


def main_effects(results: pd.DataFrame, key: str, output: str) -> pd.DataFrame:
    """The output's mean, min and max over the other keys at each value of grid key ``key``."""
    g = results.groupby(key, sort=False)[output]
    return pd.DataFrame({key: list(g.groups), "mean": g.mean().to_numpy(), "min": g.min().to_numpy(),
                         "max": g.max().to_numpy()})


def _grid_effects(results, keys, output, title, units):
    n = len(keys)
    fig, axes = new_figure(ncols=min(n, 3), nrows=(n + 2) // 3, width=4.0 * min(n, 3), height=3.2 * ((n + 2) // 3))
    axes = np.atleast_1d(axes).ravel()
    for ax, key in zip(axes, keys):
        eff = main_effects(results, key, output)
        x, cats = _positions(eff[key])
        order = np.argsort(x, kind="stable")
        ax.fill_between(x[order], eff["min"].to_numpy()[order], eff["max"].to_numpy()[order], color=COLORS[0], alpha=0.2,
                        label="min-max over the other keys" if n > 1 else None)
        ax.plot(x[order], eff["mean"].to_numpy()[order], "o-", color=COLORS[0], label="mean" if n > 1 else None)
        if cats:
            ax.set_xticks(range(len(cats)), [str(c) for c in cats], fontsize=7)
        finish(ax, _label(key, units), _label(output, units), legend=ax is axes[0])
    for ax in axes[n:]:
        ax.set_visible(False)
    suptitle(fig, title)
    return fig


def _interactions(results, keys, output, title, units):
    pairs = list(itertools.permutations(keys, 2))[:6]
    # one line per value of the other key fills the panel: the legend (titled with that key) goes right of it
    fig, axes = new_figure(ncols=min(len(pairs), 3), nrows=(len(pairs) + 2) // 3, width=5.6 * min(len(pairs), 3),
                           height=3.2 * ((len(pairs) + 2) // 3))
    axes = np.atleast_1d(axes).ravel()
    for ax, (kx, kl) in zip(axes, pairs):
        g = results.groupby([kl, kx], sort=False)[output].mean().reset_index()
        levels = list(dict.fromkeys(g[kl].tolist()))
        for i, lev in enumerate(levels[:8]):
            sub = g[g[kl] == lev]
            x, cats = _positions(sub[kx])
            order = np.argsort(x, kind="stable")
            ax.plot(x[order], sub[output].to_numpy()[order], "o-", color=COLORS[i % len(COLORS)],
                    label=f"{lev:.4g}" if isinstance(lev, float) else f"{lev}")
            if cats:
                ax.set_xticks(range(len(cats)), [str(c) for c in cats], fontsize=7)
        finish(ax, _label(kx, units), _label(output, units, " (mean)"), legend=True, outside=True,
               legend_title=_label(kl, units))
    for ax in axes[len(pairs):]:
        ax.set_visible(False)
    suptitle(fig, title)
    return fig


def _distribution(x, output, title, units):
    fig, (a1, a2) = new_figure(ncols=2, width=9.0, height=3.4)
    fin = x[np.isfinite(x)]
    a1.hist(fin, bins=min(50, max(10, int(np.sqrt(fin.size)))), color=COLORS[0], alpha=0.8)
    finish(a1, _label(output, units), "points", legend=False)
    xs = np.sort(fin)
    a2.step(xs, np.arange(1, xs.size + 1) / xs.size, where="post", color=COLORS[0])
    for q, ls in ((0.05, ":"), (0.5, "--"), (0.95, ":")):
        v = np.quantile(xs, q)
        a2.axvline(v, color="0.4", ls=ls, lw=0.8, label=f"{int(q * 100)} %: {v:.4g}")
    finish(a2, _label(output, units), "cumulative fraction [-]", legend=True, loc="lower right")
    missing = x.size - fin.size
    suptitle(fig, title + (f" ({missing} point(s) without a value left out)" if missing else ""))
    return fig


def _scatter(results, inputs, output, title, units):
    n = len(inputs)
    fig, axes = new_figure(ncols=min(n, 3), nrows=(n + 2) // 3, width=4.0 * min(n, 3), height=3.2 * ((n + 2) // 3))
    axes = np.atleast_1d(axes).ravel()
    y = results[output].to_numpy(dtype=float)
    for ax, key in zip(axes, inputs):
        x, cats = _positions(results[key])
        ax.plot(x, y, ".", ms=2 if len(y) > 2000 else 4, alpha=0.5, color=COLORS[0])
        if cats:
            ax.set_xticks(range(len(cats)), [str(c) for c in cats], fontsize=7)
        finish(ax, _label(key, units), _label(output, units), legend=False)
    for ax in axes[n:]:
        ax.set_visible(False)
    suptitle(fig, title)
    return fig


def _tornado(torn: dict, title):
    outs = list(torn)[:MAX_OUTPUTS]
    n = len(outs)
    k = max(len(torn[o]) for o in outs)
    fig, axes = new_figure(ncols=min(n, 3), nrows=(n + 2) // 3, width=4.2 * min(n, 3),
                           height=max(2.4, 1.0 + 0.45 * k) * ((n + 2) // 3))
    axes = np.atleast_1d(axes).ravel()
    for ax, o in zip(axes, outs):
        rows = torn[o][::-1]
        rho = [r["rho"] if np.isfinite(r["rho"]) else 0.0 for r in rows]
        ax.barh(range(len(rows)), rho, color=[COLORS[1] if v < 0 else COLORS[0] for v in rho])
        ax.set_yticks(range(len(rows)), [r["input"] for r in rows], fontsize=8)
        ax.axvline(0.0, color="0.3", lw=0.8)
        ax.set_xlim(-1.05, 1.05)
        finish(ax, "Spearman rank correlation [-]", "", title=o, legend=False)
    for ax in axes[n:]:
        ax.set_visible(False)
    suptitle(fig, title)
    return fig


def _sobol(sob: dict, title):
    outs = [o for o in sob if sob[o]["indices"]][:MAX_OUTPUTS]
    if not outs:
        return None
    n = len(outs)
    fig, axes = new_figure(ncols=min(n, 2), nrows=(n + 1) // 2, width=5.2 * min(n, 2), height=3.4 * ((n + 1) // 2))
    axes = np.atleast_1d(axes).ravel()
    for ax, o in zip(axes, outs):
        rows = sob[o]["indices"]
        cells = sorted({r["cell"] for r in rows})
        inputs = list(dict.fromkeys(r["input"] for r in rows))
        width = 0.8 / (2 * len(cells))
        for c_i, cell in enumerate(cells[:4]):
            rs = {r["input"]: r for r in rows if r["cell"] == cell}
            x = np.arange(len(inputs))
            for j, (ind, col) in enumerate((("S1", COLORS[0]), ("ST", COLORS[1]))):
                off = (2 * c_i + j - len(cells) + 0.5) * width
                ax.bar(x + off, [rs[i][ind] for i in inputs], width, yerr=[rs[i][ind + "_conf"] for i in inputs],
                       color=col, alpha=1.0 - 0.25 * c_i, capsize=2,
                       label=(f"{'first order' if ind == 'S1' else 'total'}" + (f", cell {cell}" if len(cells) > 1 else "")))
        ax.set_xticks(range(len(inputs)), inputs, fontsize=8)
        ax.axhline(0.0, color="0.3", lw=0.8)
        finish(ax, "", "Sobol' index [-]", title=o, legend=True, loc="best")
    for ax in axes[n:]:
        ax.set_visible(False)
    suptitle(fig, title)
    return fig


def campaign_figures(design, results: pd.DataFrame, outputs: list, analysis: dict, name: str, units=None) -> dict:
    """The figures of a campaign (module doc) from its results frame (points that ran); ``outputs``: the
    numeric output columns (:func:`tirecli.campaign.analysis.numeric_outputs`), the first
    :data:`MAX_OUTPUTS` drawn; ``units``: ``{column: unit}`` of the inputs and outputs whose unit is
    known (axis labels ``distance [m]``)."""
    units = units or {}
    ok = results[results["status"] == "ok"]
    figs = {}
    if not len(ok):
        return figs
    outs = list(outputs)[:MAX_OUTPUTS]
    for o in outs:
        if ok[o].notna().sum() == 0:
            continue
        tag = safe_name(o)
        if design.grid_keys:
            figs[f"grid-{tag}"] = _grid_effects(ok, design.grid_keys, o, f"{name}: {o} against each grid key", units)
            if len(design.grid_keys) > 1:
                figs[f"interaction-{tag}"] = _interactions(ok, design.grid_keys, o,
                                                            f"{name}: {o}, interactions of the grid keys", units)
        if design.sample_keys:
            figs[f"distribution-{tag}"] = _distribution(ok[o].to_numpy(dtype=float), o,
                                                        f"{name}: distribution of {o} over {len(ok)} points", units)
            figs[f"scatter-{tag}"] = _scatter(ok, design.sample_keys, o, f"{name}: {o} against the sampled inputs", units)
    if design.sample_keys and analysis.get("tornado"):
        torn = {o: rows for o, rows in analysis["tornado"].items()
                if rows and o in outs and any(np.isfinite(r["rho"]) for r in rows)}
        if torn:
            figs["tornado"] = _tornado(torn, f"{name}: sensitivity (rank correlation of each output with each input)")
    if analysis.get("sobol"):
        fig = _sobol(analysis["sobol"], f"{name}: Sobol' indices (95 % intervals)")
        if fig is not None:
            figs["sobol"] = fig
    return figs


__all__ = ["campaign_figures", "safe_name"]
