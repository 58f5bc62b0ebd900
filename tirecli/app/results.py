"""The result writer: a study result with its figures, in the layout of a run command (:func:`write_result`:
``run.json``, ``data/NAME.csv``, ``figures/ID.*``, extra files such as ``fitted.yaml``) or of the report
(:func:`write_study`: ``studies/STUDY.json``, ``data/STUDY/NAME.csv``; figures by :func:`write_figure`);
and what a result assumes.

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


def data_comments(result) -> list[str]:
    """The comment lines of a result's CSV files: the SYNTHETIC label when it holds synthetic data."""
    return [output.SYNTHETIC_NOTE] if result.synthetic else []


def write_figure(directory, fid: str, fig, comments=(), **options) -> list:
    """Write a drawn figure into ``directory``: a :class:`~tirecli.figures.registry.Table` as ``ID.csv``, a
    matplotlib figure as ``ID.png`` and ``ID.svg`` (``options``: ``dpi``, ``formats`` of
    :func:`tirecli.io.output.save_figure`); the paths written."""
    if isinstance(fig, Table):
        import pandas as pd

        return [output.write_csv(directory / f"{fid}.csv", pd.DataFrame(fig.rows, columns=fig.columns), comments)]
    return output.save_figure(fig, directory, fid, **options)


def write_data(directory, result, data_format: str = "csv", progress=None) -> list:
    """Write a result's frames as ``directory/NAME.csv`` (or ``.parquet``); the paths written."""
    comments = data_comments(result)
    paths = []
    for name, frame in result.data.items():
        paths.append(output.write_parquet(directory / f"{name}.parquet", frame, comments)
                     if data_format == "parquet" else output.write_csv(directory / f"{name}.csv", frame, comments))
        if progress is not None:
            progress.advance(1)
    return paths


def write_result(stage, result, figures: dict, checks: list, command: str, wall_time: float,
                 extra: dict | None = None, progress=None, data_format: str = "csv") -> dict:
    """Write a study result with its drawn figures into a run's staging (the layout of a run command:
    ``run.json``, ``data/NAME.csv``, ``figures/ID.*``, the result's extra files); return the paths they
    will have in the output directory once the run is committed.

    Parameters
    ----------
    stage : tirecli.io.staging.Stage
        The run's staging (:func:`tirecli.io.staging.staged_dir`): written under ``stage.root``.
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
    comments = data_comments(result)
    if progress is not None:
        progress.start(len(result.data) + len(figures), "writing")
    fig_paths = []
    try:
        # the figures first: a table a helper process is still formatting (SpooledFrame.extend) comes last
        for fid, fig in figures.items():
            fig_paths += write_figure(out / "figures", fid, fig, comments)
            if progress is not None:
                progress.advance(1)
        data_paths = write_data(out / "data", result, data_format, progress)
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


def write_study(root, name: str, result, wall_time: float) -> list:
    """Write the result of the report's study config ``name`` in the report's layout: ``data/NAME/FRAME.csv``
    and the run record ``studies/NAME.json`` (its figures are written one by one as they are drawn,
    :func:`write_figure`); the data paths written."""
    (root / "data" / name).mkdir(parents=True, exist_ok=True)
    paths = write_data(root / "data" / name, result)
    output.write_json(root / "studies" / f"{name}.json", {
        "study": result.study, "config": result.config.label, "sha256": result.config.digest(),
        "parameters": result.parameter_records(), "assumed": assumed_list(result),
        "citations": result.citations(), "meta": result.meta, "synthetic": result.synthetic,
        "wall_time_s": round(wall_time, 4),
    })
    return paths


__all__ = ["write_result", "write_study", "write_figure", "write_data", "data_comments", "assumed_list",
           "scenario_assumptions"]
