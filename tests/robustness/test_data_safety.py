"""Data safety (issue 13): nothing lost, nothing mixed.

Two runs into one target at once (``mf eval`` and a study), Ctrl-C in the middle of a run, a run
that fails while writing, stale locks, inputs inside ``--out``, ``--out ''`` and ragged points
rows. Each through the real CLI in a subprocess (:mod:`harness`); the failures injected at a
chosen point of the writing run the CLI in-process (``cli`` fixture).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from harness import BASE_CMD, assert_clean_error, assert_unchanged, run, snapshot

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TYRE = "externdata-205-60r15"

#: A transient run that takes several seconds after taking the lock (one distributed braking at tol 1e-6).
SLOW = """\
study: simulate
tire: canudas2003-table2
vehicle: canudas2003-obs-quarter-car
initial: {v: 20, slip: 0}
input:
  pressure: {table: {t: [0, 0.5, 2.0, 2.6], value: [0, 0, 50, 0]}}
  pressure_gain: 20
t_end: 3.5
cases:
  - {model: distributed, label: slow, solver: {tol: 1.0e-6}}
figures: [transient-histories]
"""


#: Two quick sweeps with different outputs (the second writes no figure, so files of the first are left over).
FIRST = "study: sweep\ntitle: first\ntire: canudas2003-table1\nsweep: {slip: {start: -0.5, stop: 0.5, num: 11}}\n"
SECOND = FIRST.replace("title: first", "title: second") + "figures: [fm-table1]\n"


#: A campaign of two sweeps over the base config ``BASE`` (figures off: it is quick).
CAMPAIGN = "campaign: c\nbase: BASE\nvary: {tire.mu_s: [1.4, 1.5]}\noutputs: ['mu_peak[0]']\nfigures: false\n"


def _popen(args, cwd) -> subprocess.Popen:
    """``tirecli ARGS`` in the background, Ctrl-C handled as in a terminal (a SIGINT ignored by the
    test runner's parent would otherwise be inherited)."""
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.Popen(BASE_CMD + [str(a) for a in args], cwd=cwd, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for(path: Path, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    """Until ``path`` exists (the run took its lock); fails if the process ends first."""
    t0 = time.monotonic()
    while not path.exists():
        assert proc.poll() is None, f"the run ended early: {proc.communicate()}"
        assert time.monotonic() - t0 < timeout, f"{path} did not appear"
        time.sleep(0.05)


def _lock(target: Path) -> Path:
    return target.parent / f".{target.name}.tirecli-lock"


def _listed(out: Path) -> set[str]:
    """The files run.json lists, with run.json."""
    outputs = json.loads((out / "run.json").read_text())["outputs"]
    return {"run.json"} | {rel for group in ("data", "figures", "files") for rel in outputs[group]}


def _files(out: Path) -> set[str]:
    return {str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def configs(tmp_path_factory) -> dict:
    d = tmp_path_factory.mktemp("configs")
    for name, text in (("first", FIRST), ("second", SECOND), ("slow", SLOW)):
        (d / f"{name}.yaml").write_text(text)
    return {name: d / f"{name}.yaml" for name in ("first", "second", "slow")}


@pytest.fixture(scope="module")
def earlier(configs, tmp_path_factory) -> Path:
    """An output directory holding a complete earlier run."""
    out = tmp_path_factory.mktemp("earlier") / "o"
    r = run(["sweep", configs["first"], "--out", out, "--quiet"], timeout=120)
    assert r.code == 0, r.err
    return out


@pytest.fixture
def previous(earlier, tmp_path) -> Path:
    """A fresh copy of the earlier run's directory, alone in ``tmp_path``."""
    out = tmp_path / "o"
    shutil.copytree(earlier, out)
    return out


def _points(path: Path, fz: float, n: int = 50_000) -> Path:
    kappa = np.linspace(-0.5, 0.5, n)
    rows = np.column_stack([kappa, np.full(n, 0.02), np.zeros(n), np.full(n, fz)])
    np.savetxt(path, rows, delimiter=",", header="kappa,alpha,gamma,fz", comments="", fmt="%.6g")
    return path


# --------------------------------------------------------------------------- two runs at once


def test_two_mf_evals_into_one_file_never_mix(tmp_path):
    """Both succeed, or one is refused naming the other: the result is one run's complete output,
    and a file of the user's named like a temporary file is not touched."""
    from tirecli.app.mf import mf_eval

    a, b = _points(tmp_path / "a.csv", 4000.0), _points(tmp_path / "b.csv", 3000.0)
    for pts, ref in ((a, "ra.csv"), (b, "rb.csv")):
        mf_eval(TYRE, pts, tmp_path / ref)
    refs = {(tmp_path / "ra.csv").read_bytes(), (tmp_path / "rb.csv").read_bytes()}
    assert len(refs) == 2
    (tmp_path / "r.csv.part").write_text("my own file")
    procs = [_popen(["mf", "eval", TYRE, "--points", pts, "--out", "r.csv", "--quiet"], tmp_path) for pts in (a, b)]
    results = [(p.pid, p.wait(timeout=120), p.stderr.read()) for p in procs]
    assert any(code == 0 for _, code, _ in results), results
    for (pid, code, err), (other, _, _) in zip(results, reversed(results)):
        assert code == 0 or (code == 2 and re.fullmatch(
            rf"error: --out r\.csv: in use by another tirecli run \(pid {other} on .*\n", err)), (code, err)
    assert (tmp_path / "r.csv").read_bytes() in refs
    assert (tmp_path / "r.csv.part").read_text() == "my own file"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.csv", "r.csv", "r.csv.part", "ra.csv", "rb.csv"]


def test_a_second_study_into_a_held_directory_is_refused_and_ctrl_c_keeps_the_previous_results(
        configs, previous, tmp_path):
    """While a run holds DIR, a second run into it is refused naming the first; Ctrl-C in the middle
    of the first leaves the earlier results byte-identical and no lock or staging behind."""
    before = snapshot(previous)
    first = _popen(["simulate", configs["slow"], "--out", "o"], tmp_path)
    try:
        _wait_for(_lock(previous), first)
        r = run(["sweep", configs["second"], "--out", previous], timeout=60)
        assert_clean_error(r, 2, rf"--out .*o: in use by another tirecli run \(pid {first.pid} on .*, started .*: "
                                 r"tirecli simulate .*slow\.yaml --out o\); wait for it to finish or choose another --out")
        first.send_signal(signal.SIGINT)
        code = first.wait(timeout=60)
    finally:
        first.kill()
    err = first.stderr.read()
    assert code == 130 and err == "error: interrupted: previous results in o kept\n", (code, err)
    assert_unchanged(before, previous)
    assert os.listdir(tmp_path) == ["o"]


def test_sigterm_is_handled_as_ctrl_c(configs, previous, tmp_path):
    """``kill`` or ``timeout`` stop a run like Ctrl-C: earlier results kept, staging and lock removed."""
    before = snapshot(previous)
    proc = _popen(["simulate", configs["slow"], "--out", "o"], tmp_path)
    try:
        _wait_for(_lock(previous), proc)
        time.sleep(0.5)
        proc.terminate()
        code = proc.wait(timeout=60)
    finally:
        proc.kill()
    assert (code, proc.stderr.read()) == (130, "error: interrupted: previous results in o kept\n")
    assert_unchanged(before, previous)
    assert os.listdir(tmp_path) == ["o"]


@pytest.mark.parametrize("failure, code, message", [
    (KeyboardInterrupt, 130, "error: interrupted: previous results in {out} kept"),
    (RuntimeError("the disk caught fire"), 1, "error: internal error: RuntimeError: the disk caught fire "
                                              "(run with --debug for the traceback); previous results in {out} kept"),
])
def test_a_study_stopped_while_writing_keeps_the_previous_results(cli, monkeypatch, configs, previous, tmp_path,
                                                                  failure, code, message):
    """Ctrl-C or a failure after the data files and half a figure were written: nothing of it shows."""
    from tirecli.io import output

    def half_written(fig, directory, name, dpi=150):
        (Path(directory) / f"{name}.png").write_bytes(b"\x89PNG half")
        raise failure

    monkeypatch.setattr(output, "save_figure", half_written)
    before = snapshot(previous)
    rc, out, err = cli("sweep", configs["first"], "--out", previous, "--quiet")
    assert (rc, err) == (code, message.format(out=previous) + "\n")
    assert_unchanged(before, previous)
    assert os.listdir(tmp_path) == ["o"]


def test_a_figure_error_keeps_the_previous_results(configs, previous):
    before = snapshot(previous)
    r = run(["sweep", configs["second"], "--out", previous, "--set", "figures=[fm-fig6-surface]"])
    assert_clean_error(r, 2, "at least two speeds")
    assert_unchanged(before, previous)
    assert os.listdir(previous.parent) == ["o"]


def test_mf_eval_stopped_while_writing_keeps_the_previous_file(cli, monkeypatch, tmp_path):
    from tirecli.io import fastcsv

    pts = _points(tmp_path / "p.csv", 4000.0, n=10)
    out = tmp_path / "r.csv"
    assert cli("mf", "eval", TYRE, "--points", pts, "--out", out)[0] == 0
    before = out.read_bytes()

    def half_written(path, header, *args, **kwargs):
        Path(path).write_text(header + "\n0.1,")
        raise KeyboardInterrupt

    monkeypatch.setattr(fastcsv, "write_table", half_written)
    rc, _, err = cli("mf", "eval", TYRE, "--points", pts, "--out", out)
    assert (rc, err) == (130, f"error: interrupted: previous {out} kept\n")
    assert out.read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["p.csv", "r.csv"]


def test_a_failed_mf_eval_keeps_the_previous_file(tmp_path):
    from tirecli.app.mf import mf_eval

    mf_eval(TYRE, _points(tmp_path / "p.csv", 4000.0, n=10), tmp_path / "r.csv")
    before = (tmp_path / "r.csv").read_bytes()
    (tmp_path / "bad.csv").write_text("kappa,alpha,gamma,fz\n0.1,0,0,1e300\n")
    r = run(["mf", "eval", TYRE, "--points", "bad.csv", "--out", "r.csv", "--no-limits"], cwd=tmp_path)
    assert r.code in (1, 2) and "Traceback" not in r.err and r.err.count("error:") == 1, r.err
    assert (tmp_path / "r.csv").read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["bad.csv", "p.csv", "r.csv"]


# --------------------------------------------------------------------------- locks


def test_a_stale_lock_and_staging_are_taken_over(configs, previous, tmp_path):
    """A killed run leaves its lock file and staging directory: the next run takes over and cleans up."""
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    _lock(previous).write_text(json.dumps({"pid": dead.pid, "host": "here", "started": 0, "command": "tirecli sweep"}))
    staging = tmp_path / ".o.tirecli-tmp-killed01"
    (staging / "data").mkdir(parents=True)
    (staging / "data" / "sweep.csv").write_text("model,v\nlumped,")
    r = run(["sweep", configs["second"], "--out", previous, "--quiet"], timeout=60)
    assert r.code == 0, r.err
    assert json.loads((previous / "run.json").read_text())["title"] == "second"
    assert _files(previous) == _listed(previous)
    assert os.listdir(tmp_path) == ["o"]


# --------------------------------------------------------------------------- SIGKILL at the commit

#: ``tirecli ARGS`` that kills itself (SIGKILL: no handler, no cleanup) as it moves a file of its commit into
#: place: before the ``KILL_AT_MOVE``-th move, or before the move of the file named ``KILL_AT_NAME``.
KILLED_AT_COMMIT = """
import os, signal, sys
import tirecli.io.commit as commit
real, moves = commit._move, [0]
def move(src, dst):
    moves[0] += 1
    if moves[0] == int(os.environ.get("KILL_AT_MOVE", "0")) or os.path.basename(dst) == os.environ.get("KILL_AT_NAME"):
        os.kill(os.getpid(), signal.SIGKILL)
    real(src, dst)
commit._move = move
from tirecli.cli.main import main
main(sys.argv[1:])
"""


def _killed_at_commit(args, cwd, **where) -> subprocess.CompletedProcess:
    env = dict(os.environ, MPLBACKEND="Agg", **{k: str(v) for k, v in where.items()})
    p = subprocess.run([sys.executable, "-c", KILLED_AT_COMMIT, *map(str, args)], cwd=cwd, env=env, capture_output=True,
                       text=True, timeout=120)
    assert p.returncode == -signal.SIGKILL, (p.returncode, p.stderr[-800:])
    return p


@pytest.mark.parametrize("where", [{"KILL_AT_MOVE": 2}, {"KILL_AT_NAME": "run.json"}], ids=["after-one-move", "before-the-marker"])
def test_a_sweep_killed_while_it_commits_is_completed_by_the_next_run(configs, previous, tmp_path, where):
    """SIGKILL at any instant of the commit (the earlier run's marker already removed, some files moved): the
    next run into the folder completes the killed run's commit from its staging, says so, and the folder then
    holds that run's complete results; nothing of either run is left over."""
    _killed_at_commit(["sweep", configs["second"], "--out", previous, "--quiet"], tmp_path, **where)
    assert not (previous / "run.json").exists() or where.get("KILL_AT_NAME") is None
    from tirecli.io import staging

    with staging._claimed(previous, is_dir=True):  # what the next run finds when it takes the folder
        pass
    assert json.loads((previous / "run.json").read_text())["title"] == "second"
    assert _files(previous) == _listed(previous)
    assert sorted(os.listdir(tmp_path)) == ["o"]  # no staging, journal or lock left

    _killed_at_commit(["sweep", configs["first"], "--out", previous, "--quiet"], tmp_path, **where)
    r = run(["sweep", configs["second"], "--out", previous, "--quiet"], timeout=60)
    assert r.code == 0, r.err
    assert re.fullmatch(rf"note: --out {re.escape(str(previous))}: a run \(pid \d+, started [-\d: ]+: tirecli sweep .*first\.yaml"
                        r".*\) was killed while moving its results into place; its move was completed, so .* held that "
                        r"run's complete results\n", r.err), r.err
    assert json.loads((previous / "run.json").read_text())["title"] == "second"
    assert _files(previous) == _listed(previous)
    assert sorted(os.listdir(tmp_path)) == ["o"]


def test_a_report_killed_while_it_commits_is_completed_by_the_next_run(tmp_path):
    out = tmp_path / "rep"
    args = ["report", "--out", out, "--quiet", "--jobs", "1", "--cache", tmp_path / "cache"]
    r = run([*args, "--only", "fm-table1"], timeout=120)
    assert r.code == 0, r.err
    _killed_at_commit([*args, "--only", "fm-fig1-left"], tmp_path, KILL_AT_NAME="summary.json")
    assert not (out / "summary.json").exists()
    from tirecli.io import commit, staging

    with staging._claimed(out, is_dir=True):
        pass
    summary = json.loads((out / "summary.json").read_text())
    assert [c["id"].split("/")[0] for c in summary["checks"]] == ["fm-fig1-left"] * len(summary["checks"])
    assert {str(p.relative_to(out)) for p in out.rglob("*") if p.is_file()} == commit.listed_outputs(out)
    assert sorted(os.listdir(tmp_path)) == ["cache", "rep"]


def _dead_pid() -> int:
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    return dead.pid


def test_temporary_files_of_killed_runs_are_removed_by_the_next_run(configs, previous, tmp_path):
    """A run killed with SIGKILL leaves its staging, its journal's and its files' temporary copies: the next run
    into the same folder removes those whose process is dead (a campaign's folder too, and the report's cache),
    and leaves a live process's and anything that is not tirecli's."""
    dead, live = _dead_pid(), os.getpid()
    beside = [tmp_path / f".o.tirecli-tmp-{dead}-abcdefgh", tmp_path / f"..o.tirecli-commit.tirecli-tmp-{dead}-abcdefgh"]
    inside = [previous / "data" / f".sweep.csv.tirecli-tmp-{dead}-abcdefgh"]
    stays = [previous / "data" / f".sweep.csv.tirecli-tmp-{live}-abcdefgh", previous / f"mine.tirecli-tmp-{dead}-abcdefgh"]
    beside[0].mkdir()
    (beside[0] / "run.json").write_text("{}")
    for path in beside[1:] + inside + stays:
        path.write_text("partial")
    r = run(["sweep", configs["second"], "--out", previous, "--quiet"], timeout=60)
    assert r.code == 0, r.err
    assert not any(p.exists() for p in beside + inside) and all(p.exists() for p in stays)

    camp = tmp_path / "c"
    (camp / "points").mkdir(parents=True)
    (tmp_path / "c.yaml").write_text(CAMPAIGN.replace("BASE", str(configs["first"])))
    left = [camp / f".results.csv.tirecli-tmp-{dead}-abcdefgh", camp / "points" / f".part-000001.parquet.tirecli-tmp-{dead}-a1b2c3d4"]
    for path in left:
        path.write_text("partial")
    r = run(["campaign", tmp_path / "c.yaml", "--out", camp, "--quiet"], timeout=60)
    assert r.code == 0, r.err
    assert not any(p.exists() for p in left)

    from tirecli.io.cache import write_timings

    cache = tmp_path / "cache"
    (cache / "v1" / "memo").mkdir(parents=True)
    left = [cache / "v1" / "memo" / f".abc.txt.tirecli-tmp-{dead}-abcdefgh", cache / "v1" / f".timings.json.tirecli-tmp-{dead}-abcdefgh"]
    for path in left:
        path.write_text("partial")
    write_timings(cache, {"sweep": 1.0})
    assert not any(p.exists() for p in left) and (cache / "v1" / "timings.json").is_file()


# --------------------------------------------------------------------------- inputs inside --out


def test_inputs_inside_out_are_never_removed_or_overwritten(configs, previous):
    """A config inside --out that the earlier run listed as its output stays; a run whose output
    would overwrite its own config is refused before anything moves."""
    cfg = previous / "my.yaml"
    shutil.copyfile(configs["second"], cfg)
    text = cfg.read_bytes()
    record = json.loads((previous / "run.json").read_text())
    record["outputs"]["files"] = ["my.yaml"]  # as if the earlier run had written it (like fit's fitted.yaml)
    (previous / "run.json").write_text(json.dumps(record))
    r = run(["sweep", cfg, "--out", previous], timeout=60)
    assert r.code == 0, r.err
    assert cfg.read_bytes() == text
    assert re.search(r"note: kept .*my\.yaml of the earlier run in .*: an input of this run", r.out), r.out
    assert not (previous / "figures" / "sweep-mu-slip.png").exists()  # the earlier run's own outputs are gone

    (previous / "run.json").write_bytes(text)  # a config named run.json: the run would write over it
    before = snapshot(previous)
    r = run(["sweep", previous / "run.json", "--out", previous], timeout=60)
    assert_clean_error(r, 2, r"--out .*o: the run would overwrite its input .*o/run\.json; choose another --out")
    assert_unchanged(before, previous)


@pytest.mark.parametrize("campaign_name, base_name, overwritten", [
    ("c.yaml", "results.csv", "results.csv"),         # the base config named like the results
    ("summary.json", "base.yaml", "summary.json"),    # the campaign file named like its summary
    ("points/c.yaml", "base.yaml", "points/c.yaml"),  # in the folder of stored points (pruned by the campaign)
])
def test_a_campaign_never_overwrites_its_inputs(configs, tmp_path, campaign_name, base_name, overwritten):
    """As every other command: a campaign whose outputs in --out would overwrite its campaign file or its base
    config is refused before it runs, naming the input, and nothing in --out changes."""
    out = tmp_path / "o"
    (out / "points").mkdir(parents=True)
    shutil.copyfile(configs["first"], out / base_name)
    base = os.path.relpath(out / base_name, (out / campaign_name).parent)
    (out / campaign_name).write_text(CAMPAIGN.replace("BASE", base))
    before = snapshot(out)
    r = run(["campaign", out / campaign_name, "--out", out], cwd=tmp_path, timeout=60)
    assert_clean_error(r, 2, rf"--out .*o: the run would overwrite its input .*o/{re.escape(overwritten)}\b.*choose another --out")
    assert_unchanged(before, out)


@pytest.mark.parametrize("args", [
    ["mf", "eval", TYRE, "--points", "r.csv", "--out", "r.csv"],
    ["tir", "convert", "my.tir", "--to", "tir", "--out", "my.tir"],
])
def test_a_single_file_output_never_overwrites_its_input(tmp_path, args):
    _points(tmp_path / "r.csv", 4000.0, n=5)
    shutil.copyfile(Path(__file__).resolve().parents[2] / "tirecli" / "parameters" / "data" / f"{TYRE}.tir",
                    tmp_path / "my.tir")
    before = snapshot(tmp_path)
    r = run(args, cwd=tmp_path)
    assert_clean_error(r, 2, rf"--out {args[-1]}: the run would overwrite its input {args[-1]}")
    assert_unchanged(before, tmp_path)


# --------------------------------------------------------------------------- arguments and points


def test_a_special_file_as_out_is_refused_not_replaced(tmp_path):
    os.mkfifo(tmp_path / "fifo")
    _points(tmp_path / "p.csv", 4000.0, n=5)
    r = run(["mf", "eval", TYRE, "--points", "p.csv", "--out", "fifo"], cwd=tmp_path)
    assert_clean_error(r, 2, r"--out fifo: (is a FIFO.*)?not a regular file")
    assert (tmp_path / "fifo").is_fifo() and sorted(os.listdir(tmp_path)) == ["fifo", "p.csv"]


@pytest.mark.parametrize("args", [
    ["sweep", EXAMPLES / "fm-fig1-left.yaml"],
    ["simulate", EXAMPLES / "fm-fig4.yaml"],
    ["report", "--only", "FM"],
    ["mf", "eval", TYRE, "--points", "p.csv"],
    ["tir", "convert", TYRE, "--to", "yaml"],
])
def test_empty_out_is_an_error(tmp_path, args):
    r = run(args + ["--out", ""], cwd=tmp_path)
    assert_clean_error(r, 2, r"^error: --out '': empty")
    assert os.listdir(tmp_path) == []


def test_points_row_with_another_field_count_is_an_error_naming_the_row(tmp_path):
    """A trailing comma on one row would shift every output column of the copied row."""
    (tmp_path / "p.csv").write_text("kappa,alpha,gamma,fz\n0,0,0,4000\n0.1,0.02,0,4000,\n")
    r = run(["mf", "eval", TYRE, "--points", "p.csv", "--out", "r.csv"], cwd=tmp_path)
    assert_clean_error(r, 2, r"p\.csv: data row 2 has 5 fields but the header names 4 columns")
    assert os.listdir(tmp_path) == ["p.csv"]
