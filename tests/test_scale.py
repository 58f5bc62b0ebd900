"""Large outputs (issue 15, scale): the chunked CSV writer, block-wise sweeps, Parquet, the sample
budget of a large sweep, simulate with many cases, ``mf eval``. No timings here (benchmarks/bench_scale.py)."""
from __future__ import annotations

import importlib.util
import math
import os

import numpy as np
import pandas as pd
import pytest
from conftest import block_pyarrow

from tirecli.io import fastcsv, output


def previous_csv_text(frame, comments=()) -> str:
    """The CSV text of the previous (one-piece, ``repr`` per cell) writer: the reference format."""
    header = ",".join(output._csv_cells(np.array([str(c) for c in frame.columns], dtype=object)))
    columns = [output._csv_cells(frame[c].to_numpy()) for c in frame.columns]
    text = "".join(f"# {c}\n" for c in comments) + header + "\n"
    if columns and columns[0]:
        text += "\n".join(map(",".join, zip(*columns))) + "\n"
    return text


def _awkward_doubles(rng, n):
    x = rng.standard_normal(n) * 10.0 ** rng.integers(-12, 22, n)
    special = [0.1, 0.5, 1e16, 9.999999999999999e15, 1e15, 1e-4, 9.99e-5, 1e-5, 123.0, 100.0, 1e22, -0.0, 0.0,
               5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 1.2345e-300, -1.5e-7, 2.0 ** 53, 2.0 ** 60,
               0.30000000000000004, 1 / 3, math.pi * 1e-200, np.nan, np.inf, -np.inf]
    return np.concatenate([special, x, np.round(x, 3), rng.integers(-10 ** 6, 10 ** 6, n) / 64.0,
                           np.linspace(-1, 1, n), np.nextafter(10.0 ** rng.integers(-300, 300, n), 0.0)])


def test_repr_matrix_is_repr_byte_for_byte():
    x = _awkward_doubles(np.random.default_rng(7), 40_000)
    m = fastcsv.repr_matrix(x)
    got = [bytes(r).rstrip(b"\0").decode() for r in m]
    want = ["" if v != v else repr(v) for v in x.tolist()]
    assert [(g, w) for g, w in zip(got, want) if g != w] == []


def test_repr_matrix_is_repr_where_long_double_is_double():
    """Where ``long double`` is ``double`` (Windows, macOS on ARM): emulated by a copy of the module
    computing in ``double``, whose texts are still those of ``repr`` (the vectorized digits were wrong
    in about one value of five, some not reading back)."""
    import warnings
    from pathlib import Path

    src = Path(fastcsv.__file__).read_text().replace("np.longdouble", "np.float64")
    emulated: dict = {"__name__": "fastcsv_double"}
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        exec(compile(src, "fastcsv_double", "exec"), emulated)  # noqa: S102 - the module's own source
        assert not emulated["_EXTENDED"]
        x = _awkward_doubles(np.random.default_rng(8), 2_000)
        m = emulated["repr_matrix"](x)
    got = [bytes(r).rstrip(b"\0").decode() for r in m]
    want = ["" if v != v else repr(v) for v in x.tolist()]
    assert [(g, w) for g, w in zip(got, want) if g != w] == []


def test_chunked_csv_identical_to_previous_writer(tmp_path, monkeypatch):
    rng = np.random.default_rng(3)
    n = 5003
    frame = pd.DataFrame({
        "a": _awkward_doubles(rng, 1000)[:n], "nan": np.full(n, np.nan), "const": np.full(n, 2.5),
        "model": np.where(rng.random(n) < 0.5, "x,y", "plain"), "i": rng.integers(-5, 100, n),
        "flag": rng.random(n) < 0.5, "obj": np.array([None, 'q"t', 1.5, " sp", "é", np.nan] * (n // 6 + 1),
                                                     dtype=object)[:n],
    })
    frame.loc[3, "const"] = -0.0
    monkeypatch.setattr(output, "CSV_CHUNK_ROWS", 997)  # many chunks, the last one short
    path = output.write_csv(tmp_path / "f.csv", frame, ["SYNTHETIC", "second comment"])
    assert path.read_bytes().decode() == previous_csv_text(frame, ["SYNTHETIC", "second comment"])
    # a text with a zero byte, an empty frame, a frame without columns
    odd = pd.DataFrame({"t": ["a\0b", "c"], "x": [1.0, 2.0]})
    assert output.write_csv(tmp_path / "z.csv", odd).read_bytes().decode() == previous_csv_text(odd)
    empty = frame.iloc[:0]
    assert output.write_csv(tmp_path / "e.csv", empty, ["c"]).read_bytes().decode() == previous_csv_text(empty, ["c"])


def test_runs_of_equal_values_formatted_once_keep_their_text(tmp_path, monkeypatch):
    """Columns that repeat values (formatted once per run, a few runs by repr): signed zeros, NaN runs,
    runs across chunk edges, a column of many runs; the text is the previous writer's."""
    n = 3000
    idx = np.arange(n)
    frame = pd.DataFrame({
        "zeros": np.where(idx % 3 == 1, -0.0, 0.0),  # equal values, different texts
        "steps": np.repeat([5.0, 0.1, np.nan, 1e22, -2.5e-7], n // 5),
        "half": np.where(idx < n // 2, 20.0, np.linspace(0, 1, n)),  # a run, then distinct values
        "pairs": np.repeat(np.linspace(-1, 1, n // 2), 2),  # many runs of two
        "const": np.full(n, 1 / 3),
    })
    monkeypatch.setattr(output, "CSV_CHUNK_ROWS", 701)
    path = output.write_csv(tmp_path / "runs.csv", frame)
    assert path.read_bytes().decode() == previous_csv_text(frame)
    first, ids = fastcsv._runs(frame["pairs"].to_numpy())
    assert first.size == n // 2 and np.array_equal(frame["pairs"].to_numpy()[first][ids], frame["pairs"].to_numpy())
    assert fastcsv._runs(np.linspace(0, 1, 100)) is None


def test_ordered_map_keeps_the_order_and_raises():
    from tirecli.parallel import ordered_map

    def slow_square(k):
        import time

        time.sleep(0.001 * (k % 3))  # later items may finish first
        if k == 13:
            raise ValueError("thirteen")
        return k * k

    for threads in (1, 2, 3):
        assert list(ordered_map(slow_square, range(13), threads)) == [k * k for k in range(13)]
        with pytest.raises(ValueError, match="thirteen"):
            list(ordered_map(slow_square, range(20), threads))
    assert list(ordered_map(slow_square, [], 2)) == []


# --------------------------------------------------------------------------- sweep

SWEEP = """study: sweep
tire: canudas2003-table2
sweep:
  slip: {start: -1, stop: 1, num: 41}
  speeds: [0, 5, 20]
  theta: [0.5, 1.0]
  models:
    - distributed
    - {model: distributed, load: exponential, lambda: 2}
    - {model: lumped, kappa0: Z}
    - {model: lumped, kappa0: 1.5, label: k15}
"""


def _sweep_inputs(text=SWEEP):
    from tirecli.config.loader import config_from_text
    from tirecli.studies import sweep as sw

    plan = sw.plan(config_from_text(text, label="<test>"))
    s = plan.checked["sweep"]
    return plan.detail.variants, plan.sets["tire"].model(), s["slip"], s["speeds"], plan.detail.thetas_fm


def test_blockwise_sweep_equals_one_block():
    from tirecli.studies.sweep_frames import sweep_frame

    variants, p, slips, speeds, thetas = _sweep_inputs()
    with np.errstate(all="ignore"):
        whole = sweep_frame(variants, p, slips, speeds, thetas, block=10 ** 9)
        for block in (1, 7, 41, 100):
            pd.testing.assert_frame_equal(sweep_frame(variants, p, slips, speeds, thetas, block=block), whole,
                                          check_exact=True)
    assert len(whole) == 4 * 2 * 3 * 41
    # rows: variant, theta, speed, slip (the order of the previous one-piece frame)
    first = whole.iloc[:41]
    assert (first["model"] == variants[0].label).all() and (first["speed"] == 0.0).all()
    assert np.array_equal(first["slip"].to_numpy(), np.asarray(slips, dtype=float))
    assert set(whole["direction"]) == {"braking", "driving"}
    assert whole.loc[whole["model"] == "k15", "kappa0"].eq(1.5).all()
    assert whole.loc[whole["model"] == variants[0].label, ["kappa0", "Z"]].isna().all().all()


def test_sweep_frame_compact_columns_same_csv(tmp_path):
    """The sweep frame's text columns are categoricals and its columns constant over the sweep are
    stored once; its CSV is the previous writer's text of the same values (categories as texts)."""
    from tirecli.studies.sweep_frames import sweep_frame

    one_theta = SWEEP.replace("theta: [0.5, 1.0]", "theta: [0.8]").replace(
        "    - {model: lumped, kappa0: Z}\n    - {model: lumped, kappa0: 1.5, label: k15}\n", "")
    for text, constant in ((SWEEP, []), (one_theta, ["theta", "theta_obs", "kappa0", "Z"])):
        variants, p, slips, speeds, thetas = _sweep_inputs(text)
        with np.errstate(all="ignore"):
            df = sweep_frame(variants, p, slips, speeds, thetas, block=50)
        assert df["model"].dtype == "category" and df["direction"].dtype == "category"
        for col in ("speed", "v", "romega", "theta", "theta_obs", "slip", "mu", "kappa0", "Z"):
            assert (df[col].to_numpy().strides == (0,)) == (col in constant), col
        for col in constant:
            assert len(set(df[col].astype(str))) == 1, col
        plain = df.astype({"model": object, "direction": object})
        assert output.write_csv(tmp_path / "s.csv", df).read_bytes().decode() == previous_csv_text(plain)
        if importlib.util.find_spec("pyarrow"):  # Parquet: the values as texts, not categoricals
            back = pd.read_parquet(output.write_parquet(tmp_path / "s.parquet", df))
            assert str(back["model"].dtype) == str(back["direction"].dtype) == "str"
            pd.testing.assert_frame_equal(back, plain.astype({"model": "str", "direction": "str"}))


def _exact_csv(path):
    """A CSV of tirecli as a frame, numbers parsed by Python's float (exact), text kept."""
    raw = pd.read_csv(path, comment="#", dtype=str, keep_default_na=False)
    out = {}
    for col in raw.columns:
        try:
            out[col] = np.array([float(v) if v != "" else np.nan for v in raw[col]])
        except ValueError:
            out[col] = raw[col].replace("", None)
    return pd.DataFrame(out)


def test_sweep_parquet_equals_csv(cli, tmp_path):
    pytest.importorskip("pyarrow")
    cfg = tmp_path / "s.yaml"
    cfg.write_text(SWEEP)
    for fmt in ("csv", "parquet"):
        code, _, err = cli("--quiet", "sweep", cfg, "--out", tmp_path / fmt, "--format", fmt)
        assert code == 0, err
    for name in ("sweep", "peaks"):
        from_csv = _exact_csv(tmp_path / "csv" / "data" / f"{name}.csv")
        from_pq = pd.read_parquet(tmp_path / "parquet" / "data" / f"{name}.parquet")
        assert list(from_pq.columns) == list(from_csv.columns)
        assert len(from_pq) == len(from_csv) > 0
        for col in from_csv.columns:
            a, b = from_csv[col], from_pq[col]
            if a.dtype.kind == "f" and b.dtype.kind == "f":
                assert np.array_equal(a.to_numpy(), b.to_numpy(), equal_nan=True), col
            else:  # text (kappa0 of peaks: a number or Z)
                assert [None if pd.isna(v) else str(v) for v in a] == [None if pd.isna(v) else str(v) for v in b], col
    run = (tmp_path / "parquet" / "run.json").read_text()
    assert "data/sweep.parquet" in run and "sweep.csv" not in run


def test_campaign_parquet_as_pandas_writes_it(tmp_path, monkeypatch):
    """Campaign files go through the row-group writer: the schema (types inferred from the values, the
    pandas metadata) and the values pandas' own writer gives, over several row groups too."""
    pq = pytest.importorskip("pyarrow.parquet")
    from tirecli.io import campaign

    n = 50
    frame = pd.DataFrame({"id": [f"p{i:03d}" for i in range(n)], "error": [None] * n,
                          "note": np.array(["x" if i % 3 else None for i in range(n)], dtype=object),
                          "k": np.arange(n), "ok": np.arange(n) % 2 == 0, "v": np.linspace(0, 1, n)})
    frame.loc[4, "v"] = np.nan
    frame.to_parquet(tmp_path / "pandas.parquet", index=False, engine="pyarrow")
    for group in (output.PARQUET_GROUP_ROWS, 7):
        monkeypatch.setattr(output, "PARQUET_GROUP_ROWS", group)
        path = campaign.write_parquet(tmp_path / f"sub{group}" / "ours.parquet", frame)
        assert pq.read_schema(path).equals(pq.read_schema(tmp_path / "pandas.parquet"), check_metadata=True)
        assert pq.ParquetFile(path).metadata.num_row_groups == -(-n // group)
        pd.testing.assert_frame_equal(campaign.read_parquet(path), pd.read_parquet(tmp_path / "pandas.parquet"))


def test_format_errors_are_one_line(cli, tmp_path, monkeypatch):
    cfg = tmp_path / "s.yaml"
    cfg.write_text(SWEEP)
    code, _, err = cli("sweep", cfg, "--out", tmp_path / "o", "--format", "xlsx")
    assert code == 2 and "--format 'xlsx'" in err and len(err.strip().splitlines()) == 1
    block_pyarrow(monkeypatch)
    code, _, err = cli("sweep", cfg, "--out", tmp_path / "o", "--format", "parquet")
    assert code == 2 and "--format parquet needs pyarrow, which is not installed" in err, err
    assert "pip install 'pyarrow'" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()  # refused before the run


def test_million_point_sweep_within_the_default_budget():
    from tirecli import limits
    from tirecli.studies.sweep import sweep_estimate

    est = sweep_estimate(1, 1, 10, 100_000)  # 10^6 points: within the default budget of 10^6 samples
    assert est.samples == 1_000_000 == limits.DEFAULT_MAX_SAMPLES
    assert est.problem(None, "<test>") is None
    assert est.memory < 300e6  # the estimate reflects the block-wise run
    over = sweep_estimate(2, 1, 10, 100_000).problem(None, "<test>")  # still refused above the budget
    assert over is not None and "2,000,000 samples" in over.message


def test_million_point_sweep_config_passes_the_check():
    from tirecli.config.loader import config_from_text
    from tirecli.errors import ConfigError
    from tirecli.studies import sweep as sw

    million = "study: sweep\ntire: canudas2003-table1\nsweep:\n  slip: {start: -1, stop: 1, num: 100000}\n" \
              "  speeds: {start: 5, stop: 50, num: 10}\n"
    sw.plan(config_from_text(million, label="<test>"))  # not refused (the peak rows are not counted)
    with pytest.raises(ConfigError, match="1,100,000 samples"):
        sw.plan(config_from_text(million.replace("num: 10}", "num: 11}"), label="<test>"))


# --------------------------------------------------------------------------- simulate


def _many_cases(n: int) -> str:
    cases = "\n".join(f"  - {{model: lumped, kappa0: {'Z' if i % 2 else 1.0 + 0.05 * i}, label: c{i:02d}}}"
                      for i in range(n))
    return f"""study: simulate
tire: canudas2003-table2
initial: {{v: 20, slip: 0}}
input:
  brake_torque: {{initial: 0, changes: [{{at: 0.05, duration: 0.1, to: 900, shape: linear}}]}}
t_end: 0.3
output: {{dt: 0.002}}
cases:
{cases}
"""


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_many_cases_stream_the_same_timeseries(cli, tmp_path, monkeypatch):
    from tirecli.studies.simulate import running

    cfg = tmp_path / "many.yaml"
    cfg.write_text(_many_cases(14))
    assert 14 > running.SPOOL_CASES
    code, _, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / "streamed")
    assert code == 0, err
    monkeypatch.setattr(running, "SPOOL_CASES", 100)  # the frame kept in memory, as before
    code, _, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / "frame")
    assert code == 0, err
    for name in ("timeseries", "events"):
        assert (tmp_path / "streamed" / "data" / f"{name}.csv").read_bytes() == \
            (tmp_path / "frame" / "data" / f"{name}.csv").read_bytes()
    ts = pd.read_csv(tmp_path / "streamed" / "data" / "timeseries.csv")
    assert list(dict.fromkeys(ts["case"])) == [f"c{i:02d}" for i in range(14)]
    assert (tmp_path / "streamed" / "figures" / "transient-histories.png").stat().st_size > 10_000


def test_spooled_frame_reads_back():
    from tirecli.io.output import SpooledFrame

    parts = [pd.DataFrame({"case": [f"c{k}"] * 3, "t": [0.0, 0.1, 0.30000000000000004], "x": [1.5, np.nan, -2e-7]})
             for k in range(3)]
    spool = SpooledFrame(["case", "t", "x"])
    for p in parts:
        spool.append(p)
    assert len(spool) == 9
    pd.testing.assert_frame_equal(spool.to_frame(), pd.concat(parts, ignore_index=True), check_dtype=False)
    with pytest.raises(ValueError):
        spool.append(parts[0][["t", "case", "x"]])


def test_spooled_frame_filled_by_a_helper_process(tmp_path):
    """Rows formatted in a forked helper process: the same text and count as in this process; the
    helper's error is raised where the rows are read."""
    from tirecli.io.output import SpooledFrame, write_csv

    rng = np.random.default_rng(4)
    parts = [pd.DataFrame({"case": [f"c{k}"] * 500, "t": rng.standard_normal(500), "x": rng.random(500) < 0.5})
             for k in range(5)]
    texts = []
    for background in (False, True):
        spool = SpooledFrame(["case", "t", "x"])
        first = spool.extend(iter(parts), background=background, first=lambda: {"pid": os.getpid()})
        assert (first()["pid"] != os.getpid()) == background  # made by the helper
        assert len(spool) == 2500
        texts.append(write_csv(tmp_path / f"{background}.csv", spool).read_bytes())
    assert texts[0] == texts[1]

    def failing():
        yield parts[0]
        raise ValueError("part 2 is broken")

    spool = SpooledFrame(["case", "t", "x"])
    assert spool.extend(failing(), background=True)() is None
    with pytest.raises(ValueError, match="part 2 is broken"):
        write_csv(tmp_path / "f.csv", spool)
    spool = SpooledFrame(["case", "t", "x"])
    first = spool.extend(iter(parts), background=True, first=lambda: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        first()
    with pytest.raises(ZeroDivisionError):
        len(spool)


@pytest.mark.parametrize("dt", [0.002, 0.0])
def test_drawn_rows_are_rows_of_the_timeseries(dt):
    """The rows kept for the figures of a streamed run, evaluated alone, are those rows of the whole
    time series (the same numbers)."""
    from tirecli.config.loader import config_from_text
    from tirecli.studies import simulate
    from tirecli.studies.simulate import running

    config = config_from_text(_many_cases(2).replace("dt: 0.002", f"dt: {dt}"), label="<test>")
    plan = simulate.plan(config)
    checked, cases = plan.checked, plan.detail
    car = plan.sets["vehicle"].model()
    trs = simulate.run_cases(cases, plan.sets["tire"].model(), car, checked["t_end"])
    for c in cases:
        cache = trs[c.label].sample_cache  # a kept run's samples (runs.quarter_car(reuse=True))
        whole = running.case_frame(trs[c.label], c, dt, car.r, 20.0)
        kept = len(cache)
        drawn = running.case_frame(trs[c.label], c, dt, car.r, 20.0, points=40, keep=False)
        assert len(cache) == kept and (kept >= 1 or dt == 0)  # keep=False: not kept with the run
        rows = running.thinned(len(whole), 40)
        assert 20 < len(drawn) <= 41 and rows[-1] == len(whole) - 1
        pd.testing.assert_frame_equal(drawn, whole.iloc[rows].reset_index(drop=True), check_exact=True)


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_many_cases_same_files_with_or_without_the_helper_process(cli, tmp_path, monkeypatch):
    from tirecli import parallel

    cfg = tmp_path / "many.yaml"
    cfg.write_text(_many_cases(14))
    for helper in (True, False):
        monkeypatch.setattr(parallel, "helper_process_ok", lambda helper=helper: helper)
        code, _, err = cli("--quiet", "simulate", cfg, "--out", tmp_path / str(helper))
        assert code == 0, err
    for name in ("data/timeseries.csv", "data/events.csv", "figures/transient-histories.png"):
        assert (tmp_path / "True" / name).read_bytes() == (tmp_path / "False" / name).read_bytes()


# --------------------------------------------------------------------------- mf eval


def test_field_counts_like_the_csv_reader():
    import csv
    import io

    body = "a, b ,c\n1,2,3\n\n  \n4,5\n\t\n6,7,8,\n\x0c\n9,,\n"
    counts, lines = fastcsv.field_counts(body.encode())
    rows = [(i, r) for i, r in enumerate(csv.reader(io.StringIO(body), skipinitialspace=True))
            if r and not (len(r) == 1 and not r[0].strip())]
    assert counts.tolist() == [len(r) for _, r in rows]
    assert lines.tolist() == [i for i, _ in rows]


def test_mf_eval_field_check_messages(cli, tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0.01,0,0,4000\n\n0.02,0,0\n")
    code, _, err = cli("mf", "eval", "pacejka2006-205-60r15", "--points", pts, "--out", tmp_path / "o.csv")
    assert code == 2
    assert "data row 2 has 3 fields but the header names 4 columns" in err


def test_mf_eval_results_unchanged(cli, tmp_path):
    """The output of ``mf eval`` against the model evaluated directly (17-digit text, exact)."""
    from tirecli.app.mf import load_tire
    from tirecli.models.magic_formula import evaluate

    rng = np.random.default_rng(5)
    n = 3000
    cols = {"kappa": np.round(rng.uniform(-0.3, 0.3, n), 5), "alpha": np.round(rng.uniform(-0.2, 0.2, n), 5),
            "gamma": np.round(rng.uniform(-0.05, 0.05, n), 5), "fz": np.round(rng.uniform(2000, 6000, n), 1)}
    pts = tmp_path / "p.csv"
    pd.DataFrame(cols).to_csv(pts, index=False)
    code, _, err = cli("--quiet", "mf", "eval", "pacejka2006-205-60r15", "--points", pts, "--out", tmp_path / "o.csv")
    assert code == 0, err
    got = _exact_csv(tmp_path / "o.csv")
    _, tire = load_tire("pacejka2006-205-60r15")
    res = evaluate(tire, cols["kappa"], cols["alpha"], cols["gamma"], cols["fz"], tire.reference_speed,
                   tire.default_pressure)
    for k in ("fx", "fy", "mz", "mx", "my"):
        assert np.array_equal(got[k].to_numpy(), np.asarray(getattr(res, k), dtype=float)), k
    assert np.array_equal(got["kappa"].to_numpy(), cols["kappa"])


def test_helper_process_errors_keep_their_type_and_text(tmp_path):
    """An error of the helper process is raised here as the same class with the same text, also for
    errors whose constructor does not take their message (``FormulaError``, ``ConfigError``): a usage
    error stays a one-line usage error (exit code 2), not an internal error."""
    from tirecli.errors import ConfigError, Problem
    from tirecli.io.output import SpooledFrame
    from tirecli.models.profiles import FormulaError

    errors = [FormulaError("100/(t-0.5)", "gives inf at t = 0.5 s"),
              ConfigError([Problem("a.yaml", 3, "input.torque", "not finite"), Problem("a.yaml", 4, "t_end", "< 0")])]
    for error in errors:
        def failing(error=error):
            yield pd.DataFrame({"x": [1.0]})
            raise error

        spool = SpooledFrame(["x"])
        spool.extend(failing(), background=True)
        with pytest.raises(type(error)) as info:
            len(spool)
        assert str(info.value) == str(error)
        assert vars(info.value) == vars(error)


def test_parquet_text_column_empty_in_its_first_row_group(tmp_path, monkeypatch):
    """A text column (object) without a value in the first row group (pyarrow infers the type null
    there) and texts later is written: its texts read back."""
    pytest.importorskip("pyarrow")
    from tirecli.io import output

    monkeypatch.setattr(output, "PARQUET_GROUP_ROWS", 4)
    note = pd.Series([None] * 6 + ["late", None, "last"], dtype=object)
    for frame in (pd.DataFrame({"x": np.arange(9.0), "note": note}),
                  pd.DataFrame({"x": np.arange(9.0), "note": note,
                                "model": pd.Categorical.from_codes([0, 1] * 4 + [0], categories=["a", "b"])})):
        path = output.write_parquet(tmp_path / "f.parquet", frame)
        back = pd.read_parquet(path)
        assert (back["note"][6], back["note"][8]) == ("late", "last")
        assert back["note"].isna().tolist() == [True] * 6 + [False, True, False]
        assert back["x"].tolist() == list(np.arange(9.0))


def test_helper_process_ends_when_its_parent_is_killed(tmp_path):
    """A parent killed outright (``kill -9``) while its helper process has a message larger than the
    pipe's buffer to send: the helper ends (it held the pipe's other end and waited for ever)."""
    import contextlib
    import signal
    import subprocess
    import sys
    import time

    if not sys.platform.startswith("linux"):
        pytest.skip("the helper process runs on Linux only")

    script = tmp_path / "parent.py"
    script.write_text(
        "import os, sys, time\nimport pandas as pd\nfrom tirecli.io.output import SpooledFrame\n"
        "spool = SpooledFrame(['a'])\n"
        "spool.extend(iter([pd.DataFrame({'a': [1.0]})]), background=True, first=lambda: b'x' * 1_000_000)\n"
        "print(spool._helper[0].pid, flush=True)\ntime.sleep(600)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True, env=env)
    try:
        helper = int(parent.stdout.readline())
        time.sleep(1.0)  # the helper is blocked on its message
        parent.send_signal(signal.SIGKILL)
        parent.wait()

        def running() -> bool:
            try:
                with open(f"/proc/{helper}/stat") as fh:
                    return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
            except OSError:
                return False

        for _ in range(300):  # a liveness check: it ends at once (a few ms), or never
            if not running():
                break
            time.sleep(0.1)
        assert not running()
    finally:
        parent.kill()
        with contextlib.suppress(NameError, ProcessLookupError):
            if running():
                os.kill(helper, signal.SIGKILL)


def _helper_ok_in_child(queue):
    from tirecli import parallel

    queue.put(parallel.helper_process_ok())


def test_no_helper_process_inside_a_worker_process():
    """Only the command's own process forks a helper: a report's or campaign's worker process (a child,
    daemonic or not) does not, so ending a worker can leave nothing behind."""
    import multiprocessing
    import sys

    from tirecli import parallel

    if sys.platform.startswith("linux") and parallel.default_jobs() > 1 and parallel.LIMIT != 1:
        assert parallel.helper_process_ok()
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    proc = ctx.Process(target=_helper_ok_in_child, args=(queue,))  # not daemonic, like a report worker
    proc.start()
    answer = queue.get(timeout=60)
    proc.join()
    assert answer is False
