"""The report's speed machinery (issue 14): the study cache, the process pool, figures rendered once.

No timings here (see benchmarks/bench_report.py): each test checks what ran (``study_cached`` in
summary.json, the calls of ``run_study``) and that the outputs do not depend on the cache or on
the number of processes.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

#: Three small studies of three papers: a sweep (with a table), the golden MF data and one MCPS slider.
ONLY = ["--only", "fm-fig1-left", "--only", "fm-table1", "--only", "mf-golden-fx0", "--only", "mcps-fig3"]
STUDIES = {"fm-fig1-left", "mf-golden", "mcps-fig3"}


def _report(cli, out: Path, *extra) -> dict:
    code, stdout, err = cli("--quiet", "report", "--out", out, *ONLY, *extra)
    assert code == 0, err
    return json.loads((out / "summary.json").read_text())


def _cache() -> Path:
    """The study cache of a report without --cache: $TIRECLI_CACHE_DIR, a folder of this test (tests/conftest.py)."""
    return Path(os.environ["TIRECLI_CACHE_DIR"])


def _files(out: Path, pattern: str) -> dict:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.glob(pattern))}


def _with_changed_set(monkeypatch, tmp_path: Path, name: str, change, run):
    """``run()`` while the file of built-in parameter set ``name`` reads as ``change(text)``; then the real one again."""
    from tirecli.parameters import sets
    from tirecli.report import work

    real_path = sets.builtin_path
    changed = tmp_path / f"{name}.yaml"
    changed.write_text(change(real_path(name).read_text()))
    assert changed.read_text() != real_path(name).read_text()
    monkeypatch.setattr(sets, "builtin_path", lambda n: changed if n == name else real_path(n))
    caches = (sets._parsed_builtin, work.set_digest)
    for fn in caches:
        fn.cache_clear()
    try:
        return run()
    finally:  # the real set again, for this process's later tests
        monkeypatch.setattr(sets, "builtin_path", real_path)
        for fn in caches:
            fn.cache_clear()


@pytest.fixture
def counted(monkeypatch) -> list:
    """The studies run in this process (``--jobs 1``), by name."""
    from tirecli.studies import registry  # the report runs its studies through it

    calls, real = [], registry.run_study

    def run_study(config, *args, **kwargs):
        calls.append(config.label)
        return real(config, *args, **kwargs)

    monkeypatch.setattr(registry, "run_study", run_study)
    return calls


def test_a_second_report_takes_every_study_from_the_cache(cli, tmp_path, counted):
    out = tmp_path / "rep"
    first = _report(cli, out, "--jobs", "1")
    assert first["study_cached"] == dict.fromkeys(STUDIES, False) and len(counted) == 3
    before = {**_files(out, "data/*/*.csv"), **_files(out, "figures/*"), **_files(out, "studies/*.json")}
    second = _report(cli, out, "--jobs", "1")
    assert len(counted) == 3, "a study ran again"
    assert second["study_cached"] == dict.fromkeys(STUDIES, True)
    assert second["checks"] == first["checks"] and second["n_checks"] > 10
    assert {**_files(out, "data/*/*.csv"), **_files(out, "figures/*"), **_files(out, "studies/*.json")} == before
    # the cache lives outside the report's folder (which an artifact of a CI job keeps): nothing of it there
    assert (_cache() / "v1" / "mcps-fig3").is_dir() and out not in _cache().parents
    assert not [p for p in out.rglob("*") if "cache" in p.name or p.name in ("manifest.json", "card.json")]
    assert "data:image/png;base64," in (out / "index.html").read_text()

    third = _report(cli, out, "--jobs", "1", "--no-cache")
    assert len(counted) == 6 and third["study_cached"] == dict.fromkeys(STUDIES, False)
    assert third["checks"] == first["checks"]


def test_a_changed_parameter_or_config_reruns_only_the_studies_it_affects(cli, tmp_path, monkeypatch, counted):
    from tirecli.report import build

    out = tmp_path / "rep"
    _report(cli, out, "--jobs", "1")
    # canudas2003-table1 (read by fm-fig1-left only) gets another value of sigma2
    second = _with_changed_set(monkeypatch, tmp_path, "canudas2003-table1",
                               lambda text: text.replace("sigma2: 0.0018", "sigma2: 0.0019"),
                               lambda: _report(cli, out, "--jobs", "1"))
    assert second["study_cached"] == {"fm-fig1-left": False, "mf-golden": True, "mcps-fig3": True}
    assert counted[3:] == ["<built-in fm-fig1-left>"]

    # a changed config value: its study runs (and fm-fig1-left, whose parameter set is back to the real one)
    real = build.builtin_config
    monkeypatch.setattr(build, "builtin_config",
                        lambda name, overrides=(): real(name, list(overrides) + (["period=2.5"] if name == "mcps-fig3" else [])))
    third = _report(cli, out, "--jobs", "1")
    assert third["study_cached"] == {"fm-fig1-left": False, "mf-golden": True, "mcps-fig3": False}
    assert sorted(counted[4:]) == ["<built-in fm-fig1-left>", "<built-in mcps-fig3>"]


@pytest.mark.parametrize("damage", ["manifest", "csv", "png", "card"])
def test_a_damaged_cache_entry_is_recomputed(cli, tmp_path, damage):
    out = tmp_path / "rep"
    first = _report(cli, out, "--jobs", "1")
    before = {**_files(out, "data/*/*.csv"), **_files(out, "figures/*")}
    entry = next(_cache().glob("v1/mcps-fig3/*"))
    target = {"manifest": entry / "manifest.json", "csv": next(entry.glob("files/data/*.csv")),
              "png": next(entry.glob("fig-*/*.png")), "card": next(entry.glob("fig-*/card.json"))}[damage]
    target.write_bytes(target.read_bytes()[: len(target.read_bytes()) // 2])
    second = _report(cli, out, "--jobs", "1")
    assert second["study_cached"] == {"fm-fig1-left": True, "mf-golden": True, "mcps-fig3": False}
    assert second["checks"] == first["checks"]
    assert {**_files(out, "data/*/*.csv"), **_files(out, "figures/*")} == before
    assert _report(cli, out, "--jobs", "1")["study_cached"]["mcps-fig3"] is True  # the entry was replaced


def test_a_cache_elsewhere_and_an_unreadable_one(cli, tmp_path):
    out, cache = tmp_path / "rep", tmp_path / "cache"
    _report(cli, out, "--jobs", "1", "--cache", cache)
    assert not any(_cache().iterdir()) and (cache / "v1" / "mcps-fig3").is_dir()
    assert set(_report(cli, tmp_path / "other", "--jobs", "1", "--cache", cache)["study_cached"].values()) == {True}
    (cache / "v1" / "mcps-fig3").chmod(0o000)  # (root reads it anyway: then it is simply a hit)
    try:
        summary = _report(cli, tmp_path / "third", "--jobs", "1", "--cache", cache)
    finally:
        (cache / "v1" / "mcps-fig3").chmod(0o755)
    assert summary["n_failed"] == 0


def test_a_cache_that_is_a_file_is_a_usage_error(cli, tmp_path):
    """``--cache FILE`` (an existing file) ran the report without any cache, silently (exit 0): it is
    refused before the studies run, naming the option and the file."""
    (tmp_path / "afile").write_text("")
    code, out, err = cli("report", "--only", "mcps-fig3", "--out", tmp_path / "rep", "--cache", tmp_path / "afile")
    assert code == 2 and err.startswith("error: --cache ") and "not a directory" in err and err.count("\n") == 1, err
    assert not (tmp_path / "rep").exists()


def test_one_process_or_two_give_the_same_report(cli, tmp_path):
    one = _report(cli, tmp_path / "one", "--jobs", "1", "--no-cache")
    two = _report(cli, tmp_path / "two", "--jobs", "2", "--no-cache")
    assert (one["jobs"], two["jobs"]) == (1, 2)
    assert one["checks"] == two["checks"] and one["n_checks"] > 10
    assert one["outputs"] == two["outputs"]
    for pattern in ("data/*/*.csv", "figures/*.csv", "studies/*.json"):
        a, b = _files(tmp_path / "one", pattern), _files(tmp_path / "two", pattern)
        assert a.keys() == b.keys() and a
        if pattern != "studies/*.json":  # the run records hold each study's wall time
            assert a == b


def test_formats(cli, tmp_path):
    out = tmp_path / "rep"
    summary = _report(cli, out, "--jobs", "1")
    assert summary["formats"] == ["png"]
    assert not list(out.rglob("*.svg")) and not list(_cache().rglob("*.svg"))
    assert (out / "figures" / "fm-fig1-left.png").is_file()
    html = (out / "index.html").read_text()
    assert 'href="figures/fm-fig1-left.png"' in html and ".svg" not in html

    summary = _report(cli, out, "--jobs", "1", "--formats", "png,svg")
    assert summary["study_cached"] == dict.fromkeys(STUDIES, False)  # the SVGs need the figures drawn again
    assert (out / "figures" / "fm-fig1-left.svg").read_text().lstrip().startswith("<?xml")
    assert 'href="figures/fm-fig1-left.svg"' in (out / "index.html").read_text()
    summary = _report(cli, out, "--jobs", "1")  # back to PNG only: from the cache, and the SVGs removed
    assert set(summary["study_cached"].values()) == {True} and not list((out / "figures").glob("*.svg"))

    for bad, msg in (("svg", "must include png"), ("png,gif", "unknown format 'gif'")):
        code, _, err = cli("report", "--out", tmp_path / "x", "--only", "fm-table1", "--formats", bad)
        assert code == 2 and msg in err, err
    code, _, err = cli("report", "--out", tmp_path / "x", "--only", "fm-table1", "--jobs", "0")
    assert code == 2 and "--jobs 0" in err


def test_save_figure_lays_out_once_for_several_formats(tmp_path):
    from tirecli.figures.style import new_figure
    from tirecli.io.output import save_figure

    fig, ax = new_figure(width=4, height=3)
    ax.plot([0, 1], [0, 1])
    calls = []
    engine = fig.get_layout_engine()
    real = engine.execute
    engine.execute = lambda f: calls.append(1) or real(f)
    paths = save_figure(fig, tmp_path, "f", formats=("png", "svg"))
    assert [p.name for p in paths] == ["f.png", "f.svg"] and len(calls) == 1
    assert fig.get_layout_engine() is engine
    assert [p.name for p in save_figure(fig, tmp_path, "g", formats=("png",))] == ["g.png"]


def test_a_cache_hit_reads_each_cached_file_once(cli, tmp_path, monkeypatch):
    """The files of a cache entry are read once: the bytes whose hash was checked are the bytes copied."""
    out = tmp_path / "rep"
    _report(cli, out, "--jobs", "1")
    cache = _cache().resolve()
    from tirecli.io import cache as cache_io

    reads, real = [], cache_io._read

    def read(path, root):  # every read of a cached file goes through the cache's gate
        if cache in Path(path).resolve().parents and path.name != "manifest.json" and path.name != "card.json":
            reads.append(str(path))
        return real(path, root)

    monkeypatch.setattr(cache_io, "_read", read)
    before = {**_files(out, "data/*/*.csv"), **_files(out, "figures/*")}
    summary = _report(cli, out, "--jobs", "1")
    assert summary["study_cached"] == dict.fromkeys(STUDIES, True)
    assert reads and len(reads) == len(set(reads)), "a cached file was read twice"
    assert {**_files(out, "data/*/*.csv"), **_files(out, "figures/*")} == before


def test_svg_files_are_the_same_from_run_to_run(tmp_path):
    """Clip paths and markers get ids from a fixed salt (matplotlib draws a random one per id)."""
    from tirecli.figures.style import new_figure
    from tirecli.io.output import save_figure

    def saved(sub):
        fig, ax = new_figure(width=4, height=3)
        ax.plot([0, 1], [0, 1], marker="o")
        ax.fill_between([0, 1], [0, 0], [1, 2])
        (tmp_path / sub).mkdir()
        return save_figure(fig, tmp_path / sub, "f", formats=("svg",))[0].read_bytes()

    a, b = saved("a"), saved("b")
    assert b"clip-path" in a and a == b


@pytest.mark.parametrize("study", ["fm-fig1-left", "mcps-fig3"])
def test_a_png_has_the_pixels_savefig_writes(tmp_path, study):
    """The PNG drawn once (layout and rendering in one pass, tirecli's encoder) has pixel for pixel the
    image and the resolution of the file ``savefig`` writes (with the same settings); the same figure
    gives the same bytes."""
    import io

    import matplotlib
    import numpy as np
    from PIL import Image

    from tirecli.figures.registry import load_all
    from tirecli.io.output import SAVE_RC, save_figure
    from tirecli.studies.configs import builtin_config
    from tirecli.studies.registry import run_study

    res = run_study(builtin_config(study))
    figs = [f for f in load_all().values() if f.study == study]
    assert figs
    for f in figs:
        fig = f.draw(res)
        if not hasattr(fig, "savefig"):
            continue
        ref = io.BytesIO()
        with matplotlib.rc_context(SAVE_RC):
            f.draw(res).savefig(ref, format="png", dpi=150, metadata={"Software": None})
        (path,) = save_figure(fig, tmp_path, f.id, dpi=150, formats=("png",))
        with Image.open(ref) as a, Image.open(path) as b:
            assert a.size == b.size and b.info["dpi"] == pytest.approx(a.info["dpi"]), f.id
            assert np.array_equal(np.asarray(a.convert("RGBA")), np.asarray(b.convert("RGBA"))), f.id
        (again,) = save_figure(f.draw(res), tmp_path, f.id + "-again", dpi=150, formats=("png",))
        assert again.read_bytes() == path.read_bytes(), f.id


def test_png_bytes_keeps_every_pixel():
    """An opaque image is written as RGB, one with transparency as RGBA; both decode to the same pixels."""
    import io

    import numpy as np
    from PIL import Image

    from tirecli.io.output import png_bytes

    rng = np.random.default_rng(3)
    img = rng.integers(0, 256, size=(7, 5, 4), dtype=np.uint8)
    img[..., 3] = 255
    seethrough = img.copy()
    seethrough[2, 3, 3] = 17
    for arr, mode in ((img, "RGB"), (seethrough, "RGBA")):
        with Image.open(io.BytesIO(png_bytes(arr, 150))) as im:
            assert im.mode == mode and im.size == (5, 7) and im.info["dpi"] == pytest.approx((150, 150), rel=1e-3)
            assert np.array_equal(np.asarray(im.convert("RGBA")), arr)


def _sum_on_threads() -> int:
    from tirecli.parallel import thread_pool

    return thread_pool(2).submit(sum, [1, 2]).result(timeout=20)


def test_a_forked_worker_starts_its_own_thread_pool():
    """The parent's thread pool (MF evaluator, CSV formatter) has no threads in a forked worker: work
    given to it there would wait for ever."""
    import multiprocessing

    from tirecli.report import work

    assert _sum_on_threads() == 3  # the pool exists in this process
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    from tirecli.parallel import fork_point

    with ctx.Pool(1, initializer=work._init_worker, initargs=(q, fork_point())) as pool:
        assert pool.apply_async(_sum_on_threads).get(timeout=60) == 3


@pytest.mark.parametrize("jobs", ["1", "2"])
def test_a_failing_study_is_an_error_card_and_is_not_cached(cli, tmp_path, monkeypatch, jobs):
    from tirecli.studies import registry  # the report runs its studies through it

    real = registry.run_study

    def run_study(config, *args, **kwargs):
        if config.label == "<built-in mcps-fig3>":
            raise RuntimeError("the slider broke")
        return real(config, *args, **kwargs)

    monkeypatch.setattr(registry, "run_study", run_study)
    out = tmp_path / "rep"
    code, _, err = cli("--quiet", "report", "--out", out, *ONLY, "--jobs", jobs, "--strict")
    assert code == 1, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["study_errors"] == {"mcps-fig3": "RuntimeError: the slider broke"}
    assert [c["id"] for c in summary["checks"] if not c["passed"]] == ["mcps-fig3/study-ran"]
    assert summary["study_cached"] == {"fm-fig1-left": False, "mf-golden": False}
    assert "the slider broke" in (out / "index.html").read_text()
    monkeypatch.setattr(registry, "run_study", real)
    assert _report(cli, out, "--jobs", jobs)["study_cached"] == {"fm-fig1-left": True, "mf-golden": True,
                                                                 "mcps-fig3": False}


def test_a_worker_that_dies_is_an_error_and_the_previous_report_stays(cli, tmp_path, monkeypatch):
    import os

    from tirecli.studies import registry  # the report runs its studies through it

    out = tmp_path / "rep"
    _report(cli, out, "--jobs", "1", "--cache", tmp_path / "cache")
    before = _files(out, "**/*.*")
    real = registry.run_study

    def run_study(config, *args, **kwargs):
        if config.label == "<built-in mcps-fig3>":
            os._exit(9)  # as if killed
        return real(config, *args, **kwargs)

    monkeypatch.setattr(registry, "run_study", run_study)
    code, _, err = cli("report", "--out", out, *ONLY, "--jobs", "2", "--no-cache", "--cache", tmp_path / "cache")
    assert code == 1 and "a worker process of the report ended abruptly" in err and f"previous results in {out} kept" in err
    assert _files(out, "**/*.*") == before and len(before) > 10
    assert sorted(os.listdir(tmp_path)) == ["cache", "rep"]


def test_a_parameter_set_read_by_a_figure_invalidates_its_card(cli, tmp_path, monkeypatch):
    """A figure (or its checks) may read a built-in set its study did not: the card is keyed on it too."""
    import dataclasses

    from tirecli.figures.registry import REGISTRY, load_all
    from tirecli.parameters import sets

    load_all()
    fdef = REGISTRY["mcps-fig3"]

    def draw(res):
        sets.load_builtin("canudas2003-table2")
        return fdef.draw(res)

    monkeypatch.setitem(REGISTRY, "mcps-fig3", dataclasses.replace(fdef, draw=draw))
    out = tmp_path / "rep"
    _report(cli, out, "--jobs", "1")
    summary = _with_changed_set(monkeypatch, tmp_path, "canudas2003-table2", lambda text: text + "\n# changed\n",
                                lambda: _report(cli, out, "--jobs", "1"))
    assert summary["study_cached"] == {"fm-fig1-left": True, "mf-golden": True, "mcps-fig3": False}


def test_the_default_cache_folder(monkeypatch, tmp_path):
    """Outside the report: $TIRECLI_CACHE_DIR, else $XDG_CACHE_HOME/tirecli (absolute), else ~/.cache/tirecli."""
    from tirecli.io.cache import default_dir

    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.setenv("TIRECLI_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert default_dir() == tmp_path / "mine"
    monkeypatch.setenv("TIRECLI_CACHE_DIR", " ")
    assert default_dir() == tmp_path / "xdg" / "tirecli"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative/path")  # the XDG rule: a relative path is ignored
    assert default_dir() == tmp_path / "home" / ".cache" / "tirecli"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.delenv("TIRECLI_CACHE_DIR")
    assert default_dir() == tmp_path / "home" / ".cache" / "tirecli"


def test_a_report_keeps_no_cache_in_its_folder(cli, tmp_path, monkeypatch):
    """The cache was DIR/.tirecli-cache, half of a 104 MB report folder that CI jobs archive: now it is
    the user's cache folder (here $XDG_CACHE_HOME/tirecli), and a cache left in DIR by an earlier
    version is named once (not used, not removed)."""
    monkeypatch.delenv("TIRECLI_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    out = tmp_path / "rep"
    code, stdout, err = cli("report", "--out", out, "--only", "mcps-fig3", "--jobs", "1")
    assert code == 0, err
    assert (tmp_path / "xdg" / "tirecli" / "v1" / "mcps-fig3").is_dir()
    assert sorted(p.name for p in out.iterdir()) == ["data", "docs", "figures", "index.html", "studies", "summary.json"]
    assert "note:" not in stdout.replace("note: building matplotlib's font cache (first run only)", "")
    (out / ".tirecli-cache" / "v1").mkdir(parents=True)
    code, stdout, err = cli("report", "--out", out, "--only", "mcps-fig3", "--jobs", "1")
    assert code == 0 and f"note: {out / '.tirecli-cache'} is the study cache of an earlier tirecli" in stdout, stdout
    assert json.loads((out / "summary.json").read_text())["study_cached"] == {"mcps-fig3": True}
    assert (out / ".tirecli-cache" / "v1").is_dir()


def test_a_cache_variable_that_names_a_file_is_a_usage_error(cli, tmp_path, monkeypatch):
    (tmp_path / "afile").write_text("")
    monkeypatch.setenv("TIRECLI_CACHE_DIR", str(tmp_path / "afile"))
    code, out, err = cli("report", "--only", "mcps-fig3", "--out", tmp_path / "rep")
    assert code == 2 and err.startswith("error: TIRECLI_CACHE_DIR ") and err.count("\n") == 1, err
    assert not (tmp_path / "rep").exists()


def test_the_page_embeds_a_smaller_png_and_links_the_file(cli, tmp_path):
    """index.html was 8.3 MB, 7.3 MB of it the figures' PNGs in base64: the page embeds each PNG in 256
    colours (no channel of a pixel moves by more than 20 of 255), the full-colour file is linked."""
    import base64
    import io
    import re

    import numpy as np
    from PIL import Image

    out = tmp_path / "rep"
    _report(cli, out, "--jobs", "1")
    html = (out / "index.html").read_text()
    embedded = dict(re.findall(r'<a href="(figures/[\w-]+\.png)"[^>]*>\s*<img alt="[^"]*"\s*(?:width="\d+" height="\d+" )?'
                               r'src="data:image/png;base64,([^"]+)"', html))
    assert set(embedded) == {"figures/fm-fig1-left.png", "figures/mf-golden-fx0.png", "figures/mcps-fig3.png"}
    for href, text in embedded.items():
        page, file = base64.b64decode(text), (out / href).read_bytes()
        assert len(page) < 0.5 * len(file), href
        with Image.open(io.BytesIO(page)) as a, Image.open(io.BytesIO(file)) as b:
            assert a.mode == "P" and a.size == b.size
            pa, pb = (np.asarray(im.convert("RGB"), dtype=int) for im in (a, b))
            diff = np.abs(pa - pb).max(axis=2)
            assert diff.max() <= 20 and (diff == 0).mean() > 0.5, (href, diff.max(), (diff == 0).mean())
            assert (pa[pb.sum(axis=2) == 765] == 255).all(), href  # white stays white


def test_the_first_report_says_once_that_it_builds_the_font_cache(tmp_path):
    """matplotlib scans the system's fonts on its first use on a machine: the report says so, then never again."""
    import subprocess
    import sys

    env = dict(os.environ, MPLCONFIGDIR=str(tmp_path / "mpl"), MPLBACKEND="Agg")
    note = "note: building matplotlib's font cache (first run only)"

    def report(*extra):
        proc = subprocess.run([sys.executable, "-m", "tirecli", "report", "--out", str(tmp_path / "rep"),
                               "--only", "fm-table1", "--jobs", "1", *extra], env=env, capture_output=True,
                              text=True, timeout=300)
        assert proc.returncode == 0, proc.stderr
        return proc.stdout

    assert report("--no-cache").count(note) == 1
    assert list((tmp_path / "mpl").glob("fontlist-v*.json"))
    assert note not in report("--no-cache")
