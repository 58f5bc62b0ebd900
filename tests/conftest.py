"""Shared fixtures: run the real CLI entry point in-process."""
from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


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


def block_pyarrow(monkeypatch) -> None:
    """Make ``import pyarrow`` (and its submodules) fail for the rest of the test, as on an install without it."""
    import builtins

    real_import = builtins.__import__

    def no_pyarrow(name, *args, **kw):
        if name == "pyarrow" or name.startswith("pyarrow."):
            raise ImportError(name)
        return real_import(name, *args, **kw)

    monkeypatch.setattr(builtins, "__import__", no_pyarrow)
