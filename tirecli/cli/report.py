"""``tirecli report``: the full HTML report of every paper."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import echo, progress, result_line


def report(
    campaigns: Optional[List[Path]] = typer.Argument(None, metavar="[CAMPAIGN]...",
                                                     help="Campaign files to report (then only their sections, "
                                                          "unless --only names papers or figures)."),
    out: str = typer.Option("tirecli-out/report", "--out", "-o", help="Output directory."),
    strict: bool = typer.Option(False, "--strict", help="Exit 1 when any reference check fails."),
    only: Optional[List[str]] = typer.Option(None, "--only", help="Only these papers or figure ids (repeatable)."),
) -> None:
    """Run the built-in study of every registered figure and write DIR/index.html.

    Also writes summary.json (every reference check), the figures as PNG/SVG and the data as CSV.
    With campaign files: their sections (each campaign runs or resumes in tirecli-out/campaign-NAME),
    and their checks in summary.json.
    """
    from tirecli.errors import RunError
    from tirecli.report.build import build_report

    summary = build_report(out, only=only or None, progress=progress(), campaigns=list(campaigns or []))
    failed = [c for c in summary["checks"] if not c["passed"]]
    echo(f"{summary['n_figures']} figure{'' if summary['n_figures'] == 1 else 's'}, {len(summary['checks'])} reference checks, {len(failed)} failed, "
         f"{summary['wall_time_s']:.1f} s")
    for c in failed:
        echo(f"check failed: {c['id']}: {c['value']} vs reference {c['reference']} (tolerance {c['tolerance']})")
    result_line(f"wrote {Path(out) / 'index.html'}")
    if strict and failed:
        raise RunError(f"{len(failed)} reference check(s) failed (--strict)")
