"""The fast exact float formatter of tirecli mf eval: every double reads back exactly, with the
digits of repr (shortest round trip) in all but rare near-tie cases."""
import numpy as np
from conftest import block_pyarrow

from tirecli.io.fastcsv import format_exact, format_rows


def _values():
    rng = np.random.default_rng(11)
    bits = rng.integers(0, 2 ** 63 - 1, 20000, dtype=np.int64).view(np.float64)
    bits = bits[np.isfinite(bits)]
    nice = np.round(rng.uniform(-1e4, 1e4, 5000) * 100.0) / 100.0
    edge = [0.0, -0.0, 1.0, 0.1, 4000.0, -6.26, 16.67, 1 / 3, 5e-324, 2.2250738585072014e-308,
            1.7976931348623157e308, 9.999999999999999e22, 1e23, 1e16, 1e17, 12345678901234567.0]
    return np.concatenate([bits, -bits, nice, 2.0 ** np.arange(-1074, 1024), 10.0 ** np.arange(-300, 301), edge])


def test_every_double_reads_back_exactly():
    v = _values()
    text = format_exact(v)
    back = np.array([float(t) for t in text])
    np.testing.assert_array_equal(back, v)


def test_shortest_digits_like_repr():
    v = _values()
    text = format_exact(v)

    def digits(s):
        m = s.lstrip("-").split("e")[0].replace(".", "").strip("0")
        return len(m)

    longer = sum(digits(t.decode()) > digits(repr(float(x))) for t, x in zip(text, v) if x != 0)
    shorter = sum(digits(t.decode()) < digits(repr(float(x))) for t, x in zip(text, v) if x != 0)
    assert shorter == 0 and longer < 0.005 * len(v)  # at most one extra digit near ties
    assert format_exact([-6.26, 4000.0, 0.0, 0.1]) == [b"-6.26e+00", b"4e+03", b"0", b"1e-01"]


def test_rows_nan_inf_and_threads():
    a = np.array([1.5, np.nan, np.inf, -2.0, 1e300])
    b = np.array([0.0, 2.0, -np.inf, 3.25, -1e-300])
    rows = format_rows([a, b])
    assert rows == [b"1.5e+00,0", b",2e+00", b"inf,-inf", b"-2e+00,3.25e+00", b"1e+300,-1e-300"]
    x = np.random.default_rng(0).normal(size=200_003)
    assert format_rows([x, -x], threads=1) == format_rows([x, -x], threads=3)


def test_rows_after_input_lines_and_special_values(tmp_path):
    """write_table with the input lines: each row is the line, the lead, then the columns' texts as
    format_rows gives them (special values, constant columns, lines of different lengths, a block edge)."""
    from tirecli.io.fastcsv import write_table

    n = 70_000  # more than one block of rows
    rng = np.random.default_rng(3)
    x = rng.normal(size=n) * 10.0 ** rng.integers(-120, 120, n)
    x[::1000] = np.inf
    x[5::1000] = 0.0
    x[6::1000] = -0.0
    const = np.full(n, -12.52)
    lines = [b",".join(b"%d" % v for v in range(i % 7 + 1)) for i in range(n)]
    text = b"h\n" + b"\n".join(lines)
    nl = np.flatnonzero(np.frombuffer(text, dtype=np.uint8) == 10)
    out = tmp_path / "t.csv"
    write_table(out, "head", [x, const], lines=(text, nl, np.append(nl[1:], len(text))), lead=b",2.2e5", threads=2)
    expected = [b"head"] + [ln + b",2.2e5," + row for ln, row in zip(lines, format_rows([x, const], threads=1))]
    assert out.read_bytes() == b"\n".join(expected) + b"\n"
    write_table(out, "head", [x, const])
    assert out.read_bytes() == b"\n".join([b"head", *format_rows([x, const])]) + b"\n"


def test_plain_csv_reads_as_the_general_reader(tmp_path):
    """The fast reader of plain numeric CSVs gives the general reader's values (signed zeros of integer
    and float columns, integers, long digits, exponents) or declines (then the general reader decides)."""
    import pytest

    pytest.importorskip("pyarrow")
    from tirecli.errors import DataError
    from tirecli.io.data import plain_columns, read_columns

    cells = {"a": ["-0", "3", "7", "-9007199254740993", "-5"],
             "b": ["-0.0", "1e5", "0.1000000000000000055511151231257827", "-.5", "4.9e-324"],
             "c": ["+1.", "2E-3", "-0e0", "+7", "1e22"],
             "d": ["12345678901234567890", "0.30000000000000004", "2.2250738585072011e-308", "1e-400", "6"]}
    files = {"plain": "\n".join([",".join(cells)] + [",".join(r) for r in zip(*cells.values())]) + "\n",
             "no final newline": "a,b,c,d\n1,2,3,4",
             "empty cell": "a,b,c,d\n1,,3,4\n", "text": "a,b,c,d\n1,x,3,4\n", "nan": "a,b,c,d\n1,nan,3,4\n",
             "too many": "a,b,c,d\n1,2,3,4,\n", "too few": "a,b,c,d\n1,2,3\n", "huge": "a,b,c,d\n1,1e999,3,4\n",
             "-0 integers": "a,b,c,d\n-0,2,3,4\n5,6,7,8\n", "-0 among floats": "a,b,c,d\n-0,2,3,4\n5.5,6,7,8\n",
             "space": "a,b,c,d\n1, 2,3,4\n", "not a number": "a,b,c,d\n1,1-2,3,4\n", "crlf": "a,b,c,d\r\n1,2,3,4\r\n"}
    fast_ones = set()
    for name, text in files.items():
        path = tmp_path / "f.csv"
        path.write_text(text, newline="")
        fast = plain_columns(text.encode(), list("abcd"))
        try:
            slow = read_columns(path, list("abcd"), min_rows=1)
        except DataError:
            slow = None
        if fast is not None:
            fast_ones.add(name)
            assert slow is not None, name
            for c in "abcd":
                np.testing.assert_array_equal(fast[c], slow[c])
                np.testing.assert_array_equal(np.signbit(fast[c]), np.signbit(slow[c]), err_msg=name)
    assert fast_ones == {"plain", "no final newline", "-0 integers"}


def test_mf_eval_same_file_with_and_without_pyarrow(tmp_path, monkeypatch):
    """Without pyarrow (a plain install) the general reader reads the points: the same result file."""
    from tirecli.app.mf import mf_eval

    rng = np.random.default_rng(2)
    cols = [rng.uniform(-0.3, 0.3, 500).round(6), rng.uniform(-0.2, 0.2, 500), rng.uniform(-0.05, 0.05, 500).round(4),
            rng.uniform(2000, 6000, 500).round(1)]
    rows = [",".join(map(repr, r)) for r in zip(*(c.tolist() for c in cols))]
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n" + "\n".join(rows) + "\n")
    mf_eval("pacejka2006-205-60r15", pts, tmp_path / "a.csv")
    block_pyarrow(monkeypatch)
    mf_eval("pacejka2006-205-60r15", pts, tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
    assert (tmp_path / "a.csv").read_bytes().count(b"\n") == 501
