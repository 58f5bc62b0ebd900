"""Shared look of tirecli figures (matplotlib object API; no pyplot state, never saves).

matplotlib is imported when the first figure is made, not with this module: checking a config
(its ``figures:`` ids import the figure modules) stays fast, so a refused run fails at once.
"""
from __future__ import annotations

#: A colour cycle readable in print and for colour-blind readers (Okabe-Ito; its yellow, faint on white, last).
COLORS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#F0E442"]
LINESTYLES = ["-", "--", "-.", ":"]

#: The widest figure [in]: the six-panel Magic Formula sweeps (12.5 in, 1375 px at the report's 110 px per inch).
MAX_WIDTH = 12.5
#: The widest shape (width / height) of a figure. A wider strip is shrunk to the width of a phone (or of a
#: text column) until its panels are too low to read; its panels belong in rows. :func:`new_figure` makes a
#: figure at least ``width / MAX_ASPECT`` high.
MAX_ASPECT = 2.5
#: At most this many panels side by side (each then keeps about 3.5 in of a figure's width or more).
MAX_COLUMNS = 3


def figure(**kw):
    """A matplotlib ``Figure`` (Agg backend unless one was chosen)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    return Figure(**kw)


def new_figure(ncols: int = 1, nrows: int = 1, width: float = 6.4, height: float = 4.2, **kw):
    """A figure and its axes array (squeezed like ``plt.subplots``), at least ``width / MAX_ASPECT`` high."""
    fig = figure(figsize=(width, max(height, width / MAX_ASPECT)), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


def finish(ax, xlabel: str, ylabel: str, title: str | None = None, legend: bool = True, outside: bool = False,
           legend_title: str | None = None, **legend_kw):
    """Label axes (with units), add a grid and a legend (``outside``: right of the axes, never over a
    curve; for panels whose curves fill every corner; ``legend_title`` above its entries)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if legend and ax.get_legend_handles_labels()[0]:
        if outside:
            legend_kw = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0,
                         "frameon": False, **legend_kw}
        if legend_title:
            legend_kw = {"title": legend_title, "title_fontsize": 8, **legend_kw}
        ax.legend(fontsize=8, **legend_kw)


def readable_3d(ax, nbins: int = 4, fontsize: float = 8) -> None:
    """Few, legible tick labels on the three axes of a 3-D panel (at most ``nbins + 1`` per axis, at
    ``fontsize`` points): matplotlib's default crowds 7-9 labels along each foreshortened edge."""
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(nbins=nbins))
    ax.tick_params(labelsize=fontsize)


def direct_labels(ax, ends, fontsize: float = 8, min_gap: float = 0.07) -> None:
    """Name curves at their ends instead of in a legend.

    ``ends`` is a list of ``(x, y, text, color)``: each text is written just right of its curve's end
    ``(x, y)`` in the curve's colour. Texts closer than ``min_gap`` of the panel's height are moved apart
    (kept inside the panel). Set the panel's limits first (and leave room right of the curves): the
    texts are placed in data coordinates.
    """
    if not ends:
        return
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    gap = min_gap * (y1 - y0)
    order = sorted(range(len(ends)), key=lambda k: ends[k][1])
    ys = [min(max(ends[k][1], y0 + 0.5 * gap), y1 - 0.5 * gap) for k in order]
    for i in range(1, len(ys)):  # push up what sits too close above its neighbour...
        ys[i] = max(ys[i], ys[i - 1] + gap)
    if ys[-1] > y1 - 0.5 * gap:  # ...and back down from the top edge
        ys[-1] = y1 - 0.5 * gap
        for i in range(len(ys) - 2, -1, -1):
            ys[i] = min(ys[i], ys[i + 1] - gap)
    for k, y in zip(order, ys):
        x, _, text, color = ends[k]
        ax.text(x + 0.012 * (x1 - x0), y, text, color=color, fontsize=fontsize, ha="left", va="center")


def suptitle(fig, text: str, fontsize: float = 10, **kw):
    """The figure's title, wrapped to the figure's width: a constrained layout makes room for
    several lines but never shortens one, and a line wider than the figure runs off both edges.

    The wrap width assumes an average character of 0.6 em (DejaVu Sans, mixed text), in points:
    ``width [in] * 72 / (0.6 * fontsize)`` characters. ``kw`` go to ``Figure.suptitle`` (e.g. ``y``, ``va``).
    """
    import textwrap

    chars = max(20, int(fig.get_figwidth() * 72.0 / (0.6 * fontsize)))
    return fig.suptitle("\n".join(textwrap.wrap(text, chars)) or text, fontsize=fontsize, **kw)


def legend_room(ax, frac: float = 0.3, where: str = "bottom") -> None:
    """Extend the y-range of ``ax`` by ``frac`` of its span at the bottom (or top), so that a legend
    placed at that edge stays clear of the curves."""
    lo, hi = ax.get_ylim()
    span = hi - lo
    ax.set_ylim((lo - frac * span, hi) if where == "bottom" else (lo, hi + frac * span))


def synthetic_mark(fig, text: str = "SYNTHETIC DATA (generated by tirecli, not measured)", top: float | None = None):
    """Label a figure that shows synthetic 'measured' data.

    With a constrained layout the axes are kept below ``top`` (figure fraction; default: 0.22 inch
    below the top edge, the label's height) so titles do not run into the label.
    """
    if top is None:
        top = 1.0 - 0.22 / fig.get_figheight()
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set") and "rect" in engine.get():
        engine.set(rect=(0.0, 0.0, 1.0, top))
    fig.text(0.5, 0.995, text, ha="center", va="top", fontsize=8, color="#B00020")


#: Up to this many cases are told apart by colour, line style and a legend; more are coloured along a colour scale.
MAX_LEGEND = 12


class CaseScale:
    """Colours of many cases along a colour scale (viridis), with what the scale means.

    When every label is the same text with one number that changes (``T_max = 950 N m``,
    ``T_max = 1000 N m``...), the cases are coloured by that number and the scale is labelled with
    the text around it (``T_max [N m]``); otherwise by their position in the config.
    """

    def __init__(self, labels: list[str], cmap: str = "viridis"):
        import matplotlib as mpl

        values, label = _numbered(labels)
        if values is None:
            values = list(range(1, len(labels) + 1))
            label = "case number (order of the config)"
        lo, hi = min(values), max(values)
        self.norm = mpl.colors.Normalize(lo, hi if hi > lo else lo + 1)
        self.cmap = mpl.colormaps[cmap]
        self.colors = [self.cmap(self.norm(v)) for v in values]
        self.label = label

    def colorbar(self, fig, axes, **kw):
        """A colour bar of the scale beside ``axes`` (an Axes or a list of them)."""
        import matplotlib as mpl

        sm = mpl.cm.ScalarMappable(norm=self.norm, cmap=self.cmap)
        cb = fig.colorbar(sm, ax=axes, **kw)
        cb.set_label(self.label, fontsize=9)
        return cb


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _numbered(labels: list[str]):
    """(values, axis label) when the labels differ only in one number, else (None, None)."""
    import re

    if len(labels) < 2:
        return None, None
    texts = [re.split(_NUM, lab) for lab in labels]
    nums = [re.findall(_NUM, lab) for lab in labels]
    if any(t != texts[0] for t in texts) or not nums[0]:
        return None, None
    varying = [j for j in range(len(nums[0])) if len({n[j] for n in nums}) > 1]
    if len(varying) != 1:
        return None, None
    j = varying[0]
    before = re.split(r"[,;(]", texts[0][j])[-1].strip().rstrip("=:#").strip()
    after = re.split(r"[,;()]", texts[0][j + 1])[0].strip().strip("[]").strip()
    label = (before or "value") + (f" [{after}]" if after else "")
    if len(before) <= 2 and not after:  # a bare prefix (labels c000, c001...): say where the number is from
        label += " (number in the case labels)"
    return [float(n[j]) for n in nums], label
