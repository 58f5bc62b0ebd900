"""Transient numerics: exactness along characteristics, convergence orders, lock, stop, conservation.

Facts from docs/models/lugre_friction.md §3.3-§4.2, §7 and closed forms; no timing assertions.
"""
import math

import numpy as np
import pytest

from tirecli.models.lugre import (lumped_decay_rate, mu_ss_density, mu_ss_exponential, mu_ss_uniform,
                                  kappa0_of_x, parabolic_density, patch_ratio, tabulated_density)
from tirecli.models.lugre_pde import patch_reduction, upwind_steady_mu
from tirecli.models.profiles import Change, Constant, Expression, Transitions
from tirecli.models.variants import FrictionVariant
from tirecli.numerics import runs
from tirecli.numerics.lumped import kappa0_and_slope


@pytest.fixture(scope="module")
def car():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-quarter-car").model()


def fm_torque(tmax=1000.0, step_release=False):
    """The reference braking (docs/models/lugre_friction.md §7): ramp 0 -> T_max over 0.5-2.0 s, release to 0 over 2.0-2.6 s."""
    release = Change(2.6, 0.0, 0.0, "step") if step_release else Change(2.0, 0.0, 0.6, "linear")
    return Transitions(0.0, (Change(0.5, -tmax, 1.5, "linear"), release))


def constant_slip(variant, p, car, s=-0.1, v=20.0, t_end=0.05, tol=None):
    """The tire alone at constant v and slip from z = 0 (open loop)."""
    omega = v * (1.0 + s) / car.r
    return runs.open_loop(variant, p, car, Constant(v), Constant(omega), Constant(1.0), t_end,
                          runs.SolverOptions(tol=tol))


# --------------------------------------------------------------------------- distributed model


def test_pde_equals_eq4_exactly_from_transit_time_on(table1, car):
    """docs/models/lugre_friction.md §3.4: from z = 0 at constant speeds the PDE reaches (4) exactly at t = L/|r omega|."""
    v, s = 20.0, -0.1
    tr = constant_slip(FrictionVariant("distributed"), table1, car, s, v, t_end=0.05, tol=1e-5)
    ref = float(mu_ss_uniform(v * s, v * (1 + s), table1))
    T = table1.L / (v * (1 + s))
    assert T == pytest.approx(0.0111, abs=1e-4)
    after = tr.t >= T
    assert np.max(np.abs(tr.out["mu"][after] - ref)) < 2e-5
    # ... and not before: at half the transit time the force is still far from it
    assert abs(np.interp(0.5 * T, tr.t, tr.out["mu"]) - ref) > 1e-2


def test_pde_constant_slip_settles_within_1e4_at_default_resolution(table1, car):
    v, s = 20.0, -0.1
    tr = constant_slip(FrictionVariant("distributed"), table1, car, s, v, t_end=0.05)
    ref = float(mu_ss_uniform(v * s, v * (1 + s), table1))
    assert abs(tr.out["mu"][-1] - ref) < 1e-4
    assert np.max(np.abs(tr.out["mu"][tr.t >= 0.02] - ref)) < 1e-4
    # docs/models/lugre_friction.md §4.2: the (200-400 cell) reference PDE settles at -0.92616 after 0.0111 s
    assert abs(tr.out["mu"][-1] - (-0.92616)) < 1e-3


@pytest.mark.parametrize("load, kw", [("exponential", {"lam": 2.0}), ("parabolic", {}),
                                      ("tabulated", {"u": (0.0, 0.3, 0.7, 1.0), "f": (1.0, 2.0, 2.0, 0.5)})])
def test_pde_any_load_reaches_its_steady_state(table1, car, load, kw):
    v, s = 20.0, -0.1
    var = FrictionVariant("distributed", load=load, lam=kw.get("lam", 0.0), u=kw.get("u"), f=kw.get("f"))
    tr = constant_slip(var, table1, car, s, v, t_end=0.05, tol=1e-5)
    if load == "exponential":
        ref = mu_ss_exponential(v * s, v * (1 + s), table1, 2.0)
    elif load == "parabolic":
        ref = mu_ss_density(v * s, v * (1 + s), table1, parabolic_density, nodes=40)
    else:
        ref = mu_ss_density(v * s, v * (1 + s), table1, tabulated_density(kw["u"], kw["f"]), nodes=40)
    assert tr.out["mu"][-1] == pytest.approx(float(ref), abs=2e-5)
    T = table1.L / (v * (1 + s))
    assert np.max(np.abs(tr.out["mu"][tr.t >= T] - float(ref))) < 5e-5


def test_patch_reduction_weights_integrate_the_density():
    """w.S reproduces int w z du for z = 1 (S_j = int_0^{u_p} phi_j)."""
    for load, kw in [("uniform", {}), ("exponential", {"lam": 3.0}), ("parabolic", {}),
                     ("tabulated", {"u": (0.1, 0.5, 0.9), "f": (1.0, 3.0, 1.0)})]:
        red = patch_reduction(load, **kw)
        assert float(red.w @ red.A) == pytest.approx(1.0, abs=1e-12)


def test_force_jump_at_zero_deflection(table1, car):
    """docs/models/lugre_friction.md §3.4: with z = 0 the force is (sigma1 + sigma2) vr F_n: mu = -2.0036 at vr = -2 m/s."""
    for var in (FrictionVariant("distributed"), FrictionVariant("lumped", kappa0="Z"),
                FrictionVariant("lumped", kappa0=1.0)):
        tr = constant_slip(var, table1, car, -0.1, 20.0, t_end=0.001)
        assert tr.out["mu"][0] == pytest.approx((table1.sigma1 + table1.sigma2) * -2.0, abs=1e-12)
        assert tr.out["mu"][0] == pytest.approx(-2.0036, abs=1e-12)


def upwind_order(table1):
    v, s = 20.0, -0.1
    exact = float(mu_ss_uniform(v * s, v * (1 + s), table1))
    errs = [abs(upwind_steady_mu(v * s, v * (1 + s), table1, n) - exact) for n in (50, 200, 800)]
    return errs, exact


def test_upwind_reference_converges_at_first_order(table1):
    """docs/models/lugre_friction.md §3.3: -0.927964, -0.926421, -0.926036 for N = 50, 200, 800 versus -0.925908."""
    v, s = 20.0, -0.1
    vals = [upwind_steady_mu(v * s, v * (1 + s), table1, n) for n in (50, 200, 800)]
    assert vals == pytest.approx([-0.927964, -0.926421, -0.926036], abs=1e-6)
    errs, exact = upwind_order(table1)
    assert exact == pytest.approx(-0.925908, abs=1e-6)
    orders = [math.log(errs[i] / errs[i + 1], 4) for i in range(2)]
    assert orders == pytest.approx([1.0, 1.0], abs=0.05)


def fixed_step(variant, p, car, h, t_end=0.1):
    """Open-loop run with a fixed step h (tolerance never active) under smooth, varying kinematics."""
    vp = Expression("20 - 5*t")
    sp = Expression("-0.05*(1 - cos(2*pi*3*t))")  # starts at s = 0, ds/dt = 0: no initial layer
    wp = type("W", (), {"at": staticmethod(lambda t: vp.at(t) * (1 + sp.at(t)) / car.r),
                        "breakpoints": staticmethod(lambda: ()), "__call__": None})
    from tirecli.numerics.ros2 import integrate

    st = runs._stepper(variant, p, car, Constant(0.0).at, Constant(1.0).at, vp.at, wp.at, tol=1e9)
    tr = integrate(st, runs._initial_state(variant, st, vp.at(0.0), wp.at(0.0)), 0.0, t_end, (), tol=1e9,
                   h_max=h, h0=h, prescribed=True)
    return tr.out["mu"][-1]


@pytest.mark.parametrize("variant", [FrictionVariant("distributed"), FrictionVariant("distributed", load="parabolic"),
                                     FrictionVariant("lumped", kappa0="Z")], ids=lambda v: v.label)
def test_time_step_convergence_is_second_order(table1, car, variant):
    """The characteristics solver (and the lumped stepper) converge at order 2 in the step.

    Observed order from successive halvings: log2(|mu_h - mu_h/2| / |mu_h/2 - mu_h/4|).
    """
    hs = [4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5]
    mus = [fixed_step(variant, table1, car, h) for h in hs]
    diffs = [abs(a - b) for a, b in zip(mus, mus[1:])]
    orders = [math.log2(diffs[i] / diffs[i + 1]) for i in range(len(diffs) - 1)]
    assert all(1.75 < o < 2.3 for o in orders[1:]), (diffs, orders)
    assert orders[-1] > 1.9, (diffs, orders)


# --------------------------------------------------------------------------- lumped model


def test_lumped_kappa0_z_matches_the_pde_steady_state(table1, car):
    """FM eq. (10): the lumped model with kappa0(Z) has the distributed steady state (4)."""
    for s, v in ((-0.02, 20.0), (-0.1, 20.0), (-0.3, 10.0), (-0.8, 5.0)):
        tr = constant_slip(FrictionVariant("lumped", kappa0="Z"), table1, car, s, v, t_end=0.2)
        pde = constant_slip(FrictionVariant("distributed"), table1, car, s, v, t_end=0.2, tol=1e-5)
        ref = float(mu_ss_uniform(v * s, v * (1 + s), table1))
        assert tr.out["mu"][-1] == pytest.approx(ref, abs=1e-7)
        assert pde.out["mu"][-1] == pytest.approx(tr.out["mu"][-1], abs=2e-5)


def test_lumped_decay_rate_of_the_spec(table1, car):
    """docs/models/lugre_friction.md §4.2: kappa0(Z) = 1.3927, decay 393.7 1/s, limit -0.92591."""
    v, s = 20.0, -0.1
    vr, rw = v * s, v * (1 + s)
    assert float(kappa0_of_x(patch_ratio(vr, rw, table1))) == pytest.approx(1.3927, abs=1e-4)
    a = float(lumped_decay_rate(vr, rw, table1, "Z"))
    assert a == pytest.approx(393.7, abs=0.05)
    tr = constant_slip(FrictionVariant("lumped", kappa0="Z"), table1, car, s, v, t_end=0.05, tol=1e-6)
    assert tr.out["mu"][-1] == pytest.approx(-0.92591, abs=1e-5)
    # exponential approach: z(t) = z_ss (1 - e^{-a t}) exactly (constant coefficients)
    z_ss = vr / a
    t = tr.t[(tr.t > 0.002) & (tr.t < 0.01)]
    z = np.interp(t, tr.t, tr.y[:, 2])
    assert np.max(np.abs(z - z_ss * (1 - np.exp(-a * t)))) < 2e-4 * abs(z_ss)


def test_kappa0_slope_is_the_derivative():
    for x in (1e-6, 1e-3, 0.5, 3.0, 40.0):
        k, dk = kappa0_and_slope(x)
        assert k == pytest.approx(float(kappa0_of_x(x)), rel=1e-12)
        hstep = 1e-3 * max(x, 1e-3)
        num = (kappa0_and_slope(x + hstep)[0] - kappa0_and_slope(max(x - hstep, 0.0))[0]) / (
            x + hstep - max(x - hstep, 0.0))
        assert dk == pytest.approx(num, rel=1e-4, abs=1e-8)


# --------------------------------------------------------------------------- quarter car


def test_momentum_identity(table2, car):
    """r m v + J omega changes by the integral of u - sigma_w omega (the tire force cancels)."""
    for var in (FrictionVariant("lumped", kappa0="Z"), FrictionVariant("distributed")):
        tq = fm_torque(900.0)
        tr = runs.quarter_car(var, table2, car, tq, Constant(1.0), 20.0, 80.0, 3.0, runs.SolverOptions(tol=1e-5))
        assert not tr.events["lock"]
        P = car.r * car.m * tr.y[:, 0] + car.J * tr.y[:, 1]
        rate = tr.out["torque"] - table2.sigma_w * tr.y[:, 1]
        impulse = np.concatenate(([0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(tr.t))))
        assert np.max(np.abs((P - P[0]) - impulse)) < 1e-4 * np.max(np.abs(impulse))


def test_spec_braking_references(table2, car):
    """docs/models/lugre_friction.md §7: PDE s_min -0.1777 at 2.00 s, |mu|max 1.1663, v(3 s) = 6.33 m/s; lumped kappa0(Z) close."""
    pde = runs.quarter_car(FrictionVariant("distributed"), table2, car, fm_torque(), Constant(1.0), 20.0, 80.0, 3.5)
    i = int(np.argmin(pde.out["slip"]))
    assert pde.out["slip"][i] == pytest.approx(-0.1777, abs=2e-4)
    assert pde.t[i] == pytest.approx(2.00, abs=0.01)
    assert np.max(np.abs(pde.out["mu"])) == pytest.approx(1.1663, abs=2e-4)
    assert np.interp(3.0, pde.t, pde.y[:, 0]) == pytest.approx(6.33, abs=0.005)
    lum = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), table2, car, fm_torque(), Constant(1.0), 20.0, 80.0,
                           3.5, runs.SolverOptions(tol=3e-4))
    assert np.max(np.abs(np.interp(pde.t, lum.t, lum.out["slip"]) - pde.out["slip"])) < 1.2e-3
    assert np.max(np.abs(np.interp(pde.t, lum.t, lum.out["mu"]) - pde.out["mu"])) < 6e-3


def test_wheel_lock_holds_and_releases(table2, car):
    """T_max = 1100 N m locks the wheel at ~1.99 s; omega = 0 while |r F| <= T_b, never negative; it unlocks."""
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), table2, car, fm_torque(1100.0), Constant(1.0),
                          20.0, 80.0, 3.5)
    assert len(tr.events["lock"]) >= 1
    t_lock, t_unlock = tr.events["lock"][0]
    assert t_lock == pytest.approx(1.99, abs=0.01)
    assert t_unlock is not None and 2.0 < t_unlock < 2.6
    assert np.all(tr.y[:, 1] >= 0.0)
    locked = tr.out["locked"] > 0.5
    assert np.all(tr.y[locked, 1] == 0.0)
    assert np.all(np.abs(tr.out["slip"][locked] + 1.0) < 1e-12)
    # while locked the brake holds the tire torque: -r F <= T_b
    F = tr.out["mu"][locked] * car.F_n
    assert np.all(-car.r * F <= tr.out["brake_torque"][locked] + 1e-9)


@pytest.mark.parametrize("case", ["lock", "step-release", "open-loop", "exponential-lock"])
def test_one_state_steps_equal_the_general_steps_bit_for_bit(table2, car, monkeypatch, case):
    """The stepper of a load with one tire state (uniform, exponential: scalar ``_eval1``/``_attempt1``)
    gives the runs of the general loops over the states exactly: free, locked (T_max = 1100 N m) and
    prescribed (open loop) steps."""
    from tirecli.numerics.characteristics import CharacteristicsStepper

    var = FrictionVariant("distributed", load="exponential", lam=2.0) if case.startswith("exponential") else \
        FrictionVariant("distributed")

    def run():
        if case == "open-loop":
            return constant_slip(var, table2, car, s=-0.15, t_end=0.05, tol=1e-5)
        return runs.quarter_car(var, table2, car, fm_torque(1100.0 if case.endswith("lock") else 1000.0, case == "step-release"),
                                Constant(1.0), 20.0, 80.0, 3.5)

    made, real_init = [], CharacteristicsStepper.__init__

    def init(self, *args, **kwargs):
        real_init(self, *args, **kwargs)
        made.append(self.__dict__.get("attempt"))

    monkeypatch.setattr(CharacteristicsStepper, "__init__", init)
    fast = run()
    assert made and all(m is not None for m in made), "the one-state steps were not used"

    def general(self, *args, **kwargs):
        real_init(self, *args, **kwargs)
        del self._eval, self.attempt  # the methods with the loops over the states

    monkeypatch.setattr(CharacteristicsStepper, "__init__", general)
    slow = run()
    if case.endswith("lock"):
        assert fast.events["lock"] and fast.events["lock"] == slow.events["lock"]
    assert fast.stats == slow.stats
    for a, b in [(fast.t, slow.t), (fast.y, slow.y), (fast.dy, slow.dy)] + [(fast.out[k], slow.out[k]) for k in fast.out]:
        assert np.array_equal(a, b, equal_nan=True)


def test_plain_negative_torque_would_reverse_the_wheel_but_the_brake_does_not(table2, car):
    """docs/models/lugre_friction.md §7: brake torque never drives the wheel backwards, even held far above the grip limit."""
    tq = Transitions(0.0, (Change(0.1, -2500.0, 0.2, "linear"),))
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0=2.0), table2, car, tq, Constant(1.0), 20.0, 80.0, 3.0)
    assert np.all(tr.y[:, 1] >= 0.0) and np.all(tr.out["slip"] >= -1.0)
    assert tr.events["lock"] and tr.events["lock"][0][1] is None  # stays locked


def test_stop_condition_and_zero_speed(table2, car):
    """A strong braking ends when v reaches v_stop; LuGre stays finite down to v = 0."""
    tq = Transitions(0.0, (Change(0.0, -900.0, 0.3, "linear"),))
    for v_stop in (0.5, 0.0):
        tr = runs.quarter_car(FrictionVariant("distributed"), table2, car, tq, Constant(1.0), 10.0, 40.0, 20.0,
                              runs.SolverOptions(v_stop=v_stop))
        assert tr.events["reason"] == "stop"
        assert tr.y[-1, 0] == pytest.approx(v_stop, abs=1e-9)
        assert tr.t[-1] < 5.0
        for k, arr in tr.out.items():
            if k != "kappa0":
                assert np.all(np.isfinite(arr)), k
        # stopping distance: between the bounds of constant deceleration at the peak and at the sliding level
        d = tr.out["distance"][-1]
        assert 10.0 ** 2 / (2 * 9.81 * 1.6) < d + 0.5 < 10.0 ** 2 / (2 * 9.81 * 0.5) + 5.0


def test_driving_torque_and_theta_step(table2, car):
    """Traction (u > 0) gives positive slip and force; a theta step (FM convention) changes the force level."""
    tq = Constant(300.0)
    th = Transitions(1.0, (Change(0.5, 0.5, 0.0, "step"),))
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), table2, car, tq, th, 10.0, 40.0, 1.0)
    assert np.all(tr.out["slip"][tr.t > 0.05] > 0) and np.all(tr.out["mu"][tr.t > 0.05] > 0)
    assert tr.out["theta"][0] == 1.0 and tr.out["theta"][-1] == 0.5
    assert 0.5 in set(np.round(tr.t, 12))  # the step is a breakpoint


def test_kept_runs_are_shared_read_only_and_equal_to_fresh_ones(table2, car):
    """``reuse=True`` (what the simulate study asks: fm-fig6/7/8 reuse fm-fig4's brakings) returns the kept run for
    the same inputs: arrays shared and read-only, containers its own, dense-output samples cached; equal to a
    fresh run bit for bit. Other inputs are another run."""
    args = (FrictionVariant("distributed"), table2, car, fm_torque(), Constant(1.0), 20.0, 80.0, 1.0)
    a = runs.quarter_car(*args, reuse=True)
    b = runs.quarter_car(*args, reuse=True)
    fresh = runs.quarter_car(*args)
    assert b is not a and b.out is not a.out and np.shares_memory(a.y, b.y)
    assert not np.shares_memory(fresh.y, a.y)
    np.testing.assert_array_equal(fresh.y, a.y)
    np.testing.assert_array_equal(fresh.out["mu"], b.out["mu"])
    with pytest.raises(ValueError):
        b.y[0, 0] = 0.0
    b.out["mu"] = None                  # a caller's own container: the kept run is untouched
    assert a.out["mu"] is not None
    grid = np.arange(0.0, 1.0, 1e-3)
    (ya, oa), (yb, ob), (yf, of) = a.sample(grid), b.sample(grid), fresh.sample(grid)
    assert len(a.sample_cache) == 1 and a.sample_cache is b.sample_cache and fresh.sample_cache is None
    np.testing.assert_array_equal(ya, yf)
    np.testing.assert_array_equal(yb, yf)
    np.testing.assert_array_equal(ob["mu"], of["mu"])
    yb[0, 0] = -1.0                     # samples are the caller's copies
    assert a.sample(grid)[0][0, 0] == yf[0, 0]
    other = runs.quarter_car(*args[:5], 19.0, 76.0, 1.0, reuse=True)
    assert not np.shares_memory(other.y, a.y) and other.y[0, 0] == 19.0
