"""mfeval's further outputs (relaxation lengths, slip/carcass/vertical stiffnesses, rolling radius, contact patch).

References are independent hand computations of the published formulas (written out here with ``math``
from the file's coefficients), never the code's own output:

- mfeval ``Solver.calculateRelax`` (Besselink et al. 2010 eqs. 17-19 for MF 6.x; MF-Tyre 5.2 manual
  for PTX/PTY), ``calculateFx0`` (K_xk, 4.E15), ``calculateFy0`` (K_ya, 4.E25), ``calculateRe``,
  ``calculateRhoRl61`` (book A3.3) and ``calculateContactPatch`` (paper eqs. 9, 10; MF 5.2 form);
- its input limits: ``Fz`` clipped to ``FZMAX``, ``gamma`` and ``p`` to their ranges.
"""
import math

import numpy as np
import pandas as pd
import pytest

from tirecli.models.magic_formula import contact, relaxation
from tirecli.models.magic_formula.extras import EXTRA_OUTPUTS, available, evaluate_extras
from tirecli.models.magic_formula.tire import MFTire
from tirecli.parameters.mf import builtin_tire_names, load_builtin_tire_data


def _tyre(name):
    return load_builtin_tire_data(name).tire()


def _clip(x, lo, hi):
    return min(max(x, lo), hi)


def _mfeval_relax(v: dict, version: str, fz: float, gamma: float, p: float | None, rule: str):
    """mfeval's ``calculateRelax`` with its ``Kxk`` and ``Kya`` for one point (plain ``math``)."""
    fz = min(fz, v.get("FZMAX", math.inf))
    gamma = _clip(gamma, v.get("CAMMIN", -math.inf), v.get("CAMMAX", math.inf))
    fz0, lfzo, r0 = v["FNOMIN"], v["LFZO"], v["UNLOADED_RADIUS"]
    fz0p = fz0 * lfzo
    dfz = (fz - fz0p) / fz0p
    if version == "5.2" or p is None:
        dpi = 0.0
    else:
        p = _clip(p, v.get("PRESMIN", -math.inf), v.get("PRESMAX", math.inf))
        dpi = (p - v["NOMPRES"]) / v["NOMPRES"]
    g = lambda k: v.get(k, 0.0)  # noqa: E731
    kxk = fz * (g("PKX1") + g("PKX2") * dfz) * math.exp(g("PKX3") * dfz) * (1 + g("PPX1") * dpi + g("PPX2") * dpi ** 2) * v["LKX"]
    pky4 = 2.0 if version == "5.2" else v["PKY4"]
    kya = (g("PKY1") * fz0p * (1 + g("PPY1") * dpi) * (1 - g("PKY3") * abs(gamma))
           * math.sin(pky4 * math.atan((fz / fz0p) / ((g("PKY2") + g("PKY5") * gamma ** 2) * (1 + g("PPY2") * dpi))))
           * v["LKY"])
    cx = cy = math.nan
    if "LONGITUDINAL_STIFFNESS" in v:
        cx = v["LONGITUDINAL_STIFFNESS"] * (1 + g("PCFX1") * dfz + g("PCFX2") * dfz ** 2) * (1 + g("PCFX3") * dpi)
    if "LATERAL_STIFFNESS" in v:
        cy = v["LATERAL_STIFFNESS"] * (1 + g("PCFY1") * dfz + g("PCFY2") * dfz ** 2) * (1 + g("PCFY3") * dpi)
    if rule == "pt":
        sx = (v["PTX1"] + g("PTX2") * dfz) * math.exp(-g("PTX3") * dfz) * v.get("LSGKP", 1.0) * r0 * fz / fz0
        sy = (v["PTY1"] * math.sin(2 * math.atan(fz / (v["PTY2"] * fz0p))) * (1 - g("PKY3") * abs(gamma)) * r0 * lfzo
              * v.get("LSGAL", 1.0))
    else:
        sx, sy = abs(kxk / cx), abs(kya / cy)
    return {"Kxk": kxk, "Kya": kya, "Cx": cx, "Cy": cy, "sigmax": sx, "sigmay": sy}


CASES = [("mfeval-255-55r20", "version", "stiffness"), ("chrono-185-80r14", "version", "pt"),
         ("externdata-205-60r15", "pt", "pt")]


@pytest.mark.parametrize("name, source, rule", CASES)
def test_relaxation_lengths_follow_mfeval_at_several_loads_pressures_cambers(name, source, rule):
    t = _tyre(name)
    v = t.coef
    fzmax = v.get("FZMAX", 3 * v["FNOMIN"])
    loads = np.array([300.0, 0.5 * v["FNOMIN"], v["FNOMIN"], 1.6 * v["FNOMIN"], fzmax * 1.2])  # the last clipped
    nom = t.nominal_pressure
    pressures = [None] if nom is None else [0.8 * nom, nom, 1.15 * nom, 2.0 * nom]  # 0.8, 2.0: clipped when ranged
    assert relaxation.sigma_source(t, source) == rule
    for p in pressures:
        for gamma in (0.0, 0.03, -0.06, 0.5):  # 0.5 rad beyond the camber range
            got_k = relaxation.slip_stiffness(t, loads, gamma, p)
            got_c = relaxation.carcass_stiffness(t, loads, p)
            got_s = relaxation.relaxation_lengths(t, loads, gamma, p, source=source)
            for i, fz in enumerate(loads):
                ref = _mfeval_relax(v, t.version, float(fz), gamma, p, rule)
                got = {"Kxk": got_k[0][i], "Kya": got_k[1][i], "Cx": got_c[0][i], "Cy": got_c[1][i],
                       "sigmax": got_s[0][i], "sigmay": got_s[1][i]}
                for k, r in ref.items():
                    if math.isnan(r):
                        assert np.isnan(got[k]), (k, fz, p, gamma)
                    else:
                        assert got[k] == pytest.approx(r, rel=1e-12, abs=1e-12), (k, fz, p, gamma)
    # a sanity anchor in numbers: the mfeval sample tyre at its nominal load and pressure
    if name == "mfeval-255-55r20":
        sx, sy = relaxation.relaxation_lengths(t, v["FNOMIN"], 0.0)
        assert 0.2 < sx < 0.6 and 0.3 < sy < 0.8


def test_relaxation_lengths_absent_without_their_coefficients():
    ext, pac = _tyre("externdata-205-60r15"), _tyre("pacejka2006-205-60r15")
    for t in (ext, pac):  # MF 6.1 files without LONGITUDINAL_/LATERAL_STIFFNESS: mfeval's rule gives nothing
        sx, sy = relaxation.relaxation_lengths(t, [2000.0, 4000.0])
        assert np.isnan(sx).all() and np.isnan(sy).all()
        assert not available(t)["sigmax"] and not available(t)["Cx"]
    assert available(ext, "pt")["sigmax"] and not available(pac, "pt")["sigmax"]
    with pytest.raises(ValueError, match="unknown relaxation-length source"):
        relaxation.relaxation_lengths(ext, 4000.0, source="book")


def _re_by_hand(v, fz, kappa, vx, p):
    cz = v["VERTICAL_STIFFNESS"] * (1 + v.get("PFZ1", 0.0) * (p - v["NOMPRES"]) / v["NOMPRES"])
    r0, fz0, v0 = v["UNLOADED_RADIUS"], v["FNOMIN"], v["LONGVL"]
    defl = (fz0 / cz) * (v["DREFF"] * math.atan(v["BREFF"] * fz / fz0) + v["FREFF"] * fz / fz0)
    re, old = r0 * 0.965, r0
    omega = 0.0
    while abs(re - old) > 1e-14:  # mfeval's fixed point (its tolerance 1e-9 tightened)
        old = re
        omega = (kappa * vx + vx) / re
        re = r0 * (v["Q_RE0"] + v.get("Q_V1", 0.0) * (omega * r0 / v0) ** 2) - defl
    return re, omega, cz


def _eval_one(cli, tmp_path, name, row):
    pts = tmp_path / "p.csv"
    pd.DataFrame([row]).to_csv(pts, index=False)
    out = tmp_path / "o.csv"
    code, stdout, err = cli("mf", "eval", name, "--points", pts, "--out", out)
    assert code == 0, err
    return pd.read_csv(out).iloc[0], stdout


def test_mf_eval_extra_columns_by_hand_mf61(cli, tmp_path):
    """Every extra column of mf eval for the MF 6.1 mfeval sample at one point, against the formulas."""
    v = _tyre("mfeval-255-55r20").coef
    row = {"kappa": 0.03, "alpha": 0.02, "gamma": 0.02, "fz": 5000.0, "p": 240000.0, "vx": 20.0}
    r, _ = _eval_one(cli, tmp_path, "mfeval-255-55r20", row)
    names = ["kappa", "alpha", "gamma", "fz", "p", "vx", "fx", "fy", "mz", "mx", "my", *EXTRA_OUTPUTS]
    assert list(r.index) == names  # the forces keep their place; all ten extras given
    ref = _mfeval_relax(v, "6.1", row["fz"], row["gamma"], row["p"], "stiffness")
    re, omega, ncz = _re_by_hand(v, row["fz"], row["kappa"], row["vx"], row["p"])
    ref["re"] = re
    # Cz: the load-deflection quadratic (A3.3) at the row's own forces, Cz = Fz/rho
    r0, fz0 = v["UNLOADED_RADIUS"], v["FNOMIN"]
    q_fz1 = math.sqrt((v["VERTICAL_STIFFNESS"] * r0 / fz0) ** 2 - 4 * v["Q_FZ2"])
    dpi = (row["p"] - v["NOMPRES"]) / v["NOMPRES"]
    ext = (1 + v["Q_V2"] * (r0 / v["LONGVL"]) * abs(omega) - (v["Q_FCX"] * r["fx"] / fz0) ** 2
           - (v["Q_FCY"] * r["fy"] / fz0) ** 2) * (1 + v["PFZ1"] * dpi) * fz0
    x = (-q_fz1 + math.sqrt(q_fz1 ** 2 + 4 * v["Q_FZ2"] * row["fz"] / ext)) / (2 * v["Q_FZ2"])
    ref["Cz"] = row["fz"] / (x * r0)
    ratio = row["fz"] / (ncz * r0)
    ref["a"] = r0 * (v["Q_RA2"] * ratio + v["Q_RA1"] * math.sqrt(ratio))
    ref["b"] = v["WIDTH"] * (v["Q_RB2"] * ratio + v["Q_RB1"] * ratio ** (1 / 3))
    for k in EXTRA_OUTPUTS:
        assert r[k] == pytest.approx(ref[k], rel=1e-10), k
    assert 0.3 < r["sigmax"] < 0.6 and 0.3 < r["sigmay"] < 0.7 and 0.05 < r["a"] < 0.07  # [m], plausible sizes


def test_mf_eval_extra_columns_by_hand_mf52(cli, tmp_path):
    """The MF 5.2 (PAC2002) Chrono tyre at one point: PTX/PTY lengths, mfeval's empirical Q_A1/Q_A2, b = W/2."""
    v = _tyre("chrono-185-80r14").coef
    row = {"kappa": -0.04, "alpha": -0.03, "gamma": -0.02, "fz": 4500.0, "vx": 15.0}
    r, stdout = _eval_one(cli, tmp_path, "chrono-185-80r14", row)
    assert [k for k in EXTRA_OUTPUTS if k in r.index] == ["sigmax", "sigmay", "Kxk", "Kya", "Cz", "a", "b"]
    assert "not written" in stdout and "Cx (needs LONGITUDINAL_STIFFNESS)" in stdout and "re (needs Q_RE0" in stdout
    ref = _mfeval_relax(v, "5.2", row["fz"], row["gamma"], None, "pt")
    r0, fz0 = v["UNLOADED_RADIUS"], v["FNOMIN"]
    y = math.log10(r0 * v["VERTICAL_STIFFNESS"] / fz0)
    q_a1 = -0.0388 * y ** 3 + 0.2509 * y ** 2 - 0.6283 * y + 0.6279
    q_a2 = 1.693 * q_a1 ** 2
    ref["a"] = r0 * (q_a2 * row["fz"] / fz0 + q_a1 * math.sqrt(row["fz"] / fz0))
    ref["b"] = v["WIDTH"] / 2
    ref["Cz"] = v["VERTICAL_STIFFNESS"]  # Q_FZ2 = Q_FCX = Q_FCY = Q_V2 = 0: a linear spring
    for k in ("sigmax", "sigmay", "Kxk", "Kya", "Cz", "a", "b"):
        assert r[k] == pytest.approx(ref[k], rel=1e-10), k
    # PTX1 = 1.9021: sigma_kappa at Fz0 is 1.9021 R0 (0.715 m); here a little more load
    assert 0.7 < r["sigmax"] < 0.9


@pytest.mark.parametrize("name", builtin_tire_names())
def test_extras_finite_over_each_builtin_tyres_ranges(name):
    t = _tyre(name)
    rng = np.random.default_rng(7)
    n = 400
    fz = rng.uniform(0.0, 2.5 * t.coef["FNOMIN"], n)
    fz[:3] = [0.0, 1.0, 50 * t.coef["FNOMIN"]]  # no load, a touch, far above FZMAX
    kappa, alpha, gamma = rng.uniform(-1, 1, n), rng.uniform(-0.5, 0.5, n), rng.uniform(-0.1, 0.1, n)
    vx = rng.uniform(-5.0, 40.0, n)
    out = evaluate_extras(t, kappa, alpha, gamma, fz, vx)
    assert list(out) == [k for k, ok in available(t).items() if ok]
    for k, a in out.items():
        assert a.shape == (n,) and np.isfinite(a).all(), k
    if "sigmax" in out:
        assert (out["sigmax"] >= 0).all() and (out["sigmay"] >= 0).all()


def test_mf62_deflection_solve():
    """MF 6.2's loaded-radius solve: the same deflection as MF 6.1's quadratic when the 6.2 terms are 0;
    with them, the load of the solved deflection equals the target."""
    base = _tyre("mfeval-255-55r20")
    t62 = MFTire({**base.coef}, "6.2", base.side, "t62")
    fz = np.array([500.0, 3000.0, 6752.0, 12000.0])
    fx, fy, omega = np.array([100.0, -2000.0, 3000.0, 0.0]), np.array([-500.0, 1500.0, -4000.0, 8000.0]), 50.0
    rho61, cz61 = contact.deflection(base, fz, fx, fy, omega)
    rho62, cz62 = contact.deflection(t62, fz, fx, fy, omega)
    np.testing.assert_allclose(rho62, rho61, rtol=1e-12)
    np.testing.assert_allclose(cz62, cz61, rtol=1e-12)
    t62b = MFTire({**base.coef, "Q_FCY2": 0.5, "Q_CAM1": 0.3, "Q_CAM2": 0.1, "Q_CAM3": 0.2, "Q_FYS1": 200.0,
                   "Q_FYS2": 50.0, "Q_FYS3": 10.0}, "6.2", base.side, "t62b")
    gamma = np.array([0.0, 0.03, -0.05, 0.08])
    rho, _ = contact.deflection(t62b, fz, fx, fy, omega, gamma)
    from tirecli.models.magic_formula.radius import free_spinning_radius

    r_omega = free_spinning_radius(t62b, omega)
    # invert: find the loaded radius of each rho and check its load
    lo, hi = r_omega - base.coef["UNLOADED_RADIUS"], np.full(4, r_omega)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        f, _ = contact._fz62(t62b, mid, r_omega, gamma, omega, fx, fy, None)
        lo, hi = np.where(f > fz, mid, lo), np.where(f > fz, hi, mid)
    f, rho_check = contact._fz62(t62b, 0.5 * (lo + hi), r_omega, gamma, omega, fx, fy, None)
    np.testing.assert_allclose(f, fz, rtol=1e-9)
    np.testing.assert_allclose(rho, rho_check, rtol=1e-12)


def test_contact_patch_held_at_rim_bottoming():
    t = _tyre("mfeval-255-55r20")
    v = t.coef
    ncz = v["VERTICAL_STIFFNESS"]  # at the nominal pressure
    fz_btm = (v["UNLOADED_RADIUS"] - v["RIM_RADIUS"] - v["BOTTOM_OFFST"]) * ncz
    a, b = contact.contact_patch(t, [fz_btm, 2 * fz_btm, 10 * fz_btm], v["NOMPRES"])
    assert a[1] == a[0] == a[2] and b[1] == b[0]


def test_pac89_has_no_extras(cli, tmp_path):
    from conftest import ROOT

    from tirecli.parameters.mf import read_tire_data

    t = read_tire_data(ROOT / "tests" / "data" / "tir" / "pac89-hmmwv.tir").tire()
    assert not any(available(t).values()) and evaluate_extras(t, 0.0, 0.0, 0.0, 4000.0, 10.0) == {}
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0.05,0.02,0,4000\n")
    code, out, err = cli("mf", "eval", ROOT / "tests" / "data" / "tir" / "pac89-hmmwv.tir", "--points", pts,
                         "--out", tmp_path / "o.csv")
    assert code == 0, err
    assert "sigmax, sigmay, Kxk, Kya, Cx, Cy, Cz, re, a, b (a PAC89 tyre has none of these)" in out
    assert pd.read_csv(tmp_path / "o.csv").columns[-1] == "my"
