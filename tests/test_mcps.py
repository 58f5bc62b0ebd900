"""MCPS tire model (Sorine & Szymanski 2000): friction laws, slider, standstill, rolling tire, complete
model. Reference values: docs/models/mcps_tire.md (§3-§7, §11)."""
import math

import numpy as np
import pytest

from tirecli.models.mcps import law as L
from tirecli.models.mcps import tire as T
from tirecli.numerics import mcps_stationary as S
from tirecli.numerics import mcps_transient as TR

DEG = math.pi / 180


@pytest.fixture(scope="module")
def p():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("sorine2000-mcps").model()


@pytest.fixture(scope="module")
def slider_law(p):
    return p.slider_law(p.patch(4000).P)


# --------------------------------------------------------------------------- laws (§2-§3)


def test_coulomb_maximal_dissipation():
    """Eq. (2): f on the ellipse |F_k^-1 f| = 1, f . du = |F_k du| and no admissible force dissipates more."""
    Fk = np.array([20.0, 12.0])
    rng = np.random.default_rng(0)
    du = rng.normal(size=(50, 2))
    f = L.coulomb(du, Fk)
    assert np.allclose(np.hypot(f[:, 0] / Fk[0], f[:, 1] / Fk[1]), 1.0, rtol=1e-13)
    assert np.allclose(np.sum(f * du, axis=1), np.hypot(Fk[0] * du[:, 0], Fk[1] * du[:, 1]), rtol=1e-13)
    th = np.linspace(0, 2 * np.pi, 721)
    ring = np.stack([Fk[0] * np.cos(th), Fk[1] * np.sin(th)], axis=-1)          # the whole boundary of C
    assert np.all(np.sum(f * du, axis=1) >= (du @ ring.T).max(axis=1) - 1e-9)
    # not collinear with du unless along a principal axis
    assert abs(f[0, 0] * du[0, 1] - f[0, 1] * du[0, 0]) > 1e-6
    assert np.allclose(L.coulomb([[0.0, 0.0]], Fk), 0.0)


@pytest.mark.parametrize("order", ["first", "second"])
def test_coulomb_level_in_six_directions(order):
    """For a fixed sliding direction the differential laws tend to the Coulomb force (2) (docs §3.2)."""
    K, Fk = [5000.0, 3500.0], [19.8, 18.7]
    lw = L.first_order(K, Fk, 0.35, 0.187) if order == "first" else L.second_order(K, Fk, [3, 2.5], [1.5, 1.8], 0.35, 0.187, 3, 1.5)
    for th in np.linspace(0, np.pi, 6, endpoint=False) + 0.1:
        d = np.array([math.cos(th), math.sin(th)])
        F, M = L.step(np.zeros((lw.nb, 2)), np.zeros(lw.nbz), 5.0 * d, 0.0, 0.0, lw)   # 5 m of sliding
        f, _ = L.output(F, M, lw)
        assert np.allclose(f, L.coulomb(d, Fk), rtol=1e-11, atol=0)


def test_small_deformation_stiffness_and_first_order_limit():
    """From rest df = K du (both laws); the second-order law with alpha = beta is the first-order law."""
    K, Fk = np.array([5000.0, 3500.0]), np.array([19.8, 18.7])
    two = L.second_order(K, Fk, [2.0, 2.0], [2.0, 2.0], 0.35, 0.187, 2.0, 2.0)
    one = L.first_order(K, Fk, 0.35, 0.187)
    for lw in (one, two):
        du = np.array([1e-9, -2e-9])
        F, M = L.step(np.zeros((lw.nb, 2)), np.zeros(lw.nbz), du, 1e-9, 0.0, lw)
        f, m = L.output(F, M, lw)
        assert np.allclose(f / du, K, rtol=1e-6)
        assert m / 1e-9 == pytest.approx(0.35, rel=1e-6)
    rng = np.random.default_rng(3)
    F1, M1 = np.zeros((1, 2)), np.zeros(1)
    F2, M2 = np.zeros((2, 2)), np.zeros(2)
    for _ in range(30):
        du = rng.normal(size=2) * 5e-3
        dp = rng.normal() * 0.3
        F1, M1 = L.step(F1, M1, du, dp, 0.0, one)
        F2, M2 = L.step(F2, M2, du, dp, 0.0, two)
        assert np.allclose(L.output(F1, M1, one)[0], L.output(F2, M2, two)[0], rtol=1e-10, atol=1e-12)
        assert L.output(F1, M1, one)[1] == pytest.approx(L.output(F2, M2, two)[1], rel=1e-10, abs=1e-12)


@pytest.mark.parametrize("ab,peak", [((3, 1.5), 4 / 3), ((2, 1.5), 1.0370), ((2.5, 1.5), 1.1689), ((4, 1.5), 1.6921),
                                     ((3, 2), 1.0625), ((1.5, 1.5), 1.0), ((1.5, 3.0), 1.0)])
def test_overshoot_only_when_alpha_exceeds_beta(ab, peak):
    """1-D monotone response g(p) (docs §3.2): overshoot iff alpha > beta, with the printed peaks; the
    exact steps reproduce the closed form."""
    a, b = ab
    K, Fk = 5000.0, 19.8
    lw = L.second_order([K, K], [Fk, Fk], [a, a], [b, b], 1.0, 1.0, 3, 1.5)
    path = np.linspace(0, 40 * Fk / K, 801)
    F, M = np.zeros((2, 2)), np.zeros(2)
    g = [0.0]
    for dp in np.diff(path):
        F, M = L.step(F, M, np.array([dp, 0.0]), 0.0, 0.0, lw)
        g.append(L.output(F, M, lw)[0][0] / Fk)
    g = np.array(g)
    assert np.allclose(g, L.path_response(path, a, b, K, Fk), atol=1e-12)
    assert g.max() == pytest.approx(peak, abs=2e-4)
    ps, gp = L.overshoot_peak(a, b, K, Fk)
    if a > b:
        assert gp == pytest.approx(peak, abs=1e-4) and ps > 4 * Fk / K
        assert 2 * gp - 1 > gp  # a reversal from saturation overshoots more
    else:
        assert gp == 1.0 and np.all(np.diff(g) >= -1e-15)


def test_exact_step_matches_a_tight_reference_with_the_frame_term():
    """The closed-form 2 x 2 exponential against DOP853 at rtol 1e-13 (random states, rates, frame rotation)."""
    from scipy.integrate import solve_ivp

    lw = L.second_order([5000, 3500], [19.8, 18.7], [3, 2.5], [1.5, 1.8], 0.35, 0.187, 3, 1.5)
    rng = np.random.default_rng(1)
    for _ in range(5):
        F0, M0 = rng.normal(size=(2, 2)) * 10, rng.normal(size=2) * 0.1
        du = rng.normal(size=2) * 0.01 * 10 ** rng.uniform(-4, 0)
        dth, dps = rng.normal() * 10 ** rng.uniform(-3, 1), rng.normal() * 0.5

        def f(t, x):
            return L.rhs(t, x, (du[0], du[1], dps, dth), lw)

        ref = solve_ivp(f, (0, 1), np.r_[F0.ravel(), M0], method="DOP853", rtol=1e-13, atol=1e-14).y[:, -1]
        F1, M1 = L.step(F0, M0, du, dps, dth, lw)
        assert np.max(np.abs(F1.ravel() - ref[:4])) < 1e-9
        assert np.max(np.abs(M1 - ref[4:])) < 1e-12


def test_rotating_frame_level_stays_above_coulomb():
    """Sliding while the frame turns: the steady level exceeds F_k (docs §3.2, isotropic formula)."""
    K, Fk, a, b = 5000.0, 19.8, 3.0, 1.5
    lw = L.second_order([K, K], [Fk, Fk], [a, a], [b, b], 1.0, 1.0, 3, 1.5)
    chi = 8.0
    F, M = np.zeros((2, 2)), np.zeros(2)
    for _ in range(4000):  # slide along y while the frame turns: K |du| / (F_k |dtheta|) = chi
        F, M = L.step(F, M, np.array([0.0, 1e-4]), 0.0, K * 1e-4 / (Fk * chi), lw)
    f, _ = L.output(F, M, lw)
    nu1, nu2 = b * chi / a, (b - 1) * chi / (a - 1)
    assert f[1] / Fk == pytest.approx(1 - a / (1 + nu1**2) + (a - 1) / (1 + nu2**2), rel=1e-9)
    assert f[1] > Fk


# --------------------------------------------------------------------------- slider (Fig. 3)


def test_slider_loop_reference_values_and_rate_independence(p, slider_law):
    lw = slider_law
    Fk, K = lw.Fk[0], lw.K[0]
    A, Psi = 8 * Fk / K, 8 * lw.Mkz / lw.Sz
    ph = np.linspace(0, 2, 2 * 800 + 1)
    ux, psi = A * np.sin(2 * np.pi * ph), Psi * np.sin(2 * np.pi * ph)
    f, m = TR.simulate_slider(lw, ux, 0 * ux, psi)
    g, n = TR.integrate_slider_in_time(lw, A, Psi, 0.5, ph)   # another period, integrated in time
    assert np.max(np.abs(g - f)) <= 1e-6 and np.max(np.abs(n - m)) <= 1e-9
    first = ph <= 0.25
    assert f[first, 0].max() == pytest.approx(26.37, abs=0.01)
    assert m[first].max() == pytest.approx(0.2491, abs=1e-4)
    sec = ph >= 1
    assert f[sec, 0].max() == pytest.approx(32.50, abs=0.01) and f[sec, 0].min() == pytest.approx(-32.50, abs=0.01)
    assert f[sec, 0].max() < 5 / 3 * Fk


# --------------------------------------------------------------------------- standstill (§5)


@pytest.mark.parametrize("frame,refs", [(True, (-18.837, -84.294, -147.330)), (False, (-18.837, -84.311, -147.434))])
def test_standstill_first_loading_and_yaw_stiffness(p, frame, refs):
    pa, lw = p.patch(4000), p.patch_law(4000)
    xi, w = TR.gauss_patch(pa.l, 24)
    psi = np.array([0.0, 1e-3, 0.01, 0.05, 0.1])
    r = TR.simulate_standstill(lw, p.c_Mz, psi, psi, xi, w, frame_term=frame)
    assert -r["mz"][1] / 1e-3 == pytest.approx(1932.08, abs=0.01)
    assert p.stiffnesses(4000)["C_z"] == pytest.approx(1937.54, abs=0.01)
    assert np.allclose(r["mz"][2:], refs, atol=1e-3)
    assert np.allclose(r["fx"], 0.0, atol=1e-9) and np.allclose(r["fy"], 0.0, atol=1e-9)  # odd in xi


def test_standstill_quadrature_is_converged(p):
    pa, lw = p.patch(4000), p.patch_law(4000)
    t, psi, leg = TR.triangle_yaw(0.45, 1.0, 1, 100)
    res = [TR.simulate_standstill(lw, p.c_Mz, t, psi, *TR.gauss_patch(pa.l, n))["mz"] for n in (8, 16, 32)]
    assert np.max(np.abs(res[1] - res[2])) < 1e-8 and np.max(np.abs(res[0] - res[2])) < 1e-4


@pytest.mark.parametrize("A,at_minus_A,mx,psi_mx", [(0.45, 301.92, 329.28, 0.14), (math.pi / 4, 265.16, 347.26, -0.23)])
def test_standstill_yaw_cycle(p, A, at_minus_A, mx, psi_mx):
    pa, lw = p.patch(4000), p.patch_law(4000)
    t, psi, leg = TR.triangle_yaw(A, 1.0, 1, 800)
    assert np.allclose(psi[[np.flatnonzero(leg == k)[-1] for k in range(3)]], [A, -A, A])
    xi, w = TR.gauss_patch(pa.l, 24)
    g = np.linspace(-pa.l / 2, pa.l / 2, 81)
    r = TR.simulate_standstill(lw, p.c_Mz, t, psi, xi, w, g)
    assert r["mz"][np.flatnonzero(leg == 1)[-1]] == pytest.approx(at_minus_A, abs=0.01)
    i = int(np.argmax(np.abs(r["mz"])))
    assert abs(r["mz"][i]) == pytest.approx(mx, abs=0.01) and psi[i] == pytest.approx(psi_mx, abs=0.01)
    assert leg[i] == 2
    assert np.max(np.abs(r["fy_grid"] + r["fy_grid"][:, ::-1])) < 1e-9 * lw.Fk[1]
    assert np.abs(r["fy_grid"]).max() / lw.Fk[1] == pytest.approx(1.59 if A == 0.45 else 1.63, abs=0.01)


@pytest.mark.parametrize("frame,ref", [(True, 249.995), (False, 229.500)])
def test_asymptotic_torque(p, frame, ref):
    """Eq. (12) without the frame term; above it with the term; a long monotone yaw tends to both."""
    from scipy.integrate import quad

    pa, lw = p.patch(4000), p.patch_law(4000)
    v = TR.asymptotic_standstill_torque(lw, pa.l, p.c_Mz, frame)
    assert v == pytest.approx(ref, abs=1e-3)
    if not frame:
        assert v == pytest.approx(p.stiffnesses(4000)["Mz_inf"], rel=1e-12)
    else:  # the Gauss rule against adaptive quadrature of the same integrand
        def fy(x):
            n = lw.Fk[1] * x
            P, Q = n * lw.g[:, 0], n * lw.g[:, 1]
            return x * float(lw.sigma @ (P * lw.h[:, 1] * x / (P * Q + 1)))

        ad = pa.l * float(lw.sigz @ (lw.hz / lw.gz)) + 2 * quad(fy, 0, pa.l / 2, epsabs=1e-13, epsrel=1e-13)[0]
        assert v == pytest.approx(ad, rel=1e-12)
    psi = np.linspace(0, 20, 2001)
    r = TR.simulate_standstill(lw, p.c_Mz, psi, psi, *TR.gauss_patch(pa.l, 24), frame_term=frame)
    assert -r["mz"][-1] == pytest.approx(ref, abs=0.1)


# --------------------------------------------------------------------------- rolling, solid carcass (§6)


def test_small_argument_series_are_continuous_and_exact():
    from fractions import Fraction

    def exact(z):  # f1(z)/z and f2(z)/z from their series in exact rationals
        z = Fraction(z)
        f1 = sum((-1) ** (j + 1) * z ** (j - 1) / math.factorial(j + 1) for j in range(1, 30))
        f2 = sum((-1) ** j * j * z ** (j - 1) / (2 * math.factorial(j + 2)) for j in range(1, 30))
        return float(f1), float(f2)

    for z in (0.0, 1e-12, 1e-6, 1e-4, 0.01, 0.0499999, 0.05, 0.0500001, 0.2, 1.0):
        e1, e2 = exact(z)
        assert T.f1z(z) == pytest.approx(e1, rel=1e-14)
        assert T.f2z(z) == pytest.approx(e2, rel=1e-12)


def test_stiffness_table(p):
    """Numerical slopes of the stationary patch (14) reproduce the table of docs §6 to 1e-7."""
    st = p.stiffnesses(4000)
    assert (st["D_xsigma"], st["D_yalpha"], st["D_zalpha"], st["D_yphi"], st["D_zphi"]) == pytest.approx(
        (63700, 44590, 1040.43, 1040.43, 62.80), abs=0.01)
    h = 1e-6

    def slope(k, a, c, which):
        r = S.solve(p, 4000, [k * h, 2 * k * h], [a * h, 2 * a * h], [c * h, 2 * c * h], carcass="rigid")
        v = getattr(r, which)
        return 2 * v[0] / h - v[1] / (2 * h)  # Richardson: the O(h) term cancels

    assert slope(1, 0, 0, "fx") == pytest.approx(st["D_xsigma"], rel=1e-7)
    assert -slope(0, 1, 0, "fy") == pytest.approx(st["D_yalpha"], rel=1e-7)
    assert slope(0, 1, 0, "mz") == pytest.approx(st["D_zalpha"], rel=1e-7)
    assert -slope(0, 0, 1, "fy") == pytest.approx(st["D_yphi"], rel=1e-7)
    assert -slope(0, 0, 1, "mz") == pytest.approx(st["D_zphi"], rel=1e-7)


def test_pure_slip_closed_form_and_reference_values(p):
    k = np.array([0.01, 0.05, 0.1, 0.12, 1.0, -0.05, -0.5])
    fx = T.pure_longitudinal_fx(k, p, 4000)
    assert np.allclose(fx[:5], [586.79, 2177.23, 3176.78, 3410.85, 3987.57], atol=0.01)
    assert np.all(np.sign(fx) == np.sign(k))
    for carcass in ("rigid", "complete"):  # the carcass does not act in pure longitudinal slip
        r = S.solve(p, 4000, k, 0 * k, 0 * k, carcass=carcass)
        assert np.allclose(r.fx, fx, atol=1e-7) and np.allclose(r.fy, 0, atol=1e-9)


def test_rigid_sideslip_reference_values(p):
    a = np.radians([4, 12, 20, 21.2])
    r = S.solve(p, 4000, 0 * a, a, 0 * a, carcass="rigid")
    assert np.allclose(-r.fy, [2177.39, 3634.41, 3868.41, 3870.6], atol=0.05)
    assert np.allclose(r.mz[1:3], [41.65, 22.69], atol=0.01)


def test_stationary_curves_do_not_depend_on_speed(p):
    k = np.array([0.05, 0.0, 0.03, 0.0, -0.08])
    a = np.array([0.0, 0.05, 0.03, 0.0, 0.04])
    c = np.array([0.0, 0.0, 0.0, 0.05, 0.02])
    runs = [S.solve(p, 4000, k, a, c, speed=V, tol=1e-13) for V in (5, 20, 40)]
    for r in runs[1:]:
        for name in ("fx", "fy", "mz"):
            assert np.max(np.abs(getattr(r, name) - getattr(runs[0], name))) < 1e-9


def test_yaw_integration_converges(p):
    """The RK4 patch integration with a yaw rate (split where the lateral slip vanishes) against a
    finer grid: converged to 1e-6 N at the default resolution, even at large curvatures."""
    law, l = p.patch_law(2000), p.patch(2000).l
    sx, sy, ph = np.array([0.0, 0.02, -0.01]), np.array([0.0, 0.01, -0.003]), np.array([0.1, 2.0, 5.0])
    ref = T.stationary_linear(sx, sy, ph, law, l, steps=2000)
    a = T.stationary_linear(sx, sy, ph, law, l)
    b = T.stationary_linear(sx, sy, ph, law, l, steps=16)
    for x, y, z in zip(a, b, ref):
        assert np.max(np.abs(x - z)) < 1e-6
    for x, y, z in zip(a[:2], b[:2], ref[:2]):  # forces and moments (the torsion is uniform and exact)
        assert np.max(np.abs(y - z)) > 100 * max(np.max(np.abs(x - z)), 1e-12)  # the coarse grid is worse
    # a vanishing curvature is the uniform closed form
    u = T.stationary_uniform(np.stack([sx, sy], -1), 0 * sx, law, l)
    z = T.stationary_linear(sx, sy, 0 * ph, law, l)
    assert all(np.allclose(x, y, rtol=1e-9, atol=1e-9) for x, y in zip(u, z))


def test_no_nan_at_zero_slip(p):
    r = S.solve(p, 4000, [0.0], [0.0], [0.0])
    assert (r.fx[0], r.fy[0], r.mz[0], r.x[0], r.y[0], r.delta[0]) == (0.0,) * 6
    f0, f1, m0 = T.stationary_uniform(np.zeros((3, 2)), np.zeros(3), p.patch_law(4000), 0.14)
    assert np.all(np.isfinite(f0)) and np.all(f0 == 0) and np.all(m0 == 0)
    run = TR.simulate_rolling(p, 4000, 10.0, 0.0, 10.0, 0.0, 0.2, cells=20)
    assert np.all(run.fy == 0) and np.all(np.isfinite(run.fx))


# --------------------------------------------------------------------------- complete model (§7)


def test_complete_model_stiffnesses_eq20(p):
    h = 1e-5
    r = S.solve(p, 4000, [0, 0], [h, 2 * h], [0, 0], tol=1e-14)
    dy = -(2 * r.fy[0] / h - r.fy[1] / (2 * h))
    dz = 2 * r.mz[0] / h - r.mz[1] / (2 * h)
    st = p.stiffnesses(4000)
    assert dy == pytest.approx(36909.60, abs=0.01) and dy == pytest.approx(st["D_yalphaF"], rel=1e-8)
    assert dz == pytest.approx(861.22, abs=0.01) and dz == pytest.approx(st["D_zalphaF"], rel=1e-8)
    # curvature: linear theory of docs §7 (1504.0 N m, 51.98 N m^2 at 4000 N)
    r = S.solve(p, 4000, [0, 0], [0, 0], [h, 2 * h], tol=1e-14)
    assert -(2 * r.fy[0] / h - r.fy[1] / (2 * h)) == pytest.approx(1504.0, abs=0.05)
    assert -(2 * r.mz[0] / h - r.mz[1] / (2 * h)) == pytest.approx(51.98, abs=0.005)


def test_complete_model_reference_values(p):
    a = np.radians([1, 2, 4, 12])
    r = S.solve(p, 4000, 0 * a, a, 0 * a)
    assert np.all(r.converged) and np.all(r.residual < 1e-10)
    assert np.allclose(r.fy, [-606.949, -1141.538, -2009.78, -3600.32], atol=0.005)
    assert np.allclose(r.mz, [13.5854, 24.4155, 38.859, 41.811], atol=0.001)
    assert r.fx[0] == pytest.approx(-0.87, abs=0.005)
    r = S.solve(p, 4000, [0.0, -0.05, 0.0, 0.05], np.radians([-2, -4, -4, -4]), 0)
    expect = [(-2.68, 1141.54, -24.42), (-1911.33, 1990.82, -17.54), (-6.22, 2009.78, -38.86), (1858.81, 1723.95, -47.15)]
    for i, e in enumerate(expect):
        assert (r.fx[i], r.fy[i], r.mz[i]) == pytest.approx(e, abs=0.01)
    # a positive slip angle mirrors Fy and Mz
    m = S.solve(p, 4000, [-0.05], np.radians([4]), 0)
    assert (m.fx[0], m.fy[0], m.mz[0]) == pytest.approx((r.fx[1], -r.fy[1], -r.mz[1]), abs=1e-7)


def test_curvature_complete_below_linear_at_2000(p):
    phi = np.array([0.1])
    r = S.solve(p, 2000, [0.0], [0.0], phi, carcass="rigid")
    assert (r.fy[0], r.mz[0]) == pytest.approx((-36.23, -3.076), abs=(0.01))
    c = S.solve(p, 2000, [0.0], [0.0], phi)
    st = p.stiffnesses(2000)
    assert abs(c.fy[0]) > abs(r.fy[0]) and abs(c.mz[0]) < abs(r.mz[0])   # the twist raises |Fy|, lowers |Mz|
    assert -c.fy[0] < st["D_yphiF"] * 0.1 and -c.mz[0] < st["D_zphiF"] * 0.1


def test_locked_twist_and_failures(p):
    r = S.solve(p, 4000, [0.0], [DEG], [0.0], locked=(2,))
    assert r.delta[0] == 0 and r.fy[0] == pytest.approx(-708.541, abs=1e-3)   # y does not enter without yaw
    bad = S.solve(p.with_values(k_delta=1e-3), 4000, [0.0], [0.2], [0.0])
    assert not bad.converged[0]                                                   # reported, not hidden


# --------------------------------------------------------------------------- transients (§6-§7)


def test_rigid_relaxation_is_exact_and_second_order(p):
    a = DEG
    errs = []
    for n in (50, 100, 200):
        run = TR.simulate_rolling(p, 4000, 20, 20 * math.tan(a), 20, 0, 0.3, cells=n, carcass="rigid")
        fy, mz = TR.rigid_relaxation_exact(p, 4000, a, run.s)
        errs.append(np.max(np.abs(run.fy - fy)))
        assert np.max(np.abs(run.mz - mz)) < 0.05
    assert errs[0] / errs[1] == pytest.approx(4, rel=0.15) and errs[1] / errs[2] == pytest.approx(4, rel=0.15)
    from tirecli.studies.mcps.relaxation import crossings

    s = np.linspace(0, 0.3, 30001)
    fy, _ = TR.rigid_relaxation_exact(p, 4000, a, s)
    finf = S.solve(p, 4000, [0], [a], [0], carcass="rigid").fy[0]
    assert fy[-1] == pytest.approx(finf, abs=1e-9)
    got = [crossings(s, fy / finf, lev)[0] for lev in (0.63, 0.95, 0.99)]
    assert got == pytest.approx([0.051685, 0.106260, 0.124713], abs=2e-6)


def test_complete_transient_tends_to_the_fixed_point(p):
    a = DEG
    run = TR.simulate_rolling(p, 4000, 20, 20 * math.tan(a), 20, 0, 4.0, cells=100)
    st = S.solve(p, 4000, [0], [a], [0])
    assert abs(run.fy[-1] - st.fy[0]) < 0.01 and abs(run.mz[-1] - st.mz[0]) < 0.01 and abs(run.fx[-1] - st.fx[0]) < 0.01
    assert run.delta[-1] == pytest.approx(st.delta[0], rel=1e-4)
    ratio = run.fy / st.fy[0]
    early, dip = run.s <= 0.13, (run.s > 0.1) & (run.s < 0.3)
    assert ratio[early].max() == pytest.approx(0.72, abs=0.01) and ratio[dip].min() == pytest.approx(0.25, abs=0.01)


def test_relaxation_converges_with_the_cells(p):
    """Twist locked at 20 m/s: 63 % at 0.309 m, 95 % at 0.933 m, converged in the number of cells."""
    from tirecli.studies.mcps.relaxation import crossings

    a = DEG
    finf = S.solve(p, 4000, [0], [a], [0], locked=(2,)).fy[0]
    got = []
    for n in (100, 200):
        run = TR.simulate_rolling(p, 4000, 20, 20 * math.tan(a), 20, 0, 1.2, cells=n, locked=(2,))
        got.append([crossings(run.s, run.fy / finf, lev)[0] for lev in (0.63, 0.95)])
    assert got[1] == pytest.approx([0.309, 0.933], abs=0.002)
    assert got[0] == pytest.approx(got[1], abs=2e-4)


def test_lag_integral_invariant(p):
    """T = int (1 - Fy/Fy_inf) ds of the linearised complete model (docs §7) at a tiny slip angle;
    Richardson over two grids."""
    a, V = 1e-5, 20.0
    st = p.stiffnesses(4000)
    l = p.patch(4000).l
    e = st["D_zalpha"] / p.k_delta
    exact = l / 3 - st["D_yphi"] / st["D_yalpha"] * e + (
        st["D_yalpha"] / p.k_y - e * (l / 2 + p.c_delta * V / p.k_delta + st["D_zphi"] / p.k_delta)) / (1 + e)
    finf = S.solve(p, 4000, [0], [a], [0], tol=1e-14).fy[0]
    vals = []
    for n in (50, 100):
        run = TR.simulate_rolling(p, 4000, V, V * math.tan(a), V, 0, 8.0, cells=n)
        vals.append(np.trapezoid(1 - run.fy / finf, run.s))
    rich = (4 * vals[1] - vals[0]) / 3
    assert rich == pytest.approx(exact, abs=1e-4)


def test_low_speed_relaxation_stays_stable(p):
    """At 0.3 m/s the study raises the cell count so the belt-patch coupling is resolved."""
    from tirecli.studies.mcps.relaxation import RelaxCase, _cells

    checked = {"cells": 100, "fz": 4000.0, "speed": 0.3, "alpha": DEG}
    n = _cells(p, checked, RelaxCase("c", "complete", ()))
    assert n > 400
    run = TR.simulate_rolling(p, 4000, 0.3, 0.3 * math.tan(DEG), 0.3, 0, 1.0, cells=n)
    st = S.solve(p, 4000, [0], [DEG], [0])
    assert np.all(np.isfinite(run.fy)) and np.max(np.abs(run.fy)) < 1.3 * abs(st.fy[0])


def test_simple_magic_formula_fallback():
    from tirecli.parameters.sets import load_builtin

    m = load_builtin("mcps-simple-mf").model()
    k = np.linspace(0, 0.3, 30001)
    fx = m.pure(k, 0, 4000)[0]
    assert fx.max() == pytest.approx(4000, abs=0.01) and k[np.argmax(fx)] == pytest.approx(0.146, abs=1e-3)
    assert m.pure(0.12, 0, 4000)[0] == pytest.approx(3952.6, abs=0.2)
    a = np.radians(np.linspace(0, 20, 20001))
    _, fy, mz = m.pure(0, a, 4000)
    assert -m.pure(0, 4 * DEG, 4000)[1] == pytest.approx(2705, abs=2)
    assert -fy.min() == pytest.approx(3800, abs=0.01) and np.degrees(a[np.argmin(fy)]) == pytest.approx(11.8, abs=0.05)
    assert mz.max() == pytest.approx(50, abs=1e-3) and np.degrees(a[np.argmax(mz)]) == pytest.approx(4.5, abs=0.05)
    # combined slip reduces to the pure curves
    c = m.evaluate([0.05, 0.0], [0.0, 0.05], 4000)
    assert c[0][0] == pytest.approx(m.pure(0.05, 0, 4000)[0]) and c[1][1] == pytest.approx(m.pure(0, 0.05, 4000)[1])


def test_calibration_against_the_fallback(p):
    """docs §8: against the simple-form fallback mu_x and alpha_x end at their bounds, a gap of about
    121 N remains (the closed form of Fx re-evaluated here), and the slip stiffness ends about 25 % above
    the Magic Formula's."""
    from tirecli.models.mcps.tire import pure_longitudinal_fx
    from tirecli.numerics.mcps_calibrate import calibrate_to_mf
    from tirecli.parameters.sets import load_builtin

    m = load_builtin("mcps-simple-mf").model()
    k, a = np.linspace(0, 0.12, 49), np.radians(np.linspace(0, 12, 13))
    cal = calibrate_to_mf(p, 4000, lambda kk, aa: m.evaluate(kk, aa, 4000), k, a)
    f = cal.fitted
    assert f["mu_x"].at_bound == "lower" and f["alpha_x"].at_bound == "upper" and f["r_x"].at_bound is None
    gap = np.max(np.abs(pure_longitudinal_fx(k, cal.params, 4000) - m.evaluate(k, 0.0, 4000)[0]))
    assert gap == pytest.approx(121.0, abs=0.5) and cal.gaps["calibrated"]["fx"].max == pytest.approx(gap, abs=1e-6)
    assert cal.gaps["calibrated"]["fx"].max < cal.gaps["start"]["fx"].max
    assert cal.params.stiffnesses(4000)["D_xsigma"] / (m.Bx * m.Cx * m.Dx * 4000) == pytest.approx(1.25, abs=0.03)


def test_rate_independence_of_the_time_integrated_law(slider_law):
    """Eq. (9) integrated in time (DOP853, not the exact increments) at T = 2 s and 0.5 s gives the same
    loop at equal phases: the right-hand side is homogeneous of degree 1 in the rates."""
    from scipy.integrate import solve_ivp

    lw = slider_law
    A, Psi = 8 * lw.Fk[0] / lw.K[0], 8 * lw.Mkz / lw.Sz
    ph = np.linspace(0, 1.25, 501)
    out = []
    for T_ in (2.0, 0.5):
        w = 2 * np.pi / T_

        def f(t, x):
            return L.rhs(t, x, (A * w * np.cos(w * t), 0.0, Psi * w * np.cos(w * t), 0.0), lw)

        # split at the reversals (kinks of |du|) so the integrator never steps across one
        pieces, x0 = [], np.zeros(6)
        for a, b in ((0, 0.25), (0.25, 0.75), (0.75, 1.25)):
            q = (ph >= a) & (ph <= b)
            sol = solve_ivp(f, (a * T_, b * T_), x0, method="DOP853", rtol=1e-11, atol=1e-12, t_eval=ph[q] * T_)
            x0 = sol.y[:, -1]
            pieces.append((ph[q], sol.y))
        fx = np.concatenate([(y[0] - y[2]) for _, y in pieces])
        out.append(fx)
    assert np.max(np.abs(out[0] - out[1])) < 1e-6
    # and the exact increments give the same loop
    ux = A * np.sin(2 * np.pi * ph)
    f, _ = TR.simulate_slider(lw, ux, 0 * ux, Psi * np.sin(2 * np.pi * ph))
    phs = np.concatenate([p_ for p_, _ in pieces])
    assert np.max(np.abs(np.interp(phs, ph, f[:, 0]) - out[0])) < 1e-6


def test_check_bounds():
    from tirecli.studies.base import Check

    assert Check("a", "", 0.9, 1.0, 0.0, bound="max").passed and not Check("a", "", 1.1, 1.0, 0.0, bound="max").passed
    assert Check("a", "", 1.1, 1.0, 0.0, bound="min").passed and not Check("a", "", 0.9, 1.0, 0.0, bound="min").passed
    assert not Check("a", "", float("nan"), 1.0, 0.0, bound="min").passed
    assert Check("a", "", 1.1, 1.0, 0.0, bound="max").record()["bound"] == "max"


def test_large_slip_angle_relaxation_is_resolved(p):
    """At large slip angles the entry boundary layer is short: the cell count grows with it."""
    a = 1.0
    n = TR.cells_needed(p, 4000, 20, 100, "rigid", slip=(0, math.tan(a)))
    assert n > 100
    run = TR.simulate_rolling(p, 4000, 20, 20 * math.tan(a), 20, 0, 0.3, cells=n, carcass="rigid")
    fy, _ = TR.rigid_relaxation_exact(p, 4000, a, run.s)
    assert np.max(np.abs(run.fy - fy)) < 1.0 and abs(run.fy[-1] - fy[-1]) < 0.01   # of 3566 N
