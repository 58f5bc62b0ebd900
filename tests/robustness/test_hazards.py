"""Hazards of issue 24 (items 4 and 5): inputs that hung a run, or let a library's warning or a meaningless
result reach the user.

- formulas that switch too often escaped the cap at some frequencies (the count aliased away), and an input's
  switching or oscillation rate was not in a run's step estimate;
- observe runs whose work (solver choice, measurement rate, gains) was not estimated before they started;
- gains or inputs no solver can integrate, and a solver's failure, reached the user as a library warning;
- control characters in a title or label;
- a fit whose data cannot identify its parameters claimed zero-width intervals.

Each refusal goes through the real ``tirecli`` (:func:`harness.run`, with a hang limit) or its entry point in
this process (``cli``): exit 2 (an input at fault) or 1 (a run failure), exactly one ``error:`` line, no
library warning, no raw control byte.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from harness import Result, assert_clean_error, copy_example, run, run_warm

from tirecli import limits

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
#: A run that has not ended after this long hangs (each refusal here takes a second or two).
HANG_SECONDS = 60

SIMULATE = """study: simulate
tire: canudas2003-table2
initial: {v: 20, slip: 0}
input:
  pressure: {expr: "PRESSURE"}
t_end: TEND
cases: [lumped]
"""


def _write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _no_library_noise(r: Result) -> None:
    for word in ("Warning", "warnings.warn", "lsoda:", "site-packages", "\x1b", "\x07", "\x00"):
        assert word not in r.err and word not in r.out, (word, r.err[-800:])


@pytest.fixture
def refused_here(cli):
    """The CLI's entry point in this process: exit ``code``, one ``error:`` line matching ``pattern``."""
    def check(args, pattern, code=2):
        c, out, err = cli(*args)
        r = Result(c, out, err, 0.0)
        assert_clean_error(r, code, pattern)
        _no_library_noise(r)
        return r

    return check


def warm_refused(args, pattern, code=2):
    """Through the CLI forked from a warm ``tirecli`` (:func:`harness.run_warm`), with the hang limit: for inputs
    that hung before (in this process a hang would stop the test run)."""
    r = run_warm(args, timeout=HANG_SECONDS)
    assert_clean_error(r, code, pattern)
    _no_library_noise(r)
    return r


# --------------------------------------------------------------------------- formulas that switch too often


@pytest.mark.parametrize("formula", [
    "where(sin(2*pi*15000*t) > 0, 800, 0)",     # 30,000 switches: on the old 20,001-point grid every sample was a zero
    "where(sin(1e5*t) > 0, 800, 0)",            # 31,831
    "800*abs(sin(1e6*t))",                      # 318,310 kinks: counted on sample windows
    "10*(sin(2*pi*20000*t) > 0)",               # 40,000
    "(1e6*t) % 1",                              # 1,000,000 jumps, several per grid interval
])
def test_periodic_switching_cannot_alias_past_the_cap(tmp_path, refused_here, formula):
    cfg = _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", formula).replace("TEND", "1"))
    refused_here(["params", "validate", cfg], r"s\.yaml:5: input\.pressure\.expr: switches .* in \[0, 1\] s .*at most 10,000")


def test_the_cap_through_the_real_command(tmp_path):
    cfg = _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", "where(sin(2*pi*15000*t) > 0, 800, 0)").replace("TEND", "1"))
    r = run(["simulate", cfg, "-o", tmp_path / "o"], timeout=HANG_SECONDS)
    assert_clean_error(r, 2, r"input\.pressure\.expr: switches \(jumps or kinks\) 29,999 times or more in \[0, 1\] s")
    assert not (tmp_path / "o").exists()


def test_switch_counts_are_exact_for_periodic_formulas():
    from tirecli.models.formulas import formula_frequency, oscillation_rate, switch_times

    # a 2 kHz square wave has 2 switches per period: 3999 in (0, 1) s (the zeros at 0 and 1 s are not inside)
    times = switch_times("10*(sin(2*pi*2000*t) > 0)", 1.0)
    assert len(times) == 3999
    assert max(abs(t * 4000 - round(t * 4000)) for t in times) < 1e-6      # at k/4000 s, refined to 1e-12 s
    assert switch_times("where(sin(2*pi*1e5*t) > 2, 1, 0)", 10.0) == ()    # fast, but never crosses 2
    assert formula_frequency("800 + 100*sin(2*pi*20000*t)", 1.0) == pytest.approx(20000.0, rel=1e-6)
    assert formula_frequency("t > 1", 2.0) == 0.0
    assert formula_frequency("10*(sin(2*pi*200*t) > 0)", 1.0) == 0.0          # the sine only decides where it switches
    assert formula_frequency("abs(sin(2*pi*50*t))", 1.0) == pytest.approx(50.0, rel=1e-6)
    import ast
    import numpy as np

    # sin(1e6 t^2): the argument's slope 2e6 t reaches 2e6 1/s at 1 s: 2e6/pi sign changes per second
    assert oscillation_rate(ast.parse("sin(1e6*t*t)", mode="eval"), np.linspace(0, 1, 20001)) == \
        pytest.approx(2e6 / np.pi, rel=1e-3)


# --------------------------------------------------------------------------- an input's rate in the step estimate


def test_a_fast_oscillating_input_is_in_the_step_estimate(tmp_path, refused_here, cli):
    """A smooth 20 kHz input has no switches, but a run must resolve each period (~10 steps): over 10 s that is
    2 million steps, refused up front with the estimate and the option that raises it, instead of a minute of
    stepping into the step budget."""
    cfg = _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", "40 + 30*sin(2*pi*20000*t)").replace("TEND", "10"))
    r = warm_refused(["simulate", cfg, "-o", tmp_path / "o"],
                     r"s\.yaml:5: input\.pressure: the run would need 2,0\d\d,\d\d\d samples .* 2,000,00\d of them for the "
                     r"solver steps to follow input\.pressure \(oscillating at up to 2e\+04 Hz over 10 s\); "
                     r"the budget is 1,000,000 \(raise it with --max-samples 2100000")
    assert not (tmp_path / "o").exists()
    assert r.code == 2
    # the switches of a formula within the cap count too (10 steps each)
    cfg2 = _write(tmp_path, "q.yaml", SIMULATE.replace("PRESSURE", "10*(sin(2*pi*200*t) > 0)").replace("TEND", "5"))
    refused_here(["params", "validate", cfg2, "--max-samples", "10000"],
                 r"input\.pressure: .*1,999 switches over 5 s")
    code, _, err = cli("params", "validate", cfg2, "--max-samples", "30000")
    assert code == 0, err


# --------------------------------------------------------------------------- observe: the work before the run


@pytest.mark.parametrize("sets, pattern", [
    (["observer.gamma=1e30"],
     r"observer\.gamma: the run would need 3\.9e\+18 samples .* adaptation loop's ringing at 4\.52e\+16 rad/s "
     r"\(damping ratio 4\.3e-11, .*make it smaller"),
    (["measurement.rate=100000", "solver.method=lsoda", "scenario.duration=2", "metrics.phases=[0, 1, 2]"],
     r"measurement\.rate: the run would need .* the lsoda solver's 200,009 restarts .*raise it with --max-samples \d+"),
    (["measurement.rate=10000", "solver.method=radau"],
     r"measurement\.rate: the run would need 80,\d{3},\d{3} samples .* the radau solver's 200,009 restarts "
     r".*raise it with --max-samples 81000000"),
])
def test_observe_runs_are_estimated_with_their_solver_and_gains(tmp_path, sets, pattern):
    """Each of these ran for more than a minute; now each is refused before it starts, with its estimate."""
    cfg = copy_example("obs-fig2.yaml", tmp_path)
    r = run(["observe", cfg, "-o", tmp_path / "o"] + [a for s in sets for a in ("--set", s)], timeout=HANG_SECONDS)
    assert_clean_error(r, 2, pattern)
    _no_library_noise(r)
    assert not (tmp_path / "o").exists()


def test_a_gain_study_names_the_case(tmp_path):
    cfg = copy_example("obs-gain-study.yaml", tmp_path)
    warm_refused(["observe", cfg, "-o", tmp_path / "o", "--set", "gain_study.values=[2.0e+5, 1.0e+14]"],
                 r"<command line --set>: gain_study\.values: .*ringing at 4\.52e\+08 rad/s .*\(case gamma = 1e\+14\)")


@pytest.mark.parametrize("sets, pattern", [
    (["observer.alpha=1e30"], r"<command line --set>: observer\.alpha: 1e\+30 is more than an adaptive solver can integrate "
                              r"in double precision: .* into z_hat .* may be at most about 3e\+06"),
    (["observer.k1=1e30"], r"observer\.k1: 1e\+30 is more than an adaptive solver .* into eta_hat"),
    (["scenario.torque=1e9"], r"scenario\.torque: up to 1e\+09 N m is far more than the tyre transmits \(1\.36e\+03 N m\): "
                              r"the wheel would spin up to \|v_r\| ~ 2\.5e\+08 m/s.*give a torque the tyre can transmit"),
    (["scenario.torque=1e5"], r"scenario\.torque: the run would need .* ringing .*the torque \(up to 1e\+05 N m, the tyre "
                              r"transmits 1\.36e\+03\) spins the wheel"),
    (["scenario.torque=-1e9"], r"scenario\.torque: up to 1e\+09 N m is far more than the tyre transmits"),
    (["scenario.v0=1e9"], r"scenario\.v0: 1e\+09 m/s turns the wheel at 4\.18e\+09 rad/s: .*no adaptive solver converges"),
    (["scenario.theta=1e-9"], r"scenario\.theta: theta_obs from 1e-09 to 1 \(OBS convention\) is beyond the model's range"),
    (["solver.rtol=1e-15"], r"solver\.rtol: 1e-15 is tighter than the rounding noise .* use 1e-07 \(the default\) or looser"),
])
def test_gains_and_torques_no_solver_can_follow_are_refused_by_name(tmp_path, sets, pattern):
    """Were a scipy UserWarning ('lsoda: Repeated convergence failures') and exit 1, or a hang."""
    cfg = copy_example("obs-fig2.yaml", tmp_path)
    warm_refused(["observe", cfg, "-o", tmp_path / "o"] + [a for s in sets for a in ("--set", s)], pattern)


def _fig2_case(*sets):
    from tirecli.config.loader import load_config
    from tirecli.studies import observe

    p = observe.plan(load_config(EXAMPLES / "obs-fig2.yaml", list(sets))).detail
    return p, p.cases[0]


def test_a_solver_failure_is_one_line_naming_the_solver():
    """alpha = 1e7 passes no check here (the plan refuses it: this calls the integrator directly)."""
    import warnings

    from tirecli.errors import RunError
    from tirecli.numerics.observer.adaptive import simulate_adaptive

    p, case = _fig2_case()
    gains = case.gains.replace(alpha=1e7)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(RunError) as err:
            simulate_adaptive(p.plant, gains, case.scenario, case.sensor, method="lsoda", rtol=1e-7)
    assert not caught, [str(w.message) for w in caught]
    msg = str(err.value)
    assert msg.startswith("the lsoda solver failed at t = 7 s (repeated convergence failures): try solver.method: "
                          "radau or bdf"), msg
    assert "\n" not in msg and "Unexpected istate" not in msg


def test_the_fixed_scheme_failing_is_one_line(monkeypatch):
    from tirecli.errors import RunError
    from tirecli.numerics.observer import method

    p, case = _fig2_case()

    def overflow(*args, **kwargs):
        raise OverflowError("math range error")

    monkeypatch.setattr(method, "simulate_fast", overflow)
    with pytest.raises(RunError, match=r"^the fixed solver failed at t = 0 s \(overflowerror: math range error\): "
                                       r"try solver\.method: lsoda or radau"):
        method.simulate(p.plant, case.gains, case.scenario, case.sensor, method.SolverOptions(method="fixed"))


def test_work_past_the_budget_stops_a_run_at_once():
    """The run-time guard: OBS Fig. 2 takes about 3,400 evaluations; at a limit of 1,000 it stops, naming the
    option that raises the budget; the projection stops a run whose pace would pass the limit."""
    from tirecli.errors import RunError
    from tirecli.numerics.observer.adaptive import simulate_adaptive
    from tirecli.numerics.solver_guard import CHECK_EVERY, WorkGuard

    p, case = _fig2_case()
    with limits.budget(1000), pytest.raises(RunError, match=r"at its pace up to t = .* the lsoda solver would need about "
                                                           r"[\d,]+ samples; the budget is 1,000 \(raise it with "
                                                           r"--max-samples \d+"):
        simulate_adaptive(p.plant, case.gains, case.scenario, case.sensor, method="lsoda", rtol=1e-7)
    with pytest.raises(RunError, match=r"would need about [\d,]+ evaluations, more than its limit of 1,000;"):
        simulate_adaptive(p.plant, case.gains, case.scenario, case.sensor, method="lsoda", rtol=1e-7, max_work=1000)
    guard = WorkGuard("bdf", 0.0, 20.0, limit=1e6)
    f = guard.wrap(lambda t, x: x)
    for k in range(CHECK_EVERY * 15):       # 15,000 BDF evaluations (49,500 of LSODA's cost) for the first 0.1 s
        f(0.1 * k / (CHECK_EVERY * 15), 0.0)
    with pytest.raises(RunError, match=r"t = 0\.1 s of 20 s \(52,800 evaluations .* would need about 10,560,001 samples"):
        for k in range(CHECK_EVERY * 2):    # past 5% of the limit (at 16,000): the pace projects 200 times the work
            f(0.1, 0.0)
    ok = WorkGuard("lsoda", 0.0, 20.0, limit=1e6).wrap(lambda t, x: x)
    for k in range(CHECK_EVERY * 60):       # 60,000 evaluations for all 20 s: fine
        ok(20.0 * k / (CHECK_EVERY * 60), 0.0)


def test_the_adaptation_loop_closed_form_matches_the_full_jacobian():
    """``s^2 + lambda_f s + gamma phi^2 P/J``: its ringing frequency against the eigenvalues of the finite-difference
    Jacobian of the full 7-state system (plant + observer) at a braking state with theta_hat = theta."""
    import numpy as np

    from tirecli.numerics.observer.adaptive import scalar_rhs, state_scales
    from tirecli.observers import envelope as en

    p, case = _fig2_case()
    plant, c = p.plant, p.plant.car
    v, vr = 15.0, -1.8
    y = (v + vr) / c.r
    g = float(__import__("tirecli.models.lugre", fromlist=["stribeck"]).stribeck(vr, plant.tire))
    a_phi = plant.tire.sigma0 * abs(vr) / g
    z = vr / (a_phi + plant.kappa * c.r * abs(y))           # the steady bristle state, theta = 1
    X = np.array([v, y, z, c.r * c.m * v + c.J * y, c.J * y + plant.P * z, z, 1.0])
    for gamma in (1e12, 1e14):
        gains = case.gains.replace(gamma=gamma)
        f = scalar_rhs(plant, gains, case.scenario)
        J = np.empty((7, 7))
        f0 = f(1.0, X)
        for i in range(7):
            h = 1e-7 * max(abs(X[i]), state_scales(plant)[i])
            Xp = X.copy()
            Xp[i] += h
            J[:, i] = (f(1.0, Xp) - f0) / h
        imag = float(np.max(np.abs(np.linalg.eigvals(J).imag)))
        wa, zeta = en.adaptation_loop(plant, gains, abs(a_phi * z), 1.0)
        assert imag == pytest.approx(wa * np.sqrt(1 - zeta ** 2), rel=0.02), (gamma, imag, wa, zeta)


def test_the_envelope_of_a_spinning_wheel():
    """At 5000 N m the OBS plant's wheel spins up until its viscous friction takes the excess torque: the
    envelope's slip speed r (u - r F_n mu_s)/sigma_w against the run's."""
    import numpy as np

    from tirecli.numerics.observer.adaptive import simulate_adaptive
    from tirecli.numerics.observer_work import scenario_envelope
    from tirecli.observers.envelope import knee_slip_speed, steady_phi

    p, case = _fig2_case("scenario.torque=5000", "scenario.duration=5", "metrics.phases=[0, 5]")
    env = scenario_envelope(p.plant, case.scenario)
    c, t = p.plant.car, p.plant.tire
    assert env.spin and env.capacity == pytest.approx(c.r * c.F_n * t.mu_s)
    tr = simulate_adaptive(p.plant, case.gains, case.scenario, case.sensor, method="lsoda", rtol=1e-6)
    vr_run = float(np.max(c.r * tr.omega - tr.v))
    assert 0.8 < env.vr / vr_run < 1.3, (env.vr, vr_run)
    knee = knee_slip_speed(p.plant, 20.0)
    assert steady_phi(p.plant, knee, 20.0 - knee) == pytest.approx(knee / 2, rel=1e-9)   # transport = relaxation


# --------------------------------------------------------------------------- control characters in texts


@pytest.mark.parametrize("args, pattern", [
    (["observe", "obs-noise.yaml", "--set", 'cases=[{label: "a\\e[31mred", measurement: {rate: 1000}}]'],
     r"<command line --set>: cases\[0\]\.label: contains the control character \\x1b \(at character 2\)"),
    (["simulate", "fm-fig4.yaml", "--set", 'cases=[{model: lumped, label: "bell\\a"}]'],
     r"cases\[0\]\.label: contains the control character \\x07 \(at character 5\)"),
    (["sweep", "fm-fig1-left.yaml", "--set", 'title="nul\\0"'], r"title: contains the control character \\x00"),
    (["sweep", "fm-fig1-left.yaml", "--set", 'tire={set: ./s.yaml}'], r"s\.yaml:3: title: contains the control character \\x1b"),
])
def test_control_characters_in_texts_are_refused_at_their_key(tmp_path, refused_here, args, pattern):
    """They wrote an SVG that is not well-formed XML and sent raw ESC/BEL/NUL to the terminal through
    matplotlib's missing-glyph warnings."""
    (tmp_path / "s.yaml").write_text('name: s\nkind: lugre\ntitle: "\\e[2J"\ncitation: none\nvalues: {sigma0: 181.54}\n')
    args = [str(copy_example(a, tmp_path)) if a.endswith(".yaml") else a for a in args]
    refused_here(args + ["-o", tmp_path / "o"], pattern)   # ./s.yaml: beside the config
    assert not (tmp_path / "o").exists()


def test_tabs_and_line_breaks_in_texts_are_fine(cli, tmp_path):
    cfg = copy_example("fm-fig1-left.yaml", tmp_path)
    code, _, err = cli("params", "validate", cfg)
    assert code == 0, err
    from tirecli.config.schema import Context, Str
    from tirecli.io.yamlio import Origins

    ctx = Context(Origins())
    assert Str().check("two\tcolumns\nand lines", ("k",), ctx) == "two\tcolumns\nand lines"
    assert not ctx.problems
    Str().check("right-to-left \u202e override", ("k",), ctx)
    assert "\\u202e" in ctx.problems[-1].message


# --------------------------------------------------------------------------- a fit the data cannot identify


def test_a_fit_of_data_that_identify_nothing_is_refused(tmp_path):
    """40 identical rows (one operating point) wrote fitted.yaml with every parameter at +/- 0 and a zero-width
    interval; the steady-state Jacobian has rank 1 of 5."""
    data = tmp_path / "same.csv"
    data.write_text("t,v,s,mu\n" + "".join(f"{i * 0.01:.2f},20,-0.05,-0.5\n" for i in range(40)))
    cfg = copy_example("fm-fig6.yaml", tmp_path)
    r = run(["fit", cfg, "--data", data, "-o", tmp_path / "o"], timeout=HANG_SECONDS)
    assert_clean_error(r, 2, r"same\.csv: the steady state \(FM eq\. 4\) fit is refused: the data cannot identify any of "
                             r"the fitted parameters \(sigma0, sigma2, mu_c, mu_s, v_s: the fit's Jacobian has rank 1 of 5")
    assert not (tmp_path / "o").exists()


def test_unidentifiable_parameters_get_no_interval_and_the_others_their_exact_one():
    """Columns (x, y, x): a and c enter only as a + c (the null direction (1, 0, -1)/sqrt 2): neither is identifiable;
    b is, with the variance of the full-rank fit in (a + c, b)."""
    import numpy as np

    from tirecli.numerics.identify import _stats, identifiability

    rng = np.random.default_rng(3)
    x, y = rng.normal(size=30), rng.normal(size=30)
    J = np.column_stack([x, y, x])
    resid = rng.normal(scale=0.1, size=30)
    names = ["a", "b", "c"]
    assert identifiability(J, names) == (["a", "c"], 2)
    st = _stats(J, resid, names, {"a": 1.0, "b": 2.0, "c": 3.0}, dict.fromkeys(names, -10.0), dict.fromkeys(names, 10.0),
                0.95)
    assert np.isnan(st["se"]["a"]) and np.isnan(st["se"]["c"]) and np.isnan(st["ci_low"]["a"]) and np.isnan(st["ci_high"]["c"])
    J2 = np.column_stack([x, y])
    s2 = float(resid @ resid) / (30 - 3)
    assert st["se"]["b"] == pytest.approx(np.sqrt(s2 * np.linalg.inv(J2.T @ J2)[1, 1]), rel=1e-9)
    assert identifiability(np.column_stack([x, y, np.zeros(30)]), names) == (["c"], 2)     # a column of zeros
    w = rng.normal(size=30)
    assert identifiability(np.column_stack([x, y, x + 1e-3 * w]), names) == ([], 3)       # nearly, but determined


def test_a_partly_identified_fit_says_which_and_claims_no_interval_for_them():
    import numpy as np

    from tirecli.numerics.identify import FitResult

    nan = float("nan")
    f = FitResult(names=["a", "b"], estimate={"a": 1.0, "b": 2.0}, se={"a": nan, "b": 0.1}, ci_low={"a": nan, "b": 1.8},
                  ci_high={"a": nan, "b": 2.2}, corr=np.full((2, 2), nan), cov=np.full((2, 2), nan), at_bound={"a": False, "b": False},
                  residual_rms=0.01, n=10, dof=8, confidence=0.95, unidentifiable=["a"], rank=1)
    assert f.failure() is None
    assert f.identifiability_text() == "the data cannot identify a (a: the fit's Jacobian has rank 1 of 2; e.g. every " \
                                       "sample at one operating point)"
    assert f.record()["unidentifiable"] == ["a"]
    f.unidentifiable = ["a", "b"]
    assert f.failure().startswith("the data cannot identify any of the fitted parameters")
