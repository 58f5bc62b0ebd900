"""One entry point for measured tyre data files: pick the reader by format, write a table back.

:func:`read_measured` reads a ``.tdx`` (TYDEX 1.3), ``.csv``, ``.parquet`` or ``.mf4``/``.mdf`` file into
the channel table of :mod:`tirecli.io.measured`; :func:`write_measured` writes a table as TYDEX, CSV or
Parquet. Every reader goes through the input gate of :mod:`tirecli.io.files` (regular files only, size
caps, the sample budget) and reports a bad file in one line (exit 2).
"""
from __future__ import annotations

from pathlib import Path

from tirecli.errors import UsageError, token
from tirecli.io.measured import MeasuredData

#: File suffix -> format.
SUFFIXES = {".tdx": "tdx", ".csv": "csv", ".parquet": "parquet", ".pq": "parquet", ".mf4": "mf4", ".mdf": "mf4"}
#: Formats read; formats written (``--to``).
READ_FORMATS = ("tdx", "csv", "parquet", "mf4")
WRITE_FORMATS = ("tdx", "csv", "parquet")
#: Suffix of a written file of each format.
WRITE_SUFFIX = {"tdx": ".tdx", "csv": ".csv", "parquet": ".parquet"}


def format_of(path) -> str:
    """The format of a data file from its suffix; UsageError for another suffix."""
    suffix = Path(str(path)).suffix.lower()
    if suffix not in SUFFIXES:
        from tirecli.io.files import show_path

        raise UsageError(f"{show_path(path)}: unknown data format {token(suffix or '(no suffix)', 20)}; expected "
                         ".tdx (TYDEX), .csv, .parquet or .mf4 (MDF4)")
    return SUFFIXES[suffix]


def read_measured(path, *, mapping: dict | None = None, units: dict | None = None, convention: str | None = None,
                  rate: float | None = None, require=()) -> MeasuredData:
    """Read a measured data file into the channel table.

    Parameters
    ----------
    mapping : dict or None
        ``{name in the file: column name}`` (``--map``): a CSV/Parquet column, a TYDEX channel, or the
        MDF channels to read.
    units : dict or None
        ``{column or file name: unit}`` (``--units``), replacing the unit of the file (default SI for CSV
        and Parquet).
    convention : str or None
        Axis convention of the file (``iso``, ``sae``, ``adapted-iso``); default: what the file declares,
        else ``iso``.
    rate : float or None
        MDF only: resample onto this many samples per second (default: the first channel's time stamps).
    require : sequence of str
        Columns the caller needs: a missing one is an error naming it and the file.
    """
    from tirecli.conventions import AXIS_CONVENTIONS

    if convention is not None and convention not in AXIS_CONVENTIONS:
        raise UsageError(f"--convention {token(convention, 20)}: expected one of {', '.join(AXIS_CONVENTIONS)}")
    fmt = format_of(path)
    if rate is not None and fmt != "mf4":
        raise UsageError(f"--rate applies to MDF files only ({Path(str(path)).name} is {fmt})")
    if fmt == "tdx":
        from tirecli.io.tydex import read_tydex

        data = read_tydex(path, mapping, units, convention)
    elif fmt == "csv":
        from tirecli.io.tables import read_csv_table

        data = read_csv_table(path, mapping, units, convention)
    elif fmt == "parquet":
        from tirecli.io.tables import read_parquet_table

        data = read_parquet_table(path, mapping, units, convention)
    else:
        from tirecli.io.mdf import read_mdf

        data = read_mdf(path, mapping, units, convention, rate)
    known = set(data.channels) | {ch.source for ch in data.channels.values()}
    unused = [k for k in (units or {}) if k not in known]
    if unused:
        raise UsageError(f"--units {token(unused[0], 40)}: {Path(str(path)).name} has no column or channel of that name")
    data.require(*require)
    return data


def write_measured(path, data: MeasuredData, fmt: str, comments=(), header=None) -> None:
    """Write a table as ``fmt`` (``tdx``, ``csv`` or ``parquet``) to ``path`` (through a temporary file)."""
    if fmt == "tdx":
        from tirecli.io.tydex import write_tydex

        write_tydex(path, data, comments, header)
    elif fmt == "csv":
        from tirecli.io.tables import write_csv_table

        write_csv_table(path, data, comments)
    elif fmt == "parquet":
        from tirecli.io.tables import write_parquet_table

        write_parquet_table(path, data, comments)
    else:
        raise UsageError(f"--to {token(fmt, 20)}: expected one of {', '.join(WRITE_FORMATS)}")


__all__ = ["read_measured", "write_measured", "format_of", "SUFFIXES", "READ_FORMATS", "WRITE_FORMATS"]
