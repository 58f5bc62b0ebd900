"""``tirecli report``: run the built-in study of every registered figure, render one HTML file.

Writes ``DIR/index.html`` (self-contained: figures embedded as PNG, no network resources),
``DIR/summary.json`` (every reference check), ``DIR/figures/ID.png|svg`` (tables as CSV),
``DIR/data/STUDY/NAME.csv``, ``DIR/studies/STUDY.json`` (the run record of each study) and
``DIR/docs/`` (the user documentation as HTML; each card links its model's page, see
:mod:`tirecli.report.docs`). Written like every run (:func:`tirecli.io.atomic.staged_dir`),
``summary.json`` last: it lists the report's files (``outputs``).
"""
from __future__ import annotations

import base64
import time
import traceback
from pathlib import Path

import jinja2

from tirecli import __version__
from tirecli.figures.registry import PAPERS, Table, load_all
from tirecli.io import output
from tirecli.io.atomic import out_path, staged_dir
from tirecli.io.files import check_output_dir
from tirecli.report.cards import card_files
from tirecli.report.docs import card_doc, link_sources, write_docs
from tirecli.studies.base import Check, builtin_config, run_study

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


def build_report(out: str | Path, only=None, progress=None, campaigns=()) -> dict:
    """Build the report into ``out``; returns the summary (also written as ``summary.json``).

    A study that fails is shown as an error card and recorded as a failed check, so the report
    is always written and ``--strict`` fails. ``campaigns``: campaign files whose sections the
    report shows (:mod:`tirecli.report.campaign`); with campaigns and no ``only``, the report has
    only their sections.
    """
    t_start = time.perf_counter()
    out = out_path(out)
    reg = load_all()
    entries = _select(reg, only) if only or not campaigns else []
    if campaigns:
        from tirecli.campaign.spec import load_campaign

        for path in campaigns:  # a bad campaign file fails before anything runs
            load_campaign(path)
    # a bad location fails before the studies run
    check_output_dir(out, files=("index.html", "summary.json"), dirs=("data", "figures"))
    with staged_dir(out, marker="summary.json") as stage:
        return _write_report(stage, entries, t_start, progress, campaigns)


def _write_report(stage, entries: list, t_start: float, progress, campaigns=()) -> dict:
    """Run the studies of ``entries`` and write the report under ``stage.root``; the summary."""
    out = stage.root
    (out / "data").mkdir()
    (out / "figures").mkdir()
    studies = list(dict.fromkeys(f.study for f in entries))
    results, errors, timings = {}, {}, {}
    if progress is not None:
        progress.start(len(studies), "report")
    for name in studies:
        t0 = time.perf_counter()
        try:
            results[name] = run_study(builtin_config(name))
        except Exception as exc:  # noqa: BLE001 - reported in the page and as a failed check
            errors[name] = f"{type(exc).__name__}: {exc}\n" + traceback.format_exc(limit=4)
        timings[name] = time.perf_counter() - t0
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()

    for name, res in results.items():
        (out / "data" / name).mkdir(parents=True, exist_ok=True)
        comments = [output.SYNTHETIC_NOTE] if res.synthetic else []
        for dname, frame in res.data.items():
            output.write_csv(out / "data" / name / f"{dname}.csv", frame, comments)

    docs = write_docs(out, __version__)
    cards, all_checks = [], []
    for f in entries:
        card = {"id": f.id, "paper": f.paper, "label": f.label, "title": f.title, "caption": f.caption_for(results.get(f.study)),
                "paper_shows": f.paper_shows, "study": f.study, "image": None, "table": None, "error": None,
                "checks": [], "parameters": [], "files": [], "synthetic": False, "assumed": [],
                "doc": card_doc(f.paper, docs)}
        res = results.get(f.study)
        if res is None:
            card["error"] = errors.get(f.study, "study did not run")
            chk = Check("study-ran", f"built-in study {f.study} ran", float("nan"), 0.0, 0.0, "-", "report")
            chk.id = f"{f.id}/study-ran"
            card["checks"].append(chk.record())
            all_checks.append(chk.record())
            cards.append(card)
            continue
        card["synthetic"] = res.synthetic
        card["assumed"] = output.scenario_assumptions(res)
        card["parameters"] = [{"group": g, "set": ps.name, "citation": ps.citation, "rows": ps.rows()}
                              for g, ps in res.parameter_sets.items()]
        try:
            fig = f.draw(res)
            checks = f.checks(res) if f.checks else []
        except Exception as exc:  # noqa: BLE001
            card["error"] = f"{type(exc).__name__}: {exc}\n" + traceback.format_exc(limit=4)
            chk = Check("figure-drawn", f"figure {f.id} drawn", float("nan"), 0.0, 0.0, "-", "report")
            checks, fig = [chk], None
        for c in checks:
            c.id = f"{f.id}/{c.id}"
            card["checks"].append(c.record())
            all_checks.append(c.record())
        if isinstance(fig, Table):
            import pandas as pd

            card["table"] = {"columns": fig.columns, "rows": fig.rows, "notes": fig.notes}
            card["files"] = [str(output.write_csv(out / "figures" / f"{f.id}.csv",
                                                  pd.DataFrame(fig.rows, columns=fig.columns),
                                                  [output.SYNTHETIC_NOTE] if res.synthetic else []).relative_to(out))]
        elif fig is not None:
            paths = output.save_figure(fig, out / "figures", f.id)
            card["files"] = [str(p.relative_to(out)) for p in paths]
            card["image"] = base64.b64encode(output.png_bytes(fig)).decode("ascii")
            fig.clf()
        cards.append(card)

    (out / "studies").mkdir(exist_ok=True)
    for name, res in results.items():
        output.write_json(out / "studies" / f"{name}.json", {
            "study": res.study, "config": res.config.label, "sha256": res.config.digest(),
            "parameters": res.parameter_records(), "assumed": output.assumed_list(res),
            "citations": res.citations(), "meta": res.meta, "synthetic": res.synthetic,
            "wall_time_s": round(timings[name], 4),
        })

    for card in cards:  # the card's links (PNG, SVG, data CSVs, run record) and display size
        res = results.get(card["study"])
        card.update(card_files(out, card["files"], card["study"], list(res.data) if res else [], res is not None))

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

