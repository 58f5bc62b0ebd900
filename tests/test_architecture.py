"""The layers of tirecli and no import cycle, lazy (function-level) imports included.

The rules are the import-linter contracts in ``pyproject.toml`` (``[tool.importlinter]``): from the leaves
(errors; parallel, limits, conventions) through models and io, observers, numerics, config and parameters,
studies, figures, the application layer (app, report, campaign) up to the CLI, which only ``__main__``
imports. They run here on the import graph grimp builds from the source (every ``import`` statement,
also those inside functions); the same graph must have no cycle between modules.
"""
from __future__ import annotations

import contextlib
import copy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"


@pytest.fixture(scope="module")
def graph():
    """The import graph of this checkout's tirecli (built once for the module)."""
    import grimp

    import tirecli

    # the package under test: this checkout, or the copy of it that 'pip install .' made (CI)
    assert (Path(tirecli.__file__).resolve().parent / "__init__.py").read_bytes() == (ROOT / "tirecli" / "__init__.py").read_bytes()
    return grimp.build_graph("tirecli", cache_dir=None)


@contextlib.contextmanager
def _graph_given(graph):
    """import-linter checks a copy of ``graph`` instead of building its own."""
    from importlinter import api  # noqa: F401 - configures import-linter's adapters
    from importlinter.application.app_config import settings

    class Given:
        def build(self, **options):
            return copy.deepcopy(graph)

    saved = settings.GRAPH_BUILDER
    settings.configure(GRAPH_BUILDER=Given())
    try:
        yield
    finally:
        settings.configure(GRAPH_BUILDER=saved)


def lint(graph, contracts=()) -> tuple[bool, str]:
    """Check the contracts of pyproject.toml (only ``contracts``, by id, when given) on ``graph`` with
    import-linter: ``(all kept, import-linter's report)``."""
    from importlinter.application import use_cases
    from importlinter.application.output import console

    with _graph_given(graph), console.capture() as text:
        kept = use_cases.lint_imports(str(PYPROJECT), limit_to_contracts=tuple(contracts), cache_dir=None,
                                      no_logo=True)
    return kept, text.get()


def contract_ids() -> list[str]:
    from importlinter import api

    return [c["id"] for c in api.read_configuration(str(PYPROJECT))["contracts_options"]]


def test_the_import_contracts_are_kept(graph):
    assert contract_ids() == ["layers", "observers-numerics-no-io", "config-parameters-no-numerics",
                              "figures-draw-only"]
    kept, text = lint(graph)
    assert kept, text
    assert "4 kept, 0 broken" in text, text


@pytest.mark.parametrize("importer, imported, contract", [
    ("tirecli.models.lugre", "tirecli.io.files", "layers"),                    # models: no file access
    ("tirecli.io.fastcsv", "tirecli.numerics.lumped", "layers"),               # io: only io and leaves
    ("tirecli.io.output", "tirecli.figures.registry", "layers"),
    ("tirecli.limits", "tirecli.config.schema", "layers"),                     # a leaf imports no other layer
    ("tirecli.parallel", "tirecli.conventions", "layers"),                     # ... nor another leaf (but errors)
    ("tirecli.studies.mf_sweep", "tirecli.app.mf", "layers"),                  # studies: no application layer
    ("tirecli.studies.base", "tirecli.figures.registry", "layers"),            # ... no figures
    ("tirecli.report.build", "tirecli.cli.main", "layers"),                    # only __main__ imports the CLI
    ("tirecli.numerics.lumped", "tirecli.io.data", "observers-numerics-no-io"),
    ("tirecli.observers.metrics", "tirecli.io.files", "observers-numerics-no-io"),
    ("tirecli.parameters.sets", "tirecli.numerics.runs", "config-parameters-no-numerics"),
    ("tirecli.config.loader", "tirecli.numerics.runs", "config-parameters-no-numerics"),
    ("tirecli.figures.steady", "tirecli.numerics.characteristics", "figures-draw-only"),
    ("tirecli.figures.transient", "tirecli.io.output", "figures-draw-only"),
])
def test_a_forbidden_import_breaks_its_contract(graph, importer, imported, contract):
    g = copy.deepcopy(graph)
    g.add_import(importer=importer, imported=imported, line_number=1, line_contents=f"import {imported}  # test")
    kept, text = lint(g, [contract])
    assert not kept and "BROKEN" in text and f"{importer} -> {imported}" in text, text


def find_cycle(graph) -> list[str] | None:
    """One import cycle of ``graph`` as ``[a, b, ..., a]`` (a strongly connected component of more than one
    module, walked from its first module back to it), or None when there is none."""
    index, low, stack, on_stack, comps = {}, {}, [], set(), []
    for start in sorted(graph.modules):  # Tarjan's algorithm, iterative (no recursion limit)
        if start in index:
            continue
        work = [(start, iter(sorted(graph.find_modules_directly_imported_by(start))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.find_modules_directly_imported_by(child)))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = set()
                while True:
                    m = stack.pop()
                    on_stack.discard(m)
                    comp.add(m)
                    if m == node:
                        break
                if len(comp) > 1:
                    comps.append(comp)
    if not comps:
        return None
    comp = min(comps, key=lambda c: (len(c), sorted(c)))
    first = min(comp)
    # the shortest way from first back to first inside the component (breadth first)
    prev, frontier = {}, [first]
    while frontier:
        nxt = []
        for m in frontier:
            for t in sorted(graph.find_modules_directly_imported_by(m) & comp):
                if t == first:
                    path = [m]
                    while path[-1] != first:
                        path.append(prev[path[-1]])
                    return [first] + path[::-1][1:] + [first] if len(path) > 1 else [first, first]
                if t not in prev:
                    prev[t] = m
                    nxt.append(t)
        frontier = nxt
    raise AssertionError("unreachable: a component of several modules has a cycle")


def describe(graph, cycle: list[str]) -> str:
    """``a -> b (a.py:12) -> ...``: each import of the cycle with the line that makes it."""
    parts = [cycle[0]]
    for a, b in zip(cycle, cycle[1:]):
        lines = sorted(d["line_number"] for d in graph.get_import_details(importer=a, imported=b))
        parts.append(f"{b} (line {lines[0] if lines else '?'} of {a})")
    return " -> ".join(parts)


def test_no_import_cycle_between_modules(graph):
    cycle = find_cycle(graph)
    assert cycle is None, "import cycle: " + describe(graph, cycle)


def test_the_cycle_check_finds_and_names_a_cycle(graph):
    import grimp

    g = grimp.ImportGraph()
    for a, b in (("p.a", "p.b"), ("p.b", "p.c"), ("p.c", "p.a"), ("p.c", "p.d"), ("p.d", "p.e")):
        g.add_import(importer=a, imported=b, line_number=3, line_contents=f"import {b}")
    assert find_cycle(g) == ["p.a", "p.b", "p.c", "p.a"]
    assert describe(g, find_cycle(g)) == "p.a -> p.b (line 3 of p.a) -> p.c (line 3 of p.b) -> p.a (line 3 of p.c)"
    g.remove_import(importer="p.c", imported="p.a")
    assert find_cycle(g) is None
    # and in tirecli itself: a lazy import from a leaf back up closes a cycle
    g = copy.deepcopy(graph)
    g.add_import(importer="tirecli.limits", imported="tirecli.config.schema", line_number=1, line_contents="x")
    cycle = find_cycle(g)
    assert cycle[0] == cycle[-1] and {"tirecli.limits", "tirecli.config.schema"} <= set(cycle), cycle


# --------------------------------------------------------------------------- module size

#: Largest module under tirecli/ [lines] (ARCHITECTURE.md, "Size": split by concept, not by line count).
MAX_LINES = 600
#: Modules over MAX_LINES still allowed (none: every module was split by concept).
OVERSIZED_ALLOWED: frozenset = frozenset()


def oversized(root: Path, limit: int = MAX_LINES, allowed=frozenset()) -> dict[str, int]:
    """The modules under ``root / 'tirecli'`` over ``limit`` lines and not ``allowed`` (paths relative to ``root``,
    with ``/``): path -> line count."""
    found = {}
    for path in sorted((root / "tirecli").rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n > limit and rel not in allowed:
            found[rel] = n
    return found


def test_no_module_is_over_600_lines():
    assert oversized(ROOT, allowed=OVERSIZED_ALLOWED) == {}, f"split by concept (at most {MAX_LINES} lines a module)"


def test_the_size_check_finds_a_long_module(tmp_path):
    pkg = tmp_path / "tirecli" / "sub"
    pkg.mkdir(parents=True)
    (pkg / "short.py").write_text("x = 1\n" * MAX_LINES)
    (pkg / "long.py").write_text("x = 1\n" * (MAX_LINES + 1))
    assert oversized(tmp_path) == {"tirecli/sub/long.py": MAX_LINES + 1}
    assert oversized(tmp_path, allowed={"tirecli/sub/long.py"}) == {}
