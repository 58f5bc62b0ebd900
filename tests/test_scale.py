"""Large outputs (issue 15, scale): the chunked CSV writer, block-wise sweeps, Parquet, the sample
budget of a large sweep, simulate with many cases, ``mf eval``. No timings here (benchmarks/bench_scale.py)."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

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
