"""``tirecli report``: the full HTML report of every paper."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import (JunitOpt, StrictOpt, echo, failed_check_line, jobs_option, progress, result_line,
                                strict_exit)


def report(
    campaign: Optional[Path] = typer.Argument(None, metavar="CAMPAIGN", show_default=False,
                                              help="A campaign file to report (then only its section, unless "
                                                   "--only names papers or figures)."),
    out: str = typer.Option("tirecli-out/report", "--out", "-o", metavar="DIR", help="Output directory."),
    strict: bool = StrictOpt,
    only: Optional[List[str]] = typer.Option(None, "--only", metavar="NAME",
                                             help="Only this paper (FM, OBS, MF, MCPS) or figure id (repeatable)."),
    junit: Optional[str] = JunitOpt,
    jobs: Optional[int] = typer.Option(None, "--jobs", "-j", metavar="N", show_default=False,
                                       help="Processes for the studies and figures [default: every core]; "
                                            "1 runs them all in this process."),
    cache: Optional[str] = typer.Option(None, "--cache", metavar="DIR", show_default=False,
                                        help="Folder of the study cache [default: $TIRECLI_CACHE_DIR, else "
                                             "$XDG_CACHE_HOME/tirecli, else ~/.cache/tirecli; never inside --out]: "
                                             "a study whose config, parameters and tirecli version are unchanged "
                                             "is not run again."),
    no_cache: bool = typer.Option(False, "--no-cache", help="Run every study (the cache is refreshed, not read)."),
    formats: str = typer.Option("png", "--formats", metavar="LIST",
                                help="Figure files to write: png, or png,svg (the page embeds the PNG)."),
) -> None:
    """Run the built-in study of every registered figure and write DIR/index.html.

    Also writes summary.json (every reference check), the figures as PNG (and SVG with
    --formats png,svg) and the data as CSV. Studies run on every core and are cached: a second
    report with nothing changed copies their results. With a campaign file: its section (the campaign runs, or resumes, in its default folder),
    and its checks in summary.json.
    """
    from tirecli.report.build import build_report

    if junit is not None:
        from tirecli.io import junit as jx

        jx.target(junit, outputs=_report_outputs(out))  # a bad --junit fails before the studies run
    summary = build_report(out, only=only or None, progress=progress(), campaigns=[campaign] if campaign else [],
                           jobs=jobs_option(jobs), cache=_cache_dir(cache), use_cache=not no_cache,
                           formats=_formats(formats), note=lambda text: echo(f"note: {text}"))
    failed = [c for c in summary["checks"] if not c["passed"]]
    n = summary["n_figures"]
    what = f"{n} figure{'' if n == 1 else 's'}" if n or not campaign else ""
    if campaign:  # its figures are in its section, not among the paper figures counted here
        what += (" and " if what else "") + f"the campaign section of {campaign}"
    echo(f"{what}, {len(summary['checks'])} reference checks, {len(failed)} failed, {summary['wall_time_s']:.1f} s")
    for c in failed:
        echo(failed_check_line(c))
    result_line(f"wrote {Path(out) / 'index.html'}")
    if junit is not None:
        result_line(f"wrote {jx.write(junit, report_suites(summary), 'tirecli report', done=f'the report is in {out}', outputs=_report_outputs(out))}")
    strict_exit(summary["checks"], strict)


def _report_outputs(out) -> list[Path]:
    """What the report writes in ``out`` (files, and folders it writes into): no place for ``--junit``."""
    return [Path(out) / name for name in ("index.html", "summary.json", "data", "docs", "figures", "studies",
                                          "campaigns")]


def _cache_dir(value: Optional[str]) -> Optional[str]:
    """``--cache DIR`` checked (UsageError for an empty name or a place that cannot be a folder); without
    it, ``$TIRECLI_CACHE_DIR`` is checked the same way when set (None: the default folder)."""
    import os

    from tirecli.errors import UsageError
    from tirecli.io.cache import ENV
    from tirecli.io.files import check_output_dir

    if value is not None and not value.strip():
        raise UsageError("--cache '': empty; give a folder")
    if value is not None:  # a file there would leave the report without a cache, silently
        check_output_dir(value, option="--cache")
    elif os.environ.get(ENV, "").strip():
        check_output_dir(os.environ[ENV].strip(), option=ENV)
    return value


def _formats(text: str) -> tuple:
    """``--formats png,svg`` as a tuple; UsageError for an unknown format or one without PNG."""
    from tirecli.errors import UsageError
    from tirecli.report.work import FORMATS

    names = [t.strip().lower() for t in text.split(",") if t.strip()]
    bad = [n for n in names if n not in FORMATS]
    if bad:
        raise UsageError(f"--formats {text!r}: unknown format {bad[0]!r} (choose from {', '.join(FORMATS)})")
    if "png" not in names:
        raise UsageError(f"--formats {text!r}: must include png (the page embeds the PNG)")
    return tuple(dict.fromkeys(names))


def report_suites(summary: dict) -> list:
    """The JUnit suites of a report: one per paper (in the report's order), a case per check
    (classname: the figure id); a suite's time is that of its papers' studies."""
    from tirecli.figures.registry import load_all
    from tirecli.io import junit as jx

    reg = load_all()
    groups: dict[str, list] = {}
    for c in summary["checks"]:
        fid = c["id"].split("/", 1)[0]
        if fid == "campaign":  # campaign/NAME/CHECK: a suite per campaign
            groups.setdefault(f"campaign {c['id'].split('/')[1]}", []).append(c)
            continue
        groups.setdefault(reg[fid].paper if fid in reg else "report", []).append(c)
    times = summary.get("study_wall_time_s") or {}
    suites = []
    for paper, records in groups.items():
        studies = {reg[c["id"].split("/", 1)[0]].study for c in records if c["id"].split("/", 1)[0] in reg}
        suites.append(jx.checks_suite(f"report {paper}", records, sum(times.get(s, 0.0) for s in studies)))
    return suites
