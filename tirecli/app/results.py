"""The result writer: a study result with its figures into a run's output directory (the layout of
:mod:`tirecli.io.output`: ``run.json``, ``data/``, ``figures/``), and what a result assumes.

The files are written by :mod:`tirecli.io` (atomically, into the run's staging); this module decides
what a run's outputs are.
"""
from __future__ import annotations

import time

from tirecli.figures.registry import REGISTRY, Table
from tirecli.io import output


def assumed_list(result) -> list[str]:
    """``group.param: reason`` for every value of a result still flagged as assumed.

    A study's own assumptions (scenario values the paper does not print) come from
    ``result.meta["assumed"]`` and the config's top-level ``assumed:`` (each a text or a list of texts).
    """
    out = []
    for group, ps in result.parameter_sets.items():
        for key, why in ps.assumed.items():
            out.append(f"{group}.{key}: {why}")
    return out + scenario_assumptions(result)


def scenario_assumptions(result) -> list[str]:
    """The study's and the config's own assumptions (scenario values, not parameter values)."""
    out = []
    extra = result.meta.get("assumed") if isinstance(result.meta, dict) else None
    declared = result.config.data.get("assumed") if result.config is not None else None
    for notes in (extra, declared):
        for why in ([notes] if isinstance(notes, str) else list(notes or [])):
            if str(why) and str(why) not in out:
                out.append(str(why))
    return out


def write_result(stage, result, figures: dict, checks: list, command: str, wall_time: float,
                 extra: dict | None = None, progress=None, data_format: str = "csv") -> dict:
    """Write a study result with its drawn figures into a run's staging; return the paths they will
    have in the output directory once the run is committed.

    Parameters
    ----------
    stage : tirecli.io.atomic.Stage
        The run's staging (:func:`tirecli.io.atomic.staged_dir`): written under ``stage.root``.
    figures : dict
        Figure id -> matplotlib Figure or :class:`tirecli.figures.registry.Table`.
    checks : list
        :class:`tirecli.studies.base.Check` objects evaluated on the result.
    progress : object or None
        Progress reporter (``start``, ``advance``, ``close``), advanced per data file and figure.
    data_format : str
        ``csv`` (``data/NAME.csv``) or ``parquet`` (``data/NAME.parquet``, :func:`~tirecli.io.output.write_parquet`).
    """
    t_write = time.perf_counter()
    out = stage.root
    (out / "data").mkdir(exist_ok=True)
    (out / "figures").mkdir(exist_ok=True)
    comments = [output.SYNTHETIC_NOTE] if result.synthetic else []
    if progress is not None:
        progress.start(len(result.data) + len(figures), "writing")
    data_paths, fig_paths = [], []
    try:
        # the figures first: a table a helper process is still formatting (SpooledFrame.extend) comes last
        for fid, fig in figures.items():
            if isinstance(fig, Table):
                import pandas as pd

                fig_paths.append(output.write_csv(out / "figures" / f"{fid}.csv",
                                           pd.DataFrame(fig.rows, columns=fig.columns), comments))
            else:
                fig_paths += output.save_figure(fig, out / "figures", fid)
            if progress is not None:
                progress.advance(1)
        for name, frame in result.data.items():
            data_paths.append(output.write_parquet(out / "data" / f"{name}.parquet", frame, comments)
                              if data_format == "parquet" else
                              output.write_csv(out / "data" / f"{name}.csv", frame, comments))
            if progress is not None:
                progress.advance(1)
    finally:
        if progress is not None:
            progress.close()
    file_paths = [output.write_text(out / name, text) for name, text in getattr(result, "files", {}).items()]
    record = {
        "tool": "tirecli",
        "command": command,
        "study": result.study,
        "title": result.meta.get("title", ""),
        "synthetic": result.synthetic,
        "config": {"file": result.config.label, "sha256": result.config.digest(), "document": result.config.data},
        "parameters": result.parameter_records(),
        "assumed": assumed_list(result),
        "citations": result.citations(),
        "meta": {k: v for k, v in result.meta.items() if k != "title"},
        "checks": [c.record() for c in checks],
        "outputs": {
            "data": [str(p.relative_to(out)) for p in data_paths],
            "figures": [str(p.relative_to(out)) for p in fig_paths],
            "files": [str(p.relative_to(out)) for p in file_paths],
            # what each figure shows, its parameters and assumptions (as in ``tirecli report``)
            "captions": {fid: REGISTRY[fid].caption_for(result) for fid in figures if fid in REGISTRY},
        },
        # the run up to here: the study, drawing, and writing data and figures (``wall_time`` is
        # the time spent before this call)
        "wall_time_s": round(wall_time + time.perf_counter() - t_write, 4),
        "environment": output.environment(),
    }
    if result.synthetic:
        record["note"] = output.SYNTHETIC_NOTE
    if extra:
        record.update(extra)
    run = output.write_json(out / "run.json", record)
    return {"dir": stage.target, "data": [stage.final(p) for p in data_paths],
            "figures": [stage.final(p) for p in fig_paths], "files": [stage.final(p) for p in file_paths],
            "run": stage.final(run)}


__all__ = ["write_result", "assumed_list", "scenario_assumptions"]
