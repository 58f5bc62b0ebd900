"""The observer on a measured log (measurement.log): bad input refused in one line, and the observer on the
log of the plant's own simulation reproduces the simulated-plant observe run (an independent check: the
log run integrates the observer alone from the file's samples)."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LOG = EXAMPLES / "data" / "synthetic-obs-log.csv"
PLANT = EXAMPLES / "data" / "obs-log-plant.yaml"


def _config(tmp_path, log_text, **measurement):
    (tmp_path / "log.csv").write_text(log_text)
    doc = yaml.safe_load((EXAMPLES / "obs-log.yaml").read_text())
    doc["measurement"] = {"log": "log.csv", **measurement}
    doc.pop("cases")
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


GOOD = "t,omega,torque,vx\n0,80,350,20\n0.02,80.1,350,20.05\n0.04,80.2,350,20.1\n"


@pytest.mark.parametrize("text, extra, needle", [
    ("t,omega,vx\n0,80,20\n0.02,80,20\n", {}, "missing channel(s) torque"),
    ("t,omega,torque\n0,80,350\n0.02,nan,350\n", {}, "NaN"),
    ("t,omega,torque\n0,80,350\n0.04,80,350\n0.02,80,350\n", {}, "t does not increase at row 3"),
    (GOOD, {"units": {"omega": "deg"}}, "expected rad/s"),
    (GOOD, {"units": {"torque": "N"}}, "expected N m"),
    ("t,omega,torque\n0,80,350\n", {}, "at least 2"),
])
def test_bad_log_is_one_line_exit_2_nothing_written(cli, tmp_path, text, extra, needle):
    cfg = _config(tmp_path, text, **extra)
    out = tmp_path / "out"
    code, stdout, err = cli("observe", cfg, "--out", out)
    assert code == 2, err
    assert needle in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_log_options_exclude_the_simulated_sensor(cli, tmp_path):
    cfg = _config(tmp_path, GOOD, rate=100)
    code, _, err = cli("observe", cfg, "--out", tmp_path / "out")
    assert code == 2 and "drop 'rate'" in err


def _plan(cfg):
    from tirecli.config.loader import load_config
    from tirecli.studies.registry import plan

    return plan(load_config(cfg)).detail


def test_mapped_columns_and_units(tmp_path):
    """A log in its own names and units (rpm; a brake torque, > 0 braking) reads as the SI log: omega in
    rad/s, the wheel torque u = -brake torque (conventions.wheel_torque_from_brake)."""
    text = "time,wheel_speed,brake\n0,600,100\n0.5,570,100\n"
    cfg = _config(tmp_path, text, map={"wheel_speed": "omega", "brake": "brake_torque"}, units={"omega": "rpm"})
    d = _plan(cfg)
    assert d.omega[0] == pytest.approx(600 * 2 * np.pi / 60, rel=1e-12) and d.v is None
    assert d.torque.tolist() == [-100.0, -100.0]


def test_wheel_speed_as_r_omega_and_torque_from_pressure(tmp_path):
    """``romega`` [m/s] is divided by the vehicle's wheel radius; a brake pressure times ``torque_gain``
    [N m/Pa] is a brake torque."""
    text = "t,romega,p\n0,20,1.0e5\n0.01,19.9,2.0e5\n"
    d = _plan(_config(tmp_path, text, torque_gain=2.0e-3))
    r = d.plant.car.r
    assert d.omega.tolist() == pytest.approx([20 / r, 19.9 / r], rel=1e-12)
    assert d.torque.tolist() == [-200.0, -400.0]


@pytest.mark.parametrize("text, extra, needle", [
    ("t,omega,romega,torque\n0,80,20,0\n0.1,80,20,0\n", {}, "the wheel speed given twice (omega and romega)"),
    ("t,omega,p\n0,80,1\n0.1,80,1\n", {}, "missing channel(s) torque"),
    ("t,romega,torque\n0,80,0\n0.1,80,0\n", {"units": {"romega": "rad/s"}}, "channel romega: unit rad/s, expected m/s"),
])
def test_ambiguous_or_wrong_channels(cli, tmp_path, text, extra, needle):
    code, _, err = cli("observe", _config(tmp_path, text, **extra), "--out", tmp_path / "out")
    assert code == 2 and needle in err, err


def test_observer_on_the_plants_log_reproduces_the_simulated_run():
    """The shipped SYNTHETIC log holds the plant of obs-log-plant.yaml sampled at 50 Hz as its observe run
    measures it (same seeded noise, torque steps on the sampling grid, so the held torque is exact). The
    observer run on the log's samples then matches the simulated-plant run's estimates at the sample times:
    both integrate the same observer with LSODA from the same held inputs; what differs is the solver's path
    (the observer alone, rtol 1e-7, restarted per sample, vs plant + observer, rtol 1e-9). Measured: 1.9e-5
    in theta_hat and 3.5e-8 m/s in v_hat; tolerance 1e-4 in theta_hat (OBS) and 1e-6 m/s in v_hat."""
    from tirecli.config.loader import config_from_mapping, load_config
    from tirecli.studies.registry import run_study

    sim_doc = yaml.safe_load(PLANT.read_text())
    sim_doc["solver"]["rtol"] = 1e-9          # as the log was made
    sim = run_study(config_from_mapping(sim_doc, base_dir=PLANT.parent))
    tr = sim.payload["trajectories"][0]
    doc = yaml.safe_load((EXAMPLES / "obs-log.yaml").read_text())
    doc["cases"] = doc["cases"][:1]
    res = run_study(config_from_mapping(doc, base_dir=EXAMPLES))
    lg = res.payload["trajectories"][0]
    i = np.searchsorted(tr.t, lg.t + 1e-12, side="right") - 1     # the simulated run right after each sample
    assert np.max(np.abs(tr.t[i] - lg.t)) < 1e-9
    # the same held samples, up to the plant's tolerance 
    assert np.max(np.abs(tr.y[i] - lg.y)) < 1e-6
    d_theta = np.abs(tr.theta_hat[i] - lg.theta_hat)
    d_v = np.abs(tr.v_hat[i] - lg.v_hat)
    assert d_theta.max() < 1e-4, (d_theta.max(), lg.t[d_theta.argmax()])
    assert d_v.max() < 1e-6, (d_v.max(), lg.t[d_v.argmax()])
    # the measured speed is the reference: the plant's own v
    assert np.max(np.abs(res.data["observer"]["v"].to_numpy() - tr.v[i])) < 1e-5
    assert res.synthetic


@pytest.mark.slow
def test_shipped_log_is_reproducible(tmp_path):
    """The shipped log is what its command in the file writes (seeded)."""
    from tirecli.app.data import observer_log_synth

    shutil.copy(PLANT, tmp_path / PLANT.name)
    out = observer_log_synth(str(tmp_path / PLANT.name), str(tmp_path / "log.csv"), rate=50, noise=0.005, seed=1)
    new = Path(out).read_text().splitlines()
    old = LOG.read_text().splitlines()
    assert [ln for ln in new if not ln.startswith("# made by")] == [ln for ln in old if not ln.startswith("# made by")]


@pytest.mark.parametrize("key, value, needle", [
    ("scenario", {"duration": 1, "theta": 1, "torque": 0, "v0": 20}, "replaces the simulated scenario"),
    ("metrics", {"phases": [0, 1]}, "the phase metrics need the true theta"),
    ("gain_study", {"gain": "gamma", "values": [1, 2]}, "not available on a measured log"),
])
def test_simulation_keys_refused_with_a_log(cli, tmp_path, key, value, needle):
    cfg = _config(tmp_path, GOOD)
    doc = yaml.safe_load(cfg.read_text())
    doc[key] = value
    cfg.write_text(yaml.safe_dump(doc))
    code, _, err = cli("observe", cfg, "--out", tmp_path / "out")
    assert code == 2 and needle in err and f"{key}" in err, err


def test_no_scenario_and_no_log_names_both(cli, tmp_path):
    doc = yaml.safe_load((EXAMPLES / "obs-log.yaml").read_text())
    doc.pop("measurement")
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(doc))
    code, _, err = cli("observe", tmp_path / "c.yaml", "--out", tmp_path / "out")
    assert code == 2 and "scenario: missing" in err and "measurement.log" in err, err
