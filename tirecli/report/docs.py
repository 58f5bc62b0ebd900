"""The user documentation inside the report: the pages of ``docs/`` as HTML in ``DIR/docs/``.

The report is a folder that must work offline and without the repository (``pip install .``
puts no ``docs/`` beside the package), so the pages travel with the package and are copied into
the report: a wheel carries them as ``tirecli/docs/`` (``setup.py`` copies ``docs/models/*.md``
and ``docs/*.md`` there at build time); a source checkout or an editable install reads the
repository's ``docs/``. Each page is rendered to one self-contained HTML file (markdown-it, which
Typer's ``rich`` brings; a plain-text page if it is missing), headings carry GitHub's anchors and
``sN`` for section N, and links between the pages point to the HTML copies.

Card links: :data:`PAPER_DOC` maps a figure's paper to its model page; :func:`link_sources` turns
the ``docs/models/NAME.md §N`` of check sources and captions into links.
"""
from __future__ import annotations

import html
import re
from pathlib import Path

from markupsafe import Markup

from tirecli.io import output
from tirecli.io.cache import memo_text

#: Paper of a figure (registry ``paper``) -> model page under docs/models/.
PAPER_DOC = {"FM": "lugre_friction", "OBS": "observer_model", "MF": "magic_formula_tyre", "MCPS": "mcps_tire"}

_REF = re.compile(r"docs/models/(\w+)\.md(?: (§\d+(?:\.\d+)?))?")
_LINK = re.compile(r'href="([^"#:]+)\.md(#[^"]*)?"')


def source_dir() -> Path | None:
    """The folder holding ``models/*.md`` (and the command guides): the package's copy, else the
    repository's ``docs/`` next to the package; None when neither exists."""
    here = Path(__file__).resolve().parent.parent
    for cand in (here / "docs", here.parent / "docs"):
        if (cand / "models").is_dir() and any((cand / "models").glob("*.md")):
            return cand
    return None


def slug(text: str) -> str:
    """GitHub's heading anchor: lower case, punctuation dropped, blanks to hyphens."""
    text = re.sub(r"<[^>]+>", "", text).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def _render_markdown(text: str) -> str:
    try:
        from markdown_it import MarkdownIt
    except ImportError:  # pragma: no cover - rich (a Typer dependency) brings markdown-it-py
        return f"<pre>{html.escape(text)}</pre>"
    md = MarkdownIt("commonmark", {"html": False}).enable("table")
    tokens = md.parse(text)
    for i, tok in enumerate(tokens):
        if tok.type == "heading_open" and i + 1 < len(tokens):
            title = tokens[i + 1].content
            tok.attrSet("id", slug(title))
    body = md.renderer.render(tokens, md.options, {})

    # "## 7. Title" / "### 3.3 Title": also an anchor "s7" / "s3.3", the target of "docs/models/NAME.md §7"
    return re.sub(r'(<h[23] id="[^"]*">)(\d+(?:\.\d+)?)(?=[. ])', r'\1<a id="s\2"></a>\2', body)


_PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title} - tirecli documentation</title>
<style>
body {{ font-family: -apple-system, "Segoe UI", Roboto, Helvetica, Arial, sans-serif; margin: 0 auto; padding: 1em 2em 3em;
       max-width: 60em; color: #222; line-height: 1.45; }}
pre, code {{ font-family: monospace; font-size: .9em; }} pre {{ background: #f5f5f5; padding: .6em; overflow-x: auto; }}
table {{ border-collapse: collapse; font-size: .88em; margin: .6em 0; display: block; overflow-x: auto; }}
th, td {{ border: 1px solid #ddd; padding: .2em .5em; text-align: left; vertical-align: top; }} th {{ background: #fafafa; }}
h2 {{ border-bottom: 1px solid #ccc; padding-bottom: .15em; margin-top: 1.6em; }}
.nav {{ font-size: .9em; color: #666; }}
</style></head><body>
<p class="nav">tirecli {version} documentation &middot; {source} &middot; <a href="{back}">back to the report</a></p>
{body}
</body></html>
"""


def write_docs(out: Path, version: str, cache=None) -> dict[str, str]:
    """Render every page into ``out/docs/`` (same layout as the repository's ``docs/``); ``cache``:
    the report's cache folder, which keeps the rendered pages (:func:`tirecli.io.cache.memo_text`).

    Returns ``{"models/lugre_friction": "docs/models/lugre_friction.html", ...}`` (paths relative to ``out``); empty
    when the documentation is not installed (the cards then name the page without a link).
    """
    src = source_dir()
    if src is None:
        return {}
    pages = sorted(src.glob("*.md")) + sorted((src / "models").glob("*.md"))
    names = {p.relative_to(src).with_suffix("").as_posix() for p in pages}
    written = {}
    for page in pages:
        rel = page.relative_to(src).with_suffix("")
        text = page.read_text(encoding="utf-8")
        body = memo_text(cache, {"markdown": text}, lambda text=text: _render_markdown(text))
        here = rel.parent.as_posix()

        def relink(m, here=here):
            target = (Path(here) / m.group(1)).as_posix()
            parts = []
            for part in target.split("/"):
                if part == "..":
                    if parts:
                        parts.pop()
                elif part not in ("", "."):
                    parts.append(part)
            if "/".join(parts) in names:
                return f'href="{m.group(1)}.html{m.group(2) or ""}"'
            return m.group(0)

        body = _LINK.sub(relink, body)
        title = re.search(r"<h1[^>]*>(.*?)</h1>", body)
        dest = out / "docs" / rel.with_suffix(".html")
        back = "../" * (len(rel.parts)) + "index.html"
        dest.parent.mkdir(parents=True, exist_ok=True)
        output.write_text(dest, _PAGE.format(title=re.sub(r"<[^>]+>", "", title.group(1)) if title else rel.name,
                                     version=version, source=f"docs/{rel.as_posix()}.md", back=back, body=body))
        written[rel.as_posix()] = f"docs/{rel.as_posix()}.html"
    return written


def card_doc(paper: str, written: dict[str, str]) -> dict | None:
    """The model page of a card: ``{"name": "docs/models/lugre_friction.md", "href": ... or None}``."""
    page = PAPER_DOC.get(paper)
    if page is None:
        return None
    return {"name": f"docs/models/{page}.md", "href": written.get(f"models/{page}")}


def link_sources(text, written: dict[str, str]) -> Markup:
    """``text`` HTML-escaped, with each ``docs/models/NAME.md §N`` a link to the report's copy."""
    esc = str(Markup.escape(text if text is not None else ""))

    def repl(m):
        href = written.get(f"models/{m.group(1)}")
        if href is None:
            return m.group(0)
        anchor = f"#s{m.group(2)[1:]}" if m.group(2) else ""
        return f'<a href="{href}{anchor}">{m.group(0)}</a>'

    return Markup(_REF.sub(repl, esc))
