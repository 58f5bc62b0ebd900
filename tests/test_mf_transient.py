"""The transient Magic Formula (first-order relaxation of the slips) and its exact-step integrator.

References: the closed-form solutions of the linear lag ``dx/ds = (u - x)/sigma`` in the rolled
distance (a step: ``u + (x0 - u) exp(-s/sigma)``; a ramp in ``s``: ``u(s) - g sigma + (x0 - u0 + g sigma)
exp(-s/sigma)``), the steady-state Magic Formula, and an adaptive solver of the model's ``rhs``.
"""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tirecli.models.magic_formula import evaluate
from tirecli.models.magic_formula import transient as T
from tirecli.numerics import mf_transient as N
from tirecli.parameters.mf import builtin_tire_names, load_builtin_tire_data

SIGMA_OK = {"mfeval-255-55r20": "version", "chrono-185-80r14": "version", "externdata-205-60r15": "pt"}


def _p(name="mfeval-255-55r20", source=None):
    return T.TransientMF(load_builtin_tire_data(name).tire(), sigma_source=source or SIGMA_OK[name])


@pytest.mark.parametrize("name", list(SIGMA_OK))
def test_step_in_the_middle_of_a_run_matches_the_closed_form(name):
    p = _p(name)
    fz = 0.8 * p.tire.coef["FNOMIN"]
    t = np.linspace(0.0, 1.5, 30001)
    t_step = t[9000]
    u = {"kappa": np.where(t >= t_step, -0.06, 0.01), "alpha": np.where(t >= t_step, 0.04, -0.01), "fz": fz,
         "vx": 12.0}
    run = N.simulate(p, t, u)
    sx, sy = (float(v) for v in T.relaxation_at({"fz": fz}, p))
    after = t >= t_step
    s = 12.0 * (t[after] - t_step)
    gap_k = np.abs(run.x[after, 0] - T.step_response(s, sx, -0.06, 0.01)).max()
    gap_a = np.abs(run.x[after, 1] - T.step_response(s, sy, 0.04, -0.01)).max()
    assert gap_k <= 1e-6 and gap_a <= 1e-6, (gap_k, gap_a)
    assert np.abs(run.x[~after] - [0.01, -0.01]).max() <= 1e-13  # steady before the step (rounding only)


def test_step_with_variable_speed_matches_the_closed_form_in_rolled_distance():
    """A speed ramp (and a deceleration through part of the run): the state depends on the distance only."""
    p = _p()
    t = np.linspace(0.0, 2.0, 4001)
    vx = np.where(t < 1.0, 5.0 + 20.0 * t, 25.0 - 15.0 * (t - 1.0))  # straight in t on each side of t = 1 (a sample)
    t_step = t[600]
    u = {"kappa": np.where(t >= t_step, 0.08, 0.0), "alpha": np.where(t >= t_step, -0.05, 0.0), "fz": 6000.0,
         "vx": vx}
    run = N.simulate(p, t, u)
    s_exact = np.where(t < 1.0, 5.0 * t + 10.0 * t ** 2, 15.0 + 25.0 * (t - 1.0) - 7.5 * (t - 1.0) ** 2)
    np.testing.assert_allclose(run.s, s_exact, rtol=0, atol=1e-12)
    sx, sy = (float(v) for v in T.relaxation_at({"fz": 6000.0}, p))
    after = t >= t_step
    s = s_exact[after] - s_exact[600]
    assert np.abs(run.x[after, 0] - T.step_response(s, sx, 0.08)).max() <= 1e-6
    assert np.abs(run.x[after, 1] - T.step_response(s, sy, -0.05)).max() <= 1e-6


def test_linear_hold_matches_the_ramp_closed_form():
    p = _p("chrono-185-80r14")
    t = np.linspace(0.0, 0.5, 51)  # coarse: exact anyway
    vx = 20.0
    g = 0.3  # slip per metre
    u = {"kappa": 0.01 + g * vx * t, "alpha": -0.02 + 0.5 * g * vx * t, "fz": 3000.0, "vx": vx}
    run = N.simulate(p, t, u, x0=[0.0, 0.0], hold="linear")
    sx, sy = (float(v) for v in T.relaxation_at({"fz": 3000.0}, p))
    s = vx * t
    for col, (u0, gg, sig) in enumerate(((0.01, g, sx), (-0.02, 0.5 * g, sy))):
        ref = u0 + gg * s - gg * sig + (0.0 - u0 + gg * sig) * np.exp(-s / sig)
        assert np.abs(run.x[:, col] - ref).max() <= 1e-12


def test_integrator_against_an_adaptive_solver_of_rhs():
    """Parity with the model's rhs: piecewise-constant inputs with a varying load (hence sigma), solved
    interval by interval by an adaptive Runge-Kutta at rtol 1e-12."""
    p = _p()
    rng = np.random.default_rng(3)
    t = np.sort(np.concatenate(([0.0], rng.uniform(0.0, 0.4, 10))))
    u = {"kappa": rng.uniform(-0.2, 0.2, t.size), "alpha": rng.uniform(-0.1, 0.1, t.size),
         "gamma": rng.uniform(-0.05, 0.05, t.size), "fz": rng.uniform(1000.0, 9000.0, t.size),
         "vx": rng.uniform(3.0, 30.0, t.size), "p": rng.uniform(220000.0, 300000.0, t.size)}
    x0 = np.array([0.05, -0.02])
    run = N.simulate(p, t, u, x0=x0, outputs=())
    vx = u["vx"]
    x = x0.copy()
    worst = 0.0
    for k in range(t.size - 1):
        uk = {name: arr[k] for name, arr in u.items()}
        # the integrator holds the inputs over the interval and rolls the trapezoid of |vx|: same here
        uk["vx"] = 0.5 * (vx[k] + vx[k + 1])
        sol = solve_ivp(lambda tt, xx: T.rhs(tt, xx, uk, p), (t[k], t[k + 1]), x, rtol=1e-12, atol=1e-14,
                        method="DOP853")
        x = sol.y[:, -1]
        worst = max(worst, float(np.abs(x - run.x[k + 1]).max()))
    assert worst <= 1e-9, worst


def test_rhs_vanishes_at_steady_state_and_outputs_equal_the_static_mf():
    p = _p()
    tire = p.tire
    rng = np.random.default_rng(11)
    n = 50
    u = {"kappa": rng.uniform(-0.3, 0.3, n), "alpha": rng.uniform(-0.2, 0.2, n), "gamma": rng.uniform(-0.05, 0.05, n),
         "fz": rng.uniform(500.0, 10000.0, n), "vx": rng.uniform(1.0, 40.0, n), "p": rng.uniform(2.2e5, 3e5, n)}
    x = np.stack([u["kappa"], u["alpha"]])
    assert np.abs(T.rhs(0.0, x, u, p)).max() == 0.0
    out = T.outputs(0.0, x, u, p)
    ref = evaluate(tire, u["kappa"], u["alpha"], u["gamma"], u["fz"], u["vx"], u["p"], low_speed=False)
    for k in ("fx", "fy", "mz", "mx", "my"):
        np.testing.assert_array_equal(out[k], getattr(ref, k))
    # a long run at constant inputs reaches the static MF (30 relaxation lengths: exp(-30) ~ 1e-13)
    sx, sy = (float(v) for v in T.relaxation_at({"fz": 4000.0}, p))
    t = np.linspace(0.0, 30.0 * max(sx, sy) / 10.0, 301)
    run = N.simulate(p, t, {"kappa": 0.07, "alpha": 0.05, "fz": 4000.0, "vx": 10.0}, x0=[0.0, 0.0])
    ref = evaluate(tire, 0.07, 0.05, 0.0, 4000.0, 10.0, low_speed=False)
    assert abs(run.outputs["fx"][-1] - float(ref.fx)) <= 1e-6 * abs(float(ref.fx))
    assert abs(run.outputs["fy"][-1] - float(ref.fy)) <= 1e-6 * abs(float(ref.fy))


def test_array_inputs_in_the_order_of_INPUTS():
    p = _p("chrono-185-80r14")
    u_arr = np.array([0.05, 0.02, 0.0, 4000.0, -15.0])  # backwards: the lag uses |vx|
    u_map = dict(zip(T.INPUTS, u_arr))
    np.testing.assert_array_equal(T.rhs(0, [0.0, 0.0], u_arr, p), T.rhs(0, [0.0, 0.0], u_map, p))
    sx, sy = (float(v) for v in T.relaxation_at(u_map, p))
    np.testing.assert_allclose(T.rhs(0, [0.0, 0.0], u_arr, p), [15.0 * 0.05 / sx, 15.0 * 0.02 / sy], rtol=1e-15)


def test_step_responses_distances():
    """63.2 % of the slip state at one relaxation length; the force's distances where its normalised
    value reaches the level; the simulated curves on the closed form."""
    p = _p()
    res = N.step_responses(p, 5000.0, 20.0, kappa_step=0.03, alpha_step=0.02, samples=2001)
    lv63, lv95 = N.LEVELS
    for slip, r in res.items():
        assert np.abs(r.state - r.closed_form).max() <= 1e-12
        assert r.distances["state"][lv63] == pytest.approx(r.sigma, rel=1e-15)
        assert r.distances["state"][lv95] == pytest.approx(r.sigma * math.log(20.0), rel=1e-15)
        # the simulated curve crosses 1 - 1/e at sigma (linear interpolation on the grid: < 1e-4 sigma)
        i = int(np.flatnonzero(r.state_norm >= lv63)[0])
        s_cross = np.interp(lv63, r.state_norm[i - 1:i + 1], r.s[i - 1:i + 1])
        assert abs(s_cross - r.sigma) <= 1e-4 * r.sigma
        for lv in (lv63, lv95):
            d = r.distances["force"][lv]
            x = float(T.step_response(d, r.sigma, r.step))
            kx, ax = (x, 0.0) if slip == "kappa" else (0.0, x)
            f = getattr(evaluate(p.tire, kx, ax, 0.0, 5000.0, 20.0, low_speed=False), "fx" if slip == "kappa" else "fy")
            assert (float(f) - r.force_start) / (r.force_steady - r.force_start) == pytest.approx(lv, abs=1e-9)
            # the force saturates: it gets there before the slip state does
            assert d < r.distances["state"][lv]
        assert r.force_norm[0] == pytest.approx(0.0, abs=1e-12) and 0.99 < r.force_norm[-1] <= 1.0 + 1e-12


def test_linear_recurrence_chains_blocks_exactly():
    rng = np.random.default_rng(5)
    n = 3000
    z = rng.uniform(0.0, 3.0, (n, 2))
    z[100:110] = 80.0  # beyond Z_MAX: the state forgets (exp(-50) ~ 2e-22)
    f = rng.normal(size=(n, 2))
    x0 = np.array([1.0, -2.0])
    got = N.linear_recurrence(np.exp(-z), f, x0)  # summed z ~ 4500 per column: nine blocks
    ref = np.empty((n + 1, 2))
    ref[0] = x0
    for k in range(n):
        ref[k + 1] = np.exp(-min(z[k, 0], N.Z_MAX)) * ref[k] * [1, 0] + np.exp(-min(z[k, 1], N.Z_MAX)) * ref[k] * [0, 1] + f[k]
    assert np.abs(got - ref).max() <= 1e-12 * max(1.0, np.abs(ref).max())


@pytest.mark.parametrize("name", builtin_tire_names())
def test_outputs_finite_for_every_builtin_tyre(name):
    tire = load_builtin_tire_data(name).tire()
    if name not in SIGMA_OK:
        with pytest.raises(ValueError, match="gives no relaxation lengths"):
            T.TransientMF(tire)
        return
    p = T.TransientMF(tire, sigma_source=SIGMA_OK[name])
    t = np.linspace(0.0, 1.0, 201)
    u = {"kappa": 0.2 * np.sin(7 * t), "alpha": 0.1 * np.cos(5 * t), "gamma": 0.02, "vx": 15.0 - 14.0 * t,
         "fz": tire.coef["FNOMIN"] * (1.0 + 0.5 * np.sin(3 * t))}
    run = N.simulate(p, t, u, hold="linear")
    assert np.isfinite(run.x).all() and np.isfinite(run.sigma).all() and (run.sigma > 0).all()
    for k, v in run.outputs.items():
        assert np.isfinite(v).all(), k


def test_bad_inputs():
    p = _p()
    with pytest.raises(ValueError, match="strictly increasing"):
        N.simulate(p, [0.0, 0.0], {"kappa": 0, "alpha": 0, "fz": 1000, "vx": 1})
    with pytest.raises(ValueError, match="needs the input 'vx'"):
        N.simulate(p, [0.0, 1.0], {"kappa": 0, "alpha": 0, "fz": 1000})
    with pytest.raises(ValueError, match="hold"):
        N.simulate(p, [0.0, 1.0], {"kappa": 0, "alpha": 0, "fz": 1000, "vx": 1}, hold="cubic")
    with pytest.raises(ValueError, match="non-zero speed"):
        N.step_responses(p, 4000.0, 0.0)
