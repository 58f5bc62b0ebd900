"""Shared fixtures: run the real CLI entry point in-process."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture(autouse=True, scope="session")
def _study_cache_session(tmp_path_factory):
    """The report's study cache of session-wide fixtures in a temporary folder: a test never reads or
    writes the user's cache (``~/.cache/tirecli``)."""
    mp = pytest.MonkeyPatch()
    mp.setenv("TIRECLI_CACHE_DIR", str(tmp_path_factory.mktemp("tirecli-cache")))
    yield
    mp.undo()


@pytest.fixture(autouse=True)
def _study_cache(tmp_path_factory, monkeypatch):
    """Each test's reports share a study cache of their own (a new temporary folder per test, beside the
    test's tmp_path, not in it), as each report folder once had: a test starts without cached studies."""
    monkeypatch.setenv("TIRECLI_CACHE_DIR", str(tmp_path_factory.mktemp("tirecli-cache")))


@pytest.fixture
def cli(capsys):
    """Run ``tirecli ARGS...`` through :func:`tirecli.cli.main.main`; return (code, stdout, stderr)."""
    from tirecli.cli.main import main

    def run(*args):
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return code, out.out, out.err

    return run


@pytest.fixture
def table1():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-table1").model()


@pytest.fixture
def table2():
    from tirecli.parameters.sets import load_builtin

    return load_builtin("canudas2003-table2").model()


def block_module(monkeypatch, *names: str) -> None:
    """Make ``import NAME`` (and its submodules) fail for the rest of the test for each of ``names``, as on
    an install without them (ModuleNotFoundError, as Python raises it)."""
    import builtins
    import importlib

    real_import = builtins.__import__
    real_import_module = importlib.import_module

    def blocked(name):
        return any(name == n or name.startswith(n + ".") for n in names)

    def no_import(name, *args, **kw):
        if blocked(name):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return real_import(name, *args, **kw)

    def no_import_module(name, package=None):
        if blocked(name):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return real_import_module(name, package)

    monkeypatch.setattr(builtins, "__import__", no_import)
    monkeypatch.setattr(importlib, "import_module", no_import_module)


def block_pyarrow(monkeypatch) -> None:
    """Make ``import pyarrow`` (and its submodules) fail for the rest of the test, as on an install without it."""
    block_module(monkeypatch, "pyarrow")
