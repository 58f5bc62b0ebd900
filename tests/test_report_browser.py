"""The report in a real browser: headless Chromium renders index.html on a desktop (1280 px), a phone
(420 px) and for print; every figure image must load and nothing may reach past the page's width
unless it is inside a box marked as scrolling sideways (tests/browser.py). On the phone the tables are
stacked rows that fit the screen and a figure of many panels pans in such a box, with a link to the
file; in print every table is there, those of closed sections too.

The browser is driven over the DevTools protocol on a pipe (tests/browser.py, no extra package).
Screenshots (and a PDF of the print layout) are saved in the test's temporary folder, or in
``$TIRECLI_TEST_ARTIFACTS`` when set. Without Chromium (Debian package ``chromium``; ``.ci/run``
installs it where it can) the tests are skipped with a message.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

import pytest

from browser import Browser, find_chromium, inspect_page, problems

CHROMIUM = find_chromium()
pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="Chromium not found: install the Debian package 'chromium' (or set TIRECLI_CHROMIUM "
                             "to a Chromium/Chrome executable) to run the report's browser tests")

#: A small report: two table cards (FM Table 1, the MCPS parameters), a figure beside its text, a wide
#: six-panel figure, three papers.
SUBSET = ["fm-table1", "fm-fig1-left", "mf-tire-pacejka2006-205-60r15", "mcps-fig10", "mcps-table"]

#: On the phone: each table's layout and size, and each wide figure's box and link.
PHONE = r"""(() => {
  const lines = el => el.getBoundingClientRect().height / parseFloat(getComputedStyle(el).lineHeight);
  const tables = [...document.querySelectorAll('main table')].map(t => {
    const cells = [...t.querySelectorAll('td')].filter(td => td.getBoundingClientRect().height > 0);
    return {card: (t.closest('article') || {}).id || '', summary: t.classList.contains('summary'),
            stacked: getComputedStyle(t).display === 'block', right: t.getBoundingClientRect().right,
            unlabelled: cells.filter(td => ['none', 'normal', '""'].includes(getComputedStyle(td, '::before').content)).length,
            tallest: Math.max(0, ...cells.map(lines))};
  });
  const wide = [...document.querySelectorAll('article.card.wide')].map(c => {
    const f = c.querySelector('.figure'), open = c.querySelector('.open');
    return {card: c.id, ratio: f.scrollWidth / f.clientWidth,
            link: !!open && getComputedStyle(open).display !== 'none' && !!open.querySelector('a[href$=".png"]')};
  });
  return {tables, wide};
})()"""

#: In print: every table, and how many of them are in sections that are closed on the screen.
PRINT = r"""(() => {
  const tables = [...document.querySelectorAll('main table')];
  return {n: tables.length, hidden: tables.filter(t => t.getBoundingClientRect().height === 0).length,
          in_closed: tables.filter(t => { const d = t.closest('details'); return d && !d.open; }).length};
})()"""
#: Viewports: name, width [CSS px], phone.
VIEWS = [("desktop", 1280, False), ("phone", 420, True)]


def _artifacts(tmp_path_factory, name: str) -> Path:
    root = os.environ.get("TIRECLI_TEST_ARTIFACTS")
    path = Path(root) / name if root else tmp_path_factory.mktemp(name)
    path.mkdir(parents=True, exist_ok=True)
    return path


def _build(out: Path, only=(), drift: bool = False) -> Path:
    from tirecli.cli.main import main

    args = ["--quiet", "report", "--out", str(out)]
    for name in only:
        args += ["--only", name]
    if drift:  # one drifted reference: the summary then lists a failing check with its link
        from tirecli.studies.checks import steady

        # a cache of its own: the session's may hold the card with the real reference, and must not get the drifted one
        args += ["--cache", str(out.parent / "drift-cache")]

        with pytest.MonkeyPatch.context() as mp:
            mp.setitem(steady._REF_SPEEDS, 20, (1.20, 0.212, 0.6451, 0.8717))
            assert main(args) == 0
    else:
        assert main(args) == 0
    return out


@pytest.fixture(scope="session")
def browser():
    with Browser(CHROMIUM) as b:
        yield b


@pytest.fixture(scope="session")
def small_report(tmp_path_factory):
    """The report of :data:`SUBSET`, built once per session, with one failing check."""
    return _build(tmp_path_factory.mktemp("browser-report") / "report", SUBSET, drift=True)


def _check_views(browser, report: Path, shots: Path) -> dict:
    """Inspect ``report/index.html`` in every view and for print; save screenshots; the measures."""
    n_png = len(list((report / "figures").glob("*.png")))
    measures = {}
    for name, width, phone in VIEWS:
        m = inspect_page(browser, report / "index.html", width, mobile=phone)
        shot = browser.screenshot(shots / f"report-{name}-{width}px.png")
        bad = problems(m)
        assert not bad, f"{name} ({width} px, screenshot {shot}):\n" + "\n".join(bad)
        assert len(m["images"]) == n_png, f"{len(m['images'])} images on the page, {n_png} figures written"
        if phone:
            m["layout"] = browser.evaluate(PHONE)
        measures[name] = m
    browser.send("Emulation.setEmulatedMedia", {"media": "print"})
    try:
        m = inspect_page(browser, report / "index.html", 680)  # A4 less the print margins, in CSS px
        bad = problems(m)
        assert not bad, "print layout:\n" + "\n".join(bad)
        m["tables"] = browser.evaluate(PRINT)
        pdf = browser.send("Page.printToPDF", {"printBackground": False, "preferCSSPageSize": True})
    finally:
        browser.send("Emulation.setEmulatedMedia", {"media": ""})
    import base64

    data = base64.b64decode(pdf["data"])
    assert data.startswith(b"%PDF")
    (shots / "report-print.pdf").write_bytes(data)
    measures["print"] = m
    return measures


def test_small_report_in_the_browser(browser, small_report, tmp_path_factory):
    shots = _artifacts(tmp_path_factory, "report-screenshots")
    m = _check_views(browser, small_report, shots)
    # the six-panel sweep spans the card on the desktop; the others leave room for the paper's text beside them
    wide = [i for i in m["desktop"]["images"] if i["alt"].startswith("mf-tire-")]
    narrow = [i for i in m["desktop"]["images"] if i["alt"].startswith("fm-fig1-left:")]
    assert wide and narrow and wide[0]["width"] > 1000 > narrow[0]["width"]
    # on the phone every image fits the screen, or pans in its box (a figure of many panels, at twice the width)
    assert all(i["width"] <= 420 or i["in_scroll_box"] for i in m["phone"]["images"])
    _phone_layout(m["phone"]["layout"])
    # in print every table is there: those of the closed sections (parameters, checks that passed) too
    assert m["print"]["tables"]["hidden"] == 0 and m["print"]["tables"]["in_closed"] >= len(SUBSET), m["print"]["tables"]
    # the paper's description beside a figure where there is room, else below it
    assert _layout(browser, small_report, 1280, False) == {
        "fm-table1": "beside", "fm-fig1-left": "beside", "mf-tire-pacejka2006-205-60r15": "below", "mcps-fig10": "below",
        "mcps-table": "beside"}
    assert set(_layout(browser, small_report, 420, True).values()) == {"below"}
    for f in ("report-desktop-1280px.png", "report-phone-420px.png", "report-print.pdf"):
        assert (shots / f).stat().st_size > 1000


def _phone_layout(layout: dict) -> None:
    """Tables of the cards are stacked rows (each cell named, no cell taller than 4 lines), fit the 420 px
    screen; each wide figure pans at twice the width, with a visible link to its file."""
    cards = [t for t in layout["tables"] if not t["summary"]]
    assert cards and all(t["stacked"] and t["right"] <= 420 and not t["unlabelled"] for t in cards), cards
    mcps = [t for t in cards if t["card"] == "mcps-table"]
    assert mcps and all(t["tallest"] <= 4.05 for t in mcps), mcps  # it had rows of 8-10 lines
    assert all(t["tallest"] <= 6.05 for t in cards), [t for t in cards if t["tallest"] > 6.05]
    assert layout["wide"] and all(w["ratio"] > 1.9 and w["link"] for w in layout["wide"]), layout["wide"]


def _layout(browser, report: Path, width: int, phone: bool) -> dict:
    """Card id -> where its "paper shows" box is: beside or below the figure column."""
    browser.open(report / "index.html", width, mobile=phone)
    return browser.evaluate("""Object.fromEntries([...document.querySelectorAll('article.card')].map(c => {
      const o = c.querySelector('.ours').getBoundingClientRect(), p = c.querySelector('.paper').getBoundingClientRect();
      return [c.id, p.left >= o.right - 1 ? 'beside' : p.top >= o.bottom - 1 ? 'below' : 'overlapping'];
    }))""")


def test_summary_links_reach_the_failing_checks_and_every_card(browser, small_report):
    browser.open(small_report / "index.html", 1280)
    got = browser.evaluate(r"""(() => {
      const target = a => document.getElementById(decodeURIComponent(a.getAttribute('href').slice(1)));
      const failing = [...document.querySelectorAll('.failing a')].map(a => {
        const t = target(a); return {href: a.getAttribute('href'), found: !!t, visible: !!t && t.offsetHeight > 0}; });
      const toc = [...document.querySelectorAll('nav.toc a')].map(a => [a.getAttribute('href'), !!target(a)]);
      const cards = [...document.querySelectorAll('article.card')].map(c => c.id);
      return {failing, toc, cards};
    })()""")
    summary = json.loads((small_report / "summary.json").read_text())
    failed = [c["id"] for c in summary["checks"] if not c["passed"]]
    assert "fm-fig1-left/peak-v20" in failed
    assert [f["href"] for f in got["failing"]] == [f"#check-{i}" for i in failed]
    assert all(f["found"] and f["visible"] for f in got["failing"])
    assert all(found for _, found in got["toc"])
    assert {h[1:] for h, _ in got["toc"] if not h.startswith("#paper-")} == set(got["cards"]) == set(SUBSET)


def test_the_checks_can_fail(browser, small_report):
    """A page that overflows, and an image that does not load, are reported."""
    html = (small_report / "index.html").read_text(encoding="utf-8")
    broken = small_report / "broken.html"
    broken.write_text(html.replace('<main>', '<main><div id="too-wide" style="width: 2000px">a wide block</div>'
                                            '<table><tr><td>' + "x" * 400 + '</td></tr></table>'
                                            '<img alt="missing" src="figures/missing.png">'
                                            '<div style="overflow-x: auto"><p id="unmarked" style="width: 3000px">'
                                            'scrolls in a box that does not say so</p></div>', 1), encoding="utf-8")
    try:
        for _, width, phone in VIEWS:
            bad = problems(inspect_page(browser, broken, width, mobile=phone))
            assert any("scrolls sideways" in p for p in bad), bad
            assert any("too-wide" in p for p in bad), bad
            assert any(p == "image not loaded: missing" for p in bad), bad
            assert any("unmarked" in p for p in bad), bad
    finally:
        broken.unlink()


@pytest.mark.slow
def test_full_report_in_the_browser(browser, tmp_path_factory):
    """The default report, every figure: also run by hand (pytest -m slow)."""
    report = _build(tmp_path_factory.mktemp("browser-full") / "report")
    summary = json.loads((report / "summary.json").read_text())
    assert summary["n_failed"] == 0
    _check_views(browser, report, _artifacts(tmp_path_factory, "report-screenshots-full"))
    html = (report / "index.html").read_text(encoding="utf-8")
    assert len(re.findall(r'<article class="card', html)) == summary["n_figures"]
