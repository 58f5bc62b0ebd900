"""What a CI pipeline reads: ``--junit FILE`` (JUnit XML, one test case per reference check),
``--strict`` on every command with checks, and summary.json / run.json against the JSON Schemas
shipped in the package (docs/ci.md)."""
from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from importlib import resources

import pytest

from conftest import EXAMPLES

SWEEP = EXAMPLES / "fm-fig1-right.yaml"  # a sweep with 13 reference checks (fm-fig1-right)


@pytest.fixture
def no_render(monkeypatch):
    """Figures drawn but not rendered to PNG/SVG (most of a run's time; nothing here looks at them)."""
    from tirecli.io import output

    monkeypatch.setattr(output, "save_figure", lambda fig, *a, **k: [])


def junit_cases(path) -> tuple[ET.Element, list[ET.Element]]:
    """Parse a JUnit file and check the structure the common JUnit schema (Jenkins' junit-10.xsd,
    which GitLab and the GitHub actions read too) expects; the root and every test case."""
    root = ET.parse(path).getroot()
    assert root.tag == "testsuites"
    cases = []
    for attr in ("tests", "failures", "errors"):
        assert int(root.get(attr)) >= 0
    float(root.get("time"))
    suites = list(root)
    assert suites and all(s.tag == "testsuite" for s in suites)
    for suite in suites:
        assert suite.get("name")
        own = list(suite)
        assert all(c.tag == "testcase" for c in own), [c.tag for c in own]
        assert int(suite.get("tests")) == len(own)
        assert int(suite.get("failures")) == sum(c.find("failure") is not None for c in own)
        assert int(suite.get("errors")) == sum(c.find("error") is not None for c in own)
        assert int(suite.get("skipped")) == 0
        assert float(suite.get("time")) >= 0
        assert len(suite.get("timestamp")) == 19  # xs:dateTime without a zone: 2024-01-31T12:00:00
        for case in own:
            assert case.get("classname") and case.get("name")
            assert float(case.get("time")) >= 0
            for child in case:
                assert child.tag in ("failure", "error", "system-out"), child.tag
                if child.tag in ("failure", "error"):
                    assert child.get("message") and child.get("type")
        cases += own
    for attr in ("tests", "failures", "errors"):
        assert int(root.get(attr)) == sum(int(s.get(attr)) for s in suites)
    return root, cases


def schema(name: str) -> dict:
    return json.loads(resources.files("tirecli").joinpath("schemas", f"{name}.schema.json").read_text(encoding="utf-8"))


def validate(instance, name: str) -> None:
    jsonschema = pytest.importorskip("jsonschema")  # the test extra: pip install '.[test]'
    sch = schema(name)
    jsonschema.Draft202012Validator.check_schema(sch)
    errors = sorted(jsonschema.Draft202012Validator(sch).iter_errors(instance), key=lambda e: list(e.path))
    assert not errors, "\n".join(f"{'/'.join(map(str, e.path))}: {e.message}" for e in errors[:10])


# --------------------------------------------------------------------------- run commands


def test_sweep_junit_has_one_case_per_check_and_validates_run_json(cli, tmp_path, no_render):
    out, junit = tmp_path / "out", tmp_path / "ci" / "junit.xml"  # a missing folder is created
    code, stdout, err = cli("sweep", SWEEP, "--out", out, "--junit", junit, "--strict")
    assert code == 0, err
    assert f"wrote {junit}" in stdout
    run = json.loads((out / "run.json").read_text())
    validate(run, "run")
    root, cases = junit_cases(junit)
    assert root.get("failures") == "0" and root.get("errors") == "0"
    assert [(c.get("classname"), c.get("name")) for c in cases] == \
        [("fm-fig1-right", "run")] + [tuple(c["id"].split("/", 1)) for c in run["checks"]]
    first = next(c for c in cases if c.get("name") == run["checks"][0]["id"].split("/", 1)[1])
    text = first.find("system-out").text
    check = run["checks"][0]
    for key in ("description", "source"):
        assert f"{key}: {check[key]}" in text
    assert f"reference: {check['reference']:.6g}" in text and f"tolerance: {check['tolerance']:.6g}" in text
    assert not [p.name for p in junit.parent.iterdir() if p.name != "junit.xml"]  # no temporary file left


def test_failed_checks_are_junit_failures_and_strict_exits_1(cli, tmp_path, no_render):
    out, junit = tmp_path / "out", tmp_path / "junit.xml"
    code, stdout, err = cli("sweep", SWEEP, "--out", out, "--junit", junit, "--set", "tire.alpha=2")
    assert code == 0, err  # without --strict failed checks do not change the exit code
    run = json.loads((out / "run.json").read_text())
    failed = [c for c in run["checks"] if not c["passed"]]
    assert failed
    root, cases = junit_cases(junit)
    assert int(root.get("failures")) == len(failed) and root.get("errors") == "0"
    by_name = {(c.get("classname"), c.get("name")): c for c in cases}
    for chk in failed:
        fail = by_name[tuple(chk["id"].split("/", 1))].find("failure")
        msg = fail.get("message")
        assert chk["description"] in msg
        assert f"value {chk['value']:.6g}" in msg and f"reference {chk['reference']:.6g}" in msg
        assert f"tolerance {chk['tolerance']:.6g}" in msg and f"source: {chk['source']}" in fail.text

    code, stdout, err = cli("sweep", SWEEP, "--out", out, "--junit", junit, "--set", "tire.alpha=2", "--strict")
    assert code == 1
    assert f"error: {len(failed)} of {len(run['checks'])} reference check(s) failed (--strict)" in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert (out / "run.json").exists() and junit_cases(junit)[0].get("failures") == str(len(failed))


@pytest.mark.parametrize("command", ["sweep", "simulate", "observe", "compare", "fit"])
def test_every_run_command_takes_strict_and_junit(command):
    from doc_commands import parse

    path, params = parse([command, "c.yaml", "--strict", "--junit", "ci/j.xml"])
    assert path == [command] and params["strict"] is True and params["junit"] == "ci/j.xml"


def test_observe_strict_junit_with_a_drifted_reference(cli, tmp_path, monkeypatch, no_render):
    """A drifted OBS Fig. 2 reference: --strict exits 1 and the JUnit file has the check as a failure
    beside the passing run case."""
    from tirecli.studies.checks import observer

    monkeypatch.setitem(observer.FIG2_THETA_HAT, 8.0, (1.70, 3e-4))
    junit = tmp_path / "obs.xml"
    code, out, err = cli("--quiet", "observe", EXAMPLES / "obs-fig2.yaml", "--out", tmp_path / "out",
                         "--strict", "--junit", junit)
    assert code == 1 and "error: 1 of " in err and "reference check(s) failed (--strict)" in err
    root, cases = junit_cases(junit)
    assert root.get("failures") == "1" and root.get("errors") == "0"
    assert (cases[0].get("classname"), cases[0].get("name")) == ("obs-fig2", "run")
    assert [(c.get("classname"), c.get("name")) for c in cases if c.find("failure") is not None] == \
        [("obs-fig2", "theta-hat-8s")]


@pytest.mark.parametrize("exc, code", [("run", 1), ("internal", 1)])
def test_a_failed_run_is_a_junit_error(cli, tmp_path, monkeypatch, exc, code):
    from tirecli.app import run
    from tirecli.errors import RunError

    def broken(config, *args, **kw):
        raise RunError("the solver did not converge") if exc == "run" else ZeroDivisionError("boom")

    monkeypatch.setattr(run, "execute", broken)
    junit = tmp_path / "junit.xml"
    rc, stdout, err = cli("simulate", EXAMPLES / "fm-fig4.yaml", "--out", tmp_path / "out", "--junit", junit)
    assert rc == code
    root, cases = junit_cases(junit)
    assert root.get("errors") == "1" and root.get("failures") == "0"
    (case,) = cases
    assert (case.get("classname"), case.get("name")) == ("fm-fig4", "run")
    error = case.find("error")
    assert ("the solver did not converge" if exc == "run" else "ZeroDivisionError: boom") in error.get("message")
    assert not (tmp_path / "out").exists()


def test_bad_junit_targets_are_usage_errors_before_the_run(cli, tmp_path):
    (tmp_path / "dir").mkdir()
    cfg = tmp_path / "c.yaml"
    cfg.write_text(SWEEP.read_text())
    before = cfg.read_bytes()
    for target, words in ((tmp_path / "dir", "is a directory"), ("", "empty"), (cfg, "an input of this run")):
        code, out, err = cli("sweep", cfg, "--out", tmp_path / "out", "--junit", target)
        assert code == 2 and words in err and err.count("\n") == 1, err
    assert cfg.read_bytes() == before and not (tmp_path / "out").exists()  # refused before the run
    code, out, err = cli("report", "--out", tmp_path / "rep", "--junit", tmp_path / "dir")
    assert code == 2 and "is a directory" in err and not (tmp_path / "rep").exists()


def test_junit_never_replaces_an_output_of_the_run(cli, tmp_path, no_render, monkeypatch):
    """``--junit OUT/run.json`` replaced the run's run.json with the JUnit XML (exit 0). A --junit on a
    file the run writes (or in a folder it writes into) is refused: before the run when --out names
    the folder (report, campaign, run commands), after it when the folder is the default one (the
    run's files are kept, exit 2)."""
    out = tmp_path / "out"
    for command, cfg, target in (("sweep", SWEEP, out / "run.json"), ("sweep", SWEEP, out / "data" / "sweep.csv"),
                                 ("fit", EXAMPLES / "fm-fig6.yaml", out / "fitted.yaml")):  # a file of the fit study
        code, _, err = cli(command, cfg, "--out", out, "--junit", target)
        assert code == 2 and "an output of this run" in err and err.count("\n") == 1, err
        assert not out.exists()  # refused before the run
    code, _, err = cli("report", "--out", tmp_path / "rep", "--junit", tmp_path / "rep" / "summary.json")
    assert code == 2 and "an output of this run" in err and not (tmp_path / "rep").exists()
    code, _, err = cli("campaign", EXAMPLES / "campaign-mf-fy.yaml", "--out", tmp_path / "camp",
                       "--junit", tmp_path / "camp" / "results.csv")
    assert code == 2 and "an output of this run" in err and not (tmp_path / "camp").exists()
    # the default folder: known once the config is loaded; the run is kept, the JUnit file not written
    monkeypatch.chdir(tmp_path)
    run_json = tmp_path / "tirecli-out" / "sweep-fm-fig1-right" / "run.json"
    code, _, err = cli("sweep", SWEEP, "--junit", run_json)
    assert code == 2 and "an output of this run" in err and "the results are in" in err, err
    assert json.loads(run_json.read_text())["study"] == "sweep"
    # beside the outputs is fine
    code, _, err = cli("sweep", SWEEP, "--out", out, "--junit", out / "junit.xml")
    assert code == 0, err
    assert json.loads((out / "run.json").read_text())["study"] == "sweep" and junit_cases(out / "junit.xml")


def test_junit_is_written_atomically(tmp_path, monkeypatch):
    """A failure while writing leaves the earlier file as it was, no temporary file, and one error line."""
    from tirecli.errors import UsageError
    from tirecli.io import atomic
    from tirecli.io import junit as jx

    path = tmp_path / "j.xml"
    jx.write(path, [jx.checks_suite("s", [])], "tirecli test")
    before = path.read_bytes()

    def full(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(atomic.os, "replace", full)
    with pytest.raises(UsageError, match="cannot write it .No space left on device.; the results are in DIR"):
        jx.write(path, [jx.checks_suite("s", [{"id": "f/c", "passed": True}])], "tirecli test",
                 done="the results are in DIR")
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["j.xml"]


def test_junit_text_is_valid_xml_whatever_the_messages(tmp_path):
    from tirecli.io import junit as jx

    record = {"id": "fig/odd", "description": 'a <b> & "c"\x01', "value": float("nan"), "reference": 1.0,
              "tolerance": 0.1, "deviation": float("nan"), "unit": "N", "source": "x", "passed": False, "bound": "max"}
    path = jx.write(tmp_path / "j.xml", [jx.checks_suite("s", [record])], "tirecli test")
    root, (case,) = junit_cases(path)
    msg = case.find("failure").get("message")
    assert 'a <b> & "c"?' in msg and "value nan N vs upper bound 1 N" in msg


# --------------------------------------------------------------------------- the report


def test_report_junit_and_summary_schema(cli, tmp_path):
    out, junit = tmp_path / "rep", tmp_path / "report.xml"
    code, stdout, err = cli("--quiet", "report", "--out", out, "--only", "fm-table1", "--only", "fm-fig1-right",
                            "--strict", "--junit", junit)
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    validate(summary, "summary")
    root, cases = junit_cases(junit)
    assert int(root.get("tests")) == summary["n_checks"] == len(cases)
    assert [s.get("name") for s in root] == ["report FM"]
    assert [f"{c.get('classname')}/{c.get('name')}" for c in cases] == [c["id"] for c in summary["checks"]]


def test_report_strict_and_junit_with_a_drifted_check(cli, tmp_path, monkeypatch):
    from tirecli.studies.checks import steady

    monkeypatch.setitem(steady._REF_SPEEDS, 20, (1.20, 0.212, 0.6451, 0.8717))  # a drifted reference
    junit = tmp_path / "report.xml"
    code, out, err = cli("report", "--out", tmp_path / "rep", "--only", "fm-fig1-left", "--strict", "--junit", junit)
    assert code == 1 and "reference check(s) failed (--strict)" in err
    root, cases = junit_cases(junit)
    failed = [c for c in cases if c.find("failure") is not None]
    assert [(c.get("classname"), c.get("name")) for c in failed] == [("fm-fig1-left", "peak-v20")]
    assert "reference 1.2 " in failed[0].find("failure").get("message")


# --------------------------------------------------------------------------- the schemas


def test_schemas_are_shipped_and_share_the_check_record():
    jsonschema = pytest.importorskip("jsonschema")
    summary, run = schema("summary"), schema("run")
    for sch in (summary, run):
        jsonschema.Draft202012Validator.check_schema(sch)
    assert summary["$defs"]["check"] == run["$defs"]["check"]
    assert summary["$defs"]["environment"] == run["$defs"]["environment"]


def test_check_records_match_the_schema():
    """A check record of every kind (bounds, a value that is not finite) is what the schema describes."""
    from tirecli.io.output import _jsonable
    from tirecli.studies.base import Check

    defs = schema("summary")["$defs"]
    for chk in (Check("c", "d", 1.0, 1.0, 0.1), Check("c", "d", 2.0, 1.0, 0.1, "N", "src", bound="max"),
                Check("c", "d", float("nan"), 1.0, 0.1, bound="min")):
        chk.id = f"fig/{chk.id}"
        _validate_check(_jsonable(chk.record()), defs)


def _validate_check(record: dict, defs: dict) -> None:
    jsonschema = pytest.importorskip("jsonschema")
    sch = {"$schema": "https://json-schema.org/draft/2020-12/schema", "$ref": "#/$defs/check", "$defs": defs}
    errors = list(jsonschema.Draft202012Validator(sch).iter_errors(record))
    assert not errors, [e.message for e in errors]
