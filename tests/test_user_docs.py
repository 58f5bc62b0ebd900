"""Nothing user-facing refers to files a user does not have; the model documentation is complete
and the report links it.

Users get the repository's README, ``docs/``, ``examples/`` and the installed package (its sources,
templates, built-in configs and parameter sets, whose texts end up in captions, check sources,
run.json, warnings and ``--help``). Every reference there must point inside the repository: to a
page of ``docs/models/`` with its section (``docs/models/lugre_friction.md §7``) or to a paper (``FM eq. (9)``),
never to the development specification or other folders outside the repository.
"""
from __future__ import annotations

import io
import re
import tokenize
from pathlib import Path

import pytest

from conftest import ROOT

#: What users receive: the README, the docs, the examples and the package (sources and package data).
USER_FILES = sorted({ROOT / "README.md", ROOT / "setup.py",
                     *(ROOT / "docs").rglob("*.md"),
                     *(p for p in (ROOT / "examples").rglob("*") if p.is_file()),
                     *(p for p in (ROOT / "tirecli").rglob("*")
                       if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".pyc")})

#: Anywhere: paths outside the repository.
OUTSIDE = re.compile(r"\.\./shared|\bshared/(?:spec|papers|data)\b|/work/|\.\./\.\./\.\.")
#: In prose (Markdown, YAML, .tir, templates; strings and comments of Python): the development
#: specification by name.
SPEC_PROSE = re.compile(r"(?i)\bthe spec\b|\bspec's\b|\bspec\s*§|\(spec\b|\bspec(?: value)?:|\bproject spec"
                        r"|\bspec\s+`?\w+\.md|\bspecification\b")
#: The file names of the development specification's pages. The user's pages are named otherwise
#: (docs/models/lugre_friction.md, ...), so that no user-facing text can be read as citing a page
#: users do not have, whatever folder precedes the name.
SPEC_PAGE = re.compile(r"(?<![\w-])(?:figures|lugre|magic_formula|mcps|observer)\.md\b")
#: Any Markdown file named in the text.
MD_NAME = re.compile(r"(?<![\w.-])((?:\.\./|\./)?[\w./-]*[\w-]\.md)\b")
#: A section of a model page: docs/models/NAME.md §N or §N.M.
SECTION = re.compile(r"docs/models/(\w+)\.md §(\d+(?:\.\d+)?)")


def _prose(path: Path) -> str:
    """The text a user reads: all of it, except in Python where only strings and comments count
    (``spec`` is also the name of schema objects in code)."""
    text = path.read_text(encoding="utf-8", errors="replace")
    if path.suffix != ".py":
        return text
    out = []
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type in (tokenize.STRING, tokenize.COMMENT) or getattr(tokenize, "FSTRING_MIDDLE", -1) == tok.type:
            out.append(tok.string)
    return "\n".join(out)


def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _resolves(name: str, path: Path) -> bool:
    """Whether a Markdown file named in ``path`` exists: relative to that file's folder (links
    inside docs/), to docs/ (link labels of the model pages) or to the repository root."""
    name = name.split("#")[0]
    if "NAME" in name:  # a placeholder (docs/models/NAME.md)
        return True
    return any((base / name).is_file() for base in (path.parent, ROOT, ROOT / "docs"))


def test_user_files_found():
    names = {_rel(p) for p in USER_FILES}
    assert {"README.md", "docs/models/lugre_friction.md", "docs/models/observer_model.md", "docs/models/magic_formula_tyre.md",
            "docs/models/mcps_tire.md", "docs/models/README.md", "tirecli/templates/report.html.j2"} <= names
    assert any(n.startswith("tirecli/studies/configs/") for n in names)
    assert any(n.startswith("tirecli/parameters/data/") for n in names)


def test_no_reference_outside_the_repository():
    bad = []
    for path in USER_FILES:
        text = path.read_text(encoding="utf-8", errors="replace")
        prose = _prose(path)
        for lineno, line in enumerate(text.splitlines(), 1):
            for m in OUTSIDE.finditer(line):
                bad.append(f"{_rel(path)}:{lineno}: {m.group(0)!r} (a path outside the repository)")
        for m in SPEC_PROSE.finditer(prose):
            bad.append(f"{_rel(path)}: {m.group(0)!r} (the development specification; cite docs/models/ or the paper)")
        for m in SPEC_PAGE.finditer(prose):
            bad.append(f"{_rel(path)}: {m.group(0)!r} (the name of a specification page; cite docs/models/NAME.md)")
        for m in MD_NAME.finditer(prose):
            if not _resolves(m.group(1), path):
                bad.append(f"{_rel(path)}: {m.group(1)!r} names no file of the repository")
    assert not bad, "user-facing references to files users do not have:\n" + "\n".join(sorted(set(bad)))


def test_cited_sections_exist():
    """Every ``docs/models/NAME.md §N`` cited anywhere users look has that numbered section."""
    heads = {}
    for page in (ROOT / "docs" / "models").glob("*.md"):
        heads[page.stem] = set(re.findall(r"(?m)^#{2,3} (\d+(?:\.\d+)?)[. ]", page.read_text(encoding="utf-8")))
    bad = []
    for path in USER_FILES:
        for m in SECTION.finditer(path.read_text(encoding="utf-8", errors="replace")):
            page, sec = m.groups()
            if page != "NAME" and (page not in heads or sec not in heads[page]):
                bad.append(f"{_rel(path)}: {m.group(0)}")
    assert not bad, "cited sections that do not exist:\n" + "\n".join(sorted(set(bad)))


@pytest.mark.parametrize("page", ["lugre_friction", "observer_model", "magic_formula_tyre", "mcps_tire"])
def test_model_pages_are_numbered(page):
    text = (ROOT / "docs" / "models" / f"{page}.md").read_text(encoding="utf-8")
    numbers = [int(n) for n in re.findall(r"(?m)^## (\d+)\. ", text)]
    assert numbers == list(range(1, len(numbers) + 1)) and len(numbers) >= 8


def test_report_cards_link_their_model_page(tmp_path):
    """The report carries the pages as HTML and each card links its model's page (offline)."""
    from tirecli.report.build import build_report

    out = tmp_path / "report"
    build_report(out, only=["fm-fig1-right", "fm-table2"])
    html = (out / "index.html").read_text(encoding="utf-8")
    assert 'href="docs/models/lugre_friction.html"' in html
    assert 'href="docs/models/lugre_friction.html#s5"' in html  # a check source linked to its section
    page = (out / "docs" / "models" / "lugre_friction.html").read_text(encoding="utf-8")
    assert 'id="s5"' in page and 'id="s10"' in page and "<table>" in page
    assert (out / "docs" / "models" / "observer_model.html").is_file()
    for doc in [html, page]:
        assert not OUTSIDE.search(doc) and not SPEC_PROSE.search(doc)
    assert "scenario: scenario:" not in html and "ASSUMED</span> scenario: scenario" not in html


#: Rows of docs/transient.md's table of FM checks: (figure, words of the row's check column) -> the
#: check ids whose values the row's tirecli column quotes, in order.
TRANSIENT_ROWS = {("fm-fig7", "kappa0 = 1"): ["maxdmu-k1", "rms100-k1"],
                  ("fm-fig7", "kappa0 = 2"): ["maxdmu-k2", "rms100-k2"],
                  ("fm-fig8", "kappa0(Z) (+ max"): ["maxdmu-kZ", "rms100-kZ", "max100-kZ"],
                  ("fm-fig8", "coupled quarter car"): ["coupled-dmu", "coupled-ds"]}


def test_transient_guide_quotes_the_checks_it_lists(cli, tmp_path):
    """docs/transient.md's table of the FM Figs. 7-8 checks quotes what `tirecli simulate` gives, to
    the digits it prints (it said 0.0095 for 0.0097 and 0.1243 for 0.12438), and its reference column
    states the checks' bounds (it said '<= 0.0046' for a check of 0.0046 +- 0.0005 that 0.00476 passes)."""
    import json

    text = (ROOT / "docs" / "transient.md").read_text(encoding="utf-8")
    checks = {}
    for fig in ("fm-fig7", "fm-fig8"):
        code, _, err = cli("simulate", ROOT / "examples" / f"{fig}.yaml", "--out", tmp_path / fig, "-q")
        assert code == 0, err
        run = json.loads((tmp_path / fig / "run.json").read_text(encoding="utf-8"))
        checks.update({c["id"]: c for c in run["checks"]})
    number = re.compile(r"-?\d+\.\d+")
    for (fig, words), ids in TRANSIENT_ROWS.items():
        rows = [line for line in text.splitlines() if line.startswith(f"| {fig} |") and words in line]
        assert len(rows) == 1, (fig, words)
        _, _, _, quoted, reference, _ = rows[0].split("|")
        values = number.findall(quoted)
        assert len(values) == len(ids), rows[0]
        for q, cid in zip(values, ids):
            c = checks[f"{fig}/{cid}"]
            digits = len(q.split(".")[1])
            assert abs(c["value"] - float(q)) <= 0.5 * 10.0 ** -digits + 1e-12, (cid, q, c["value"])
        if "<=" in reference:  # a stated upper bound must be one the checks hold
            for cid, bound in zip(ids, number.findall(reference)):
                assert checks[f"{fig}/{cid}"]["value"] <= float(bound), (cid, bound)


def test_documented_commands_write_inside_the_working_folder():
    """A documented command line writes where the reader runs it (``--out tirecli-out/...``), not to a
    folder of the machine the docs were written on (docs/models/mcps_tire.md had ``--out /tmp/docrx``,
    which does not exist on Windows and is shared with other users elsewhere)."""
    from pathlib import PurePosixPath, PureWindowsPath

    from doc_commands import shell_commands

    bad = []
    for cmd in shell_commands():
        for opt, value in zip(cmd.argv, cmd.argv[1:]):
            if opt in ("--out", "-o", "--junit", "--cache", "--data", "-d", "--points") and (
                    PurePosixPath(value).is_absolute() or PureWindowsPath(value).is_absolute()):
                bad.append(cmd.id)
    assert bad == []
