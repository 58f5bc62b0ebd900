"""The .tir reader and writer: every quirk of docs/models/magic_formula_tyre.md §12.5, units, versions, required keys,
the malformed-file corpus, and the lossless YAML round trip."""
import math

import pytest

from tirecli.errors import ConfigError
from tirecli.io import tir as tirio
from tirecli.io.yamlio import dump_yaml, parse_yaml
from tirecli.parameters.mf import load_builtin_tire_data, read_tire_data, tire_data

from conftest import ROOT

DATA = ROOT / "tests" / "data" / "tir"
SAMPLES = ["ExternData_sample.tir", "MagicFormula61_Parameters.tir", "mf_185_80R14.tir"]

MINIMAL = """\
[MODEL]
FITTYP = 61
LONGVL = 16.7
[DIMENSION]
UNLOADED_RADIUS = 0.3
[VERTICAL]
FNOMIN = 4000
[LONGITUDINAL_COEFFICIENTS]
PCX1 = 1.6
PDX1 = 1.0
PKX1 = 20
[LATERAL_COEFFICIENTS]
PCY1 = 1.3
PDY1 = 1.0
PKY1 = -15
PKY2 = 2
"""


def parse(text, name="t.tir"):
    return tirio.parse_tir(text.encode("latin-1"), name)


def problems(text):
    with pytest.raises(ConfigError) as exc:
        tire_data(parse(text))
    return exc.value.problems


@pytest.mark.parametrize("name", SAMPLES)
def test_samples_parse(name):
    td = read_tire_data(DATA / name)
    assert td.version in ("6.1", "5.2")
    assert td.values["FNOMIN"] > 0 and td.values["UNLOADED_RADIUS"] > 0


def test_sample_facts():
    a = read_tire_data(DATA / "MagicFormula61_Parameters.tir")
    assert (a.version, a.side, a.values["FNOMIN"], a.values["NOMPRES"]) == ("6.1", "right", 6752.0, 260000.0)
    assert a.doc.value("UNITS", "MASS") == "kg" and a.doc.value("INERTIA", "MASS") == 17.451  # §12.5 item 2
    b = read_tire_data(DATA / "mf_185_80R14.tir")
    assert (b.version, b.version_source) == ("5.2", "PROPERTY_FILE_FORMAT = 'PAC2002'")
    assert b.values["VERTICAL_STIFFNESS"] == 1.75e5  # 1.75e+005
    shape = b.doc.sections["SHAPE"].table
    assert shape.header == "radial width" and shape.rows[-1] == [0.9, 1.0]
    c = read_tire_data(DATA / "ExternData_sample.tir")
    assert c.side == "left"  # 'Left'
    assert any("QV1" in str(w) and "unknown key" in str(w) for w in c.warnings)
    assert c.values["Q_RE0"] == 0.9974  # taken from the non-standard [LOADED_RADIUS_COEFFICIENTS]


def test_crlf_lf_and_cr_read_the_same():
    text = MINIMAL.replace("PCX1 = 1.6", "PCX1 = 1.6 $shape")
    docs = [tirio.parse_tir(text.replace("\n", eol).encode(), "x") for eol in ("\n", "\r\n", "\r")]
    vals = [tire_data(d).values for d in docs]
    assert vals[0] == vals[1] == vals[2]
    assert docs[1].entry("LONGITUDINAL_COEFFICIENTS", "PCX1").line == 9


def test_line_quirks():
    text = MINIMAL + """\
[OVERTURNING_COEFFICIENTS]
  qsx1=1.0D-03       $leading blanks, lower case key, Fortran exponent, no blanks around =
QSX2\t=\t-.100000E+01\t! tab padding, ! comment
QSX3 = 2   $Revision: 1.2 $ with = and ( in the comment
[model]
TYRESIDE = 'Left' $ quoted $ sign: 'x$y'

[MDI_HEADER]
FILE_TYPE = 'a$b'   $dollar inside quotes is data
"""
    doc = parse(text)
    assert doc.value("OVERTURNING_COEFFICIENTS", "QSX1") == 1e-3
    assert doc.value("OVERTURNING_COEFFICIENTS", "QSX2") == -1.0
    assert doc.value("OVERTURNING_COEFFICIENTS", "QSX3") == 2
    assert doc.value("MODEL", "TYRESIDE") == "Left"
    assert doc.value("MDI_HEADER", "FILE_TYPE") == "a$b"
    assert tire_data(doc).side == "left"


def test_tables_and_comment_blocks_are_not_errors():
    doc = parse(MINIMAL + "[SHAPE]\n{radial width}\n 1.0 0.0\n 0.9 1.0\n[COMMENTS]\n(COMMENTS)\n{comment_string}\n'a free comment'\n")
    assert doc.sections["SHAPE"].table.rows == [[1.0, 0.0], [0.9, 1.0]]
    tire_data(doc)


def test_duplicate_key_is_a_warning_first_kept():
    doc = parse(MINIMAL + "[VERTICAL]\nFNOMIN = 5000\n")
    td = tire_data(doc)
    assert td.values["FNOMIN"] == 4000
    assert any("given twice" in str(w) or "appears again" in str(w) for w in td.warnings)


@pytest.mark.parametrize("line, expected", [
    ("PCX1 = ", "missing value"),
    ("PCX1 = .", "cannot read the value '.'"),
    ("PCX1 = 1.6.1", "cannot read the value '1.6.1'"),
    ("PCX1 = 'abc", "unterminated"),
    ("PCX1 = nan", "cannot read the value 'nan'"),
    ("PC X1 = 1", "cannot read the key"),
])
def test_bad_values_name_file_line_and_key(line, expected):
    text = MINIMAL.replace("PCX1 = 1.6", line)
    with pytest.raises(ConfigError) as exc:
        parse(text, "bad.tir")
    msg = str(exc.value)
    assert msg.startswith("bad.tir:9: ") and expected in msg


def test_text_where_a_number_is_expected():
    p = problems(MINIMAL.replace("PCX1 = 1.6", "PCX1 = 'one'"))
    assert str(p[0]).startswith("t.tir:9: PCX1: expected a number")
    # one problem: not also 'missing required coefficient (... not in [LONGITUDINAL_COEFFICIENTS])' for a
    # key that is there with a bad value
    assert [q.key for q in p] == ["PCX1"], [str(q) for q in p]


def test_missing_required_and_defaults():
    p = problems(MINIMAL.replace("PKY2 = 2\n", "").replace("PCX1 = 1.6\n", ""))
    assert {q.key for q in p} == {"PKY2", "PCX1"}
    td = tire_data(parse(MINIMAL))
    assert td.values["LMUY"] == 1.0 and td.values["PKY4"] == 2.0 and td.values["QDZ8"] == 0.0
    assert "QDZ8" in td.defaulted and "QSY1" in td.defaulted
    assert any("take tirecli's default" in str(w) for w in td.warnings)


@pytest.mark.parametrize("change, key", [
    (("PKY2 = 2", "PKY2 = 0"), "PKY2"),
    (("FNOMIN = 4000", "FNOMIN = 0"), "FNOMIN"),
    (("UNLOADED_RADIUS = 0.3", "UNLOADED_RADIUS = -0.3"), "UNLOADED_RADIUS"),
    (("FITTYP = 61", "FITTYP = 99"), "FITTYP"),
])
def test_value_checks(change, key):
    p = problems(MINIMAL.replace(*change))
    assert p[0].key == key and p[0].line is not None


def test_pressure_coefficients_need_nompres():
    p = problems(MINIMAL + "[LONGITUDINAL_COEFFICIENTS]\nPPX1 = 0.3\n")
    assert p[0].key == "NOMPRES"


def test_version_detection():
    assert tire_data(parse(MINIMAL)).version == "6.1"
    no_fittyp = MINIMAL.replace("FITTYP = 61\n", "")
    assert tire_data(parse(no_fittyp + "[LATERAL_COEFFICIENTS]\nPHY3 = 0.01\n")).version == "5.2"
    assert tire_data(parse(no_fittyp.replace("[MODEL]\n", "[MODEL]\nPROPERTY_FILE_FORMAT = 'MF_05'\n"))).version == "5.2"
    assert tire_data(parse(MINIMAL.replace("FITTYP = 61", "FITTYP = 62"))).version == "6.2"
    assert tire_data(parse(MINIMAL.replace("FITTYP = 61", "FITTYP = 21"))).version == "5.2"


def test_units_are_converted_to_si():
    text = MINIMAL.replace("[MODEL]", "[UNITS]\nLENGTH = 'mm'\nFORCE = 'kN'\nTIME = 'sec'\n[MODEL]")
    text = text.replace("UNLOADED_RADIUS = 0.3", "UNLOADED_RADIUS = 300").replace("FNOMIN = 4000", "FNOMIN = 4")
    text += "[VERTICAL]\nVERTICAL_STIFFNESS = 200\n[OPERATING_CONDITIONS]\nNOMPRES = 0.22\n"
    td = tire_data(parse(text))
    assert td.values["UNLOADED_RADIUS"] == pytest.approx(0.3)
    assert td.values["FNOMIN"] == pytest.approx(4000.0)
    assert td.values["LONGVL"] == pytest.approx(0.0167)  # 16.7 mm/s
    assert td.values["VERTICAL_STIFFNESS"] == pytest.approx(200e3 / 1e-3)  # kN/mm -> N/m
    assert td.values["NOMPRES"] == pytest.approx(0.22e3 / 1e-6)  # kN/mm^2 -> Pa
    assert td.values["PKX1"] == 20  # dimensionless: unchanged
    psi = tire_data(parse(MINIMAL.replace("[MODEL]", "[UNITS]\nPRESSURE = 'psi'\n[MODEL]") + "[OPERATING_CONDITIONS]\nNOMPRES = 30\n"))
    assert psi.values["NOMPRES"] == pytest.approx(30 * 6894.757293168361)


def test_unknown_unit_and_degrees():
    p = problems(MINIMAL.replace("[MODEL]", "[UNITS]\nLENGTH = 'furlong'\n[MODEL]"))
    assert p[0].key == "LENGTH" and "unknown unit" in p[0].message
    p = problems(MINIMAL.replace("[MODEL]", "[UNITS]\nANGLE = 'deg'\n[MODEL]"))
    assert p[0].key == "ANGLE" and "radians only" in p[0].message


@pytest.mark.parametrize("name, expected", [
    ("empty.tir", "empty file"),
    ("binary.tir", "binary file"),
    ("truncated.tir", "may be truncated"),
    ("truncated-late.tir", "truncated-late.tir:251: the file may be truncated"),
    ("missing-section.tir", "[LATERAL_COEFFICIENTS] is missing"),
    ("bad-number.tir", "bad-number.tir:197: PCY1: cannot read the value '1.47.59'"),
    ("bad-unit-angle.tir", "bad-unit-angle.tir:9: ANGLE"),
])
def test_malformed_corpus(name, expected):
    with pytest.raises(ConfigError) as exc:
        read_tire_data(DATA / "malformed" / name)
    assert expected in str(exc.value)


def test_truncated_after_the_required_keys_is_an_error(tmp_path):
    """A file cut in the middle of a line after every required key (here in [ALIGNING_COEFFICIENTS],
    inside QBZ1) must not evaluate with zeros for the rest: issue 6, truncated file -> clear error."""
    raw = (DATA / "MagicFormula61_Parameters.tir").read_bytes()
    cut = raw[:raw.index(b"QBZ1") + 35]  # "QBZ1 = 12.59" of 12.5909
    assert not cut.endswith((b"\n", b"\r"))
    with pytest.raises(ConfigError) as exc:
        tire_data(tirio.parse_tir(cut, "cut.tir"))
    text = str(exc.value)
    assert "cut.tir:" in text and "may be truncated" in text and "QBZ2" in text
    # the same keys with a final line break: a (short) complete file, defaults with a warning
    td = tire_data(tirio.parse_tir(cut + b"\r\n", "short.tir"))
    assert "QBZ2" in td.defaulted


def test_complete_file_without_a_final_line_break_is_not_truncated():
    """No final line break is not a cut when the lacking coefficients belong to earlier sections
    (here QSY8 of [ROLLING_COEFFICIENTS]), nor when the file ends in blanks."""
    raw = (DATA / "MagicFormula61_Parameters.tir").read_bytes()
    lines = raw.split(b"\n")
    no_qsy8 = b"\n".join(ln for ln in lines if not ln.strip().upper().startswith(b"QSY8")).rstrip(b"\r\n")
    td = tire_data(tirio.parse_tir(no_qsy8, "no-qsy8.tir"))
    assert td.defaulted == ["QSY8"]
    doc = tirio.parse_tir(raw.rstrip(b"\r\n") + b"\n   ", "blanks.tir")
    assert not doc.ends_mid_line
    tire_data(doc)


def test_junk_without_nul_bytes_and_missing_file(tmp_path):
    junk = tmp_path / "junk.tir"
    junk.write_bytes(bytes(range(1, 32)) * 20)
    with pytest.raises(ConfigError, match="binary file"):
        read_tire_data(junk)
    with pytest.raises(ConfigError, match="file not found"):
        read_tire_data(tmp_path / "nope.tir")
    text = tmp_path / "text.tir"
    text.write_text("hello world\nthis is not a tyre\n")
    with pytest.raises(ConfigError, match="no \\[SECTION\\] header"):
        read_tire_data(text)


@pytest.mark.parametrize("name", SAMPLES + ["pac89-hmmwv.tir"])
def test_yaml_round_trip_is_lossless(name, tmp_path):
    doc = tirio.read_tir(DATA / name)
    text = dump_yaml(tirio.to_yaml_data(doc))
    data, origins = parse_yaml(text, "x.yaml")
    back = tirio.from_yaml_data(data, origins, "x.yaml")
    a, b = tirio.to_yaml_data(doc), tirio.to_yaml_data(back)
    a.pop("source"), b.pop("source")
    assert a == b  # sections, values, tables, descriptions, preamble
    for sname, sec in doc.sections.items():
        for key, e in sec.entries.items():
            v = back.sections[sname].entries[key].value
            assert type(v) is type(e.value) and v == e.value
    out = tmp_path / "back.tir"
    tirio.write_tir(out, back)
    again = tirio.read_tir(out)
    assert tirio.to_yaml_data(again)["sections"] == tirio.to_yaml_data(doc)["sections"]
    assert read_tire_data(out).values == read_tire_data(DATA / name).values


def test_book_set_builtin_citation_and_values():
    td = load_builtin_tire_data("pacejka2006-205-60r15")
    assert td.version == "6.1" and td.values["PDY1"] == -0.990 and td.values["PKY4"] == 2
    assert any("Table A3.1" in line for line in td.doc.preamble)
    assert not math.isnan(td.values["QSY1"])
