"""Error control across steps of the drive (issue 22, deliverable 6): every tyre model, driven open loop through
jumps of its kinematics or coupled to the quarter car through jumps of the brake torque, keeps the friction within
1e-2 of a tight independent reference at the default tolerance, including the first 50 ms after each step.

References (rtol 1e-10, split at the jumps, inputs read from inside each piece): scipy DOP853 on the lumped tyre's
``rhs`` (tests/reference_quarter_car.py ``reference_open_loop``), scipy Radau with event location on the quarter
car's ``rhs`` (``reference_run``), DOP853 plus adaptive quadrature over the patch for the distributed tyre driven
open loop (tests/driven_reference.py); the coupled distributed quarter car has no independent solver here: the
ROS2 solver itself at tol 1e-7, checked to have converged (within 1e-5 of its run at 1e-6).

Both kinds of step: a table with two points at the same time, and a transition ``shape: step``. The drive releases
a braking by a step (the case of the issue), brakes again by a step and turns the braking into driving by a step.

Two bounds: the issue's 1e-2 over the whole run, and, in the first 50 ms after each step, 1.5 times the model's
default local tolerance (lumped 1e-3, distributed 3e-4): right after a step the error must be no larger than
elsewhere in the run. Measured on the open-loop drive below (max |mu error| in those 50 ms): before the fix the
lumped tyres were off by 2.4e-3-2.5e-3 (kappa0 = 1, 2, Z) and the distributed one by 6.5e-4, 3.9-4.8 ms after the
step to slip -0.3 at 0.7 s (the step ending on a jump read the kinematics after it, and the error of the bristle
state was measured by sigma0 z although mu moves by (sigma0 - sigma1 a) z, many times more where the bristles are
stiff); after it 7.4e-4 and 2.2e-4 (their largest errors anywhere in the run: 9.0e-4, 4.6e-4).
"""
import numpy as np
import pytest

from driven_reference import reference_mu as distributed_reference_mu
from reference_quarter_car import reference_mu, reference_open_loop, reference_run

from tirecli.models.profiles import Change, Constant, Table, Transitions
from tirecli.models.variants import FrictionVariant
from tirecli.numerics import runs

#: Largest |mu| error at the default tolerance (the issue's bound), over the run and in the first 50 ms after a step.
BOUND = 1e-2
#: Largest |mu| error in the first 50 ms after a step of the open-loop drive: 1.5 times the default local tolerance.
AFTER = {"lumped": 1.5 * runs.DEFAULT_TOL["lumped"], "distributed": 1.5 * runs.DEFAULT_TOL["distributed"]}
T_END = 1.0
STEPS = (0.5, 0.7, 0.85)
LUMPED = {"kappa0=1": 1.0, "kappa0=2": 2.0, "kappa0(Z)": "Z"}


@pytest.fixture(scope="module")
def p():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-table2").model()


@pytest.fixture(scope="module")
def car():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-quarter-car").model()


def _stepped(kind: str, ramp_to: float, levels: tuple):
    """A profile that ramps from 0 to ``ramp_to`` over 0.05-0.35 s, then steps to ``levels`` at :data:`STEPS`:
    a table (two points at each step's time) or transitions with ``shape: step``."""
    if kind == "table":
        t, y = [0.0, 0.05, 0.35], [0.0, 0.0, ramp_to]
        prev = ramp_to
        for at, level in zip(STEPS, levels):
            t += [at, at]
            y += [prev, level]
            prev = level
        return Table(tuple(t), tuple(y))
    return Transitions(0.0, (Change(0.05, ramp_to, 0.3, "linear"),)
                       + tuple(Change(at, level, 0.0, "step") for at, level in zip(STEPS, levels)))


class _Omega:
    """``omega(t)`` [rad/s] of a drive by speed ``v(t)`` and slip ``s(t)`` (conventions: s < 0 braking)."""

    def __init__(self, v, slip, r):
        self.v, self.slip, self.r = v, slip, r

    def at(self, t):
        v, s = self.v.at(t), self.slip.at(t)
        return (v * (1.0 + s) if s <= 0.0 else v / (1.0 - s)) / self.r

    def breakpoints(self, t_end=None):
        return tuple(self.v.breakpoints(t_end)) + tuple(self.slip.breakpoints(t_end))


def _drive(kind, car):
    """A braking (slip to -0.15) released by a step at 0.5 s, braking again by a step to slip -0.3 at 0.7 s and
    driving (slip +0.1) from a step at 0.85 s, while the vehicle slows from 20 to 14 m/s."""
    v = Table((0.0, T_END), (20.0, 14.0))
    return v, _Omega(v, _stepped(kind, -0.15, (0.0, -0.3, 0.1)), car.r)


def _torque(kind):
    """Brake torque ramp to 900 N m (the kappa0 = 2 wheel locks), released by a step at 0.5 s, a step to 1400 N m at
    0.7 s (every wheel locks) and a driving torque of 300 N m from 0.85 s (signed wheel torque, < 0 brakes)."""
    return _stepped(kind, -900.0, (0.0, -1400.0, 300.0))


def _grid():
    """1 ms over the run and 50 us in the first 50 ms after each step (the step times themselves excluded: the
    value at a jump is a matter of convention)."""
    g = np.concatenate([np.arange(0.0, T_END, 1e-3)] + [s + np.arange(1, 1000) * 5e-5 for s in STEPS])
    g = np.unique(np.round(g, 12))
    return g[(g <= T_END) & np.all(np.abs(g[:, None] - np.array(STEPS)) > 1e-9, axis=1)]


def _after_steps(t):
    return np.any((t[:, None] > np.array(STEPS)) & (t[:, None] <= np.array(STEPS) + 0.05), axis=1)


def _assert_within(t, mu, ref, what, after=BOUND):
    """|mu - ref| below :data:`BOUND` everywhere and below ``after`` in the first 50 ms after each step."""
    err = np.abs(np.asarray(mu) - np.asarray(ref))
    assert np.all(np.isfinite(err)), what
    i = int(np.argmax(err))
    first = err[_after_steps(t)]
    assert err[i] < BOUND, f"{what}: max |mu error| {err[i]:.3g} at t = {t[i]:.5f} s"
    assert first.size and first.max() < after, f"{what}: max |mu error| {first.max():.3g} in the first 50 ms"
    return err[i]


@pytest.mark.parametrize("kind", ["table", "transition"])
@pytest.mark.parametrize("name", list(LUMPED))
def test_lumped_open_loop_through_steps_of_the_drive(p, car, kind, name):
    """The lumped tyre (kappa0 = 1, 2, Z) alone, driven through jumps of omega(t): within 1e-2 of DOP853 on its rhs,
    and within 1.5e-3 in the first 50 ms after each step (2.4e-3 before the fix, 7.4e-4 after)."""
    kappa0 = LUMPED[name]
    v, omega = _drive(kind, car)
    tr = runs.open_loop(FrictionVariant("lumped", kappa0=kappa0), p, car, v, omega, Constant(1.0), T_END)
    for b in STEPS:
        assert np.any(np.abs(tr.t - b) < 1e-12), f"no step ends at the jump {b}"
    grid = _grid()
    ref = reference_open_loop(p, car, kappa0, v.at, omega.at, omega.breakpoints(T_END), T_END, grid)
    _assert_within(grid, tr.sample(grid)[1]["mu"], ref, f"open loop, lumped {name}, {kind} steps", AFTER["lumped"])


@pytest.mark.parametrize("kind", ["table", "transition"])
def test_distributed_open_loop_through_steps_of_the_drive(p, car, kind):
    """The distributed tyre alone through the same jumps, also one patch transit after each (the jump reaches the
    trailing edge): within 1e-2 of DOP853 plus quadrature over the patch (a 2 ms grid, 0.25 ms after the steps), and
    within 4.5e-4 in the first 50 ms after each step (6.5e-4 before the fix, 2.2e-4 after)."""
    v, omega = _drive(kind, car)
    tr = runs.open_loop(FrictionVariant("distributed"), p, car, v, omega, Constant(1.0), T_END)
    grid = _grid()
    grid = grid[(np.round(grid * 1e3) % 2 == 0) | (_after_steps(grid) & (np.round(grid * 2e4) % 5 == 0))]
    ref = distributed_reference_mu(v.at, lambda t: car.r * omega.at(t), p, grid, rtol=1e-10,
                                   breakpoints=omega.breakpoints(T_END))
    _assert_within(grid, tr.sample(grid)[1]["mu"], ref, f"open loop, distributed, {kind} steps", AFTER["distributed"])


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["table", "transition"])
@pytest.mark.parametrize("name", list(LUMPED))
def test_lumped_quarter_car_through_steps_of_the_torque(p, car, kind, name):
    """The quarter car with the lumped tyre through jumps of the brake torque (locked-wheel releases included):
    within 1e-2 of Radau with event location on the quarter car's rhs, at the reference's own points."""
    kappa0 = LUMPED[name]
    torque = _torque(kind)
    T, Y, M, ev = reference_run(p, car, kappa0, torque, T_END, 20.0, 20.0 / car.r, rtol=1e-10, atol=1e-12,
                                max_step=1e-3)
    tr = runs.quarter_car(FrictionVariant("lumped", kappa0=kappa0), p, car, torque, Constant(1.0), 20.0, 20.0 / car.r,
                          T_END)
    assert len(tr.events["lock"]) == len(ev["lock"])
    keep = (T > 0.0) & (T < T_END) & np.all(np.abs(T[:, None] - np.array(STEPS)) > 1e-9, axis=1)
    T, Y = T[keep], Y[keep]
    _assert_within(T, tr.sample(T)[1]["mu"], reference_mu(p, car, kappa0, T, Y, torque),
                   f"quarter car, lumped {name}, {kind} steps")


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["table", "transition"])
def test_distributed_quarter_car_through_steps_of_the_torque(p, car, kind):
    """The quarter car with the distributed tyre through the same torque jumps: within 1e-2 of the solver at
    tol 1e-7, which is within 1e-5 of its run at 1e-6 (converged)."""
    torque = _torque(kind)
    grid = _grid()

    def mu(tol):
        tr = runs.quarter_car(FrictionVariant("distributed"), p, car, torque, Constant(1.0), 20.0, 20.0 / car.r, T_END,
                              runs.SolverOptions(tol=tol))
        return tr.sample(grid)[1]["mu"]

    ref, ref6 = mu(1e-7), mu(1e-6)
    assert np.max(np.abs(ref - ref6)) < 1e-5
    _assert_within(grid, mu(None), ref, f"quarter car, distributed, {kind} steps")


@pytest.mark.slow
@pytest.mark.parametrize("model", list(LUMPED) + ["distributed"])
def test_open_loop_driven_by_a_braking_with_a_step_release(p, car, model):
    """The issue's run: every model driven open loop by the kinematics of a coupled braking (lumped kappa0(Z) quarter
    car, 1100 N m: the wheel locks) released by a tabulated step, against the references on the same drive."""
    torque = Table((0.0, 0.05, 0.35, 0.7, 0.7), (0.0, 0.0, -1100.0, -1100.0, 0.0))
    drv = runs.quarter_car(FrictionVariant("lumped", kappa0="Z"), p, car, torque, Constant(1.0), 20.0, 20.0 / car.r,
                           T_END)
    assert drv.events["lock"] and drv.events["lock"][0][1] == pytest.approx(0.7, abs=1e-12)
    v, omega = runs.kinematics_of(drv, "braking", torque.breakpoints(T_END))
    grid = np.unique(np.round(np.concatenate([np.arange(0.0, T_END, 2e-3), 0.7 + np.arange(1, 200) * 2.5e-4]), 12))
    grid = grid[np.abs(grid - 0.7) > 1e-9]
    if model == "distributed":
        variant = FrictionVariant("distributed")
        ref = distributed_reference_mu(v.at, lambda t: car.r * omega.at(t), p, grid, rtol=1e-10,
                                       breakpoints=omega.breakpoints(T_END))
    else:
        variant = FrictionVariant("lumped", kappa0=LUMPED[model])
        ref = reference_open_loop(p, car, LUMPED[model], v.at, omega.at, omega.breakpoints(T_END), T_END, grid)
    tr = runs.open_loop(variant, p, car, v, omega, Constant(1.0), T_END)
    err = np.abs(tr.sample(grid)[1]["mu"] - ref)
    first = err[(grid > 0.7) & (grid <= 0.75)]
    assert err.max() < BOUND and first.max() < BOUND, (model, err.max(), first.max())
