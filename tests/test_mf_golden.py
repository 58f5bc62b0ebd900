"""Magic Formula against published numbers: the golden rows of magic_formula.md §15.4 (to 1e-6
with the ``teasit`` convention) and the derived checks of §15.5 (with the default convention)."""
import numpy as np
import pytest

from tirecli.models.magic_formula import evaluate
from tirecli.models.magic_formula.mf61 import pure_slip_factors
from tirecli.parameters.mf import load_builtin_tire_data

# kappa, alpha_rad, gamma_rad, fz_n, p_pa, vx_mps, fx_n, fy_n, mz_nm, mx_nm, my_nm (spec §15.4, copied
# from KMoula30/outlap crates/outlap-tire/tests/golden/pacejka_2006_205_60r15/*.csv, CC-BY-SA-4.0 data)
GOLDEN = {
    "fx0": """\
-0.15,0,0,2000,220000,16.67,-2454.789881,-163.6411509,-34.24337069,0,-6.26
0,0,0,2000,220000,16.67,-114.5334541,20.90991048,-5.335080564,0,-6.26
0.03,0,0,2000,220000,16.67,977.4660065,126.1319875,8.965539804,0,-6.26
0.09,0,0,2000,220000,16.67,2191.276563,206.0867675,27.49964628,0,-6.26
0.15,0,0,2000,220000,16.67,2450.690818,191.902705,31.78587536,0,-6.26
0.3,0,0,2000,220000,16.67,2277.776872,134.568265,30.07213503,0,-6.26
-0.15,0,0,4000,220000,16.67,-4837.649514,-167.3415256,-66.91405564,0,-12.52
0,0,0,4000,220000,16.67,-172.0094611,42.00044636,-11.32558474,0,-12.52
0.03,0,0,4000,220000,16.67,2233.419392,157.4861513,22.09031303,0,-12.52
0.09,0,0,4000,220000,16.67,4516.362632,242.9226944,57.60092987,0,-12.52
0.15,0,0,4000,220000,16.67,4839.604625,224.1087646,63.35152795,0,-12.52
0.3,0,0,4000,220000,16.67,4391.07609,155.4577919,58.27506941,0,-12.52""",
    "fy0_mz": """\
0,-0.084,0,2000,220000,16.67,-77.50329094,1779.957807,-21.74256282,0,-6.26
0,0.0105,0,2000,220000,16.67,-111.9493809,-256.041834,-0.9853385911,0,-6.26
0,0.042,0,2000,220000,16.67,-95.30455754,-1007.626856,9.46346945,0,-6.26
0,0.084,0,2000,220000,16.67,-69.47185887,-1639.609431,11.66389292,0,-6.26
0,0.147,0,2000,220000,16.67,-42.776985,-1949.290859,4.798332809,0,-6.26
0,0.21,0,2000,220000,16.67,-27.38732579,-2006.056707,0.01818198794,0,-6.26
0,-0.084,0,4000,220000,16.67,-116.3965535,3217.709141,-74.45864437,0,-12.52
0,0.0105,0,4000,220000,16.67,-168.1286296,-438.816506,3.635828161,0,-12.52
0,0.042,0,4000,220000,16.67,-143.1309805,-1787.245403,40.24745993,0,-12.52
0,0.084,0,4000,220000,16.67,-104.33473,-3016.577643,48.95772197,0,-12.52
0,0.147,0,4000,220000,16.67,-64.24364128,-3655.379973,21.76276893,0,-12.52
0,0.21,0,4000,220000,16.67,-41.13103189,-3770.833167,2.325187217,0,-12.52
0,0,-0.06981317008,4000,220000,16.67,-172.0094611,298.4070726,14.43501152,0,-12.52
0,0.042,-0.06981317008,4000,220000,16.67,-143.1309805,-1536.449936,67.10076447,0,-12.52
0,0.084,-0.06981317008,4000,220000,16.67,-104.33473,-2825.287933,74.4599996,0,-12.52
0,0.147,-0.06981317008,4000,220000,16.67,-64.24364128,-3615.557914,37.84952244,0,-12.52""",
    "combined": """\
-0.25,-0.17,0,4000,220000,16.67,-3563.509474,2203.153893,-39.36321111,0,-12.52
-0.1,0.102,0,4000,220000,16.67,-3228.969873,-2922.957587,-40.55411641,0,-12.52
-0.05,0.136,0,4000,220000,16.67,-1636.029361,-3541.718361,-6.77807309,0,-12.52
0.05,0.068,0,4000,220000,16.67,2484.914109,-2402.289342,59.18035787,0,-12.52
0.1,0.034,0,4000,220000,16.67,4349.523184,-1034.154623,59.66406817,0,-12.52
0.25,0.17,0,4000,220000,16.67,3450.343003,-2000.887769,34.47427631,0,-12.52""",
    "combined_camber": """\
-0.1,0.102,-0.06981317008,4000,220000,16.67,-3228.969873,-2760.248592,-32.59451589,0,-12.52
0.05,0.068,-0.06981317008,4000,220000,16.67,2484.914109,-2235.494474,75.87749138,0,-12.52
-0.1,0.102,0.06981317008,4000,220000,16.67,-3228.969873,-3279.314013,-46.39796357,0,-12.52
0.05,0.068,0.06981317008,4000,220000,16.67,2484.914109,-2655.457264,48.30154784,0,-12.52""",
}
TOL = 1e-6  # N and N m: the print precision of the golden CSVs (spec §15.2)


def rows(block):
    return np.array([[float(x) for x in line.split(",")] for line in GOLDEN[block].splitlines()])


@pytest.fixture(scope="module")
def book():
    return load_builtin_tire_data("pacejka2006-205-60r15").tire()


@pytest.mark.parametrize("block", list(GOLDEN))
def test_golden_rows_teasit(book, block):
    g = rows(block)
    r = evaluate(book, g[:, 0], g[:, 1], g[:, 2], g[:, 3], g[:, 5], g[:, 4], convention="teasit")
    for name, col in (("fx", 6), ("fy", 7), ("mz", 8), ("mx", 9), ("my", 10)):
        err = np.abs(getattr(r, name) - g[:, col])
        assert err.max() <= TOL, f"{block} {name}: largest residual {err.max():.3g} at row {err.argmax()}"


def test_golden_rows_are_convention_sensitive(book):
    """The default convention departs from the teasit data by the amounts of spec §10 (so the
    golden test above checks the convention switches, not only the core equations)."""
    g = np.vstack([rows(b) for b in GOLDEN])
    r = evaluate(book, g[:, 0], g[:, 1], g[:, 2], g[:, 3], g[:, 5], g[:, 4])
    pure_fx = rows("fx0")
    rp = evaluate(book, pure_fx[:, 0], pure_fx[:, 1], pure_fx[:, 2], pure_fx[:, 3], pure_fx[:, 5])
    assert np.abs(rp.fx - pure_fx[:, 6]).max() < 1e-6  # Fx0 at alpha = gamma = 0 agrees (§15.2)
    assert 1.0 < np.abs(r.fx - g[:, 6]).max() < 25.0   # tan(alpha) vs alpha in G_xa (§10: up to 21 N)
    assert 1.0 < np.abs(r.mz - g[:, 8]).max() < 80.0   # camber term of s, trail choices (§10)


@pytest.mark.parametrize("fz, mux, kxk, muy, kya", [
    (2000.0, 1.2285, 38204.2551, -1.0625, -26608.8700),
    (4000.0, 1.2100, 86040.0, -0.9900, -46009.1387),
])
def test_derived_load_dependence(book, fz, mux, kxk, muy, kya):
    f = pure_slip_factors(book, fz)  # default (mfeval) convention
    assert f["fx"]["mu"] == pytest.approx(mux, abs=5e-5)
    assert f["fx"]["K"] == pytest.approx(kxk, abs=5e-5)
    assert f["fy"]["mu"] == pytest.approx(muy, abs=5e-5)
    assert f["fy"]["K"] == pytest.approx(kya, abs=5e-5)


def test_nominal_load_identities(book):
    """At Fz = Fz0, dp = 0: mu_x = PDX1 LMUX and K_xk = Fz0 PKX1 LKX (§15.5), also with scaling."""
    from dataclasses import replace

    t = replace(book, coef={**book.coef, "LMUX": 0.8, "LKX": 1.3})
    f = pure_slip_factors(t, 4000.0)
    assert f["fx"]["mu"] == pytest.approx(1.21 * 0.8, rel=1e-14)
    assert f["fx"]["K"] == pytest.approx(4000.0 * 21.51 * 1.3, rel=1e-14)
