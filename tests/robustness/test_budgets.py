"""Nothing hangs, nothing exhausts memory (issue 13): formulas, YAML, file sizes, the sample budget, free text.

Each hostile input must be refused with one ``error:`` line and exit 2. One case of each kind goes
through the real ``tirecli`` in a subprocess with a time limit (a hang fails the test; how fast a refusal
is, under 2 s, is measured by ``benchmarks/bench_refusals.py``, not asserted here); the other cases of
the class run the same entry point in-process (``cli``), which keeps this file fast. A refusal must
not even load pandas, scipy or matplotlib. The limits themselves are unit-tested at the end
(:mod:`tirecli.limits`).
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest
from harness import Result, assert_clean_error, assert_unchanged, copy_example, run, snapshot

from tirecli import limits

#: A refusal that has not come after this long hangs (it takes well under 2 s even on a loaded machine).
HANG_SECONDS = 60
TIR = Path(__file__).resolve().parents[1] / "data" / "tir" / "MagicFormula61_Parameters.tir"

SIMULATE = """study: simulate
tire: canudas2003-table2
initial: {v: 20, slip: 0}
input:
  pressure: {expr: "PRESSURE"}
t_end: 1
cases: [lumped]
"""
OBSERVE = """study: observe
tire: canudas2003-table1
scenario: {duration: 5, theta: {expr: "THETA"}, torque: 0, v0: 20}
"""
SWEEP = """study: sweep
tire: canudas2003-table1
sweep: {slip: {start: -1, stop: 0, num: 11}, speeds: [20], models: [lumped]}
"""


def _bomb(levels: int = 9, prefix: str = "study: sweep\n") -> str:
    """A billion-laughs document: 9^levels values from a few hundred bytes."""
    lines = [prefix + 'a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


def _write(tmp_path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def refused(args, pattern, cwd=None):
    """Through the real ``tirecli`` in a subprocess: exit 2, one line matching ``pattern``, no hang."""
    r = run(args, cwd=cwd, timeout=HANG_SECONDS)
    assert_clean_error(r, 2, pattern)
    return r


@pytest.fixture
def refused_here(cli):
    """The same contract through the CLI's entry point in this process (no start-up cost)."""
    def check(args, pattern):
        code, out, err = cli(*args)
        r = Result(code, out, err, 0.0)
        assert_clean_error(r, 2, pattern)
        return r

    return check


# --------------------------------------------------------------------------- formulas


def test_a_formula_bomb_fails_at_once(tmp_path):
    refused(["params", "validate", _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", "9**9**9"))],
            r"s\.yaml:5: input\.pressure\.expr: cannot be evaluated at t = 0 s: a value overflows")


@pytest.mark.parametrize("where, formula, pattern", [
    ("simulate", "(9**9)**(9**9) * t", r"overflow"),
    ("simulate", "1" + "0" * 400, r"a number too large"),
    ("simulate", "sqrt(t, t)", r"takes 1 argument"),
    ("simulate", "+".join(["t"] * 300), r"formula too long"),
    ("simulate", "-" * 400 + "t", r"formula nested too deeply"),            # no RecursionError either
    ("simulate", "*".join(["t"] * 120), r"formula nested too deeply"),
    ("simulate", "-(" * 110 + "t" + ")" * 110, r"formula nested too deeply"),
    ("observe", "1 + 9**9**9**9", r"scenario\.theta\.expr: .*overflow"),
    ("observe", "clip(t, 0)", r"takes 3 arguments"),
])
def test_formula_bombs_are_refused(tmp_path, refused_here, where, formula, pattern):
    text = SIMULATE.replace("PRESSURE", formula) if where == "simulate" else OBSERVE.replace("THETA", formula)
    refused_here(["params", "validate", _write(tmp_path, f"{where}.yaml", text)], pattern)


def test_formula_bombs_in_set_values_and_drives(tmp_path, refused_here):
    cfg = _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", "t"))
    refused_here(["simulate", cfg, "-o", tmp_path / "o", "--set", 'input.pressure={expr: "2**2**2**2**2**2"}'],
                 r"<command line --set>: input\.pressure\.expr: .*overflow")
    refused_here(["simulate", cfg, "-o", tmp_path / "o", "--set",
                  'cases[0]={model: lumped, drive: {v: 20, slip: {expr: "-0.1*(t > 9**9**9)"}}}'],
                 r"cases\[0\]\.drive\.slip\.expr: .*overflow")


def test_a_formula_switching_too_often_is_refused(tmp_path, refused_here):
    cfg = _write(tmp_path, "s.yaml", SIMULATE.replace("PRESSURE", "10*(sin(2*pi*12345.6*t) > 0)"))
    refused(["simulate", cfg, "-o", tmp_path / "o"], r"s\.yaml:5: input\.pressure\.expr: switches .*at most 10,000")
    refused_here(["params", "validate", cfg], r"s\.yaml:5: input\.pressure\.expr: switches")
    obs = _write(tmp_path, "o.yaml", OBSERVE.replace("THETA", "1 - 0.4*(sin(2*pi*1500*t) > 0)"))   # 15,000 in 5 s
    refused_here(["params", "validate", obs, ], r"o\.yaml:3: scenario\.theta\.expr: switches .* in \[0, 5\] s")
    refused_here(["simulate", cfg, "--set", "input.pressure={expr: 'abs(t - 0.5)'}",
                  "--set", "cases[0]={model: lumped, drive: {v: 20, slip: {expr: '-0.1*(sin(2*pi*9000*t) > 0)'}}}"],
                 r"<command line --set>: cases\[0\]\.drive\.slip\.expr: switches")


# --------------------------------------------------------------------------- YAML and files


@pytest.mark.parametrize("name, text, pattern", [
    ("bomb.yaml", _bomb(), r"bomb\.yaml:\d+: more than 20,000 values"),
    ("rec.yaml", "study: sweep\na: &a [1, *a]\n", r"rec\.yaml:2: recursive alias"),
    ("deep.yaml", "study: sweep\nx: " + "[" * 5000 + "]" * 5000 + "\n", r"deep\.yaml:2: nested more than 50 levels"),
    ("flat.yaml", "study: sweep\nx: [" + ",".join(["0"] * 400_000) + "]\n", r"flat\.yaml:2: more than 20,000 values"),
    ("empty.yaml", "study: sweep\nx: [" + ",".join(["[]"] * 30_000) + "]\n", r"empty\.yaml:2: more than 20,000 values"),
    ("anchors.yaml", "study: sweep\nx: [" + ",".join(f"&a{i} 1" for i in range(30_000)) + "]\n", r"more than 20,000"),
])
def test_yaml_bombs_fail_at_once(tmp_path, name, text, pattern):
    refused(["params", "validate", _write(tmp_path, name, text)], pattern)


@pytest.mark.parametrize("name, text, pattern", [
    ("map.yaml", "study: sweep\na: &a {b: {c: *a}}\n", r"map\.yaml:\d: recursive alias"),
    ("chain.yaml", "study: sweep\na0: &a0 [1]\n" + "".join(f"a{i}: &a{i} [*a{i - 1}]\n" for i in range(1, 300)),
     r"nested more than 50"),
    ("big.yaml", "study: sweep\n" + "# padding\n" * 200_000, r"big\.yaml: too large for a YAML file \(2 MB, at most 1 MB\)"),
    ("digits.yaml", "study: sweep\ntitle: 1" + "0" * 5000 + "\n", r"title: cannot read value"),
])
def test_oversized_yaml_is_refused(tmp_path, refused_here, name, text, pattern):
    refused_here(["params", "validate", _write(tmp_path, name, text)], pattern)


def test_yaml_bombs_in_parameter_sets_and_set_values(tmp_path, refused_here):
    _write(tmp_path, "set.yaml", _bomb(prefix="name: x\nkind: lugre\n"))
    cfg = _write(tmp_path, "c.yaml", SWEEP.replace("canudas2003-table1", "{set: set.yaml}"))
    refused_here(["sweep", cfg, "-o", tmp_path / "o"], r"set\.yaml:\d+: more than 20,000 values")
    cfg = _write(tmp_path, "s.yaml", SWEEP)
    refused_here(["sweep", cfg, "--set", "title=" + _bomb(6, "").replace("\n", ", ").join("{}")],
                 r"<command line --set>: title: more than")
    refused_here(["sweep", cfg, "--set", "title=&x [*x]"], r"<command line --set>: title: recursive alias")
    refused_here(["sweep", cfg, "--set", ".".join(["x"] * 5000) + "=1"], r"--set: key too long")


def test_a_huge_tir_file_is_refused(tmp_path):
    big = tmp_path / "big.tir"
    big.write_bytes(TIR.read_bytes() + b"\n[EXTRA]\n" + b"".join(b"X%07d = 1.0\n" % i for i in range(100_000)))
    refused(["tir", "show", big], r"big\.tir: too large for a \.tir file")


# --------------------------------------------------------------------------- the sample budget of every run command


def _over(tmp_path, command, example, sets):
    cfg = copy_example(example, tmp_path)
    return [command, cfg, "-o", tmp_path / "out"] + [a for s in sets for a in ("--set", s)]


@pytest.mark.parametrize("command, example, sets, pattern", [
    ("sweep", "fm-fig1-left.yaml", ["sweep.slip={start: -1, stop: 0, num: 10000}", "sweep.speeds={start: 1, stop: 30, num: 10000}"],
     r"sweep\.(slip|speeds): the sweep \(.*\) would need 100,000,000 samples"),
    ("simulate", "fm-fig4.yaml", ["output.dt=1e-9"], r"output\.dt: the run would need 24,500,0\d\d,\d\d\d samples"),
    ("observe", "obs-fig2.yaml", ["solver.step=1e-15"], r"solver\.step: .*samples"),
    ("compare", "mcps-fig7-9.yaml", ["kappa={start: 0, stop: 0.2, num: 2000000}"], r"kappa\.num: a grid of 2,000,000 points"),
])
def test_runs_over_the_budget_fail_at_once_and_leave_outputs_alone(tmp_path, command, example, sets, pattern):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("previous results")
    before = snapshot(out)
    refused(_over(tmp_path, command, example, sets), pattern, cwd=tmp_path)
    assert_unchanged(before, out)


@pytest.mark.parametrize("command, example, sets, pattern", [
    ("sweep", "fm-fig1-left.yaml", ["sweep.slip.num=1e12"], r"sweep\.slip\.num: a grid of 1,000,000,000,000 points"),
    ("sweep", "mf-sweep-chrono-185-80r14.yaml", ["sweep.loads={start: 1000, stop: 8000, num: 5000}"],
     r"sweep\.loads: .* samples"),
    ("simulate", "fm-fig4.yaml", ["t_end=3600"], r"t_end: .*samples.*budget is 1,000,000"),
    ("simulate", "fm-fig4.yaml", ["solver.h_max=1e-12"], r"solver\.h_max: .*samples"),
    ("simulate", "fm-fig4.yaml", ["measurement.rate=100000", "t_end=3600"], r"samples"),
    ("simulate", "mcps-relaxation.yaml", ["distance=1000"], r"distance: .*samples|element-steps"),
    ("observe", "obs-fig2.yaml", ["measurement.rate=1e9"], r"measurement\.rate: .*samples"),
    ("observe", "obs-fig2.yaml", ["output.dt=1e-12"], r"output\.dt: .*samples"),
    ("observe", "obs-gain-study.yaml", ["scenario.duration=3600"], r"scenario\.duration: .*samples"),
])
def test_runs_over_the_budget_are_refused_with_their_estimate(tmp_path, refused_here, command, example, sets, pattern):
    refused_here(_over(tmp_path, command, example, sets), pattern)
    assert not (tmp_path / "out").exists()


def test_the_refusal_says_how_to_raise_the_budget(tmp_path, refused_here):
    cfg = copy_example("fm-fig4.yaml", tmp_path)
    r = refused_here(["simulate", cfg, "--set", "t_end=300"],
                     r"the budget is 1,000,000 \(raise it with --max-samples (\d+) or run\.max_samples: \1\)")
    assert "GB" in r.err  # the memory estimate
    refused_here(["params", "validate", cfg, "--max-samples", "1000"], r"fm-fig4\.yaml:\d+: t_end: .*budget is 1,000 ")


def test_a_data_file_over_the_budget_is_refused_before_it_is_read(tmp_path, refused_here):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n" + "0.1,0,0,4000\n" * 2000)
    refused(["mf", "eval", "chrono-185-80r14", "--points", pts, "-o", tmp_path / "r.csv", "--max-samples", "1000"],
            r"p\.csv: 2,000 data rows would need 2,000 samples .*budget is 1,000 \(raise it with --max-samples 2000\)$")
    assert not (tmp_path / "r.csv").exists()
    fit = copy_example("fm-fig6.yaml", tmp_path)
    data = tmp_path / "braking.csv"
    data.write_text("t,v,s,mu\n" + "".join(f"{i * 0.01},20,-0.05,-0.5\n" for i in range(2000)))
    refused_here(["fit", fit, "--data", data, "--max-samples", "1e3", "-o", tmp_path / "o"], r"braking\.csv: 2,000 data rows")
    refused_here(["fit", fit, "--data", data, "--max-samples", "10", "-o", tmp_path / "o"],
                 r"too large for a data file .* the cap grows with the sample budget")


def test_data_files_with_huge_lines_or_rows_are_refused_before_they_are_parsed(tmp_path, refused_here):
    pts = tmp_path / "p.csv"
    pts.write_text("kappa,alpha,gamma,fz\n0.1,0,0,4000\n0.1,0,0," + "4" * 20_000 + "\n0.2,0,0,4000\n")
    args = ["mf", "eval", "chrono-185-80r14", "--points", pts, "-o", tmp_path / "r.csv"]
    refused_here(args, r"p\.csv: line 3 is longer than 10,000 bytes")
    pts.write_text("kappa,alpha,gamma,fz\n0.1,0,0," + "4" * 20_000)          # the last line, no newline
    refused_here(args, r"p\.csv: line 2 is longer than 10,000 bytes")
    pts.write_text(",".join(f"c{i}" for i in range(200)) + "\n" + (",".join(["0"] * 200) + "\n") * 1000)
    refused_here(args + ["--max-samples", "5000"],
                 r"p\.csv: 1,000 data rows of 200 columns \(13 samples a row\) would need 13,000 samples")
    refused(["mf", "eval", "chrono-185-80r14", "--points", "/dev/zero", "-o", tmp_path / "r.csv"],
            r"/dev/zero: (line 1 is longer than 10,000 bytes|too large|.*not a regular file)")
    assert not (tmp_path / "r.csv").exists()


def test_running_out_of_memory_is_one_clean_line(tmp_path, cli, monkeypatch):
    """Within the budget the estimates should leave room, but a MemoryError is never a traceback."""
    from tirecli.studies import sweep

    def exhausted(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(sweep, "sweep_frame", exhausted)
    out = tmp_path / "o"
    out.mkdir()
    (out / "keep.txt").write_text("previous results")
    before = snapshot(out)
    code, _, err = cli("sweep", _write(tmp_path, "s.yaml", SWEEP), "-o", out)
    assert_clean_error(Result(code, "", err, 0.0), 2, r"^error: out of memory: .*make it smaller")
    assert_unchanged(before, out)


@pytest.mark.parametrize("args", [
    ["simulate", "fm-fig4.yaml", "--set", "t_end=3600"],
    ["observe", "obs-fig2.yaml", "--set", "solver.step=1e-12"],
    ["compare", "mcps-fig7-9.yaml", "--set", "kappa={start: 0, stop: 0.2, num: 2000000}"],
    ["fit", "fm-fig6.yaml", "--max-samples", "10"],
    ["params", "validate", "mcps-relaxation.yaml", "--max-samples", "100"],
])
def test_a_refusal_loads_no_heavy_library(tmp_path, args):
    """A refused run fails before pandas, scipy or matplotlib are imported (each takes a good part of a
    second to load): the checks and estimates need numpy only."""
    import subprocess
    import sys

    cmd = [str(copy_example(a, tmp_path)) if a.endswith(".yaml") else a for a in args]
    if args[0] != "params":
        cmd += ["-o", str(tmp_path / "o")]
    code = ("import sys\nfrom tirecli.cli.main import main\nc = main(sys.argv[1:])\n"
            "print(c, sorted(m for m in ('pandas', 'scipy', 'matplotlib') if m in sys.modules))")
    p = subprocess.run([sys.executable, "-c", code] + cmd, capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert p.stdout.strip() == "2 []", (p.stdout, p.stderr[-500:])


@pytest.mark.parametrize("value", ["0", "-5", "1.5", "lots", "1e400", "2e12"])
def test_bad_max_samples_values_are_refused(tmp_path, refused_here, value):
    refused_here(["sweep", _write(tmp_path, "s.yaml", SWEEP), "--max-samples", value], r"--max-samples .*whole number")


def test_a_run_within_the_budget_works_and_one_sample_more_is_refused(tmp_path, cli, refused_here):
    cfg = _write(tmp_path, "s.yaml", SWEEP)   # 11 slips x 1 speed x 1 model: 11 rows (the 1 peak row is not counted)
    refused_here(["sweep", cfg, "--max-samples", "10", "-o", tmp_path / "a"], r"would need 11 samples")
    refused_here(["sweep", cfg, "--set", "run.max_samples=10", "-o", tmp_path / "a"], r"s\.yaml:3: sweep\.slip(\.num)?: ")
    code, _, err = cli("sweep", cfg, "--set", "run.max_samples=10", "--max-samples", "11", "-o", tmp_path / "b")
    assert code == 0, err
    assert (tmp_path / "b" / "data" / "sweep.csv").read_text().count("\n") == 12


# --------------------------------------------------------------------------- campaigns


def _mc(tmp_path, n: int, budget: str | None = None) -> Path:
    """The FM Fig. 4 Monte Carlo example with ``n`` samples (and the file's ``run:`` budget replaced by ``budget``)."""
    text = (Path(__file__).resolve().parents[2] / "examples" / "campaign-fm-fig4-mc.yaml").read_text(encoding="utf-8")
    text = text.replace("base: fm-fig4.yaml", "base: fm-fig4").replace("\n  n: 1000\n", f"\n  n: {n}\n")
    text = "\n".join(ln for ln in text.splitlines() if not ln.startswith("run:")) + "\n"
    return _write(tmp_path, "mc.yaml", text + (f"run: {{max_samples: {budget}}}\n" if budget else ""))


@pytest.mark.parametrize("command, n", [("campaign", 10_000_000), ("params validate", 2_000_000)])
def test_a_campaign_counts_its_points_against_the_budget(tmp_path, command, n):
    """Points x the samples of one run, estimated before the design is made (a design of 10^7 points was built
    and checked for minutes); the refusal names the estimate and the option that raises it."""
    cfg = _mc(tmp_path, n)
    args = [*command.split(), cfg] + (["-o", tmp_path / "o"] if command == "campaign" else [])
    refused(args, rf"mc\.yaml:\d+: sample\.n: {n:,} point\(s\) x ([\d,]+) samples per run would need [\d,]+ samples; "
                  r"the budget is 1,000,000 \(raise it with --max-samples (\d+) or run\.max_samples: \2\)", cwd=tmp_path)
    assert not (tmp_path / "o").exists()


def test_the_campaign_budget_is_raised_by_its_file_or_the_option(tmp_path, cli, refused_here):
    from tirecli.campaign.spec import load_campaign

    cfg = _mc(tmp_path, 300)
    r = refused_here(["params", "validate", cfg], r"sample\.n: 300 point\(s\) x ([\d,]+) samples per run would need")
    per_run = int(r.err.split(" x ")[1].split(" ")[0].replace(",", ""))
    assert 100 < per_run < 100_000  # a braking of a few seconds, as its simulate estimates it
    enough = str(300 * per_run)
    assert load_campaign(cfg, max_samples=int(enough)).max_samples == int(enough)
    refused_here(["params", "validate", _mc(tmp_path, 300, str(300 * per_run - 1))], rf"the budget is {300 * per_run - 1:,}")
    assert load_campaign(_mc(tmp_path, 300, enough)).max_samples == int(enough)
    # a grid counts the same way, before its points are made
    grid = _write(tmp_path, "g.yaml", "campaign: g\nbase: fm-fig1-left\nvary: {tire.mu_s: {start: 1, stop: 2, num: 5000}, "
                                      "tire.mu_c: {start: 0.5, stop: 0.9, num: 300}}\noutputs: [x]\n")
    refused_here(["campaign", grid, "-o", tmp_path / "o", "--max-samples", "10000"],
                 r"g\.yaml:3: vary: 1,500,000 point\(s\) x [\d,]+ samples per run would need [\d,]+ samples; the budget is 10,000 ")


# --------------------------------------------------------------------------- free text


def test_a_huge_title_fails_at_once(tmp_path):
    refused(["sweep", _write(tmp_path, "s.yaml", SWEEP), "--set", "title=" + "x" * 100_000],
            r"<command line --set>: title: too long: 100,000 characters")


@pytest.mark.parametrize("text, pattern", [
    ("title: " + "T" * 300, r"title: too long: 300 characters \(at most 200\)"),
    ("description: " + "d" * 5000, r"description: too long: 5,000 characters \(at most 2,000\)"),
    ("assumed: [" + "a" * 3000 + "]", r"assumed\[0\]: too long: 3,000 characters"),
    ("? " + "k" * 5000 + "\n: 1", r"a key of 5,000 characters \(at most 1,000\)"),   # an explicit key: no YAML limit
])
def test_long_free_text_is_refused(tmp_path, refused_here, text, pattern):
    refused_here(["params", "validate", _write(tmp_path, "t.yaml", SWEEP + text + "\n")], pattern)


def test_long_labels_and_citations_are_refused(tmp_path, refused_here):
    refused_here(["sweep", _write(tmp_path, "s.yaml", SWEEP), "--set",
                  "sweep.models=[{model: lumped, label: " + "L" * 1000 + "}]"],
                 r"sweep\.models\[0\]\.label: too long: 1,000 characters \(at most 200\)")
    pset = _write(tmp_path, "set.yaml", "name: x\nkind: lugre\ncitation: " + "c" * 5000 + "\nvalues: {sigma0: 1}\n")
    refused_here(["params", "validate", pset], r"citation: too long")


# --------------------------------------------------------------------------- unit tests of the limits


def test_steps_never_overflow():
    assert limits.steps(3.5, 1e-3) == 3501
    assert limits.steps(3600, 1e-9) == pytest.approx(3.6e12 + 1)
    assert limits.steps(1e308, 1e-308) == math.inf
    assert limits.steps(1.0, 0.0) == math.inf
    assert limits.steps(0.0, 1e-9) == 1


def test_texts_of_counts_and_sizes():
    assert limits.count_text(3_600_001) == "3,600,001"
    assert limits.count_text(2.5e16) == "2.5e+16"
    assert limits.count_text(math.inf) == "infinitely many"
    assert limits.bytes_text(1.4e9) == "~1.4 GB"
    assert limits.bytes_text(5.6e10) == "~56 GB"
    assert limits._round_up(3_688_027) == "3700000"
    assert limits._round_up(12) == "12"


def test_parse_max_samples():
    assert limits.parse_max_samples("2e6") == 2_000_000
    assert limits.parse_max_samples("2_000_000") == 2_000_000
    assert limits.parse_max_samples(None) is None
    for bad in ("0", "1.5", "x", "1e13", "nan", "inf"):
        with pytest.raises(limits.UsageError):
            limits.parse_max_samples(bad)


def test_estimate_blames_the_largest_term_at_the_key_the_user_gave():
    from tirecli.errors import ConfigError
    from tirecli.io.yamlio import parse_yaml

    _, origins = parse_yaml("t_end: 10\noutput: {dt: 1.0e-6}\n", "c.yaml")
    est = (limits.Estimate().add(10, (("solver", "h_max"), ("t_end",)), "the steps", 100)
           .add(limits.steps(10, 1e-6), (("output", "dt"), ("t_end",)), "the rows", 100))
    with limits.budget(1000):
        with pytest.raises(ConfigError) as err:
            est.check(origins)
    msg = str(err.value)
    assert msg.startswith("c.yaml:2: output.dt: the run would need 10,000,011 samples (~1 GB), 10,000,001 of them for the rows")
    assert msg.endswith("the budget is 1,000 (raise it with --max-samples 11000000 or run.max_samples: 11000000)")
    with limits.budget(20_000_000):
        est.check(origins)   # within the budget (and the memory of any test machine)
    assert limits.max_samples() == limits.DEFAULT_MAX_SAMPLES


def test_estimate_refuses_what_cannot_fit_in_memory(monkeypatch):
    monkeypatch.setattr(limits, "available_memory", lambda: 4e9)
    est = limits.Estimate().add(5e6, ((),), "the rows", 1000)
    with limits.budget(10**9):
        problem = est.problem(None, "x.yaml")
    assert problem is not None and "more than the 4 GB of memory available" in problem.message
    assert "make it smaller" in problem.message and "--max-samples" not in problem.message


def test_yaml_limits_in_process():
    from tirecli.errors import ConfigError
    from tirecli.io.yamlio import load_value, parse_yaml

    for text, what in ((_bomb(), "more than 20,000 values"), ("a: &a [*a]", "recursive alias"),
                       ("a: " + "[" * 60 + "]" * 60, "nested more than 50"),
                       ("a: &a {b: [1, *a]}", "recursive alias")):
        with pytest.raises(ConfigError, match=what):
            parse_yaml(text, "x.yaml")
    assert parse_yaml("a: &a [1, 2]\nb: [*a, *a]\n", "x.yaml")[0] == {"a": [1, 2], "b": [[1, 2], [1, 2]]}
    assert load_value("[1, 2.5e3, x]") == [1, 2500.0, "x"]
    with pytest.raises(ConfigError, match=r"<command line --set>: k: recursive alias"):
        load_value("&a [*a]", path=("k",))


def test_formula_sandbox_evaluates_in_floats():
    from tirecli.errors import UsageError
    from tirecli.models.profiles import Expression, expression_problem, switch_times

    assert expression_problem("9**9**9") is None            # admissible, but evaluated in floats:
    with pytest.raises(UsageError, match="overflow"):
        Expression("9**9**9")(0.0)
    assert Expression("2**10 + t")(1.0) == 1025.0
    assert Expression("7 % 3")(0.0) == 1.0
    assert "too long" in expression_problem("t+" * 300 + "t")
    assert "argument" in expression_problem("sin(t, t)")
    assert "too large" in expression_problem("1" + "0" * 400)
    assert expression_problem("'a' * 10**9") == "only numbers are allowed as constants"
    with pytest.raises(UsageError, match="switches"):
        switch_times("sign(sin(2*pi*1234567.8*t))", 10.0)
    assert switch_times("t > 1", 2.0) == pytest.approx((1.0,))


def test_schema_caps_text_and_huge_integers():
    from tirecli.config.schema import Context, Num, Str
    from tirecli.io.yamlio import Origins

    ctx = Context(Origins())
    assert Str().check("x" * limits.MAX_TEXT_CHARS, ("k",), ctx) == "x" * limits.MAX_TEXT_CHARS
    assert Str(max_len=5).check("abcdef", ("k",), ctx) is not None and "too long" in ctx.problems[-1].message
    Num(integer=True).check(10**400, ("n",), ctx)
    assert "finite" in ctx.problems[-1].message


def test_the_mcps_compute_caps_grow_with_the_sample_budget(tmp_path, refused_here, cli):
    """The MCPS studies' fixed caps (curvature points, element-steps, ...) scale with ``--max-samples``."""
    cfg = copy_example("mcps-fig7-9.yaml", tmp_path)
    text = Path(cfg).read_text(encoding="utf-8").replace("calibrate: true", "calibrate: false")
    Path(cfg).write_text(text + "curvature: {start: 0, stop: 0.1, num: 3000}\n", encoding="utf-8")
    refused_here(["params", "validate", cfg],
                 r"6000 curvature points .* budget of 5000 .*raise --max-samples or run\.max_samples; the cap scales")
    code, out, err = cli("params", "validate", cfg, "--max-samples", "2e6")
    assert code == 0, err
    with limits.budget(3 * limits.DEFAULT_MAX_SAMPLES):
        assert limits.compute_cap(5000) == 15000
    assert limits.compute_cap(5000) == 5000
    with limits.budget(10):  # a lowered budget never lowers a cap below its default
        assert limits.compute_cap(5000) == 5000
