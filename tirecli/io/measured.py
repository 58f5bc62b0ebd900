"""The channel table of measured tyre data: one DataFrame, canonical names, SI units, ISO-W signs.

Every reader of measured data (TYDEX :mod:`tirecli.io.tydex`, MDF4 :mod:`tirecli.io.mdf`, CSV and
Parquet :mod:`tirecli.io.tables`) returns a :class:`MeasuredData`: its ``frame`` has one float column per
channel, named as in :data:`CANONICAL` (the point columns of ``tirecli mf eval`` -- ``kappa, alpha,
gamma, fz, p, vx`` -- and its outputs ``fx, fy, mz, mx, my``, plus ``t``, ``run``, ``re``, ``omega``),
in SI units and in the ISO-W axes of ``mf eval`` (``fz > 0`` is the load); any other channel of the
file keeps its own name, in its SI unit. ``channels`` describes each column: unit, description,
the channel it came from and the factor applied. This table is the interface of the Magic Formula
fitter and of ``fit``/``observe`` on measured data.

:func:`assemble` is the one place raw columns become that table: units to SI (:mod:`tirecli.units`),
axis convention to ISO-W (:mod:`tirecli.conventions`), every value a finite number, the sample budget.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import DataError, token

#: Inputs of a Magic Formula point (the columns of ``tirecli mf eval --points``).
INPUTS = ("kappa", "alpha", "gamma", "fz", "p", "vx")
#: Forces and moments (the output columns of ``tirecli mf eval``).
OUTPUTS = ("fx", "fy", "mz", "mx", "my")
#: Further channels with a fixed meaning.
EXTRAS = ("t", "run", "re", "omega")

#: ``name -> (SI unit, description)`` of every canonical channel, in the column order of a table.
CANONICAL: dict[str, tuple[str, str]] = {
    "t": ("s", "time"),
    "run": ("-", "measurement (run) number"),
    "kappa": ("-", "longitudinal slip ratio (ISO-W: > 0 driving, < 0 braking, -1 locked)"),
    "alpha": ("rad", "slip angle (ISO-W: > 0 gives a negative side force)"),
    "gamma": ("rad", "inclination (camber) angle (ISO-W)"),
    "fz": ("N", "vertical load (> 0 in compression)"),
    "p": ("Pa", "inflation pressure"),
    "vx": ("m/s", "forward speed of the wheel centre"),
    "fx": ("N", "longitudinal force (ISO-W)"),
    "fy": ("N", "lateral force (ISO-W)"),
    "mz": ("N m", "aligning moment (ISO-W)"),
    "mx": ("N m", "overturning moment (ISO-W)"),
    "my": ("N m", "rolling resistance moment (ISO-W)"),
    "re": ("m", "effective rolling radius"),
    "omega": ("rad/s", "wheel angular speed"),
}

#: Synonyms accepted for canonical names in CSV/Parquet headers and MDF channel names (case-insensitive).
ALIASES = {"slip": "kappa", "time": "t", "meas": "run", "pressure": "p", "speed": "vx", "v": "vx"}

#: Bytes per value of a table while it is read and used (arrays, the frame, copies) [bytes].
BYTES_PER_VALUE = 40


@dataclass(frozen=True)
class Channel:
    """One column of a :class:`MeasuredData` table.

    Attributes
    ----------
    name : str
        Column name: a key of :data:`CANONICAL`, else the channel's own name in the file.
    unit : str
        SI unit of the column (``"-"`` dimensionless; ``""`` when the file gave none for a channel
        that is not canonical).
    description : str
        What the channel is (the file's description where it gives one).
    source : str
        The channel's name in the file (``FZW``, ``Fz_kN``, ...), or ``"constant NAME"`` for a column
        filled from a TYDEX constant.
    factor : float
        ``SI value = factor * file value + offset`` (the unit's factor, the TYDEX channel's own
        factor and the axis convention's sign, multiplied).
    offset : float
        Added after the factor (non-zero only for temperatures in degrees Celsius).
    file_unit : str
        The unit as the file wrote it.
    """

    name: str
    unit: str
    description: str
    source: str
    factor: float = 1.0
    offset: float = 0.0
    file_unit: str = ""


@dataclass
class MeasuredData:
    """A measured data set: the table, what each column is, and where it came from.

    Attributes
    ----------
    frame : pandas.DataFrame
        One float64 column per channel (:data:`CANONICAL` names first, in that order; other channels
        after, in file order), SI units, ISO-W signs.
    channels : dict
        Column name -> :class:`Channel`, in the column order.
    source : str
        The file (as given).
    format : str
        ``"tdx"``, ``"csv"``, ``"parquet"`` or ``"mf4"``.
    convention : str
        The axis convention the file was read in (``iso``, ``sae`` or ``adapted-iso``).
    header : dict
        Descriptive entries of the file (TYDEX ``**HEADER``, Parquet metadata): name -> text.
    comments : list of str
        Comment lines of the file (TYDEX ``**COMMENTS``, ``#`` lines of a CSV).
    constants : dict
        TYDEX ``**CONSTANTS``: name -> ``(SI value, SI unit)`` (a value that is not a number is kept as text
        with unit ``""``).
    notes : list of str
        What the reader did beyond the plain reading (a resampling, columns filled from constants).
    """

    frame: object
    channels: dict
    source: str
    format: str
    convention: str = "iso"
    header: dict = field(default_factory=dict)
    comments: list = field(default_factory=list)
    constants: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.frame)

    @property
    def synthetic(self) -> bool:
        """Whether the file says it holds SYNTHETIC data (tirecli labels every data set it generates)."""
        texts = [*self.comments, *map(str, self.header.values())]
        return any("SYNTHETIC" in t for t in texts)

    def has(self, *names: str) -> bool:
        return all(n in self.frame.columns for n in names)

    def require(self, *names: str) -> None:
        """DataError naming the file and the channels of ``names`` the table lacks."""
        missing = [n for n in names if n not in self.frame.columns]
        if missing:
            have = ", ".join(self.frame.columns[:16]) or "none"
            raise DataError(f"{self.source}: missing channel(s) {', '.join(missing)} (the file gives: {have})")

    def column(self, name: str) -> np.ndarray:
        """Column ``name`` as a float array (DataError naming the file when it is missing)."""
        self.require(name)
        return self.frame[name].to_numpy(dtype=float)


def canonical_name(name: str) -> str | None:
    """The canonical channel a column name stands for (``fz``, ``Fz``, ``FZ`` -> ``fz``; ``slip`` ->
    ``kappa``), or None."""
    low = str(name).strip().lower()
    if low in CANONICAL:
        return low
    return ALIASES.get(low)


@dataclass
class RawColumn:
    """A column as read from a file, before :func:`assemble`: values in the file's unit and convention."""

    values: np.ndarray
    name: str          # the table's column name (canonical or own)
    source: str        # the channel's name in the file
    unit: str          # the unit as written in the file (None: SI of a canonical column)
    description: str = ""
    factor: float = 1.0  # the file's own factor (TYDEX), applied before the unit


def assemble(path, fmt: str, columns: list, convention: str, *, header=None, comments=None, constants=None,
             notes=None, rows=None) -> MeasuredData:
    """The :class:`MeasuredData` of raw columns: units to SI, signs to ISO-W, checks.

    Parameters
    ----------
    path : str or Path
        The file, for messages.
    fmt : str
        Its format (``tdx``, ``csv``, ``parquet``, ``mf4``).
    columns : list of RawColumn
        In file order; two columns for one name are an error naming both sources.
    convention : str
        Axis convention of the file (:data:`tirecli.conventions.AXIS_CONVENTIONS`).
    rows : callable or None
        ``rows(i)`` -> the text naming data row ``i`` in a message (default ``row i+1``).

    Raises
    ------
    DataError
        An unknown unit (naming the channel), a unit of the wrong kind for a canonical channel (``fz``
        in ``deg``), a value that is not a finite number (naming channel and row), loads that are not
        positive after the convention (a wrong ``--convention``), a channel given twice.
    """
    import pandas as pd

    from tirecli import units
    from tirecli.conventions import axis_sign

    where = rows or (lambda i: f"row {i + 1}")
    seen: dict[str, str] = {}
    converted: dict[str, np.ndarray] = {}
    described: dict[str, Channel] = {}
    for col in columns:
        if col.name in seen:
            raise DataError(f"{path}: channel {token(col.name)} given twice (by {token(seen[col.name])} and "
                            f"{token(col.source)})")
        seen[col.name] = col.source
        canonical = col.name in CANONICAL
        unit_text = col.unit
        if unit_text is None or (canonical and not str(unit_text).strip()):
            unit_text = CANONICAL[col.name][0] if canonical else ""
        try:
            si_unit, factor, offset = units.si(unit_text)
        except KeyError:
            raise DataError(f"{path}: channel {token(col.source)}: unknown unit {token(str(unit_text), 30)} "
                            f"(known: {', '.join(units.names())}; override with --units NAME=UNIT)") from None
        if canonical and si_unit != CANONICAL[col.name][0]:
            raise DataError(f"{path}: channel {token(col.source)} read as {col.name}: unit {token(str(unit_text), 30)} "
                            f"is {si_unit}, expected {CANONICAL[col.name][0]} "
                            f"(override with --units {col.name}=UNIT)")
        if not canonical and not str(unit_text).strip():
            si_unit = ""
        values = np.asarray(col.values, dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            i = int(bad[0])
            what = "NaN (no value)" if np.isnan(values[i]) else "infinite"
            raise DataError(f"{path}: channel {token(col.source)} {where(i)}: {what}; a finite number is needed")
        sign = axis_sign(col.name, convention)
        total = sign * factor * col.factor
        si_values = values * total + sign * offset if (total != 1.0 or offset) else values.copy()
        converted[col.name] = si_values
        described[col.name] = Channel(col.name, si_unit, col.description or CANONICAL.get(col.name, ("", ""))[1],
                                      col.source, total, sign * offset, str(col.unit or ""))
    if not converted:
        raise DataError(f"{path}: no channel read")
    require_known(list(converted), [c.source for c in columns], path)
    lengths = {len(v) for v in converted.values()}
    if len(lengths) != 1:  # a reader's bug, never the user's: say so plainly
        raise DataError(f"{path}: channels of different lengths ({sorted(lengths)})")
    if "fz" in converted:
        _check_loads(path, converted["fz"], convention)
    order = [n for n in CANONICAL if n in converted] + [n for n in converted if n not in CANONICAL]
    frame = pd.DataFrame({n: converted[n] for n in order})
    return MeasuredData(frame, {n: described[n] for n in order}, str(path), fmt, convention, dict(header or {}),
                        list(comments or []), dict(constants or {}), list(notes or []))


def require_known(columns, sources, path) -> None:
    """DataError when none of ``columns`` (the table's names) is a canonical channel: the file is not
    measured tyre data as named here (its own names, ``sources``, listed only where they look like names)."""
    if not any(c in CANONICAL for c in columns):
        from tirecli.io.data import names

        raise DataError(f"{path}: no known channel ({', '.join(CANONICAL)}, or TYDEX names); name the file's "
                        f"columns with --map FILE_COLUMN=NAME (the file gives: {names(sources) or 'none'})")


def _check_loads(path, fz: np.ndarray, convention: str) -> None:
    """A table whose loads are mostly not positive was read in the wrong axis convention."""
    if fz.size and np.median(fz) <= 0:
        share = float(np.mean(fz <= 0))
        other = "iso" if convention == "sae" else "sae"
        raise DataError(f"{path}: fz: {share:.0%} of the loads are not positive in the {convention} convention "
                        f"(median {float(np.median(fz)):g} N); is the file in another convention? "
                        f"(--convention {other})")


_CONVENTION = re.compile(r"^\s*convention\s*[:=]\s*([A-Za-z-]+)")
_UNITS = re.compile(r"^\s*units\s*[:=]\s*(.*)$")


def declared(comments, path) -> tuple[str | None, dict]:
    """``(convention, {column: unit})`` declared by a file's comment lines (``convention: sae``,
    ``units: NAME=UNIT, ...``); DataError for a convention that is not one of the three."""
    from tirecli.conventions import AXIS_CONVENTIONS

    convention, units = None, {}
    for line in comments:
        m = _CONVENTION.match(line)
        if m:
            value = m.group(1).lower()
            if value not in AXIS_CONVENTIONS:
                raise DataError(f"{path}: the file declares convention {token(value, 20)}; expected one of "
                                f"{', '.join(AXIS_CONVENTIONS)}")
            convention = value
        m = _UNITS.match(line)
        if m:
            for part in m.group(1).split(","):
                name, sep, unit = part.partition("=")
                if sep and name.strip():
                    units[name.strip()] = unit.strip()
    return convention, units


def choose_convention(path, declared_convention: str | None, option: str | None) -> str:
    """The axis convention of a file: the run's ``--convention``, else what the file declares, else ``iso``;
    DataError when both are given and differ."""
    if option and declared_convention and option != declared_convention:
        raise DataError(f"{path}: the file declares convention {declared_convention}, --convention says {option}; "
                        "drop one of them")
    return option or declared_convention or "iso"


def is_declaration(line: str) -> bool:
    """Whether a comment line is a ``convention:`` or ``units:`` declaration (:func:`declared`)."""
    return bool(_CONVENTION.match(line) or _UNITS.match(line))


def check_budget(path, rows: int, columns: int) -> None:
    """Refuse a table of ``rows`` x ``columns`` values over the sample budget (a row of more than
    :data:`tirecli.limits.CSV_VALUES_PER_SAMPLE` values counts as several samples, as for a CSV)."""
    from tirecli import limits

    per_row = -(-max(columns, 1) // limits.CSV_VALUES_PER_SAMPLE)
    if rows * per_row > limits.max_samples():
        what = f"{rows:,} data rows" + (f" of {columns:,} channels ({per_row} samples a row)" if per_row > 1 else "")
        limits.refuse_over_budget(rows * per_row, what, BYTES_PER_VALUE * limits.CSV_VALUES_PER_SAMPLE,
                                  fallback=str(path))


__all__ = ["CANONICAL", "INPUTS", "OUTPUTS", "EXTRAS", "Channel", "MeasuredData", "RawColumn", "assemble",
           "canonical_name", "check_budget", "declared", "choose_convention", "is_declaration", "require_known"]
