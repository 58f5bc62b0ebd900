"""Reading tabular input data (CSV): columns by name, checked, with clear errors.

Lines starting with ``#`` are comments (tirecli's own CSVs use them to label synthetic data); a
``#`` inside a cell is data (tirecli's case labels read ``braking #1``).
Every problem is a :class:`~tirecli.errors.DataError` (exit code 2) naming the file, the
column and the row (1-based data row, i.e. not counting the header).
"""
from __future__ import annotations

import io
import os
import re
import stat
import warnings
from pathlib import Path

import numpy as np

from tirecli.errors import DataError, UsageError, clip, token

#: Most column names listed in a message (a header is input too: never printed whole).
_MAX_NAMES = 12


#: A column name as people write them (``mu``, ``v [m/s]``, ``Fx (N)``, ``slip %``); anything else in a
#: header is not echoed: a file that is not a CSV table (a password file, a log) would have its first
#: line printed as "the column names".
_PLAIN_NAME = re.compile(r"[\w .,/()\[\]%+-]{1,40}")


def names(columns, quoted: bool = False) -> str:
    """Column names for a message: at most a dozen, each cut to 40 characters (quoted when ``quoted``
    or when it is not a plain name). Names read from a file (``quoted`` False) that do not look like
    column names are counted, not shown."""
    cols = [str(c) for c in columns]
    if not quoted:
        hidden = sum(not _PLAIN_NAME.fullmatch(c) for c in cols)
        cols = [c for c in cols if _PLAIN_NAME.fullmatch(c)]
        if hidden:
            rest = f"{hidden} header field(s) that do not look like column names, not shown"
            return (names(cols) + "; " + rest) if cols else rest
    shown = ", ".join(c if not quoted and c.isidentifier() and len(c) <= 40 else token(c, 40)
                      for c in cols[:_MAX_NAMES])
    return shown + (f", ... ({len(cols)} columns)" if len(cols) > _MAX_NAMES else "")

#: Memory per row of a data file while it is read and used (pandas frame, columns, results) [bytes].
BYTES_PER_ROW = 700


def check_size(path: str | Path) -> None:
    """Refuse a data file over the limits of :mod:`tirecli.limits` before it is parsed: over its size cap,
    a line longer than :data:`~tirecli.limits.MAX_CSV_LINE_BYTES`, or more samples than the budget (its
    data rows; a row of more than :data:`~tirecli.limits.CSV_VALUES_PER_SAMPLE` columns counts as several
    samples). Reads at most the cap, and stops at the budget's rows. Missing or unreadable files are left
    to the reader."""
    from tirecli import limits

    path = Path(path)
    cap, budget = limits.csv_max_bytes(), limits.max_samples()
    size, rows, more = 0, -1, False   # the header is not a row; comment lines are counted (an upper bound)
    line = 0          # length of the line being read (it may span chunks)
    columns = 1       # of the first line that is not a comment (the header)
    try:
        st = path.stat()
        if not stat.S_ISREG(st.st_mode):  # a FIFO, a device, a directory: the reader names it (never opened here)
            return
        if st.st_size > cap:
            raise DataError(f"{path}: {_file_too_large(path, cap)}")
        with os.fdopen(os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)), "rb") as fh:  # never waits
            while chunk := fh.read(1 << 22):
                if size == 0:
                    header = next((ln for ln in chunk.split(b"\n", 1000)
                                   if ln.strip() and not ln.lstrip().startswith(b"#")), b"")
                    columns = header[:limits.MAX_CSV_LINE_BYTES + 1].count(b",") + 1
                nl = np.flatnonzero(np.frombuffer(chunk, dtype=np.uint8) == 10)
                lengths = np.diff(nl, prepend=-1 - line) - 1 if nl.size else np.array([line + len(chunk)])
                if lengths.max(initial=0) > limits.MAX_CSV_LINE_BYTES:
                    at = rows + 2 + int(np.argmax(lengths > limits.MAX_CSV_LINE_BYTES))
                    raise DataError(f"{path}: line {at:,} is longer than {limits.MAX_CSV_LINE_BYTES:,} bytes "
                                    "(a data file has one row a line)")
                line = len(chunk) - 1 - int(nl[-1]) if nl.size else line + len(chunk)
                size += len(chunk)
                rows += int(nl.size)
                if rows > budget or size > cap:
                    more = bool(fh.read(1))
                    break
    except OSError:
        return
    if size > cap:  # grew since the stat
        raise DataError(f"{path}: {_file_too_large(path, cap)}")
    if line > limits.MAX_CSV_LINE_BYTES and not more:
        raise DataError(f"{path}: line {rows + 2:,} is longer than {limits.MAX_CSV_LINE_BYTES:,} bytes "
                        "(a data file has one row a line)")
    rows += line > 0 and not more   # a last row without a newline
    per_row = -(-columns // limits.CSV_VALUES_PER_SAMPLE)
    if rows * per_row > budget:
        what = f"more than {budget:,} data rows" if more else f"{rows:,} data rows"
        if per_row > 1:
            what += f" of {columns:,} columns ({per_row} samples a row)"
        limits.refuse_over_budget(rows * per_row, what, BYTES_PER_ROW, fallback=str(path))


def _file_too_large(path: Path, cap: int) -> str:
    from tirecli.io.files import too_large

    return f"{too_large(path, 'a data file', cap)}; the cap grows with the sample budget (--max-samples)"


def read_table(path: str | Path):
    """Read a CSV into a DataFrame of strings/numbers; DataError if missing, empty, unreadable or over the
    limits of :func:`check_size`."""
    from tirecli import limits
    from tirecli.io.files import read_input_text

    path = Path(path)
    check_size(path)   # before anything is read: a file over the limits is refused at once
    text = read_input_text(path, "a CSV file", encoding="utf-8-sig", max_bytes=limits.csv_max_bytes())
    import pandas as pd
    # whole-line comments only: pandas' comment="#" would also cut a row at a "#" inside a cell
    # (tirecli's own case labels are "braking #1", ...) and leave NaN in the rest of it
    text = text.replace("\r\n", "\n").replace("\r", "\n")  # CRLF and CR-only files
    body = "\n".join(line for line in text.split("\n") if not line.lstrip().startswith("#")) if "#" in text else text
    header = _check_fields(body, path)
    try:
        with warnings.catch_warnings():  # trailing separators: pandas warns, the frame is right
            warnings.simplefilter("ignore", pd.errors.ParserWarning)
            frame = pd.read_csv(io.StringIO(body), skipinitialspace=True, index_col=False)
    except pd.errors.EmptyDataError:
        raise DataError(f"{path}: empty file (expected a header line and data rows)") from None
    except (pd.errors.ParserError, ValueError, OverflowError) as exc:
        raise DataError(f"{path}: cannot read as CSV ({clip((str(exc).splitlines() or [''])[0], 120)})") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    named = [c for c in header if c]  # trailing separators give unnamed, empty columns
    dupes = sorted({c for c in named if named.count(c) > 1})
    if dupes:
        raise DataError(f"{path}: column(s) {names(dupes, quoted=True)} appear more than once in the header")
    return frame


def _check_fields(body: str, path) -> list[str]:
    """The header's column names, as written (pandas renames a repeated ``fz`` to ``fz.1``);
    DataError naming the first data row whose number of fields differs from the header's (pandas
    would shift the columns, drop extra cells or fill missing ones with NaN; a trailing comma on a
    row is such a field). Blank lines are skipped, rows counted as in every other message."""
    import csv

    if body.isascii() and '"' not in body and "\0" not in body:  # no quoted cells: commas counted with numpy
        from tirecli.io.fastcsv import field_counts

        counts, lines = field_counts(body.encode("utf-8"))
        if counts.size == 0:
            return []
        h = int(lines[0])
        header = [c.strip() for c in body.split("\n", h + 1)[h].split(",")]
        bad = np.flatnonzero(counts[1:] != counts[0])
        if bad.size:
            i = int(bad[0])
            raise DataError(f"{path}: data row {i + 1} has {int(counts[i + 1])} fields but the header names "
                            f"{len(header)} columns ({names(header)})")
        return header
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
                                f"{len(header)} columns ({names(header)})")
    except csv.Error as exc:
        raise DataError(f"{path}: cannot read as CSV ({clip(exc, 120)})") from None
    return header or []


def _cell_float(v) -> float:
    """One cell as a float: NaN if it is not a number, +-inf if it is one too large for a double."""
    try:
        return float(v)
    except OverflowError:  # an integer beyond the double range
        return float("inf") if v > 0 else float("-inf")
    except (TypeError, ValueError):
        return float("nan")


_DECIMAL = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$")


def _too_large(cell) -> bool:
    """A cell that is a number, but one beyond the range of a double (400 digits, 1e999)."""
    text = str(cell).strip()
    return isinstance(cell, int) and not isinstance(cell, bool) and not np.isfinite(_cell_float(cell)) or bool(
        _DECIMAL.match(text) and (len(text) > 300 or not np.isfinite(_cell_float(text))))


def numeric_column(frame, name: str, path, finite: bool = True, rows=None) -> np.ndarray:
    """Column ``name`` as floats; DataError naming the column, the row and the cell of the first
    cell that is not a plain number: text, a boolean (``True``/``False`` are not 1/0), a number
    beyond the range of a double, an empty cell, NaN or an infinity (the last three allowed with
    ``finite=False``, as NaN/inf).

    ``rows`` are the 1-based data rows of the frame's rows in the file (default: 1, 2, ...), so a
    frame whose rows were selected still names the rows of the file.
    """
    import pandas as pd

    col = frame[name]

    def where(i: int) -> str:
        r = int(rows[i]) if rows is not None else i + 1
        return f"{path}: column {token(name)} row {r}"

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
        try:
            vals = pd.to_numeric(col, errors="coerce").to_numpy(dtype=float)
        except (OverflowError, ValueError, TypeError):  # e.g. a 400-digit integer among the cells
            vals = np.array([_cell_float(v) for v in cells], dtype=float)
        big = np.flatnonzero(~np.isfinite(vals) & col.notna().to_numpy())
        for i in big[:1]:
            if _too_large(cells[i]):
                raise DataError(f"{where(int(i))}: number too large for a double ({token(str(cells[i]).strip(), 20)})")
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


#: Bytes of a plain numeric CSV body (digits, sign, point, exponent, comma, newline): the fast reader's input.
_PLAIN_BYTES = b"0123456789+-.eE,\n"
_PLAIN_HEADER = re.compile(rb"[A-Za-z_][A-Za-z0-9_]*(?:,[A-Za-z_][A-Za-z0-9_]*)*")


def plain_columns(data: bytes, columns, min_rows: int = 1, optional=(), rename: dict | None = None) -> dict | None:
    """The named columns of a plain numeric CSV (``data``: the file's bytes) as float arrays, parsed with
    pyarrow's multi-threaded reader, or None when the file is not plain or pyarrow is not installed:
    then :func:`read_columns` reads it with every check and names the problem.

    Plain: a header of distinct identifier-like names, data rows of digits, signs, points, exponents
    and commas only (no blanks, quotes, comments, carriage returns, NaN or infinity), every row with the header's
    number of fields and every cell a finite number. The values are those of :func:`read_columns`
    (correctly rounded doubles; ``-0`` is 0.0 in a column of integers, else -0.0).
    """
    head, sep, body = data.partition(b"\n")
    if not sep or not body or body[:1] == b"\n" or not _PLAIN_HEADER.fullmatch(head):
        return None
    header = head.decode("ascii").split(",")
    if len(set(header)) != len(header) or b"\n\n" in body:
        return None
    if body.translate(None, _PLAIN_BYTES):  # a byte of another kind
        return None
    if rename:
        if any(src not in header for src in rename):
            return None
        header = [rename.get(c, c) for c in header]
        if len(set(header)) != len(header):
            return None
    if any(c not in header for c in columns):
        return None
    try:
        import pyarrow as pa
        import pyarrow.csv as pacsv
    except ImportError:
        return None
    try:
        table = pacsv.read_csv(pa.py_buffer(body), read_options=pacsv.ReadOptions(column_names=header),
                               convert_options=pacsv.ConvertOptions(null_values=[], strings_can_be_null=False))
    except (pa.ArrowException, ValueError):
        return None
    n = body.count(b"\n") + (body[-1:] != b"\n")
    if table.num_rows != n or n < min_rows:
        return None
    out, nl = {}, None
    for c in [*columns, *(c for c in optional if c in header)]:
        col = table.column(c)
        if col.type not in (pa.float64(), pa.int64()) or col.null_count:
            return None
        kind = np.float64 if col.type == pa.float64() else np.int64  # (to_numpy would import pandas)
        out[c] = np.concatenate([np.frombuffer(ch.buffers()[1], dtype=kind, count=len(ch), offset=8 * ch.offset)
                                 for ch in col.chunks]).astype(float, copy=False)
        x = out[c]
        if not np.isfinite(x).all():
            return None
        negzero = np.flatnonzero((x == 0) & np.signbit(x))
        if negzero.size:
            nl = np.flatnonzero(np.frombuffer(body, dtype=np.uint8) == 10) if nl is None else nl
            if not _float_cell(body, nl, int(negzero[0]), header.index(c)):
                return None  # "-0": 0 in a column of integers (pandas), else -0.0
    return out


def _float_cell(body: bytes, nl, row: int, field: int) -> bool:
    """Whether a cell of a plain CSV body (``nl``: the positions of its newlines) is written as a float
    (with a point or an exponent), so that pandas reads its column as floats."""
    start = int(nl[row - 1]) + 1 if row else 0
    line = body[start:int(nl[row]) if row < nl.size else len(body)]
    return any(ch in line.split(b",")[field] for ch in (b".", b"e", b"E"))


def rename_columns(frame, rename: dict | None, path):
    """Apply a column mapping ``{name in file: expected name}``; DataError if a mapped column is absent."""
    if not rename:
        return frame
    missing_src = [src for src in rename if src not in frame.columns]
    if missing_src:
        raise DataError(f"{path}: mapped column(s) {names(missing_src, quoted=True)} not in the file "
                        f"(columns: {names(frame.columns)})")
    return frame.rename(columns=rename)


def select_rows(frame, where: dict | None, path, key: str = "where"):
    """Keep the rows whose column equals the value, for each ``{column: value}`` of ``where``.

    DataError (naming ``key``, e.g. ``data.where``) if a column is absent or no row is left.
    """
    for col, val in (where or {}).items():
        if col not in frame.columns:
            raise DataError(f"{path}: {key}: no column {token(col)} (columns: {names(frame.columns)})")
        frame = frame[frame[col].astype(str) == str(val)] if isinstance(val, str) else frame[frame[col] == val]
        if frame.empty:
            shown = col if str(col).isidentifier() and len(str(col)) <= 40 else token(col)
            raise DataError(f"{path}: {key}: no row has {shown} == {token(val)}")
    return frame


def leading_comments(path: str | Path, limit: int = 20) -> list[str]:
    """The ``#`` comment lines at the top of a CSV (e.g. tirecli's ``# SYNTHETIC DATA ...`` label)."""
    from tirecli.io.files import read_input_bytes
    from tirecli.limits import csv_max_bytes

    out = []
    try:
        text = read_input_bytes(path, "a CSV file", csv_max_bytes()).decode("utf-8", errors="replace")
    except UsageError:  # the reader reports the file itself
        return []
    for line in text.splitlines()[:limit]:
        if not line.startswith("#"):
            break
        out.append(line[1:].strip())
    return out


def frame_columns(frame, columns, path, increasing: str | None = None, min_rows: int = 2,
                  optional=()) -> dict:
    """Named numeric columns of an already read (and possibly filtered) frame, with the checks of
    :func:`read_columns` (missing columns, non-numbers, NaN, too few rows, non-increasing time)."""
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        cols = [str(c) for c in frame.columns]
        sep = next((t for t in (";", "\t", "|") if len(cols) == 1 and t in cols[0]), None)
        hint = (f"; its header is one field with {sep!r} in it: tirecli reads comma-separated files "
                f"(',' between values, '.' in numbers)") if sep else ""
        raise DataError(f"{path}: missing column(s) {names(missing, quoted=True)} "
                        f"(file has: {names(frame.columns) or 'none'}; map names with --map FILE_COLUMN=NAME){hint}")
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
            raise DataError(f"{path}: column {token(increasing)} row {rows[i]}: time does not increase "
                            f"({t[i - 1]:g} then {t[i]:g})")
    return out


def data_rows(frame) -> np.ndarray:
    """1-based data rows of the file for the rows of a frame from :func:`read_table` (rows kept by
    :func:`select_rows` keep their numbers); 1, 2, ... for a frame of another origin."""
    idx = frame.index
    if idx.dtype.kind in "iu" and len(idx) and idx.min() >= 0:
        return idx.to_numpy(dtype=np.int64) + 1
    return np.arange(1, len(frame) + 1)
