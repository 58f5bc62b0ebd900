"""Plant + observer simulation: exactness, convergence, freezing at v_r = 0, the fast scheme vs Radau."""
import math
from dataclasses import replace

import numpy as np
import pytest

from tirecli.conventions import theta_fm_from_obs
from tirecli.models.profiles import Change, Constant, Transitions
from tirecli.numerics import observer_integrator as oi
from tirecli.observers.measurement import Sensor


from observer_fixtures import gains, plant  # noqa: F401 (fixtures)


def theta_of(profile_obs):
    """``theta_fm(t)`` from a profile in the OBS convention."""
    return lambda t: theta_fm_from_obs(profile_obs(t))


def scenario(duration, torque, theta_obs, v0=20.0, slip0=0.0, r=0.25, **kw):
    th = theta_obs if callable(theta_obs) else Constant(float(theta_obs))
    bps = []
    for prof in (torque, th):
        if isinstance(prof, Transitions):
            bps += [c.at for c in prof.changes] + [c.at + c.duration for c in prof.changes]
    romega = v0 * (1 + slip0) if slip0 <= 0 else v0 / (1 - slip0)
    return oi.Scenario(duration=duration, torque=torque, theta_fm=theta_of(th), v0=v0, omega0=romega / r,
                       breakpoints=tuple(bps), **kw)


def test_expo2_matches_expm():
    from scipy.linalg import expm

    for M in ([[-4.27, -155114.0], [1.078, -1600.0]],   # the plant's (chi, z) block
              [[-1.0, 5.0], [-5.0, -1.0]],               # complex eigenvalues
              [[-2.0, 1e-9], [0.0, -2.0]],               # (nearly) repeated
              [[0.3, 0.1], [0.2, -0.4]]):
        M = np.array(M)
        for h in (1e-3, 2.5e-3):
            big = np.zeros((6, 6))
            big[:2, :2] = h * M
            big[:2, 2:4] = np.eye(2)
            big[2:4, 4:] = np.eye(2)
            ex = expm(big)
            got = np.array(oi._expo2(*M.ravel(), h)).reshape(3, 2, 2)
            for k, ref in enumerate((ex[:2, :2], ex[:2, 2:4], ex[:2, 4:])):
                np.testing.assert_allclose(got[k], ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max())


def test_time_grid_contains_breakpoints_and_samples():
    g = oi.time_grid(1.0, 0.003, breakpoints=(0.5, 0.1234), samples=np.arange(0, 1.0001, 0.01))
    assert g[0] == 0.0 and g[-1] == 1.0
    assert np.all(np.diff(g) <= 0.003 + 1e-12) and np.all(np.diff(g) > 0)
    for t in (0.5, 0.1234, 0.37, 0.99):
        assert np.min(np.abs(g - t)) < 1e-12


def test_exact_initial_state_stays_exact(plant, gains):
    """x_hat(0) = x(0), theta_hat(0) = theta: the estimates stay exact (accelerating, then braking)."""
    u = Transitions(350.0, (Change(1.0, -300.0, 0.5, "half-cosine"),))
    sc = scenario(3.0, u, 5.0 / 3.0, theta_hat0=5.0 / 3.0)
    tr = oi.simulate_fast(plant, gains, sc)
    assert np.max(np.abs(tr.theta_hat - tr.theta)) < 1e-12
    assert np.max(np.abs(tr.v_hat - tr.v)) < 1e-12
    assert np.max(np.abs(tr.z_hat - tr.z)) < 1e-15
    ref = oi.simulate_reference(plant, gains, replace(sc, duration=1.2))
    assert np.max(np.abs(ref.theta_hat - ref.theta)) < 1e-6
    assert np.max(np.abs(ref.v_hat - ref.v)) < 1e-8


def test_wrong_theta_hat_converges_when_braking(plant, gains):
    """Constant-theta braking at slip about 0.05 from theta_hat(0) = 1 on a wet road (theta = 5/3)."""
    sc = scenario(3.0, Constant(-300.0), 5.0 / 3.0, v0=30.0, slip0=-0.04, theta_hat0=1.0)
    tr = oi.simulate_fast(plant, gains, sc)
    slip = (plant.car.r * tr.omega - tr.v) / tr.v
    assert -0.055 < slip[len(slip) // 3] < -0.04
    err = np.abs(tr.theta_hat - tr.theta)
    assert err[0] == pytest.approx(2.0 / 3.0)
    e = np.interp([0.1, 0.3, 1.0, 3.0], tr.t, err)
    assert e[0] < 0.6 * err[0] and e[1] < 0.2 * err[0] and e[2] < 1e-3 and e[3] < 1e-3
    ref = oi.simulate_reference(plant, gains, replace(sc, duration=0.6))
    both = np.arange(0.0, 0.6, 0.005)  # on both output grids
    # theta_hat moves 0.6 in 0.1 s here: the default step stays within 1 % of that jump
    assert np.max(np.abs(np.interp(both, tr.t, tr.theta_hat) - np.interp(both, ref.t, ref.theta_hat))) < 6e-3


def test_small_slip_convergence_is_slow(plant, gains):
    """observer.md §8: theta_hat(0) = 1.5 on a dry road at slip about 0.01 decays only to 1.23 in 5 s."""
    u = Transitions(250.0, (Change(7.0, -250.0, 1.0, "half-cosine"),))
    tr = oi.simulate_fast(plant, gains, scenario(5.0, u, 1.0, theta_hat0=1.5))
    assert float(np.interp(5.0, tr.t, tr.theta_hat)) == pytest.approx(1.23, abs=0.01)


def test_theta_hat_freezes_while_vr_is_zero(plant, gains):
    """Pure rolling at constant speed (u = sigma_w omega): v_r = 0, phi = 0, so theta_hat must not move,
    not even when the road changes."""
    w0 = 20.0 / plant.car.r
    th = Transitions(1.0, (Change(1.0, 2.5, 0.0, "step"),))
    sc = scenario(3.0, Constant(plant.tire.sigma_w * w0), th, theta_hat0=1.5)
    tr = oi.simulate_fast(plant, gains, sc)
    assert np.max(np.abs(plant.car.r * tr.omega - tr.v)) < 1e-12
    assert np.all(np.isfinite(tr.theta_hat))
    assert np.max(np.abs(tr.theta_hat - 1.5)) < 1e-12
    ref = oi.simulate_reference(plant, gains, replace(sc, duration=1.5))
    assert np.max(np.abs(ref.theta_hat - 1.5)) < 1e-9


def test_fast_scheme_matches_radau(plant, gains):
    """A 2 s run with a theta step and a torque reversal: the fast scheme against Radau (rtol 1e-8)."""
    u = Transitions(300.0, (Change(0.8, -300.0, 0.4, "half-cosine"),))
    th = Transitions(1.0, (Change(0.3, 5.0 / 3.0, 0.0, "step"),))
    sc = scenario(2.0, u, th, v0=25.0)
    ref = oi.simulate_reference(plant, gains, sc)
    both = np.arange(0.0, 2.0, 0.005)  # on both output grids
    errs = []
    for step in (oi.DEFAULT_STEP, 1e-3):
        fast = oi.simulate_fast(plant, gains, sc, step=step)
        f = lambda x: np.interp(both, fast.t, x)  # noqa: E731
        r = lambda x: np.interp(both, ref.t, x)  # noqa: E731
        errs.append(np.max(np.abs(f(fast.theta_hat) - r(ref.theta_hat))))
        assert np.max(np.abs(f(fast.v) - r(ref.v))) < 1e-4
        assert np.max(np.abs(f(fast.v_hat - fast.v) - r(ref.v_hat - ref.v))) < 1e-5
    assert errs[0] < 2e-3          # the default step during a fast torque reversal
    assert errs[1] < errs[0] / 3   # second order: (2.5/1)^2 = 6.25


def test_sampled_measurement_matches_radau(plant, gains):
    """Zero-order hold at 1 kHz (with noise): the closed-form fast layer after each sample jump vs Radau
    resolving it (theta_hat rises: the alpha y~^2 term rectifies the jumps)."""
    u = Constant(350.0)
    for sensor in (Sensor(rate=1000.0), Sensor(rate=1000.0, noise_std=0.02, seed=3)):
        sc = scenario(0.01, u, 1.0)
        fast = oi.simulate_fast(plant, gains, sc, sensor)
        ref = oi.simulate_reference(plant, gains, sc, sensor, rtol=1e-9, atol=1e-12)
        rise_f, rise_r = fast.theta_hat[-1] - 1.0, ref.theta_hat[-1] - 1.0
        assert rise_r > 0.05
        assert rise_f == pytest.approx(rise_r, rel=0.02)
        assert fast.v_hat[-1] - fast.v[-1] == pytest.approx(ref.v_hat[-1] - ref.v[-1], abs=2e-6)


def test_too_slow_fast_mode_is_refused(plant, gains):
    from tirecli.errors import RunError

    with pytest.raises(RunError, match="reference"):
        oi.simulate_fast(plant, gains.replace(k3=-1.0, alpha=0.0), scenario(1.0, Constant(0.0), 1.0))


@pytest.mark.slow
def test_fig2_fast_scheme_matches_radau(plant, gains):
    """The whole 20 s OBS Fig. 2 run: fast scheme (2.5 ms) against Radau (rtol 1e-8, about 10 s)."""
    from tirecli.studies.base import builtin_config
    from tirecli.studies.observe import plan

    p = plan(builtin_config("obs-fig2"))
    sc = p.cases[0].scenario
    fast = oi.simulate_fast(plant, gains, sc)
    ref = oi.simulate_reference(plant, gains, sc)
    both = np.arange(0.0, 20.0, 0.005)  # on both output grids
    f = lambda x: np.interp(both, fast.t, x)  # noqa: E731
    r = lambda x: np.interp(both, ref.t, x)  # noqa: E731
    assert np.max(np.abs(f(fast.theta_hat) - r(ref.theta_hat))) < 3e-4
    assert np.max(np.abs(f(fast.v) - r(ref.v))) < 1e-4
    assert np.max(np.abs(f(fast.v_hat - fast.v) - r(ref.v_hat - ref.v))) < 1e-5
    assert np.max(np.abs(ref.v_hat - ref.v)) == pytest.approx(4.6e-4, abs=0.05e-4)
    assert not math.isnan(ref.theta_hat[-1])
