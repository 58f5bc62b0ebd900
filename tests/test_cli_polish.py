"""Command-line polish: help placeholders, -V/--version, ``python -m tirecli``, aligned listings,
the README's and docs' commands as written, outputs git ignores, the package's licence metadata."""
from __future__ import annotations

import fnmatch
import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT
from doc_commands import parse, shell_commands
from test_cli import all_commands

COMMANDS = shell_commands()
README = [c for c in COMMANDS if c.file == "README.md"]
#: Files of the user's own that a guide's example names (the text around it describes them).
USER_FILES = {("docs/transient.md", "my-fit.yaml"), ("docs/transient.md", "braking.csv"),
              ("docs/data.md", "tirecli-out/mf-fit/fitted.tir")}  # written by the command before it
#: Parameters that name an input file, and those that name an output.
INPUTS = ("config", "points", "data", "file")
OUTPUTS = ("out", "junit")


def test_version(cli):
    from tirecli import __version__

    for flag in ("-V", "--version"):
        code, out, err = cli(flag)
        assert code == 0 and out == f"tirecli {__version__}\n"


def test_python_m_tirecli():
    from tirecli import __version__

    res = subprocess.run([sys.executable, "-m", "tirecli", "-V"], capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout == f"tirecli {__version__}\n", res.stderr
    res = subprocess.run([sys.executable, "-m", "tirecli", "params", "show", "no-such-set"],
                         capture_output=True, text=True)
    assert res.returncode == 2 and res.stderr.startswith("error: ") and "Traceback" not in res.stderr


def _command(path):
    import typer.main

    from tirecli.cli.main import app

    cmd = typer.main.get_command(app)
    for name in path:
        cmd = cmd.commands[name]
    return cmd


@pytest.mark.parametrize("path", all_commands(), ids=lambda p: " ".join(p) or "tirecli")
def test_help_placeholders(cli, path):
    """Every value is shown by what it is (CONFIG, NAME, FILE, DIR, CSV, KEY=VALUE, a|b), never by
    a Python type (``<str>``, ``<list[str]>``, TEXT, PATH)."""
    cmd = _command(path)
    for p in cmd.params:
        if p.param_type_name == "argument":
            assert p.metavar and re.fullmatch(r"[A-Z][A-Z_]*", p.metavar), (path, p.name, p.metavar)
        elif not (p.is_flag or getattr(p, "count", False)):
            assert p.metavar and re.fullmatch(r"[A-Z][A-Z_=]*|[a-z0-9]+(\|[a-z0-9]+)+", p.metavar), \
                (path, p.name, p.metavar)
    code, out, err = cli(*path, "--help")
    assert code == 0
    assert "<list[" not in out
    options = out[out.index("Options:"):] if "Options:" in out else ""
    options = options.split("Commands:")[0]
    for word in ("<str>", "<path>", "<int>", "<float>", " TEXT", " PATH", " INTEGER", " FLOAT"):
        assert word not in options, f"tirecli {' '.join(path)} --help: {word.strip()} in\n{options}"


def _columns(line: str) -> list[int]:
    """Where each column of a listing line starts (columns are two or more spaces apart)."""
    return [m.start() for m in re.finditer(r"(?:^|(?<=\s{2}))\S", line)]


@pytest.mark.parametrize("command", [("params", "list"), ("figures", "list")])
def test_listings_are_aligned(cli, command):
    code, out, err = cli(*command)
    assert code == 0
    lines = out.splitlines()
    assert len(lines) > 5
    starts = [_columns(line)[:3] for line in lines]
    assert all(s == starts[0] for s in starts), "\n".join(lines)
    assert len(starts[0]) == 3


# --------------------------------------------------------------------------- the documented commands


def test_documented_commands_are_found():
    assert len(README) >= 25
    assert {c.argv[0] for c in README} >= {"report", "sweep", "simulate", "compare", "observe", "fit", "tir", "mf"}


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: f"{c.file}:{c.line}")
def test_documented_command_parses_and_its_files_exist(command):
    """Each command of the README's and the docs' shell blocks is valid as written (options, arguments),
    the files it reads are in the repository (run from its root), and what it writes git ignores."""
    names, params = parse(command.argv)
    for key in INPUTS:
        values = params.get(key)
        for value in values if isinstance(values, (list, tuple)) else [values]:  # mf fit DATA...: a list
            if value is None or (key == "file" and not re.search(r"[/.]", str(value))):  # a built-in tyre name
                continue
            if (command.file, str(value)) in USER_FILES:
                continue
            assert (ROOT / value).is_file(), f"{command.id}: {value} is not in the repository"
    if names[0] in ("sweep", "simulate", "compare", "fit", "observe", "report") and params.get("out") is None:
        params["out"] = "tirecli-out/x"  # the default output folder
    for key in OUTPUTS:
        value = params.get(key)
        if value is not None and not Path(value).is_absolute():
            assert git_ignored(str(value)), f"{command.id}: {value} is not in .gitignore"


def git_ignored(rel: str) -> bool:
    """Whether .gitignore ignores the path ``rel`` (itself or a folder above it), for the kinds of
    pattern it uses (``name``, ``name/``, ``/name/``, globs)."""
    patterns = [p.strip() for p in (ROOT / ".gitignore").read_text().splitlines() if p.strip() and not p.startswith("#")]
    parts = Path(rel).parts
    for pat in patterns:
        dir_only, body = pat.endswith("/"), pat.strip("/")
        anchored = pat.startswith("/") or "/" in body
        for i in range(1, len(parts) + 1):
            if dir_only and i == len(parts):  # a folder pattern, and this is the file itself
                continue
            if fnmatch.fnmatchcase("/".join(parts[:i]) if anchored else parts[i - 1], body):
                return True
    return False


def test_gitignore_covers_the_default_outputs_and_run_leftovers():
    from tirecli.app.run import DEFAULT_OUT

    for rel in (f"{DEFAULT_OUT}/report/index.html", "out/fig2/run.json", ".mine.tirecli-lock",
                "tirecli-out/.report.tirecli-tmp-abcd1234/x", ".mine.tirecli-tmp-abcd1234"):
        assert git_ignored(rel), rel
    for rel in ("tirecli/app/run.py", "examples/fm-fig4.yaml", "docs/ci.md", "README.md"):
        assert not git_ignored(rel), rel


@pytest.fixture
def repo_cwd(tmp_path, monkeypatch):
    """A working directory in which the repository's relative paths (examples/, tests/) resolve and
    outputs stay in the temporary directory."""
    for name in ("examples", "tests"):
        (tmp_path / name).symlink_to(ROOT / name)
    monkeypatch.chdir(tmp_path)
    return tmp_path


QUICK = [c for c in README if c.argv[0] in ("tir", "mf", "params", "figures")]


@pytest.mark.parametrize("command", QUICK, ids=lambda c: " ".join(c.argv))
def test_quick_readme_commands_run_as_written(cli, repo_cwd, command):
    """``tir show`` and ``mf eval`` of the README run as written (examples/points.csv is in examples/)."""
    code, out, err = cli(*command.argv)
    assert code == 0, f"{command.id}: {err}"


@pytest.mark.slow
@pytest.mark.parametrize("command", README, ids=lambda c: " ".join(c.argv))
def test_readme_commands_run_as_written(cli, repo_cwd, command):
    code, out, err = cli("--quiet", *command.argv)
    assert code == 0, f"{command.id}: {err}"


# --------------------------------------------------------------------------- packaging


def test_licence_metadata_is_pep_639():
    """``license`` is an SPDX expression with ``license-files`` (no setuptools deprecation warning at
    install), and the build requires a setuptools that reads them (77 and newer)."""
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())
    project = meta["project"]
    assert project["license"] == "BSD-3-Clause"
    assert project["license-files"] == ["LICENSE"] and (ROOT / "LICENSE").is_file()
    assert "BSD" in (ROOT / "LICENSE").read_text()
    assert not [c for c in project.get("classifiers", []) if c.startswith("License ::")]
    (setuptools,) = [r for r in meta["build-system"]["requires"] if r.startswith("setuptools")]
    m = re.fullmatch(r"setuptools>=(\d+)(?:\.(\d+))?(?:\.(\d+))?", setuptools.replace(" ", ""))
    assert m and tuple(int(x or 0) for x in m.groups()) >= (77, 0, 0), setuptools
    assert "jsonschema" in " ".join(project["optional-dependencies"]["test"])
    assert "schemas/*.json" in meta["tool"]["setuptools"]["package-data"]["tirecli"]
