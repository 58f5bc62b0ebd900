"""TYDEX 1.3 measurement files (``.tdx``): reader and writer.

Layout (TYDEX-Format, Description and Reference Manual, Release 1.3, Unrau & Zamow, 1997; the
column layout as public TYDEX tools read and write it): keyword lines ``**HEADER``, ``**COMMENTS``,
``**CONSTANTS``, ``**MEASURCHANNELS``, ``**MEASURDATA``, ``**END`` (model sections such as
``**MODELPARAMETERS`` ... ``**MODELEND`` are skipped); ``!`` starts a comment line. Entry lines are
fixed columns -- name in columns 1-10, description 11-40, unit 41-50, then the value (``**CONSTANTS``)
or the channel's factor and, optionally, a measurement and a physical offset, 10 columns each
(``**MEASURCHANNELS``) -- and are also read when their fields are only separated by blanks. Data rows
hold one number per channel, separated by blanks or in fields of 10 columns (then numbers may touch).

A channel's value is ``factor * number`` in its unit (offsets other than 0 are refused: their
definition differs between tools). Channels with a standard name become the canonical columns of
:mod:`tirecli.io.measured` (:data:`CHANNELS`); inputs not measured but given as a constant (a TYDEX
file of one sweep often gives ``FZW`` or ``INFLPRES`` under ``**CONSTANTS``) become constant columns.
TYDEX's W axes are ISO-W (x forward, y left, z up, the road's force on the tyre): a file is read in
the ``iso`` convention unless told otherwise.
"""
from __future__ import annotations

import re

import numpy as np

from tirecli.errors import DataError, token
from tirecli.io.measured import (CANONICAL, MeasuredData, RawColumn, assemble, check_budget, choose_convention,
                                 declared)

#: TYDEX channel name -> canonical column (reading); FX and FXW are both the longitudinal force.
CHANNELS = {"MEASNUMB": "run", "RUNTIME": "t", "LONGSLIP": "kappa", "SLIPANGL": "alpha", "INCLANGL": "gamma",
            "FZW": "fz", "INFLPRES": "p", "LONGVEL": "vx", "FX": "fx", "FXW": "fx", "FYW": "fy", "MXW": "mx",
            "MYW": "my", "MZW": "mz", "ROLLRADI": "re", "WHROTSPD": "omega"}
#: Canonical column -> TYDEX channel name and description (writing).
NAMES = {"run": ("MEASNUMB", "Measurement number"), "t": ("RUNTIME", "Time"),
         "kappa": ("LONGSLIP", "Longitudinal slip"), "alpha": ("SLIPANGL", "Slip angle"),
         "gamma": ("INCLANGL", "Inclination angle"), "fz": ("FZW", "Vertical force W"),
         "p": ("INFLPRES", "Inflation pressure"), "vx": ("LONGVEL", "Longitudinal velocity"),
         "fx": ("FX", "Longitudinal force W"), "fy": ("FYW", "Lateral force W"),
         "mz": ("MZW", "Aligning torque W"), "mx": ("MXW", "Overturning moment W"),
         "my": ("MYW", "Rolling resistance moment W"), "re": ("ROLLRADI", "Rolling radius"),
         "omega": ("WHROTSPD", "Wheel rotational speed")}
#: Sections of a TYDEX file (others are skipped).
SECTIONS = ("HEADER", "COMMENTS", "CONSTANTS", "MEASURCHANNELS", "MEASURDATA", "END")
#: Width of a field of the fixed layout.
WIDTH = 10
#: A channel name as TYDEX writes them (at most 8 characters, letters, digits, underscores).
_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,9}")
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?")


def _number(text: str) -> bool:
    return bool(_NUMBER.fullmatch(text))


def _float(text: str) -> float:
    return float(text.replace("d", "e").replace("D", "e"))


# --------------------------------------------------------------------------- reading


def read_tydex(path, mapping: dict | None = None, units: dict | None = None,
               convention: str | None = None) -> MeasuredData:
    """Read a TYDEX ``.tdx`` file into a :class:`~tirecli.io.measured.MeasuredData` table.

    Parameters
    ----------
    mapping : dict or None
        ``{TYDEX channel name: column name}`` for channels without a standard name (``FY`` -> ``fy``).
    convention : str or None
        Axis convention of the file: ``--convention``, else a ``convention: NAME`` line of
        ``**COMMENTS``, else ``iso`` (TYDEX's W axes).
    units : dict or None
        ``{name: unit}`` replacing the unit the file gives a channel (``name``: the TYDEX name or the
        canonical one).

    Raises
    ------
    ConfigError, DataError
        (exit 2) A file that is not a readable TYDEX file: missing, binary, not starting with
        ``**HEADER``, without ``**MEASURCHANNELS``/``**MEASURDATA``/``**END``, a data row with another
        number of values than channels, a cell that is not a number, an unknown unit (naming the
        channel), more rows than the sample budget.
    """
    from tirecli import limits
    from tirecli.io.files import decode_text, read_input_bytes, show_path

    shown = show_path(path)
    data = read_input_bytes(path, "a TYDEX file", limits.csv_max_bytes())
    if b"\x00" in data:
        decode_text(data, path, "a TYDEX file")  # a binary file: ConfigError naming the line of its first NUL
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:  # TYDEX files of German rigs are often Latin-1
        text = data.decode("latin-1")
    del data
    sections = split_sections(text, shown)
    return _table(sections, shown, convention, units or {}, mapping or {})


_KEYWORD = re.compile(r"^[ \t]*\*\*([A-Za-z]*)[^\n]*$", re.M)


def split_sections(text: str, path: str) -> dict:
    """``{KEYWORD: (number of the section's first line, its text)}`` of a TYDEX text (the text between the
    keyword line and the next); DataError for a text that is not one."""
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    sections: dict = {}
    line, pos, current = 1, 0, None
    for m in _KEYWORD.finditer(text):
        if current is None:
            before = text[:m.start()].split("\n")
            if any(t.strip() and not t.lstrip().startswith("!") for t in before):
                break  # text before **HEADER: not a TYDEX file
        else:
            sections[current] = (line, text[pos:m.start()])
        key = m.group(1).upper()
        if current is None and key != "HEADER":
            break
        if key in sections and key in SECTIONS:
            raise DataError(f"{path}:{text.count(chr(10), 0, m.start()) + 1}: a second **{key} section")
        current, pos = key, min(m.end() + 1, len(text))
        line = text.count("\n", 0, pos) + 1
        if key == "END":
            sections[key] = (line, "")
            break
    if "HEADER" not in sections and current != "HEADER":
        raise DataError(f"{path}: not a TYDEX file (it does not start with a **HEADER line)")
    if current is not None and current not in sections:
        sections[current] = (line, text[pos:])
    for key in ("MEASURCHANNELS", "MEASURDATA"):
        if key not in sections:
            raise DataError(f"{path}: no **{key} section (a TYDEX file of measured data needs one)")
    if "END" not in sections:
        raise DataError(f"{path}: no **END line after the data (is the file cut short?)")
    return sections


def _lines(section) -> list:
    """``[(line number, text)]`` of a section's lines."""
    first, text = section
    return [(first + i, t.rstrip()) for i, t in enumerate(text.split("\n"))]


def _content(lines):
    """The entry lines of a section: blank lines and ``!`` comment lines left out."""
    return [(no, t) for no, t in lines if t.strip() and not t.lstrip().startswith("!")]


def entry(line: str, max_numbers: int) -> tuple[str, str, str, list[str]]:
    """``(name, description, unit, numbers)`` of an entry line, fixed columns or blank-separated.

    The fixed layout is taken when the line fits it (name alone in columns 1-10, a unit in 41-50,
    1 to ``max_numbers`` numbers from column 51) unless the blank-separated reading gives a known unit
    and the fixed one does not. ``numbers`` is empty when the value is text (a constant such as a name).
    """
    from tirecli import units

    fixed = None
    if len(line) > 5 * WIDTH and len(line[:WIDTH].split()) == 1 and line[4 * WIDTH:5 * WIDTH].strip():
        nums = line[5 * WIDTH:].split()
        if 1 <= len(nums) <= max_numbers and all(_number(x) for x in nums):
            fixed = (line[:WIDTH].strip(), line[WIDTH:4 * WIDTH].strip(), line[4 * WIDTH:5 * WIDTH].strip(), nums)
    loose = _loose(line, max_numbers)
    if fixed is not None and (units.known(fixed[2]) or not units.known(loose[2])):
        return fixed
    return loose


def _loose(line: str, max_numbers: int) -> tuple[str, str, str, list[str]]:
    """:func:`entry` of a blank-separated line: the name first, the numbers last, the unit before them
    (``N m`` is one unit: the longest known unit of the last one or two words), the description between."""
    from tirecli import units

    words = line.split()
    k = 0
    while k < min(max_numbers, len(words) - 1) and _number(words[-1 - k]):
        k += 1
    nums = words[len(words) - k:] if k else []
    rest = words[1:len(words) - k]
    unit, ndesc = "", len(rest)
    for take in (2, 1):
        if len(rest) >= take and units.known(" ".join(rest[-take:])):
            unit, ndesc = " ".join(rest[-take:]), len(rest) - take
            break
    else:
        if rest and nums:
            unit, ndesc = rest[-1], len(rest) - 1
    return words[0] if words else "", " ".join(rest[:ndesc]), unit, nums


def _header(lines) -> dict:
    out = {}
    for _, t in _content(lines):
        if len(t) > 4 * WIDTH and len(t[:WIDTH].split()) == 1:
            name, value = t[:WIDTH].strip(), t[4 * WIDTH:].strip()
        else:
            words = t.split()
            name, value = words[0], (words[-1] if len(words) > 1 else "")
        out.setdefault(name, value)
    return out


def _constants(lines, path, overrides: dict) -> dict:
    """``{NAME: (SI value, SI unit)}``; a text value is kept as ``(text, "")``; an unknown unit of a
    number is an error naming the constant."""
    from tirecli import units

    out = {}
    for no, t in _content(lines):
        name, desc, unit, nums = entry(t, 1)
        if not nums:  # a text value (a name, a date): kept as text
            out[name] = (t[5 * WIDTH:].strip() if len(t) > 5 * WIDTH else " ".join(t.split()[1:]), "")
            continue
        unit = overrides.get(name, overrides.get(CHANNELS.get(name, ""), unit))
        try:
            si_unit, factor, offset = units.si(unit)
        except KeyError:
            raise DataError(f"{path}:{no}: constant {token(name)}: unknown unit {token(unit, 30)} "
                            f"(known: {', '.join(units.names())})") from None
        out[name] = (_float(nums[0]) * factor + offset, si_unit)
    return out


def _channels(lines, path) -> list[tuple[int, str, str, str, float]]:
    """``[(line, name, description, unit, factor)]`` of ``**MEASURCHANNELS``."""
    out, seen = [], {}
    for no, t in _content(lines):
        name, desc, unit, nums = entry(t, 3)
        if not _NAME.fullmatch(name):
            raise DataError(f"{path}:{no}: {token(name, 20)} is not a channel name (letters, digits, underscores, "
                            "at most 10 characters)")
        if not nums:
            raise DataError(f"{path}:{no}: channel {name}: no factor (name, description, unit, factor expected)")
        offsets = [_float(x) for x in nums[1:]]
        if any(o != 0.0 for o in offsets):
            raise DataError(f"{path}:{no}: channel {name}: offsets other than 0 are not supported "
                            f"(measurement offset and physical offset {', '.join(nums[1:])})")
        factor = _float(nums[0])
        if factor == 0.0 or not np.isfinite(factor):
            raise DataError(f"{path}:{no}: channel {name}: factor {token(nums[0], 20)} (a non-zero number expected)")
        if name in seen:
            raise DataError(f"{path}:{no}: channel {name} is also defined at line {seen[name]}")
        seen[name] = no
        out.append((no, name, desc, unit, factor))
    if not out:
        raise DataError(f"{path}: **MEASURCHANNELS names no channel")
    return out


def _data(section, names: list, path) -> tuple[np.ndarray, list[int]]:
    """The ``**MEASURDATA`` values (rows x channels) and the line number of each row."""
    rows = _content(_lines(section))
    n = len(names)
    check_budget(path, len(rows), n)
    if not rows:
        raise DataError(f"{path}: **MEASURDATA holds no data row")
    counts = [len(t.split()) for _, t in rows]
    if counts.count(n) == len(rows):  # blank-separated throughout: one conversion
        try:
            values = np.array(" ".join(t for _, t in rows).split(), dtype=float).reshape(len(rows), n)
        except ValueError:
            values = None
        if values is not None:
            return values, [no for no, _ in rows]
    values = np.empty((len(rows), n))
    for k, (no, t) in enumerate(rows):
        cells = t.split() if counts[k] == n else _fixed_cells(t, n)
        if cells is None:
            raise DataError(f"{path}:{no}: data row {k + 1} has {counts[k]} value(s) but **MEASURCHANNELS names "
                            f"{n} channel(s)")
        try:
            values[k] = [_float(c) for c in cells]
        except ValueError:
            j = next(j for j, c in enumerate(cells) if not _is_float(c))
            cell = cells[j].strip()
            what = "NOTAVAIL (no value)" if cell.upper() == "NOTAVAIL" else f"not a number ({token(cell, 20)})"
            raise DataError(f"{path}:{no}: channel {names[j]} (data row {k + 1}): {what}") from None
    return values, [no for no, _ in rows]


def _is_float(text: str) -> bool:
    try:
        _float(text)
    except ValueError:
        return False
    return True


def _fixed_cells(text: str, n: int):
    """The ``n`` fields of 10 columns of a data row written in the fixed layout (numbers may touch), or None."""
    body = text.rstrip()
    if not (WIDTH * (n - 1) < len(body) <= WIDTH * n):
        return None
    cells = [body[i * WIDTH:(i + 1) * WIDTH] for i in range(n)]
    return cells if all(c.strip() and len(c.split()) == 1 for c in cells) else None


def _table(sections: dict, path: str, option: str | None, unit_map: dict, mapping: dict) -> MeasuredData:
    header = _header(_lines(sections["HEADER"]))
    comments = [t.strip() for _, t in _lines(sections.get("COMMENTS", (0, ""))) if t.strip()]
    convention = choose_convention(path, declared(comments, path)[0], option)
    constants = _constants(_lines(sections.get("CONSTANTS", (0, ""))), path, unit_map)
    channels = _channels(_lines(sections["MEASURCHANNELS"]), path)
    names = [c[1] for c in channels]
    missing = [src for src in mapping if src not in names]
    if missing:
        raise DataError(f"{path}: mapped channel(s) {', '.join(token(m) for m in missing)} not in **MEASURCHANNELS "
                        f"(channels: {', '.join(names[:16])})")
    values, line_of = _data(sections["MEASURDATA"], names, path)
    columns, notes = [], []
    for j, (_, name, desc, unit, factor) in enumerate(channels):
        col = mapping.get(name) or CHANNELS.get(name.upper(), name)
        unit = unit_map.get(name, unit_map.get(col, unit))
        columns.append(RawColumn(values[:, j], col, name, unit, desc, factor))
    have = {c.name for c in columns}
    for tydex_name, col in CHANNELS.items():  # inputs held constant through the file, given once
        if col in ("kappa", "alpha", "gamma", "fz", "p", "vx") and col not in have and tydex_name in constants:
            value, si_unit = constants[tydex_name]
            if si_unit:
                columns.append(RawColumn(np.full(len(values), value), col, f"constant {tydex_name}", si_unit,
                                         CANONICAL[col][1]))
                have.add(col)
                notes.append(f"{col} = {value:g} {si_unit} for every row (the constant {tydex_name})")
    return assemble(path, "tdx", columns, convention, header=header, comments=comments, constants=constants,
                    notes=notes, rows=lambda i: f"line {line_of[i]}")


# --------------------------------------------------------------------------- writing


def format_tydex(data: MeasuredData, comments=(), header=None, threads: int | None = None) -> str:
    """The text of a TYDEX 1.3 file of ``data`` (ISO-W, SI: every channel's unit is its SI unit and its
    factor 1; values exact, so that the file reads back to the same floats).

    Entry lines are in the fixed layout (name 10, description 30, unit 10 columns); data rows hold
    the exact text of each value, separated by blanks. ``comments`` go to ``**COMMENTS`` after the data's
    own; ``header`` entries are added to ``**HEADER`` (``RELEASE`` is 1.3). A column whose name is not a
    TYDEX channel name (letters, digits, underscores, at most 10 characters) is an error naming it.
    """
    names = []
    for col in data.frame.columns:
        name = NAMES.get(col, (col, ""))[0]
        if not _NAME.fullmatch(str(name)):
            raise DataError(f"{data.source}: channel {token(str(col))} cannot be written to a TYDEX file "
                            "(a channel name there has at most 10 letters, digits or underscores; rename it with "
                            "--map)")
        names.append(name)
    head = {"RELEASE": ("Release of TYDEX-Format", "1.3")}
    for k, v in {**data.header, **(header or {})}.items():
        if k != "RELEASE" and _NAME.fullmatch(str(k)):
            head[k] = (_HEADER_TEXT.get(k, ""), _one_line(v))
    out = ["**HEADER"]
    out += [f"{k:<{WIDTH}}{desc[:30]:<30}{v}" for k, (desc, v) in head.items()]
    out.append("**COMMENTS")
    out += [_one_line(c) for c in [*data.comments, *comments] if _one_line(c)]
    constants = [(k, v, u) for k, (v, u) in data.constants.items() if u and _NAME.fullmatch(str(k))]
    if constants:
        out.append("**CONSTANTS")
        out += [f"{k:<{WIDTH}}{'':<30}{_unit_text(u):<{WIDTH}}{repr(float(v))}" for k, v, u in constants]
    out.append("**MEASURCHANNELS")
    for col, name in zip(data.frame.columns, names):
        ch = data.channels.get(col)
        desc = NAMES[col][1] if col in NAMES else _one_line(ch.description if ch else "")
        unit = ch.unit if ch is not None and ch.unit else CANONICAL.get(col, ("-", ""))[0]
        out.append(f"{name:<{WIDTH}}{desc[:29]:<30}{_unit_text(unit):<{WIDTH}}1")
    out.append("**MEASURDATA")
    body = _data_text([data.frame[c].to_numpy(dtype=float) for c in data.frame.columns])
    return "\n".join(out) + "\n" + body + ("\n" if body else "") + "**END\n"


def _data_text(columns) -> str:
    """Data rows: each value as the text of ``repr`` (exact: it reads back to the same float),
    right-aligned in a field of at least 10 columns, one blank at least between values."""
    from tirecli.io.fastcsv import repr_matrix

    if not columns or len(columns[0]) == 0:
        return ""
    rows = None
    for col in columns:
        texts = repr_matrix(col).view("S24").ravel()
        width = max(WIDTH, int(np.char.str_len(texts).max()) + 1)
        cells = np.char.rjust(texts, width)
        rows = cells if rows is None else np.char.add(rows, cells)
    return b"\n".join(rows.tolist()).decode("ascii")


#: Descriptions of the header entries tirecli writes.
_HEADER_TEXT = {"MEASID": "Measurement ID", "SUPPLIER": "Data supplier", "DATE": "Date", "CLCKTIME": "Clock time",
                "TYRESIDE": "Tyre side", "TITLE": "Title", "GENERATR": "Generated by", "SEED": "Random seed"}


def _unit_text(unit: str) -> str:
    return unit if unit else "-"


def _one_line(text) -> str:
    """A value or comment as one printable line (control characters and line breaks become blanks)."""
    return re.sub(r"[\x00-\x1f\x7f]+", " ", str(text)).strip()


def write_tydex(path, data: MeasuredData, comments=(), header=None) -> None:
    """Write :func:`format_tydex` of ``data`` to ``path`` (through a temporary file)."""
    from tirecli.io.output import write_text

    write_text(path, format_tydex(data, comments, header))


__all__ = ["read_tydex", "write_tydex", "format_tydex", "split_sections", "entry", "CHANNELS", "NAMES"]
