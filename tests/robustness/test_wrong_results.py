"""No silently wrong results (issue 13): each class through the real CLI, several cases each.

- input profiles checked against their limits over the whole run (not only at t = 0);
- ``.tir`` files: truncated mid-number, non-finite values, unknown switches, overrides that would
  change nothing, loads the tyre cannot evaluate (an error) or evaluates only by extrapolation (flagged);
- fits that do not converge: exit 1, nothing written;
- CSV cells that are not plain numbers (``True``, ``nan``, ``inf``, text): errors naming column and row;
- ``tir convert``: apostrophes, keys before the first section, encodings, identical round trips;
- YAML values that only look numeric (``1:30``, ``010``) are refused, not read as 90 and 8.

Every error is one line, exit 2 (exit 1 for a fit that did not converge), and leaves a pre-existing
output directory byte-identical.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from harness import assert_clean_error, assert_unchanged, run, snapshot

ROOT = Path(__file__).resolve().parents[2]
TIRES = ROOT / "tirecli" / "parameters" / "data"
SIM = """study: simulate
tire: canudas2003-table2
t_end: 4
output: {dt: 0.01}
cases: [lumped]
"""
OBS = """study: observe
tire: canudas2003-table1
scenario: {duration: 10, theta: 1, torque: 300, v0: 20}
"""


def _write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def _keep(tmp_path) -> tuple[Path, dict]:
    """A pre-existing output directory and its snapshot (must stay byte-identical after a refused run)."""
    out = tmp_path / "out"
    (out / "data").mkdir(parents=True)
    (out / "run.json").write_text('{"tool": "tirecli", "previous": true}\n')
    (out / "data" / "old.csv").write_text("a,b\n1,2\n")
    return out, snapshot(out)


# --------------------------------------------------------------------------- profiles over the whole run


@pytest.mark.parametrize("inputs, pattern", [
    # the cases: a negative brake torque (it would drive the wheel) and theta going to -2
    ('input: {brake_torque: {expr: "1000*sin(pi*t/3)"}}', r"input\.brake_torque\.expr: .*-0\.2\d* at t = 3\.0\d* s.*"
                                                           r"leaves its range at t = 3 s.*>= 0"),
    ('input: {theta: {expr: "1 - 3*(t > 2.5)"}}', r"input\.theta\.expr: the formula gives -2 at t = 2\.5\d* s.*> 0"),
    ('input: {torque: {expr: "100/(t - 2)"}}', r"input\.torque\.expr: the formula gives inf at t = 2 s"),
])
def test_simulate_formula_profiles_are_checked_over_the_run(tmp_path, inputs, pattern):
    cfg = _write(tmp_path / "sim.yaml", SIM + inputs + "\n")
    out, before = _keep(tmp_path)
    r = run(["simulate", cfg, "--out", out])
    assert_clean_error(r, 2, pattern)
    assert "sim.yaml:" in r.err
    assert_unchanged(before, out)


def test_case_overrides_and_open_loop_drives_are_checked_over_the_run(tmp_path):
    cfg = _write(tmp_path / "sim.yaml", SIM.replace(
        "cases: [lumped]", 'cases:\n  - {model: lumped, label: a}\n'
                           '  - {model: lumped, label: b, input: {theta: {expr: "0.5 - 0.2*t"}}}\n'))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"sim\.yaml:7: cases\[1\]\.input\.theta\.expr: .*t = 2\.5")
    cfg = _write(tmp_path / "drive.yaml", SIM.replace(
        "cases: [lumped]", 'cases:\n  - {model: lumped, drive: {v: {expr: "20 - 8*t"}, slip: -0.1}}\n'))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"cases\[0\]\.drive\.v\.expr: .* at t = 2\.5")
    cfg = _write(tmp_path / "slip.yaml", SIM.replace(
        "cases: [lumped]", 'cases:\n  - {model: lumped, drive: {v: 20, slip: {expr: "0.5*t"}}}\n'))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"drive\.slip\.expr: .* at t = 2\.0\d* s.*<= 1")


def test_csv_profiles_are_checked_naming_the_row(tmp_path):
    _write(tmp_path / "p.csv", "t,p\n0,0\n1,30\n2,-5\n3,0\n")
    cfg = _write(tmp_path / "sim.yaml", SIM + "input: {pressure: {csv: p.csv, value: p}}\n")
    assert_clean_error(run(["simulate", cfg, "--out", tmp_path / "o"]), 2,
                       r"input\.pressure\.csv: .*p\.csv: column 'p' row 3 \(t = 2 s\): -5 is out of range")
    assert not (tmp_path / "o").exists()
    _write(tmp_path / "d.csv", "t,v,s\n0,20,0\n1,19,-0.1\n2,18,-1.5\n")
    cfg = _write(tmp_path / "drive.yaml", SIM.replace("cases: [lumped]", "cases:\n  - {model: lumped, drive: {csv: d.csv}}\n"))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"d\.csv: .*column 's' row 3 \(t = 2 s\)")


def test_observe_profiles_are_checked_over_the_run(tmp_path):
    cfg = _write(tmp_path / "obs.yaml", OBS.replace("theta: 1,", 'theta: {expr: "1 + 0.5*sin(t) - 2*(t > 6)"},'))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"scenario\.theta\.expr: the formula gives -1\.1\d* at t = 6")
    cfg = _write(tmp_path / "obs2.yaml", OBS + 'cases:\n  - {label: a}\n  - {label: b, torque: {expr: "300*log(5 - t)"}}\n')
    assert_clean_error(run(["params", "validate", cfg]), 2, r"cases\[1\]\.torque\.expr: .*(nan|inf).* at t = 5")


# --------------------------------------------------------------------------- .tir files


def _tir(tmp_path, name="x.tir", edit=None, cut=None) -> Path:
    raw = (TIRES / "externdata-205-60r15.tir").read_bytes()
    if edit:
        raw = edit(raw)
    if cut:
        raw = raw[:raw.rindex(cut[0]) + cut[1]]
    p = tmp_path / name
    p.write_bytes(raw)
    return p


def test_tir_truncated_mid_number_and_non_finite_values(tmp_path):
    cut = _tir(tmp_path, "cut.tir", cut=(b"0.7098", 4))  # "PFZ1 = 0.70": every key is there
    assert_clean_error(run(["tir", "show", cut]), 2, r"cut\.tir:\d+: the file may be truncated.*PFZ1 = 0\.70")
    # cut earlier, in the middle of a number with coefficients after it: one line, the coefficients named
    early = _tir(tmp_path, "early.tir", cut=(b"=  1.579", 6))  # "PCX1 = 1.5"
    assert_clean_error(run(["tir", "check", early]), 2, r"early\.tir:\d+: the file may be truncated: .*'PCX1 = 1\.\d*'.*"
                                                       r"required coefficient\(s\) are not in it \(PDX1, ")
    big = _tir(tmp_path, "big.tir", edit=lambda b: re.sub(rb"\nPDX1 *=[^$\n]*", b"\nPDX1 = 1e999 ", b))
    assert_clean_error(run(["tir", "check", big]), 2, r"big\.tir:\d+: PDX1: .*1e999.*beyond the range")
    side = _tir(tmp_path, "side.tir", edit=lambda b: b.replace(b"'Left'", b"'Middle'"))
    assert_clean_error(run(["tir", "show", side]), 2, r"TYRESIDE: unknown side 'Middle' \(expected 'LEFT' or 'RIGHT'")


def test_tir_overrides_that_would_change_nothing_are_refused(tmp_path):
    cfg = _write(tmp_path / "mf.yaml", "study: sweep\ntire: externdata-205-60r15\n")
    out, before = _keep(tmp_path)
    r = run(["sweep", cfg, "--out", out, "--set", "tire.FITTYP=99"])
    assert_clean_error(r, 2, r"tire\.FITTYP: unknown Magic Formula version 99 \(expected 61, 62")
    r = run(["sweep", cfg, "--out", out, "--set", "tire.USE_MODE=2"])
    assert_clean_error(r, 2, r"tire\.USE_MODE: not read by .* would change nothing")
    # an override obeys the rules of the file it changes: never a negative FZMAX or an inverted range
    r = run(["sweep", cfg, "--out", out, "--set", "tire.FZMAX=-5"])
    assert_clean_error(r, 2, r"tire\.FZMAX: must be > 0, got -5")
    r = run(["sweep", cfg, "--out", out, "--set", "tire.FZMIN=20000"])
    assert_clean_error(r, 2, r"tire\.FZMIN: range minimum FZMIN = 20000 is above its maximum FZMAX = 10000")
    assert_unchanged(before, out)


def test_absurd_loads_are_an_error_or_flagged(tmp_path):
    pts = _write(tmp_path / "pts.csv", "kappa,alpha,gamma,fz\n0.05,0,0,4000\n0.05,0,0,1e12\n")
    r = run(["mf", "eval", "chrono-185-80r14", "--points", pts, "--out", tmp_path / "r.csv", "--no-limits"])
    assert_clean_error(r, 2, r"pts\.csv: row 2: the Magic Formula gives no finite fx.*fz = 1e\+12 N.*above FZMAX")
    assert not (tmp_path / "r.csv").exists()
    # evaluated, but far outside the tyre's ranges: a warning, whatever --quiet says
    r = run(["--quiet", "mf", "eval", "externdata-205-60r15", "--points", pts, "--out", tmp_path / "r.csv",
             "--no-limits"])
    assert r.code == 0 and "warning: 1 point(s): loads outside [FZMIN, FZMAX]" in r.err
    cfg = _write(tmp_path / "sw.yaml", "study: sweep\ntire: chrono-185-80r14\nlimits: false\n"
                                       "sweep: {kappa: [-0.1, 0.1], alpha: [0, 0.1], loads: [4000, 1e12]}\n")
    r = run(["sweep", cfg, "--out", tmp_path / "sw"])
    assert_clean_error(r, 2, r"sw\.yaml:4: sweep\.loads: family fx-kappa: .*fz = 1e\+12 N")
    assert not (tmp_path / "sw").exists()


# --------------------------------------------------------------------------- fits that do not converge


@pytest.mark.parametrize("mu, pattern", [
    ("1e300", r"did not converge: the residuals or estimates are not finite"),
    ("50", r"did not converge: the residual RMS .* of the data.s RMS"),
])
def test_a_fit_that_did_not_converge_exits_1_and_writes_nothing(tmp_path, mu, pattern):
    t = np.linspace(0.0, 2.0, 40)
    rows = "".join(f"{a:.6g},{20 - 5 * a:.6g},{-0.01 - 0.1 * a:.6g},{mu}\n" for a in t)
    _write(tmp_path / "data.csv", "t,v,s,mu\n" + rows)
    cfg = _write(tmp_path / "fit.yaml", "study: fit\ntire: canudas2003-table1\ndata: {csv: data.csv}\n")
    out, before = _keep(tmp_path)
    r = run(["fit", cfg, "--out", out], timeout=60)
    assert_clean_error(r, 1, "fit: the steady state .* " + pattern + r".*no fitted\.yaml was written")
    assert not (out / "fitted.yaml").exists()
    assert_unchanged(before, out)


# --------------------------------------------------------------------------- CSV cells


@pytest.mark.parametrize("cell, pattern", [
    ("True", r"column 'fz' row 2: not a number \('True'; true/false are not numbers\)"),
    ("nan", r"column 'fz' row 2: empty or NaN value"),
    ("4e3N", r"column 'fz' row 2: not a number \('4e3N'\)"),
])
def test_mf_eval_points_cells_that_are_not_numbers(tmp_path, cell, pattern):
    pts = _write(tmp_path / "pts.csv", f"kappa,alpha,gamma,fz\n0,0,0,4000\n0,0,0,{cell}\n")
    r = run(["mf", "eval", "externdata-205-60r15", "--points", pts, "--out", tmp_path / "r.csv"])
    assert_clean_error(r, 2, r"pts\.csv: " + pattern)
    assert not (tmp_path / "r.csv").exists()


def test_fit_data_and_drive_cells_that_are_not_numbers(tmp_path):
    rows = "".join(f"{0.1 * i:.3g},{20 - i:.3g},-0.1,{'True' if i == 3 else 0.8}\n" for i in range(12))
    _write(tmp_path / "data.csv", "t,v,s,mu\n" + rows)
    cfg = _write(tmp_path / "fit.yaml", "study: fit\ntire: canudas2003-table1\ndata: {csv: data.csv}\n")
    assert_clean_error(run(["fit", cfg, "--out", tmp_path / "o"]), 2, r"data\.csv: column 'mu' row 4: not a number \('True'")
    _write(tmp_path / "d.csv", "t,v,s\n0,20,0\n1,yes,-0.1\n")
    cfg = _write(tmp_path / "drive.yaml", SIM.replace("cases: [lumped]", "cases:\n  - {model: lumped, drive: {csv: d.csv}}\n"))
    assert_clean_error(run(["params", "validate", cfg]), 2, r"d\.csv: column 'v' row 2: not a number \('yes'\)")


# --------------------------------------------------------------------------- tir convert


def test_tir_convert_apostrophes_sections_and_encodings(tmp_path):
    def edit(b):
        b = b.replace(b"'Left'", b"'Left'\nFUNCTION_NAME = \"it's\"", 1)
        return b.replace(b"$Mounted side", "$Montée côté".encode("latin-1"), 1)

    src = _tir(tmp_path, "lat.tir", edit=edit)
    assert run(["tir", "convert", src, "--to", "yaml", "--out", tmp_path / "lat.yaml"]).code == 0
    text = (tmp_path / "lat.yaml").read_text(encoding="utf-8")
    assert "encoding: latin-1" in text and "FUNCTION_NAME: it's" in text and "Montée côté" in text
    assert run(["tir", "convert", tmp_path / "lat.yaml", "--to", "tir", "--out", tmp_path / "back.tir"]).code == 0
    assert run(["tir", "convert", src, "--to", "tir", "--out", tmp_path / "same.tir"]).code == 0
    back = (tmp_path / "back.tir").read_bytes()
    assert back == (tmp_path / "same.tir").read_bytes()
    assert "Montée côté".encode("latin-1") in back and b"\xc3" not in back  # not encoded twice
    assert b"= \"it's\"" in back
    # a UTF-8 file stays UTF-8 (its bytes read as Latin-1 and written as UTF-8 would double-encode)
    utf = _tir(tmp_path, "utf.tir", edit=lambda b: b.replace(b"$Mounted side", "$Montée".encode("utf-8"), 1))
    assert run(["tir", "convert", utf, "--to", "tir", "--out", tmp_path / "utf2.tir"]).code == 0
    assert "$Montée".encode("utf-8") in (tmp_path / "utf2.tir").read_bytes()
    # a key before the first section: an error naming the line, never a '[]' section
    pre = _tir(tmp_path, "pre.tir", edit=lambda b: b"FNOMIN = 4000\n" + b)
    r = run(["tir", "convert", pre, "--to", "yaml", "--out", tmp_path / "pre.yaml"])
    assert_clean_error(r, 2, r"pre\.tir:1: FNOMIN: key before the first \[SECTION\] header")
    assert not (tmp_path / "pre.yaml").exists()


# --------------------------------------------------------------------------- YAML values that look numeric


def test_yaml_values_that_only_look_numeric_are_refused(tmp_path):
    """YAML 1.1 would read ``1:30`` as 90 (base 60) and ``010`` as 8 (octal): both stay text and are refused."""
    for value, hint in (("1:30", "base-60"), ("010", "a leading zero")):
        cfg = _write(tmp_path / "sim.yaml", SIM.replace("t_end: 4", f"t_end: {value}"))
        assert_clean_error(run(["params", "validate", cfg]), 2,
                           rf"sim\.yaml:3: t_end: expected a number \[s\], got the text '{value}' \({hint}")


SHIPPED = {p.read_bytes(): p for p in sorted(TIRES.glob("*.tir")) + sorted((ROOT / "tests" / "data" / "tir").glob("*.tir"))}


@pytest.mark.parametrize("path", sorted(SHIPPED.values()), ids=lambda p: p.name)
def test_tir_convert_round_trip_of_every_shipped_file(tmp_path, path):
    """tir -> yaml -> tir -> yaml through the CLI: the same values, comments and tables; the second
    YAML is the first (but for the file name it names)."""
    from tirecli.io import tir as tirio

    a, b, c = tmp_path / "a.yaml", tmp_path / "b.tir", tmp_path / "c.yaml"
    for src, to, dst in ((path, "yaml", a), (a, "tir", b), (b, "yaml", c)):
        r = run(["tir", "convert", src, "--to", to, "--out", dst])
        assert r.code == 0 and not r.err.strip(), r.err

    def body(p):
        return [ln for ln in p.read_text(encoding="utf-8").splitlines() if not ln.startswith(("#", "source:"))]

    assert body(a) == body(c)
    d0, d1 = tirio.parse_tir(path.read_bytes(), path.name), tirio.parse_tir(b.read_bytes(), "b.tir")
    assert d0.preamble == d1.preamble and list(d0.sections) == list(d1.sections)
    for name, sec in d0.sections.items():
        other = d1.sections[name]
        assert {k: (e.value, type(e.value), e.comment) for k, e in sec.entries.items()} == \
            {k: (e.value, type(e.value), e.comment) for k, e in other.entries.items()}
        assert (sec.table is None) == (other.table is None)
        if sec.table is not None:
            assert (sec.table.header, sec.table.rows) == (other.table.header, other.table.rows)


def test_tir_text_holding_an_apostrophe_is_read_whole(tmp_path):
    """``'it's'`` in a .tir file: the quotes do not pair up, the value is the whole text (not an error
    about the comment after it), written back in double quotes."""
    src = _tir(tmp_path, "ap.tir", edit=lambda b: b.replace(b"[MODEL]", b"[MODEL]\nFUNCTION_NAME = 'it's'   $name", 1))
    r = run(["tir", "convert", src, "--to", "tir", "--out", tmp_path / "ap2.tir"])
    assert r.code == 0, r.err
    assert re.search(rb'FUNCTION_NAME += "it\'s" +\$name', (tmp_path / "ap2.tir").read_bytes())
