"""Observer design (docs/models/observer_model.md §1-§6): coordinates, plant form, observability, G(s), gain checks."""
import numpy as np
import pytest

from tirecli.observers import lugre_observer as lo
from tirecli.observers import observer
from tirecli.observers import plant as obs_plant


from observer_fixtures import gains, plant  # noqa: F401 (fixtures)


def test_gain_set_is_obs(gains):
    assert (gains.k1, gains.k2, gains.k3, gains.gamma, gains.alpha) == (1000.0, 0.0, -1000.0, 2e5, 20.0)


def test_coordinates_round_trip(plant):
    v, w, z = np.array([20.0, 31.0]), np.array([79.0, 130.0]), np.array([1e-3, -2e-3])
    back = plant.from_obs_coords(*plant.to_obs_coords(v, w, z))
    np.testing.assert_allclose(np.vstack(back), np.vstack([v, w, z]), rtol=1e-14)


def test_obs_form_equals_quarter_car_plant(plant):
    """OBS (22) in (eta, chi, z) is the quarter car with sigma2 in the vehicle equation only (OBS (3)-(5))."""
    from tirecli.models.lugre_lumped import LumpedTire
    from tirecli.models.quarter_car import QuarterCar, rhs

    qc = QuarterCar(tire=LumpedTire(plant.tire), car=plant.car, sigma2_in_wheel=False)
    rng = np.random.default_rng(0)
    for _ in range(20):
        v, w, z = rng.uniform(5, 40), rng.uniform(20, 160), rng.uniform(-3e-3, 3e-3)
        u, th_obs = rng.uniform(-400, 400), rng.uniform(1, 2.5)
        dv, dw, dz = rhs(0.0, (v, w, z), (u, 1.0 / th_obs), qc)
        x = np.array(plant.to_obs_coords(v, w, z))
        deta, dchi, dz2 = obs_plant.rhs(0.0, x, (u, th_obs), plant)
        c = plant.car
        np.testing.assert_allclose([deta, dchi, dz2],
                                   [c.r * c.m * dv + c.J * dw, c.J * dw + plant.P * dz, dz], rtol=1e-9, atol=1e-9)


def test_observer_at_the_plant_state_has_no_injection(plant, gains):
    x = np.array(plant.to_obs_coords(25.0, 101.0, 1.2e-3))
    y = plant.from_obs_coords(*x)[1]
    deta, dchi, dz, dth = observer.rhs(0.0, [*x, 1.7], (y, 120.0), observer.Observer(plant, gains))
    np.testing.assert_allclose([deta, dchi, dz], obs_plant.rhs(0.0, x, (120.0, 1.7), plant), rtol=1e-12)
    assert dth == 0.0


def test_observability_matches_closed_form(plant):
    o = lo.observability(plant)
    assert o["rank"] == 3
    assert o["det"] == pytest.approx(o["det_closed_form"], rel=1e-9)
    assert o["det"] == pytest.approx(-2.24e10, rel=3e-3)          # docs/models/observer_model.md §4
    assert o["factor"] == pytest.approx(-63532.7, abs=0.05)


def test_observability_lost_when_factor_vanishes(plant):
    from dataclasses import replace

    t, c = plant.tire, plant.car
    sigma2 = c.m * t.sigma0 / (c.F_n * t.sigma1)  # F_n sigma1 sigma2 = m sigma0
    bad = replace(plant, tire=replace(t, sigma2=sigma2))
    assert lo.observability(bad)["rank"] < 3
    assert not next(cd for cd in lo.design_conditions(bad, lo.ObserverGains(1e3, 0, -1e3, 2e5, 20)) if cd.id == "observability").ok


def test_error_poles_match_spec(plant, gains):
    """Linearised error dynamics A - K C: eig = -3.733e6, -181.55, -0.0294 1/s (docs/models/observer_model.md §6)."""
    p = np.sort(lo.error_poles(plant, gains).real)
    assert p[0] == pytest.approx(-3.733e6, rel=2e-4)
    assert p[1] == pytest.approx(-181.55, abs=0.01)
    assert p[2] == pytest.approx(-0.0294, abs=5e-5)
    assert lo.slow_pole_estimate(plant, gains) == pytest.approx(p[2], rel=1e-3)


def test_transfer_function_closed_forms(plant):
    """G(s) coefficients of docs/models/observer_model.md §6 for k2 = 0 and several (k1, k3)."""
    t, c = plant.tire, plant.car
    Fn, m, J, r, s0, s1, s2 = c.F_n, c.m, c.J, c.r, t.sigma0, t.sigma1, t.sigma2
    for k1, k3 in ((1000.0, -1000.0), (250.0, -40.0), (5e4, -3e3)):
        tf = lo.transfer_function(plant, lo.ObserverGains(k1, 0.0, k3, 1.0, 1.0))
        assert tf["k_c"] == pytest.approx(r * Fn * s1 / J, rel=1e-8)
        assert tf["a1"] == pytest.approx(s0 / s1 + Fn * s2 / m, rel=1e-8)
        assert tf["a0"] == pytest.approx(Fn * s0 * s2 / (m * s1), rel=1e-6)
        assert tf["b2"] == pytest.approx(Fn * s2 / m - k3 * r * Fn * s1 / J, rel=1e-10)
        assert tf["b1"] == pytest.approx(Fn / (J * m) * (k1 * s1 - k3 * m * r * s0 - k3 * Fn * r * s1 * s2), rel=1e-10)
        assert tf["b0"] == pytest.approx(Fn * s0 / (J * m) * (k1 - k3 * Fn * r * s2), rel=1e-8)


def test_spec_numbers_for_obs_gains(plant, gains):
    tf = lo.transfer_function(plant, gains)
    c0, c1, c2 = tf["re_coeffs"]
    assert (c0, c1, c2) == (pytest.approx(6.5e7, rel=0.01), pytest.approx(1.23e11, rel=0.005), pytest.approx(3.73e6, rel=0.002))
    assert sorted(np.real(tf["zeros"])) == [pytest.approx(-181.54, abs=0.01), pytest.approx(-0.018, abs=5e-4)]
    assert all(cd.ok for cd in lo.design_conditions(plant, gains))


@pytest.mark.parametrize("change, failing", [
    ({"k3": 1000.0}, {"k3-negative", "hurwitz", "coefficients", "spr"}),
    ({"k1": -1000.0}, {"k1-positive"}),          # still Hurwitz: F_n sigma2/m > |k1|/(r m |k3|)
    ({"k1": -5000.0}, {"k1-positive", "hurwitz", "coefficients"}),
    ({"k3": -0.01}, {"k3-negative", "spr"}),
    ({"gamma": 0.0}, {"gamma-positive"}),
])
def test_gain_checks_flag_wrong_signs(plant, gains, change, failing):
    bad = {cd.id for cd in lo.design_conditions(plant, gains.replace(**change)) if not cd.ok}
    assert failing <= bad
    assert "observability" not in bad


def test_passivity_margin_is_tiny(plant, gains):
    """Among P with P B = C', lambda_min(Q) stays about 1.1e-6 (docs/models/observer_model.md §6): (17) needs a huge alpha."""
    pm = lo.passivity_margin(plant, gains)
    assert 0 < pm["lambda_min_q"] <= 1.1e-6
    P = pm["P"]
    _, B, _, _, C = plant.matrices()
    np.testing.assert_allclose(P @ B, C, rtol=1e-12)
    assert np.linalg.eigvalsh(P)[0] > 0
    lip = lo.lipschitz_sizes(plant, 1.9, 155.0, 2.5e-3)
    assert lip["k_z"] == pytest.approx(4.2e2, rel=0.03) and lip["L_psi"] == pytest.approx(3.9e2, rel=0.01)
    assert lo.alpha_bound(pm["lambda_min_q"], 2.5, lip["L_phi"], lip["L_psi"]) > 1e10


def test_fast_rate(plant, gains):
    A, B, R, E, C = plant.matrices()
    keff = gains.K + gains.alpha * (1.0 + 1.3) * B
    assert plant.fast_rate(gains, 1.3) == pytest.approx(C @ keff, rel=1e-12)
