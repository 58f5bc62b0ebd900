"""``tirecli report``: run the built-in study of every registered figure, render one HTML file.

Writes ``DIR/index.html`` (self-contained: figures embedded as PNG, no network resources),
``DIR/summary.json`` (every reference check), ``DIR/figures/ID.png|svg`` (tables as CSV),
``DIR/data/STUDY/NAME.csv``, ``DIR/studies/STUDY.json`` (the run record of each study) and
``DIR/docs/`` (the user documentation as HTML; each card links its model's page, see
:mod:`tirecli.report.docs`). Written like every run (:func:`tirecli.io.staging.staged_dir`),
``summary.json`` last: it lists the report's files (``outputs``).
"""
from __future__ import annotations

import threading
import time
import traceback
from pathlib import Path

import jinja2

from tirecli._version import __version__
from tirecli.figures.registry import PAPERS, load_all
from tirecli.io import output
from tirecli.io.staging import out_path, staged_dir
from tirecli.io.cache import read_bytes, read_timings, write_timings
from tirecli.io.files import check_output_dir
from tirecli.parallel import default_jobs
from tirecli.report.cards import card_files, page_image
from tirecli.report import work
from tirecli.report.docs import card_doc, link_sources, write_docs
from tirecli.studies.base import Check
from tirecli.studies.configs import builtin_config

PAPER_ORDER = ["FM", "OBS", "MF", "MCPS"]


def _env() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader("tirecli", "templates"),
        autoescape=jinja2.select_autoescape(["html", "j2"]),
        undefined=jinja2.StrictUndefined,
    )


def _select(reg: dict, only) -> list:
    """The report's figures: all with a built-in study, or those ``only`` names (a paper such as
    ``FM``, any case, or a figure id); an unknown name is a UsageError with a did-you-mean."""
    import difflib

    from tirecli.errors import UsageError

    entries = [f for f in reg.values() if f.study]
    if only:
        papers = {f.paper.lower(): f.paper for f in entries}
        ids = {f.id for f in entries}
        wanted = set()
        for name in only:
            if name.lower() in papers:
                wanted.add(papers[name.lower()])
            elif name in ids:
                wanted.add(name)
            else:
                hint = difflib.get_close_matches(name, sorted(ids) + sorted(papers.values()), n=1)
                dym = f"; did you mean {hint[0]!r}?" if hint else ""
                raise UsageError(f"--only {name!r}: not a paper ({', '.join(sorted(papers.values()))}) nor a figure "
                                 f"of the report{dym} (see 'tirecli figures list')")
        entries = [f for f in entries if f.paper in wanted or f.id in wanted]
    return sorted(entries, key=lambda f: (PAPER_ORDER.index(f.paper) if f.paper in PAPER_ORDER else 99, f.order, f.id))


def build_report(out: str | Path, only=None, progress=None, campaigns=(), jobs: int | None = None,
                 cache: str | Path | None = None, use_cache: bool = True, formats=("png",), note=None) -> dict:
    """Build the report into ``out``; returns the summary (also written as ``summary.json``).

    A study that fails is shown as an error card and recorded as a failed check, so the report
    is always written and ``--strict`` fails. ``campaigns``: campaign files whose sections the
    report shows (:mod:`tirecli.report.campaign`); with campaigns and no ``only``, the report has
    only their sections.

    ``jobs``: processes for the studies and figures (None: every core; 1: this process only).
    ``cache``: folder of the study cache (:mod:`tirecli.io.cache`; None: :func:`tirecli.io.cache.default_dir`,
    outside the report); ``use_cache=False`` runs every study (and refreshes the cache). ``formats``: the
    figure files (``png``, and ``svg`` if asked). ``note(text)`` is told what a user may wonder about (a
    first run that builds matplotlib's font cache, a cache of an earlier version left in ``out``).
    """
    from tirecli.io.cache import OLD_NAME, default_dir

    t_start = time.perf_counter()
    out = out_path(out)
    formats = tuple(dict.fromkeys(formats))
    reg = load_all()
    entries = _select(reg, only) if only or not campaigns else []
    if campaigns:
        from tirecli.campaign.spec import load_campaign

        for path in campaigns:  # a bad campaign file fails before anything runs
            load_campaign(path)
    # a bad location fails before the studies run
    check_output_dir(out, files=("index.html", "summary.json"), dirs=("data", "figures"))
    if cache is None:
        cache = default_dir()
    settings = {"jobs": jobs or default_jobs(), "use_cache": use_cache, "formats": formats,
                "cache": str(cache) if cache is not None else None, "note": note or (lambda text: None)}
    if (out / OLD_NAME).is_dir() and (cache is None or Path(cache).resolve() != (out / OLD_NAME).resolve()):
        settings["note"](f"{out / OLD_NAME} is the study cache of an earlier tirecli, no longer used (the cache is "
                         f"now {cache if cache is not None else 'off'}): delete that folder to save its space")
    with staged_dir(out, marker="summary.json") as stage:
        return _write_report(stage, entries, t_start, progress, campaigns, settings)


class _Progress:
    """One bar over the report's studies and figures, naming the one in work (thread-safe)."""

    def __init__(self, progress, total: int):
        self.progress, self.lock = progress, threading.Lock()
        if progress is not None:
            progress.start(total, "report")

    def __call__(self, kind: str, name: str) -> None:
        if self.progress is None:
            return
        with self.lock:
            if kind in ("study", "figure"):
                self.progress.item(f"{kind} {name}")
            elif kind in ("study-done", "figure-done"):
                self.progress.advance(1)
            else:
                self.progress.refresh()

    def close(self) -> None:
        if self.progress is not None:
            self.progress.close()


def _write_report(stage, entries: list, t_start: float, progress, campaigns=(), settings=None) -> dict:
    """Run (or take from the cache) the studies of ``entries`` and write the report under
    ``stage.root``; the summary."""
    out = stage.root
    for sub in ("data", "figures", "studies"):
        (out / sub).mkdir()
    studies = list(dict.fromkeys(f.study for f in entries))
    errors, timings, facts = {}, {}, {}
    tasks = []
    fkey = work.figure_key(settings["formats"])
    for name in studies:
        t0 = time.perf_counter()
        try:
            config = builtin_config(name)
            key = work.study_key(name, config)
        except Exception as exc:  # noqa: BLE001 - reported in the page and as a failed check
            errors[name] = f"{type(exc).__name__}: {exc}\n" + traceback.format_exc(limit=4)
            timings[name] = time.perf_counter() - t0
            continue
        tasks.append({"study": name, "figures": [f.id for f in entries if f.study == name], "config": config,
                      "key": key, "fkey": fkey, "root": str(out), "cache": settings["cache"],
                      "use_cache": settings["use_cache"], "formats": settings["formats"]})
    bar = _Progress(progress, len(studies) + len(entries))
    try:
        todo = []
        for task in tasks:
            bar("study", task["study"])
            hit = work.probe(task)
            if hit is None:
                todo.append(task)
                continue
            facts[task["study"]] = hit
            for _ in range(1 + len(task["figures"])):
                bar("study-done", task["study"])
        for _ in [f for f in entries if f.study in errors] + list(errors):  # configs that did not load
            bar("study-done", "")
        if todo:  # matplotlib's first use on this machine: said once, and done before the workers fork
            from tirecli.io.fonts import build_font_cache, font_cache_missing

            if font_cache_missing():
                settings["note"]("building matplotlib's font cache (first run only)")
                build_font_cache()
        earlier = read_timings(settings["cache"])
        # the slowest units (study and figures, as last measured; unknown ones) start first
        todo.sort(key=lambda t: -earlier.get(t["study"], float("inf")))
        docs = {}  # the documentation pages, rendered in this process while the workers run the studies
        for res in work.run_units(todo, settings["jobs"], bar,
                                  meanwhile=lambda: docs.update(write_docs(out, __version__, settings["cache"]))):
            facts[res["study"]] = res
    finally:
        bar.close()
    for name in studies:
        res = facts.get(name)
        if res is None:
            continue
        timings[name] = res["wall"]
        if res["error"] is not None:
            errors[name] = res["error"]
    ran = {name: res["unit_wall"] for name, res in facts.items() if not res["cached"] and res["error"] is None}
    if ran:
        write_timings(settings["cache"], ran)

    cards, all_checks = [], []
    for f in entries:
        card = {"id": f.id, "paper": f.paper, "label": f.label, "title": f.title, "caption": f.caption_for(None),
                "paper_shows": f.paper_shows, "study": f.study, "image": None, "table": None, "error": None,
                "checks": [], "parameters": [], "files": [], "synthetic": False, "assumed": [],
                "doc": card_doc(f.paper, docs)}
        res = facts.get(f.study)
        if res is None or res["error"] is not None:
            card["error"] = errors.get(f.study, "study did not run")
            chk = Check("study-ran", f"built-in study {f.study} ran", float("nan"), 0.0, 0.0, "-", "report")
            chk.id = f"{f.id}/study-ran"
            card["checks"].append(chk.record())
            all_checks.append(chk.record())
            cards.append(card)
            continue
        card.update({k: v for k, v in res["cards"][f.id].items() if k not in ("id", "deps")})
        all_checks += card["checks"]
        png = next((p for p in card["files"] if p.endswith(".png")), None)
        if png is not None and not card.get("image"):  # made by the worker that drew it (kept in the cache)
            card["image"] = page_image(read_bytes(out / png))
        cards.append(card)

    for card in cards:  # the card's links (PNG, SVG, data CSVs, run record) and display size
        res = facts.get(card["study"])
        ok = res is not None and res["error"] is None
        card.update(card_files(out, card["files"], card["study"], res["record"]["data"] if ok else [], ok))

    sections = []
    for paper in PAPER_ORDER + sorted({c["paper"] for c in cards} - set(PAPER_ORDER)):
        pc = [c for c in cards if c["paper"] == paper]
        if pc:
            npass = sum(ch["passed"] for c in pc for ch in c["checks"])
            ntot = sum(len(c["checks"]) for c in pc)
            sections.append({"paper": paper, "title": PAPERS.get(paper, paper), "cards": pc,
                             "passed": npass, "total": ntot})
    campaign_html = ""
    if campaigns:
        from markupsafe import Markup

        from tirecli.report.campaign import campaign_sections

        campaign_html, campaign_checks = campaign_sections(campaigns, out, _env(), progress)
        campaign_html = Markup(campaign_html)
        all_checks += campaign_checks
    failed = [c for c in all_checks if not c["passed"]]
    wall = time.perf_counter() - t_start
    summary = {
        "tool": "tirecli", "version": __version__, "n_figures": len(cards), "n_studies": len(studies),
        "checks": all_checks, "n_checks": len(all_checks), "n_failed": len(failed),
        "study_errors": {k: v.splitlines()[0] for k, v in errors.items()},
        "study_wall_time_s": {k: round(v, 3) for k, v in timings.items()},
        "study_cached": {k: bool(facts[k]["cached"]) for k in studies if k in facts and facts[k]["error"] is None},
        "jobs": settings["jobs"], "formats": list(settings["formats"]),
        "wall_time_s": wall, "environment": output.environment(),
    }
    html = _env().get_template("report.html.j2").render(
        version=__version__, sections=sections, n_checks=len(all_checks), n_failed=len(failed),
        n_figures=len(cards), wall=wall, environment=summary["environment"],
        doclinks=lambda text: link_sources(text, docs), docs_index=docs.get("models/README"),
        campaign_html=campaign_html,
    )
    output.write_text(out / "index.html", html)
    summary["outputs"] = stage.files() + ["summary.json"]
    output.write_json(out / "summary.json", summary)
    return summary

