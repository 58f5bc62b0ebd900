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


@pytest.mark.parametrize("config", _builtin_configs())
def test_legends_stay_off_the_curves(config):
    """No legend inside a panel of a report figure covers its panel's curves (the MF six-panel tyre figures'
    camber legend, the transient fit's and MCPS Fig. 3's did)."""
    for fid, fig in _study_figures(config):
        assert _legends_over_curves(fig) == [], fid


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
