"""JUnit XML of the reference checks (``--junit FILE``), for the test reports of CI systems.

GitLab, GitHub (through a test-report action) and Jenkins read the JUnit XML format: one
``<testsuites>`` holding ``<testsuite>`` elements (``name``, ``tests``, ``failures``, ``errors``,
``skipped``, ``time``, ``timestamp``), each holding ``<testcase>`` elements (``classname``,
``name``, ``time``). tirecli writes one test case per reference check: ``classname`` is the figure
id (the part of the check id before ``/``), ``name`` the check's name; a failed check carries a
``<failure>`` whose message gives the value, the reference and the tolerance, and every case's
``<system-out>`` lists the check's description, value, reference, tolerance, deviation, unit and
source. A run command (``sweep``, ``simulate``, ...) adds a case ``run`` (classname: the study)
for the run itself, which holds an ``<error>`` when the run failed.

The file is written like every output (:func:`tirecli.io.atomic.atomic_write`): complete or not at all.
"""
from __future__ import annotations

import math
import os
import re
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from tirecli.errors import UsageError
from tirecli.io.atomic import atomic_write
from tirecli.io.files import inputs_read

#: Characters XML 1.0 does not allow (a traceback or a file name may carry them).
_ILLEGAL = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ufffe\uffff]")


@dataclass
class Case:
    """One ``<testcase>``: ``failure`` / ``error`` hold the message of a failed check / run."""

    classname: str
    name: str
    time: float = 0.0
    output: str = ""
    failure: str | None = None
    error: str | None = None
    error_type: str = "RunError"


@dataclass
class Suite:
    """One ``<testsuite>`` of cases."""

    name: str
    cases: list[Case] = field(default_factory=list)
    time: float = 0.0


def _num(x) -> str:
    if x is None:
        return "n/a"
    try:
        f = float(x)
    except (TypeError, ValueError):
        return str(x)
    return f"{f:.6g}" if math.isfinite(f) else str(f)


def check_case(record: dict, default_class: str = "checks") -> Case:
    """The test case of a check record (:meth:`tirecli.studies.base.Check.record`)."""
    cid = str(record.get("id", ""))
    classname, _, name = cid.rpartition("/")
    unit = record.get("unit") or "-"
    unit_txt = "" if unit == "-" else f" {unit}"
    bound = record.get("bound", "abs")
    ref = {"max": "upper bound", "min": "lower bound"}.get(bound, "reference")
    message = (f"{record.get('description', cid)}: value {_num(record.get('value'))}{unit_txt} vs {ref} "
               f"{_num(record.get('reference'))}{unit_txt} (tolerance {_num(record.get('tolerance'))}, "
               f"deviation {_num(record.get('deviation'))})")
    lines = [f"{key}: {_num(record.get(key)) if key in ('value', 'reference', 'tolerance', 'deviation') else record.get(key)}"
             for key in ("description", "value", "reference", "tolerance", "deviation", "unit", "source")
             if key in record]
    lines.append(f"bound: {bound} ("
                 + {"max": "passes when value <= reference + tolerance",
                    "min": "passes when value >= reference - tolerance"}.get(bound, "passes when |value - reference| <= tolerance")
                 + ")")
    lines.append(f"passed: {'yes' if record.get('passed') else 'no'}")
    return Case(classname=classname or default_class, name=name or cid, output="\n".join(lines),
                failure=None if record.get("passed") else message)


def checks_suite(name: str, records: list[dict], time_s: float = 0.0, first: Case | None = None) -> Suite:
    """A suite of the check records (``first``: a case before them, e.g. the run itself)."""
    return Suite(name=name, cases=([first] if first else []) + [check_case(r) for r in records], time=time_s)


def to_xml(suites: list[Suite], name: str) -> str:
    """The JUnit XML document of ``suites`` (``<testsuites name=NAME>``)."""
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S")
    root = ET.Element("testsuites")
    totals = {"tests": 0, "failures": 0, "errors": 0}
    for suite in suites:
        n_fail = sum(c.failure is not None and c.error is None for c in suite.cases)
        n_err = sum(c.error is not None for c in suite.cases)
        el = ET.SubElement(root, "testsuite", {
            "name": _clean(suite.name), "tests": str(len(suite.cases)), "failures": str(n_fail),
            "errors": str(n_err), "skipped": "0", "time": f"{suite.time:.3f}", "timestamp": stamp})
        for case in suite.cases:
            tc = ET.SubElement(el, "testcase", {"classname": _clean(case.classname), "name": _clean(case.name),
                                                "time": f"{case.time:.3f}"})
            if case.error is not None:
                ET.SubElement(tc, "error", {"message": _clean(case.error.splitlines()[0] if case.error else ""),
                                            "type": case.error_type}).text = _clean(case.error)
            elif case.failure is not None:
                ET.SubElement(tc, "failure", {"message": _clean(case.failure), "type": "reference check"}
                              ).text = _clean(case.output)
            if case.output and case.failure is None:  # a failure carries the details itself
                ET.SubElement(tc, "system-out").text = _clean(case.output)
        totals["tests"] += len(suite.cases)
        totals["failures"] += n_fail
        totals["errors"] += n_err
    root.attrib.update({"name": _clean(name), **{k: str(v) for k, v in totals.items()},
                        "time": f"{sum(s.time for s in suites):.3f}"})
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _clean(text: str) -> str:
    return _ILLEGAL.sub("?", str(text))


def _written_by_run(path, outputs) -> str | None:
    """The entry of ``outputs`` (files the run writes, or folders it writes into) that ``path`` is
    or lies in, else None."""
    real = os.path.realpath(path)
    for o in outputs:
        ro = os.path.realpath(o)
        if real == ro or real.startswith(ro.rstrip(os.sep) + os.sep):
            return str(o)
    return None


def target(path, inputs=(), outputs=()) -> Path:
    """``--junit FILE`` checked before the run: UsageError for an empty path, a directory, a file
    that is not a regular file (a device, a FIFO), one of ``inputs`` (e.g. the config) or a file
    among ``outputs`` (files the run writes, or in folders it writes into: ``OUT/run.json``,
    ``OUT/data/``, ...), which the JUnit file would replace."""
    if path is None or not str(path).strip():
        raise UsageError("--junit '': empty; give the file to write the JUnit XML to")
    path = Path(path)
    if path.is_dir():
        raise UsageError(f"--junit {path}: is a directory; give a file name, e.g. {path / 'junit.xml'}")
    if path.exists() and not path.is_file():
        raise UsageError(f"--junit {path}: not a regular file")
    if any(os.path.realpath(path) == os.path.realpath(p) for p in inputs):
        raise UsageError(f"--junit {path}: an input of this run; choose another file")
    hit = _written_by_run(path, outputs)
    if hit is not None:
        raise UsageError(f"--junit {path}: an output of this run ({hit}); choose another file")
    return path


def write(path, suites: list[Suite], name: str, done: str = "", outputs=()) -> Path:
    """Write the JUnit XML of ``suites`` to ``path`` (its missing folders created), atomically.

    A file the run read (its config, a data file) or wrote (``outputs``: its files, or folders it
    wrote into) is never overwritten. ``done`` (e.g. ``the run's results are in DIR``) is added to
    the message of a write error, as the run itself succeeded.
    """
    path = target(path)
    note = f"; {done}" if done else ""
    if os.path.realpath(path) in inputs_read():
        raise UsageError(f"--junit {path}: an input of this run; choose another file{note}")
    hit = _written_by_run(path, outputs)
    if hit is not None:
        raise UsageError(f"--junit {path}: an output of this run ({hit}); choose another file{note}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_write(path) as fh:
            fh.write(to_xml(suites, name))
    except OSError as exc:
        raise UsageError(f"--junit {path}: cannot write it ({exc.strerror or exc}){note}") from None
    return path
