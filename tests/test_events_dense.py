"""Events, breakpoints and dense output of the transient runs (issue: numerics to reference grade), against
an independent reference (scipy Radau/DOP853 on the model's own right-hand side, tests/reference_quarter_car.py)."""
import json

import numpy as np
import pytest

from reference_quarter_car import reference_mu, reference_open_loop, reference_run

from tirecli.models.profiles import Change, Constant, Expression, Table, Transitions, switch_times
from tirecli.models.variants import FrictionVariant
from tirecli.numerics import runs

LUMPED = FrictionVariant(model="lumped", kappa0=2.0)


@pytest.fixture(scope="module")
def p():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-table2").model()


@pytest.fixture(scope="module")
def car():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-quarter-car").model()


def _lock_torque(shape):
    return Transitions(0.0, (Change(0.5, -1100.0, 1.5, "linear"), Change(2.0, 0.0, 0.6 if shape == "linear" else 0.0, shape)))


@pytest.fixture(scope="module")
def lock_refs(p, car):
    return {shape: reference_run(p, car, 2.0, _lock_torque(shape), 2.4, 20.0, 20.0 / car.r) for shape in ("linear", "step")}


@pytest.mark.parametrize("shape", ["linear", "step"])
@pytest.mark.parametrize("tol,bound", [(None, 2e-4), (1e-6, 2e-6)])
def test_lock_and_unlock_times(p, car, lock_refs, shape, tol, bound):
    """The wheel's lock and unlock times are root-found on the integrator's solution: within ``bound`` of
    an independent Radau reference with event detection, at the default and at a tight tolerance."""
    T, Y, M, ev = lock_refs[shape]
    tr = runs.quarter_car(LUMPED, p, car, _lock_torque(shape), Constant(1.0), 20.0, 20.0 / car.r, 2.4,
                          runs.SolverOptions(tol=tol))
    (t_lock, t_unlock), = tr.events["lock"]
    (r_lock, r_unlock), = ev["lock"]
    assert abs(t_lock - r_lock) < bound and abs(t_unlock - r_unlock) < bound
    if shape == "step":  # a jump of the brake torque releases the wheel exactly at the breakpoint
        assert t_unlock == pytest.approx(2.0, abs=1e-12)
    # the recorded states: omega = 0 over the locked interval, > 0 after
    locked = (tr.t > t_lock + 1e-9) & (tr.t < t_unlock - 1e-9)
    assert np.all(tr.y[locked, 1] == 0.0) and np.all(tr.out["locked"][locked] == 1.0)


def test_stop_time(p, car):
    torque = Constant(-600.0)
    T, Y, M, ev = reference_run(p, car, 2.0, torque, 6.0, 20.0, 20.0 / car.r, v_stop=12.0)
    for tol, bound in ((None, 5e-5), (1e-6, 1e-6)):
        tr = runs.quarter_car(LUMPED, p, car, torque, Constant(1.0), 20.0, 20.0 / car.r, 6.0,
                              runs.SolverOptions(tol=tol, v_stop=12.0))
        assert tr.events["reason"] == "stop" and abs(tr.events["stop"] - ev["stop"]) < bound
        assert tr.y[-1, 0] == 12.0 and tr.t[-1] == tr.events["stop"]


def test_dense_output_between_steps(p, car, lock_refs):
    """States between the steps come from the integrator's own step from the last recorded point, outputs
    from the model at those states: mu as accurate as at the steps (no worse than interpolating the step
    values, converging with the tolerance), v better than linear interpolation; exact at the recorded
    steps and continuous into them."""
    torque = _lock_torque("linear")
    T, Y, M, ev = lock_refs["linear"]
    win = (T > 0.6) & (T < 1.8)                            # the wheel turns freely
    Tw, ref_mu = T[win], reference_mu(p, car, 2.0, T[win], Y[win], torque)
    for tol, mu_bound in ((None, 3e-4), (1e-6, 1e-6)):
        tr = runs.quarter_car(LUMPED, p, car, torque, Constant(1.0), 20.0, 20.0 / car.r, 2.4, runs.SolverOptions(tol=tol))
        Ys, O = tr.sample(Tw)
        dense = np.max(np.abs(O["mu"] - ref_mu))
        linear = np.max(np.abs(np.interp(Tw, tr.t, tr.out["mu"]) - ref_mu))
        assert dense < mu_bound and dense <= 1.1 * linear + 1e-9, (tol, dense, linear)
        v_dense = np.max(np.abs(Ys[:, 0] - Y[win, 0]))
        v_linear = np.max(np.abs(np.interp(Tw, tr.t, tr.y[:, 0]) - Y[win, 0]))
        assert v_dense < 0.5 * v_linear, (tol, v_dense, v_linear)
    Yk, Ok = tr.sample(tr.t[10:20])
    assert np.array_equal(Yk, tr.y[10:20]) and np.array_equal(Ok["mu"], tr.out["mu"][10:20])
    dt = 1e-6 * np.diff(tr.t)[10:20]                      # just before the step ends: continuous into them
    Yk, Ok = tr.sample(tr.t[11:21] - dt)
    assert np.all(np.abs(Yk - tr.y[11:21]) <= 2.0 * dt[:, None] * np.abs(tr.dy_left[11:21]) + 1e-12)
    # the travelled distance integrates the dense output of v exactly
    tr = runs.quarter_car(LUMPED, p, car, torque, Constant(1.0), 20.0, 20.0 / car.r, 2.4, runs.SolverOptions(tol=1e-6))
    d = runs.distance_at(tr, [1.8])[0] - runs.distance_at(tr, [0.6])[0]
    assert d == pytest.approx(np.trapezoid(Y[win, 0], Tw) + 0.5 * (Y[win, 0][0] + np.interp(0.6, T, Y[:, 0])) * (Tw[0] - 0.6)
                              + 0.5 * (Y[win, 0][-1] + np.interp(1.8, T, Y[:, 0])) * (1.8 - Tw[-1]), abs=1e-5)


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_extrema_are_root_found(p, car):
    """Peak |slip| of a braking without lock: the maximum of the dense output (to 1e-10 of a fine scan)
    and within the integration error of the reference's peak."""
    torque = Transitions(0.0, (Change(0.5, -950.0, 1.5, "linear"), Change(2.0, 0.0, 0.6, "linear")))
    T, Y, M, ev = reference_run(p, car, 2.0, torque, 2.6, 20.0, 20.0 / car.r, max_step=2e-4)
    s_ref = (car.r * Y[:, 1] - Y[:, 0]) / Y[:, 0]
    i = int(np.argmax(np.abs(s_ref)))
    tr = runs.quarter_car(LUMPED, p, car, torque, Constant(1.0), 20.0, 20.0 / car.r, 2.6, runs.SolverOptions(tol=1e-7))

    def abs_slip(t, Yv, O):
        return np.abs((car.r * Yv[:, 1] - Yv[:, 0]) / Yv[:, 0])

    t_pk, s_pk = tr.extremum(abs_slip, "max")
    assert s_pk == pytest.approx(abs(s_ref[i]), abs=2e-6) and t_pk == pytest.approx(T[i], abs=2e-3)
    fine = np.linspace(t_pk - 2e-3, t_pk + 2e-3, 4001)
    Ys, O = tr.sample(fine)
    assert s_pk >= abs_slip(fine, Ys, O).max() - 1e-10


def _slip_drive(v, slip):
    """(v(t), omega(t)) profiles of an open-loop drive by speed and slip profiles."""
    from tirecli.studies.simulate.planning import _SlipOmega

    return v, _SlipOmega(v, slip, 0.3)


@pytest.mark.parametrize("kind", ["formula step", "table step", "transitions step", "formula kink", "table ramp"])
def test_every_breakpoint_kind(p, car, kind):
    """A step or kink of an input is an integration breakpoint (the run never steps across it): the open-loop
    tire driven through it matches an independent reference at a loose and at a tight tolerance."""
    slip = {
        "formula step": Expression("-0.1*(t > 0.3) + 0.08*(t > 0.6)"),
        "table step": Table((0.0, 0.3, 0.3, 0.6, 0.6), (0.0, 0.0, -0.1, -0.1, -0.02)),
        "transitions step": Transitions(0.0, (Change(0.3, -0.1, 0.0, "step"), Change(0.6, -0.02, 0.0, "step"))),
        "formula kink": Expression("-0.2*abs(t - 0.45) + 0.09*(t > 0.2)*(t < 0.7) - 0.09"),
        "table ramp": Table((0.0, 0.3, 0.31, 0.6), (0.0, 0.0, -0.12, -0.05)),
    }[kind]
    vp, wp = _slip_drive(Constant(20.0), slip)
    car_ = car
    grid = np.round(np.linspace(0.0, 1.0, 1001), 12)
    ref = reference_open_loop(p, car_, 2.0, vp.at, wp.at, slip.breakpoints(1.0), 1.0, grid)
    for tol, bound in ((1e-3, 5e-3), (1e-6, 2e-5)):
        tr = runs.open_loop(LUMPED, p, car_, vp, wp, Constant(1.0), 1.0, runs.SolverOptions(tol=tol))
        for b in slip.breakpoints(1.0):
            assert np.any(np.abs(tr.t - b) < 1e-12), f"no step ends at the breakpoint {b}"
        Ys, O = tr.sample(grid)
        off = np.ones(grid.size, dtype=bool)
        for b in slip.breakpoints(1.0):      # the value at a jump itself is a matter of convention
            off &= np.abs(grid - b) > 1e-9
        assert np.max(np.abs(O["mu"] - ref)[off]) < bound, (kind, tol)


def test_switch_times_of_formulas():
    cases = {
        "-0.1*(t > 0.3) + 0.1*(t > 0.6)": (0.3, 0.6),
        "where(t < 1.25, 0, 2)": (1.25,),
        "abs(t - 0.7)": (0.7,),
        "clip(t, 0.2, 0.9)": (0.2, 0.9),
        "maximum(0.4, t)": (0.4,),
        "sign(sin(2*pi*t))": (0.5, 1.0, 1.5),
        "t % 0.25": (0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75),
        "heaviside(t - 0.123456789, 1)": (0.123456789,),
        "20 - 4*t": (),
        "0.1*sin(2*pi*t)": (),
    }
    for text, want in cases.items():
        got = switch_times(text, 2.0)
        assert len(got) == len(want) and np.allclose(got, want, atol=1e-10), (text, got)
    e = Expression("-0.1*(t > 0.3)")
    e.breakpoints(1.0)
    assert e.at(0.3) == -0.1 and e.at(0.3 - 1e-6) == 0.0   # at a switch: the value from that time on


def test_events_csv_lists_lock_intervals(cli, tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("""study: simulate
tire: canudas2003-table2
initial: {v: 20, slip: 0}
input:
  brake_torque: {initial: 0, changes: [{at: 0.5, duration: 1.5, to: 1100, shape: linear}, {at: 2.0, duration: 0.6, to: 0, shape: linear}]}
t_end: 2.4
cases: [{model: lumped, kappa0: 2, label: L}]
""")
    code, out, err = cli("simulate", cfg, "--out", tmp_path / "o")
    assert code == 0, err
    import pandas as pd

    ev = pd.read_csv(tmp_path / "o" / "data" / "events.csv")
    lock = ev[ev["event"] == "wheel_lock"]
    assert len(lock) == 1 and 1.84 < lock["t"].iloc[0] < 1.86 and 2.18 < lock["t_end"].iloc[0] < 2.19
    assert {"peak_abs_slip", "min_slip", "peak_abs_mu", "end"} <= set(ev["event"])
    run = json.loads((tmp_path / "o" / "run.json").read_text())
    assert run["meta"]["events"][0]["wheel_lock"][0][1] == pytest.approx(lock["t_end"].iloc[0])
    assert "wheel lock: 1.8499-2.18" in out


def test_paper_checks_only_for_figures_asked_for(cli, tmp_path):
    """A custom observe run without ``figures:`` prints its own facts and runs no paper checks; asking for
    the paper's figure by name runs its checks (and on a custom scenario they fail, as they should)."""
    cfg = tmp_path / "custom.yaml"
    cfg.write_text("study: observe\ntire: canudas2003-table1\n"
                   "scenario: {duration: 8, v0: 25, theta: {initial: 1, changes: [{at: 3, to: 1.5, shape: step}]},\n"
                   "           torque: {initial: 300, changes: [{at: 5, duration: 1, to: -200}]}}\n"
                   "estimate: {v_error: 0, z: 0, theta: 1}\n")
    code, out, err = cli("observe", cfg, "--out", tmp_path / "a")
    assert code == 0, err
    assert json.loads((tmp_path / "a" / "run.json").read_text())["checks"] == []
    text = (out + err).replace(str(tmp_path), "")
    assert "check failed" not in text and "checks" not in text and "max |v_hat - v|" in text
    code, out, err = cli("observe", cfg, "--out", tmp_path / "b", "--set", "figures=[obs-fig2]")
    checks = json.loads((tmp_path / "b" / "run.json").read_text())["checks"]
    assert len(checks) > 10 and any(not c["passed"] for c in checks)


@pytest.mark.slow  # long for the default run (CI's 15 min); -m slow runs it
def test_open_loop_after_step_release_with_measurement_block(p, car):
    """The issue's case: a coupled braking at 950 N m with a step release, sampled at 100 Hz (the sample times
    are breakpoints), drives the lumped kappa0(Z) tire open loop through the wheel's spin-up (was |dmu| 0.34)."""
    torque = Transitions(0.0, (Change(0.5, -950.0, 1.5, "linear"), Change(2.6, 0.0, 0.0, "step")))
    samples = np.round(np.arange(0.0, 3.5 + 1e-9, 0.01), 10)
    grid = np.round(np.linspace(0.0, 3.5, 3501), 10)
    for tol, bound in ((None, 1e-3), (1e-6, 5e-6)):
        tr = runs.quarter_car(FrictionVariant("lumped", kappa0=2.0), p, car, torque, Constant(1.0), 20.0, 20.0 / car.r,
                              3.5, runs.SolverOptions(tol=tol), sample_times=samples)
        vp, wp = runs.kinematics_of(tr, "coupled", tuple(torque.breakpoints(3.5)) + tuple(samples))
        ol = runs.open_loop(FrictionVariant("lumped", kappa0="Z"), p, car, vp, wp, Constant(1.0), 3.5,
                            runs.SolverOptions(tol=tol))
        ref = reference_open_loop(p, car, "Z", vp.at, wp.at, vp.breakpoints(), 3.5, grid)
        _, O = ol.sample(grid)
        off = np.abs(grid - 2.6) > 1e-9
        assert np.max(np.abs(O["mu"] - ref)[off]) < bound, tol


@pytest.mark.parametrize("kappa0", [2.0, "Z"])
def test_dense_output_over_arrays_equals_the_per_point_step(p, car, kappa0):
    """The lumped runs' dense output evaluated at all output times at once (numpy arrays over the points) gives
    the per-point path's values (one ``advance`` + ``evaluate`` call per time) to rounding, 1e-12 of each
    quantity's scale: brakings through a lock with a ramped and a stepped release, a lock held to the end, a
    varying adhesion; on the 1 ms grid, just after recorded points, at recorded points and outside the run."""
    from dataclasses import replace

    variant = FrictionVariant(model="lumped", kappa0=kappa0)
    theta = Table((0.0, 1.0, 2.0), (1.0, 0.6, 0.9))
    torques = [_lock_torque("linear"), _lock_torque("step"), Transitions(0.0, (Change(0.1, -1200.0, 0.2, "half-cosine"),))]
    for torque in torques:
        tr = runs.quarter_car(variant, p, car, torque, theta, 20.0, 20.0 / car.r, 2.6)
        assert tr.dense is not None and tr.events["lock"]
        grid = np.concatenate([np.round(np.arange(int(tr.t[-1] / 1e-3) + 1) * 1e-3, 12), tr.t[5:60] + 1e-7,
                               tr.t[60:70], [-0.1, tr.t[-1] + 0.1]])
        Ya, Oa = tr.sample(grid)
        Yb, Ob = replace(tr, dense=None).sample(grid)     # the per-point path
        inside = (grid > 0) & (grid < tr.t[-1]) & ~np.isin(grid, tr.t)
        assert inside.sum() > 2000 and np.any(Oa["locked"][inside] == 1.0) and np.any(Oa["locked"][inside] == 0.0)
        for i in range(Yb.shape[1]):
            assert np.max(np.abs(Ya[:, i] - Yb[:, i])) <= 1e-12 * np.max(np.abs(Yb[:, i]))
        for n in Ob:
            assert np.max(np.abs(Oa[n] - Ob[n])) <= 1e-12 * max(np.max(np.abs(Ob[n])), 1e-300), n
