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

import pytest
from harness import Result, assert_clean_error, copy_example, run

from tirecli import limits

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
    r = refused_here(["simulate", cfg, "-o", tmp_path / "o"],
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
