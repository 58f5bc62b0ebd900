"""The observe study, its metrics, the sensor model, the command and the report entries."""
import json
import math

import numpy as np
import pytest

from conftest import EXAMPLES

from tirecli.observers import metrics as om
from tirecli.observers.measurement import Sensor


# --------------------------------------------------------------------------- metrics


def test_zero_crossings_interpolate_and_skip_a_start_from_zero():
    t = np.linspace(0.0, 10.0, 10001)
    x = np.sin(t)
    x[0] = 0.0
    np.testing.assert_allclose(om.zero_crossings(t, x), [math.pi, 2 * math.pi, 3 * math.pi], atol=1e-6)


def test_phase_errors_and_exclusion():
    t = np.linspace(0.0, 4.0, 4001)
    err = np.where(t < 2.0, 0.1, -0.3)
    err[np.abs(t - 3.0) < 0.2] = 5.0  # a spike near a "crossing" at 3 s
    ph = om.phase_errors(t, err, [0, 2, 4], crossings=[3.0], margin=0.5)
    assert ph[0]["rms"] == pytest.approx(0.1, rel=1e-3) and ph[0]["max"] == pytest.approx(0.1)
    assert ph[1]["max"] == 5.0 and ph[1]["max_excl"] == pytest.approx(0.3)
    assert ph[1]["rms_excl"] == pytest.approx(0.3, rel=1e-9)


def test_settle_times():
    t = np.linspace(0.0, 10.0, 10001)
    err = np.where(t < 5.0, 0.0, np.exp(-(t - 5.0)))   # a step at 5 s decaying with rate 1
    s = om.settle_times(t, err, [0.0, 5.0], tol=0.05)
    assert s[0]["time"] == 0.0
    assert s[1]["time"] == pytest.approx(math.log(1 / 0.05), abs=1e-3)
    never = om.settle_times(t, np.ones_like(t), [1.0], tol=0.05)
    assert never[0]["time"] is None


def test_excitation_share_and_decay_rate():
    t = np.linspace(0.0, 10.0, 1001)
    assert om.excitation_share(t, np.where(t < 2.5, 0.0, 1.0), 0.05) == pytest.approx(0.75, abs=2e-3)
    assert om.decay_rate(t, 0.1 * np.exp(-0.03 * t), 1.0, 9.0) == pytest.approx(-0.03, rel=1e-9)


# --------------------------------------------------------------------------- sensor


def _drive(sampler, w, rate, duration, h=1e-4):
    """Advance a sampler with constant wheel speed ``w`` and sample at ``rate``; returns the samples."""
    out, k = [], 1
    sampler.sample(0.0, w)
    n = int(round(duration / h))
    for i in range(n):
        sampler.advance(i * h, (i + 1) * h, w, w)
        if abs((i + 1) * h - k / rate) < 1e-9:
            out.append(sampler.sample(k / rate, w))
            k += 1
    return np.array(out)


def test_encoder_period_method_is_exact_at_constant_speed():
    s = Sensor(rate=1000.0, teeth=48, method="period")
    w = 93.7
    y = _drive(s.sampler(100, w), w, 1000.0, 0.05)
    np.testing.assert_allclose(y, w, rtol=1e-9)


def test_encoder_count_method_quantises():
    s = Sensor(rate=100.0, teeth=48, method="count")
    q = s.resolution()
    assert q == pytest.approx(2 * math.pi * 100 / 48)
    y = _drive(s.sampler(100, 80.0), 80.0, 100.0, 0.5)
    assert np.allclose(y / q, np.round(y / q))          # multiples of the quantum
    assert np.mean(y) == pytest.approx(80.0, rel=0.05)  # counts average to the speed


def test_noise_is_seeded():
    a = Sensor(rate=100.0, noise_std=0.1, seed=4).sampler(50, 10.0)
    b = Sensor(rate=100.0, noise_std=0.1, seed=4).sampler(50, 10.0)
    c = Sensor(rate=100.0, noise_std=0.1, seed=5).sampler(50, 10.0)
    ya = [a.sample(k / 100, 10.0) for k in range(50)]
    assert ya == [b.sample(k / 100, 10.0) for k in range(50)]
    assert ya != [c.sample(k / 100, 10.0) for k in range(50)]
    assert np.std(ya) == pytest.approx(0.1, rel=0.3)
    assert Sensor(rate=100.0, noise_std=0.1).synthetic and not Sensor(rate=100.0).synthetic and not Sensor().synthetic


# --------------------------------------------------------------------------- studies


@pytest.fixture(scope="module")
def fig2():
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    return run_study(builtin_config("obs-fig2"))


def test_fig2_reference_values_within_2_percent(fig2):
    """docs/models/lugre_friction.md §10 (OBS Fig. 2): theta_hat = 1.6669 (8 s), 2.498 (16 s), 2.4978 (20 s)."""
    tr = fig2.payload["trajectories"][0]
    for t, ref in ((8.0, 1.6669), (16.0, 2.498), (20.0, 2.4978)):
        assert float(np.interp(t, tr.t, tr.theta_hat)) == pytest.approx(ref, rel=0.02)


def test_fig2_checks_pass_and_features(fig2):
    from tirecli.studies.checks.observer import fig2_checks

    checks = fig2_checks(fig2)
    assert len(checks) > 30 and all(c.passed for c in checks), [c.id for c in checks if not c.passed]
    m = fig2.meta["runs"][0]["metrics"]
    assert len(m["crossings_s"]) == 2
    # theta_hat flat around the crossing at 12.5 s while theta keeps rising (docs/models/observer_model.md §8)
    tr = fig2.payload["trajectories"][0]
    near = (tr.t > 12.3) & (tr.t < 12.7)
    assert np.ptp(tr.theta_hat[near]) < 0.3 * np.ptp(tr.theta[near])
    assert fig2.meta["warnings"] == []


def test_fig2_frame_and_conventions(fig2):
    df = fig2.data["observer"]
    for col in ("t", "theta", "theta_hat", "v", "v_hat", "omega", "vr", "slip", "theta_fm", "theta_hat_fm"):
        assert col in df.columns
    np.testing.assert_allclose(df["theta_fm"] * df["theta"], 1.0)
    assert df["theta"].max() == pytest.approx(2.5) and df["theta"].min() == pytest.approx(1.0)
    assert "OBS convention" in fig2.meta["theta_convention"]
    assert fig2.meta["assumed"] and "docs/models/observer_model.md §7" in fig2.meta["assumed"][0]


def test_speed_error_study_reproduces_section_8():
    from tirecli.studies.checks.observer import speed_error_checks
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    res = run_study(builtin_config("obs-speed-error"))
    checks = {c.id: c for c in speed_error_checks(res)}
    assert {"v-error-20s", "theta-hat-4.9s", "theta-hat-20s", "theta-hat-20s-2ms", "slow-mode-rate"} <= set(checks)
    assert all(c.passed for c in checks.values()), [(c.id, c.value) for c in checks.values() if not c.passed]


def test_gain_study_frame():
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    res = run_study(builtin_config("obs-gain-study", overrides=["gain_study.values=[1.0e+5, 4.0e+5]"]))
    gs = res.data["gain_study"]
    assert list(gs["value"]) == [1e5, 4e5]
    assert gs["settle_time_s"].iloc[1] < gs["settle_time_s"].iloc[0]
    assert set(res.data["observer"]["case"]) == {"gamma = 100000", "gamma = 400000"}
    # the convergence-time panel's gain axis carries the gain's unit (gamma [s/m], parameter kind 'observer')
    from tirecli.figures.registry import get

    fig = get("obs-gain-study").draw(res)  # the registry imports the figure module (alone, this file imports none)
    assert fig.axes[1].get_xlabel().endswith("gamma [s/m]")
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()][1:] == ["gamma = 1e5 s/m", "gamma = 4e5 s/m"]


# --------------------------------------------------------------------------- command


def test_observe_command(cli, tmp_path):
    code, out, err = cli("observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path, "--set", "scenario.duration=8",
                         "--set", "metrics.phases=[0, 4, 8]")
    assert code == 0, err
    assert "max |v_hat - v|" in out and "v_r zero crossings" in out and "assumed:" in out
    run = json.loads((tmp_path / "run.json").read_text())
    # exact start: theta_hat stays on theta to the adaptive method's tolerance (auto: LSODA, rtol 1e-7)
    assert run["meta"]["runs"][0]["metrics"]["phases"][0]["rms"] < 1e-6
    assert run["meta"]["assumed"]
    assert (tmp_path / "figures" / "obs-fig2.png").exists() and (tmp_path / "figures" / "obs-fig2.svg").exists()
    head = (tmp_path / "data" / "observer.csv").read_text().splitlines()[0].split(",")
    assert head[:4] == ["case", "t", "theta", "theta_hat"]
    assert "warning:" not in err
    # the whole-run row of the metrics table is told apart from the phase rows
    assert "  all 0-8 " in out
    # the figure's caption (what is shown, parameters, [assumed] scenario) travels with the run
    assert "[assumed]" in run["outputs"]["captions"]["obs-fig2"]
    assert "  change at 5 s: |theta_hat - theta| < 0.05 after " in out and "from the start" not in out
    # an estimate that starts off is settled from t = 0, which is not a change of theta
    code, out, err = cli("observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path / "e", "--set", "scenario.duration=8",
                         "--set", "metrics.phases=[0, 4, 8]", "--set", "estimate.theta=1.5", "-q")
    assert code == 0, err
    assert "  from the start (initial estimate off): |theta_hat - theta|" in out and "change at 0 s" not in out


def test_report_strict_fails_when_speed_error_study_drifts(cli, tmp_path, monkeypatch):
    """The speed-error study is registered with its spec checks: --strict fails when one drifts."""
    monkeypatch.setattr(om, "decay_rate", lambda *a, **k: 0.0)  # a drifted slow-mode rate
    code, out, err = cli("report", "--out", tmp_path, "--only", "obs-speed-error", "--strict")
    assert code == 1 and "obs-speed-error/slow-mode-rate" in out + err
    assert json.loads((tmp_path / "summary.json").read_text())["n_failed"] == 1


def test_observe_warns_on_bad_gains_but_succeeds(cli, tmp_path):
    code, out, err = cli("observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path, "--set", "observer.k1=-5000",
                         "--set", "scenario.duration=3", "--set", "metrics.phases=[0, 3]")
    assert code == 0, err
    warns = [l for l in err.splitlines() if l.startswith("warning:")]
    assert any("k1-positive" in w for w in warns) and any("hurwitz" in w for w in warns)
    run = json.loads((tmp_path / "run.json").read_text())
    assert len(run["meta"]["warnings"]) == len(warns)


def test_observe_warns_without_excitation(cli, tmp_path):
    # pure rolling at constant speed: u = sigma_w omega = 80 N m, v_r = 0 throughout
    code, out, err = cli("observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path, "--set", "scenario.torque=80",
                         "--set", "scenario.duration=2", "--set", "metrics.phases=[0, 2]")
    assert code == 0
    assert "warning:" in err and "excitation" in err


def test_observe_config_errors(cli, tmp_path):
    bad = tmp_path / "bad.yaml"
    text = (EXAMPLES / "obs-fig2.yaml").read_text()
    bad.write_text(text + "measurement: {noise: {std: 0.1}}\n")
    code, out, err = cli("observe", bad, "--out", tmp_path / "o")
    assert code == 2 and "measurement" in err and "rate" in err
    bad.write_text(text.replace("solver: {method: auto", "solver: {methd: auto"))
    code, out, err = cli("observe", bad, "--out", tmp_path / "o")
    assert code == 2 and "did you mean 'method'" in err
    bad.write_text(text.replace("solver: {method: auto", "solver: {method: lsodaa"))
    code, out, err = cli("observe", bad, "--out", tmp_path / "o")
    assert code == 2 and "lsoda" in err and len(err.strip().splitlines()) == 1
    bad.write_text(text + "numerics: {method: fast}\n")
    code, out, err = cli("observe", bad, "--out", tmp_path / "o")
    assert code == 2 and "'solver' only" in err


def test_deprecated_numerics_block_still_runs():
    """The old numerics: {method: fast|reference} block maps to solver: fixed|radau, with a warning."""
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    over = ["scenario.duration=1", "metrics.phases=[0, 1]"]
    cfg = builtin_config("obs-fig2", overrides=over)
    cfg.data.pop("solver")
    cfg.data["numerics"] = {"method": "fast", "step": 0.002}
    res = run_study(cfg)
    assert res.meta["runs"][0]["integrator"] == "fixed (step 2 ms)"
    assert any("'numerics' is deprecated" in w and "method: fixed, step: 0.002" in w for w in res.meta["warnings"])


def test_report_strict_fails_when_fig2_drifts(cli, tmp_path, monkeypatch):
    from tirecli.studies.checks import observer

    monkeypatch.setitem(observer.FIG2_THETA_HAT, 8.0, (1.70, 3e-4))  # a drifted reference
    code, out, err = cli("report", "--out", tmp_path, "--only", "obs-fig2", "--strict")
    assert code == 1 and "obs-fig2/theta-hat-8s" in out + err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["n_failed"] == 1


def test_reference_integrator_through_the_study():
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    res = run_study(builtin_config("obs-fig2", overrides=["solver.method=radau", "solver.rtol=1e-8",
                                                          "scenario.duration=1", "metrics.phases=[0, 1]"]))
    run = res.meta["runs"][0]
    assert run["integrator"] == "radau (rtol 1e-08)"
    assert run["metrics"]["phases"][0]["max"] < 1e-6   # exact start, constant theta


def test_failed_checks_after_overrides_say_why(cli, tmp_path):
    from conftest import EXAMPLES

    code, out, err = cli("observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path, "--set", "observer.gamma=1e5")
    assert code == 0
    assert "reference checks differ from the paper's values" in out and "--set overrides change it" in out
    assert "check failed:" not in out + err
