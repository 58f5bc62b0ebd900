"""A corpus of bad inputs through the real ``tirecli`` (issue 13): configs, parameter sets, ``.tir``
files, points CSVs, fit data, options and output locations.

Each case runs in a fresh directory holding its input files and a previous run's output
directory ``prev/``; it must end within the time limit with its exit code and one ``error:`` line
matching its pattern, print no line of a file's content beyond the offending token, escape control
characters, and leave every file of the directory (inputs and ``prev/``) byte-identical.

Each command runs in its own process: a few cases (:data:`SCRIPT_CASES`) through the console
script, the rest forked from a warm ``tirecli`` (:func:`harness.run_warm`: the same entry point
without the second of interpreter start and imports per case; ``TIRECLI_ROBUSTNESS_SCRIPT=1`` runs
every case through the script). The cases are started together on a small pool of threads (each
test waits for its own).
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from harness import assert_clean_error, assert_no_leak, run, run_warm, snapshot

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"
TIR = ROOT / "tests" / "data" / "tir" / "mf_185_80R14.tir"
SWEEP = EX / "fm-fig1-left.yaml"
FIT = EX / "fm-fig6.yaml"
OBS = EX / "obs-fig2.yaml"
LIMIT = 30.0  # s per case: a hang detector (each case takes about a second alone)

# a file of secrets: every line longer than the 80-character token limit, none of it may be printed
SECRET = "".join(f"user{i}:$6$Zq8s9Yw1$" + "k3Jf9a8B" * 12 + ":19000:0:99999:7:::\n" for i in range(12))
# the same as a YAML mapping (one key per account)
SECRET_YAML = "".join(f"user{i}: $6$Zq8s9Yw1$" + "k3Jf9a8B" * 12 + ":19000:0:99999:7\n" for i in range(12))
# a shadow file of short lines (each one a YAML key: the file reads as a mapping), and a password file (a YAML text)
SHADOW = "root:$6$Zq8s9Yw1$k3Jf9a8B:19000:0:99999:7:::\ndaemon:*:19000:0:99999:7:::\nbob:!:19000:0:99999:7:::\n"
PASSWD = "root:x:0:0:root:/root:/bin/bash\nbob:x:1000:1000:Bob,,,:/home/bob:/bin/sh\n"
#: Text of SHADOW and PASSWD that no message may show (not even as a short token).
SHADOW_TEXT = ("root", "daemon", "bob", "Zq8s9Yw1", "99999", "/bin/")
GOOD_POINTS = "kappa,alpha,gamma,fz\n0.1,0,0,4000\n0.2,0.01,0,4000\n"
GOOD_DATA = "t,v,s,mu\n0,20,-0.01,-0.3\n0.01,19.9,-0.02,-0.5\n0.02,19.8,-0.03,-0.6\n"
BAD_TIME = "t,v,s,mu\n0,20,-0.01,-0.3\n0.01,19.9,-0.02,-0.5\n0.005,19.8,-0.03,-0.6\n"
DATE_TIME = "t,v,s,mu\n0,20,-0.01,-0.3\n2024-01-01T00:00:01,19.9,-0.02,-0.5\n0.02,19.8,-0.03,-0.6\n"
FIG1 = SWEEP.read_text(encoding="utf-8")
SET_FILE = """name: my-set
kind: lugre
title: a set
citation: none
values: {sigma0: 181.54, sigma1: 1.0, sigma2: 0.0018, mu_c: 0.8, mu_s: 1.55, v_s: 6.57, L: 0.2, alpha: 1.0}
"""
LONG = "x" * 300
#: A small campaign over a built-in config (two points of the observer's convergence).
CAMPAIGN = (EX / "campaign-obs-convergence.yaml").read_text(encoding="utf-8").replace(
    "base: obs-gain-study.yaml", "base: obs-gain-study")


class Fifo:
    """A named pipe (reading it would wait for a writer forever)."""


class Dir:
    """A directory (with one file in it)."""


@dataclass
class Link:
    target: str


@dataclass
class Case:
    id: str
    args: list
    code: int
    pattern: str
    files: dict = field(default_factory=dict)
    secret: str | None = None
    forbid: tuple = ()  # text of an input that must not be printed (not even as a short token)
    root_skip: bool = False  # permissions do not bind root


def cfg(old: str, new: str) -> str:
    """The fm-fig1-left config with ``old`` replaced by ``new``."""
    assert old in FIG1, old
    return FIG1.replace(old, new)


def tir_with(old: str, new: str) -> bytes:
    data = TIR.read_bytes()
    assert old.encode() in data, old
    return data.replace(old.encode(), new.encode(), 1)


def sweep(*extra):
    return ["sweep", "c.yaml", "--out", "prev", *extra]


def mf(points="p.csv", out="prev/r.csv", tire=str(TIR), extra=()):
    return ["mf", "eval", tire, "--points", points, "--out", out, *extra]


def fit(data="d.csv", *extra):
    return ["fit", str(FIT), "--data", data, "--out", "prev", *extra]


CASES = [
    # ---------------------------------------------------------------- configs
    Case("config-missing", ["sweep", "nope.yaml", "--out", "prev"], 2, r"nope\.yaml: file not found"),
    Case("config-empty", sweep(), 2, r"c\.yaml: is an empty file", {"c.yaml": ""}),
    Case("config-blank", sweep(), 2, r"c\.yaml: .*empty", {"c.yaml": "\n  \n# only a comment\n"}),
    Case("config-directory", sweep(), 2, r"c\.yaml: is a directory", {"c.yaml": Dir}),
    Case("config-dev-null", ["sweep", "/dev/null", "--out", "prev"], 2, r"/dev/null: is an empty file"),
    Case("config-dev-zero", ["sweep", "/dev/zero", "--out", "prev"], 2, r"/dev/zero: is a character device"),
    Case("config-fifo", sweep(), 2, r"c\.yaml: is a FIFO", {"c.yaml": Fifo}),
    Case("config-binary", sweep(), 2, r"c\.yaml:1: binary file", {"c.yaml": b"\x00\x01\x02study: sweep\n"}),
    Case("config-latin1", sweep(), 2, r"c\.yaml:2: not UTF-8 text", {"c.yaml": b"study: sweep\ntitle: \xe9t\xe9\n"}),
    Case("config-unclosed-bracket", sweep(), 2, r"c\.yaml:\d+: malformed YAML", {"c.yaml": cfg('speeds: [5,', "speeds: [5, [10,")}),
    Case("config-tab-indent", sweep(), 2, r"c\.yaml:\d+: malformed YAML", {"c.yaml": cfg('  speeds', "\tspeeds")}),
    Case("config-control-char", sweep(), 2, r"c\.yaml:\d+: malformed YAML: character U\+0007", {"c.yaml": FIG1 + "note: a\x07b\n"}),
    Case("config-list", sweep(), 2, r"c\.yaml:1: expected a YAML mapping", {"c.yaml": "- study\n- sweep\n"}),
    Case("config-scalar", sweep(), 2, r"c\.yaml:1: expected a YAML mapping", {"c.yaml": "just text\n"}),
    Case("config-unknown-key", sweep(), 2, r"sweep\.speedz: unknown key; did you mean 'speeds'", {"c.yaml": cfg('  speeds:', "  speedz:")}),
    Case("config-bad-timestamp", sweep(), 2, r"c\.yaml:13: when: cannot read value '2024-13-45': not a valid date",
         {"c.yaml": FIG1 + "when: 2024-13-45\n"}),
    Case("config-bad-timestamp-in-set", sweep(), 2, r"c\.yaml:5: tire\.sigma0: cannot read value .*date",
         {"c.yaml": cfg('tire: canudas2003-table1', "tire: {set: canudas2003-table1, sigma0: 2001-02-30}")}),
    Case("config-400-digit-int", sweep(), 2, r"c\.yaml:5: tire\.sigma0: expected a finite number .*an integer of about 40\d digits",
         {"c.yaml": cfg('tire: canudas2003-table1', "tire: {set: canudas2003-table1, sigma0: " + "9" * 400 + "}")}),
    Case("config-5000-digit-int", sweep(), 2, r"c\.yaml:8: sweep\.speeds\[0\]: cannot read value",
         {"c.yaml": cfg('[5, 10, 15, 20, 25, 30]', "[" + "7" * 5000 + "]")}),
    Case("config-python-tag", sweep(), 2, r"c\.yaml:13: x: cannot read value: the tag '!!python/object/apply:os\.system' is not allowed",
         {"c.yaml": FIG1 + "x: !!python/object/apply:os.system ['touch pwned']\n"}),
    Case("config-long-token", sweep(), 2, r"study: unknown value 'y{77}\.\.\.'",
         {"c.yaml": FIG1.replace("study: sweep", "study: " + "y" * 5000)}),
    Case("config-long-key", sweep(), 2, r"c\.yaml:13: k{77}\.\.\.: unknown key", {"c.yaml": FIG1 + "k" * 500 + ": 1\n"}),
    Case("config-escape-sequence", sweep(), 2, r"unknown value '\\x1b\[2J",
         {"c.yaml": FIG1.replace("study: sweep", 'study: "\\e[2Jhello"')}),
    Case("config-name-too-long", ["sweep", "c" * 300 + ".yaml", "--out", "prev"], 2, r"file name too long"),
    Case("config-dir-component-too-long", ["sweep", "d" * 300 + "/c.yaml", "--out", "prev"], 2, r"file name too long"),
    Case("config-symlink-loop", sweep(), 2, r"c\.yaml: too many levels of symbolic links", {"c.yaml": Link("c.yaml")}),
    Case("config-broken-symlink", sweep(), 2, r"c\.yaml: file not found \(a broken symbolic link\)", {"c.yaml": Link("gone.yaml")}),
    Case("config-parent-is-file", ["sweep", "f.yaml/c.yaml", "--out", "prev"], 2, r"f\.yaml/c\.yaml: not found \(a part of the path is a file",
         {"f.yaml": FIG1}),
    Case("config-unreadable", sweep(), 2, r"c\.yaml: permission denied", {"c.yaml": FIG1}, root_skip=True),
    Case("config-secret-file", ["sweep", "secret", "--out", "prev"], 2, r"secret:1: (expected a YAML mapping|not a study config)",
         {"secret": SECRET}, secret=SECRET),
    # ---------------------------------------------------------------- parameter sets
    Case("set-secret-via-set", sweep("--set", "tire.set=./secret"), 2, r"secret:1: not a parameter set",
         {"c.yaml": FIG1, "secret": SECRET_YAML}, secret=SECRET_YAML),
    Case("set-shadow-via-set", sweep("--set", "tire.set=./shadow"), 2, r"shadow:1: (expected|not) a parameter set",
         {"c.yaml": FIG1, "shadow": SECRET}, secret=SECRET),
    Case("config-secret-mapping", ["sweep", "secret", "--out", "prev"], 2, r"secret:1: not a study config",
         {"secret": SECRET_YAML}, secret=SECRET_YAML),
    Case("set-secret-yaml-via-set", sweep("--set", "tire.set=./secret.yaml"), 2, r"secret\.yaml:1: (not a parameter set|expected a parameter set)",
         {"c.yaml": FIG1, "secret.yaml": "".join(f"k{i}: {'v' * 200}\n" for i in range(30))}, secret="v" * 200),
    Case("set-missing-file", sweep("--set", "tire.set=./nope.yaml"), 2, r"nope\.yaml: file not found", {"c.yaml": FIG1}),
    Case("set-empty-file", sweep("--set", "tire.set=./s.yaml"), 2, r"s\.yaml: is an empty file", {"c.yaml": FIG1, "s.yaml": ""}),
    Case("set-directory", sweep("--set", "tire.set=./s.yaml"), 2, r"s\.yaml: is a directory", {"c.yaml": FIG1, "s.yaml": Dir}),
    Case("set-fifo", sweep("--set", "tire.set=./s.yaml"), 2, r"s\.yaml: is a FIFO", {"c.yaml": FIG1, "s.yaml": Fifo}),
    Case("set-dev-zero", sweep("--set", "tire.set=/dev/zero"), 2, r"/dev/zero: is a character device", {"c.yaml": FIG1}),
    Case("set-in-config-missing", sweep(), 2, r"gone\.yaml: file not found",
         {"c.yaml": cfg('tire: canudas2003-table1', "tire: {set: gone.yaml}")}),
    Case("set-text-value", sweep("--set", "tire.set=./s.yaml"), 2, r"s\.yaml:5: values\.sigma0: expected a number .*got the text 'abc'",
         {"c.yaml": FIG1, "s.yaml": SET_FILE.replace("181.54", "abc")}),
    Case("set-400-digit-value", sweep("--set", "tire.set=./s.yaml"), 2, r"s\.yaml:5: values\.sigma0: .*an integer of about 40\d digits",
         {"c.yaml": FIG1, "s.yaml": SET_FILE.replace("181.54", "4" * 400)}),
    Case("set-wrong-kind", ["simulate", str(EX / "fm-fig4.yaml"), "--set", "tire.set=chrono-185-80r14", "--out", "prev"], 2,
         r"tire\.set: set 'chrono-185-80r14' is of kind 'magic_formula', expected 'lugre'"),
    Case("params-validate-fifo", ["params", "validate", "s.yaml"], 2, r"s\.yaml: is a FIFO", {"s.yaml": Fifo}),
    Case("params-validate-dev-zero", ["params", "validate", "/dev/zero"], 2, r"/dev/zero: is a character device"),
    Case("params-validate-timestamp", ["params", "validate", "s.yaml"], 2, r"s\.yaml:6: date: cannot read value .*date",
         {"s.yaml": SET_FILE + "date: 2023-02-29\n"}),
    Case("params-show-directory", ["params", "show", "d"], 2, r"d: is a directory", {"d": Dir}),
    Case("params-show-name-too-long", ["params", "show", "n" * 300 + ".yaml"], 2, r"file name too long"),
    Case("params-show-secret", ["params", "show", "secret.yaml"], 2, r"secret\.yaml:1: not a parameter set",
         {"secret.yaml": "".join(f"line{i}: {'w' * 120}\n" for i in range(25))}, secret="w" * 120),
    # ---------------------------------------------------------------- .tir files
    Case("tir-empty", ["tir", "show", "t.tir"], 2, r"t\.tir: is an empty file", {"t.tir": ""}),
    Case("tir-dev-null", ["tir", "show", "/dev/null"], 2, r"/dev/null: is an empty file"),
    Case("tir-dev-zero", ["tir", "check", "/dev/zero"], 2, r"/dev/zero: is a character device"),
    Case("tir-fifo", ["tir", "show", "t.tir"], 2, r"t\.tir: is a FIFO", {"t.tir": Fifo}),
    Case("tir-directory", ["tir", "check", "t.tir"], 2, r"t\.tir: is a directory", {"t.tir": Dir}),
    Case("tir-binary", ["tir", "show", "t.tir"], 2, r"t\.tir: binary file", {"t.tir": bytes(range(256)) * 4}),
    Case("tir-secret", ["tir", "show", "t.tir"], 2, r"t\.tir: not a \.tir property file", {"t.tir": SECRET}, secret=SECRET),
    Case("tir-bad-number", ["tir", "show", "t.tir"], 2, r"t\.tir:\d+: FNOMIN: cannot read the value '3800x'",
         {"t.tir": tir_with("FNOMIN                   = 3800", "FNOMIN                   = 3800x")}),
    Case("tir-400-digit-int", ["tir", "show", "t.tir"], 2, r"t\.tir:\d+: FNOMIN: the number '4+\.\.\.' is (too large|beyond the range of a double)",
         {"t.tir": tir_with("FNOMIN                   = 3800", "FNOMIN                   = " + "4" * 400)}),
    Case("tir-long-unterminated-quote", ["tir", "show", "t.tir"], 2, r"TYRESIDE: unterminated quoted text \"'LEFTq{70,80}\.\.\.\"$",
         {"t.tir": tir_with("TYRESIDE                 = 'LEFT'", "TYRESIDE                 = 'LEFT" + "q" * 500)}),
    Case("tir-name-too-long", ["tir", "show", "t" * 300 + ".tir"], 2, r"file name too long"),
    Case("tir-yaml-form-fifo", ["tir", "show", "t.yaml"], 2, r"t\.yaml: is a FIFO", {"t.yaml": Fifo}),
    Case("tir-convert-out-directory", ["tir", "convert", str(TIR), "--to", "yaml", "--out", "prev"], 2, r"--out prev: is a directory"),
    Case("tir-convert-out-too-long", ["tir", "convert", str(TIR), "--to", "yaml", "--out", "o" * 300 + ".yaml"], 2, r"file name too long"),
    Case("tir-convert-out-parent-file", ["tir", "convert", str(TIR), "--to", "yaml", "--out", "prev/run.json/t.yaml"], 2,
         r"prev/run\.json is a file, not a directory"),
    Case("tir-convert-out-dev", ["tir", "convert", str(TIR), "--to", "yaml", "--out", "/dev/null"], 2, r"/dev/null: is a character device"),
    # ---------------------------------------------------------------- points CSVs (mf eval)
    Case("points-missing", mf("nope.csv"), 2, r"nope\.csv: file not found"),
    Case("points-empty", mf(), 2, r"p\.csv: is an empty file", {"p.csv": ""}),
    Case("points-dev-null", mf("/dev/null"), 2, r"/dev/null: is an empty file"),
    Case("points-dev-zero", mf("/dev/zero"), 2, r"/dev/zero: is a character device"),
    Case("points-fifo", mf(), 2, r"p\.csv: is a FIFO", {"p.csv": Fifo}),
    Case("points-directory", mf(), 2, r"p\.csv: is a directory", {"p.csv": Dir}),
    Case("points-binary", mf(), 2, r"p\.csv:4: binary file", {"p.csv": GOOD_POINTS + "\x00\x00\n"}),
    Case("points-latin1", mf(), 2, r"p\.csv:4: not UTF-8 text \(byte 0xb0 at column 14\)", {"p.csv": GOOD_POINTS.encode() + b"0.3,0,0,4000 \xb0\n"}),
    Case("points-missing-column", mf(), 2, r"p\.csv: missing column\(s\) 'fz'", {"p.csv": GOOD_POINTS.replace(",fz", ",fx")}),
    Case("points-text-cell", mf(), 2, r"p\.csv: column 'alpha' row 2: not a number \('abc'\)", {"p.csv": GOOD_POINTS.replace("0.01", "abc")}),
    Case("points-timestamp", mf(), 2, r"p\.csv: column 'kappa' row 3: not a number \('2024-01-01 10:00:00'\)",
         {"p.csv": GOOD_POINTS + "2024-01-01 10:00:00,0,0,4000\n"}),
    Case("points-400-digit-int", mf(), 2, r"p\.csv: column 'fz' row 1: number too large for a double", {"p.csv": GOOD_POINTS.replace("4000", "9" * 400, 1)}),
    Case("points-bool", mf(), 2, r"p\.csv: column 'kappa' row 3: not a number \('True'", {"p.csv": GOOD_POINTS + "True,0,0,4000\n"}),
    Case("points-extra-field", mf(), 2, r"p\.csv: data row 2 has 5 fields", {"p.csv": GOOD_POINTS.replace("0.2,0.01,0,4000", "0.2,0.01,0,4000,7")}),
    Case("points-secret", mf(), 2, r"p\.csv: missing column\(s\)", {"p.csv": SECRET}, secret=SECRET),
    Case("points-password-file", mf(), 2, r"p\.csv: data row 1 has 4 fields .*not shown",
         {"p.csv": "root:x:0:0:root:/root:/bin/bash\nbob:x:1000:1000:Bob,,,:/home/bob:/bin/sh\n"},
         forbid=("root:x", "/bin/bash", "bob")),
    Case("fit-data-shadow-file", fit(), 2, r"d\.csv: missing column\(s\) 't', 'v', 'mu' \(file has: 1 header field",
         {"d.csv": "root:$6$Zq8s9Yw1$k3Jf9a8B:19000:0:99999:7:::\n"}, forbid=("root", "Zq8s9Yw1")),
    Case("points-long-cell", mf(), 2, r"p\.csv: column 'alpha' row 2: not a number \('z+\.\.\.'\)", {"p.csv": GOOD_POINTS.replace("0.01", "z" * 3000)}),
    Case("points-name-too-long", mf("p" * 300 + ".csv"), 2, r"file name too long"),
    Case("mf-out-directory", mf(out="prev"), 2, r"--out prev: is a directory", {"p.csv": GOOD_POINTS}),
    Case("mf-out-too-long", mf(out="r" * 300 + ".csv"), 2, r"file name too long", {"p.csv": GOOD_POINTS}),
    Case("mf-out-parent-is-file", mf(out="prev/run.json/r.csv"), 2, r"prev/run\.json is a file, not a directory", {"p.csv": GOOD_POINTS}),
    Case("mf-out-dev-zero", mf(out="/dev/zero"), 2, r"--out /dev/zero: is a character device", {"p.csv": GOOD_POINTS}),
    Case("mf-tire-fifo", mf(tire="t.tir"), 2, r"t\.tir: is a FIFO", {"p.csv": GOOD_POINTS, "t.tir": Fifo}),
    Case("mf-tire-unknown", mf(tire="no-such-tyre"), 2, r"'no-such-tyre': no such file and no built-in tyre", {"p.csv": GOOD_POINTS}),
    # ---------------------------------------------------------------- fit data
    Case("fit-data-empty", fit(), 2, r"d\.csv: is an empty file", {"d.csv": ""}),
    Case("fit-data-fifo", fit(), 2, r"d\.csv: is a FIFO", {"d.csv": Fifo}),
    Case("fit-data-dev-zero", fit("/dev/zero"), 2, r"/dev/zero: is a character device"),
    Case("fit-data-missing-column", fit(), 2, r"d\.csv: missing column\(s\) 'mu'", {"d.csv": GOOD_DATA.replace(",mu", ",friction")}),
    Case("fit-data-time-not-increasing", fit(), 2, r"d\.csv: column 't' row 3: time does not increase",
         {"d.csv": BAD_TIME}),
    Case("fit-data-timestamp", fit(), 2, r"d\.csv: column 't' row 2: not a number", {"d.csv": DATE_TIME}),
    Case("fit-data-secret", fit(), 2, r"d\.csv: missing column", {"d.csv": SECRET}, secret=SECRET),
    Case("fit-data-latin1", fit(), 2, r"d\.csv:1: not UTF-8", {"d.csv": b"t,v,s,\xb5\n0,1,0,0\n"}),
    # ---------------------------------------------------------------- options
    Case("option-unknown", ["sweep", str(SWEEP), "--bogus"], 2, r"No such option: --bogus.*tirecli sweep --help"),
    Case("option-missing-argument", ["sweep"], 2, r"Missing argument 'CONFIG'"),
    Case("option-set-no-equals", sweep("--set", "tire.sigma0"), 2, r"--set 'tire\.sigma0': expected KEY=VALUE", {"c.yaml": FIG1}),
    Case("option-set-bad-value", sweep("--set", "tire.sigma0=[1,"), 2, r"cannot read the value '\[1,'", {"c.yaml": FIG1}),
    Case("option-set-bad-date", sweep("--set", "tire.sigma0=2024-13-45"), 2, r"cannot read the value '2024-13-45'", {"c.yaml": FIG1}),
    Case("option-set-python-tag", sweep("--set", "tire.sigma0=!!python/object/apply:os.system [id]"), 2, r"cannot read the value",
         {"c.yaml": FIG1}),
    Case("option-set-huge-int", sweep("--set", "tire.sigma0=" + "3" * 400), 2, r"tire\.sigma0: .*an integer of about 40\d digits", {"c.yaml": FIG1}),
    Case("option-map", mf(out="r.csv", extra=["--map", "kappa"]), 2, r"--map 'kappa': expected FILE_COLUMN=NAME", {"p.csv": GOOD_POINTS}),
    Case("option-report-only", ["report", "--only", "no-such-paper", "--out", "prev"], 2, r"--only 'no-such-paper'"),
    # ---------------------------------------------------------------- the other commands
    Case("observe-config-fifo", ["observe", "c.yaml", "--out", "prev"], 2, r"c\.yaml: is a FIFO", {"c.yaml": Fifo}),
    Case("observe-vehicle-dev-zero", ["observe", str(OBS), "--set", "vehicle.set=/dev/zero", "--out", "prev"], 2,
         r"/dev/zero: is a character device"),
    Case("observe-run-json-directory", ["observe", str(OBS), "--out", "o"], 2, r"--out o: o/run\.json is a directory",
         {"o/run.json": Dir}),
    Case("compare-dev-null", ["compare", "/dev/null", "--out", "prev"], 2, r"/dev/null: is an empty file"),
    Case("compare-out-too-long", ["compare", str(SWEEP), "--out", "d/" + "o" * 300 + "/x"], 2, r"file name too long"),
    Case("simulate-config-empty", ["simulate", "c.yaml", "--out", "prev"], 2, r"c\.yaml: is an empty file", {"c.yaml": ""}),
    Case("simulate-config-secret", ["simulate", "c.yaml", "--out", "prev"], 2, r"c\.yaml:1: (expected a YAML mapping|not a study config)",
         {"c.yaml": SECRET}, secret=SECRET),
    Case("params-list-extra-argument", ["params", "list", "extra"], 2, r"unexpected extra argument"),
    Case("report-summary-directory", ["report", "--only", "fm-fig1-left", "--out", "o"], 2, r"o/summary\.json is a directory",
         {"o/summary.json": Dir}),
    Case("fit-data-400-digit", fit(), 2, r"d\.csv: column 'mu' row 2: (infinite value|.*number too large)",
         {"d.csv": GOOD_DATA.replace("-0.5", "-" + "5" * 400)}),
    # ---------------------------------------------------------------- secret files given to every command that reads a file
    # (through a symlink, as a link to /etc/shadow would be): no message shows any of their text
    Case("campaign-shadow-link", ["campaign", "LINK", "--out", "prev/c"], 2, r"LINK:1: not a campaign file: none of its 3 top-level",
         {"shadow": SHADOW, "LINK": Link("shadow")}, forbid=SHADOW_TEXT),
    Case("campaign-passwd", ["campaign", "passwd", "--out", "prev/c"], 2, r"passwd:1: expected a YAML mapping",
         {"passwd": PASSWD}, forbid=SHADOW_TEXT),
    Case("campaign-base-shadow", ["campaign", "c.yaml", "--out", "prev/c"], 2, r"shadow:1: not a study config",
         {"shadow": SHADOW, "c.yaml": "campaign: c\nbase: shadow\nvary: {x: [1, 2]}\noutputs: [y]\n"}, forbid=SHADOW_TEXT),
    Case("report-campaign-shadow-link", ["report", "LINK", "--out", "prev"], 2, r"LINK:1: not a campaign file",
         {"shadow": SHADOW, "LINK": Link("shadow")}, forbid=SHADOW_TEXT),
    Case("params-validate-shadow-link", ["params", "validate", "LINK"], 2, r"LINK:1: not a study config",
         {"shadow": SHADOW, "LINK": Link("shadow")}, forbid=SHADOW_TEXT),
    Case("params-show-shadow", ["params", "show", "shadow.yaml"], 2, r"shadow\.yaml:1: not a parameter set",
         {"shadow.yaml": SHADOW}, forbid=SHADOW_TEXT),
    Case("sweep-shadow-link", ["sweep", "LINK", "--out", "prev"], 2, r"LINK:1: not a study config",
         {"shadow": SHADOW, "LINK": Link("shadow")}, forbid=SHADOW_TEXT),
    Case("observe-shadow", ["observe", "shadow", "--out", "prev"], 2, r"shadow:1: not a study config",
         {"shadow": SHADOW}, forbid=SHADOW_TEXT),
    Case("compare-passwd", ["compare", "passwd", "--out", "prev"], 2, r"passwd:1: expected a YAML mapping",
         {"passwd": PASSWD}, forbid=SHADOW_TEXT),
    Case("fit-data-passwd", fit("passwd.csv"), 2, r"passwd\.csv: (missing column|data row 1 has 4 fields.*not shown)", {"passwd.csv": PASSWD}, forbid=SHADOW_TEXT),
    Case("tir-show-shadow-yaml-form", ["tir", "show", "shadow.yaml"], 2, r"shadow\.yaml:1: format: expected",
         {"shadow.yaml": SHADOW}, forbid=SHADOW_TEXT),
    Case("tir-check-passwd", ["tir", "check", "passwd.tir"], 2, r"passwd\.tir: not a \.tir property file",
         {"passwd.tir": PASSWD}, forbid=SHADOW_TEXT),
    Case("mf-points-shadow", mf("shadow.csv"), 2, r"shadow\.csv: missing column", {"shadow.csv": SHADOW}, forbid=SHADOW_TEXT),
    Case("data-show-shadow-csv", ["data", "show", "shadow.csv"], 2, r"shadow\.csv: no known channel",
         {"shadow.csv": SHADOW}, forbid=SHADOW_TEXT),
    Case("data-convert-passwd-tdx", ["data", "convert", "passwd.tdx", "--to", "csv", "--out", "prev/d.csv"], 2,
         r"passwd\.tdx: not a TYDEX file", {"passwd.tdx": PASSWD}, forbid=SHADOW_TEXT),
    Case("data-show-shadow-mf4", ["data", "show", "shadow.mf4"], 2, r"shadow\.mf4: not an MDF file",
         {"shadow.mf4": SHADOW}, forbid=SHADOW_TEXT),
    # ---------------------------------------------------------------- options never silently ignored
    Case("campaign-scheduler-refused-port", ["campaign", "c.yaml", "--out", "prev/c", "--scheduler", "tcp://127.0.0.1:1"], 2,
         r"--scheduler 'tcp://127\.0\.0\.1:1': cannot connect \(connection refused\)", {"c.yaml": CAMPAIGN}),
    Case("campaign-scheduler-word", ["campaign", "c.yaml", "--out", "prev/c", "--scheduler", "foo"], 2,
         r"--scheduler 'foo': expected 'local' or a Dask scheduler's address", {"c.yaml": CAMPAIGN}),
    Case("campaign-scheduler-empty", ["campaign", "c.yaml", "--out", "prev/c", "--scheduler", ""], 2,
         r"--scheduler '': empty", {"c.yaml": CAMPAIGN}),
    Case("campaign-scheduler-http", ["campaign", "c.yaml", "--out", "prev/c", "--scheduler", "http://127.0.0.1:1"], 2,
         r"--scheduler 'http://127\.0\.0\.1:1': http is not a Dask address scheme", {"c.yaml": CAMPAIGN}),
    Case("campaign-scheduler-bad-port", ["campaign", "c.yaml", "--out", "prev/c", "--scheduler", "tcp://127.0.0.1:99999"], 2,
         r"--scheduler 'tcp://127\.0\.0\.1:99999': cannot read the address", {"c.yaml": CAMPAIGN}),
    Case("campaign-jobs-absurd", ["campaign", "c.yaml", "--out", "prev/c", "--jobs", "99999999999999999999"], 2,
         r"--jobs 9{20}: more processes than this machine can use \(at most \d+", {"c.yaml": CAMPAIGN}),
    Case("report-jobs-absurd", ["report", "--only", "fm-fig1-left", "--out", "prev", "--jobs", "99999999999999999999"], 2,
         r"--jobs 9{20}: more processes than this machine can use"),
    Case("campaign-check-not-an-output", ["campaign", "c.yaml", "--out", "prev/c"], 2,
         r"c\.yaml:14: checks\[0\]\.output: 'converge_time' is not one of the campaign's outputs \(convergence_time, ",
         {"c.yaml": CAMPAIGN.replace("{output: convergence_time,", "{output: converge_time,")}),
    Case("params-validate-check-not-an-output", ["params", "validate", "c.yaml"], 2,
         r"c\.yaml:14: checks\[0\]\.output: 'converge_time' is not one of the campaign's outputs",
         {"c.yaml": CAMPAIGN.replace("{output: convergence_time,", "{output: converge_time,")}),
    # ---------------------------------------------------------------- output locations of runs
    Case("out-is-file", ["sweep", "c.yaml", "--out", "prev/run.json"], 2, r"--out prev/run\.json: exists and is not a directory",
         {"c.yaml": FIG1}),
    Case("out-run-json-directory", ["sweep", "c.yaml", "--out", "o"], 2, r"--out o: o/run\.json is a directory",
         {"c.yaml": FIG1, "o/run.json": Dir}),
    Case("out-data-is-file", ["sweep", "c.yaml", "--out", "o"], 2, r"--out o: o/data exists and is not a directory",
         {"c.yaml": FIG1, "o/data": "not a directory\n"}),
    Case("out-csv-is-directory", ["sweep", "c.yaml", "--out", "o"], 2, r"o/data/sweep\.csv is a directory",
         {"c.yaml": FIG1, "o/data/sweep.csv": Dir}),
    Case("out-name-too-long", ["sweep", "c.yaml", "--out", "o" * 300], 2, r"--out o+\.\.\.o+: file name too long", {"c.yaml": FIG1}),
    Case("out-parent-is-file", ["sweep", "c.yaml", "--out", "prev/run.json/o"], 2, r"prev/run\.json is a file, not a directory",
         {"c.yaml": FIG1}),
    Case("report-out-is-file", ["report", "--only", "fm-fig1-left", "--out", "prev/run.json"], 2, r"exists and is not a directory"),
]

#: Cases run through the console script itself (one of each kind of input).
SCRIPT_CASES = {"set-shadow-via-set", "tir-400-digit-int", "points-timestamp", "fit-data-fifo", "out-run-json-directory"}

IDS = [c.id for c in CASES]
assert len(IDS) == len(set(IDS)), "duplicate case ids"


def _materialize(case: Case, d: Path) -> None:
    prev = d / "prev"
    (prev / "data").mkdir(parents=True)
    (prev / "run.json").write_text('{"tool": "tirecli", "outputs": {"data": ["data/sweep.csv"]}}\n')
    (prev / "data" / "sweep.csv").write_text("# an earlier run\nslip,mu\n0,0\n")
    (prev / "r.csv").write_text("kappa,alpha,gamma,fz,p,vx,fx,fy,mz,mx,my\n")
    for name, content in case.files.items():
        p = d / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if content is Fifo:
            os.mkfifo(p)
        elif content is Dir:
            p.mkdir()
            (p / "inside.txt").write_text("x\n")
        elif isinstance(content, Link):
            os.symlink(content.target, p)
        elif isinstance(content, bytes):
            p.write_bytes(content)
        else:
            p.write_text(content, encoding="utf-8")
    if case.id == "config-unreadable":
        (d / "c.yaml").chmod(0)


def _run_case(case: Case) -> dict:
    d = Path(tempfile.mkdtemp(prefix=f"tirecli-corpus-{case.id[:20]}-"))
    try:
        _materialize(case, d)
        before = snapshot(d)
        runner = run if case.id in SCRIPT_CASES else run_warm
        r = runner(case.args, cwd=d, timeout=LIMIT)
        after = snapshot(d)
        leftovers = sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.name.startswith((".tirecli", "pwned")))
        return {"r": r, "before": before, "after": after, "leftovers": leftovers}
    except AssertionError as exc:  # the time limit
        return {"error": str(exc)}
    finally:
        for p in d.rglob("*"):
            if not p.is_symlink():
                try:
                    p.chmod(0o700 if p.is_dir() else 0o600)
                except OSError:
                    pass
        shutil.rmtree(d, ignore_errors=True)


_POOL = ThreadPoolExecutor(max_workers=2)
_FUTURES: dict = {}


def _result(case: Case) -> dict:
    if not _FUTURES:  # first test: start every case (each test then waits for its own)
        for c in CASES:
            if not _skipped(c):
                _FUTURES[c.id] = _POOL.submit(_run_case, c)
    return _FUTURES[case.id].result()


def _skipped(case: Case) -> bool:
    return case.root_skip and os.geteuid() == 0


def test_corpus_size():
    assert len(CASES) >= 60
    assert SCRIPT_CASES <= set(IDS)
    kinds = {c.id.split("-")[0] for c in CASES}
    assert {"config", "set", "tir", "points", "fit", "option", "out"} <= kinds


@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_bad_input(case: Case):
    if _skipped(case):
        pytest.skip("permissions do not bind root")
    res = _result(case)
    assert "error" not in res, res.get("error")
    r = res["r"]
    assert_clean_error(r, case.code, case.pattern)
    assert res["after"] == res["before"], f"files changed: {sorted(set(res['after'].items()) ^ set(res['before'].items()))[:6]}"
    assert not res["leftovers"], res["leftovers"]
    assert "\x1b" not in r.err and "\x07" not in r.err, "control characters printed raw"
    if case.secret is not None:
        assert_no_leak(r, case.secret)
    for text in case.forbid:
        assert text not in r.err and text not in r.out, f"{text!r} printed"
    line = r.lines[0]
    for quoted in re.findall(r"'([^']*)'", line):  # the offending token: at most 80 characters of input
        assert len(quoted) <= 84, quoted


def _readonly_dir(tmp_path: Path) -> Path | None:
    """A directory nobody may write to (a mode-555 directory; for root, a read-only system location)."""
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o555)
    probe = d / "probe"
    try:
        probe.write_text("x")
    except OSError:
        return d
    probe.unlink()
    for cand in (Path("/sys/kernel"), Path("/proc/sys")):
        try:
            (cand / "tirecli-probe").write_text("x")
        except OSError:
            return cand
    return None


@pytest.mark.parametrize("what", ["sweep", "mf-eval", "tir-convert"])
def test_read_only_output_location(tmp_path, what):
    ro = _readonly_dir(tmp_path)
    if ro is None:
        pytest.skip("no read-only location available")
    (tmp_path / "p.csv").write_text(GOOD_POINTS)
    target = ro / "sub" / "out"
    args = {"sweep": ["sweep", str(SWEEP), "--out", target],
            "mf-eval": mf("p.csv", str(target) + ".csv"),
            "tir-convert": ["tir", "convert", str(TIR), "--to", "yaml", "--out", str(target) + ".yaml"]}[what]
    r = run(args, cwd=tmp_path, timeout=LIMIT)
    assert_clean_error(r, 2, re.escape(str(ro)) + r".*cannot write there: read-only location")
    (tmp_path / "ro").chmod(0o755)


def test_missing_parents_of_out_are_created(tmp_path):
    (tmp_path / "p.csv").write_text(GOOD_POINTS)
    r = run(mf("p.csv", "a/b/c/r.csv"), cwd=tmp_path, timeout=LIMIT)
    assert r.code == 0, r.err
    assert (tmp_path / "a/b/c/r.csv").read_text().startswith("kappa,alpha,gamma,fz,p,vx,fx")
    r = run(["tir", "convert", str(TIR), "--to", "yaml", "--out", "x/y/t.yaml"], cwd=tmp_path, timeout=LIMIT)
    assert r.code == 0, r.err
    assert (tmp_path / "x/y/t.yaml").is_file()


def test_no_code_runs_from_a_config(tmp_path):
    """The YAML object tags and formula tricks of the corpus leave no trace (safe loading, sandboxed formulas)."""
    cfg_text = FIG1 + "x: !!python/object/apply:os.system ['touch pwned']\n"
    (tmp_path / "c.yaml").write_text(cfg_text)
    r = run(["params", "validate", "c.yaml"], cwd=tmp_path, timeout=LIMIT)
    assert r.code == 2 and not (tmp_path / "pwned").exists()


@pytest.mark.parametrize("command", [["campaign", "LINK", "--out", "o"], ["report", "LINK", "--out", "o"],
                                     ["sweep", "LINK", "--out", "o"]])
def test_debug_shows_no_file_content(tmp_path, command):
    """--debug adds the traceback, never the text of a file that is not of the kind expected."""
    (tmp_path / "shadow").write_text(SHADOW)
    os.symlink("shadow", tmp_path / "LINK")
    r = run_warm(["--debug", *command], cwd=tmp_path, timeout=LIMIT)
    assert r.code == 2, r.err[-800:]
    assert "not a" in r.err, r.err[-800:]
    for text in SHADOW_TEXT:
        assert text not in r.err and text not in r.out, f"{text!r} printed"
