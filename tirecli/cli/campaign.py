"""``tirecli campaign``: grid, Monte Carlo and sensitivity studies over any config key."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from tirecli.cli.common import JunitOpt, MaxSamplesOpt, echo, jobs_option, max_samples, progress, result_line, strict_exit

CampaignArg = typer.Argument(..., metavar="CAMPAIGN", help="YAML campaign file (see docs/campaigns.md).", show_default=False)


def campaign(
    config: Path = CampaignArg,
    out: Optional[str] = typer.Option(None, "--out", "-o", metavar="DIR",
                                      help="Output directory [default: tirecli-out/campaign-STEM, STEM the file name without .yaml]."),
    jobs: Optional[int] = typer.Option(None, "--jobs", "-j", metavar="N", help="Worker processes [default: the CPU count]."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", metavar="ADDRESS",
                                            help="Run on Dask: 'local' (a LocalCluster of --jobs workers) or tcp://HOST:8786."),
    strict: bool = typer.Option(False, "--strict", help="Exit 1 when a campaign check fails (or a point failed)."),
    junit: Optional[str] = JunitOpt,
    max_samples_: Optional[str] = MaxSamplesOpt,
) -> None:
    """Run a study at every point of a grid and/or a sample over config keys, and tabulate its facts.

    Each point is the base study with overrides of keys that --set accepts; every point is checked
    before any runs. Writes results.parquet and results.csv (one row per point: the varied values,
    the chosen outputs, status, error), summary.json (statistics, sensitivity, checks) and the
    analysis figures. A rerun skips the points already done (Ctrl-C keeps them).
    """
    from tirecli.app.campaign import run_campaign

    if junit is not None:
        from tirecli.io import junit as jx

        from tirecli.app.campaign import default_out

        # a bad --junit fails before the campaign runs
        jx.target(junit, inputs=[config], outputs=_campaign_outputs(out or default_out(config)))
    summary = run_campaign(config, out, jobs_option(jobs, scheduler), scheduler, progress(), note=echo,
                           max_samples=max_samples(max_samples_))
    rec = summary.record
    pts = rec["points"]
    echo(f"campaign {rec['campaign']}: {pts['ok']} ok, {pts['failed']} failed of {pts['total']} points "
         f"({pts['run_now']} run now, {pts['resumed']} resumed) in {rec['wall_time_s']:.2f} s "
         f"[{rec['execution']['executor']}, {rec['execution']['workers']} worker(s)]")
    for f in rec["failures"][:3]:
        result_line(f"  point {f['point']} failed: {f['error']}")
    for name, st in rec["analysis"]["statistics"].items():
        if st["count"]:
            result_line(f"  {name}: mean {st['mean']:.6g}, min {st['min']:.6g}, p5 {st['p5']:.6g}, "
                        f"median {st['median']:.6g}, p95 {st['p95']:.6g}, max {st['max']:.6g} ({st['count']} values)")
    failed = summary.failed_checks
    for c in failed:
        shown = "no value" if c.value != c.value else f"{c.value:.6g}"
        result_line(f"check failed: {c.id}: {c.description}: {shown}")
    result_line(f"wrote {summary.paths['results']}, {summary.paths['csv'].name}, {summary.paths['summary'].name}, "
                f"{len(summary.paths['figures'])} figure file(s)")
    records = [c.record() for c in summary.checks]
    if junit is not None:
        named = [{**r, "id": f"campaign {rec['campaign']}/{r['id']}"} for r in records]  # classname: the campaign
        suite = jx.checks_suite(f"campaign {rec['campaign']}", named, rec["wall_time_s"])
        result_line(f"wrote {jx.write(junit, [suite], 'tirecli campaign', done=f'the results are in {summary.out}', outputs=_campaign_outputs(summary.out))}")
    strict_exit(records, strict)


def _campaign_outputs(out) -> list[Path]:
    """What a campaign writes in ``out`` (files, and folders it writes into): no place for ``--junit``."""
    return [Path(out) / name for name in ("results.parquet", "results.csv", "summary.json", "figures", "points",
                                          "timeseries")]
