"""The fast exact float formatter of tirecli mf eval: every double reads back exactly, with the
digits of repr (shortest round trip) in all but rare near-tie cases."""
import numpy as np

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
