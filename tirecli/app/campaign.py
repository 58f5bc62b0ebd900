"""Application layer of ``tirecli campaign``: check every point, run the missing ones, write results.

1. The campaign file and the design are read (:func:`tirecli.campaign.spec.load_campaign`) and
   every point's config is checked (:func:`~tirecli.campaign.check.check_points`): a bad key or
   value fails the campaign (exit 2) before anything runs.
2. The output directory is locked; the points already finished there (same identity, the asked
   outputs stored, and the time series with ``keep: timeseries``) are skipped.
3. The first missing points run here (their time sizes the batches, and an output name that is not
   a fact of the run fails the campaign naming it); the others run in batches on the executor
   (:mod:`tirecli.campaign.execute`). Finished points are written every few seconds, a failed point
   is recorded with its error.
4. ``results.parquet`` / ``results.csv``, the analysis figures and ``summary.json`` (last) are
   written, also after Ctrl-C with the points finished so far (exit 130; a rerun resumes).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from tirecli.app.run import DEFAULT_OUT, command_line
from tirecli.campaign import analysis
from tirecli.campaign.check import check_points
from tirecli.campaign.spec import Campaign, load_campaign, value_text
from tirecli.errors import ConfigError, Interrupted

#: Seconds between writes of finished points.
FLUSH_SECONDS = 2.0
#: What a campaign writes in its folder: files, and folders whose files it writes and removes.
OUTPUT_FILES = ("results.parquet", "results.csv", "summary.json")
OUTPUT_DIRS = ("figures", "points", "timeseries")


@dataclass
class CampaignSummary:
    """What ``tirecli campaign`` did."""

    out: Path
    record: dict
    checks: list
    results: pd.DataFrame
    paths: dict = field(default_factory=dict)

    @property
    def failed_checks(self) -> list:
        return [c for c in self.checks if not c.passed]


def default_out(path: str | Path) -> Path:
    """``tirecli-out/campaign-STEM`` (``tirecli-out/STEM`` when the file's name starts with ``campaign``)."""
    stem = Path(path).stem
    return DEFAULT_OUT / (stem if stem.startswith("campaign") else f"campaign-{stem}")


class _Collector:
    """Receives finished points: writes time series at once, points every :data:`FLUSH_SECONDS`."""

    def __init__(self, store, root: Path, keep: bool, progress, total: int):
        self.store, self.root, self.keep, self.progress = store, root, keep, progress
        self.buffer, self.records, self.last = [], {}, time.perf_counter()
        self.ran = self.failed = 0
        if progress is not None:
            progress.start(total, "campaign")

    def __call__(self, records: list) -> None:
        from tirecli.io.campaign import write_timeseries

        for r in records:
            if self.keep and r["status"] == "ok" and r.get("frame") is not None:
                write_timeseries(self.root, r["id"], r["frame"])
            r["frame"] = None
            self.records[r["id"]] = r
            self.buffer.append(r)
            self.ran += 1
            self.failed += r["status"] != "ok"
        if self.progress is not None:
            self.progress.advance(len(records))
        if time.perf_counter() - self.last >= FLUSH_SECONDS:
            self.flush()

    def flush(self) -> None:
        self.store.append(self.buffer)
        self.buffer, self.last = [], time.perf_counter()

    def close(self) -> None:
        if self.progress is not None:
            self.progress.close()


def _done(rec, outputs, keep, root) -> bool:
    from tirecli.io.campaign import has_timeseries

    return (rec is not None and rec["status"] == "ok" and all(o in rec["facts"] for o in outputs)
            and (not keep or has_timeseries(root, rec["id"])))


#: Points run in this process first: the first checks the outputs, the others time a warm run.
PROBES = 3


def _probe(campaign: Campaign, payload, items) -> tuple[list, float]:
    """Run the first missing points here: ``(records, seconds of one warm run)``. An output name that
    is not a fact of the run is a ConfigError at its place in ``outputs``; the first run pays the
    imports and caches, so the batches are sized from the fastest of the others (CPU time)."""
    from tirecli.campaign.facts import run_batch

    recs, times = [], []
    for item in items:
        t0 = time.process_time()  # CPU time: a loaded machine does not shrink the batches
        rec = run_batch(payload, [item])[0]
        times.append(time.process_time() - t0)
        if rec["status"] != "ok" and rec.get("unknown") in campaign.outputs:
            raise ConfigError(campaign.origins.problem(("outputs", campaign.outputs.index(rec["unknown"])), rec["error"]))
        recs.append(rec)
    return recs, min(times[1:] or times)


def results_frame(campaign: Campaign, ids: list, records: dict) -> pd.DataFrame:
    """One row per point of the design that has a record: ``point, id, KEYS..., OUTPUTS..., status, error``."""
    design = campaign.design
    rows = []
    for i, (values, pid) in enumerate(zip(design.points, ids)):
        rec = records.get(pid)
        if rec is None:
            continue
        row = {"point": i, "id": pid}
        row.update({k: value_text(v) for k, v in zip(design.keys, values)})
        for o in campaign.outputs:
            row[o] = rec["facts"].get(o, np.nan) if rec["status"] == "ok" else np.nan
        row.update(status=rec["status"], error=rec["error"] or "")
        rows.append(row)
    cols = ["point", "id", *design.keys, *campaign.outputs, "status", "error"]
    frame = pd.DataFrame(rows, columns=cols)
    for c in campaign.outputs:  # facts that are numbers (with missing values): a float column
        conv = pd.to_numeric(frame[c], errors="coerce")
        if frame[c].isna().equals(conv.isna()):
            frame[c] = conv.astype(float)
        else:
            frame[c] = frame[c].map(lambda v: "" if v is None or (isinstance(v, float) and np.isnan(v)) else str(v))
    return frame


def _require_libraries() -> None:
    """UsageError (exit 2, how to install it) for a library the campaign needs and does not have:
    pyarrow (the point store and results.parquet); Dask with ``--scheduler`` is checked with the
    address (:func:`tirecli.campaign.execute.check_scheduler`)."""
    from tirecli.io.output import require_pyarrow

    require_pyarrow("a campaign (its points and results are Parquet files)")


def run_campaign(path: str | Path, out=None, jobs: int | None = None, scheduler: str | None = None,
                 progress=None, note=None, max_samples: int | None = None) -> CampaignSummary:
    """Run the campaign file ``path`` into ``out`` (module doc). ``note(text)`` reports what happens
    (points to run, resumed). ``max_samples``: the sample budget of the campaign and of each of its runs
    (``--max-samples``; default: the file's ``run.max_samples``, else :data:`tirecli.limits.DEFAULT_MAX_SAMPLES`)."""
    from tirecli import limits
    from tirecli.campaign.execute import check_scheduler
    from tirecli.io.staging import out_path

    t0 = time.perf_counter()
    out = out_path(out) if out is not None else None
    scheduler = check_scheduler(scheduler)  # an address that is no Dask scheduler fails before anything runs
    _require_libraries()  # a missing library fails before the points are checked (the budget checks one)
    campaign = load_campaign(path, max_samples)
    with limits.budget(campaign.max_samples):
        return _run_loaded(campaign, path, out, jobs, scheduler, progress, note, t0)


def _run_loaded(campaign: Campaign, path, out, jobs, scheduler, progress, note, t0) -> CampaignSummary:
    from tirecli.campaign.execute import batch_size, run_batches
    from tirecli.io.staging import keep_inputs, locked_dir
    from tirecli.io.campaign import PointStore
    from tirecli.parallel import default_jobs

    jobs = jobs or default_jobs()
    ids, study = check_points(campaign, jobs if not scheduler else min(jobs, default_jobs()))
    out = out or default_out(path)
    from tirecli.io.files import check_output_dir

    # a bad location, or outputs that would overwrite the campaign's inputs, fail before the runs
    check_output_dir(out, files=OUTPUT_FILES, dirs=OUTPUT_DIRS)
    keep_inputs(out, OUTPUT_FILES, OUTPUT_DIRS)
    keep = campaign.keep == "timeseries"
    payload = {"base": campaign.base, "fixed": campaign.fixed, "outputs": campaign.outputs, "keep": keep,
               "timeout": campaign.timeout, "max_samples": campaign.max_samples}
    with locked_dir(out) as (target, root):
        store = PointStore(root)
        stored = store.load()
        records = {pid: rec for pid, rec in stored.items() if _done(rec, campaign.outputs, keep, root)}
        todo, seen = [], set(records)
        for i, (values, pid) in enumerate(zip(campaign.design.points, ids)):
            if pid not in seen:
                seen.add(pid)
                todo.append((i, pid, campaign.point_overrides(values)))
        n_unique = len(set(ids))
        resumed = n_unique - len(todo)
        if note is not None:
            note(f"campaign {campaign.name}: {len(ids)} points ({study})"
                 + (f", {resumed} already done in {target}" if resumed else "") + f", {len(todo)} to run")
        collector = _Collector(store, root, keep, progress, len(todo))
        executor = {"executor": "none (every point was done)", "workers": 0}
        interrupted = False
        try:
            if todo:
                first, seconds = _probe(campaign, payload, todo[:PROBES])
                collector(first)
                rest = todo[len(first):]
                if rest:
                    workers = 1 if (jobs <= 1 and not scheduler) else jobs
                    size = batch_size(len(rest), workers, seconds, campaign.batch)
                    batches = [rest[k:k + size] for k in range(0, len(rest), size)]
                    executor = run_batches(payload, batches, jobs, scheduler, collector)
                    executor["batch"] = size
                else:
                    executor = {"executor": "in-process", "workers": 1}
        except KeyboardInterrupt:
            interrupted = True
        finally:
            collector.close()
            collector.flush()
        records.update(collector.records)
        if not interrupted:
            store.compact()
        summary = _finish(campaign, study, ids, records, root, target, executor, collector, resumed, interrupted,
                          time.perf_counter() - t0, jobs, scheduler)
    if interrupted:
        n_done = sum(1 for pid in set(ids) if pid in records)
        raise Interrupted(f"interrupted: {n_done} of {len(set(ids))} points finished, kept in {target} "
                          f"(results.csv has them; run the same command again to resume)")
    return summary


def _finish(campaign, study, ids, records, root, target, executor, collector, resumed, interrupted, wall,
            jobs, scheduler) -> CampaignSummary:
    from tirecli.io.campaign import write_parquet
    from tirecli.io.output import environment, write_csv, write_json

    results = results_frame(campaign, ids, records)
    n_failed = int((results["status"] != "ok").sum())
    ana = {"statistics": analysis.statistics(results, campaign.outputs)}
    design = campaign.design
    ok = results[results["status"] == "ok"]
    if design.sample_keys and len(ok) > 2:
        ana["tornado"] = analysis.tornado(ok, design.keys, campaign.outputs)
    if design.method == "saltelli" and not interrupted:
        ana["sobol"] = analysis.sobol_indices(design, results_full(results, len(ids)), campaign.outputs)
    checks = analysis.campaign_checks(results, campaign.checks, n_failed)
    write_parquet(root / "results.parquet", results)
    write_csv(root / "results.csv", results)
    previous = _previous_outputs(root)
    figure_files = []
    if campaign.figures and interrupted:  # stop quickly: the figures of the last complete run stay
        figure_files = sorted(p for p in previous if p.startswith("figures/") and (root / p).is_file())
    elif campaign.figures:
        figure_files = _write_figures(campaign, study, results, ana, root)
    outputs = ["results.parquet", "results.csv", *figure_files]
    for rel in previous - set(outputs) - {"summary.json"}:
        if rel.startswith("figures/"):
            (root / rel).unlink(missing_ok=True)
    failures = results[results["status"] != "ok"]
    record = {
        "tool": "tirecli", "command": command_line(), "kind": "campaign",
        "campaign": campaign.name, "title": campaign.title, "description": campaign.description,
        "file": campaign.label, "study": study,
        "base": {"file": campaign.base.label, "sha256": campaign.base.digest()},
        "set": {o.key: o.value for o in campaign.fixed if not o.remove},
        "unset": [o.key for o in campaign.fixed if o.remove],
        "design": design.record(), "outputs_asked": campaign.outputs, "keep": campaign.keep,
        "points": {"total": len(ids), "unique": len(set(ids)), "in_results": int(len(results)),
                   "ok": int((results["status"] == "ok").sum()), "failed": n_failed,
                   "not_run": len(ids) - int(len(results)), "run_now": collector.ran, "resumed": resumed},
        "complete": not interrupted and len(results) == len(ids),
        "failures": [{"point": int(r.point), "id": r.id, "error": r.error} for r in failures.head(20).itertuples()],
        "analysis": ana,
        "checks": [c.record() for c in checks],
        "execution": {**executor, "jobs": jobs, "scheduler": scheduler},
        "outputs": outputs,
        "wall_time_s": round(wall, 3),
        "environment": environment(),
    }
    write_json(root / "summary.json", record)
    return CampaignSummary(out=target, record=record, checks=checks, results=results,
                           paths={"results": target / "results.parquet", "csv": target / "results.csv",
                                  "summary": target / "summary.json",
                                  "figures": [target / f for f in figure_files]})


def results_full(results: pd.DataFrame, n: int) -> pd.DataFrame:
    """The results in design order with a row for every point (duplicates of a point share its values)."""
    return results.set_index("point").reindex(range(n)).reset_index()


def _previous_outputs(root: Path) -> set:
    from tirecli.io.commit import read_record

    rec = read_record(root / "summary.json", root)
    if not isinstance(rec, dict) or rec.get("kind") != "campaign" or not isinstance(rec.get("outputs"), list):
        return set()
    return {str(x) for x in rec["outputs"]}


def _write_figures(campaign, study: str, results, ana, root: Path) -> list:
    from tirecli.campaign.facts import column_units
    from tirecli.figures.campaign import campaign_figures
    from tirecli.io.output import save_figure

    figs = campaign_figures(campaign.design, results, analysis.numeric_outputs(results, campaign.outputs), ana,
                            campaign.title or campaign.name, units=column_units(campaign, study))
    (root / "figures").mkdir(exist_ok=True)
    files = []
    for name, fig in figs.items():
        for p in save_figure(fig, root / "figures", name):
            files.append(str(p.relative_to(root)))
        fig.clf()
    return files


__all__ = ["run_campaign", "CampaignSummary", "results_frame", "default_out"]
