"""MCPS against the Magic Formula tyre that is drawn: the gap metric, the calibration to that tyre and
what MCPS cannot follow (docs/models/mcps_tire.md §8). Every number of the calibration is checked
against an independent evaluation: the returned set re-solved with numerics.mcps_stationary and the
Magic Formula evaluated with tirecli.models.magic_formula.evaluate."""
import json
import math

import numpy as np
import pytest

from tirecli.numerics.gaps import curve_gap
from tirecli.numerics.mcps_stationary import solve, solve_sideslip

DEG = math.pi / 180
FZ = 4000.0
KAPPA = np.linspace(0.0, 0.12, 49)          # the drawn grids of Figs. 7-9
ALPHA = np.linspace(0.0, 12 * DEG, 49)


@pytest.fixture(scope="module")
def p():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("sorine2000-mcps").model()


@pytest.fixture(scope="module")
def tyre():
    from tirecli.parameters.mf import load_builtin_tire_data

    return load_builtin_tire_data("externdata-205-60r15").tire()


def mf_eval(tyre, kappa, alpha):
    """The drawn tyre as the study evaluates it: steady state, camber 0, limits off, at LONGVL."""
    from tirecli.models.magic_formula import evaluate

    r = evaluate(tyre, kappa, alpha, 0.0, FZ, tyre.reference_speed, convention="mfeval", limits=False,
                 low_speed=False, outputs=("fx", "fy", "mz"), combined=True)
    return r.fx, r.fy, r.mz


@pytest.fixture(scope="module")
def cal(p, tyre):
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf

    return calibrate_to_mf(p, FZ, lambda k, a: mf_eval(tyre, k, a), KAPPA, ALPHA)


# --------------------------------------------------------------------------- the gap metric


def test_curve_gap_closed_form():
    """reference 2 + cos(2 pi x), model = reference + A sin(2 pi x) + c on 8 points of one period: the
    largest gap is A + c at x = 1/4, the RMS sqrt(A^2/2 + c^2) (discrete orthogonality), the reference
    peak 3; a tie goes to the first point."""
    x = np.arange(8) / 8
    A, c = 0.3, 0.05
    ref = 2 + np.cos(2 * np.pi * x)
    g = curve_gap(x, ref + A * np.sin(2 * np.pi * x) + c, ref)
    assert g.max == pytest.approx(A + c, rel=1e-14) and g.at == 0.25
    assert g.model == pytest.approx(2 + A + c, rel=1e-14) and g.reference == pytest.approx(2, rel=1e-14)
    assert g.rms == pytest.approx(math.sqrt(A**2 / 2 + c**2), rel=1e-14)
    assert g.peak == 3 and g.max_rel == pytest.approx((A + c) / 3, rel=1e-14)
    assert g.rms_rel == pytest.approx(g.rms / 3, rel=1e-14)
    assert g.points == 8 and g.skipped == 0
    assert curve_gap([0, 1, 2], [1, 0, 1], [0, 0, 0]).at == 0
    assert curve_gap(x, ref, ref, peak=-2).max_rel == 0 and curve_gap(x, ref, ref, peak=-2).peak == 2
    assert set(g.as_dict()) == {"max", "at", "model", "reference", "rms", "peak", "max_rel", "rms_rel", "points", "skipped"}


def test_curve_gap_on_the_models_own_abscissa():
    """A model drawn against its own abscissa (e.g. Fy against Fx): a straight line is interpolated
    exactly onto the reference points; reference points outside the model's range are skipped."""
    xm = np.linspace(3.0, -1.0, 9)              # decreasing is fine
    model = 2 * xm + 1
    x = np.array([-2.0, -0.5, 0.0, 1.25, 2.0, 4.0])
    ref = 2 * x + 1 + np.array([9, 0.1, -0.2, 0.05, 0.0, 9])
    g = curve_gap(x, model, ref, model_x=xm)
    assert g.points == 4 and g.skipped == 2
    assert g.max == pytest.approx(0.2, rel=1e-12) and g.at == 0.0
    assert g.rms == pytest.approx(math.sqrt((0.01 + 0.04 + 0.0025) / 4), rel=1e-12)


@pytest.mark.parametrize("args, kw, text", [
    (([0, 1], [0, np.nan], [0, 1]), {}, "not finite"),
    (([0, 1], [0, 1, 2], [0, 1]), {}, "points"),
    (([0, 1], [0, 1], [0, 1]), {"model_x": [0, 0]}, "monotone"),
    (([5, 6], [0, 1], [0, 1]), {"model_x": [0, 1]}, "no point"),
])
def test_curve_gap_refuses_what_it_cannot_compare(args, kw, text):
    with pytest.raises(ValueError, match=text):
        curve_gap(*args, **kw)


def test_default_gaps_of_figs_7_to_9(p, tyre):
    """The default MCPS (complete carcass) against the drawn tyre, as measured when the comparison was
    reviewed: 1168 N in Fx at kappa 6.25 %, 871 N in Fy at 4.25 deg, 63.6 N m in Mz (at 12 deg)."""
    z = np.zeros_like(KAPPA)
    fx = solve(p, FZ, KAPPA, z, z).fx
    st = solve(p, FZ, z, ALPHA, z)
    mfx = mf_eval(tyre, KAPPA, 0.0)[0]
    _, mfy, mmz = mf_eval(tyre, 0.0, ALPHA)
    gx, gy, gz = curve_gap(KAPPA, fx, mfx), curve_gap(ALPHA, st.fy, mfy), curve_gap(ALPHA, st.mz, mmz)
    assert gx.max == pytest.approx(1168.15, abs=0.01) and gx.at == pytest.approx(0.0625)
    assert gy.max == pytest.approx(870.49, abs=0.01) and gy.at / DEG == pytest.approx(4.25)
    assert gz.max == pytest.approx(63.55, abs=0.01) and gz.at / DEG == pytest.approx(12)


# --------------------------------------------------------------------------- the calibration


def test_calibration_meets_the_force_targets(cal, tyre):
    """Fx and Fy of the returned set, re-solved, within 5 % of the Magic Formula peak over the drawn
    range; the reported gaps are those of the re-solved set."""
    q = cal.params
    z = np.zeros_like(KAPPA)
    fx = solve(q, FZ, KAPPA, z, z).fx
    st = solve(q, FZ, z, ALPHA, z)
    mfx = np.asarray(mf_eval(tyre, KAPPA, 0.0)[0])
    mfy = np.asarray(mf_eval(tyre, 0.0, ALPHA)[1])
    assert np.max(np.abs(fx - mfx)) <= 0.05 * np.max(np.abs(mfx))
    assert np.max(np.abs(st.fy - mfy)) <= 0.05 * np.max(np.abs(mfy))
    g = cal.gaps["calibrated"]
    assert g["fx"].max == pytest.approx(np.max(np.abs(fx - mfx)), abs=1e-6)
    assert g["fy"].max == pytest.approx(np.max(np.abs(st.fy - mfy)), abs=1e-6)
    assert g["mz"].rms == pytest.approx(np.sqrt(np.mean((st.mz - np.asarray(mf_eval(tyre, 0.0, ALPHA)[2])) ** 2)), abs=1e-6)
    assert cal.failure is None and cal.carcass == "complete"
    # better than the start set in every channel
    assert all(g[c].max < cal.gaps["start"][c].max for c in ("fx", "fy", "mz"))


def test_calibration_fits_each_models_own_output(cal, tyre):
    """The drawn tyre is asymmetric (Fy = 69.9 N at zero slip); MCPS is symmetric (Fy(0) = 0): the
    gap at alpha = 0 is the Magic Formula's own offset, never hidden by mirroring a curve."""
    fy0 = float(np.asarray(mf_eval(tyre, 0.0, 0.0)[1]))
    assert fy0 == pytest.approx(69.90, abs=0.01) and cal.offsets["fy"] == fy0
    assert cal.curves["calibrated"]["fy"][0] == 0.0
    assert cal.curves["mf"]["fy"][0] == fy0


def test_calibration_mz_peak_position(cal, p, tyre):
    """Mz peaks within 1 deg of the Magic Formula's (found independently on a 0.01 deg grid), and the
    reported peaks are those of the functions."""
    a = np.arange(0.0, 12.0 + 1e-9, 0.01) * DEG
    mz = solve(cal.params, FZ, np.zeros_like(a), a, np.zeros_like(a)).mz
    mmz = np.asarray(mf_eval(tyre, 0.0, a)[2])
    am, af = a[np.argmax(mz)], a[np.argmax(mmz)]
    assert abs(am - af) <= 1 * DEG
    assert cal.peaks["calibrated"]["alpha"] == pytest.approx(am, abs=0.01 * DEG)
    assert cal.peaks["mf"]["alpha"] == pytest.approx(af, abs=0.01 * DEG)
    assert cal.peaks["calibrated"]["mz"] == pytest.approx(mz.max(), abs=1e-3)
    assert cal.peaks["mf"]["mz"] == pytest.approx(mmz.max(), abs=1e-3)


def test_calibration_reports_the_parameters_at_bounds(cal):
    """Every fitted value within 1e-6 of its bound range (log10 for the stiffnesses) is reported at that
    bound with the bound's source; no other is."""
    from tirecli.numerics.mcps_calibrate import FIT_BOUNDS, LATERAL, LONGITUDINAL

    assert set(cal.fitted) == set(LONGITUDINAL) | set(LATERAL)
    for n, f in cal.fitted.items():
        b = FIT_BOUNDS[n]
        v, lo, hi = (np.log10([f.value, b.lo, b.hi]) if b.log else (f.value, b.lo, b.hi))
        side = "lower" if v - lo <= 1e-6 * (hi - lo) else "upper" if hi - v <= 1e-6 * (hi - lo) else None
        assert f.at_bound == side, n
        assert b.lo <= f.value <= b.hi * (1 + 1e-12)
        assert (f.source is None) == (side is None)
        if side:
            assert f.source.split(":")[0] in ("paper", "physics", "tirecli")
    assert [f.name for f in cal.at_bound()] == [n for n, f in cal.fitted.items() if f.at_bound]
    assert cal.at_bound()  # this tyre drives some parameters onto their bounds (docs §8 names them)
    d = cal.as_dict()
    assert d["at_bound"] == [f.name for f in cal.at_bound()]
    json.dumps(d)  # plain numbers: run.json-ready


def test_what_mcps_cannot_follow(cal, tyre):
    """The Magic Formula's Mz changes sign inside the drawn range; the calibrated MCPS keeps its sign
    there, and the gap past the sign change is reported."""
    from scipy.optimize import brentq

    a0 = brentq(lambda a: float(np.asarray(mf_eval(tyre, 0.0, a)[2])), 5 * DEG, 10 * DEG, xtol=1e-12)
    sc = cal.sign_change
    assert sc["mf"] == pytest.approx(a0, abs=1e-9) and sc["calibrated"] is None
    assert np.all(cal.curves["calibrated"]["mz"][1:] > 0)
    past = ALPHA > a0
    assert sc["beyond"].points == np.count_nonzero(past)
    assert sc["beyond"].max == pytest.approx(np.max(np.abs(cal.curves["calibrated"]["mz"] - cal.curves["mf"]["mz"])[past]))
    assert sc["fitted_up_to"] < a0 < sc["fitted_up_to"] + (ALPHA[1] - ALPHA[0])


def test_calibration_is_deterministic(cal, p, tyre):
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf

    again = calibrate_to_mf(p, FZ, lambda k, a: mf_eval(tyre, k, a), KAPPA, ALPHA)
    assert json.dumps(again.as_dict(), sort_keys=True) == json.dumps(cal.as_dict(), sort_keys=True)
    assert again.params == cal.params
    for s in cal.curves:
        for c in cal.curves[s]:
            assert np.array_equal(again.curves[s][c], cal.curves[s][c])


def test_calibration_refuses_a_curve_it_cannot_evaluate(p):
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf

    def nan_mf(k, a):
        k, a = np.broadcast_arrays(np.asarray(k, dtype=float), np.asarray(a, dtype=float))
        return np.zeros_like(k), np.full(k.shape, np.nan), np.zeros_like(k)

    with pytest.raises(ValueError, match="fy curve is not finite"):
        calibrate_to_mf(p, FZ, nan_mf, KAPPA[:5], ALPHA[:5])


# --------------------------------------------------------------------------- model facts the calibration rests on


def test_sideslip_fixed_point_matches_the_general_solver(p):
    """solve_sideslip (the twist-only fixed point the fit evaluates) is the complete model of solve()."""
    a = np.concatenate([ALPHA, -ALPHA[1:7], np.radians([20, 45, 80])])
    for q in (p, p.with_values(r_y=1.2e8, mu_y=0.7, alpha_y=1.5, beta_y=1.02, c_Mz=0.97, k_delta=1600)):
        s1 = solve(q, FZ, np.zeros_like(a), a, np.zeros_like(a), tol=1e-13)
        s2 = solve_sideslip(q, FZ, a, tol=1e-13)
        assert s1.converged.all() and s2.converged.all()
        for c, tol in (("fx", 1e-7), ("fy", 1e-7), ("mz", 1e-8), ("x", 1e-12), ("y", 1e-12), ("delta", 1e-12)):
            assert np.max(np.abs(getattr(s1, c) - getattr(s2, c))) <= tol, c


def test_stationary_curves_depend_on_the_patch_length_only_through_the_trail(p):
    """l -> lam l, r -> r/lam^2, c_Mz -> c_Mz/lam leaves every stationary Fx, Fy, Mz without yaw
    unchanged (pure and combined slip, both carcasses): l cannot be calibrated from these curves."""
    k = np.array([0.0, 0.03, -0.05, 0.1, 0.02, 0.0])
    a = np.radians([3, 0, 5, 2, -8, 12])
    for carcass in ("complete", "rigid"):
        ref = solve(p, 3000, k, a, np.zeros_like(k), carcass=carcass, tol=1e-13)
        for lam in (0.7, 1.4):
            q = p.with_patch_length(lam * p.l_ref)
            assert q.l_ref == pytest.approx(lam * p.l_ref) and q.c_Mz == pytest.approx(p.c_Mz / lam)
            st = solve(q, 3000, k, a, np.zeros_like(k), carcass=carcass, tol=1e-13)
            for c in ("fx", "fy", "mz"):
                assert np.max(np.abs(getattr(st, c) - getattr(ref, c))) < 1e-8, (carcass, lam, c)
    # ... but the curvature response does change
    c0 = solve(p, 3000, [0.0], [0.0], [0.05]).fy[0]
    assert abs(solve(p.with_patch_length(1.4 * p.l_ref), 3000, [0.0], [0.0], [0.05]).fy[0] - c0) > 1.0


@pytest.mark.parametrize("alpha_y, beta_y", [(1.5, 1.5), (2.0, 1.9), (3.0, 2.5), (1.514, 1.017), (3.0, 1.5), (5.0, 1.6)])
def test_large_slip_sign_of_the_aligning_torque(p, alpha_y, beta_y):
    """At large slip angles the force excess of the overshoot sits at the leading edge: the force centroid
    tends to F'k/(2 K' tan alpha) [(alpha_y-1)^2/(beta_y-1) - alpha_y^2/beta_y] ahead of the centre, so
    Mz < 0 there iff alpha_y^2 - 2 alpha_y beta_y + beta_y > 0; without that the torque keeps its sign."""
    q = p.with_values(alpha_y=alpha_y, beta_y=beta_y)
    a = np.radians(89.0)
    st = solve(q, FZ, [0.0], [a], [0.0], carcass="rigid")
    negative = alpha_y**2 - 2 * alpha_y * beta_y + beta_y > 0
    assert (st.mz[0] < 0) == negative
    if negative:  # -c_Mz mu_y Fz times the limit of the lever arm, to the leading order in 1/tan(alpha)
        pa = q.patch(FZ)
        Kp, Fk = q.w * q.r_y, q.mu_y * pa.P * q.w
        B = (alpha_y - 1) ** 2 / (beta_y - 1) - alpha_y**2 / beta_y
        assert st.mz[0] == pytest.approx(-q.c_Mz * q.mu_y * FZ * Fk / (2 * Kp * math.tan(a)) * B, rel=0.05)


# --------------------------------------------------------------------------- the paper's side-force axis, the study's gaps

ALPHA_FY = -ALPHA[::-1]                     # Fig. 8 draws Fy at alpha <= 0 against -alpha (the paper's "-delta")


def test_fig8_gap_at_negative_slip_angles(p, tyre):
    """The default MCPS against the drawn tyre where Fig. 8 draws it (alpha_s <= 0, each model's own Fy):
    the reference values of docs §11, computed here from the model functions directly."""
    z = np.zeros_like(ALPHA_FY)
    fy = solve(p, FZ, z, ALPHA_FY, z, tol=1e-12).fy
    mfy = np.asarray(mf_eval(tyre, 0.0, ALPHA_FY)[1])
    d = fy - mfy
    i = int(np.argmax(np.abs(d)))
    assert abs(d[i]) == pytest.approx(922.15, abs=0.01) and ALPHA_FY[i] / DEG == pytest.approx(-4.0)
    assert np.sqrt(np.mean(d**2)) == pytest.approx(571.84, abs=0.01)
    assert mfy[-1] == pytest.approx(69.90, abs=0.01) and fy[-1] == 0.0  # the offset is drawn, never mirrored away
    assert np.max(np.abs(mfy + np.asarray(mf_eval(tyre, 0.0, -ALPHA_FY)[1]))) > 100  # the tyre is not odd


@pytest.fixture(scope="module")
def cal_fy(p, tyre):
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf

    return calibrate_to_mf(p, FZ, lambda k, a: mf_eval(tyre, k, a), KAPPA, ALPHA, alpha_fy=ALPHA_FY)


def test_calibration_on_the_drawn_side_force(cal_fy, tyre):
    """With Fy fitted where Fig. 8 draws it: the targets hold for the re-solved set (Fx, Fy within 5 % of the
    peak; Mz peak within 1 deg), and the reported Fy gap is over alpha_fy."""
    q = cal_fy.params
    z = np.zeros_like(ALPHA_FY)
    fy = solve(q, FZ, z, ALPHA_FY, z).fy
    mfy = np.asarray(mf_eval(tyre, 0.0, ALPHA_FY)[1])
    assert cal_fy.gaps["calibrated"]["fy"].max == pytest.approx(np.max(np.abs(fy - mfy)), abs=1e-6)
    assert np.max(np.abs(fy - mfy)) <= 0.05 * np.max(np.abs(mfy))
    assert cal_fy.gaps["calibrated"]["fx"].max_rel <= 0.05
    assert abs(cal_fy.peaks["calibrated"]["alpha"] - cal_fy.peaks["mf"]["alpha"]) <= 1 * DEG
    assert cal_fy.fit["points"]["fy"] == ALPHA_FY.size and np.array_equal(cal_fy.alpha_fy, ALPHA_FY)


def test_study_gaps_are_the_drawn_curves(p, tyre):
    """stationary_gaps on a small frame: Fig. 8 compares the points with alpha <= 0, Fig. 9 those with
    alpha >= 0, each by max/at/RMS computed here with numpy; Fig. 11 against the Magic Formula line at 0."""
    import pandas as pd

    from tirecli.studies.mcps.gaps import calibration_grids, stationary_gaps

    a = np.radians([-6.0, -3.0, 0.0, 3.0, 6.0])
    z = np.zeros_like(a)
    st = solve(p, FZ, z, a, z)
    _, mfy, mmz = (np.asarray(v) for v in mf_eval(tyre, 0.0, a))
    rows = lambda model, fy, mz: pd.DataFrame({"model": model, "carcass": "complete" if model == "mcps" else "",  # noqa: E731
                                               "calibrated": False, "family": "alpha", "fz": FZ, "kappa": 0.0,
                                               "alpha": a, "phi": 0.0, "fx": 0.0, "fy": fy, "mz": mz})
    df = pd.concat([rows("mcps", st.fy, st.mz), rows("mf", mfy, mmz)], ignore_index=True)
    g = stationary_gaps(df)
    f8, f9 = g["mcps-fig8"]["4000 N"]["complete"], g["mcps-fig9"]["4000 N"]["complete"]
    neg, pos = a <= 0, a >= 0
    d8, d9 = (st.fy - mfy)[neg], (st.mz - mmz)[pos]
    assert f8["fy_points"] == 3 and f8["fy_max_N"] == pytest.approx(np.max(np.abs(d8)), abs=1e-9)
    assert f8["fy_at_rad"] == a[neg][np.argmax(np.abs(d8))]
    assert f9["mz_rms_Nm"] == pytest.approx(np.sqrt(np.mean(d9**2)), abs=1e-9)
    assert "mcps-fig7" not in g
    grids = calibration_grids([("alpha", z, a, z)])
    assert np.array_equal(grids["alpha_fy"], a[neg]) and np.array_equal(grids["alpha"], a[pos])
    assert grids["kappa"].size == 49
