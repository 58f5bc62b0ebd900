"""Every class of config error through the real CLI: one line per problem, file:line, exit code 2."""
import textwrap

import pytest

GOOD = """\
study: sweep
tire: canudas2003-table1
sweep:
  slip: {start: -1, stop: 0, num: 11}
  speeds: [20]
"""


def write(tmp_path, text, name="c.yaml"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def run_sweep(cli, tmp_path, text, *extra):
    path = write(tmp_path, text)
    code, out, err = cli("sweep", path, "--out", tmp_path / "out", *extra)
    return code, err, path


def test_good_config_runs(cli, tmp_path):
    code, err, _ = run_sweep(cli, tmp_path, GOOD)
    assert code == 0, err
    assert (tmp_path / "out" / "run.json").is_file()


@pytest.mark.parametrize("text, line, key, words", [
    # unknown key, with a did-you-mean
    (GOOD.replace("  speeds: [20]", "  speds: [20]"), 5, "sweep.speds", "did you mean 'speeds'"),
    (GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, sigm0: 170}"), 2, "tire.sigm0",
     "did you mean 'sigma0'"),
    # missing key
    ("study: sweep\nsweep: {speeds: [20]}\n", 1, "", "missing required key 'tire'"),
    ("study: sweep\ntire: {set: canudas2003-table1}\nsweep: {slip: {start: -1, num: 5}}\n", 3, "sweep.slip",
     "missing required key 'stop'"),
    # wrong type
    (GOOD.replace("speeds: [20]", "speeds: [fast]"), 5, "sweep.speeds[0]", "expected a number [m/s]"),
    (GOOD.replace("num: 11", "num: 2.5"), 4, "sweep.slip.num", "whole number"),
    # out of range
    (GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, sigma0: 0}"), 2, "tire.sigma0",
     "must be > 0"),
    (GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, L: -0.2}"), 2, "tire.L", "must be > 0"),
    (GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, mu_c: 1.6}"), 2, "tire.mu_c",
     "must be <= mu_s"),
    (GOOD.replace("start: -1", "start: -1.2"), 4, "sweep.slip.start", "must be >= -1 and <= 1"),
    (GOOD + "  models: [{model: distributed, load: exponential, lambda: -1}]\n", 6, "sweep.models[0].lambda",
     "must be >= 0"),
    (GOOD + "  models: [{model: lumped, kappa0: abc}]\n", 6, "sweep.models[0].kappa0",
     "expected a number > 0 or Z"),
    (GOOD + "  models: [{model: lumped, kappa0: -1}]\n", 6, "sweep.models[0].kappa0", "must be > 0"),
    (GOOD + "  models: [{model: lumped, load: exponential, lambda: 0}]\n", 6, "sweep.models[0].lambda",
     "lambda must be > 0"),
    (GOOD + "  models: [{model: distributed, load: exponential}]\n", 6, "sweep.models[0]",
     "missing required key 'lambda'"),
    (GOOD + "  models: [{load: uniform}]\n", 6, "sweep.models[0]", "missing required key 'model'"),
    (GOOD + "  models: [distributd]\n", 6, "sweep.models[0]", "did you mean 'distributed'"),
    # NaN / inf
    (GOOD.replace("speeds: [20]", "speeds: [.nan]"), 5, "sweep.speeds[0]", "finite"),
    (GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, v_s: .inf}"), 2, "tire.v_s", "finite"),
    # unknown choice
    (GOOD + "  models: [{model: distributed, load: exponentail, lambda: 2}]\n", 6, "sweep.models[0].load",
     "did you mean 'exponential'"),
    # unknown built-in set
    (GOOD.replace("canudas2003-table1", "canudas2003-table3"), 2, "tire.set", "did you mean 'canudas2003-table2'"),
    # a choice in the wrong case
    (GOOD + "  theta_convention: FM\n", 6, "sweep.theta_convention", "unknown value 'FM'; did you mean 'fm'?"),
    (GOOD + "  models: [Distributd]\n", 6, "sweep.models[0]", "did you mean 'distributed'"),
    # a key whose value is a block mapping or list (starting on the next line) is named at its own line
    (GOOD.replace("sweep:", "swep:"), 3, "swep", "did you mean 'sweep'"),
    ("study: sweep\ntire:\n  set: canudas2003-table1\n  sigm0:\n    value: 170\n", 4, "tire.sigm0",
     "did you mean 'sigma0'"),
    ("study: sweep\ntire: canudas2003-table1\nsweep:\n  slip:\n    start: -1\n    num: 5\n", 4, "sweep.slip",
     "missing required key 'stop'"),
    ("study: sweep\ntire:\n  set: canudas2003-table1\n  sigma0:\n    - 170\n", 4, "tire.sigma0",
     "expected a number [1/m], got a list"),
    ("study: sweep\ntire: canudas2003-table1\nsweep:\n  speeds:\n    - 20\n    - fast\n", 6, "sweep.speeds[1]",
     "expected a number [m/s]"),
])
def test_config_error_classes(cli, tmp_path, text, line, key, words):
    code, err, path = run_sweep(cli, tmp_path, text)
    assert code == 2
    lines = [l for l in err.splitlines() if l.startswith("error:")]
    expect_prefix = f"error: {path}:{line}: " + (f"{key}: " if key else "")
    assert any(l.startswith(expect_prefix) and words in l for l in lines), err
    assert "Traceback" not in err


def test_several_problems_reported_at_once(cli, tmp_path):
    text = GOOD.replace("speeds: [20]", "speeds: [x]").replace("canudas2003-table1", "{set: canudas2003-table1, sigma0: -1}")
    code, err, _ = run_sweep(cli, tmp_path, text)
    assert code == 2
    assert "sweep.speeds[0]" in err and "tire.sigma0" in err


def test_every_problem_of_a_parameter_group_at_once(cli, tmp_path):
    # a set with overrides: a bad value, mu_c > mu_s against the set's mu_s, two unknown keys
    text = GOOD.replace("tire: canudas2003-table1", """tire:
  set: canudas2003-table1
  sigma0: -3
  mu_c: 2.0
  sigma_0: 1
  foo: 1""")
    code, err, path = run_sweep(cli, tmp_path, text)
    assert code == 2 and "Traceback" not in err
    for where in (f"{path}:4: tire.sigma0: out of range: must be > 0",
                  f"{path}:5: tire.mu_c: out of range: must be <= mu_s (1.55), got 2",
                  f"{path}:6: tire.sigma_0: unknown key; did you mean 'sigma0'?",
                  f"{path}:7: tire.foo: unknown key"):
        assert any(line.startswith("error: " + where) for line in err.splitlines()), (where, err)
    # a faulty mu_s override does not fall back to the set's value for the mu_c rule
    text = GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, mu_s: abc, mu_c: 1.6}")
    code, err, path = run_sweep(cli, tmp_path, text)
    assert code == 2 and "tire.mu_s: expected a number" in err and "must be <= mu_s" not in err


def test_unknown_figure_id_names_file_line_and_key(cli, tmp_path):
    text = GOOD.replace("speeds: [20]", "speeds: [x]") + "figures: [fm-fig1-lef, sweep-mu-slip, no-such-figure]\n"
    code, err, path = run_sweep(cli, tmp_path, text)
    assert code == 2 and "Traceback" not in err
    lines = err.splitlines()
    assert f"error: {path}:6: figures[0]: unknown figure 'fm-fig1-lef'; did you mean 'fm-fig1-left'?" in err, err
    assert any(l.startswith(f"error: {path}:6: figures[2]: unknown figure 'no-such-figure'") for l in lines), err
    assert f"{path}:5: sweep.speeds[0]" in err  # reported together, before anything runs
    assert not (tmp_path / "out").exists()
    code, out, err = cli("params", "validate", path)  # validation catches it too
    assert code == 2 and "figures[0]: unknown figure" in err


def test_malformed_yaml_names_the_line(cli, tmp_path):
    code, err, path = run_sweep(cli, tmp_path, "study: sweep\ntire: [1, 2\nsweep: {}\n")
    assert code == 2 and f"{path}:" in err and "malformed YAML" in err


def test_empty_file(cli, tmp_path):
    code, err, path = run_sweep(cli, tmp_path, "")
    assert code == 2 and "empty" in err


def test_duplicate_key(cli, tmp_path):
    code, err, path = run_sweep(cli, tmp_path, GOOD + "sweep: {}\n")
    assert code == 2 and f"{path}:6: sweep: duplicate key" in err


def test_yaml_is_loaded_safely(cli, tmp_path):
    code, err, _ = run_sweep(cli, tmp_path, GOOD + "title: !!python/object/apply:os.system ['echo pwned']\n")
    assert code == 2 and "pwned" not in err


def test_missing_file_is_usage_error(cli, tmp_path):
    code, out, err = cli("sweep", tmp_path / "nope.yaml")
    assert code == 2 and "file not found" in err


def test_wrong_study_for_command(cli, tmp_path):
    code, err, _ = run_sweep(cli, tmp_path, GOOD.replace("study: sweep", "study: swep"))
    assert code == 2 and "did you mean 'sweep'" in err


def test_set_override_errors(cli, tmp_path):
    code, err, _ = run_sweep(cli, tmp_path, GOOD, "--set", "tire.sigma0=-1")
    assert code == 2 and "<command line --set>: tire.sigma0: out of range" in err
    code, err, _ = run_sweep(cli, tmp_path, GOOD, "--set", "tire.sigma0")
    assert code == 2 and "expected KEY=VALUE" in err


def test_set_override_applies_and_clears_assumed(cli, tmp_path):
    import json

    code, err, _ = run_sweep(cli, tmp_path, GOOD, "--set", "tire.sigma0=170", "--set", "tire.alpha=2")
    assert code == 0, err
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    params = run["parameters"]["tire"]["parameters"]
    assert params["sigma0"]["value"] == 170 and params["sigma0"]["source"].startswith("<command line")
    assert "assumed" not in params["alpha"] and "assumed" in params["sigma1"]


def test_usage_errors_exit_2(cli):
    code, out, err = cli("sweep", "--bogus")
    assert code == 2
    code, out, err = cli("no-such-command")
    assert code == 2


def test_debug_shows_traceback(cli, tmp_path):
    code, err, _ = run_sweep(cli, tmp_path, "", "--debug")
    assert code == 2 and "Traceback" in err


def test_parameter_set_file_errors(cli, tmp_path):
    p = write(tmp_path, """\
        name: mine
        kind: lugre
        citation: me
        values:
          sigma0: 100
          sigma1: 1
          sigma2: 0
          mu_c: 0.9
          mu_s: 0.8
          v_s: 5
          L: 0.2
          alpha: 1
          sigma3: 2
        """, "set.yaml")
    code, out, err = cli("params", "validate", p)
    assert code == 2
    assert f"{p}:13: values.sigma3: unknown key" in err
    # the cross-field rule is reported together with the other problem
    assert f"{p}:8: values.mu_c: out of range: must be <= mu_s (0.8)" in err
    p.write_text(p.read_text().replace("  sigma3: 2\n", ""))
    code, out, err = cli("params", "validate", p)
    assert code == 2 and "values.mu_c: out of range: must be <= mu_s" in err
    p.write_text(p.read_text().replace("mu_c: 0.9", "mu_c: 0.7"))
    code, out, err = cli("params", "validate", p)
    assert code == 0 and "valid lugre parameter set 'mine'" in out


def test_omitted_grid_takes_its_default_grid(cli, tmp_path):
    import pandas as pd

    code, err, _ = run_sweep(cli, tmp_path, "study: sweep\ntire: canudas2003-table1\nsweep: {speeds: [20]}\n")
    assert code == 0, err
    df = pd.read_csv(tmp_path / "out" / "data" / "sweep.csv")
    assert len(df) == 1001 and df["slip"].min() == -1.0 and df["slip"].max() == 0.0


def test_exponent_without_a_dot_is_a_number(cli, tmp_path):
    """YAML 1.2 floats: '18154e-2' in a file and '--set ...=1e5' are numbers, not text (PyYAML's 1.1 rule)."""
    import json

    cfg = tmp_path / "s.yaml"
    cfg.write_text(GOOD.replace("tire: canudas2003-table1", "tire: {set: canudas2003-table1, sigma0: 18154e-2}"))
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "o", "--quiet", "--set", "tire.v_s=657E-2")
    assert code == 0, err
    tire = json.loads((tmp_path / "o" / "run.json").read_text())["parameters"]["tire"]
    assert tire["parameters"]["sigma0"]["value"] == 181.54 and tire["parameters"]["v_s"]["value"] == 6.57


def test_yaml_dump_quotes_text_that_would_read_as_a_number():
    """The .tir YAML form and fitted sets are dumped and read back: text such as '1e5' stays text."""
    from tirecli.io.yamlio import dump_yaml, parse_yaml

    data = {"a": "1e5", "b": 1e5, "c": "-2E-3", "d": [1, 2.5, "x"], "e": "2001"}
    assert parse_yaml(dump_yaml(data))[0] == data
    assert parse_yaml("a: ._\nb: .5\nc: 5.\nd: 1_0e1\n")[0] == {"a": "._", "b": 0.5, "c": 5.0, "d": 100.0}


@pytest.mark.parametrize("command", ["sweep", "simulate", "compare", "campaign"])
def test_a_tir_file_given_as_config_is_named_as_such(cli, command):
    """``tirecli sweep my.tir`` said 'malformed YAML: did not find expected <document start>': a .tir
    file where a YAML config is read is refused as what it is, with how a tyre is used."""
    from conftest import ROOT

    tir = ROOT / "tests" / "data" / "tir" / "ExternData_sample.tir"
    code, out, err = cli(command, tir)
    assert code == 2 and err.count("\n") == 1, err
    assert "a .tir tyre property file, not a " in err and "tire: in a config" in err and "YAML" not in err
