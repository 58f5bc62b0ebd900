"""Figures stay readable: many cases on a colour scale, no empty panels, legends off the curves,
a case far larger than the others on panels of its own."""
from types import SimpleNamespace

import numpy as np
import pytest

MANY = """\
study: simulate
title: many brakings
tire: canudas2003-table2
t_end: 0.3
cases:
{cases}
"""


@pytest.fixture(scope="module")
def many_cases(tmp_path_factory):
    """14 short lumped brakings that differ only in their torque (more than a legend can tell apart)."""
    from tirecli.config.loader import load_config
    from tirecli.studies.registry import run_study

    cases = "\n".join(f'  - {{model: lumped, kappa0: Z, label: "T_max = {600 + 50 * k} N m", '
                      f'input: {{brake_torque: {{table: {{t: [0, 0.3], value: [0, {600 + 50 * k}]}}}}}}}}'
                      for k in range(14))
    cfg = tmp_path_factory.mktemp("many") / "many.yaml"
    cfg.write_text(MANY.format(cases=cases))
    return run_study(load_config(cfg))


@pytest.mark.parametrize("fid", ["transient-histories", "transient-mu-slip", "transient-overlay"])
def test_many_cases_get_a_colour_scale_instead_of_a_legend(many_cases, fid):
    from tirecli.figures.registry import get

    fig = get(fid).draw(many_cases)
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(bars) == 1 and bars[0].get_ylabel() == "T_max [N m]"
    assert bars[0].get_ylim() == pytest.approx((600, 1250))
    entries = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert not any(e.startswith("T_max") for e in entries)  # no legend entry per case
    if fid == "transient-overlay":  # no two cases share inputs: the friction panel alone, no empty panels
        assert len([ax for ax in fig.axes if ax not in bars]) == 1


def test_colour_scale_reads_the_number_that_changes():
    from tirecli.figures.style import CaseScale, _numbered

    assert _numbered(["T_max = 950 N m", "T_max = 1000 N m"]) == ([950.0, 1000.0], "T_max [N m]")
    assert _numbered(["a, T = 1 [s], v = 20 m/s", "a, T = 2 [s], v = 20 m/s"]) == ([1.0, 2.0], "T [s]")
    assert _numbered(["braking #1", "braking #2"]) == ([1.0, 2.0], "braking")
    assert _numbered(["c000", "c001"]) == ([0.0, 1.0], "c (number in the case labels)")
    assert _numbered(["dry", "wet"]) == (None, None)
    assert _numbered(["v = 1, T = 2", "v = 2, T = 3"]) == (None, None)  # two numbers change: no single scale
    scale = CaseScale(["dry", "wet", "snow"])
    assert scale.label.startswith("case number") and scale.colors[0] != scale.colors[-1]


def test_a_few_cases_keep_their_legend():
    from tirecli.figures.style import MAX_LEGEND
    from tirecli.figures.transient import _case_styles

    cases = [SimpleNamespace(mode="coupled", label=f"case {k}") for k in range(MAX_LEGEND)]
    styles, scale = _case_styles(cases)
    assert scale is None and len({(s["color"], s["ls"]) for s in styles}) == MAX_LEGEND


def test_runs_far_apart_in_error_get_panels_of_their_own():
    from tirecli.figures.observer import _split_by_size

    t = np.linspace(0, 1, 50)

    def run(err):
        return (SimpleNamespace(label=str(err)), SimpleNamespace(theta=np.ones_like(t), theta_hat=1 + err * t), None)

    runs = [run(0.0), run(0.01), run(0.02), run(1.0), run(2.0)]
    small, large = _split_by_size(runs)
    assert [r[0].label for r in small] == ["0.0", "0.01", "0.02"] and [r[0].label for r in large] == ["1.0", "2.0"]
    assert _split_by_size(runs[1:3]) == [runs[1:3]]


def _drawn(fig):
    """Lay out and render ``fig`` on an Agg canvas (a bare Figure's canvas draws nothing), so the
    legends' and axes' extents are the saved file's."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    return fig


def test_legends_outside_stay_off_the_axes():
    """An ``outside`` legend (style.finish) sits right of its axes, never over the curves."""
    from tirecli.figures.style import finish, new_figure

    fig, ax = new_figure()
    for k in range(5):
        ax.plot(np.cos(np.linspace(0, 6, 50)) * (k + 1), np.sin(np.linspace(0, 6, 50)) * (k + 1), label=f"c{k}")
    finish(ax, "x", "y", outside=True)
    _drawn(fig)
    leg = ax.get_legend().get_window_extent()
    assert leg.x0 >= ax.get_window_extent().x1


def test_many_cases_histories_mark_locks_without_shading_and_show_the_torque_band(many_cases):
    """With a colour scale, per-case lock shadings would cover the slip panel: only their ends are
    marked; the right axis shows the band of all cases' brake torques (not one case's torque)."""
    import matplotlib

    from tirecli.figures.registry import get

    fig = get("transient-histories").draw(many_cases)
    locks = sum(len(tr.events["lock"]) for tr in many_cases.payload["runs"].values())
    slip_ax = [ax for ax in fig.axes if ax.get_ylabel().startswith("slip")][0]
    assert not [p for p in slip_ax.patches if isinstance(p, matplotlib.patches.Polygon | matplotlib.patches.Rectangle)]
    if locks:
        assert any(line.get_marker() == "v" for line in slip_ax.lines)
    twins = [ax for ax in fig.axes if ax.get_ylabel().startswith("brake torque")]
    assert len(twins) == 1 and "band of the 14 coupled cases" in twins[0].get_ylabel()
    lo, hi = twins[0].get_ylim()
    assert lo <= 0 and hi >= 1250  # every case's peak torque is inside the band


def _legends_over_curves(fig) -> list[str]:
    """The in-panel legends of ``fig`` (laid out as saved) that cover a point of a line of their panel,
    the segments between the points included: ``["panel title: line label", ...]``."""
    _drawn(fig)
    found = []
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        box, axb = leg.get_window_extent(), ax.get_window_extent()
        if box.x0 >= axb.x1 - 1 or box.x1 <= axb.x0 + 1 or box.y1 <= axb.y0 + 1 or box.y0 >= axb.y1 - 1:
            continue  # outside the panel
        for line in ax.lines:
            xy = line.get_transform().transform(line.get_xydata())
            if len(xy) < 2:
                continue
            f = np.linspace(0.0, 1.0, 21)[:, None, None]
            xy = (xy[:-1] + f * (xy[1:] - xy[:-1])).reshape(-1, 2)
            if ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0) & (xy[:, 1] < box.y1)).any():
                found.append(f"{ax.get_title()}: {line.get_label()}")
    return found


def _study_figures(config: str):
    from tirecli.figures.registry import get
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    res = run_study(builtin_config(config))
    for fid in res.figures:
        fig = get(fid).draw(res)
        if hasattr(fig, "savefig"):  # tables are not drawn
            yield fid, fig


def _builtin_configs():
    from tirecli.studies.configs import builtin_config_names

    return builtin_config_names()


def _is_colorbar(ax) -> bool:
    return ax.get_label() == "<colorbar>" or getattr(ax, "_colorbar", None) is not None


def _labels_without_unit(fig) -> list[str]:
    """The axis labels of ``fig`` (x, y, z of every panel, colour bars included) that name no unit in
    brackets (``[N]``, ``[-]`` for a number without a unit): ``["panel title: label", ...]``. An empty label
    (a panel sharing its neighbour's) is fine."""
    import re

    found = []
    for ax in fig.axes:
        labels = [ax.get_xlabel(), ax.get_ylabel()] + ([ax.get_zlabel()] if ax.name == "3d" else [])
        found += [f"{ax.get_title() or ax.get_label()}: {lab!r}" for lab in labels
                  if lab.strip() and not re.search(r"\[[^\]]+\]", lab)]
    return found


def _panels_side_by_side(fig) -> int:
    """The largest number of panels (colour bars and twin axes not counted) on one horizontal line of ``fig``."""
    boxes = {tuple(np.round(ax.get_position().bounds, 2)) for ax in fig.axes
             if ax.get_visible() and not _is_colorbar(ax)}
    return max((sum(1 for _, y2, _, h2 in boxes if y2 <= y + h / 2 <= y2 + h2) for _, y, _, h in boxes), default=0)


def _too_wide(fig) -> list[str]:
    """What makes ``fig`` a strip a phone (or a text column) shrinks until it cannot be read: wider than
    style.MAX_WIDTH, flatter than style.MAX_ASPECT, more than style.MAX_COLUMNS panels side by side."""
    from tirecli.figures.style import MAX_ASPECT, MAX_COLUMNS, MAX_WIDTH

    w, h = fig.get_size_inches()
    n = _panels_side_by_side(fig)
    return [text for bad, text in ((w > MAX_WIDTH + 1e-9, f"{w:g} in wide (at most {MAX_WIDTH:g})"),
                                   (w > MAX_ASPECT * h + 1e-9,
                                    f"{w:g} x {h:g} in: {w / h:.2f} times as wide as high (at most {MAX_ASPECT:g})"),
                                   (n > MAX_COLUMNS, f"{n} panels side by side (at most {MAX_COLUMNS})")) if bad]


def _unreadable_3d(fig, most: int = 6, smallest: float = 8.0, room: float = 4.0) -> list[str]:
    """The 3-D panels of ``fig`` (laid out as saved) whose tick labels cannot be read: more than ``most``
    on an axis, smaller than ``smallest`` points, or overlapping each other; or a panel narrower than
    ``room`` inches (the cramped 3-D panel of the old FM Fig. 6)."""
    renderer = fig.canvas.get_renderer()
    found = []
    for ax in fig.axes:
        if ax.name != "3d":
            continue
        width = ax.get_position(original=True).width * fig.get_figwidth()
        if width < room:
            found.append(f"{ax.get_title()}: {width:.2f} in wide")
        for name, axis in (("x", ax.xaxis), ("y", ax.yaxis), ("z", ax.zaxis)):
            locs = axis.get_majorticklocs()
            lo, hi = sorted(axis.get_view_interval())
            eps = 1e-9 * (hi - lo or 1.0)
            labels = [t.label1 for t, loc in zip(axis.get_major_ticks(len(locs)), locs)
                      if lo - eps <= loc <= hi + eps and t.label1.get_visible() and t.label1.get_text()]
            boxes = [lab.get_window_extent(renderer).padded(-2.0) for lab in labels]  # 2 px: the glyphs' margin
            if len(labels) > most:
                found.append(f"{ax.get_title()}: {len(labels)} tick labels on {name}")
            found += [f"{ax.get_title()}: {name} tick label {lab.get_text()!r} at {lab.get_fontsize():g} pt"
                      for lab in labels if lab.get_fontsize() < smallest]
            found += [f"{ax.get_title()}: {name} tick labels {labels[i].get_text()!r} and {labels[j].get_text()!r} "
                      "overlap" for i in range(len(boxes)) for j in range(i + 1, len(boxes)) if boxes[i].overlaps(boxes[j])]
    return found


def _texts(fig) -> list[str]:
    """Every text ``fig`` shows: titles, axis labels, legend entries and titles, free texts."""
    out = [fig.get_suptitle()] + [t.get_text() for t in fig.texts]
    legends = list(fig.legends)
    for ax in fig.axes:
        out += [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()] + [t.get_text() for t in ax.texts]
        legends += [ax.get_legend()] if ax.get_legend() is not None else []
    for leg in legends:
        out += [leg.get_title().get_text()] + [t.get_text() for t in leg.get_texts()]
    return out


def _fig4_as_panels(fig):
    """MCPS Fig. 4: the surface f_y(xi, t) as a map over (xi, t) above the profiles at the reversals, no 3-D
    panel, one legend for the figure (the reversal lines on the map and the profiles share it)."""
    panels = [ax for ax in fig.axes if not _is_colorbar(ax)]
    assert [ax.name for ax in panels] == ["rectilinear", "rectilinear"]
    assert len(fig.legends) == 1 and not any(ax.get_legend() for ax in fig.axes)
    assert [ax.get_xlabel() for ax in panels] == ["", "patch abscissa xi [mm] (forward)"]  # one xi axis for both
    assert [ax.get_ylabel() for ax in fig.axes if _is_colorbar(ax)] == ["f_y [kN/m]"]


def _fig10_by_model(fig):
    """MCPS Fig. 10: one column per model, -Fy above Mz (an Mz curve never shares a panel with an Fy
    curve), one colour per slip angle, each curve named at its end in its colour, no legend."""
    assert not fig.legends and not any(ax.get_legend() for ax in fig.axes)
    rows = {}
    for ax in fig.axes:
        rows.setdefault(round(ax.get_position().y0, 2), []).append(ax)
    top, bottom = (rows[y] for y in sorted(rows, reverse=True))
    assert len(top) == len(bottom) >= 3  # MCPS complete, MCPS solid carcass, the Magic Formula
    assert top[0].get_ylabel().startswith("side force -Fy") and bottom[0].get_ylabel().startswith("aligning torque Mz")
    import matplotlib.colors as mc

    for ax in top + bottom:
        colours = [mc.to_hex(line.get_color()) for line in ax.lines]
        names = {t.get_text(): mc.to_hex(t.get_color()) for t in ax.texts}
        assert len(colours) == len(set(colours)) == len(names) == 3, ax.get_title()  # alpha_s = 1, 2, 4 deg
        assert sorted(names.values()) == sorted(colours) and all(n.endswith(" deg") for n in names)


def _fig5_says_what_is_not_modelled(fig):
    """FM Fig. 5: the image itself says that the paper's F_y and G_t are not modelled (not only the caption)."""
    text = " ".join(" ".join(_texts(fig)).split())  # wrapped lines joined
    assert "F_y" in text and "G_t" in text and "not modelled" in text


def _gain_study_with_units(fig):
    """The observer gain study: every value of the gain carries its unit, in the legend and on the axis."""
    entries = [t for t in _texts(fig) if t.startswith("gamma =")]
    assert len(entries) == 5 and all(e.endswith(" s/m") for e in entries), entries
    assert any(ax.get_xlabel().endswith("gamma [s/m]") for ax in fig.axes)


#: Rules of single report figures (figure id -> check of the drawn figure).
FIGURE_RULES = {"mcps-fig4": _fig4_as_panels, "mcps-fig10": _fig10_by_model, "fm-fig5": _fig5_says_what_is_not_modelled,
                "obs-gain-study": _gain_study_with_units}


@pytest.mark.parametrize("config", _builtin_configs())
def test_report_figures_are_readable(config):
    """Every figure of the report, laid out as saved:
    - no legend inside a panel covers its panel's curves (the MF six-panel tyre figures' camber legend,
      the transient fit's and MCPS Fig. 3's did);
    - every axis label names its unit in brackets (the gain study's gamma, the MF golden rows' row numbers);
    - it fits a phone: at most style.MAX_WIDTH wide, style.MAX_ASPECT times as wide as high and
      style.MAX_COLUMNS panels side by side (FM Fig. 6 was a 15.5 in strip of four);
    - a 3-D panel has room and a few legible tick labels that do not overlap (MCPS Fig. 4's did not);
    - and the rules of single figures (FIGURE_RULES)."""
    for fid, fig in _study_figures(config):
        assert _legends_over_curves(fig) == [], fid
        assert _labels_without_unit(fig) == [], fid
        assert _too_wide(fig) == [], fid
        assert _unreadable_3d(fig) == [], fid
        if fid in FIGURE_RULES:
            FIGURE_RULES[fid](fig)


def test_the_readability_rules_can_fail():
    """The rules of test_report_figures_are_readable catch what they are meant to: a label without a unit,
    a wide strip of four panels, a cramped 3-D panel with many small tick labels."""
    from tirecli.figures.style import figure, new_figure

    fig, axes = new_figure(ncols=4, width=15.5, height=4.9)
    axes[0].set_xlabel("gamma")
    axes[1].set_xlabel("gamma [s/m]")
    _drawn(fig)
    assert _labels_without_unit(fig) == [": 'gamma'"]
    assert _too_wide(fig) == ["15.5 in wide (at most 12.5)", "4 panels side by side (at most 3)"]
    fig, _ = new_figure(width=11.0, height=3.0)  # new_figure raises the height to the widest shape
    assert fig.get_figheight() == pytest.approx(11.0 / 2.5) and _too_wide(_drawn(fig)) == []
    fig = figure(figsize=(11.0, 4.0))
    ax = fig.add_axes((0.0, 0.0, 0.3, 1.0), projection="3d")
    ax.plot_surface(*np.meshgrid(np.linspace(0, 0.3, 5), np.linspace(5, 25, 5)), np.ones((5, 5)))
    ax.tick_params(labelsize=7)
    problems = _unreadable_3d(_drawn(fig))
    assert problems[0] == ": 3.30 in wide" and ": 7 tick labels on x" in problems
    assert ": x tick label '0.00' at 7 pt" in problems
    ax.tick_params(labelsize=9)
    ax.set_yticks(np.linspace(5, 25, 21))
    problems = _unreadable_3d(_drawn(fig))
    assert ": y tick labels '10' and '11' overlap" in problems and not any(" pt" in p for p in problems)


def test_campaign_figures_keep_their_title_inside_and_legends_off_the_curves():
    """A campaign's grid figures (examples/campaign-obs-convergence.yaml's results): the suptitle (the
    campaign's title and what the figure shows) stays inside the figure, wrapped if need be (it ran
    off both edges), and the interaction panels' legends (one line per value of the other key) cover
    no curve (the 2e5 line ran through one)."""
    from types import SimpleNamespace

    import pandas as pd

    from tirecli.figures.campaign import campaign_figures

    gammas, thetas = [5e4, 1e5, 2e5, 4e5, 8e5], [1.25, 1.6666666666666667, 2.5]
    conv = [2.8722, 2.9106, 2.8371, 2.5559, 2.7714, 2.7264, 1.0246, 1.4179, 1.2283,
            0.5013, 0.6827, 0.5898, 0.2483, 0.3362, 0.2914]
    keys = ["observer.gamma", "scenario.theta.changes[0].to"]
    results = pd.DataFrame({keys[0]: np.repeat(gammas, 3), keys[1]: np.tile(thetas, 5),
                            "convergence_time": conv, "status": "ok"})
    design = SimpleNamespace(grid_keys=keys, sample_keys=[])
    figs = campaign_figures(design, results, ["convergence_time"], {},
                            "Observer: convergence time over gamma and the wet road's theta")
    assert set(figs) == {"grid-convergence_time", "interaction-convergence_time"}
    for name, fig in figs.items():
        _drawn(fig)
        title = fig.get_suptitle() and fig._suptitle.get_window_extent()
        page = fig.bbox
        assert title.x0 >= page.x0 - 0.5 and title.x1 <= page.x1 + 0.5, name
        assert _legends_over_curves(fig) == [], name
        if name.startswith("interaction"):  # each legend names the key its lines are values of
            assert [ax.get_legend().get_title().get_text() for ax in fig.axes] == keys[::-1]
