"""Slip, speed and theta conventions (docs/models/lugre_friction.md §1, §5)."""
import numpy as np

from tirecli import conventions as c


def test_braking_and_driving_slip_definitions():
    r = 0.25
    # braking: v = 20, r omega = 15 -> s = 15/20 - 1 = -0.25
    assert np.isclose(c.slip_from_speeds(20.0, 15.0 / r, r), -0.25)
    # driving: r omega = 20, v = 15 -> s = 1 - 15/20 = 0.25
    assert np.isclose(c.slip_from_speeds(15.0, 20.0 / r, r), 0.25)
    # locked wheel and spinning at standstill
    assert c.slip_from_speeds(10.0, 0.0, r) == -1.0
    assert c.slip_from_speeds(0.0, 10.0, r) == 1.0
    assert c.slip_from_speeds(0.0, 0.0, r) == 0.0


def test_speeds_from_slip_round_trip():
    s = np.linspace(-1, 1, 41)
    v, rw = c.speeds_from_slip(s, 20.0)
    back = c.slip_from_speeds(v, rw / 0.3, 0.3)
    assert np.allclose(back, s, atol=1e-14)
    assert np.all(v[s <= 0] == 20.0) and np.all(rw[s > 0] == 20.0)


def test_kappa_slip_maps_are_inverse():
    s = np.linspace(-1, 0.95, 40)
    assert np.allclose(c.slip_from_kappa(c.kappa_from_slip(s)), s)
    assert np.allclose(c.kappa_from_slip(s[s <= 0]), s[s <= 0])


def test_theta_conventions_convert_exactly():
    th = np.array([1.0, 0.8, 0.6, 0.4, 0.25])
    assert np.array_equal(c.theta_fm_from_obs(c.theta_obs_from_fm(th)), th)
    assert np.allclose(c.theta_obs_from_fm([1.0, 0.8, 0.4]), [1.0, 1.25, 2.5])
    assert np.allclose(c.to_theta_fm([2.5], "obs"), [0.4])


def test_omega_from_slip_inverts_slip_at_fixed_vehicle_speed():
    s = np.linspace(-1, 0.9, 39)
    w = c.omega_from_slip(s, 20.0, 0.25)
    assert np.allclose(c.slip_from_speeds(20.0, w, 0.25), s, atol=1e-14)
