"""The CLI: help everywhere, sweep outputs (output contract), params and figures listings."""
import ast
import json
import subprocess
import sys

import pandas as pd
import pytest

from conftest import EXAMPLES


def all_commands():
    from tirecli.cli.main import app
    import typer.main

    group = typer.main.get_command(app)
    paths = [[]]
    for name, cmd in group.commands.items():
        paths.append([name])
        for sub in getattr(cmd, "commands", {}) or {}:
            paths.append([name, sub])
    return paths


@pytest.mark.parametrize("path", all_commands(), ids=lambda p: " ".join(p) or "tirecli")
def test_help_on_every_command(cli, path):
    code, out, err = cli(*path, "--help")
    assert code == 0
    assert "Usage:" in out


def test_installed_entry_point_runs():
    # the console script's target, in a fresh interpreter
    res = subprocess.run([sys.executable, "-c", "from tirecli.cli.main import main; main(['--version'])"],
                         capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout.startswith("tirecli ")


def test_sweep_output_contract(cli, tmp_path):
    out = tmp_path / "o"
    code, stdout, err = cli("--quiet", "sweep", EXAMPLES / "fm-fig1-right.yaml", "--out", out)
    assert code == 0, err
    assert f"wrote {out / 'run.json'}" in stdout
    run = json.loads((out / "run.json").read_text())
    for key in ("command", "config", "parameters", "assumed", "citations", "wall_time_s", "environment", "checks"):
        assert key in run
    assert len(run["config"]["sha256"]) == 64
    assert run["environment"]["tirecli"]
    assert any(a.startswith("tire.alpha") for a in run["assumed"])  # assumed values flagged
    assert run["parameters"]["tire"]["parameters"]["sigma0"] == {"value": 181.54, "unit": "1/m",
                                                                  "source": "canudas2003-table1"}
    assert all(c["passed"] for c in run["checks"]) and run["checks"]
    df = pd.read_csv(out / "data" / "sweep.csv", comment="#")
    for col in ("model", "v", "theta", "theta_obs", "slip", "mu"):
        assert col in df.columns
    assert sorted(df["theta"].unique()) == [0.4, 0.6, 0.8, 1.0]
    assert ((df["slip"] <= 0) == (df["mu"] <= 0)).all()  # braking: mu has the sign of slip
    assert (out / "figures" / "fm-fig1-right.png").stat().st_size > 10_000
    assert (out / "figures" / "fm-fig1-right.svg").read_text().lstrip().startswith("<?xml")


def test_sweep_is_deterministic(cli, tmp_path):
    for name in ("a", "b"):
        assert cli("sweep", EXAMPLES / "obs-fig1.yaml", "--out", tmp_path / name)[0] == 0
    a = (tmp_path / "a" / "data" / "sweep.csv").read_bytes()
    assert a == (tmp_path / "b" / "data" / "sweep.csv").read_bytes()


def test_sweep_driving_and_variants(cli, tmp_path):
    cfg = tmp_path / "s.yaml"
    cfg.write_text("""\
study: sweep
tire: canudas2003-table1
sweep:
  slip: {start: -1, stop: 1, num: 201}
  speeds: [20]
  models:
    - distributed
    - {model: distributed, load: exponential, lambda: 2}
    - {model: distributed, load: parabolic}
    - {model: distributed, load: tabulated, u: [0, 0.5, 1], f: [1, 2, 1]}
    - {model: lumped, kappa0: Z}
    - {model: lumped, kappa0: 1.5}
""")
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    df = pd.read_csv(tmp_path / "o" / "data" / "sweep.csv")
    assert df["model"].nunique() == 6 and set(df["direction"]) == {"braking", "driving"}
    z = df[df["model"] == "lumped kappa0(Z)"]["mu"].to_numpy()
    u = df[df["model"] == "distributed uniform"]["mu"].to_numpy()
    assert abs(z - u).max() < 1e-12


def test_params_list_and_show(cli):
    code, out, err = cli("params", "list")
    assert code == 0 and "canudas2003-table1" in out and "canudas2003-table2" in out
    code, out, err = cli("params", "show", "canudas2003-table1")
    assert code == 0
    assert "181.54 1/m" in out and "[ASSUMED]" in out and "s/m" in out
    code, out, err = cli("params", "show", "canudas2003-tabel1")
    assert code == 2 and "did you mean 'canudas2003-table1'" in err


def test_params_validate_config(cli):
    code, out, err = cli("params", "validate", EXAMPLES / "fm-fig1-left.yaml")
    assert code == 0 and "valid sweep config" in out


def test_figures_list(cli):
    code, out, err = cli("figures", "list")
    assert code == 0
    for fid in ("fm-fig1-left", "fm-fig1-right", "obs-fig1", "fm-fig6-surface", "fm-table1"):
        assert fid in out


def test_every_study_module_registers_its_entry():
    import importlib

    from tirecli.studies.registry import REGISTRY, STUDY_MODULES, load_all
    from tirecli.studies.study import Plan, Study

    for name, module in STUDY_MODULES.items():
        importlib.import_module(module)
        assert isinstance(REGISTRY.get(name), Study), f"{module} does not register study {name!r}"
        assert REGISTRY[name].name == name and callable(REGISTRY[name].plan) and callable(REGISTRY[name].run)
    assert set(load_all()) >= set(STUDY_MODULES)
    assert Plan.__dataclass_fields__.keys() >= {"config", "checked", "sets", "estimate", "detail"}


def test_lugre_sweep_loads_only_what_it_needs(tmp_path):
    # start-up time: a LuGre sweep imports neither the other studies nor their figures nor the MF engine
    code = ("import sys; from tirecli.cli.main import main; "
            f"rc = main(['--quiet', 'sweep', {str(EXAMPLES / 'fm-fig1-left.yaml')!r}, '--out', {str(tmp_path)!r}]); "
            "print(sorted(m for m in sys.modules if m.startswith('tirecli'))); sys.exit(rc)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    loaded = ast.literal_eval(res.stdout.strip().splitlines()[-1])
    assert "tirecli.figures.steady" in loaded and "tirecli.studies.sweep" in loaded
    for unwanted in ("tirecli.studies.simulate", "tirecli.studies.observe", "tirecli.figures.transient",
                     "tirecli.figures.magic_formula", "tirecli.models.magic_formula"):
        assert unwanted not in loaded


def test_generic_sweep_figure_with_many_curves(tmp_path):
    """Many (speed, theta) curves: a colour bar for the speeds, line styles for theta, one panel per
    direction, and a legend that lists the styles rather than every curve (no layout collapse)."""
    import warnings

    from tirecli.config.loader import config_from_text
    from tirecli.figures.registry import get
    from tirecli.studies.registry import run_study

    cfg = config_from_text("""\
study: sweep
tire: canudas2003-table1
sweep:
  slip: {start: -1, stop: 1, num: 101}
  speeds: {start: 5, stop: 30, num: 11}
  theta: [1.0, 0.6]
""", label="<test>")
    many = config_from_text("study: sweep\ntire: canudas2003-table1\nsweep:\n  slip: {start: -1, stop: 0, num: 21}\n"
                            "  speeds: [5, 6, 7, 8, 9, 10, 11, 12, 13]\n  theta: [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2]\n",
                            label="<test>")
    fig9 = get("sweep-mu-slip").draw(run_study(many))     # nine dash patterns needed: styles repeat
    fig9.draw_without_rendering()
    assert "more, styles repeat" in fig9.axes[0].get_legend().get_texts()[-1].get_text()
    fig = get("sweep-mu-slip").draw(run_study(cfg))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # e.g. "constrained_layout not applied"
        fig.draw_without_rendering()
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert [ax.get_title().rsplit(" ", 1)[-1] for ax in panels] == ["(braking)", "(driving)"]
    assert len(fig.axes) == 3                                  # two panels and the colour bar
    for ax in panels:  # 11 speeds x 2 theta: a curve and its peak marker each
        assert len([ln for ln in ax.get_lines() if ln.get_linestyle() != "None"]) == 22
        assert len([ln for ln in ax.get_lines() if ln.get_linestyle() == "None" and ln.get_marker() == "o"]) == 22
    labels = [t.get_text() for t in panels[0].get_legend().get_texts()]
    assert labels == ["peak of each curve (root-found, data/peaks.csv)", "theta = 1", "theta = 0.6"]


def test_progress_covers_evaluation_drawing_and_writing(tmp_path):
    from tirecli.app.run import run_config

    class Recorder:
        def __init__(self):
            self.phases = []

        def start(self, total, label=""):
            self.phases.append([label, total, 0, False])

        def advance(self, n=1):
            self.phases[-1][2] += n

        def close(self):
            self.phases[-1][3] = True

    rec = Recorder()
    run_config("sweep", EXAMPLES / "fm-fig1-left.yaml", out=tmp_path, progress=rec)
    assert [p[0] for p in rec.phases] == ["sweep", "peaks", "figures", "writing"]
    assert all(total == done and closed for _, total, done, closed in rec.phases)


def test_config_assumptions_are_listed_in_run_json(cli, tmp_path):
    code, out, err = cli("sweep", EXAMPLES / "fm-fig1-left.yaml", "--out", tmp_path, "--quiet",
                         "--set", "assumed=[my speeds, my road]")
    assert code == 0, err
    assumed = json.loads((tmp_path / "run.json").read_text())["assumed"]
    assert "my speeds" in assumed and "my road" in assumed
    assert any(a.startswith("tire.alpha:") for a in assumed)      # the parameter set's own stay listed


def test_surface_figure_refuses_a_single_speed(cli, tmp_path):
    code, out, err = cli("sweep", EXAMPLES / "fm-fig1-right.yaml", "--out", tmp_path, "--quiet",
                         "--set", "figures=[fm-fig6-surface]")
    assert code == 2 and "at least two speeds" in err


def test_figure_of_another_study_is_a_config_problem_at_its_line(cli, tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text((EXAMPLES / "fm-fig1-left.yaml").read_text().replace("figures: [fm-fig1-left, fm-table1]",
                                                                        "figures: [fm-fig1-left, obs-fig2]"))
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "o")
    assert code == 2 and "c.yaml:" in err and "figures[1]: obs-fig2:" in err and "an 'observe' run" in err


def test_golden_study_points_to_the_report(cli, tmp_path):
    cfg = tmp_path / "g.yaml"
    cfg.write_text("study: mf-golden\n")
    code, out, err = cli("sweep", cfg)
    assert code == 2 and "for 'tirecli report'" in err


def test_reused_out_dir_holds_one_run_and_says_so(cli, tmp_path):
    """A reused --out holds the new run's outputs only: the earlier run's other outputs are removed
    (the command names them), files tirecli did not write stay."""
    out = tmp_path / "o"
    assert cli("sweep", EXAMPLES / "fm-fig1-left.yaml", "--out", out, "--quiet")[0] == 0
    (out / "notes.txt").write_text("mine")
    code, stdout, err = cli("sweep", EXAMPLES / "fm-fig1-right.yaml", "--out", out)
    assert code == 0
    assert not (out / "figures" / "fm-fig1-left.png").exists() and (out / "figures" / "fm-fig1-right.png").exists()
    assert (out / "notes.txt").read_text() == "mine"
    assert "removed 3 file(s) of the earlier run" in stdout and "figures/fm-fig1-left" in stdout
