"""Every YAML snippet of README.md and docs/ is read by the loader, so documentation and loader cannot drift.

Each ```yaml block is one of:

- a study config (``study:``): ``tirecli params validate`` accepts it, and it runs with the command of
  its study (``sweep``, ``simulate``, ``observe``, ``fit``, ``compare``). The default run uses
  smaller grids and shorter times (``REDUCE``, as ``--set`` overrides) to stay fast; the ``slow``
  test runs every config exactly as documented (``pytest -m slow``);
- a parameter set (``kind:``): ``tirecli params validate`` accepts it;
- a campaign (``campaign:``): ``tirecli params validate`` accepts it (every point checked; tests/test_campaign.py
  runs campaigns);
- a CI pipeline (docs/ci.md): a GitHub Actions workflow (``jobs:`` whose jobs have ``steps:``) or
  GitLab CI jobs (mappings with ``script:``), not a tirecli file: it parses as YAML (as the CI
  system reads it), its ``tirecli`` commands are valid, and it publishes the JUnit file and keeps
  the report folder that its ``tirecli report`` writes (:func:`test_ci_pipeline`);
- a fragment (e.g. the forms a ``tire:`` group may take, one per line): listed in ``FRAGMENTS``
  with the study to check it in; each of its top-level entries is validated inside a minimal
  config of that study. A new fragment fails :func:`test_every_fragment_is_checked` until it is
  listed there.

Snippets run in a temporary directory that holds the files they refer to (``SUPPORT``): the
README's parameter set as ``my-tire.yaml``, a ``.tir`` file as ``tyres/my.tir``, and small
synthetic CSVs (``run.csv``, ``measured_clean.csv``, ``braking.csv``) and a TYDEX braking (``braking.tdx``).
"""
from __future__ import annotations

import json
import re
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT

DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
FENCE = re.compile(r"^```yaml[ \t]*\n(.*?)^```", re.S | re.M)

#: Fragments: (file, first line of the block) -> the study config lines each entry is checked in.
FRAGMENTS = {
    ("README.md", "tire: canudas2003-table1                         # a built-in set"): "study: sweep",
    ("README.md", "tire: chrono-185-80r14                    # a built-in tyre (tirecli params list)"): "study: sweep",
    ("docs/observe.md", "solver:"): ("study: observe\ntire: canudas2003-table1\nestimate: {v_error: 0}\n"
                                      "scenario: {duration: 5, theta: 1, torque: 0, v0: 20}"),
}

#: Size reductions of the default (fast) run, per study, as ``--set`` values: a top-level key always,
#: ``parent.key`` when the config has that parent (a mapping, or ``true`` which becomes ``{key: value}``);
#: every grid ``{start, stop, num}`` is capped at ``GRID_CAP`` points.
REDUCE = {
    "sweep": {},
    "mcps-stationary": {"carcass": "[rigid]"},
    "mcps-slider": {"periods": "1", "samples": "64", "compare_period": "null"},
    "mcps-standstill": {"cycles": "1", "samples": "64", "patch_samples": "8", "grid": "21"},
    "mcps-relaxation": {"distance": "0.5", "cells": "40"},
    "relaxation": {"distance": "0.5", "samples": "101", "cells": "40"},
    "observe": {"scenario.duration": "6", "metrics.phases": "[0, 3, 6]"},
    "simulate": {"t_end": "0.6"},
    "fit": {"fit.method": "fm"},  # the output-error stage (about a minute) runs in the slow test only
    "mf-fit": {"options.parts": "[longitudinal]"},
}
GRID_CAP = 21



@dataclass
class Block:
    file: str     # relative to the repository
    line: int     # line of the opening fence
    text: str

    @property
    def id(self) -> str:
        return f"{self.file}:{self.line}"

    @property
    def first_line(self) -> str:
        return self.text.splitlines()[0].rstrip() if self.text.strip() else ""

    @property
    def name(self) -> str:
        return re.sub(r"[^A-Za-z0-9]+", "-", f"{self.file}-{self.line}").strip("-") + ".yaml"


def yaml_blocks() -> list[Block]:
    out = []
    for path in DOCS:
        text = path.read_text(encoding="utf-8")
        for m in FENCE.finditer(text):
            out.append(Block(str(path.relative_to(ROOT)), text[:m.start()].count("\n") + 1, m.group(1)))
    return out


def parse(block: Block):
    """The block as the loader reads it (None for a fragment that is not one valid mapping)."""
    from tirecli.errors import ConfigError
    from tirecli.io.yamlio import parse_yaml

    try:
        data, _ = parse_yaml(block.text, block.id)
    except ConfigError:
        return None
    return data if isinstance(data, dict) else None


def ci_pipeline(block: Block):
    """The block as a CI system reads it, when it is a GitHub Actions workflow or GitLab CI jobs; else None."""
    import yaml

    try:
        data = yaml.safe_load(block.text)
    except yaml.YAMLError:
        return None
    if not isinstance(data, dict):
        return None
    jobs = data.get("jobs")
    if isinstance(jobs, dict) and jobs and all(isinstance(j, dict) and "steps" in j for j in jobs.values()):
        return data
    jobs = [v for v in data.values() if isinstance(v, dict)]
    if jobs and all("script" in j for j in jobs):
        return data
    return None


def kind_of(block: Block) -> str:
    data = parse(block)
    if data is not None and "study" in data:
        return "config"
    if data is not None and "kind" in data:
        return "set"
    if data is not None and "campaign" in data:
        return "campaign"
    if ci_pipeline(block) is not None:
        return "ci"
    return "fragment"


BLOCKS = yaml_blocks()
CONFIGS = [b for b in BLOCKS if kind_of(b) == "config"]
PIPELINES = [b for b in BLOCKS if kind_of(b) == "ci"]


def entries(text: str) -> list[str]:
    """Top-level entries of a YAML text: a line at column 0 with the indented lines after it
    (comment lines at column 0 are left out)."""
    out: list[list[str]] = []
    for line in text.splitlines():
        if line.startswith("#") or (not out and not line.strip()):
            continue
        if line.strip() and line[0] not in " \t":
            out.append([line])
        else:
            out[-1].append(line)
    return ["\n".join(e) + "\n" for e in out]


# --------------------------------------------------------------------------- support files


def _write_support(d: Path) -> None:
    """The files the snippets refer to, in the directory they run in."""
    from tirecli.models.lugre import mu_ss_uniform
    from tirecli.parameters.sets import load_builtin

    lugre_sets = [b for b in BLOCKS if b.file == "README.md" and kind_of(b) == "set"
                  and parse(b).get("kind") == "lugre"]
    assert lugre_sets, "README.md lost its LuGre parameter-set example (my-tire.yaml of its tire: forms)"
    (d / "my-tire.yaml").write_text(lugre_sets[0].text)
    (d / "examples").symlink_to(ROOT / "examples")  # the data files of docs/data.md's configs
    (d / "tyres").mkdir(exist_ok=True)
    shutil.copy(ROOT / "tests" / "data" / "tir" / "mf_185_80R14.tir", d / "tyres" / "my.tir")
    # kinematics: a braking from 20 m/s with a slip rising to 0.15 and back (t, v, s)
    t = np.round(np.arange(0, 351) * 0.01, 10)
    v = 20.0 - 4.0 * t
    s = -0.15 * np.sin(np.pi * t / 3.5) ** 2
    p = load_builtin("canudas2003-table2").model()
    mu = mu_ss_uniform(v * s, v * (1 + s), p)
    pd.DataFrame({"t": t, "v": v, "slip": s}).to_csv(d / "run.csv", index=False)
    two = pd.concat([pd.DataFrame({"case": f"braking #{k}", "braking": k, "t": t, "v": v, "s": s * k / 2, "mu": mu})
                     for k in (1, 2)])
    two.to_csv(d / "measured_clean.csv", index=False)
    two.rename(columns={"s": "slip_ratio"}).to_csv(d / "braking.csv", index=False)
    _write_rig_braking(d / "braking.tdx")


def _write_rig_braking(path: Path) -> None:
    """``braking.tdx``: a SYNTHETIC braking that locks the wheel (lumped kappa0(Z) quarter car, FM Table 2 with
    sigma1 = 1.15 s/m, 20 N m/bar x a pressure ramp to 65 bar, 100 Hz) as a rig logs it: MEASNUMB 2, RUNTIME,
    LONGVEL, WHROTSPD, ROLLRADI, FX, FZW and the brake pressure BRKPRES [bar], by tirecli's TYDEX writer."""
    from dataclasses import replace

    from tirecli.io.measured import RawColumn, assemble
    from tirecli.io.readers import write_measured
    from tirecli.models.profiles import Constant, Table
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs
    from tirecli.parameters.sets import load_builtin

    p = replace(load_builtin("canudas2003-table2").model(), sigma1=1.15)
    car = load_builtin("canudas2003-obs-quarter-car").model()
    knots, bar = (0.0, 0.1, 0.6, 0.9), (0.0, 0.0, 65.0, 0.0)
    ts = np.round(np.arange(121) * 0.01, 12)
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), p, car, Table(knots, tuple(-20.0 * b for b in bar)),
                          Constant(1.0), 20.0, 20.0 / car.r, 1.2, runs.SolverOptions(tol=1e-6), sample_times=tuple(ts))
    Y, O = tr.sample(ts)
    n = ts.size
    cols = {"run": np.full(n, 2.0), "t": ts, "vx": Y[:, 0], "omega": Y[:, 1], "re": np.full(n, car.r),
            "fx": np.asarray(O["mu"]) * car.F_n, "fz": np.full(n, car.F_n), "BRKPRES": np.interp(ts, knots, bar)}
    raw = [RawColumn(v, k, k, "bar" if k == "BRKPRES" else None) for k, v in cols.items()]
    data = assemble(path, "tdx", raw, "iso", comments=["SYNTHETIC DATA generated by tirecli (docs test)"])
    data.frame["BRKPRES"] = cols["BRKPRES"]  # written in bar, as the channel's unit says
    data.channels["BRKPRES"] = replace(data.channels["BRKPRES"], unit="bar")
    write_measured(path, data, "tdx")


@pytest.fixture(scope="module")
def snippet_dir(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("docs")
    _write_support(d)
    for b in BLOCKS:
        (d / b.name).write_text(b.text)
    return d


# --------------------------------------------------------------------------- tests


def test_docs_have_yaml_snippets():
    """The extraction finds the documented examples (a broken pattern must not pass silently)."""
    files = {b.file for b in BLOCKS}
    assert {"README.md", "docs/transient.md", "docs/observe.md", "docs/models/mcps_tire.md"} <= files
    assert len(CONFIGS) >= 10
    assert {parse(b)["study"] for b in CONFIGS} >= {"sweep", "simulate", "observe", "fit", "mcps-stationary",
                                                    "mcps-slider", "mcps-standstill", "mcps-relaxation"}
    assert len([b for b in PIPELINES if b.file == "docs/ci.md"]) == 2  # GitHub Actions and GitLab CI


def test_every_fragment_is_checked():
    """A block that is neither a study config nor a parameter set must be listed in FRAGMENTS."""
    unknown = [b.id for b in BLOCKS if kind_of(b) == "fragment" and (b.file, b.first_line) not in FRAGMENTS]
    assert not unknown, f"YAML fragments without a check (add them to FRAGMENTS in {__file__}): {unknown}"


@pytest.mark.parametrize("block", [b for b in BLOCKS if kind_of(b) != "ci"], ids=lambda b: b.id)
def test_snippet_validates(cli, snippet_dir, block):
    kind = kind_of(block)
    if kind in ("config", "set", "campaign"):
        code, out, err = cli("params", "validate", snippet_dir / block.name)
        assert code == 0, f"{block.id}: {err}"
        assert ("valid " + {"set": "parameter set", "config": "config", "campaign": "campaign"}[kind]) in out or "valid" in out
        return
    wrapper = FRAGMENTS.get((block.file, block.first_line))
    if wrapper is None:
        pytest.fail(f"{block.id}: a YAML fragment not listed in FRAGMENTS")
    parts = entries(block.text)
    assert parts, f"{block.id}: no entries"
    for i, part in enumerate(parts):
        path = snippet_dir / f"{Path(block.name).stem}-entry{i}.yaml"
        path.write_text(wrapper + "\n" + part)
        code, out, err = cli("params", "validate", path)
        assert code == 0, f"{block.id}, entry {i + 1} ({part.splitlines()[0].strip()}): {err}"


def _reductions(study: str, data: dict) -> list[str]:
    out = []

    def grids(node, path):
        if isinstance(node, dict):
            if {"start", "stop", "num"} <= set(node) and isinstance(node["num"], int) and node["num"] > GRID_CAP:
                out.append(f"{path}.num={GRID_CAP}")
            for k, v in node.items():
                grids(v, f"{path}.{k}" if path else str(k))

    grids(data, "")
    for key, value in REDUCE[study].items():
        if "." not in key:
            out.append(f"{key}={value}")
            continue
        parent, leaf = key.rsplit(".", 1)
        if isinstance(data.get(parent), dict):
            out.append(f"{key}={value}")
        elif data.get(parent) is True:  # e.g. calibrate: true -> calibrate: {points: 8}
            out.append(f"{parent}={{{leaf}: {value}}}")
    return out


def _run(cli, snippet_dir, block, tmp_path, reduced: bool):
    data = parse(block)
    study = data["study"]
    sets = _reductions(study, data) if reduced else []
    from tirecli.studies import registry

    args = [*registry.get(study).command.split(), snippet_dir / block.name, "--out", tmp_path / "out"]  # its command
    for s in sets:
        args += ["--set", s]
    code, out, err = cli("--quiet", *args)
    assert code == 0, f"{block.id} ({' '.join(map(str, args))}): {err}"
    run = json.loads((tmp_path / "out" / "run.json").read_text())
    assert run["study"] == study
    assert run["outputs"]["data"], f"{block.id}: no data written"


@pytest.mark.parametrize("block", CONFIGS, ids=lambda b: b.id)
def test_documented_config_runs(cli, snippet_dir, block, tmp_path, monkeypatch):
    """Each documented study config runs with its command: smaller grids and times (REDUCE), and its
    figures drawn but not rendered to PNG/SVG (rendering takes most of the time; the slow test does it)."""
    from tirecli.io import output

    monkeypatch.setattr(output, "save_figure", lambda fig, *a, **k: [])
    _run(cli, snippet_dir, block, tmp_path, reduced=True)


@pytest.mark.slow
@pytest.mark.parametrize("block", CONFIGS, ids=lambda b: b.id)
def test_documented_config_runs_as_written(cli, snippet_dir, block, tmp_path):
    """Each documented study config runs exactly as written (about a minute in all)."""
    _run(cli, snippet_dir, block, tmp_path, reduced=False)


def test_solver_tol_null_is_accepted_as_documented(cli, tmp_path):
    """``solver: {tol: null}`` (the documented default) and a case's ``solver: {tol: null}`` are accepted;
    a tolerance out of range is still an error."""
    base = "study: simulate\ntire: canudas2003-table2\nt_end: 0.2\n"
    good = tmp_path / "good.yaml"
    good.write_text(base + "solver: {tol: null, h_max: 0.05}\ncases: [{model: lumped, kappa0: Z, solver: {tol: null}},"
                           " {model: lumped, kappa0: 1, solver: {tol: 1.0e-4}}]\n")
    code, out, err = cli("params", "validate", good)
    assert code == 0, err
    bad = tmp_path / "bad.yaml"
    bad.write_text(base + "solver: {tol: 0}\n")
    code, out, err = cli("params", "validate", bad)
    assert code == 2 and "solver.tol: out of range" in err, err
    bad.write_text(base + "solver: {tol: fast}\n")
    code, out, err = cli("params", "validate", bad)
    assert code == 2 and "solver.tol" in err and err.count("\n") == 1, err


@pytest.mark.parametrize("block", PIPELINES, ids=lambda b: b.id)
def test_ci_pipeline(block):
    """A CI example: its tirecli commands are valid; the one running ``tirecli report --strict --junit
    FILE`` is followed by steps that publish FILE as the JUnit test report and keep the report folder,
    also when the job failed."""
    from doc_commands import parse as parse_command
    from doc_commands import split

    data = ci_pipeline(block)
    if "jobs" in data:  # GitHub Actions: steps with run: (shell) or uses: (an action)
        jobs = {name: (job["steps"], None) for name, job in data["jobs"].items()}
    else:  # GitLab CI: script lines, artifacts
        jobs = {name: ([{"run": line} for line in job["script"]], job.get("artifacts")) for name, job in data.items()}
    reports = 0
    for name, (steps, artifacts) in jobs.items():
        for step in steps:
            for argv in (a for line in str(step.get("run", "")).splitlines() for a in split(line)):
                path, params = parse_command(argv)
                if path != ["report"]:
                    continue
                assert params["strict"] and params["junit"], f"{block.id}: {name}: tirecli {' '.join(argv)}"
                junit, folder = params["junit"], params["out"].rstrip("/")
                reports += 1
                if artifacts is not None:  # GitLab
                    assert artifacts["when"] == "always"
                    assert artifacts["reports"]["junit"] == junit
                    assert folder in [p.rstrip("/") for p in artifacts["paths"]]
                else:  # GitHub
                    after = steps[steps.index(step) + 1:]
                    kept = [s for s in after if str(s.get("uses", "")).startswith("actions/upload-artifact@")]
                    published = [s for s in after if "junit" in str(s.get("uses", ""))]
                    assert kept and kept[0]["with"]["path"].rstrip("/") == folder and kept[0]["if"] == "always()"
                    assert published and published[0]["with"]["report_paths"] == junit
                    assert published[0]["if"] == "always()"
    assert reports == 1, f"{block.id}: expected one 'tirecli report --strict --junit FILE'"


# --------------------------------------------------------------------------- Python examples

PYTHON_FENCE = re.compile(r"^```python[ \t]*\n(.*?)^```", re.S | re.M)
#: The pages whose Python examples run as written: every block, in order, in one fresh Python process
#: in an empty folder (the public API, docs/api.md; adding a study, docs/development.md).
RUNNABLE_PYTHON = ["docs/api.md", "docs/development.md"]


@pytest.mark.parametrize("page", RUNNABLE_PYTHON)
def test_python_examples_run_as_written(page, tmp_path):
    import os
    import subprocess
    import sys

    blocks = PYTHON_FENCE.findall((ROOT / page).read_text(encoding="utf-8"))
    assert len(blocks) >= 3, page
    script = tmp_path / "examples.py"
    script.write_text("\n\n".join(blocks), encoding="utf-8")
    work = tmp_path / "work"
    work.mkdir()
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    res = subprocess.run([sys.executable, str(script)], cwd=work, capture_output=True, text=True, env=env, timeout=600)
    assert res.returncode == 0, f"{page}: {res.stderr[-4000:]}"
    assert "Traceback" not in res.stderr, res.stderr[-4000:]
