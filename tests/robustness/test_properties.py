"""Property-based robustness (issue 13), with hypothesis.

* Mutated configs, parameter sets and shipped ``.tir`` files (random line deletions, duplications,
  cuts, nasty tokens, type swaps, unicode, huge numbers, NaN strings) never give anything but the
  tool's own outcome: success, a clean error (exit 2) or, for ``tir check``, failed checks (exit 1);
  never an internal error or a traceback.
* LuGre steady states, the Magic Formula and the transient solvers give finite outputs for random
  valid inputs, down to v -> 0 and a locked wheel.

Runs in-process through :func:`tirecli.cli.main.main` (one subprocess case checks the real script);
examples are derandomized (reproducible in CI) and few enough that the file takes well under a minute.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from harness import assert_clean_error, run

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples").glob("*.yaml"))
SETS = sorted((ROOT / "tirecli" / "parameters" / "data").glob("*.yaml"))
TIRS = sorted((ROOT / "tirecli" / "parameters" / "data").glob("*.tir")) + sorted((ROOT / "tests" / "data" / "tir").glob("*.tir"))
FAST_EXAMPLES = [p for p in EXAMPLES if p.name not in ("fm-braking2-tight.yaml", "mcps-calibration.yaml")]

#: ``TIRECLI_HYPOTHESIS_SCALE=50`` searches 50 times longer with fresh random examples (a bug hunt);
#: the default is a fixed, reproducible set.
SCALE = max(1, int(os.environ.get("TIRECLI_HYPOTHESIS_SCALE", "1") or 1))
settings.register_profile("tirecli", derandomize=SCALE == 1, database=None, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                                 HealthCheck.filter_too_much])
settings.load_profile("tirecli")

#: Tokens a hostile or careless user puts in a file.
NASTY = ["", " ", ":", ": :", "- ", "-", "[", "]", "{", "}", "{}", "[]", "'", '"', "\t", "#", "|", ">", "?", "~",
         "null", "true", "no", "nan", ".nan", "NaN", "inf", ".inf", "-.inf", "1e999", "-1e999", "1e-400", "9" * 400,
         "-" + "9" * 400, "0x1F", "0o17", "1_000", "2024-13-45", "2001-02-29 25:61:61", "!!binary aGVsbG8=",
         "!!python/name:os.system", "!!python/object/apply:os.system ['true']", "!!str", "!!int x", "!!float x",
         "!foo bar", "é", "\u202e", "日本", "\x85", "\u2028", "%YAML 1.1", "---", "...", "*x", "Z", "x" * 300,
         "[1, [2, [3]]]", "{a: {b: {c: 1}}}", "0", "-1", "1e308", "3.4.5", "1,5", "=", "\\", "\x7f"]

TIR_NASTY = ["", "=", "= =", "'", "''", "'unterminated", "$", "!", "[", "[MODEL", "[]", "[UNITS]", "[MODEL]",
             "nan", "NaN", "inf", "-inf", "1e999", "1D999", "1.0D+03", "9" * 400, "-" + "9" * 400, "0", "-0", "1e-400",
             ".", "1.2.3", "1,5", "{", "{radial width}", "(COMMENTS)", "FITTYP = 99", "FITTYP = 5", "FITTYP = 'x'",
             "PROPERTY_FILE_FORMAT = 'PAC89'", "ANGLE = 'deg'", "LENGTH = 'mm'", "FNOMIN = 0", "FNOMIN = -1",
             "LONGVL = 0", "UNLOADED_RADIUS = 0", "PKY2 = 0", "é", "\xe9", "\x00", "\x1a", "日本", "x" * 300]


def cli(*args) -> tuple[int, str, str]:
    """``tirecli ARGS`` in-process: (exit code, stdout, stderr)."""
    from tirecli.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()


def assert_own_outcome(code: int, err: str, allowed=(0, 2), what: str = "") -> None:
    """Success or one of the tool's own errors: never an internal error, a traceback, or a raw control character."""
    assert "internal error" not in err and "Traceback" not in err, err[-3000:] + what
    assert code in allowed, f"exit {code}: {err[-800:]}"
    if code == 2:
        lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("warning:")]
        assert lines and all(ln.startswith("error: ") for ln in lines), err[-800:]
        assert len(lines) <= 20, f"{len(lines)} error lines"
        assert all(len(ln) <= 1010 for ln in lines)
    assert "\x1b" not in err and "\x00" not in err


@contextlib.contextmanager
def scratch(name: str, data: bytes):
    with tempfile.TemporaryDirectory(prefix="tirecli-prop-") as d:
        p = Path(d) / name
        p.write_bytes(data)
        yield p


# --------------------------------------------------------------------------- text mutations


@st.composite
def text_mutations(draw, text: str, nasty=NASTY, max_ops: int = 3):
    """``text`` with 1-3 random edits: delete, duplicate or swap lines, insert a nasty token, cut the text."""
    lines = text.splitlines(keepends=True) or [""]
    for _ in range(draw(st.integers(1, max_ops))):
        op = draw(st.sampled_from(["delete", "duplicate", "swap", "insert", "replace_value", "cut"]))
        i = draw(st.integers(0, max(len(lines) - 1, 0)))
        if op == "delete" and len(lines) > 1:
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "insert":
            pos = draw(st.integers(0, len(lines[i])))
            lines[i] = lines[i][:pos] + draw(st.sampled_from(nasty)) + lines[i][pos:]
        elif op == "replace_value":  # the value after the first ':' or '='
            line = lines[i]
            cut = max(line.find(":"), line.find("="))
            if cut >= 0:
                end = "\n" if line.endswith("\n") else ""
                lines[i] = line[:cut + 1] + " " + draw(st.sampled_from(nasty)) + end
        elif op == "cut":
            joined = "".join(lines)
            pos = draw(st.integers(0, len(joined)))
            lines = [joined[:pos]]
    return "".join(lines)


@st.composite
def mutated_example(draw, files):
    path = draw(st.sampled_from(files))
    return path, draw(text_mutations(path.read_text(encoding="utf-8")))


@settings(max_examples=40 * SCALE)
@given(mutated_example(FAST_EXAMPLES + SETS))
def test_mutated_yaml_text_gives_a_clean_outcome(case):
    path, text = case
    with scratch(path.name, text.encode("utf-8", "surrogatepass")) as p:
        code, _, err = cli("params", "validate", p)
    assert_own_outcome(code, err)


# --------------------------------------------------------------------------- structural mutations

VALUES = st.one_of(
    st.none(), st.booleans(),
    st.integers(min_value=-10 ** 400, max_value=10 ** 400),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["nan", ".nan", "inf", "1e999", "9" * 400, "2024-13-45", "Z", "-", "", "x" * 200, "é\u202e"]),
    st.lists(st.one_of(st.integers(-5, 5), st.floats(allow_nan=True), st.text(max_size=4)), max_size=3),
    st.dictionaries(st.text(max_size=6), st.one_of(st.integers(-3, 3), st.text(max_size=3)), max_size=2),
)


def _paths(node, prefix=()):
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _paths(v, prefix + (i,))


@st.composite
def mutated_document(draw, files):
    path = draw(st.sampled_from(files))
    doc = yaml.safe_load(path.read_text(encoding="utf-8"))
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p in _paths(doc) if p]
        if not paths:
            break
        target = draw(st.sampled_from(paths))
        parent = doc
        for part in target[:-1]:
            parent = parent[part]
        last = target[-1]
        op = draw(st.sampled_from(["set", "set", "delete", "add_key", "rename"]))
        if op == "set":
            parent[last] = draw(VALUES)
        elif op == "delete":
            del parent[last]
        elif op == "add_key" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=10))] = draw(VALUES)
        elif op == "rename" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["", "x" * 120, last + "s", "é", "1", "null"]))] = parent.pop(last)
    return path, doc


@settings(max_examples=40 * SCALE)
@given(mutated_document(FAST_EXAMPLES + SETS))
def test_mutated_yaml_documents_give_a_clean_outcome(case):
    path, doc = case
    try:
        text = yaml.safe_dump(doc, allow_unicode=True, sort_keys=False)
    except (yaml.YAMLError, ValueError, OverflowError):
        assume(False)
    with scratch(path.name, text.encode("utf-8", "surrogatepass")) as p:
        code, _, err = cli("params", "validate", p)
    assert_own_outcome(code, err)


@settings(max_examples=25 * SCALE)
@given(st.sampled_from(["tire.sigma0", "tire.set", "sweep.speeds", "sweep.slip.num", "sweep.models[0].model",
                        "sweep.models[0].lambda", "title", "figures", "study", "sweep.theta"]),
       st.sampled_from(NASTY))
def test_set_overrides_give_a_clean_outcome(key, value):
    """``--set KEY=VALUE`` with a nasty VALUE: a valid config or a clean error (exit 2)."""
    from tirecli.config.loader import load_config
    from tirecli.errors import TirecliError
    from tirecli.studies.registry import check as check_study

    try:
        check_study(load_config(ROOT / "examples" / "fm-fig1-left.yaml", [f"{key}={value}"]))
    except TirecliError as exc:
        assert exc.exit_code == 2, str(exc)


# --------------------------------------------------------------------------- .tir files


@st.composite
def mutated_tir(draw):
    path = draw(st.sampled_from(TIRS))
    text = path.read_bytes().decode("latin-1")
    out = draw(text_mutations(text, TIR_NASTY, max_ops=4))
    return path, out.encode("latin-1", "replace")


def _diff(path: Path, data: bytes) -> str:
    """The changed lines of a mutated file (for the failure message)."""
    import difflib

    old = path.read_bytes().decode("latin-1").splitlines()
    new = data.decode("latin-1").splitlines()
    return "\n" + "\n".join(list(difflib.unified_diff(old, new, lineterm="", n=0))[2:30])


@settings(max_examples=40 * SCALE)
@given(mutated_tir())
def test_mutated_tir_files_give_a_clean_outcome(case):
    path, data = case
    with scratch(path.name, data) as p:
        code, _, err = cli("tir", "show", p)
        assert_own_outcome(code, err, what=_diff(path, data))
        code, _, err = cli("tir", "check", p)
        assert_own_outcome(code, err, allowed=(0, 1, 2), what=_diff(path, data))
        if code != 2:  # the tyre reads: evaluating it is a result or the tool's own error
            pts = p.with_name("p.csv")
            pts.write_text("kappa,alpha,gamma,fz,vx\n-0.1,0.05,0.01,4000,20\n-1,0,0,4000,0\n0,0,0,0,10\n")
            code, _, err = cli("mf", "eval", p, "--points", pts, "--out", p.with_name("r.csv"))
            assert_own_outcome(code, err, allowed=(0, 1, 2), what=_diff(path, data))


def test_one_mutated_tir_through_the_real_script(tmp_path):
    """The same contract through the installed console script (a truncated, renamed section)."""
    data = TIRS[0].read_bytes()
    bad = data[: len(data) // 2].replace(b"[MODEL]", b"[MODEL")
    (tmp_path / "t.tir").write_bytes(bad)
    r = run(["tir", "check", "t.tir"], cwd=tmp_path, timeout=30)
    assert_clean_error(r, 2, r"t\.tir:\d+: cannot read the section header")


# --------------------------------------------------------------------------- finite outputs


def lugre_params():
    from tirecli.models.lugre import LuGreParams

    @st.composite
    def build(draw):
        mu_c = draw(st.floats(0.05, 1.5))
        return LuGreParams(sigma0=draw(st.floats(1.0, 1e4)), sigma1=draw(st.floats(0.0, 10.0)),
                           sigma2=draw(st.floats(0.0, 0.05)), mu_c=mu_c, mu_s=mu_c * draw(st.floats(1.0, 3.0)),
                           v_s=draw(st.floats(0.1, 50.0)), L=draw(st.floats(0.01, 1.0)), alpha=draw(st.floats(0.2, 3.0)),
                           kappa0=draw(st.floats(0.1, 10.0)), sigma_w=draw(st.floats(0.0, 5.0)))
    return build()


SPEEDS = st.one_of(st.sampled_from([0.0, 1e-300, 1e-12, 1e-6, 0.01]), st.floats(0.0, 80.0))
SLIPS = st.one_of(st.sampled_from([-1.0, -0.999999, 0.0, 1e-15, 0.5, 1.0]), st.floats(-1.0, 1.0))


@settings(max_examples=80 * SCALE)
@given(lugre_params(), SPEEDS, SLIPS, st.floats(0.1, 1.0), st.floats(0.0, 20.0))
def test_lugre_steady_states_are_finite(p, v, s, theta, lam):
    from tirecli.conventions import speeds_from_slip
    from tirecli.models.lugre import mu_ss_density, mu_ss_exponential, mu_ss_lumped, mu_ss_uniform, parabolic_density

    vv, rw = speeds_from_slip(np.array([s]), v)
    vr = rw - vv
    for mu in (mu_ss_uniform(vr, rw, p, theta), mu_ss_lumped(vr, rw, p, "Z", theta), mu_ss_lumped(vr, rw, p, None, theta),
               mu_ss_exponential(vr, rw, p, lam, theta), mu_ss_density(vr, rw, p, parabolic_density, theta)):
        mu = np.asarray(mu, dtype=float)
        assert np.isfinite(mu).all(), (p, v, s, theta, lam, mu)


MF_TIRES = ["pacejka2006-205-60r15", "externdata-205-60r15", "mfeval-255-55r20", "chrono-185-80r14"]


@pytest.fixture(scope="module")
def mf_tires():
    from tirecli.parameters.mf import load_builtin_tire_data

    return {name: load_builtin_tire_data(name).tire() for name in MF_TIRES}


@settings(max_examples=60 * SCALE)
@given(name=st.sampled_from(MF_TIRES),
       kappa=st.one_of(st.sampled_from([-1.0, 0.0, 1.0]), st.floats(-1.0, 1.0)),
       alpha=st.floats(-math.pi / 2 + 1e-6, math.pi / 2 - 1e-6),
       gamma=st.floats(-0.3, 0.3),
       load=st.one_of(st.sampled_from([0.0, 1e-9]), st.floats(0.0, 3.0)),
       vx=SPEEDS,
       convention=st.sampled_from(["mfeval", "teasit"]))
def test_magic_formula_is_finite(mf_tires, name, kappa, alpha, gamma, load, vx, convention):
    from tirecli.models.magic_formula import evaluate

    t = mf_tires[name]
    r = evaluate(t, kappa, alpha, gamma, load * t["FNOMIN"], vx, convention=convention)
    for key, val in r.as_dict().items():
        assert np.isfinite(val).all(), (name, key, kappa, alpha, gamma, load, vx, val)


@pytest.fixture(scope="module")
def quarter_car():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-obs-quarter-car").model()


@settings(max_examples=12 * SCALE)
@given(p=lugre_params(), model=st.sampled_from(["lumped", "distributed"]),
       v0=st.one_of(st.sampled_from([0.12, 0.5]), st.floats(0.2, 40.0)),
       brake=st.one_of(st.sampled_from([0.0, 5e4]), st.floats(0.0, 5e3)),
       theta=st.floats(0.1, 1.0))
def test_quarter_car_brakings_are_finite(quarter_car, p, model, v0, brake, theta):
    """From gentle braking to a locked wheel (a torque far beyond the tire's grip), down to the stop speed."""
    from tirecli.models.profiles import Change, Constant, Transitions
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs

    torque = Transitions(0.0, (Change(0.0, -brake, 0.02, "linear"),))
    tr = runs.quarter_car(FrictionVariant(model), p, quarter_car, torque, Constant(theta), v0, v0 / quarter_car.r, 0.15,
                          runs.SolverOptions(h_max=0.01))
    assert np.isfinite(tr.t).all() and tr.t[-1] <= 0.15 + 1e-12
    assert np.isfinite(tr.y).all(), (model, v0, brake)
    for key in ("mu", "slip"):
        assert np.isfinite(tr.out[key]).all(), (key, model, v0, brake)
    assert (tr.y[:, 1] >= -1e-9).all() and (tr.y[:, 0] >= -1e-9).all()  # the wheel never turns backwards


@settings(max_examples=10 * SCALE)
@given(p=lugre_params(), model=st.sampled_from(["lumped", "distributed"]),
       v0=st.floats(0.5, 30.0), s=st.one_of(st.just(-1.0), st.floats(-1.0, 0.0)))
def test_open_loop_down_to_standstill_is_finite(quarter_car, p, model, v0, s):
    """Prescribed speeds: the vehicle slows to v = 0 with the wheel at slip s (s = -1: locked)."""
    from tirecli.models.profiles import Change, Constant, Transitions
    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics import runs

    v = Transitions(v0, (Change(0.0, 0.0, 0.1, "linear"),))
    omega = Transitions(v0 * (1 + s) / quarter_car.r, (Change(0.0, 0.0, 0.1, "linear"),))
    tr = runs.open_loop(FrictionVariant(model), p, quarter_car, v, omega, Constant(1.0), 0.15, runs.SolverOptions(h_max=0.01))
    assert np.isfinite(tr.y).all(), (model, v0, s)
    assert np.isfinite(tr.out["mu"]).all(), (model, v0, s)
