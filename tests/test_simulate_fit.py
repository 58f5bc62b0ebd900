"""tirecli simulate / fit through the CLI: output contract, events, open loop, synthetic labels, identification, errors."""
import json
from dataclasses import replace

import numpy as np
import pandas as pd
import pytest

from conftest import EXAMPLES

BRAKING = """\
study: simulate
title: test braking
tire: canudas2003-table2
input:
  brake_torque: {initial: 0, changes: [{at: 0.5, duration: 1.5, to: 1100, shape: linear},
                                       {at: 2.0, duration: 0.6, to: 0, shape: linear}]}
t_end: 3.0
cases:
  - {model: lumped, kappa0: Z, label: LZ}
  - {model: lumped, kappa0: 1, drive: {case: LZ}, label: "k1 open loop"}
measurement: {rate: 100, seed: 7}
output: {dt: 0.002}
"""


@pytest.fixture(scope="module")
def braking_run(tmp_path_factory):
    from tirecli.cli.main import main

    d = tmp_path_factory.mktemp("sim")
    cfg = d / "b.yaml"
    cfg.write_text(BRAKING)
    assert main(["--quiet", "simulate", str(cfg), "--out", str(d / "out")]) == 0
    return d / "out"


def test_simulate_output_contract(braking_run):
    run = json.loads((braking_run / "run.json").read_text())
    assert run["study"] == "simulate" and run["synthetic"] is True and "SYNTHETIC" in run["note"]
    df = pd.read_csv(braking_run / "data" / "timeseries.csv", comment="#")
    for col in ("case", "t", "v", "omega", "slip", "vr", "mu", "torque"):
        assert col in df.columns
    assert set(df["case"]) == {"LZ", "k1 open loop"}
    assert np.allclose(np.diff(df.loc[df["case"] == "LZ", "t"]), 0.002)
    assert (braking_run / "data" / "timeseries.csv").read_text().startswith("# SYNTHETIC DATA")
    meas = pd.read_csv(braking_run / "data" / "measured.csv", comment="#")
    assert list(meas.columns[2:]) == ["t", "t_record", "pressure", "torque", "v", "romega", "s", "mu"]
    assert np.allclose(np.diff(meas["t"]), 0.01)
    for fid in ("transient-histories", "transient-mu-slip", "transient-overlay"):
        assert (braking_run / "figures" / f"{fid}.png").stat().st_size > 10_000


def test_simulate_events(braking_run):
    run = json.loads((braking_run / "run.json").read_text())
    ev = {e["case"]: e for e in run["meta"]["events"]}
    lz = ev["LZ"]
    assert lz["wheel_lock"] and lz["wheel_lock"][0][0] == pytest.approx(1.99, abs=0.01)  # 1100 N m locks
    assert lz["peak_abs_slip"] == pytest.approx(1.0)
    assert lz["stop_time"] is None and lz["end"] == "t_end" and lz["distance"] > 30
    # the open-loop case shares the kinematics of its driver
    assert ev["k1 open loop"]["min_slip"] == pytest.approx(lz["min_slip"], abs=1e-9)
    assert "stop_condition" in run["meta"] and "wheel_lock" in run["meta"]


def test_synthetic_measurement_noise_is_seeded(braking_run):
    meas = pd.read_csv(braking_run / "data" / "measured.csv", comment="#")
    clean = pd.read_csv(braking_run / "data" / "measured_clean.csv", comment="#")
    dv = meas["v"] - clean["v"]
    assert 0.04 < dv.std() < 0.06                      # 0.05 m/s on speeds (docs/models/lugre_friction.md §10)
    assert 0.4 < (meas["pressure"] - clean["pressure"]).std() < 0.6   # 0.5 bar on pressure
    # torque = -20 N m/bar * pressure while the wheel turns; while it is locked the brake transmits the
    # (smaller) reaction torque r F that holds the wheel
    run = json.loads((braking_run / "run.json").read_text())
    t_lock, t_unlock = run["meta"]["events"][0]["wheel_lock"][0]
    turning = (clean["t"] < t_lock - 0.005) | (clean["t"] > t_unlock + 0.005)
    assert np.allclose(clean["torque"][turning], -20.0 * clean["pressure"][turning])
    assert np.all(-clean["torque"][~turning] <= 20.0 * clean["pressure"][~turning] + 1e-9)


def test_open_loop_from_csv_and_formula(cli, tmp_path, braking_run):
    meas = braking_run / "data" / "measured_clean.csv"
    cfg = tmp_path / "ol.yaml"
    cfg.write_text(f"""\
study: simulate
tire: canudas2003-table1
t_end: 0.05
cases:
  - {{model: distributed, label: formula, drive: {{v: 20, slip: -0.1}}}}
  - {{model: lumped, kappa0: Z, label: csv, drive: {{csv: {meas}, map: {{s: s}}}}}}
""")
    code, out, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    df = pd.read_csv(tmp_path / "o" / "data" / "timeseries.csv", comment="#")
    f = df[df["case"] == "formula"]
    assert f["mu"].iloc[-1] == pytest.approx(-0.925908, abs=1e-4)   # FM eq. (4), Table 1, |s| = 0.1
    assert f["mode"].iloc[0] == "open-loop" and np.isnan(f["torque"]).all()
    c = df[df["case"] == "csv"]
    assert c["t"].iloc[-1] == pytest.approx(0.05)  # t_end caps the CSV's time range
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    assert run["synthetic"] is False


def test_open_loop_from_one_case_of_a_tirecli_csv(cli, tmp_path, braking_run):
    """drive.where picks one braking of a multi-case samples file (labels "braking #k", as in FM Fig. 4)."""
    clean = pd.read_csv(braking_run / "data" / "measured_clean.csv", comment="#")
    two = pd.concat([clean.assign(case="braking #1", s=0.5 * clean["s"]), clean.assign(case="braking #2")])
    data = tmp_path / "measured_clean.csv"
    data.write_text("# SYNTHETIC DATA generated by tirecli (not measured)\n" + two.to_csv(index=False))
    cfg = tmp_path / "ol.yaml"
    cfg.write_text(f"""\
study: simulate
tire: canudas2003-table2
t_end: 2.5
cases:
  - {{model: lumped, kappa0: Z, label: two, drive: {{csv: {data}, where: {{case: "braking #2"}}}}}}
""")
    code, out, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    ev = json.loads((tmp_path / "o" / "run.json").read_text())["meta"]["events"][0]
    assert ev["min_slip"] == pytest.approx(clean["s"][clean["t"] <= 2.5].min(), abs=1e-3)
    cfg.write_text(cfg.read_text().replace("braking #2", "braking #9"))
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "o2")
    assert code == 2 and "cases[0].drive.where: no row has case == 'braking #9'" in err, err


@pytest.mark.parametrize("bad, msg", [
    ("input: {torque: 100, pressure: 5}", "give one of torque, brake_torque, pressure"),
    ("cases: [{model: lumped, drive: {case: nope}}]", "no coupled case labelled 'nope'"),
    ("cases: [{model: lumped, kappa0: Z, drive: {v: 20}}]", "with v, give exactly one of slip, omega, romega"),
    ("cases: [{model: lumped, drive: {v: 20, slip: -0.1, where: {case: a}}}]", "where selects rows of a csv drive"),
    ("input: {theta: {expr: 'os.system(1)'}}", "only the listed functions may be called"),
    ("t_end: -1", "out of range"),
    ("cases: [{model: lumpy}]", "did you mean 'lumped'"),
])
def test_simulate_config_errors(cli, tmp_path, bad, msg):
    cfg = tmp_path / "bad.yaml"
    cfg.write_text("study: simulate\ntire: canudas2003-table2\n" + bad + "\n")
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "o")
    assert code == 2 and msg in err, err
    assert "bad.yaml:" in err


# --------------------------------------------------------------------------- identification


def steady_samples(p, noise=0.0, seed=3):
    from tirecli.models.lugre import mu_ss_uniform

    S, V = np.meshgrid(np.linspace(-1.0, -0.005, 40), np.linspace(5.0, 25.0, 9))
    s, v = S.ravel(), V.ravel()
    mu = mu_ss_uniform(v * s, v * (1 + s), p)
    if noise:
        mu = mu + np.random.default_rng(seed).normal(0.0, noise, mu.size)
    return s, v, mu


def test_fit_returns_table2_from_exact_samples(table1, table2):
    from tirecli.numerics.identify import fit_steady_state

    s, v, mu = steady_samples(table2)
    res, p = fit_steady_state(s, v, mu, replace(table1, alpha=2.0))
    for k in ("sigma0", "mu_c", "mu_s", "v_s"):
        assert res.estimate[k] == pytest.approx(getattr(table2, k), rel=1e-4)
    assert abs(res.estimate["sigma2"]) < 1e-6
    assert res.residual_rms < 1e-8


def test_fit_with_noise_contains_the_truth(table1, table2):
    from tirecli.numerics.identify import fit_steady_state

    s, v, mu = steady_samples(table2, noise=0.02)
    res, _ = fit_steady_state(s, v, mu, replace(table1, alpha=2.0))
    for k in ("sigma0", "mu_c", "mu_s", "v_s"):
        assert res.ci_low[k] <= getattr(table2, k) <= res.ci_high[k], k
        assert res.se[k] > 0
    assert res.residual_rms == pytest.approx(0.02, rel=0.15)
    assert np.allclose(np.diag(res.corr), 1.0) and np.allclose(res.corr, res.corr.T)
    assert res.at_bound["sigma2"] or res.ci_low["sigma2"] <= 0.0 <= res.ci_high["sigma2"]


def test_fit_alpha_free_and_mu_order(table2):
    from tirecli.numerics.identify import fit_steady_state

    s, v, mu = steady_samples(table2)
    res, p = fit_steady_state(s, v, mu, replace(table2, alpha=1.0, sigma0=150.0, mu_c=1.0, mu_s=1.2, v_s=3.0),
                              free=("sigma0", "mu_c", "mu_s", "v_s", "alpha"))
    assert res.estimate["alpha"] == pytest.approx(2.0, rel=1e-4)
    assert p.mu_c <= p.mu_s


def test_sigma1_is_linear_least_squares(table2):
    from tirecli.numerics.identify import fit_sigma1

    rng = np.random.default_rng(0)
    z, zd, vr = rng.normal(0, 1e-3, 200), rng.normal(0, 0.1, 200), rng.normal(-1, 0.2, 200)
    mu = table2.sigma0 * z + 1.7 * zd + table2.sigma2 * vr
    res = fit_sigma1(mu, z, zd, vr, table2)
    assert res.estimate["sigma1"] == pytest.approx(1.7, rel=1e-12)


FIT = """\
study: fit
tire: {{set: canudas2003-table1, alpha: 2}}
data: {{csv: {csv}, window: {{start: 0, end: 2.6}}}}
"""


@pytest.fixture(scope="module")
def braking_csv(tmp_path_factory):
    """A noise-free synthetic braking (lumped kappa0(Z) truth, Table 2) as a plain CSV."""
    from tirecli.models.profiles import Change, Constant, Transitions
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("canudas2003-table2").model()
    car = load_builtin("canudas2003-obs-quarter-car").model()
    tq = Transitions(0.0, (Change(0.5, -1000.0, 1.5, "linear"), Change(2.0, 0.0, 0.6, "linear")))
    ts = tuple(np.round(np.arange(0, 351) * 0.01, 10))
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), p, car, tq, Constant(1.0), 20.0, 80.0, 3.5,
                          runs.SolverOptions(tol=1e-5), sample_times=ts)
    idx = np.searchsorted(tr.t, np.array(ts) - 1e-12)
    df = pd.DataFrame({"time": tr.t[idx], "v": tr.y[idx, 0], "slip_ratio": tr.out["slip"][idx],
                       "mu": tr.out["mu"][idx]})
    path = tmp_path_factory.mktemp("csv") / "braking.csv"
    df.to_csv(path, index=False)
    return path


def test_fit_command_writes_a_usable_parameter_set(cli, tmp_path, braking_csv):
    cfg = tmp_path / "fit.yaml"
    cfg.write_text(FIT.format(csv=braking_csv))
    code, out, err = cli("fit", cfg, "--out", tmp_path / "o", "--map", "time=t", "--map", "slip_ratio=s")
    assert code == 0, err
    fitted = tmp_path / "o" / "fitted.yaml"
    assert fitted.exists() and f"wrote {fitted}" in out
    assert cli("params", "validate", fitted)[0] == 0
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    st = run["meta"]["steady_state"]
    assert set(st["parameters"]) == {"sigma0", "sigma2", "mu_c", "mu_s", "v_s"}
    for rec in st["parameters"].values():
        assert rec["ci"][0] <= rec["estimate"] <= rec["ci"][1]
    assert len(st["correlation"]["matrix"]) == 5 and st["residual_rms"] < 0.01
    # sigma0 and mu_s are well determined by the braking (docs/models/lugre_friction.md §10 (FM Fig. 6))
    assert st["parameters"]["sigma0"]["estimate"] == pytest.approx(178.0, rel=0.02)
    assert st["parameters"]["mu_s"]["estimate"] == pytest.approx(1.5, rel=0.02)
    # with the lumped kappa0(Z) truth, stage 2 recovers sigma1
    assert run["meta"]["sigma1"]["parameters"]["sigma1"]["estimate"] == pytest.approx(1.0, rel=0.05)
    # the fitted set is accepted by the other commands
    sim = tmp_path / "sim.yaml"
    sim.write_text(f"study: simulate\ntire: {{set: {fitted}}}\nt_end: 0.2\ncases: [{{model: lumped, kappa0: Z}}]\n")
    assert cli("--quiet", "simulate", sim, "--out", tmp_path / "s")[0] == 0


def test_read_table_keeps_hash_inside_cells(tmp_path):
    """Only whole lines starting with '#' are comments: tirecli's case labels ("braking #1") are data."""
    from tirecli.io.data import read_table

    f = tmp_path / "m.csv"
    f.write_text("# SYNTHETIC DATA generated by tirecli (not measured)\ncase,t,mu\nbraking #1,0.5,-0.25\n"
                 "  # an indented comment\nbraking #2,0.75,-0.5\n")
    df = read_table(f)
    assert list(df["case"]) == ["braking #1", "braking #2"]
    assert list(df["t"]) == [0.5, 0.75] and list(df["mu"]) == [-0.25, -0.5]


def test_fit_reads_tirecli_measured_csv_with_case_labels(cli, tmp_path, braking_csv):
    """The fit accepts tirecli's own synthetic samples (measured.csv layout, labels "braking #k") selected by where."""
    df = pd.read_csv(braking_csv)
    two = pd.concat([df.assign(case="braking #1", mu=df["mu"] * 0.5), df.assign(case="braking #2")])
    data = tmp_path / "measured.csv"
    data.write_text("# SYNTHETIC DATA generated by tirecli (not measured)\n" + two.to_csv(index=False))
    cfg = tmp_path / "fit.yaml"
    cfg.write_text("study: fit\ntire: {set: canudas2003-table1, alpha: 2}\n"
                   f"data: {{csv: {data}, window: {{start: 0, end: 2.6}}, where: {{case: 'braking #2'}}}}\n"
                   "fit: {sigma1: false}\nfigures: [fm-table2, fit-steady]\n")
    code, out, err = cli("fit", cfg, "--out", tmp_path / "o", "--map", "time=t", "--map", "slip_ratio=s")
    assert code == 0, err
    # synthetic input: every CSV written, the Table 2 figure included, says so
    for f in [*(tmp_path / "o" / "data").glob("*.csv"), tmp_path / "o" / "figures" / "fm-table2.csv"]:
        assert f.read_text().startswith("# SYNTHETIC DATA"), f
    st = json.loads((tmp_path / "o" / "run.json").read_text())["meta"]["steady_state"]
    assert st["parameters"]["sigma0"]["estimate"] == pytest.approx(178.0, rel=0.02)
    assert st["parameters"]["mu_s"]["estimate"] == pytest.approx(1.5, rel=0.02)


@pytest.mark.parametrize("content, msg", [
    ("t,v,mu\n0,20,0\n0.01,20,-0.1\n", "missing column 's' (slip) and no 'romega'"),
    ("t,v,s,mu\n0,20,-0.01,-0.1\n0.01,nan,-0.02,-0.2\n", "column 'v' row 2: empty or NaN"),
    ("t,v,s,mu\n0,20,-0.01,-0.1\n0.01,20,-0.02,-0.2\n", "too few samples for the steady-state fit"),
    ("t,v,s,mu\n0,20,-0.01,-0.1\n0,20,-0.02,-0.2\n", "column 't' row 2: time does not increase"),
    ("t,v,s,mu\n0,20,-0.01,-0.1\n0.01,20,abc,-0.2\n", "column 's' row 2: not a number"),
    ("", "empty file"),
])
def test_fit_rejects_bad_csv(cli, tmp_path, content, msg):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    cfg = tmp_path / "fit.yaml"
    cfg.write_text(FIT.format(csv="unused.csv"))
    code, out, err = cli("fit", cfg, "--data", bad, "--out", tmp_path / "o")
    assert code == 2, err
    assert msg in err and "bad.csv" in err


def test_fit_map_errors(cli, tmp_path, braking_csv):
    cfg = tmp_path / "fit.yaml"
    cfg.write_text(FIT.format(csv=braking_csv))
    code, out, err = cli("fit", cfg, "--out", tmp_path / "o", "--map", "nonexistent=s")
    assert code == 2 and "mapped column(s) 'nonexistent' not in the file" in err
    code, out, err = cli("fit", cfg, "--out", tmp_path / "o", "--map", "nonsense")
    assert code == 2 and "expected FILE_COLUMN=NAME" in err


def test_examples_of_fm_figures_exist():
    for n in ("fm-fig4", "fm-fig6", "fm-fig7", "fm-fig8"):
        assert (EXAMPLES / f"{n}.yaml").exists()


def test_overlay_differences_only_runs_driven_the_same_way(tmp_path):
    """transient-overlay: a coupled case is differenced against the first case with the same inputs (a model
    difference), never against a run with another torque; open-loop cases against their driver."""
    from tirecli.config.loader import load_config
    from tirecli.figures.transient import draw_overlay, overlay_base
    from tirecli.studies.registry import run_study

    cfg = tmp_path / "ov.yaml"
    cfg.write_text("""\
study: simulate
tire: canudas2003-table2
input: {brake_torque: {table: {t: [0, 0.1, 0.3], value: [0, 0, 800]}}}
t_end: 0.3
cases:
  - {model: lumped, kappa0: 1, label: A, input: {brake_torque: 500}}
  - {model: distributed, label: B}
  - {model: lumped, kappa0: Z, label: C}
  - {model: lumped, kappa0: 2, label: D, drive: {case: B}}
  - {model: lumped, kappa0: 2, label: E, input: {pressure: 10}}
""")
    res = run_study(load_config(cfg))
    cases = res.payload["cases"]
    assert [overlay_base(cases, c) for c in cases] == [None, None, "B", "B", None]
    fig = draw_overlay(res)
    assert len(fig.axes[1].lines) == 2 and len(fig.axes[2].lines) == 2


def test_case_styles_stay_distinct_past_the_colour_cycle():
    from types import SimpleNamespace

    from tirecli.figures.transient import _style

    for mode in ("coupled", "open-loop"):
        case = SimpleNamespace(mode=mode)
        styles = {(st["color"], st["ls"]) for st in (_style(i, case) for i in range(16))}
        assert len(styles) == 16


@pytest.mark.parametrize("text, words", [
    ("t,v,mu\n0,1,20,0.1\n10,2,19,0.2\n20,3,18,0.3\n", "data row 1 has 4 fields but the header names 3 columns"),
    # a trailing separator is a field: pandas would read the row right, mf eval's copy would not
    ("t,v,mu\n0,1,0.1\n\n1,2,0.2,\n", "data row 2 has 4 fields but the header names 3 columns"),
    ("t,v,mu\n0,1,0.1\n1,2\n", "data row 2 has 2 fields but the header names 3 columns"),
    ("\ufeff# SYNTHETIC\nt,v,t\n1,2,3\n", "'t' appear more than once"),
])
def test_csv_rows_with_another_field_count_than_the_header_and_repeated_columns_are_errors(tmp_path, text, words):
    from tirecli.errors import DataError
    from tirecli.io.data import read_table

    p = tmp_path / "d.csv"
    p.write_bytes(text.encode("utf-8"))
    with pytest.raises(DataError, match=words):
        read_table(p)


@pytest.mark.parametrize("text", [
    "\ufeff# exported\r\nt,v,mu,,\r\n0,1,0.1,,\r\n1,2,0.2,,\r\n",       # BOM, CRLF, trailing empty columns
    "# exported\rt,v,mu\r0,1,0.1\r1,2,0.2\r",                           # CR-only line ends
    't, v, mu, note\n0, 1, 0.1, "braking, hard"\n1, 2, 0.2, x\n',         # blanks after commas, quoted comma
])
def test_csv_variants_read(tmp_path, text):
    import warnings

    from tirecli.io.data import read_table

    p = tmp_path / "d.csv"
    p.write_bytes(text.encode("utf-8"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        frame = read_table(p)
    assert list(frame.columns[:3]) == ["t", "v", "mu"] and frame["mu"].tolist() == [0.1, 0.2]


@pytest.mark.parametrize("expr, words, code", [
    ("1/0 + t", "input.torque.expr: cannot be evaluated at t = 0 s: division by zero", 2),
    ("sqrt(-1-t)", "input.torque.expr: gives nan at t = 0 s", 2),
    # checked over the whole run before it starts (issue 13), no longer found by the integrator at 0.5 s
    ("sqrt(0.5-t)*100", "input.torque.expr: the formula gives NaN (not a number) at t = 0.5 s", 2),
])
def test_formula_that_cannot_be_evaluated_is_an_input_error(cli, tmp_path, expr, words, code):
    cfg = tmp_path / "e.yaml"
    cfg.write_text("study: simulate\ntire: canudas2003-table1\nvehicle: canudas2003-obs-quarter-car\n"
                   f"initial: {{v: 20}}\nt_end: 1\ninput: {{torque: {{expr: \"{expr}\"}}}}\ncases: [{{model: lumped}}]\n")
    rc, out, err = cli("simulate", cfg, "--out", tmp_path / "o", "--quiet")
    assert rc == code and words in err and "internal error" not in err


def test_fit_data_is_named_as_written(cli, tmp_path, monkeypatch):
    """``tirecli fit fit.yaml --data bad.csv`` named the file by its absolute path in the error (and in
    run.json), while the same file given as ``data.csv`` in the config is named as written."""
    (tmp_path / "bad.csv").write_text("t,v,s,mu\n0,20,-0.01,-0.1\n0.01,nan,-0.02,-0.2\n")
    (tmp_path / "fit.yaml").write_text(FIT.format(csv="unused.csv"))
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("fit", "fit.yaml", "--data", "bad.csv", "--out", "o")
    assert code == 2 and err.startswith("error: bad.csv: column 'v' row 2: empty or NaN"), err
    (tmp_path / "sub").mkdir()  # from another folder than the config's: the data file is still found
    monkeypatch.chdir(tmp_path / "sub")
    code, out, err = cli("fit", "../fit.yaml", "--data", "../bad.csv", "--out", "o")
    assert code == 2 and "bad.csv: column 'v' row 2: empty or NaN" in err, err


def test_an_open_loop_case_ends_with_its_drive_and_says_so(cli, tmp_path):
    """An open-loop case driven by a CSV shorter than t_end ends at the CSV's last time (the model has
    no kinematics after it); events.csv called that end 't_end' (``m/s (t_end)`` at 0.05 s of a
    0.2 s run): it says the drive ended."""
    (tmp_path / "drive.csv").write_text("t,v,s\n" + "".join(f"{0.01 * k:g},20,-0.05\n" for k in range(6)))
    cfg = tmp_path / "ol.yaml"
    cfg.write_text("study: simulate\ntire: canudas2003-table1\nt_end: 0.2\n"
                   "cases:\n  - {model: lumped, kappa0: Z, label: short, drive: {csv: drive.csv}}\n"
                   "  - {model: lumped, kappa0: Z, label: long, drive: {v: 20, slip: -0.05}}\n")
    code, out, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    ev = pd.read_csv(tmp_path / "o" / "data" / "events.csv", comment="#")
    end = ev[ev["event"] == "end"].set_index("case")
    assert end.loc["short", "t"] == pytest.approx(0.05) and end.loc["short", "unit"] == "m/s (end of the drive)"
    assert end.loc["long", "t"] == pytest.approx(0.2) and end.loc["long", "unit"] == "m/s (t_end)"
