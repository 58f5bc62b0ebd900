"""tirecli campaign: points checked before any run, identical results on every executor, resume,
failing points, determinism, Ctrl-C, time series, Sobol' indices, the report section.

The campaigns are small (Magic Formula points and short lumped brakings: milliseconds each) and
draw no figures unless the test is about them; one test starts a Dask LocalCluster (seconds).
"""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

pytest.importorskip("pyarrow")

MF_BASE = """base:
  study: mf-eval
  tire: pacejka2006-205-60r15
  points: {kappa: 0, alpha: 0.04, fz: 4000}
"""

BRAKING = """study: simulate
tire: canudas2003-table2
vehicle: canudas2003-obs-quarter-car
initial: {v: 20, slip: 0}
input:
  pressure: {table: {t: [0, 0.1, 0.4, 0.5], value: [0, 0, 50, 0]}}
t_end: 0.6
cases: [{model: lumped, kappa0: Z, label: braking}]
"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def mf_campaign(tmp_path, vary="  tire.LMUY: [0.6, 0.8, 1.0]\n  points.fz: [2000, 4000]\n", extra="figures: false\n",
                name="c.yaml"):
    return write(tmp_path, name, "campaign: mf\n" + MF_BASE + "vary:\n" + vary + "outputs: [fy, mz]\n" + extra)


def results(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "results.csv")


def test_grid_results_one_row_per_point(cli, tmp_path):
    c = mf_campaign(tmp_path)
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 0, err
    df = results(tmp_path / "o")
    assert list(df.columns) == ["point", "id", "tire.LMUY", "points.fz", "fy", "mz", "status", "error"]
    assert len(df) == 6 and (df["status"] == "ok").all() and df["id"].is_unique
    assert list(df["points.fz"]) == [2000, 4000] * 3
    # each row equals the base study run with the same overrides (as --set would give them)
    from tirecli.campaign.spec import load_campaign
    from tirecli.config.loader import apply_override
    from tirecli.studies.registry import run_study

    base = load_campaign(c).base
    apply_override(base.data, base.origins, "tire.LMUY=0.8")
    apply_override(base.data, base.origins, "points.fz=2000")
    assert run_study(base).meta["facts"]["fy"] == df.loc[2, "fy"]
    pq = pd.read_parquet(tmp_path / "o" / "results.parquet")
    assert pq["fy"].tolist() == df["fy"].tolist()
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["points"]["ok"] == 6 and summary["complete"]
    assert summary["checks"][0]["id"] == "points-ran" and summary["checks"][0]["passed"]


def test_local_cluster_equals_local_pool(cli, tmp_path):
    pytest.importorskip("distributed")
    c = mf_campaign(tmp_path, extra="figures: false\nbatch: 2\n")
    assert cli("campaign", c, "--out", tmp_path / "pool", "-j", "2")[0] == 0
    code, out, err = cli("campaign", c, "--out", tmp_path / "dask", "-j", "2", "--scheduler", "local")
    assert code == 0, err
    assert "dask local cluster" in out
    assert (tmp_path / "pool" / "results.csv").read_bytes() == (tmp_path / "dask" / "results.csv").read_bytes()


def test_resume_runs_only_the_missing_points(cli, tmp_path):
    small = mf_campaign(tmp_path, vary="  tire.LMUY: [0.6, 1.0]\n  points.fz: [2000, 4000]\n", name="small.yaml")
    big = mf_campaign(tmp_path, vary="  tire.LMUY: [0.6, 0.8, 1.0]\n  points.fz: [2000, 4000]\n", name="big.yaml")
    out = tmp_path / "o"
    assert cli("campaign", small, "--out", out, "-j", "1")[0] == 0
    code, text, err = cli("campaign", big, "--out", out, "-j", "1")
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["points"]["run_now"] == 2 and summary["points"]["resumed"] == 4
    assert "4 already done" in text
    code, text, err = cli("campaign", big, "--out", out, "-j", "1")
    assert json.loads((out / "summary.json").read_text())["points"]["run_now"] == 0
    fresh = tmp_path / "fresh"
    assert cli("campaign", big, "--out", fresh, "-j", "1")[0] == 0
    assert (out / "results.csv").read_bytes() == (fresh / "results.csv").read_bytes()


def test_a_failing_point_is_recorded_and_the_campaign_goes_on(cli, tmp_path, monkeypatch):
    from tirecli.campaign import facts
    from tirecli.errors import RunError

    real = facts.run_point

    def flaky(config, wanted=None, keep=False):
        if config.data["points"]["fz"] == 4000 and config.data["tire"]["LMUY"] == 0.8:
            raise RunError("time integration stopped (simulated failure)")
        return real(config, wanted, keep)

    monkeypatch.setattr(facts, "run_point", flaky)
    c = mf_campaign(tmp_path)
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 0, err
    df = results(tmp_path / "o")
    bad = df[df["status"] == "failed"]
    assert len(bad) == 1 and bad.iloc[0]["error"] == "time integration stopped (simulated failure)"
    assert pd.isna(bad.iloc[0]["fy"]) and (df["status"] == "ok").sum() == 5
    assert "point 3 failed: time integration stopped" in out
    assert "check failed: points-ran" in out
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1", "--strict", "--junit", tmp_path / "j.xml")
    assert code == 1  # the failed point runs again, and fails again
    xml = (tmp_path / "j.xml").read_text()
    assert 'classname="campaign mf"' in xml and 'name="points-ran"' in xml and "<failure" in xml
    monkeypatch.setattr(facts, "run_point", real)
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1", "--strict")
    assert code == 0, err
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["points"]["run_now"] == 1


def test_fixed_seed_is_deterministic(cli, tmp_path):
    def camp(seed, method, name):
        return write(tmp_path, name, "campaign: mc\n" + MF_BASE + f"""sample:
  n: 8
  seed: {seed}
  method: {method}
  tire.LMUY: {{uniform: [0.6, 1.0]}}
  points.fz: {{normal: [4000, 300]}}
  points.alpha: {{choice: [0.02, 0.04]}}
outputs: [fy]
figures: false
""")
    runs = {}
    for label, seed, method in (("a", 1, "random"), ("b", 1, "random"), ("c", 2, "random"), ("l", 1, "latin-hypercube")):
        c = camp(seed, method, f"{label}.yaml")
        assert cli("campaign", c, "--out", tmp_path / label, "-j", "2")[0] == 0
        runs[label] = (tmp_path / label / "results.csv").read_bytes()
    assert runs["a"] == runs["b"]
    assert runs["a"] != runs["c"] and runs["a"] != runs["l"]
    df = pd.read_csv(tmp_path / "l" / "results.csv")
    # latin hypercube: one sample in each of the 8 equal-probability strata of LMUY
    strata = sorted(((df["tire.LMUY"] - 0.6) / 0.4 * 8).astype(int))
    assert strata == list(range(8))


def test_bad_vary_key_fails_before_any_run(cli, tmp_path):
    c = mf_campaign(tmp_path, vary="  tire.LMUZ: [0.6, 0.8]\n")
    code, out, err = cli("campaign", c, "--out", tmp_path / "o")
    assert code == 2
    assert f"{c}:" in err and "tire.LMUZ" in err and "unknown" in err
    assert not (tmp_path / "o").exists()


def run_braking_campaign(cli, tmp_path, mu_s: str, outputs: str):
    """``tirecli campaign`` over BRAKING with ``vary: {tire.mu_s: MU_S}`` and ``outputs: OUTPUTS``."""
    c = write(tmp_path, "c.yaml", f"campaign: b\nbase: base.yaml\nvary:\n  tire.mu_s: {mu_s}\n"
                                  f"outputs: {outputs}\nfigures: false\n")
    write(tmp_path, "base.yaml", BRAKING)
    return cli("campaign", c, "--out", tmp_path / "o")


def test_bad_value_names_the_key_and_the_points(cli, tmp_path):
    code, out, err = run_braking_campaign(cli, tmp_path, "[1.5, 0.5]", "[v_final]")
    assert code == 2
    line = err.strip().splitlines()[0]
    # the problem as --set tire.mu_s=0.5 reports it, with the point that has it
    assert "tire.mu_c: out of range: must be <= mu_s (0.5)" in line
    assert "(in 1 of 2 points, e.g. point 1: tire.mu_s = 0.5)" in line
    assert not (tmp_path / "o").exists()


def test_unknown_output_fails_naming_it(cli, tmp_path):
    code, out, err = run_braking_campaign(cli, tmp_path, "[1.4, 1.6]", "[v_final, stoping_distance]")
    assert code == 2
    assert "outputs[1]" in err and "stoping_distance" in err and "did you mean 'stopping_distance'" in err
    # one plain line (not the quoted text of a KeyError), and no empty output folder left behind
    assert len(err.strip().splitlines()) == 1 and ": \"no fact" not in err and ": no fact named 'stoping_distance'" in err
    assert not (tmp_path / "o").exists()


def test_ctrl_c_keeps_finished_points_and_a_rerun_resumes(cli, tmp_path, monkeypatch):
    from tirecli.campaign import facts

    real = facts.run_point
    calls = []

    def interrupted(config, wanted=None, keep=False):
        calls.append(1)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return real(config, wanted, keep)

    monkeypatch.setattr(facts, "run_point", interrupted)
    c = mf_campaign(tmp_path)
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 130
    assert "interrupted: 3 of 6 points finished, kept in" in err
    assert len(results(tmp_path / "o")) == 3
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["complete"] is False
    monkeypatch.setattr(facts, "run_point", real)
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 0, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["points"]["run_now"] == 3 and summary["complete"]


def test_keep_timeseries_and_braking_facts(cli, tmp_path):
    write(tmp_path, "base.yaml", BRAKING)
    c = write(tmp_path, "c.yaml", """campaign: ts
base: base.yaml
vary:
  input.theta: [0.5, 1.0]
outputs: [peak_abs_slip, v_final, wheel_locks, stopping_distance]
keep: timeseries
checks:
  - {output: peak_abs_slip, max: 0.3}
  - {output: v_final, min: 10, statistic: mean}
figures: false
""")
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 0, err
    df = results(tmp_path / "o")
    ts = pd.read_parquet(tmp_path / "o" / "timeseries")
    assert set(ts["point"].astype(str)) == set(df["id"])
    assert {"t", "v", "slip", "mu"} <= set(ts.columns)
    one = ts[ts["point"].astype(str) == df["id"][0]]
    assert one["v"].iloc[-1] == pytest.approx(df["v_final"][0], abs=0.05)
    assert df["stopping_distance"].isna().all()  # 0.6 s: no braking stops
    # the facts equal those of the simulate command
    code, out, err = cli("simulate", tmp_path / "base.yaml", "--set", "input.theta=0.5", "--out", tmp_path / "s")
    ev = json.loads((tmp_path / "s" / "run.json").read_text())["meta"]["events"][0]
    assert ev["peak_abs_slip"] == df["peak_abs_slip"][0] and ev["v_final"] == df["v_final"][0]
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    ids = {c["id"]: c for c in summary["checks"]}
    assert set(ids) == {"points-ran", "peak_abs_slip-max", "v_final-min-mean"}
    assert ids["peak_abs_slip-max"]["value"] == df["peak_abs_slip"].max()
    assert ids["peak_abs_slip-max"]["passed"] == (df["peak_abs_slip"].max() <= 0.3)


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_figure_axes_carry_units(cli, tmp_path, monkeypatch):
    """Every axis of the campaign figures names its unit: the inputs' from the study's config schema and
    the parameter sets (tire.mu_s [-], input.theta [-], tire.sigma0 [1/m]), the facts' from their table."""
    from tirecli.figures import campaign as figures

    labels = {}
    real = figures.campaign_figures

    def spy(*args, **kw):  # the labels before the figures are saved and cleared
        figs = real(*args, **kw)
        for name, fig in figs.items():
            labels[name] = {t for ax in fig.axes if ax.get_visible() for t in (ax.get_xlabel(), ax.get_ylabel())
                            if t and t != "points"}
            labels[name] |= {ax.get_legend().get_title().get_text() for ax in fig.axes if ax.get_legend()} - {""}
        return figs

    monkeypatch.setattr(figures, "campaign_figures", spy)
    write(tmp_path, "base.yaml", BRAKING)
    c = write(tmp_path, "c.yaml", """campaign: u
base: base.yaml
vary:
  tire.mu_s: [1.4, 1.6]
  input.theta: [0.5, 1.0]
sample:
  n: 3
  seed: 1
  tire.sigma0: {uniform: [170, 190]}
outputs: [distance, v_final, wheel_locks]
""")
    code, out, err = cli("campaign", c, "--out", tmp_path / "o", "-j", "1")
    assert code == 0, err
    assert {"grid-distance", "interaction-distance", "distribution-distance", "scatter-distance", "tornado",
            "scatter-v_final"} <= set(labels)
    assert labels["grid-distance"] == {"tire.mu_s [-]", "input.theta [-]", "distance [m]"}
    assert labels["interaction-distance"] == {"tire.mu_s [-]", "input.theta [-]", "distance (mean) [m]"}
    assert labels["distribution-distance"] == {"distance [m]", "cumulative fraction [-]"}
    assert labels["scatter-v_final"] == {"tire.sigma0 [1/m]", "v_final [m/s]"}
    assert labels["grid-wheel_locks"] >= {"wheel_locks [-]"}
    assert labels["tornado"] == {"Spearman rank correlation [-]"}


def test_unknown_units_leave_the_bare_name():
    from tirecli.parameters.kinds import unit_at
    from tirecli.studies import registry
    from tirecli.studies.facts import fact_unit

    sim = registry.get("simulate")
    assert unit_at(sim.spec, ("tire", "sigma0")) == "1/m"
    assert unit_at(sim.spec, ("tire", "set")) is None  # the set's name: no number
    assert unit_at(sim.spec, ("cases", 0, "label")) is None
    assert fact_unit(sim, "stopping_distance[braking]") == "m" and fact_unit(sim, "end") is None
    # a study without a table of units: from the suffix of the name
    assert fact_unit(registry.get("mcps-slider"), "first_peak_force_N") == "N"
    assert fact_unit(registry.get("mcps-standstill"), "mz_at_minus_A_Nm") == "N m"
    assert fact_unit(registry.get("mcps-standstill"), "fast_rate_1_s") == "1/s"
    assert fact_unit(registry.get("mcps-stationary"), "C_kappa[stiffness, 4000 N]") is None
    from tirecli.figures.campaign import _label

    assert _label("C_kappa[stiffness, 4000 N]", {}) == "C_kappa[stiffness, 4000 N]"


def test_saltelli_sobol_indices_figures_and_report(cli, tmp_path, monkeypatch):
    pytest.importorskip("SALib")
    c = write(tmp_path, "c.yaml", "campaign: sob\n" + MF_BASE + """sample:
  n: 16
  seed: 3
  method: saltelli
  tire.LMUY: {uniform: [0.6, 1.0]}
  points.fz: {uniform: [2000, 6000]}
outputs: [fy]
checks: [{output: fy, max: 0}]
""")
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("campaign", c, "-j", "1")
    assert code == 0, err
    o = tmp_path / "tirecli-out" / "campaign-c"
    assert len(results(o)) == 16 * 4
    summary = json.loads((o / "summary.json").read_text())
    rows = summary["analysis"]["sobol"]["fy"]["indices"]
    assert {r["input"] for r in rows} == {"tire.LMUY", "points.fz"}
    st = {r["input"]: r["ST"] for r in rows}
    assert st["points.fz"] > st["tire.LMUY"] > 0  # load dominates Fy over these ranges
    figs = {Path(p).name for p in summary["outputs"] if p.startswith("figures/")}
    assert {"sobol.png", "tornado.png", "distribution-fy.png", "scatter-fy.png"} <= figs
    code, out, err = cli("report", c, "--out", tmp_path / "rep", "--junit", tmp_path / "rep.xml")
    assert code == 0, err
    assert '<testsuite name="report campaign sob"' in (tmp_path / "rep.xml").read_text()
    # the closing line names the campaign section (it read '0 figures' beside a section of figures)
    assert f"the campaign section of {c}, " in out and "0 figures" not in out, out
    html = (tmp_path / "rep" / "index.html").read_text()
    assert 'id="campaign-sob"' in html and "sobol" in html
    rep = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert {"campaign/sob/points-ran", "campaign/sob/fy-max"} <= {k["id"] for k in rep["checks"]}


def test_params_validate_checks_every_point(cli, tmp_path):
    c = mf_campaign(tmp_path)
    code, out, err = cli("params", "validate", c)
    assert code == 0 and "valid campaign 'mf': 6 points of the mf-eval study" in out


def test_fast_facts_equal_the_array_path():
    """The campaign's per-point shortcuts give the facts of the plain array code bit for bit: the
    extremum search on plain floats (slip, |slip|, |mu|), the scalar slip, the kept input-check grids."""
    import numpy as np

    from tirecli.config.loader import config_from_text
    from tirecli.conventions import slip_from_speeds, slip_of
    from tirecli.models import profiles
    from tirecli.studies import simulate as sim

    for torque in (600, 1500):  # the second locks the wheel (locked-mode steps in the searches)
        cfg = config_from_text(BRAKING.replace("t_end: 0.6", "t_end: 1.5"), "base.yaml",
                               overrides=[f"input.pressure.table.value=[0, 0, {torque / 10}, {torque / 10}]"])
        plan = sim.plan(cfg)
        checked, cases = plan.checked, plan.detail
        p, car = plan.sets["tire"].model(), plan.sets["vehicle"].model()
        tr = sim.run_cases(cases, p, car, checked["t_end"])[cases[0].label]
        r = car.r

        def slip(t, Y, O):
            return slip_from_speeds(Y[:, 0], Y[:, 1], r)

        ev = sim.case_events(tr, cases[0], r)
        assert (ev["t_peak_abs_slip"], ev["peak_abs_slip"]) == tr.extremum(lambda t, Y, O: np.abs(slip(t, Y, O)), "max")
        assert (ev["t_min_slip"], ev["min_slip"]) == tr.extremum(slip, "min")
        assert (ev["t_peak_abs_mu"], ev["peak_abs_mu"]) == tr.extremum(lambda t, Y, O: np.abs(O["mu"]), "max")
        assert torque < 1000 or ev["wheel_lock"]
    rng = np.random.default_rng(0)
    v = np.concatenate([rng.uniform(0, 30, 200), [0.0, 0.0, 5.0, np.nan, 1.0, np.inf, 0.0]])
    w = np.concatenate([rng.uniform(0, 100, 200), [0.0, 3.0, 0.0, 1.0, np.nan, 1.0, np.inf]])
    with np.errstate(invalid="ignore"):
        want = slip_from_speeds(v, w, 0.3)
    got = np.array([slip_of(a, b, 0.3) for a, b in zip(v, w)])
    assert np.array_equal(got, want, equal_nan=True)
    kept = profiles.run_times(6.0, 0.001, [0.1, 0.4])
    assert profiles.run_times(6.0, 0.001, (0.1, 0.4)) is kept and not kept.flags.writeable
    assert np.array_equal(kept, profiles._run_times(6.0, 0.001, (0.1, 0.4)))


def test_campaign_workers_use_one_thread():
    """A pool worker pins tirecli's thread pool (and the BLAS it loaded) to one thread: two workers on
    two cores run two threads."""
    import multiprocessing

    from tirecli.campaign import execute

    ctx = multiprocessing.get_context("fork" if hasattr(__import__("os"), "fork") else "spawn")
    with ctx.Pool(1, **execute.pool_options(None)) as pool:
        limit, threads, env = pool.apply(_worker_threads)
    assert limit == 1 and threads == 1 and env == "1"


def _worker_threads():
    import os

    from tirecli import parallel

    return parallel.LIMIT, parallel.default_threads(), os.environ.get("OPENBLAS_NUM_THREADS")



@pytest.mark.parametrize("jobs", ["0", "-2"])
def test_jobs_below_one_is_refused_as_report_refuses_it(cli, tmp_path, jobs):
    """``campaign --jobs 0`` said 'Invalid value for '--jobs' / '-j': Input should be greater than or
    equal to 1'; the same one line as ``report --jobs 0``, before anything is written."""
    c = mf_campaign(tmp_path)
    code, out, err = cli("campaign", c, "--jobs", jobs, "--out", tmp_path / "o")
    assert code == 2 and err == f"error: --jobs {jobs}: give a number of processes >= 1\n", err
    assert not (tmp_path / "o").exists()
    code, out, err2 = cli("report", "--jobs", jobs, "--out", tmp_path / "r")
    assert code == 2 and err2 == err
