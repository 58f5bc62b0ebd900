"""What the README's install (``pip install .``, no extras) brings is what tirecli needs; an optional
library that is missing is one line (exit 2) saying how to install it, at the start of a run.

``.ci/run`` runs every command of the README on such an install (tests/run_readme_examples.py); here:
the imports of tirecli's sources against the default dependencies of pyproject.toml, and each optional
library (Dask, and pyarrow and SALib on an install that lacks them) made missing.
"""
from __future__ import annotations

import ast
import re
import sys
import tomllib
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, block_module
from doc_commands import shell_commands

#: Import names of the distributions of pyproject's default dependencies (and of what those bring:
#: jinja2 brings markupsafe, matplotlib brings Pillow, typer brings click and rich).
IMPORT_NAMES = {"typer": {"typer", "click"}, "numpy": {"numpy"}, "scipy": {"scipy"}, "pandas": {"pandas"},
                "matplotlib": {"matplotlib", "mpl_toolkits", "PIL"}, "jinja2": {"jinja2", "markupsafe"},
                "pyyaml": {"yaml"}, "pyarrow": {"pyarrow"}, "salib": {"SALib"}}
#: Calls that check an optional library before it is imported (:func:`tirecli.errors.require`).
REQUIRE_CALLS = {"require", "require_pyarrow", "require_scheduler", "require_asammdf"}


def _default_dependencies() -> set[str]:
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    return {re.split(r"[<>=!~\[; ]", d, maxsplit=1)[0].lower() for d in deps}


def _imports(tree: ast.AST):
    """(top-level module, import node, enclosing function or None, enclosing try nodes) of every import."""
    out = []

    def visit(node, func, tries):
        for child in ast.iter_child_nodes(node):
            f, t = func, tries
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                f = child
            if isinstance(child, ast.Try):
                t = tries + [child]
            if isinstance(child, ast.Import):
                out.extend((a.name.split(".")[0], child, f, t) for a in child.names)
            elif isinstance(child, ast.ImportFrom) and child.level == 0 and child.module:
                out.append((child.module.split(".")[0], child, f, t))
            visit(child, f, t)

    visit(tree, None, [])
    return out


def _catches_import_error(tries, node) -> bool:
    for t in tries:
        if any(node in ast.walk(stmt) for stmt in t.body):
            for h in t.handlers:
                names = [h.type] if not isinstance(h.type, ast.Tuple) else h.type.elts
                if any(isinstance(n, ast.Name) and n.id in ("ImportError", "ModuleNotFoundError") for n in names):
                    return True
    return False


def _required_before(func, node) -> bool:
    """Whether ``func`` calls a require function on a line before ``node``."""
    if func is None:
        return False
    for n in ast.walk(func):
        if isinstance(n, ast.Call) and n.lineno < node.lineno:
            name = n.func.id if isinstance(n.func, ast.Name) else getattr(n.func, "attr", None)
            if name in REQUIRE_CALLS:
                return True
    return False


#: Functions that import an optional library only after their callers checked it (file, function: the check).
CHECKED_BY_CALLER = {
    ("tirecli/io/output.py", "write_parquet"): "check_data_format / require_pyarrow before the run",
    ("tirecli/campaign/execute.py", "_run_dask"): "dask_client (require_scheduler) first, and run_campaign before",
    ("tirecli/campaign/execute.py", "dask_client"): "require_scheduler() on its first line",
    ("tirecli/io/campaign.py", "write_timeseries"): "run_campaign's require_pyarrow before any point",
    ("tirecli/io/campaign.py", "read_timeseries"): "run_campaign's require_pyarrow before any point",
}


def test_every_import_is_a_dependency_or_checked_first():
    """Each third-party import of tirecli is of a default dependency, or of an optional library
    (:data:`tirecli.errors.OPTIONAL`) imported only after a check that fails in one line (or inside
    ``try/except ImportError``)."""
    from tirecli.errors import OPTIONAL

    deps = _default_dependencies()
    default = set().union(*(IMPORT_NAMES.get(d, {d}) for d in deps))
    stdlib = set(sys.stdlib_module_names) | {"__future__"}
    bad = []
    for path in sorted((ROOT / "tirecli").rglob("*.py")):
        rel = path.relative_to(ROOT).as_posix()
        for mod, node, func, tries in _imports(ast.parse(path.read_text(encoding="utf-8"))):
            if mod in stdlib or mod == "tirecli":
                continue
            where = f"{rel}:{node.lineno}: import {mod}"
            if _catches_import_error(tries, node):
                continue
            if mod in default:
                if mod in OPTIONAL and OPTIONAL[mod][1] is not None:
                    bad.append(f"{where}: in OPTIONAL as an extra, yet a default dependency")
                continue
            if mod not in OPTIONAL:
                bad.append(f"{where}: neither a default dependency (pyproject.toml) nor in tirecli.errors.OPTIONAL")
            elif func is None:
                bad.append(f"{where}: an optional library imported at module level")
            elif not _required_before(func, node) and (rel, func.name) not in CHECKED_BY_CALLER:
                bad.append(f"{where}: in {func.name}() without a require() before it")
    assert not bad, "\n".join(bad)


def test_campaign_libraries_are_in_the_default_install():
    """The README's campaign examples run after ``pip install .``: pyarrow (the campaign's point store,
    results.parquet) and SALib (Saltelli samples, Sobol' indices) are default dependencies; Dask (only
    for ``--scheduler``) is the ``campaign`` extra."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert {"pyarrow", "salib"} <= _default_dependencies()
    assert any(d.startswith("dask[distributed]") for d in project["optional-dependencies"]["campaign"])
    assert not any(d.lower().startswith("dask") for d in project["dependencies"])


def _count_point_checks(monkeypatch) -> list:
    """A list that grows by one for every point config checked (:func:`tirecli.studies.registry.check`)."""
    import tirecli.studies.registry as registry

    calls, real = [], registry.check
    monkeypatch.setattr(registry, "check", lambda *a, **k: calls.append(1) or real(*a, **k))
    return calls


def _one_line_hint(err: str, library: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert f"needs {library}, which is not installed" in err and "internal error" not in err, err


#: (libraries made missing, campaign example, more options, the library named, texts of the message)
MISSING = [
    (("SALib",), "campaign-mf-fy.yaml", (), "SALib", ("method: saltelli", "pip install 'SALib")),
    # campaign-fm-fig4-mc asked for pyarrow only after checking its 1000 points
    (("pyarrow",), "campaign-fm-fig4-mc.yaml", (), "pyarrow", ("a campaign", "pip install 'pyarrow")),
    # the hint works in a checkout (the README's install is from one) and names the package's extra too
    (("distributed", "dask"), "campaign-obs-convergence.yaml", ("--scheduler", "local"), "dask",
     ("--scheduler needs dask", "pip install '.[campaign]'", "'tirecli[campaign]'")),
]


@pytest.mark.parametrize("blocked, example, options, library, texts", MISSING, ids=[m[3] for m in MISSING])
def test_a_missing_library_is_one_line_before_any_point(cli, tmp_path, monkeypatch, blocked, example, options,
                                                        library, texts):
    block_module(monkeypatch, *blocked)
    calls = _count_point_checks(monkeypatch)
    code, out, err = cli("campaign", EXAMPLES / example, "--out", tmp_path / "c", "--jobs", "1", *options)
    assert code == 2, err
    _one_line_hint(err, library)
    assert all(t in err for t in texts), err
    assert not calls and "points" not in out and not (tmp_path / "c").exists()


@pytest.mark.parametrize("name", ["pyarrow.parquet", "dask", "SALib.analyze"])
def test_a_missing_optional_library_is_never_an_internal_error(cli, monkeypatch, name):
    """Where a code path imports an optional library without asking first, the CLI still says in one line
    what to install (exit 2)."""
    import tirecli.figures.registry as registry

    def missing():
        raise ModuleNotFoundError(f"No module named {name!r}", name=name)

    monkeypatch.setattr(registry, "load_all", missing)
    code, out, err = cli("figures", "list")
    assert code == 2, err
    _one_line_hint(err, name.split(".")[0])
    assert "pip install" in err


def test_an_unknown_missing_module_is_still_an_internal_error(cli, monkeypatch):
    import tirecli.figures.registry as registry

    def missing():
        raise ModuleNotFoundError("No module named 'nonexistent_xyz'", name="nonexistent_xyz")

    monkeypatch.setattr(registry, "load_all", missing)
    code, out, err = cli("figures", "list")
    assert code == 1 and "internal error: ModuleNotFoundError" in err


def test_the_readme_examples_are_extracted_for_ci():
    """tests/run_readme_examples.py (run by .ci/run after ``pip install .``) finds the README's commands,
    the report and both campaigns among them."""
    sys.path.insert(0, str(Path(__file__).parent))
    from run_readme_examples import readme_commands

    cmds = [" ".join(a) for a in readme_commands()]
    assert cmds[0] == "report" and len(cmds) >= 25
    assert "campaign examples/campaign-mf-fy.yaml" in cmds and "campaign examples/campaign-fm-fig4-mc.yaml" in cmds
    ci = (ROOT / ".ci" / "run").read_text()
    # the README's install command, exactly, before the examples run; the test extra only after them
    readme = (ROOT / "README.md").read_text()
    assert "pip install . && tirecli report" in readme
    assert ci.index("\npip install .\n") < ci.index("python3 tests/run_readme_examples.py") < ci.index("pip install '.[test]'")


QUICK = ("tir", "params", "figures")


@pytest.mark.parametrize("command", [c for c in shell_commands() if c.argv[0] in QUICK
                                     # a file an earlier command of the same block writes: run with its block
                                     # by the docs test (tests/test_docs.py)
                                     and not any("tirecli-out/" in a for a in c.argv)],
                         ids=lambda c: c.id)
def test_documented_quick_commands_exit_0(cli, command, monkeypatch):
    """A CI job that copies a command of the docs passes: each ``tir``, ``params`` and ``figures`` command
    shown exits 0 (``tirecli tir check chrono-185-80r14`` exits 1, so the docs show a tyre that passes)."""
    monkeypatch.chdir(ROOT)
    code, out, err = cli(*command.argv)
    assert code == 0, f"{command.id}: exit {code}\n{err}"
