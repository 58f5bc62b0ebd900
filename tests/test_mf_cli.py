"""The Magic Formula through the real CLI: tir show/check/convert, mf eval, MF sweeps, report cards."""
import json
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import EXAMPLES, ROOT

from tirecli.models.magic_formula import evaluate
from tirecli.parameters.mf import load_builtin_tire_data, read_tire_data
from tirecli.studies.mf_golden import GOLDEN, golden_rows

DATA = ROOT / "tests" / "data" / "tir"
SAMPLES = ["ExternData_sample.tir", "MagicFormula61_Parameters.tir", "mf_185_80R14.tir"]


def one_line_error(code, err, expected_code=2):
    assert code == expected_code, err
    assert "Traceback" not in err
    assert err.startswith("error: ")


# --------------------------------------------------------------------------- tir show / check / convert


@pytest.mark.parametrize("name, version, size, load", [
    ("ExternData_sample.tir", "MF 6.1", "205/60 R15", "FNOMIN 4000 N"),
    ("MagicFormula61_Parameters.tir", "MF 6.1", "255/55 R20", "FNOMIN 6752 N"),
    ("mf_185_80R14.tir", "MF 5.2 / PAC2002", "185/80 R14", "FNOMIN 3800 N"),
])
def test_tir_show(cli, name, version, size, load):
    code, out, err = cli("tir", "show", DATA / name)
    assert code == 0, err
    assert f"model: {version}" in out and size in out and load in out
    assert "ranges: Fz " in out and "[LATERAL_COEFFICIENTS]" in out


def test_tir_show_builtin_and_pressure(cli):
    code, out, err = cli("tir", "show", "mfeval-255-55r20")
    assert code == 0 and "NOMPRES 260000 Pa" in out and "citation:" in out and "-> right" in out
    code, out, err = cli("tir", "show", "mfeval-255-55r2")
    one_line_error(code, err)
    assert "did you mean 'mfeval-255-55r20'" in err


@pytest.mark.parametrize("name, expected", [
    ("empty.tir", "empty file"),
    ("binary.tir", "binary file"),
    ("truncated.tir", "may be truncated"),
    ("truncated-late.tir", "truncated-late.tir:251: the file may be truncated"),
    ("missing-section.tir", "PCY1: missing required coefficient"),
    ("bad-number.tir", "bad-number.tir:197: PCY1: cannot read the value '1.47.59'"),
    ("bad-unit-angle.tir", "bad-unit-angle.tir:9: ANGLE"),
])
@pytest.mark.parametrize("command", [("tir", "show"), ("tir", "check"), ("tir", "convert", "--to", "yaml")])
def test_malformed_files_through_the_cli(cli, name, expected, command, tmp_path):
    args = list(command[:2]) + [DATA / "malformed" / name] + list(command[2:])
    code, out, err = cli(*args)
    one_line_error(code, err)
    assert expected in err


def test_malformed_file_as_mf_eval_tire_writes_nothing(cli, tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0,0,0,4000\n")
    code, out, err = cli("mf", "eval", DATA / "malformed" / "truncated.tir", "--points", pts, "--out", tmp_path / "r.csv")
    one_line_error(code, err)
    assert not (tmp_path / "r.csv").exists()


def _with(tmp_path, replace, name="t.tir"):
    text = (ROOT / "tirecli" / "parameters" / "data" / "pacejka2006-205-60r15.tir").read_text()
    for old, new in replace:
        assert old in text
        text = text.replace(old, new)
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("replace, expected", [
    ((("PEY1                     = -1.003", "PEY1                     = 1.5"),), "curvature E_y"),
    ((("PDX1                     = 1.21", "PDX1                     = -1.21"),), "peak D_x"),
    ((("PCX1                     = 1.685", "PCX1                     = -1.685"),), "shape factor C"),
    ((("FNOMIN                   = 4000", "FNOMIN                   = 4000\n[VERTICAL_FORCE_RANGE]\nFZMIN = 100\nFZMAX = 3000"),),
     "excludes the nominal load"),
])
def test_tir_check_errors_exit_1(cli, tmp_path, replace, expected):
    path = _with(tmp_path, replace)
    code, out, err = cli("tir", "check", path)
    assert code == 1 and expected in out and "error(s)" in out
    # every finding names the file and the line of its (first) coefficient: file:line: KEY: ...
    line = next(x for x in out.splitlines() if expected in x)
    key = line.split(": ")[2].replace("..", "/").split("/")[0]
    lineno = next(i for i, t in enumerate(path.read_text().splitlines(), 1) if t.split("=")[0].strip() == key)
    assert line.startswith(f"error: {path}:{lineno}: "), line


def test_tir_check_clean_and_warnings_exit_0(cli):
    code, out, err = cli("tir", "check", "externdata-205-60r15")
    assert code == 0 and "0 error(s)" in out and "unknown key" in out  # QV1... warned
    code, out, err = cli("tir", "check", "pacejka2006-205-60r15")
    assert code == 0 and "mu_y < 0" in out


def test_tir_check_flags_the_pac2002_sample(cli):
    """mf_185_80R14.tir: PEY3 = 41.5, PEY4 = 665 make E_y > 1 at the camber limit 0.26 rad (a fact of the file)."""
    code, out, err = cli("tir", "check", DATA / "mf_185_80R14.tir")
    assert code == 1 and "E_y" in out and "gamma = 0.26181" in out


@pytest.mark.parametrize("name", SAMPLES)
def test_tir_convert_round_trip(cli, tmp_path, name):
    y = tmp_path / "t.yaml"
    back = tmp_path / "back.tir"
    assert cli("tir", "convert", DATA / name, "--to", "yaml", "--out", y)[0] == 0
    assert y.read_text().startswith("# ")
    assert cli("tir", "convert", y, "--to", "tir", "--out", back)[0] == 0
    a, b = read_tire_data(DATA / name), read_tire_data(back)
    assert a.values == b.values and a.version == b.version and a.side == b.side and a.units == b.units
    assert cli("tir", "show", y)[0] == 0
    code, out, err = cli("tir", "convert", DATA / name, "--to", "yaml")  # to stdout
    assert code == 0 and "format: tirecli-tir/1" in out
    code, out, err = cli("tir", "convert", DATA / name, "--to", "json")
    one_line_error(code, err)


# --------------------------------------------------------------------------- mf eval


def test_mf_eval_golden_rows_end_to_end(cli, tmp_path):
    g = np.vstack([golden_rows(b) for b in GOLDEN])
    pts = tmp_path / "golden.csv"
    pd.DataFrame(g[:, :6], columns=["kappa", "alpha", "gamma", "fz", "p", "vx"]).to_csv(pts, index=False)
    out = tmp_path / "r.csv"
    code, stdout, err = cli("mf", "eval", "pacejka2006-205-60r15", "--points", pts, "--out", out, "--convention", "teasit")
    assert code == 0, err
    r = pd.read_csv(out)
    # the forces first, then the extra outputs this tyre gives (slip stiffnesses only: §17)
    assert list(r.columns) == ["kappa", "alpha", "gamma", "fz", "p", "vx", "fx", "fy", "mz", "mx", "my", "Kxk", "Kya"]
    for i, c in enumerate(["fx", "fy", "mz", "mx", "my"]):
        assert np.abs(r[c].to_numpy() - g[:, 6 + i]).max() <= 1e-6


def test_mf_eval_round_trip_is_exact(cli, tmp_path):
    t = load_builtin_tire_data("mfeval-255-55r20").tire()
    rng = np.random.default_rng(2)
    n = 3000
    df = pd.DataFrame({"kappa": rng.uniform(-1.2, 1.2, n), "alpha": rng.uniform(-1, 1, n),
                       "gamma": rng.uniform(-0.1, 0.1, n), "fz": rng.uniform(0, 20000, n)})
    df.loc[0, ["kappa", "alpha", "gamma"]] = [0.0, 0.0, 0.0]
    pts = tmp_path / "p.csv"
    df.to_csv(pts, index=False)
    out = tmp_path / "r.csv"
    code, stdout, err = cli("mf", "eval", "mfeval-255-55r20", "--points", pts, "--out", out)
    assert code == 0, err
    assert "point(s): slip angles clipped" in stdout  # |alpha| > ALPMAX = 0.96 for some rows
    src = pts.read_text().splitlines()
    res = out.read_text().splitlines()
    assert [line.split(",")[:4] for line in res[1:]] == [line.split(",") for line in src[1:]]  # inputs copied
    r = pd.read_csv(out)
    ref = evaluate(t, df["kappa"].to_numpy(), df["alpha"].to_numpy(), df["gamma"].to_numpy(), df["fz"].to_numpy())
    for c in ("fx", "fy", "mz", "mx", "my"):
        np.testing.assert_array_equal(r[c].to_numpy(), getattr(ref, c))  # written exactly
    assert (r["p"] == 260000.0).all() and (r["vx"] == 16.6).all()


def test_mf_eval_other_column_order_and_map(cli, tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("fz,slip,alpha,gamma,vx\n4000,0.1,0.05,0,10\n# a comment\n3000,-0.2,0,0.01,20\n")
    out = tmp_path / "r.csv"
    code, stdout, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", out, "--map", "slip=kappa")
    assert code == 0, err
    r = pd.read_csv(out)
    assert r["kappa"].tolist() == [0.1, -0.2] and r["fz"].tolist() == [4000.0, 3000.0] and r["vx"].tolist() == [10.0, 20.0]
    t = load_builtin_tire_data("externdata-205-60r15").tire()
    ref = evaluate(t, np.array([0.1, -0.2]), np.array([0.05, 0.0]), np.array([0.0, 0.01]), np.array([4000.0, 3000.0]),
                   np.array([10.0, 20.0]))
    np.testing.assert_array_equal(r["fy"].to_numpy(), ref.fy)


def test_mf_eval_side_mirrors(cli, tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0.05,0.04,0.02,4000\n")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", a, "--side", "left")[0] == 0
    code, out, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", b, "--side", "right")
    assert code == 0 and "mirrored" in out
    ra, rb = pd.read_csv(a), pd.read_csv(b)
    t = load_builtin_tire_data("externdata-205-60r15").tire()
    ref = evaluate(t, 0.05, -0.04, -0.02, 4000.0)
    assert rb["fy"][0] == -float(ref.fy) and rb["fx"][0] == float(ref.fx) and rb["mz"][0] == -float(ref.mz)
    assert ra["fy"][0] != rb["fy"][0]
    code, out, err = cli("mf", "eval", "pacejka2006-205-60r15", "--points", pts, "--out", a, "--side", "right")
    one_line_error(code, err)
    assert "TYRESIDE" in err


@pytest.mark.parametrize("content, expected", [
    ("kappa,alpha,fz\n0,0,4000\n", "missing column(s) 'gamma'"),
    ("kappa,alpha,gamma,fz\n0,0,0,abc\n", "column 'fz' row 1: not a number ('abc')"),
    ("kappa,alpha,gamma,fz\n0,0,0,4000\n0.1,,0,4000\n", "column 'alpha' row 2: empty or NaN value"),
    ("kappa,alpha,gamma,fz\n0,0,0,4000\n0.1,nan,0,4000\n", "column 'alpha' row 2: empty or NaN value"),
    ("kappa,alpha,gamma,fz,p\n0,0,0,4000,-5\n", "column 'p' row 1: pressure must be > 0"),
    ("", "empty file"),
    (b"\x00\x01\x02binary", "binary file"),
    # more fields than header names: pandas would shift the columns (kappa read from alpha ...)
    ("kappa,alpha,gamma,fz\n0.1,0.05,0,4000,7\n", "row 1 has 5 fields but the header names 4 columns"),
    # a trailing comma: the copied row would shift every output column
    ("kappa,alpha,gamma,fz\n0,0,0,4000\n0.1,0.05,0,4000,\n", "data row 2 has 5 fields but the header names 4"),
    ("kappa,alpha,gamma,fz\n0,0,0,4000\n0.1,0.05,0\n", "data row 2 has 3 fields but the header names 4"),
    ("kappa,alpha,gamma,fz,fz\n0,0,0,4000,4000\n", "column(s) 'fz' appear more than once"),
])
def test_mf_eval_rejects_bad_points(cli, tmp_path, content, expected):
    pts = tmp_path / "p.csv"
    if isinstance(content, bytes):
        pts.write_bytes(content)
    else:
        pts.write_text(content)
    out = tmp_path / "r.csv"
    code, stdout, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", out)
    one_line_error(code, err)
    assert expected in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.csv"]  # no output, no temporary file


def test_mf_eval_usage_errors(cli, tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0,0,0,4000\n")
    for args, expected in ((("--convention", "book"), "--convention"), (("--side", "middle"), "--side"),
                           (("--map", "nonsense"), "--map")):
        code, out, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", tmp_path / "r.csv", *args)
        one_line_error(code, err)
        assert expected in err
    code, out, err = cli("mf", "eval", "canudas2003-table1", "--points", pts, "--out", tmp_path / "r.csv")
    one_line_error(code, err)
    assert "not a Magic Formula tyre" in err


# --------------------------------------------------------------------------- sweeps, params, report


def test_mf_sweep_output_contract(cli, tmp_path):
    out = tmp_path / "o"
    code, stdout, err = cli("--quiet", "sweep", EXAMPLES / "mf-sweep-chrono-185-80r14.yaml", "--out", out)
    assert code == 0, err
    run = json.loads((out / "run.json").read_text())
    assert run["parameters"]["tire"]["kind"] == "magic_formula"
    assert run["parameters"]["tire"]["details"]["version"] == "5.2"
    line = next(i for i, ln in enumerate((DATA / "mf_185_80R14.tir").read_bytes().split(b"\n"), 1) if ln.startswith(b"PCX1"))
    assert run["parameters"]["tire"]["parameters"]["PCX1"]["source"] == f"<built-in chrono-185-80r14>:{line}"
    assert run["checks"] and all(c["passed"] for c in run["checks"])
    df = pd.read_csv(out / "data" / "sweep.csv")
    assert set(df["family"]) == {"fx-kappa", "fy-alpha", "camber", "combined-alpha", "combined-kappa"}
    for col in ("kappa", "alpha", "gamma", "fz", "fx", "fy", "mz", "mx", "my", "mu_x", "slip"):
        assert col in df.columns
    assert (out / "figures" / "mf-tire-chrono-185-80r14.png").stat().st_size > 20_000
    assert (out / "figures" / "mf-tire-chrono-185-80r14.svg").exists()


def test_mf_sweep_tir_path_overrides_and_inline(cli, tmp_path):
    shutil.copy(DATA / "mf_185_80R14.tir", tmp_path / "my.tir")
    cfg = tmp_path / "s.yaml"
    cfg.write_text("study: sweep\ntire: {set: my.tir, LMUX: 0.5}\nsweep: {loads: [3800], kappa: [-0.3, -0.1, 0.1, 0.3]}\n"
                   "figures: [mf-fx-kappa]\n")
    code, out, err = cli("--quiet", "sweep", cfg, "--out", tmp_path / "a")
    assert code == 0, err
    half = pd.read_csv(tmp_path / "a" / "data" / "sweep.csv")
    code, out, err = cli("--quiet", "sweep", cfg, "--out", tmp_path / "b", "--set", "tire.LMUX=1")
    assert code == 0, err
    full = pd.read_csv(tmp_path / "b" / "data" / "sweep.csv")
    fam = "fx-kappa"
    a = half[half["family"] == fam]["fx"].to_numpy()
    b = full[full["family"] == fam]["fx"].to_numpy()
    assert np.abs(a).max() < 0.6 * np.abs(b).max()  # peak D_x scales with LMUX (§4)
    run = json.loads((tmp_path / "a" / "run.json").read_text())
    assert run["parameters"]["tire"]["parameters"]["LMUX"]["source"].startswith(str(cfg))
    cfg.write_text("study: sweep\ntire: {set: my.tir, LMUXX: 0.5}\n")
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "c")
    one_line_error(code, err)
    assert "did you mean 'LMUX'" in err and f"{cfg}:2" in err
    cfg.write_text("study: sweep\ntire: {FNOMIN: 4000, UNLOADED_RADIUS: 0.3, LONGVL: 16.7, PCX1: 1.6, PDX1: 1.0, PKX1: 20,\n"
                   "       PCY1: 1.3, PDY1: 1.0, PKY1: -15, PKY2: 2}\nsweep: {loads: [4000]}\nfigures: [mf-fy-alpha]\n")
    code, out, err = cli("--quiet", "sweep", cfg, "--out", tmp_path / "d")
    assert code == 0, err
    run = json.loads((tmp_path / "d" / "run.json").read_text())
    assert any(a.startswith("tire.QDZ1") for a in run["assumed"])  # defaulted coefficients are flagged
    cfg.write_text("study: sweep\ntire: {FNOMIN: 4000, PCX1: 1.6}\n")
    code, out, err = cli("sweep", cfg)
    one_line_error(code, err)
    assert "missing required coefficient 'PKY1'" in err


def test_params_list_show_validate_mf(cli):
    code, out, err = cli("params", "list")
    assert code == 0 and "pacejka2006-205-60r15" in out and "magic_formula" in out
    code, out, err = cli("params", "show", "pacejka2006-205-60r15")
    assert code == 0 and "PKY1" in out and "Table A3.1" in out
    code, out, err = cli("params", "validate", EXAMPLES / "mf-lugre-compare.yaml")
    assert code == 0 and "valid sweep config" in out


def test_report_mf_cards(cli, tmp_path):
    code, out, err = cli("--quiet", "report", "--out", tmp_path, "--only", "mf-golden-fx0", "--only", "mf-golden-combined-camber",
                         "--only", "mf-lugre-compare")
    assert code == 0, err
    summary = json.loads((tmp_path / "summary.json").read_text())
    golden = [c for c in summary["checks"] if "golden" in c["id"]]
    assert len(golden) == 2 and all(c["passed"] and c["value"] <= 1e-6 and c["tolerance"] == 1e-6 for c in golden)
    assert summary["n_failed"] == 0
    html = (tmp_path / "index.html").read_text()
    assert 'id="mf-lugre-compare"' in html and 'id="mf-golden-fx0"' in html


def test_figures_of_the_other_model_family_are_refused(cli, tmp_path):
    cfg = tmp_path / "s.yaml"
    cfg.write_text("study: sweep\ntire: chrono-185-80r14\nfigures: [sweep-mu-slip]\n")
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "a")
    one_line_error(code, err)
    assert "draws a LuGre sweep" in err
    cfg.write_text("study: sweep\ntire: canudas2003-table1\nsweep: {slip: [-0.1, 0]}\nfigures: [mf-fx-kappa]\n")
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "b")
    one_line_error(code, err)
    assert "figure 'mf-fx-kappa' draws a Magic Formula sweep" in err


@pytest.mark.parametrize("header, row, p, vx", [
    ("kappa,alpha,gamma,fz,vx", "0.1,0,0,4000,5", 200000.0, 5.0),
    ("kappa,alpha,gamma,fz,p", "0.1,0,0,4000,180000", 180000.0, 16.7),
    ("kappa,alpha,gamma,fz", "0.1,0,0,4000", 200000.0, 16.7),
])
def test_mf_eval_defaults_land_under_their_own_headers(cli, tmp_path, header, row, p, vx):
    pts = tmp_path / "p.csv"
    pts.write_text(f"{header}\n{row}\n")
    out = tmp_path / "r.csv"
    code, stdout, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", out)
    assert code == 0, err
    r = pd.read_csv(out)
    assert r["p"].tolist() == [p] and r["vx"].tolist() == [vx]


def test_tir_show_of_another_kind_of_file_is_one_line(cli, tmp_path):
    root = Path(__file__).resolve().parents[1]
    for name in ("pyproject.toml", "README.md"):
        code, out, err = cli("tir", "show", root / name)
        assert code == 2 and "not a .tir property file" in err and len(err.strip().splitlines()) == 1


def test_mf_eval_names_a_tir_file_as_the_user_wrote_it(cli, tmp_path, monkeypatch):
    """An error in a relative .tir path named the file by its absolute path (``tir show`` and
    ``tir check`` name it as given): one line per missing coefficient, the file as typed."""
    text = (ROOT / "tests" / "data" / "tir" / "MagicFormula61_Parameters.tir").read_text(encoding="utf-8")
    start = text.index("[LONGITUDINAL_COEFFICIENTS]")
    end = text.index("[", start + 1)
    (tmp_path / "nolong.tir").write_text(text[:start] + text[end:], encoding="utf-8")
    (tmp_path / "p.csv").write_text("kappa,alpha,gamma,fz\n0,0,0,4000\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    code, out, err = cli("mf", "eval", "nolong.tir", "--points", "p.csv", "--out", "r.csv")
    assert code == 2 and not (tmp_path / "r.csv").exists()
    lines = err.strip().splitlines()
    assert lines and all(line.startswith("error: nolong.tir: ") for line in lines), err
    assert "[LONGITUDINAL_COEFFICIENTS] is missing" in err
    code, _, err2 = cli("tir", "check", "nolong.tir")
    assert code == 2 and err2 == err


@pytest.mark.parametrize("sep", [";", "\t"])
def test_a_points_file_of_another_separator_says_so(cli, tmp_path, sep):
    """A semicolon- or tab-separated points file (a spreadsheet export) was refused as 'missing
    column(s) ... (file has: 1 header field(s) that do not look like column names, not shown)', which
    does not say why: the message names the separator and what tirecli reads."""
    pts = tmp_path / "p.csv"
    pts.write_text(sep.join(["kappa", "alpha", "gamma", "fz"]) + "\n" + sep.join(["0", "0", "0", "4000"]) + "\n")
    code, out, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", tmp_path / "r.csv")
    assert code == 2 and err.count("\n") == 1 and not (tmp_path / "r.csv").exists()
    assert f"one field with {sep!r} in it: tirecli reads comma-separated files" in err, err



def test_a_tir_file_without_its_model_section_says_so(cli, tmp_path):
    """mfeval's sample without [MODEL] was refused as 'LONGVL: missing, but QSY3/QSY4 ... need the
    reference speed', which does not say that the whole section is gone."""
    text = (ROOT / "tests" / "data" / "tir" / "MagicFormula61_Parameters.tir").read_text(encoding="utf-8")
    start = text.index("[MODEL]")
    end = text.index("[", start + 1)
    (tmp_path / "nomodel.tir").write_text(text[:start] + text[end:], encoding="utf-8")
    code, out, err = cli("tir", "check", tmp_path / "nomodel.tir")
    assert code == 2 and "LONGVL: missing" in err and "[MODEL] is missing" in err, err


def test_mf_eval_command_and_study_are_one_path(cli, tmp_path):
    """``tirecli mf eval --points CSV`` and the mf-eval study (a campaign's base) evaluate the same points to the
    same numbers and columns (the extra outputs included), default the pressure and speed alike, and refuse a
    non-finite output alike (naming the point)."""
    import pandas as pd

    from tirecli.campaign.facts import run_point
    from tirecli.config.loader import config_from_text
    from tirecli.errors import ConfigError
    from tirecli.studies.registry import get, run_study

    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0,0.03,0,3000\n0.08,-0.02,0.01,5000\n-0.1,0.1,0,4000\n")
    code, _, err = cli("mf", "eval", "externdata-205-60r15", "--points", pts, "--out", tmp_path / "r.csv")
    assert code == 0, err
    written = pd.read_csv(tmp_path / "r.csv")
    text = ("study: mf-eval\ntire: externdata-205-60r15\npoints: {kappa: [0, 0.08, -0.1], alpha: [0.03, -0.02, 0.1], "
            "gamma: [0, 0.01, 0], fz: [3000, 5000, 4000]}\n")
    res = run_study(config_from_text(text, "<test>"))
    frame = res.data["points"]
    assert list(frame.columns) == list(written.columns) and {"Kya", "Cz", "re"} <= set(frame.columns)
    np.testing.assert_array_equal(frame.to_numpy(dtype=float), written.to_numpy(dtype=float))  # p, vx defaults too
    facts = get("mf-eval").facts(res)
    assert facts["fy[1]"] == written["fy"][1] and facts["Kya[2]"] == written["Kya"][2]
    # a campaign's point: only the facts asked for, the same numbers
    assert run_point(config_from_text(text, "<test>"), ["fy[1]", "re[0]"])[0] == {"fy[1]": facts["fy[1]"], "re[0]": facts["re[0]"]}
    # an absurd load: no finite force, named at its point
    bad = "study: mf-eval\ntire: chrono-185-80r14\nlimits: false\npoints: {kappa: 0.05, alpha: 0, fz: [4000, 1.0e+12]}\n"
    with pytest.raises(ConfigError, match=r"<test>:4: points: point 1: the Magic Formula gives no finite fx.*fz = 1e\+12 N.*above FZMAX"):
        run_study(config_from_text(bad, "<test>"))
