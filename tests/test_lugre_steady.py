"""LuGre steady states against analytic facts and the reference values (docs/models/lugre_friction.md §3-§5, §9)."""
import numpy as np
import pytest

from tirecli.conventions import speeds_from_slip
from tirecli.models import lugre
from tirecli.models.lugre import (
    exponential_density, h_uniform, kappa0_of_x, mu_ss_density, mu_ss_exponential, mu_ss_lumped,
    mu_ss_uniform, parabolic_density, tabulated_density, uniform_density,
)


def braking(v, s):
    vv, rw = speeds_from_slip(-np.abs(np.asarray(s, dtype=float)), v)
    return rw - vv, rw


def peak(mu_fn, v, n=200001):
    s = np.linspace(0, 1, n)
    mu = np.abs(mu_fn(*braking(v, s)))
    i = int(np.argmax(mu))
    return s[i], mu[i]


@pytest.mark.parametrize("theta", [1.0, 0.7, 0.4])
@pytest.mark.parametrize("v", [5.0, 20.0, 30.0])
def test_small_slip_slope_is_sigma0_L_over_2_plus_sigma2_v_for_any_theta(table1, v, theta):
    ds = 1e-7
    slope = abs(mu_ss_uniform(*braking(v, ds), table1, theta)) / ds
    assert slope == pytest.approx(table1.sigma0 * table1.L / 2 + table1.sigma2 * v, rel=1e-5)


def test_locked_wheel_limit_is_sliding_level(table1):
    vr = np.array([-5.0, -20.0, 3.0])
    mu = mu_ss_uniform(vr, 0.0, table1)
    expect = np.sign(vr) * lugre.stribeck(vr, table1) + table1.sigma2 * vr
    assert np.allclose(mu, expect, rtol=0, atol=1e-15)


def test_zero_relative_velocity_gives_zero_force(table1):
    assert np.all(mu_ss_uniform(np.zeros(3), np.array([0.0, 1.0, 30.0]), table1) == 0.0)
    assert np.all(mu_ss_lumped(np.zeros(2), np.array([0.0, 10.0]), table1, "Z") == 0.0)


@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0])
def test_lumped_kappa0_Z_equals_distributed_uniform(table1, alpha):
    from dataclasses import replace

    p = replace(table1, alpha=alpha)
    s = np.linspace(0, 1, 301)
    for v in (5.0, 10.0, 20.0, 30.0):
        vr, rw = braking(v, s)
        assert np.max(np.abs(mu_ss_lumped(vr, rw, p, "Z") - mu_ss_uniform(vr, rw, p))) < 1e-12


def test_exponential_load_tends_to_uniform_as_lambda_vanishes(table1):
    vr, rw = braking(20.0, np.linspace(0, 1, 501))
    ref = mu_ss_uniform(vr, rw, table1)
    errs = [np.max(np.abs(mu_ss_exponential(vr, rw, table1, lam) - ref)) for lam in (1e-2, 1e-4, 1e-6)]
    assert errs[-1] < 1e-7
    assert errs[0] > errs[1] > errs[2]  # converges


def test_exponential_reference_values_with_corrected_sign(table1):
    # docs/models/lugre_friction.md §3.3: Table 1, alpha = 1, braking, v = 20, lambda = 2
    s = np.array([0.02, 0.1, 0.3, 0.8])
    mu = mu_ss_exponential(*braking(20.0, s), table1, 2.0)
    assert np.allclose(mu, [-0.22454, -0.73275, -0.95389, -0.88268], atol=1e-5)


@pytest.mark.parametrize("lam", [0.5, 2.0, 10.0])
def test_quadrature_of_exponential_density_equals_closed_form(table1, lam):
    vr, rw = braking(20.0, np.linspace(0, 1, 2001))
    quad = mu_ss_density(vr, rw, table1, lambda u: exponential_density(u, lam))
    assert np.max(np.abs(quad - mu_ss_exponential(vr, rw, table1, lam))) < 1e-6


def test_quadrature_of_uniform_density_and_samples_equal_eq4(table1):
    vr, rw = braking(20.0, np.linspace(0, 1, 2001))
    ref = mu_ss_uniform(vr, rw, table1)
    assert np.max(np.abs(mu_ss_density(vr, rw, table1, uniform_density) - ref)) < 1e-6
    flat = tabulated_density(np.linspace(0, 1, 5), np.full(5, 17.5))  # any scale: normalised
    assert np.max(np.abs(mu_ss_density(vr, rw, table1, flat) - ref)) < 1e-6


def test_parabolic_density_has_unit_mass_and_lies_between_uniform_and_locked(table1):
    u = np.linspace(0, 1, 100001)
    assert np.trapezoid(parabolic_density(u), u) == pytest.approx(1.0, abs=1e-9)
    vr, rw = braking(20.0, np.linspace(0.01, 1, 200))
    mu = np.abs(mu_ss_density(vr, rw, table1, parabolic_density))
    assert np.all(mu <= np.abs(vr * table1.sigma2) + lugre.stribeck(vr, table1) + 1e-12)
    # load at the trailing part, where bristles are deflected most: more force than uniform
    assert np.all(mu >= np.abs(mu_ss_uniform(vr, rw, table1)) - 1e-12)


def test_h_and_kappa0_series_match_closed_forms_at_switch():
    x = np.array([0.99e-4, 1.01e-4])
    hx = 1 - (1 - np.exp(-x)) / x
    assert np.allclose(h_uniform(x), hx, rtol=1e-7)
    assert np.allclose(kappa0_of_x(x), (1 - np.exp(-x)) / hx, rtol=1e-7)
    assert h_uniform(np.inf) == 1.0 and kappa0_of_x(np.inf) == 1.0 and kappa0_of_x(0.0) == 2.0


def test_kappa0_range_and_monotonicity():
    # docs/models/lugre_friction.md §4.2
    k = kappa0_of_x(np.logspace(-6, 3, 2000))
    assert k.min() == pytest.approx(1.0010, abs=1e-4) and k.max() == pytest.approx(1.9999997, abs=1e-7)
    assert np.all(np.diff(k) < 0)


REF_9 = {5: (1.2818, 0.374, 0.6556, 1.1594), 10: (1.1770, 0.279, 0.6520, 0.9817),
         15: (1.1074, 0.237, 0.6486, 0.9035), 20: (1.0552, 0.212, 0.6451, 0.8717),
         25: (1.0137, 0.196, 0.6417, 0.8617), 30: (0.9795, 0.184, 0.6384, 0.8618)}


@pytest.mark.parametrize("v", sorted(REF_9))
def test_reference_table_section_9(table1, v):
    pk, sp, m05, m1 = REF_9[v]
    s_pk, mu_pk = peak(lambda vr, rw: mu_ss_uniform(vr, rw, table1), v)
    assert mu_pk == pytest.approx(pk, abs=6e-5)
    assert s_pk == pytest.approx(sp, abs=6e-4)
    # docs/models/lugre_friction.md prints this column truncated (not rounded) to 4 decimals
    assert abs(mu_ss_uniform(*braking(v, 0.05), table1)) == pytest.approx(m05, abs=1e-4)
    assert abs(mu_ss_uniform(*braking(v, 1.0), table1)) == pytest.approx(m1, abs=6e-5)


def test_driving_reference(table1):
    s = np.linspace(0, 1, 100001)
    v, rw = speeds_from_slip(s, 20.0)
    mu = mu_ss_uniform(rw - v, rw, table1)
    i = int(np.argmax(mu))
    assert mu[i] == pytest.approx(1.0166, abs=6e-5) and s[i] == pytest.approx(0.220, abs=6e-4)
    assert mu[-1] == pytest.approx(0.8525, abs=6e-5)


def test_theta_family_references(table1):
    # docs/models/lugre_friction.md §5
    for th, (pk, sp, m1) in {1.0: (1.0552, 0.212, 0.8717), 0.8: (0.8714, 0.187, 0.7046),
                             0.6: (0.6795, 0.159, 0.5374), 0.4: (0.4764, 0.128, 0.3703)}.items():
        s_pk, mu_pk = peak(lambda vr, rw: mu_ss_uniform(vr, rw, table1, th), 20.0)
        assert (mu_pk, s_pk) == (pytest.approx(pk, abs=6e-5), pytest.approx(sp, abs=6e-4))
        assert abs(mu_ss_uniform(*braking(20.0, 1.0), table1, th)) == pytest.approx(m1, abs=6e-5)


def test_lumped_constant_kappa0_references(table1):
    # docs/models/lugre_friction.md §4.2
    for k0, (pk, sp) in {2: (0.9767, 0.272), 1: (1.0748, 0.182)}.items():
        s_pk, mu_pk = peak(lambda vr, rw: mu_ss_lumped(vr, rw, table1, k0), 20.0)
        assert (mu_pk, s_pk) == (pytest.approx(pk, abs=6e-5), pytest.approx(sp, abs=6e-4))


def test_lumped_exponential_vs_eq6_gap_shrinks_with_lambda(table1):
    # docs/models/lugre_friction.md §4.2: 0.270, 0.100, 0.006, < 1e-4 for lambda = 1, 2, 5, 10
    vr, rw = braking(20.0, np.linspace(0, 1, 2001))
    gaps = [np.max(np.abs(mu_ss_lumped(vr, rw, table1, lam) - mu_ss_exponential(vr, rw, table1, lam)))
            for lam in (1, 2, 5, 10)]
    assert gaps[:3] == [pytest.approx(0.270, abs=2e-3), pytest.approx(0.100, abs=2e-3), pytest.approx(0.006, abs=1e-3)]
    assert gaps[3] < 1e-4


def test_stribeck_exponent_sensitivity(table1, table2):
    # docs/models/lugre_friction.md §9: braking at v = 20 for alpha = 1/2, 1, 2
    from dataclasses import replace

    for p, refs in ((table1, {0.5: (1.0231, 0.302), 1.0: (1.0552, 0.212), 2.0: (1.1343, 0.194)}),
                    (table2, {0.5: (0.9748, 0.284), 1.0: (0.9927, 0.199), 2.0: (1.0549, 0.175)})):
        for alpha, (pk, sp) in refs.items():
            q = replace(p, alpha=alpha)
            s_pk, mu_pk = peak(lambda vr, rw: mu_ss_uniform(vr, rw, q), 20.0)
            assert (mu_pk, s_pk) == (pytest.approx(pk, abs=6e-5), pytest.approx(sp, abs=6e-4))


def test_fast_uniform_path_equals_reference_formula(table1):
    rng = np.random.default_rng(1)
    s = rng.uniform(-1, 1, 20000)
    v, rw = speeds_from_slip(s, rng.uniform(0, 30, 20000))
    vr = rw - v
    ref = np.sign(vr) * lugre.stribeck(vr, table1) * h_uniform(lugre.patch_ratio(vr, rw, table1)) + table1.sigma2 * vr
    assert np.max(np.abs(mu_ss_uniform(vr, rw, table1) - ref)) < 1e-15
    assert mu_ss_uniform(-1.0, 19.0, table1).shape == ()


def test_exponential_load_with_zero_lambda_is_the_uniform_load(cli, tmp_path):
    """docs/models/lugre_friction.md §3.2 allows lambda >= 0: lambda = 0 is the uniform load (eq. 6 -> eq. 4 exactly)."""
    import pandas as pd

    cfg = tmp_path / "s.yaml"
    cfg.write_text("study: sweep\ntire: canudas2003-table1\nsweep:\n  slip: {start: -1, stop: 1, num: 41}\n"
                   "  models: [distributed, {model: distributed, load: exponential, lambda: 0}]\n")
    code, out, err = cli("sweep", cfg, "--out", tmp_path / "o", "--quiet")
    assert code == 0, err
    df = pd.read_csv(tmp_path / "o" / "data" / "sweep.csv")
    uni, exp0 = (g["mu"].to_numpy() for _, g in df.groupby("model", sort=False))
    assert np.all(np.isfinite(exp0)) and abs(uni - exp0).max() < 1e-12
