"""MDF4/MF4 measurement files (ASAM MDF, as CAN loggers and rigs write them) through ``asammdf``.

``asammdf`` is the optional extra ``mdf`` (``pip install 'tirecli[mdf]'``); without it reading an MDF
file is one line naming the extra (exit 2). The file goes through the input gate
(:func:`tirecli.io.files.read_input_bytes`: a regular file, at most the size cap of the sample budget)
and is parsed from memory.

Channels are selected by name: ``mapping`` ``{MDF channel: column}`` (``--map``), else every channel
whose name is a canonical column (``fz``, ``Fz``, ``vx`` ...) or a TYDEX channel name (``FZW``). Each
channel has its own time stamps; the table puts them on one time base:

- the time stamps of the first selected channel (in the order of ``mapping``, else of the file), or,
  with ``rate``, a uniform grid of that many samples per second starting at the latest first stamp;
- only the span every selected channel covers (no extrapolation: base times outside it are dropped,
  and the table's notes say how many);
- values by linear interpolation between a channel's samples; the measurement number ``run`` by the
  last sample at or before the time (it is a label, not a signal).

The table gains a column ``t`` (the time base, s).
"""
from __future__ import annotations

import io

import numpy as np

from tirecli.errors import DataError, UsageError, token
from tirecli.io.measured import MeasuredData, RawColumn, assemble, canonical_name, check_budget, choose_convention

#: The optional extra that provides asammdf.
EXTRA = "mdf"


def require_asammdf():
    """The ``asammdf`` module, or a one-line UsageError naming the extra that installs it."""
    try:
        import asammdf
    except ImportError:
        raise UsageError(f"reading MDF files needs asammdf: pip install 'tirecli[{EXTRA}]' "
                         f"(from a checkout: pip install '.[{EXTRA}]')") from None
    import logging

    # asammdf logs what it finds wrong in a file on its own stderr handler: tirecli reports one line itself
    logging.getLogger("asammdf").disabled = True
    return asammdf


def _open(asammdf, data: bytes):
    """``asammdf.MDF`` of the file's bytes, or None when the library cannot read them. A half-built
    object's ``__del__`` fails on a damaged file and Python would print that on stderr: the unraisable
    hook is silenced until the object is gone."""
    import gc
    import sys

    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: None
    try:
        try:
            return asammdf.MDF(io.BytesIO(data))
        except Exception:  # noqa: BLE001 - the library's message quotes the file's bytes: never printed
            pass
        gc.collect()
        return None
    finally:
        sys.unraisablehook = hook


def _auto_selection(names) -> dict:
    """Channels read without ``--map``: canonical names and TYDEX names, first of each column."""
    from tirecli.io.tydex import CHANNELS

    out, taken = {}, set()
    for name in names:
        col = canonical_name(name) or CHANNELS.get(str(name).upper())
        if col and col not in taken and col != "t":
            out[name] = col
            taken.add(col)
    return out


def read_mdf(path, mapping: dict | None = None, units: dict | None = None, convention: str | None = None,
             rate: float | None = None) -> MeasuredData:
    """Read the selected channels of an MDF file onto one time base (see the module docstring).

    Raises
    ------
    UsageError
        asammdf is not installed (naming the extra), a ``rate`` that is not positive.
    DataError
        Not an MDF file, a damaged one, a selected channel the file lacks (or holds twice, or not as
        numbers), channels that share no time span, an unknown unit (naming the channel).
    """
    from tirecli import limits
    from tirecli.io.data import names as shown
    from tirecli.io.files import read_input_bytes

    if rate is not None and not (np.isfinite(rate) and rate > 0):
        raise UsageError(f"--rate {rate!r}: expected a positive number of samples per second")
    asammdf = require_asammdf()
    data = read_input_bytes(path, "an MDF file", limits.csv_max_bytes())
    if data[:3] != b"MDF":
        raise DataError(f"{path}: not an MDF file (it does not start with the MDF identification)")
    mdf = _open(asammdf, data)
    if mdf is None:
        raise DataError(f"{path}: cannot read as an MDF file (damaged or unsupported version)")
    try:
        names = [n for n in mdf.channels_db if n and n.lower() not in ("time", "t")]
        selection = dict(mapping) if mapping else _auto_selection(names)
        if not selection:
            raise DataError(f"{path}: no channel to read: name them with --map CHANNEL=NAME "
                            f"(channels in the file: {shown(names) or 'none'})")
        missing = [src for src in selection if src not in mdf.channels_db]
        if missing:
            raise DataError(f"{path}: channel(s) {shown(missing, quoted=True)} not in the file "
                            f"(channels: {shown(names) or 'none'})")
        signals = {src: _signal(mdf, src, path) for src in selection}
    finally:
        mdf.close()
    check_budget(path, max(len(t) for t, _, _ in signals.values()), len(signals) + 1)
    first = next(iter(signals))
    t0 = max(float(t[0]) for t, _, _ in signals.values())
    t1 = min(float(t[-1]) for t, _, _ in signals.values())
    if t1 < t0:
        raise DataError(f"{path}: the selected channels share no time span (one ends at {t1:g} s before another "
                        f"starts at {t0:g} s)")
    if rate is None:
        base_all = signals[first][0]
        base = base_all[(base_all >= t0) & (base_all <= t1)]
        dropped, how = len(base_all) - len(base), f"the time stamps of {first}"
    else:
        n = int(np.floor((t1 - t0) * rate + 1e-9)) + 1
        check_budget(path, n, len(signals) + 1)
        base, dropped, how = t0 + np.arange(n) / rate, 0, f"{rate:g} samples per second"
    if len(base) == 0:
        raise DataError(f"{path}: no sample of {first} lies in the span all selected channels cover")
    unit_map = units or {}
    columns = [RawColumn(base, "t", f"time base ({how})", "s", "time")]
    for src, col in selection.items():
        t, x, unit = signals[src]
        if col == "run":
            values = x[np.clip(np.searchsorted(t, base, side="right") - 1, 0, len(x) - 1)]
        else:
            values = np.interp(base, t, x)
        columns.append(RawColumn(values, col, src, unit_map.get(col, unit_map.get(src, unit))))
    notes = [f"resampled onto {how}, linear interpolation, {t0:g} s to {t1:g} s"]
    if dropped:
        notes.append(f"{dropped} sample(s) of {first} outside the span every channel covers dropped")
    return assemble(path, "mf4", columns, choose_convention(path, None, convention), notes=notes,
                    rows=lambda i: f"at t = {base[i]:g} s")


def _signal(mdf, name: str, path) -> tuple[np.ndarray, np.ndarray, str]:
    """``(time stamps, samples as floats, unit)`` of one channel; DataError for one that cannot be used."""
    try:
        sig = mdf.get(name)
    except Exception:  # noqa: BLE001 - e.g. a name in several groups: the library's text is not shown
        raise DataError(f"{path}: channel {token(name)} cannot be read on its own (is it in several groups? "
                        "rename it in the logger)") from None
    x = np.asarray(sig.samples)
    t = np.asarray(sig.timestamps, dtype=float)
    if x.ndim != 1 or x.dtype.kind not in "fiub":
        raise DataError(f"{path}: channel {token(name)} does not hold one number per sample")
    if len(x) == 0:
        raise DataError(f"{path}: channel {token(name)} has no sample")
    if len(t) != len(x) or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise DataError(f"{path}: channel {token(name)}: its time stamps do not increase")
    return t, x.astype(float), str(sig.unit or "")


def write_mdf(path, data: MeasuredData) -> None:
    """Write the channel table as an MDF 4.10 file: one channel per column (SI unit), all on the time
    base ``t`` (a table without ``t`` gets sample numbers as times). For tests and examples."""
    asammdf = require_asammdf()
    from tirecli.io.atomic import atomic_write

    t = data.frame["t"].to_numpy(dtype=float) if "t" in data.frame.columns else np.arange(len(data.frame), dtype=float)
    sigs = [asammdf.Signal(samples=data.frame[c].to_numpy(dtype=float), timestamps=t, name=c,
                           unit=data.channels[c].unit if c in data.channels else "")
            for c in data.frame.columns if c != "t"]
    mdf = asammdf.MDF(version="4.10")
    mdf.append(sigs)
    buf = io.BytesIO()
    mdf.save(buf, overwrite=True)
    mdf.close()
    with atomic_write(path, "wb") as fh:
        fh.write(buf.getvalue())


__all__ = ["read_mdf", "write_mdf", "require_asammdf", "EXTRA"]
