"""Measured-data readers (issue 23): the channel table, TYDEX 1.3, CSV, Parquet, MDF4, unit strings,
axis conventions, sweep detection. Values are checked against closed forms (unit factors, sign rules)
and against independent evaluations of the generating tyre, never against the reader itself."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from tirecli import conventions as cv
from tirecli import units
from tirecli.errors import DataError, UsageError
from tirecli.io.readers import read_measured, write_measured

DEG = math.pi / 180


def tyre(name: str):
    """A built-in Magic Formula tyre (through the parameter sets, as every command loads it)."""
    from tirecli.parameters.mf import tire_from_set
    from tirecli.parameters.sets import load_set

    return tire_from_set(load_set(name))


# --------------------------------------------------------------------------- unit strings


@pytest.mark.parametrize("text, unit, factor", [
    ("deg", "rad", DEG), ("°", "rad", DEG), ("[deg]", "rad", DEG), ("rad", "rad", 1.0), ("%", "-", 0.01),
    ("-", "-", 1.0), ("", "-", 1.0), ("N", "N", 1.0), ("kN", "N", 1000.0), ("N m", "N m", 1.0), ("Nm", "N m", 1.0),
    ("N*m", "N m", 1.0), ("N.m", "N m", 1.0), ("kN m", "N m", 1000.0), ("Pa", "Pa", 1.0), ("kPa", "Pa", 1000.0),
    ("KPA", "Pa", 1000.0), ("bar", "Pa", 1e5), ("psi", "Pa", 6894.757293168361), ("m/s", "m/s", 1.0),
    ("km/h", "m/s", 1 / 3.6), ("kph", "m/s", 1 / 3.6), ("mm", "m", 1e-3), ("m", "m", 1.0), ("s", "s", 1.0),
    ("ms", "s", 1e-3), ("rpm", "rad/s", 2 * math.pi / 60), ("deg/s", "rad/s", DEG), ("rad/s", "rad/s", 1.0),
    ("lbf", "N", 4.4482216152605),
])
def test_unit_table(text, unit, factor):
    got_unit, got_factor, offset = units.si(text)
    assert (got_unit, offset) == (unit, 0.0)
    assert got_factor == pytest.approx(factor, rel=1e-15)


def test_unit_case_matters_where_it_decides_and_celsius_has_an_offset():
    assert units.si("ms")[1] == 1e-3 and units.si("m")[1] == 1.0   # milliseconds, metres
    assert units.si("degC") == ("K", 1.0, 273.15)
    for bad in ("furlong", "N/rad", "kg m", "deg C F"):
        with pytest.raises(KeyError):
            units.si(bad)


# --------------------------------------------------------------------------- axis conventions

QUANTITIES = ("kappa", "alpha", "gamma", "fx", "fy", "fz", "mx", "my", "mz")


@pytest.mark.parametrize("convention", cv.AXIS_CONVENTIONS)
def test_every_convention_is_an_involution(convention):
    rng = np.random.default_rng(3)
    x = {q: rng.normal(size=5) for q in QUANTITIES}
    back = cv.axes_from_iso(cv.axes_to_iso(x, convention), convention)
    assert all(np.array_equal(back[q], x[q]) for q in QUANTITIES)


def test_conventions_compose_iso_sae_adapted_iso_and_back():
    rng = np.random.default_rng(4)
    x = {q: rng.normal(size=3) for q in QUANTITIES}
    sae = cv.axes_from_iso(x, "sae")
    adapted = cv.axes_from_iso(cv.axes_to_iso(sae, "sae"), "adapted-iso")
    back = cv.axes_to_iso(adapted, "adapted-iso")
    assert all(np.array_equal(back[q], x[q]) for q in QUANTITIES)


def test_sae_is_the_180_degree_rotation_about_x():
    # a rotation by pi about x: R = diag(1, -1, -1); forces are vectors, moments axial vectors: same signs under
    # a proper rotation. The slip angle (a rotation about z) flips, kappa and the inclination (about x) do not.
    r = np.diag([1.0, -1.0, -1.0])
    f, m = np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0])
    sae = cv.axes_from_iso({"fx": f[0], "fy": f[1], "fz": f[2], "mx": m[0], "my": m[1], "mz": m[2]}, "sae")
    assert np.allclose([sae[k] for k in ("fx", "fy", "fz")], r @ f)
    assert np.allclose([sae[k] for k in ("mx", "my", "mz")], r @ m)
    assert cv.flipped("sae") == ("alpha", "fy", "fz", "my", "mz")
    assert cv.flipped("adapted-iso") == ("alpha", "gamma") and cv.flipped("iso") == ()


def test_sign_facts_of_a_real_tyre_in_each_convention():
    """ISO-W: a positive slip angle and a positive camber give a negative side force, Fz > 0 under load.
    SAE: the load is negative, the cornering stiffness stays negative. Adapted ISO: positive alpha and
    positive gamma give a positive side force."""
    from tirecli.models.magic_formula import evaluate

    tire = tyre("externdata-205-60r15")
    a = evaluate(tire, 0.0, 2 * DEG, 0.0, 4000.0)
    g = evaluate(tire, 0.0, 0.0, 3 * DEG, 4000.0)
    iso_a = {"alpha": 2 * DEG, "fy": a.fy, "fz": 4000.0}
    iso_g = {"gamma": 3 * DEG, "fy": g.fy}
    assert a.fy < 0 and g.fy < 0
    sae = cv.axes_from_iso(iso_a, "sae")
    assert sae["fz"] < 0 and np.sign(sae["fy"]) == -np.sign(sae["alpha"])
    ad_a, ad_g = cv.axes_from_iso(iso_a, "adapted-iso"), cv.axes_from_iso(iso_g, "adapted-iso")
    assert np.sign(ad_a["fy"]) == np.sign(ad_a["alpha"]) and np.sign(ad_g["fy"]) == np.sign(ad_g["gamma"])
    assert ad_a["fz"] > 0


def test_iso_to_sae_is_the_one_in_conventions():
    from tirecli.models.magic_formula import axes

    assert axes.iso_to_sae is cv.iso_to_sae
    out = cv.iso_to_sae(fx=1.0, fy=2.0, fz=3.0, mx=4.0, my=5.0, mz=6.0, alpha=0.1)
    assert {k: float(v) for k, v in out.items()} == {"fx": 1.0, "fy": -2.0, "fz": -3.0, "mx": 4.0, "my": -5.0,
                                                     "mz": -6.0, "alpha": -0.1}


# --------------------------------------------------------------------------- TYDEX

FIXED = """**HEADER
RELEASE   Release of TYDEX-Format       1.3
MEASID    Measurement ID                rig_01
**COMMENTS
written in the fixed layout; the last two rows hold numbers that touch
**CONSTANTS
FZW       Vertical load                 kN        4.5
INFLPRES  Inflation pressure            bar       2.2
**MEASURCHANNELS
MEASNUMB  Measurement number            -         1         0         0
RUNTIME   Time                          ms        1
SLIPANGL  Slip angle                    deg       1
INCLANGL  Inclination angle             deg       1
FYW       Lateral force W               kN        1
MZW       Aligning torque W             N m       1
LONGVEL   Longitudinal velocity         km/h      1
**MEASURDATA
1         0         -2.0      1.0       1.2345678 -20.5     60.0
1         100       0.0       1.0       0.0       0.0       60.0
1         200       2.0       1.0       -1.234567820.5      60.0
1         300       4.0       1.0       -2.345678942.25     60.0
**END
"""

LOOSE = """**HEADER
RELEASE 1.3
MEASID rig_01
**COMMENTS
the same data, blank-separated
**CONSTANTS
FZW Vertical load kN 4.5
INFLPRES Inflation pressure bar 2.2
**MEASURCHANNELS
! name description unit factor
MEASNUMB Measurement number - 1
RUNTIME Time ms 1
SLIPANGL Slip angle deg 1
INCLANGL Inclination angle deg 1
FYW Lateral force W kN 1
MZW Aligning torque W N m 1
LONGVEL Longitudinal velocity km/h 1
**MEASURDATA
1 0 -2.0 1.0 1.2345678 -20.5 60.0
1 100 0.0 1.0 0.0 0.0 60.0
1 200 2.0 1.0 -1.2345678 20.5 60.0
1 300 4.0 1.0 -2.3456789 42.25 60.0
**END
"""


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_tydex_fixed_and_blank_separated_layouts_read_alike(tmp_path):
    a = read_measured(_write(tmp_path, "fixed.tdx", FIXED))
    b = read_measured(_write(tmp_path, "loose.tdx", LOOSE))
    assert list(a.frame.columns) == list(b.frame.columns) == ["t", "run", "alpha", "gamma", "fz", "p", "vx", "fy", "mz"]
    assert np.array_equal(a.frame.to_numpy(), b.frame.to_numpy())
    f = a.frame
    assert np.allclose(f["t"], [0, 0.1, 0.2, 0.3], rtol=0, atol=1e-15)             # ms -> s
    assert np.allclose(f["alpha"], np.array([-2, 0, 2, 4]) * DEG, rtol=1e-15)      # deg -> rad
    assert np.allclose(f["fy"], [1234.5678, 0, -1234.5678, -2345.6789], rtol=1e-15)  # kN -> N
    assert np.allclose(f["mz"], [-20.5, 0, 20.5, 42.25], rtol=0)
    assert np.allclose(f["vx"], 60 / 3.6, rtol=1e-15) and np.allclose(f["gamma"], DEG)
    assert np.all(f["fz"] == 4500.0) and np.allclose(f["p"], 220000.0, rtol=1e-15)    # filled from the constants
    assert a.channels["fz"].source == "constant FZW" and any("FZW" in n for n in a.notes)
    assert a.header == {"RELEASE": "1.3", "MEASID": "rig_01"} and a.channels["fy"].factor == 1000.0


def test_tydex_channel_factor_and_percent_slip(tmp_path):
    text = LOOSE.replace("FYW Lateral force W kN 1", "FYW Lateral force W N 1000").replace(
        "SLIPANGL Slip angle deg 1", "LONGSLIP Longitudinal slip % 1")
    d = read_measured(_write(tmp_path, "f.tdx", text))
    assert np.allclose(d.frame["fy"], [1234.5678, 0, -1234.5678, -2345.6789], rtol=1e-15)
    assert np.allclose(d.frame["kappa"], [-0.02, 0, 0.02, 0.04], rtol=1e-15)


def test_tydex_sae_file_gives_iso_signs(tmp_path):
    text = LOOSE.replace("**COMMENTS\n", "**COMMENTS\nconvention: sae\n")
    iso = read_measured(_write(tmp_path, "iso.tdx", LOOSE))
    text = text.replace("FZW Vertical load kN 4.5", "FZW Vertical load kN -4.5")
    sae = read_measured(_write(tmp_path, "sae.tdx", text))
    assert sae.convention == "sae"
    for q in ("alpha", "fy", "mz"):
        assert np.array_equal(sae.frame[q], -iso.frame[q])
    assert np.all(sae.frame["fz"] == 4500.0)        # -4.5 kN in SAE (z down) is a 4500 N load
    assert np.array_equal(sae.frame["gamma"], iso.frame["gamma"])


def _table(n=30, seed=0):
    from tirecli.io.measured import RawColumn, assemble

    rng = np.random.default_rng(seed)
    cols = {"t": np.arange(n) * 0.01, "run": np.repeat([1.0, 2.0], [n // 2, n - n // 2]),
            "kappa": rng.uniform(-0.3, 0.3, n), "alpha": rng.uniform(-0.2, 0.2, n), "gamma": rng.uniform(0, 0.05, n),
            "fz": rng.uniform(2000, 6000, n), "p": np.full(n, 2.2e5), "vx": np.full(n, 16.7),
            "fx": rng.normal(0, 3000, n), "fy": rng.normal(0, 3000, n), "mz": rng.normal(0, 50, n),
            "mx": rng.normal(0, 20, n), "my": rng.normal(-10, 1, n), "TEMPTREA": rng.uniform(300, 330, n)}
    raw = [RawColumn(v, k, k.upper(), "K" if k == "TEMPTREA" else None) for k, v in cols.items()]
    return assemble("<test>", "csv", raw, "iso", comments=["SYNTHETIC DATA generated by tirecli (not measured)"])


@pytest.mark.parametrize("fmt", ["tdx", "csv", "parquet"])
def test_round_trip_keeps_every_value(tmp_path, fmt):
    data = _table()
    path = tmp_path / f"t.{fmt}"
    write_measured(path, data, fmt)
    back = read_measured(path)
    assert list(back.frame.columns) == list(data.frame.columns)
    assert np.array_equal(back.frame.to_numpy(), data.frame.to_numpy())   # bit for bit
    assert back.channels["TEMPTREA"].unit == "K" and back.synthetic
    again = tmp_path / f"again.{fmt}"
    write_measured(again, back, fmt)
    assert np.array_equal(read_measured(again).frame.to_numpy(), data.frame.to_numpy())


def test_tdx_to_csv_to_parquet_to_tdx(tmp_path):
    first = read_measured(_write(tmp_path, "a.tdx", FIXED))
    write_measured(tmp_path / "b.csv", first, "csv")
    write_measured(tmp_path / "c.parquet", read_measured(tmp_path / "b.csv"), "parquet")
    write_measured(tmp_path / "d.tdx", read_measured(tmp_path / "c.parquet"), "tdx")
    last = read_measured(tmp_path / "d.tdx")
    assert np.array_equal(last.frame.to_numpy(), first.frame.to_numpy())


# --------------------------------------------------------------------------- CSV options


def test_csv_map_and_units(tmp_path):
    p = _write(tmp_path, "log.csv", "Fz_kN,SA_deg,FY,x\n4.0,-2,1000,1\n4.0,0,0,2\n4.0,2,-1000,3\n")
    d = read_measured(p, mapping={"Fz_kN": "fz", "SA_deg": "alpha", "FY": "fy"}, units={"fz": "kN", "alpha": "deg"})
    assert np.all(d.frame["fz"] == 4000.0)
    assert np.allclose(d.frame["alpha"], np.array([-2, 0, 2]) * DEG, rtol=1e-15)
    assert list(d.frame.columns) == ["alpha", "fz", "fy", "x"] and d.channels["x"].unit == ""


def test_csv_canonical_names_are_case_insensitive_and_sae_flips(tmp_path):
    p = _write(tmp_path, "sae.csv", "Kappa,Alpha,Fz,Fy,Mz\n0.1,0.02,-4000,300,-20\n")
    d = read_measured(p, convention="sae")
    assert d.frame.iloc[0].to_dict() == {"kappa": 0.1, "alpha": -0.02, "fz": 4000.0, "fy": -300.0, "mz": 20.0}


# --------------------------------------------------------------------------- MDF4


def _mdf(path, signals):
    from asammdf import MDF, Signal

    mdf = MDF(version="4.10")
    for name, (t, x, unit) in signals.items():
        mdf.append([Signal(samples=np.asarray(x, dtype=float), timestamps=np.asarray(t, dtype=float), name=name,
                           unit=unit)])
    mdf.save(str(path), overwrite=True)
    mdf.close()


def test_mdf_channels_resampled_onto_the_first_channels_time_base(tmp_path):
    pytest.importorskip("asammdf")
    t1 = np.linspace(0.0, 2.0, 201)          # 100 Hz
    t2 = np.linspace(0.5, 3.0, 51)           # 20 Hz, starts later: no extrapolation before 0.5 s
    _mdf(tmp_path / "log.mf4", {"WheelSpeed": (t1, 10 + 2 * t1, "rpm"), "Fz_kN": (t2, 4 + 0.5 * t2, "kN"),
                                "Meas": (t2, np.floor(t2), "")})
    d = read_measured(tmp_path / "log.mf4", mapping={"WheelSpeed": "omega", "Fz_kN": "fz", "Meas": "run"})
    t = d.frame["t"].to_numpy()
    assert t[0] == pytest.approx(0.5) and t[-1] == pytest.approx(2.0) and len(t) == 151
    assert np.allclose(d.frame["omega"], (10 + 2 * t) * 2 * math.pi / 60, rtol=1e-12)
    assert np.allclose(d.frame["fz"], (4 + 0.5 * t) * 1000, rtol=1e-12)   # linear: interpolation is exact
    assert set(np.unique(d.frame["run"])) <= {0.0, 1.0, 2.0} and d.frame["run"].iloc[-1] == 2.0
    assert any("50 sample(s)" in n for n in d.notes)                        # 0 .. 0.49 s of WheelSpeed dropped
    r = read_measured(tmp_path / "log.mf4", mapping={"Fz_kN": "fz"}, rate=10)
    assert np.allclose(r.frame["t"], 0.5 + np.arange(26) / 10) and np.allclose(r.frame["fz"], 4000 + 500 * r.frame["t"])


def test_mdf_written_by_tirecli_reads_back(tmp_path):
    pytest.importorskip("asammdf")
    from tirecli.io.mdf import write_mdf

    data = _table()
    write_mdf(tmp_path / "t.mf4", data)
    back = read_measured(tmp_path / "t.mf4")   # every column has a canonical name: read without --map
    for c in ("kappa", "alpha", "fz", "fy", "run"):
        assert np.array_equal(back.frame[c].to_numpy(), data.frame[c].to_numpy())


def test_without_asammdf_one_line_names_the_extra(tmp_path, monkeypatch):
    import sys

    from tirecli.io.mdf import read_mdf

    (tmp_path / "x.mf4").write_bytes(b"MDF     4.10    ")
    monkeypatch.setitem(sys.modules, "asammdf", None)
    with pytest.raises(UsageError) as exc:
        read_mdf(tmp_path / "x.mf4")
    assert str(exc.value) == ("reading MDF files needs asammdf: pip install 'tirecli[mdf]' "
                              "(from a checkout: pip install '.[mdf]')")


# --------------------------------------------------------------------------- sweeps


@pytest.fixture(scope="module")
def rig():
    from tirecli.studies.rig_data import synthetic_rig_data

    tire = tyre("externdata-205-60r15")
    return tire, synthetic_rig_data(tire, "externdata-205-60r15", noise=0.02, seed=7)


def test_sweeps_found_with_and_without_run_numbers(rig):
    from tirecli.io.sweeps import find_sweeps

    tire, data = rig
    expected = ["pure longitudinal"] * 3 + ["pure lateral"] * 5 + ["combined"] * 2
    for frame in (data.frame, data.frame.drop(columns=["run", "t"])):
        sweeps = find_sweeps(frame)
        assert [s.kind for s in sweeps] == expected
        assert [s.rows for s in sweeps] == [41] * 10
        assert [round(s.fz) for s in sweeps] == [2000, 4000, 6000] * 2 + [4000] * 4
        assert [round(math.degrees(s.gamma), 6) for s in sweeps] == [0] * 6 + [2, 4] + [0, 0]
        assert [round(math.degrees(s.held.get("alpha", 0)), 6) for s in sweeps][-2:] == [3, 6]


def test_sweeps_survive_noise_on_the_load_and_slips(rig):
    from tirecli.io.sweeps import find_sweeps

    _, data = rig
    rng = np.random.default_rng(11)
    f = data.frame.drop(columns=["run"]).copy()
    f["fz"] *= 1 + 0.01 * rng.normal(size=len(f))          # 1 % load noise
    f["kappa"] += 0.001 * rng.normal(size=len(f))
    f["alpha"] += 0.05 * DEG * rng.normal(size=len(f))
    kinds = [s.kind for s in find_sweeps(f)]
    assert kinds == ["pure longitudinal"] * 3 + ["pure lateral"] * 5 + ["combined"] * 2


def test_longitudinal_then_lateral_sweep_from_zero_at_one_load_are_two(rig):
    from tirecli.io.sweeps import find_sweeps

    up = np.concatenate([np.linspace(0, 0.2, 11), np.linspace(0.2, -0.2, 21), np.linspace(-0.2, 0, 11)])
    n = len(up)
    f = pd.DataFrame({"kappa": np.r_[up, np.zeros(n)], "alpha": np.r_[np.zeros(n), up], "fz": 4000.0})
    sweeps = find_sweeps(f)
    assert [s.kind for s in sweeps] == ["pure longitudinal", "pure lateral"]


def test_synthetic_data_are_the_tyre_exactly_without_noise():
    from tirecli.models.magic_formula import evaluate
    from tirecli.studies.rig_data import synthetic_rig_data

    tire = tyre("pacejka2006-205-60r15")
    data = synthetic_rig_data(tire, "pacejka2006-205-60r15", noise=0.0)
    f = data.frame
    res = evaluate(tire, f["kappa"].to_numpy(), f["alpha"].to_numpy(), f["gamma"].to_numpy(), f["fz"].to_numpy(),
                   f["vx"].to_numpy(), f["p"].to_numpy())
    for k in ("fx", "fy", "mz", "mx", "my"):
        assert np.array_equal(f[k].to_numpy(), getattr(res, k))
    assert data.synthetic and "re" not in f.columns      # this tyre has no rolling-radius coefficients


def test_noise_is_seeded_and_of_the_stated_size(rig):
    from tirecli.studies.rig_data import synthetic_rig_data

    tire, noisy = rig
    clean = synthetic_rig_data(tire, "x", noise=0.0)
    again = synthetic_rig_data(tire, "x", noise=0.02, seed=7)
    assert np.array_equal(again.frame["fy"], noisy.frame["fy"])
    for k in ("fx", "fy", "mz"):
        d = noisy.frame[k] - clean.frame[k]
        sigma = 0.02 * np.abs(clean.frame[k]).max()
        assert 0.8 < d.std() / sigma < 1.2    # 410 samples: the estimate is within ~7 % of sigma (1 sigma)
