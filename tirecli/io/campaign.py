"""Files of a campaign (``tirecli campaign``): written as points finish, so that Ctrl-C or a crash
keeps every finished point and a rerun resumes. Layout of ``DIR``::

    DIR/points/part-*.parquet      the records of finished points (id, status, error, facts), one
                                   file per flush (every few seconds), merged into one at the end
    DIR/timeseries/point=ID/part-0.parquet   with keep: timeseries, the run's time series (a Parquet
                                   dataset partitioned by point: pandas.read_parquet(DIR/timeseries))
    DIR/results.parquet, results.csv   one row per point of the design (written at the end, also
                                   after Ctrl-C with the points finished so far)
    DIR/summary.json               the campaign: design, counts, statistics, sensitivity, checks
    DIR/figures/*.png|svg          the analysis figures

Every file goes through a temporary file and a rename (:func:`tirecli.io.atomic.atomic_write`);
the directory is locked for the campaign's duration (:func:`tirecli.io.staging.locked_dir`).
"""
from __future__ import annotations

import json
import os
import secrets
from pathlib import Path

import numpy as np

from tirecli.io import output
from tirecli.io.output import require_pyarrow

#: Column of a stored record listing the facts it holds (JSON).
FACTS = "_facts"


def write_parquet(path: str | Path, frame) -> Path:
    """Write a DataFrame as Parquet (no index) through a temporary file, its folder made if needed
    (:func:`tirecli.io.output.write_parquet`)."""
    require_pyarrow("a campaign (Parquet files)")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return output.write_parquet(path, frame)


def read_parquet(path: str | Path, within: str | Path | None = None):
    """A Parquet file of the campaign folder ``within`` (its parent by default) through the input gate
    (:func:`tirecli.io.files.read_own_file`); ValueError when it is not a regular file of that folder."""
    import io

    import pandas as pd

    from tirecli import limits
    from tirecli.io.files import read_own_file

    require_pyarrow("a campaign (Parquet files)")
    data = read_own_file(path, limits.csv_max_bytes(), within=Path(path).parent if within is None else within)
    if data is None:
        raise ValueError(f"{path}: not a regular file of the campaign")
    return pd.read_parquet(io.BytesIO(data), engine="pyarrow")


def _records_frame(records: list):
    """Point records -> a frame ``id, status, error, FACT...`` (facts as their own columns)."""
    import pandas as pd

    rows = [{"id": r["id"], "status": r["status"], "error": r["error"], FACTS: json.dumps(sorted(r["facts"])),
             **r["facts"]} for r in records]
    frame = pd.DataFrame(rows)
    for c in frame.columns:  # a fact that is text in some rows and a number in others: text
        if frame[c].dtype == object and c not in ("id", "status", "error", FACTS):
            frame[c] = frame[c].map(lambda v: "" if v is None or (isinstance(v, float) and np.isnan(v)) else str(v))
    return frame


class PointStore:
    """The finished points of a campaign in ``DIR/points`` (see the module doc)."""

    def __init__(self, root: str | Path):
        self.root = Path(root)
        self.dir = self.root / "points"

    def parts(self) -> list[Path]:
        return sorted(self.dir.glob("part-*.parquet")) if self.dir.is_dir() else []

    def load(self) -> dict:
        """``id -> record dict`` of every stored point (the latest record of an id wins); a record's
        ``facts`` is the dict of the facts it holds."""
        import pandas as pd

        frames = []
        for p in self.parts():
            try:
                frames.append(read_parquet(p, self.root))
            except Exception:  # noqa: BLE001 - a damaged part (e.g. a full disk): its points run again
                continue
        if not frames:
            return {}
        df = pd.concat(frames, ignore_index=True, sort=False)
        out = {}
        for row in df.to_dict(orient="records"):
            names = json.loads(row.get(FACTS) or "[]")
            out[row["id"]] = {"id": row["id"], "status": row["status"], "error": row["error"] or "",
                              "facts": {n: row.get(n) for n in names}}
        return out

    def append(self, records: list) -> Path | None:
        """Write ``records`` as a new part file."""
        if not records:
            return None
        name = f"part-{len(self.parts()):06d}-{secrets.token_hex(4)}.parquet"
        return write_parquet(self.dir / name, _records_frame(records))

    def compact(self, keep_ids=None) -> None:
        """Merge the part files into one (the latest record of each id; only ``keep_ids`` when given
        and the others' records are dropped)."""
        parts = self.parts()
        if len(parts) <= 1 and keep_ids is None:
            return
        recs = self.load()
        if keep_ids is not None:
            recs = {k: v for k, v in recs.items() if k in keep_ids}
        frame = _records_frame(list(recs.values()))
        new = write_parquet(self.dir / f"part-{0:06d}-{secrets.token_hex(4)}.parquet", frame) if len(frame) else None
        for p in parts:
            if p != new:
                try:
                    os.unlink(p)
                except OSError:
                    pass


def timeseries_path(root: str | Path, pid: str) -> Path:
    return Path(root) / "timeseries" / f"point={pid}" / "part-0.parquet"


def write_timeseries(root: str | Path, pid: str, frame) -> Path:
    """The time series of one point: ``DIR/timeseries/point=ID/part-0.parquet``."""
    return write_parquet(timeseries_path(root, pid), frame)


def has_timeseries(root: str | Path, pid: str) -> bool:
    return timeseries_path(root, pid).is_file()


__all__ = ["PointStore", "write_parquet", "read_parquet", "write_timeseries", "has_timeseries", "timeseries_path"]
