"""``tirecli report``: the full HTML report of every paper."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import JunitOpt, StrictOpt, echo, progress, result_line, strict_exit


def report(
    campaign: Optional[Path] = typer.Argument(None, metavar="CAMPAIGN", show_default=False,
                                              help="A campaign file to report (then only its section, unless "
                                                   "--only names papers or figures)."),
    out: str = typer.Option("tirecli-out/report", "--out", "-o", metavar="DIR", help="Output directory."),
    strict: bool = StrictOpt,
    only: Optional[List[str]] = typer.Option(None, "--only", metavar="NAME",
                                             help="Only this paper (FM, OBS, MF, MCPS) or figure id (repeatable)."),
    junit: Optional[str] = JunitOpt,
) -> None:
    """Run the built-in study of every registered figure and write DIR/index.html.

    Also writes summary.json (every reference check), the figures as PNG/SVG and the data as CSV.
    With a campaign file: its section (the campaign runs, or resumes, in its default folder),
    and its checks in summary.json.
    """
    from tirecli.report.build import build_report

    if junit is not None:
        from tirecli.io import junit as jx

        jx.target(junit)  # a bad --junit fails before the studies run
    summary = build_report(out, only=only or None, progress=progress(), campaigns=[campaign] if campaign else [])
    failed = [c for c in summary["checks"] if not c["passed"]]
    echo(f"{summary['n_figures']} figure{'' if summary['n_figures'] == 1 else 's'}, {len(summary['checks'])} reference checks, {len(failed)} failed, "
         f"{summary['wall_time_s']:.1f} s")
    for c in failed:
        echo(f"check failed: {c['id']}: {c['value']} vs reference {c['reference']} (tolerance {c['tolerance']})")
    result_line(f"wrote {Path(out) / 'index.html'}")
    if junit is not None:
        result_line(f"wrote {jx.write(junit, report_suites(summary), 'tirecli report', done=f'the report is in {out}')}")
    strict_exit(summary["checks"], strict)


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
