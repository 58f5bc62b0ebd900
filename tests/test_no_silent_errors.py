"""Unit tests of the rules against silently wrong results (issue 13): profile limits over a run,
strict numeric CSV cells, ``.tir`` reading and writing, Magic Formula switches and non-finite
outputs, fits that did not converge, YAML values that only look numeric. The CLI-level cases are in
``tests/robustness/test_wrong_results.py``."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tirecli.errors import ConfigError, DataError, UsageError
from tirecli.io import tir as tirio

ROOT = Path(__file__).resolve().parents[1]
TIR_DATA = ROOT / "tests" / "data" / "tir"
SHIPPED_TIR = sorted((ROOT / "tirecli" / "parameters" / "data").glob("*.tir")) + sorted(TIR_DATA.glob("*.tir")) \
    + sorted((ROOT / "examples").rglob("*.tir"))


# --------------------------------------------------------------------------- profiles


def test_formula_checked_over_the_run_not_only_at_zero():
    from tirecli.models.profiles import Expression, Limits, check_over_run

    lim = Limits("-", gt=0.0)
    assert check_over_run(Expression("1 + 0.5*sin(t)"), lim, 10.0) is None
    key, msg = check_over_run(Expression("1 - 3*(t > 2.5)"), lim, 4.0)
    assert key == "expr" and "gives -2 at t = 2.5" in msg and "(0 .. 4 s)" in msg
    # a smooth crossing: the sampled value and the time it leaves its range
    key, msg = check_over_run(Expression("2 - t"), Limits("N m", lo=0.0), 4.0, dt=0.01)
    assert "leaves its range at t = 2 s" in msg
    # a 1 ms pulse in a 1000 s run: between the grid points, found through the switch times
    key, msg = check_over_run(Expression("1 - 2*(t > 400)*(t < 400.001)"), lim, 1000.0)
    assert "gives -1 at t = 400 s" in msg  # from the switch at 400 s on
    # not finite: inf and NaN are out of any range
    assert "inf" in check_over_run(Expression("1/(t - 1)"), Limits("N m"), 2.0)[1]
    assert "NaN" in check_over_run(Expression("sqrt(1 - t)"), Limits("N m"), 2.0)[1]


def test_tables_transitions_and_csv_tables():
    from tirecli.models.profiles import Change, Limits, Table, Transitions, check_over_run

    lim = Limits("N m", lo=0.0)
    assert check_over_run(Table((0, 1, 2), (0, 5, 0)), lim, 3.0) is None
    assert check_over_run(Transitions(0.0, (Change(1.0, 10.0, 0.5, "linear"), Change(2.0, 0.0))), lim, 3.0) is None
    key, msg = check_over_run(Table((0, 1, 2), (0, -5, 0), source="p.csv", column="p"), lim, 3.0)
    assert key == "csv" and msg.startswith("p.csv: column 'p' row 2 (t = 1 s): -5 is out of range")


def test_run_times_hold_the_grid_and_both_sides_of_breakpoints():
    from tirecli.models.profiles import CHECK_POINTS, run_times

    t = run_times(5.0, 0.001, (1.25, 7.0))
    assert t[0] == 0.0 and t[-1] == 5.0 and len(t) >= CHECK_POINTS
    i = np.searchsorted(t, 1.25)
    assert t[i] == 1.25 and t[i - 1] < 1.25 < t[i + 1] and t[i + 1] - t[i - 1] < 1e-8
    assert not (t > 5.0).any()


# --------------------------------------------------------------------------- CSV cells


def _frame(tmp_path, text):
    from tirecli.io.data import read_table

    p = tmp_path / "d.csv"
    p.write_text(text)
    return read_table(p), p


@pytest.mark.parametrize("body, message", [
    ("a\nTrue\nFalse\n", "column 'a' row 1: not a number ('True'; true/false are not numbers)"),
    ("a\n1\ntrue\n", "column 'a' row 2: not a number ('true'; true/false are not numbers)"),
    ("a\nTrue\n\nFalse\n", "column 'a' row 1: not a number ('True'"),
    ("a\n1\n0x10\n", "column 'a' row 2: not a number ('0x10')"),
    ("a\n1\n1_000\n", "column 'a' row 2: not a number ('1_000')"),
    ("a\n1\nnan\n", "column 'a' row 2: empty or NaN value"),
    ("a,b\n1,2\n,3\n", "column 'a' row 2: empty or NaN value"),
    ("a\n1\n1e999\n", "column 'a' row 2: infinite value"),
])
def test_numeric_cells_are_plain_numbers(tmp_path, body, message):
    from tirecli.io.data import frame_columns

    frame, p = _frame(tmp_path, body)
    with pytest.raises(DataError) as exc:
        frame_columns(frame, ["a"], p, min_rows=1)
    assert str(exc.value).startswith(f"{p}: {message}")


def test_rows_are_the_files_rows_after_a_selection(tmp_path):
    from tirecli.io.data import frame_columns, select_rows

    frame, p = _frame(tmp_path, "case,t\n1,0\n2,0\n2,1\n2,oops\n")
    sel = select_rows(frame, {"case": 2}, p)
    with pytest.raises(DataError, match=r"column 't' row 4: not a number \('oops'\)"):
        frame_columns(sel, ["t"], p)
    frame, p = _frame(tmp_path, "case,t\n1,0\n2,1\n2,1\n")
    with pytest.raises(DataError, match=r"column 't' row 3: time does not increase"):
        frame_columns(select_rows(frame, {"case": 2}, p), ["t"], p, increasing="t")


# --------------------------------------------------------------------------- .tir reading and writing


def _snap(doc):
    return (doc.preamble, doc.encoding if doc.encoding == "latin-1" else "utf-8",
            {n: ({k: (type(e.value), e.value, e.comment) for k, e in s.entries.items()},
                 None if s.table is None else (s.table.header, s.table.rows)) for n, s in doc.sections.items()})


def _round_trip(data: bytes, name: str = "x.tir"):
    from tirecli.io.yamlio import dump_yaml, parse_yaml

    d1 = tirio.parse_tir(data, name)
    y, o = parse_yaml(dump_yaml(tirio.to_yaml_data(d1)), "x.yaml")
    d2 = tirio.from_yaml_data(y, o, "x.yaml")
    out = tirio.encode_tir(d2, tirio.format_tir(d2))
    return d1, tirio.parse_tir(out, "back.tir"), out


@pytest.mark.parametrize("path", SHIPPED_TIR, ids=lambda p: p.name)
def test_round_trip_is_identical_for_every_shipped_tir(path):
    raw = path.read_bytes()
    d1, d3, out = _round_trip(raw, path.name)
    assert _snap(d1) == _snap(d3)
    # tir -> tir and tir -> yaml -> tir give the same bytes, and converting again changes nothing
    assert out == tirio.encode_tir(d1, tirio.format_tir(d1))
    assert _round_trip(out)[2] == out


def test_encodings_are_kept_never_encoded_twice():
    raw = (TIR_DATA / "ExternData_sample.tir").read_bytes()
    lat = raw.replace(b"$Mounted side", "$Montée côté".encode("latin-1"), 1)
    d1, d3, out = _round_trip(lat)
    assert d1.encoding == "latin-1" and _snap(d1) == _snap(d3)
    assert "Montée côté".encode("latin-1") in out and b"\xc3" not in out
    utf = raw.replace(b"$Mounted side", "$Montée côté".encode("utf-8"), 1)
    d1, d3, out = _round_trip(utf)
    assert d1.encoding == "utf-8" and "Montée côté".encode("utf-8") in out and _snap(d1) == _snap(d3)
    bom = b"\xef\xbb\xbf" + raw
    assert "MDI_HEADER" in tirio.parse_tir(bom, "bom.tir").sections
    assert tirio.decode_text(b"abc") == ("abc", "ascii", False)


def test_apostrophes_and_quotes_in_text():
    raw = (TIR_DATA / "ExternData_sample.tir").read_bytes()
    ap = raw.replace(b"'Left'", b"'Left'\nFUNCTION_NAME = \"it's\"", 1)
    d1, d3, out = _round_trip(ap)
    assert d3.value("MODEL", "FUNCTION_NAME") == "it's" and b'"it\'s"' in out
    assert tirio.format_value("a'b") == '"a\'b"' and tirio.format_value("ab") == "'ab'"
    with pytest.raises(ValueError, match="both quote characters"):
        tirio.format_value("a'b\"c")
    from tirecli.io.yamlio import parse_yaml

    data, o = parse_yaml("format: tirecli-tir/1\nsections:\n  MODEL: {FUNCTION_NAME: \"a'b\\\"c\"}\n", "y.yaml")
    with pytest.raises(ConfigError, match="y.yaml:3: sections.MODEL.FUNCTION_NAME: a text value holding both"):
        tirio.from_yaml_data(data, o, "y.yaml")


def test_key_before_the_first_section_and_non_finite_numbers_are_errors():
    with pytest.raises(ConfigError, match=r"x.tir:1: FNOMIN: key before the first \[SECTION\]"):
        tirio.parse_tir(b"FNOMIN = 4000\n[MODEL]\nFITTYP = 61\n", "x.tir")
    with pytest.raises(ConfigError, match=r"x.tir:3: PDX1: the number '1e999' is too large: beyond the range of a double"):
        tirio.parse_tir(b"[MODEL]\nFITTYP = 61\nPDX1 = 1e999\n", "x.tir")
    with pytest.raises(ConfigError, match=r"x.tir:3: table row of \[SHAPE\]: the number '-1D400'"):
        tirio.parse_tir(b"[SHAPE]\n{radial width}\n 1.0 -1D400\n", "x.tir")
    from tirecli.io.yamlio import parse_yaml

    data, o = parse_yaml("format: tirecli-tir/1\nsections:\n  MODEL: {FITTYP: 61, LONGVL: .inf}\n", "y.yaml")
    with pytest.raises(ConfigError, match="LONGVL: expected a finite number, got inf"):
        tirio.from_yaml_data(data, o, "y.yaml")


def test_truncated_in_the_middle_of_the_last_number():
    from tirecli.parameters.mf import tire_data

    raw = (TIR_DATA / "ExternData_sample.tir").read_bytes()
    cut = raw[:raw.rindex(b"0.7098") + 4]  # "PFZ1 = 0.70", no line break
    with pytest.raises(ConfigError, match=r"cut.tir:\d+: the file may be truncated: .*'PFZ1 = 0.70'"):
        tire_data(tirio.parse_tir(cut, "cut.tir"))
    tire_data(tirio.parse_tir(cut + b"\n", "whole.tir"))                   # a line break: complete
    tire_data(tirio.parse_tir(cut + b" $effect", "comment.tir"))           # a comment after it: complete


def test_switches_and_ranges_of_a_tir_file():
    from tirecli.parameters.mf import tire_data

    raw = (TIR_DATA / "ExternData_sample.tir").read_bytes()

    def problems(edit):
        with pytest.raises(ConfigError) as exc:
            tire_data(tirio.parse_tir(edit(raw), "t.tir"))
        return str(exc.value)

    assert "TYRESIDE: unknown side 'SYMMETRIC'" in problems(lambda b: b.replace(b"'Left'", b"'SYMMETRIC'"))
    assert "FITTYP: unknown Magic Formula version 99 (expected 61, 62" in problems(
        lambda b: b.replace(b"FITTYP                   = 61", b"FITTYP = 99"))
    assert "FZMAX: must be > 0, got -1" in problems(lambda b: __import__("re").sub(rb"\nFZMAX *=[^$\n]*", b"\nFZMAX = -1 ", b))
    assert "VXLOW: must be >= 0, got -1" in problems(lambda b: __import__("re").sub(rb"\nVXLOW *=[^$\n]*", b"\nVXLOW = -1 ", b))


def test_fittyp_and_inert_overrides():
    from tirecli.io.yamlio import parse_yaml
    from tirecli.parameters.mf import tire_from_values
    from tirecli.parameters.sets import resolve_tire

    def resolve(text):
        data, o = parse_yaml(text, "c.yaml")
        return resolve_tire(data["tire"], o, ("tire",), ROOT)

    ps, t = resolve("tire: {set: externdata-205-60r15, FITTYP: 6}\n")
    assert t.version == "5.2" and "override" in ps.extra["version_source"]
    with pytest.raises(ConfigError, match=r"c.yaml:1: tire.FITTYP: unknown Magic Formula version 99"):
        resolve("tire: {set: externdata-205-60r15, FITTYP: 99}\n")
    with pytest.raises(ConfigError, match=r"tire.USE_MODE: not read by tirecli's 6.1 .* would change nothing"):
        resolve("tire: {set: externdata-205-60r15, USE_MODE: 2}\n")
    with pytest.raises(ConfigError, match="unknown Magic Formula version 7"):
        tire_from_values(FITTYP=7, FNOMIN=4000, UNLOADED_RADIUS=0.3, PCX1=1.6, PDX1=1, PKX1=20, PCY1=1.3,
                         PDY1=1, PKY1=-15, PKY2=2)


def test_non_finite_outputs_are_named_and_extrapolation_counted():
    from tirecli.models.magic_formula.engine import nonfinite_point
    from tirecli.models.magic_formula import evaluate
    from tirecli.parameters.mf import load_builtin_tire_data

    t = load_builtin_tire_data("chrono-185-80r14").tire()
    fz = np.array([4000.0, 1e12])
    r = evaluate(t, 0.05, 0.0, 0.0, fz, limits=False)
    assert r.outside == {"fz": 1}
    i, text, at_fault = nonfinite_point(t, r, {"kappa": 0.05, "alpha": 0.0, "gamma": 0.0, "fz": fz}, False)
    assert i == 1 and at_fault and "fz = 1e+12 N" in text and "above FZMAX = 8550 N" in text
    ok = evaluate(t, 0.05, 0.0, 0.0, fz)   # limits on: clipped to FZMAX, counted, finite
    assert ok.counts["fz"] == 1 and ok.outside == {} and np.isfinite(ok.fx).all()
    nofzmax = load_builtin_tire_data("pacejka2006-205-60r15").tire()
    assert evaluate(nofzmax, 0.05, 0.0, 0.0, np.array([4000.0, 1e6])).outside == {"fz_extreme": 1}


# --------------------------------------------------------------------------- fits


def test_fit_failure_rules(table1):
    from tirecli.numerics import identify

    t = np.linspace(0, 2, 40)
    v, s = 20 - 5 * t, -0.01 - 0.1 * t
    with np.errstate(all="raise"):  # no numpy warning escapes: the failure says what happened
        res, _ = identify.fit_steady_state(s, v, np.full(40, 1e300), table1)
    assert "not finite" in res.failure()
    res, _ = identify.fit_steady_state(s, v, identify.romega_of(s, v) * 0 + 0.7, table1, free=("mu_c", "mu_s"))
    assert res.failure() is None or "bound" in res.failure()
    s1 = identify.fit_sigma1(np.ones(5), np.zeros(5), np.zeros(5), np.zeros(5), table1)
    assert s1.failure().startswith("the data cannot identify any of the fitted parameters (sigma1: ")   # rank 0


def test_mcps_calibration_refuses_a_target_it_cannot_evaluate():
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf
    from tirecli.parameters.sets import load_builtin

    p = load_builtin("sorine2000-mcps").model()

    def nan(k, a):
        k, a = np.broadcast_arrays(np.asarray(k, dtype=float), np.asarray(a, dtype=float))
        return np.full(k.shape, np.nan), np.zeros(k.shape), np.zeros(k.shape)

    with pytest.raises(ValueError, match="fx curve is not finite"):
        calibrate_to_mf(p, 4000.0, nan, np.linspace(0.01, 0.1, 5), np.linspace(0.01, 0.1, 5))


# --------------------------------------------------------------------------- YAML


@pytest.mark.parametrize("text, value", [
    ("010", "010"), ("-010", "-010"), ("1:30", "1:30"), ("1:30.5", "1:30.5"), ("12", 12), ("-7", -7), ("0", 0),
    ("0x1A", 26), ("0o17", 15), ("1e5", 1e5), ("010.5", 10.5), ("5.", 5.0),
])
def test_yaml_numbers_are_never_guessed(text, value):
    from tirecli.io.yamlio import dump_yaml, load_value

    got = load_value(text)
    assert got == value and type(got) is type(value)
    if isinstance(value, str):  # written back quoted, so any YAML reader keeps it text
        assert load_value(dump_yaml(value)) == value and dump_yaml(value).startswith("'")


def test_formula_errors_inside_the_check_are_usage_errors():
    from tirecli.models.profiles import Expression

    with pytest.raises(UsageError, match="cannot be evaluated at t = 0 s: the value is a complex number"):
        Expression("(-8)**(1/3) + t").values(np.array([0.0, 1.0]))
    with pytest.raises(UsageError, match="complex number"):
        Expression("t + (-8)**0.5")(1.0)


def test_numbers_beyond_a_double_are_errors_not_crashes(tmp_path):
    from tirecli.config.loader import load_config
    from tirecli.io.yamlio import parse_yaml

    with pytest.raises(ConfigError, match=r"x.tir:2: FITTYP: the number '9999.*beyond the range of a double"):
        tirio.parse_tir(b"[MODEL]\nFITTYP = " + b"9" * 400 + b"\n", "x.tir")
    with pytest.raises(ConfigError, match=r"x.tir:2: FITTYP: the number '9999.*beyond the range"):
        tirio.parse_tir(b"[MODEL]\nFITTYP = " + b"9" * 5000 + b"\n", "x.tir")
    with pytest.raises(ConfigError, match=r"c.yaml:1: t_end: cannot read value: a number of thousands of digits"):
        parse_yaml("t_end: " + "9" * 5000 + "\n", "c.yaml")
    cfg = tmp_path / "c.yaml"
    cfg.write_text("study: simulate\ntire: canudas2003-table2\nt_end: " + "9" * 400 + "\n")
    from tirecli.studies.registry import plan

    with pytest.raises(ConfigError, match=r"t_end: expected a finite number \[s\], got an integer of about 401 digits"):
        plan(load_config(cfg))
    with pytest.raises(UsageError, match=r"--set t_end=\.\.\.: cannot read the value"):
        load_config(cfg, ["t_end=" + "9" * 5000])


def test_text_with_an_apostrophe_is_read_whole_and_overrides_obey_the_files_rules():
    with pytest.raises(ConfigError, match=r"q.tir:4: OTHER: unterminated quoted text \"'Bob\""):
        tirio.parse_tir(b"[MODEL]\nFITTYP = 61\nNAME = 'it's'   $a note\nOTHER = 'Bob$s\n", "q.tir")
    doc = tirio.parse_tir(b"[MODEL]\nFITTYP = 61\nNAME = 'it's'   $a note\n", "q.tir")
    e = doc.entry("MODEL", "NAME")
    assert (e.value, e.comment) == ("it's", "a note")
    from tirecli.io.yamlio import parse_yaml
    from tirecli.parameters.mf import coefficient_problems
    from tirecli.parameters.sets import resolve_tire

    assert coefficient_problems({"FZMIN": 100.0, "FZMAX": -5.0}, "mf") == [(("FZMAX",), "must be > 0, got -5")]
    assert coefficient_problems({"FZMIN": 100.0, "FZMAX": 50.0}, "mf")[0][0] == ("FZMIN", "FZMAX")
    data, o = parse_yaml("tire: {set: externdata-205-60r15, FZMAX: 50}\n", "c.yaml")
    with pytest.raises(ConfigError, match=r"c.yaml:1: tire.FZMAX: range minimum FZMIN = 100 is above its maximum"):
        resolve_tire(data["tire"], o, ("tire",), ROOT)
