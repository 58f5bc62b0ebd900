"""Measured tyre data as CSV or Parquet: reader and writer of the channel table (:mod:`tirecli.io.measured`).

A CSV is read through the CSV gate of :mod:`tirecli.io.data` (size cap and sample budget before
parsing, a row with another number of fields than the header, text, empty or NaN cells: one line naming
the column and the row). Columns named like the point columns of ``tirecli mf eval`` (``kappa, alpha,
gamma, fz, p, vx``), its outputs (``fx, fy, mz, mx, my``) or ``t, run, re, omega`` are the canonical
channels (case-insensitive); other columns keep their names. ``--map FILE_COLUMN=NAME`` renames a
column, ``--units NAME=UNIT`` gives a column's unit (default: SI). A file may declare its axis
convention and the units of its other columns in comment lines (``# convention: sae``,
``# units: temp=degC``), as tirecli's own files do; Parquet files carry the same lines in their
metadata (``tirecli.comments``).
"""
from __future__ import annotations

import numpy as np

from tirecli.errors import DataError, token
from tirecli.io.measured import (MeasuredData, RawColumn, assemble, canonical_name, check_budget, choose_convention,
                                 declared, is_declaration, require_known)

def _columns(names, values_of, mapping: dict | None, units: dict, file_units: dict, path) -> list[RawColumn]:
    """Raw columns of a table: canonical names recognised, ``mapping`` applied, units looked up."""
    mapping = dict(mapping or {})
    missing = [src for src in mapping if src not in names]
    if missing:
        from tirecli.io.data import names as shown

        raise DataError(f"{path}: mapped column(s) {shown(missing, quoted=True)} not in the file "
                        f"(columns: {shown(names)})")
    targets = [mapping.get(src) or canonical_name(src) or src for src in names]
    require_known(targets, names, path)
    out = []
    for src, name in zip(names, targets):
        unit = units.get(name, units.get(src, file_units.get(src, file_units.get(name))))
        out.append(RawColumn(values_of(src), name, src, unit))
    return out


def read_csv_table(path, mapping: dict | None = None, units: dict | None = None,
                   convention: str | None = None) -> MeasuredData:
    """Read a CSV of measured data (see the module docstring) into the channel table."""
    from tirecli.io.data import data_rows, leading_comments, numeric_column, read_table

    frame = read_table(path)  # the gate: size cap, budget, fields per row, duplicate headers
    if len(frame) == 0:
        raise DataError(f"{path}: no data row (a header line and data rows are expected)")
    comments = leading_comments(path)
    declared_convention, file_units = declared(comments, path)
    rows = data_rows(frame)
    frame = frame.reset_index(drop=True)
    names = [str(c) for c in frame.columns]
    columns = _columns(names, lambda c: numeric_column(frame, c, path, rows=rows), mapping, units or {},
                       file_units, path)
    return assemble(path, "csv", columns, choose_convention(path, declared_convention, convention),
                    comments=comments)


def read_parquet_table(path, mapping: dict | None = None, units: dict | None = None,
                       convention: str | None = None) -> MeasuredData:
    """Read a Parquet file of measured data (numeric columns; see the module docstring)."""
    from tirecli import limits
    from tirecli.io.files import read_input_bytes
    from tirecli.io.output import require_pyarrow

    pa = require_pyarrow("reading a Parquet file")
    import pyarrow.parquet as pq

    data = read_input_bytes(path, "a Parquet file", limits.csv_max_bytes())
    if len(data) < 12 or data[:4] != b"PAR1" or data[-4:] != b"PAR1":
        raise DataError(f"{path}: not a Parquet file (no PAR1 marks at its start and end)")
    try:
        reader = pq.ParquetFile(pa.BufferReader(data))
        check_budget(path, reader.metadata.num_rows, reader.metadata.num_columns)
        table = reader.read()
    except DataError:
        raise
    except Exception:  # noqa: BLE001 - a damaged file: the library's text may quote the file, never printed
        raise DataError(f"{path}: cannot read as Parquet (damaged or unsupported file)") from None
    meta = table.schema.metadata or {}
    comments = meta.get(b"tirecli.comments", b"").decode("utf-8", "replace").splitlines()
    declared_convention, file_units = declared(comments, path)
    if table.num_rows == 0:
        raise DataError(f"{path}: no data row")

    def values_of(name):
        col = table.column(name)
        kind = col.type
        if not (pa.types.is_floating(kind) or pa.types.is_integer(kind)):
            raise DataError(f"{path}: column {token(name)}: not numbers ({kind}; a number per row is needed)")
        if col.null_count:
            i = int(np.flatnonzero(col.is_null().to_numpy(zero_copy_only=False))[0])
            raise DataError(f"{path}: column {token(name)} row {i + 1}: empty (a finite number is needed)")
        return col.to_numpy().astype(float)

    columns = _columns([str(n) for n in table.column_names], values_of, mapping, units or {}, file_units, path)
    return assemble(path, "parquet", columns, choose_convention(path, declared_convention, convention),
                    comments=comments)


def table_comments(data: MeasuredData) -> list[str]:
    """The comment lines tirecli writes into a CSV or Parquet file of ``data``: its own comments, then its
    convention (always ISO-W: the table is) and the units of the columns that are not canonical."""
    from tirecli.io.measured import CANONICAL

    keep = [c for c in data.comments if not is_declaration(c)]
    out = [*keep, "convention: iso (ISO-W axes, SI units; columns as in docs/data.md)"]
    extra = [f"{n}={ch.unit}" for n, ch in data.channels.items() if n not in CANONICAL and ch.unit]
    if extra:
        out.append("units: " + ", ".join(extra))
    return out


def write_csv_table(path, data: MeasuredData, comments=()) -> None:
    """Write the channel table as CSV (exact values; ``#`` comment lines first, see :func:`table_comments`)."""
    from tirecli.io.output import write_csv

    write_csv(path, data.frame, [*table_comments(data), *comments])


def write_parquet_table(path, data: MeasuredData, comments=()) -> None:
    """Write the channel table as Parquet (needs pyarrow; the comment lines in the file's metadata)."""
    from tirecli.io.output import require_pyarrow, write_parquet

    require_pyarrow("--to parquet")
    write_parquet(path, data.frame, [*table_comments(data), *comments])


__all__ = ["read_csv_table", "read_parquet_table", "write_csv_table", "write_parquet_table", "table_comments"]
