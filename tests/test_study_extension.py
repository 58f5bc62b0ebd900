"""A study added at runtime, without touching any module of tirecli, runs through a ``simulate``-style
command, ``report --only`` and a two-point campaign: the CLI, the report and campaigns use only its
registry entry (tirecli.studies.study.Study).

The test study: a first-order lag driven by a unit step, ``x(t) = 1 - exp(-t/tau)`` (a closed form):
its rise time to 63.2 % is ``tau``; its figure's reference check compares the rise time read off the
samples with ``tau``.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

NAME, FIGURE, CONFIG = "test-lag", "test-lag-step", "test-lag-report"


def _study():
    from tirecli.config.schema import Map, Num
    from tirecli.limits import Estimate
    from tirecli.studies.base import Check, StudyResult, common_fields
    from tirecli.studies.study import Line, Plan, Study

    spec = Map(fields=common_fields() | {
        "tau": Num(unit="s", gt=0, doc="time constant"),
        "t_end": Num(unit="s", gt=0, default=1.0, doc="end time"),
        "points": Num(unit="-", integer=True, ge=2, default=2001, doc="output points"),
    })

    def plan(config):
        checked = config.checked(spec)
        est = Estimate().add(checked["points"], (("points",),), "data/lag.csv", 100)
        est.check(config.origins)
        return Plan(NAME, config, checked, {}, est, detail=float(checked["tau"]))

    def run(plan_, progress=None):
        import pandas as pd

        tau, c = plan_.detail, plan_.checked
        t = np.linspace(0.0, c["t_end"], int(c["points"]))
        x = 1.0 - np.exp(-t / tau)
        rise = float(np.interp(1.0 - math.exp(-1.0), x, t))
        return StudyResult(study=NAME, config=plan_.config, parameter_sets={},
                           data={"lag": pd.DataFrame({"t": t, "x": x})},
                           meta={"title": c["title"], "tau_s": tau, "facts": {"rise_time_s": rise, "final": float(x[-1])}},
                           figures=c["figures"] or [FIGURE])

    def checks(result):
        return [Check("rise-time", "time to 63.2 % read off the samples", result.meta["facts"]["rise_time_s"],
                      result.meta["tau_s"], 1e-4, "s", "closed form: tau")]

    def summary(result):
        return [f"  rise time {result.meta['facts']['rise_time_s']:.4f} s", Line("a note", "note")]

    return Study(name=NAME, command="simulate", spec=spec, plan=plan, run=run, figures=(FIGURE,),
                 checks={FIGURE: checks}, summary=summary, fact_units={"rise_time_s": "s", "final": "-"},
                 primary_frame="lag")


def _draw(result):
    import matplotlib.figure

    fig = matplotlib.figure.Figure(figsize=(4, 3))
    ax = fig.add_subplot()
    ax.plot(result.data["lag"]["t"], result.data["lag"]["x"])
    return fig


@pytest.fixture
def registered():
    """The test study, its figure and its report config registered (and removed again afterwards)."""
    from tirecli.figures import registry as figures
    from tirecli.studies import registry
    from tirecli.studies.configs import register_config, unregister_config

    study = registry.register(_study())
    figures.register(FIGURE, paper="TEST", label="step", title="First-order lag", caption="x(t) = 1 - exp(-t/tau)",
                     study=CONFIG)(_draw)
    register_config(CONFIG, f"study: {NAME}\ntitle: lag\ntau: 0.1\nfigures: [{FIGURE}]\n")
    try:
        yield study
    finally:
        registry.unregister(NAME)
        figures.REGISTRY.pop(FIGURE, None)
        unregister_config(CONFIG)


def test_the_study_runs_through_a_simulate_style_command(registered, tmp_path, capsys):
    from tirecli.cli.main import main

    cfg = tmp_path / "lag.yaml"
    cfg.write_text(f"study: {NAME}\ntau: 0.2\nfigures: [{FIGURE}]\n")
    assert main(["simulate", str(cfg), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "  rise time 0.2000 s" in out and "a note" in out
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["study"] == NAME and run["outputs"]["data"] == ["data/lag.csv"]
    assert run["outputs"]["figures"] == [f"figures/{FIGURE}.png", f"figures/{FIGURE}.svg"]
    (check,) = run["checks"]
    assert check["id"] == f"{FIGURE}/rise-time" and check["passed"] and abs(check["value"] - 0.2) < 1e-4
    assert main(["params", "validate", str(cfg)]) == 0 and f"valid {NAME} config" in capsys.readouterr().out
    # --quiet hides the note, not the result line
    assert main(["--quiet", "simulate", str(cfg), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "rise time" in out and "a note" not in out
    # its command is simulate: another command names it, a bad value is one line at its key
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "o2")]) == 2
    assert f"{cfg}:1: study: this config is for 'tirecli simulate', not 'tirecli sweep'" in capsys.readouterr().err
    cfg.write_text(f"study: {NAME}\ntau: -1\n")
    assert main(["simulate", str(cfg), "--out", str(tmp_path / "o3")]) == 2
    assert f"{cfg}:2: tau: out of range: must be > 0, got -1" in capsys.readouterr().err
    assert not (tmp_path / "o3").exists()


def test_the_study_is_in_the_report(registered, tmp_path, capsys):
    from tirecli.cli.main import main

    rep = tmp_path / "rep"
    assert main(["--quiet", "report", "--only", FIGURE, "--out", str(rep), "--jobs", "1", "--no-cache"]) == 0
    summary = json.loads((rep / "summary.json").read_text())
    assert summary["n_figures"] == 1 and summary["n_failed"] == 0
    assert [c["id"] for c in summary["checks"]] == [f"{FIGURE}/rise-time"]
    assert (rep / "data" / CONFIG / "lag.csv").is_file() and (rep / "figures" / f"{FIGURE}.png").is_file()
    assert json.loads((rep / "studies" / f"{CONFIG}.json").read_text())["study"] == NAME


def test_the_study_is_a_campaign_base(registered, tmp_path, capsys):
    from tirecli.cli.main import main

    camp = tmp_path / "camp.yaml"
    camp.write_text(f"campaign: lag-grid\nbase: {CONFIG}\nvary: {{tau: [0.1, 0.25]}}\noutputs: [rise_time_s]\n"
                    "keep: timeseries\nfigures: false\n")
    assert main(["--quiet", "campaign", str(camp), "--out", str(tmp_path / "c"), "-j", "1"]) == 0
    import pandas as pd

    res = pd.read_csv(tmp_path / "c" / "results.csv")
    assert list(res["status"]) == ["ok", "ok"]
    assert np.abs(res["rise_time_s"] - res["tau"]).max() < 1e-4  # the closed form at both points
    kept = pd.read_parquet(tmp_path / "c" / "timeseries")        # keep: timeseries keeps the primary frame
    assert {"t", "x"} <= set(kept.columns) and len(kept) == 2 * 2001


def test_the_study_through_the_python_api(registered):
    import tirecli

    r = tirecli.run({"study": NAME, "tau": 0.05, "figures": [FIGURE]}, set=["points=4001"])
    assert set(r.frames) == {"lag"} and len(r.frames["lag"]) == 4001
    assert abs(r.facts["rise_time_s"] - 0.05) < 1e-4 and r.facts["final"] == pytest.approx(1 - math.exp(-20))
    assert [(c.id, c.status) for c in r.checks] == [(f"{FIGURE}/rise-time", "passed")]
