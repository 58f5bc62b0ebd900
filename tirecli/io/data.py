"""Reading tabular input data (CSV): columns by name, checked, with clear errors.

Lines starting with ``#`` are comments (tirecli's own CSVs use them to label synthetic data); a
``#`` inside a cell is data (tirecli's case labels read ``braking #1``).
Every problem is a :class:`~tirecli.errors.DataError` (exit code 2) naming the file, the
column and the row (1-based data row, i.e. not counting the header).
"""
from __future__ import annotations

import io
import warnings
from pathlib import Path

import numpy as np

from tirecli.errors import DataError
from tirecli.io.files import note_input


def read_table(path: str | Path):
    """Read a CSV into a DataFrame of strings/numbers; DataError if missing, empty or unreadable."""
    import pandas as pd

    path = Path(path)
    note_input(path)
    if not path.is_file():
        raise DataError(f"{path}: file not found")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataError(f"{path}: cannot read ({exc.strerror})") from None
    if b"\x00" in raw[:4096]:
        raise DataError(f"{path}: binary file, expected CSV text")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    # whole-line comments only: pandas' comment="#" would also cut a row at a "#" inside a cell
    # (tirecli's own case labels are "braking #1", ...) and leave NaN in the rest of it
    text = text.replace("\r\n", "\n").replace("\r", "\n")  # CRLF and CR-only files
    body = "\n".join(line for line in text.split("\n") if not line.lstrip().startswith("#"))
    header = _check_fields(body, path)
    try:
        with warnings.catch_warnings():  # trailing separators: pandas warns, the frame is right
            warnings.simplefilter("ignore", pd.errors.ParserWarning)
            frame = pd.read_csv(io.StringIO(body), skipinitialspace=True, index_col=False)
    except pd.errors.EmptyDataError:
        raise DataError(f"{path}: empty file (expected a header line and data rows)") from None
    except pd.errors.ParserError as exc:
        raise DataError(f"{path}: cannot read as CSV ({str(exc).splitlines()[0]})") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    named = [c for c in header if c]  # trailing separators give unnamed, empty columns
    dupes = sorted({c for c in named if named.count(c) > 1})
    if dupes:
        raise DataError(f"{path}: column(s) {', '.join(map(repr, dupes))} appear more than once in the header")
    return frame


def _check_fields(body: str, path) -> list[str]:
    """The header's column names, as written (pandas renames a repeated ``fz`` to ``fz.1``);
    DataError naming the first data row whose number of fields differs from the header's (pandas
    would shift the columns, drop extra cells or fill missing ones with NaN; a trailing comma on a
    row is such a field). Blank lines are skipped, rows counted as in every other message."""
    import csv

    header, row_no = None, 0
    try:
        for row in csv.reader(io.StringIO(body, newline=""), skipinitialspace=True):
            if not row or (len(row) == 1 and not row[0].strip()):
                continue
            if header is None:
                header = [c.strip() for c in row]
                continue
            row_no += 1
            if len(row) != len(header):
                raise DataError(f"{path}: data row {row_no} has {len(row)} fields but the header names "
                                f"{len(header)} columns ({', '.join(header)})")
    except csv.Error as exc:
        raise DataError(f"{path}: cannot read as CSV ({exc})") from None
    return header or []


def numeric_column(frame, name: str, path, finite: bool = True, rows=None) -> np.ndarray:
    """Column ``name`` as floats; DataError naming the column, the row and the cell of the first
    cell that is not a plain number: text, a boolean (``True``/``False`` are not 1/0), an empty
    cell, NaN or an infinity (the last three allowed with ``finite=False``, as NaN/inf).

    ``rows`` are the 1-based data rows of the frame's rows in the file (default: 1, 2, ...), so a
    frame whose rows were selected still names the rows of the file.
    """
    import pandas as pd

    col = frame[name]

    def where(i: int) -> str:
        r = int(rows[i]) if rows is not None else i + 1
        return f"{path}: column {name!r} row {r}"

    kind = col.dtype.kind
    if kind == "b":
        raise DataError(f"{where(0)}: not a number ({_cell(col.iloc[0])}; true/false are not numbers)")
    if kind in "fiu":
        vals = col.to_numpy(dtype=float)
    else:  # text (or mixed) cells: every non-empty cell must read as a number, none a boolean
        cells = col.to_numpy(dtype=object)
        flags = np.fromiter((isinstance(c, (bool, np.bool_)) for c in cells), dtype=bool, count=len(cells))
        if flags.any():
            i = int(np.flatnonzero(flags)[0])
            raise DataError(f"{where(i)}: not a number ({_cell(cells[i])}; true/false are not numbers)")
        vals = pd.to_numeric(col, errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(np.isnan(vals) & col.notna().to_numpy())
        if bad.size:
            i = int(bad[0])
            hint = "; true/false are not numbers" if str(cells[i]).strip().lower() in ("true", "false") else ""
            raise DataError(f"{where(i)}: not a number ({_cell(cells[i])}{hint})")
    if finite:
        bad = np.flatnonzero(~np.isfinite(vals))
        if bad.size:
            i = int(bad[0])
            what = "empty or NaN" if np.isnan(vals[i]) else "infinite"
            raise DataError(f"{where(i)}: {what} value (a finite number is needed)")
    return vals


def _cell(v) -> str:
    """A cell for a message: its text, at most 40 characters."""
    text = str(v)
    return repr(text if len(text) <= 40 else text[:37] + "...")


def read_columns(path: str | Path, columns, increasing: str | None = None, min_rows: int = 2,
                 optional=(), rename: dict | None = None) -> dict:
    """Read named numeric columns of a CSV.

    Parameters
    ----------
    columns : sequence of str
        Required columns (after ``rename``).
    increasing : str or None
        A column (time) that must increase strictly.
    min_rows : int
        Fewest data rows accepted.
    optional : sequence of str
        Columns read when present.
    rename : dict or None
        Column mapping ``{name in file: expected name}`` (``--map`` options).

    Returns
    -------
    dict
        Column name -> float array.
    """
    path = Path(path)
    frame = rename_columns(read_table(path), rename, path)
    return frame_columns(frame, columns, path, increasing=increasing, min_rows=min_rows, optional=optional)


def rename_columns(frame, rename: dict | None, path):
    """Apply a column mapping ``{name in file: expected name}``; DataError if a mapped column is absent."""
    if not rename:
        return frame
    missing_src = [src for src in rename if src not in frame.columns]
    if missing_src:
        raise DataError(f"{path}: mapped column(s) {', '.join(map(repr, missing_src))} not in the file "
                        f"(columns: {', '.join(map(str, frame.columns))})")
    return frame.rename(columns=rename)


def select_rows(frame, where: dict | None, path, key: str = "where"):
    """Keep the rows whose column equals the value, for each ``{column: value}`` of ``where``.

    DataError (naming ``key``, e.g. ``data.where``) if a column is absent or no row is left.
    """
    for col, val in (where or {}).items():
        if col not in frame.columns:
            raise DataError(f"{path}: {key}: no column {col!r} (columns: {', '.join(map(str, frame.columns))})")
        frame = frame[frame[col].astype(str) == str(val)] if isinstance(val, str) else frame[frame[col] == val]
        if frame.empty:
            raise DataError(f"{path}: {key}: no row has {col} == {val!r}")
    return frame


def leading_comments(path: str | Path, limit: int = 20) -> list[str]:
    """The ``#`` comment lines at the top of a CSV (e.g. tirecli's ``# SYNTHETIC DATA ...`` label)."""
    out = []
    note_input(path)
    try:
        with Path(path).open(encoding="utf-8", errors="replace") as fh:
            for _ in range(limit):
                line = fh.readline()
                if not line.startswith("#"):
                    break
                out.append(line[1:].strip())
    except OSError:
        return []
    return out


def frame_columns(frame, columns, path, increasing: str | None = None, min_rows: int = 2,
                  optional=()) -> dict:
    """Named numeric columns of an already read (and possibly filtered) frame, with the checks of
    :func:`read_columns` (missing columns, non-numbers, NaN, too few rows, non-increasing time)."""
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise DataError(f"{path}: missing column(s) {', '.join(map(repr, missing))} "
                        f"(file has: {', '.join(map(str, frame.columns)) or 'none'}; map names with --map FILE_COLUMN=NAME)")
    if len(frame) < min_rows:
        raise DataError(f"{path}: too few data rows ({len(frame)}, need at least {min_rows})")
    rows = data_rows(frame)
    frame = frame.reset_index(drop=True)
    out = {c: numeric_column(frame, c, path, rows=rows) for c in columns}
    for c in optional:
        if c in frame.columns:
            out[c] = numeric_column(frame, c, path, rows=rows)
    if increasing is not None:
        t = out[increasing]
        bad = np.flatnonzero(np.diff(t) <= 0)
        if bad.size:
            i = int(bad[0]) + 1
            raise DataError(f"{path}: column {increasing!r} row {rows[i]}: time does not increase "
                            f"({t[i - 1]:g} then {t[i]:g})")
    return out


def data_rows(frame) -> np.ndarray:
    """1-based data rows of the file for the rows of a frame from :func:`read_table` (rows kept by
    :func:`select_rows` keep their numbers); 1, 2, ... for a frame of another origin."""
    idx = frame.index
    if idx.dtype.kind in "iu" and len(idx) and idx.min() >= 0:
        return idx.to_numpy(dtype=np.int64) + 1
    return np.arange(1, len(frame) + 1)
