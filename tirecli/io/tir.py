"""Reading and writing ``.tir`` tyre property files and their YAML form (docs/models/magic_formula_tyre.md §12).

A ``.tir`` file is a TeimOrbit property file: ``[SECTION]`` headers, ``KEY = value`` lines,
``$`` / ``!`` comments, optional tables. :func:`parse_tir` copes with every quirk of §12.5:

1. CRLF, LF or CR line ends (``\\r`` stripped explicitly); UTF-8 text when the bytes are valid
   UTF-8, else Latin-1 (item 12), remembered so a converted file is written in the same encoding
   (never encoded twice);
2. the same key in two sections (``[UNITS] MASS`` and ``[INERTIA] MASS``): keys are stored per
   section, the section-qualified map is the primary structure (items 2, 3);
3. inline comments cut at the first ``$`` (or ``!``) outside single quotes (item 4); ``KEY=value``
   without blanks, leading blanks, tabs, trailing blanks, blank lines (item 5);
4. keys and section names upper-cased; string values kept as written (item 6);
5. lines without ``=`` (``{radial width}`` table headers, numeric table rows, ``(COMMENTS)``
   blocks and quoted comment rows) are collected as tables or skipped, never errors (item 7);
6. Fortran ``D`` exponents (``1.0D+03``); an empty value or a bare ``.`` is an error (item 11), and
   so is a number beyond the range of a double (``1e999`` would read as an infinity) and a key
   before the first ``[SECTION]`` header.

It knows nothing of the Magic Formula: units, versions, required keys and defaults are applied
by :mod:`tirecli.parameters.mf`. Every problem is a :class:`~tirecli.errors.Problem` naming the
file and line; all syntax errors of a file are reported together in one
:class:`~tirecli.errors.ConfigError` (exit code 2). Duplicate keys in one section and lines
that cannot be read are warnings (the first value is kept).

The YAML form (``tirecli tir convert --to yaml``) keeps the sections, keys, values (numbers as
numbers, strings as strings), tables, inline descriptions and the leading comment block, so
``tir -> yaml -> tir`` is lossless for the coefficients and the units.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from tirecli.errors import ConfigError, Problem, token

#: Sections holding tables (rows of numbers) rather than keys (§12.1, §12.6 step 3).
TABLE_SECTIONS = ("SHAPE", "DEFLECTION_LOAD_CURVE", "BOTTOMING_CURVE")

#: Marker of the YAML form.
YAML_FORMAT = "tirecli-tir/1"

_SECTION = re.compile(r"^\[\s*([A-Za-z0-9_\- ]+?)\s*\]\s*(?:[$!].*)?$")
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_NUMBER = re.compile(r"^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?$")
_INTEGER = re.compile(r"^[+-]?\d+$")
_WORD = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-/:]*$")
_LINE_SPLIT = re.compile(r"\r\n|\r|\n")


@dataclass
class TirEntry:
    """One ``KEY = value`` line.

    Attributes
    ----------
    value : float, int or str
        The value as written: ``int`` for integer literals, ``float`` for other numbers, ``str``
        for quoted text (or a bare word).
    line : int
        1-based line number.
    comment : str
        Inline description after ``$`` (without the ``$``).
    quoted : bool
        Whether a string value was in quotes.
    """

    value: float | int | str
    line: int
    comment: str = ""
    quoted: bool = True

    @property
    def is_number(self) -> bool:
        return isinstance(self.value, (int, float)) and not isinstance(self.value, bool)


@dataclass
class TirTable:
    """A table of a section (rows of numbers) with its ``{...}`` header text."""

    header: str
    rows: list
    line: int


@dataclass
class TirSection:
    """A ``[NAME]`` section: its entries (in file order) and its table, if any."""

    name: str
    line: int
    entries: dict = field(default_factory=dict)
    table: TirTable | None = None


@dataclass
class TirDocument:
    """A parsed ``.tir`` file (or its YAML form).

    Attributes
    ----------
    file : str
        Name used in messages (the path as given).
    sections : dict
        Section name (upper case) -> :class:`TirSection`, in file order.
    preamble : list of str
        Comment lines before the first section (kept by the converters).
    warnings : list of Problem
        Non-fatal findings (duplicate keys, unreadable lines).
    ends_mid_line : bool
        The file does not end with a line break (a truncation hint for later errors).
    last_line : int
        Number of the last line.
    encoding : str
        ``ascii``, ``utf-8`` (valid UTF-8 with non-ASCII text) or ``latin-1`` (anything else):
        the converters write the file back in it.
    bom : bool
        The file starts with a UTF-8 byte-order mark (skipped; not written back: it carries no meaning).
    cut_number : tuple or None
        ``(key, number)`` when the file ends without a line break right after an unquoted number
        (the shape of a file cut in the middle of a number; :mod:`tirecli.parameters.mf` refuses it).
    """

    file: str
    sections: dict = field(default_factory=dict)
    preamble: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    ends_mid_line: bool = False
    last_line: int = 0
    n_bytes: int = 0
    line_ends: str = ""
    encoding: str = "ascii"
    bom: bool = False
    cut_number: tuple | None = None

    def entry(self, section: str, key: str) -> TirEntry | None:
        sec = self.sections.get(section.upper())
        return None if sec is None else sec.entries.get(key.upper())

    def value(self, section: str, key: str, default=None):
        e = self.entry(section, key)
        return default if e is None else e.value

    def find(self, key: str) -> list[tuple[str, TirEntry]]:
        """Every ``(section, entry)`` holding ``key``, in file order."""
        key = key.upper()
        return [(name, s.entries[key]) for name, s in self.sections.items() if key in s.entries]

    def problem(self, line: int | None, key: str, message: str) -> Problem:
        return Problem(self.file, line, key, message)


def _cut_comment(text: str) -> tuple[str, str]:
    """Split ``value $comment`` at the first ``$`` or ``!`` outside quotes. Text holding its own quote
    character (``'it's'   $note``: the quotes do not pair up) is cut at the first ``$`` or ``!`` after
    the last quote character, so the value is the whole quoted text."""
    quote = None
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "$!":
            return text[:i].strip(), text[i + 1:].strip()
    if quote:
        last = text.rindex(quote)
        m = re.search(r"[$!]", text[last + 1:])
        if m:
            i = last + 1 + m.start()
            return text[:i].strip(), text[i + 1:].strip()
    return text.strip(), ""


def parse_value(text: str) -> tuple[object, bool]:
    """A value's text -> ``(value, quoted)``; ``ValueError`` with a reason if it cannot be read."""
    if not text:
        raise ValueError("missing value after '='")
    if text[0] in "'\"":
        q = text[0]
        if len(text) < 2 or text[-1] != q:
            raise ValueError(f"unterminated quoted text {token(text)}")
        return text[1:-1], True
    if _NUMBER.match(text):
        beyond = ValueError(f"the number {token(text)} is too large: beyond the range of a double (about 1.8e308)")
        if _INTEGER.match(text):
            if len(text) > 320:  # (Python refuses to read integers of thousands of digits at all)
                raise beyond
            value = int(text)
            try:
                float(value)
            except OverflowError:
                raise beyond from None
            return value, False
        value = float(text.replace("D", "E").replace("d", "e"))
        if not math.isfinite(value):
            raise beyond
        return value, False
    if _WORD.match(text) and not text.lower() in ("nan", "inf", "infinity"):
        return text, False
    raise ValueError(f"cannot read the value {token(text)} as a number (text must be in single quotes)")


def _is_number(tok: str) -> bool:
    return bool(_NUMBER.match(tok))


def _check_binary(data: bytes, file: str) -> None:
    if not data.strip():
        raise ConfigError(Problem(file, None, "", "empty file (expected a .tir property file with [SECTION] headers)"))
    head = data[:65536]
    if b"\x00" in head:
        raise ConfigError(Problem(file, None, "", "binary file (NUL bytes), expected a .tir text file"))
    ctrl = sum(1 for b in head if b < 32 and b not in (9, 10, 12, 13)) + head.count(0x7F)
    if ctrl > max(8, len(head) // 50):
        raise ConfigError(Problem(file, None, "", f"binary file ({ctrl} control bytes in the first "
                                                  f"{len(head)}), expected a .tir text file"))


#: Sections every kind of .tir file has at least one of (docs/models/magic_formula_tyre.md §12).
_TIR_SECTIONS = {"MDI_HEADER", "UNITS", "MODEL", "DIMENSION", "VERTICAL", "SCALING_COEFFICIENTS",
                 "LONGITUDINAL_COEFFICIENTS", "LATERAL_COEFFICIENTS", "ALIGNING_COEFFICIENTS", "SHAPE"}


def parse_tir(data: bytes | str, file: str = "<input>") -> TirDocument:
    """Parse the bytes (or text) of a ``.tir`` file into a :class:`TirDocument`.

    Raises
    ------
    ConfigError
        Empty or binary data, no section header, unreadable keys or values (every problem of
        the file at once, each as ``file:line: key: what is wrong``).
    """
    if isinstance(data, str):
        data = data.encode("utf-8")
    _check_binary(data, file)
    doc = TirDocument(file=file)
    text, doc.encoding, doc.bom = decode_text(data)
    lines = _LINE_SPLIT.split(text)
    content = data.rstrip(b" \t\x1a")  # trailing blanks or a DOS end-of-file mark are not a cut line
    doc.ends_mid_line = bool(content) and not content.endswith((b"\n", b"\r"))
    doc.n_bytes = len(data)
    doc.line_ends = "CRLF" if b"\r\n" in data else ("CR" if b"\r" in data else "LF")
    if lines and lines[-1] == "":
        lines.pop()
    doc.last_line = len(lines)  # the last line with content (trailing blank lines do not count)
    while doc.last_line and not lines[doc.last_line - 1].strip(" \t\x1a"):
        doc.last_line -= 1
    problems: list[Problem] = []
    sec: TirSection | None = None
    in_comment_block = False
    for no, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line or line[0] in "$!":
            if sec is None and line.startswith("!"):  # the leading comment block, kept by the converters
                doc.preamble.append(line)
            continue
        m = _SECTION.match(line)
        if m:
            name = m.group(1).strip().upper().replace(" ", "_")
            in_comment_block = False
            if name in doc.sections:
                doc.warnings.append(doc.problem(no, "", f"section [{name}] appears again (first at line "
                                                        f"{doc.sections[name].line}); its keys are merged"))
                sec = doc.sections[name]
            else:
                sec = doc.sections[name] = TirSection(name=name, line=no)
            continue
        if line.startswith("["):
            problems.append(doc.problem(no, "", f"cannot read the section header {token(line)} (expected [NAME])"))
            continue
        if "=" in line and not line.startswith(("{", "(", "'")):
            key_text, _, rest = line.partition("=")
            key = key_text.strip().upper()
            if not _KEY.match(key):
                problems.append(doc.problem(no, "", f"cannot read the key {token(key_text.strip())} "
                                                    "(expected a name of letters, digits and _)"))
                continue
            value_text, comment = _cut_comment(rest)
            try:
                value, quoted = parse_value(value_text)
            except ValueError as exc:
                problems.append(doc.problem(no, key, str(exc)))
                continue
            if sec is None:  # no section to keep it in (nor to write it back under)
                problems.append(doc.problem(no, key, "key before the first [SECTION] header (put it under "
                                                     "the section it belongs to, e.g. [MODEL])"))
                continue
            if key in sec.entries:
                first = sec.entries[key]
                same = "same value" if first.value == value else f"first value {token(first.value)} kept, {token(value)} ignored"
                doc.warnings.append(doc.problem(no, key, f"given twice in [{sec.name}] (first at line {first.line}; {same})"))
                continue
            sec.entries[key] = TirEntry(value=value, line=no, comment=comment, quoted=quoted)
            continue
        # lines without '=': table headers, table rows, comment blocks
        if sec is None:
            doc.warnings.append(doc.problem(no, "", f"ignored line before any [SECTION] header: {token(line, 40)}"))
            continue
        if line.startswith("{"):
            in_comment_block = False
            header = line[1:line.index("}")] if "}" in line else line[1:]
            sec.table = TirTable(header=header.strip(), rows=[], line=no)
            continue
        if line.startswith("("):
            in_comment_block = True
            continue
        if line.startswith("'"):
            continue  # a quoted comment row, e.g. inside (COMMENTS)
        toks = _cut_comment(line)[0].split()
        if toks and all(_is_number(t) for t in toks) and not in_comment_block:
            if sec.table is None:
                sec.table = TirTable(header="", rows=[], line=no)
            row = [float(t.replace("D", "E").replace("d", "e")) for t in toks]
            if not all(math.isfinite(x) for x in row):
                tok = next(t for t, x in zip(toks, row) if not math.isfinite(x))
                problems.append(doc.problem(no, "", f"table row of [{sec.name}]: the number {tok[:40]!r} is beyond "
                                                    "the range of a double (about 1.8e308)"))
                continue
            sec.table.rows.append(row)
            continue
        doc.warnings.append(doc.problem(no, "", f"ignored line in [{sec.name}] (not KEY = value, a table row "
                                                f"or a comment): {token(line, 40)}"))
    if doc.ends_mid_line and doc.last_line:
        doc.cut_number = _cut_number(lines[doc.last_line - 1])
    if not doc.sections:  # then the line-by-line problems are noise: say only what the file is not
        problems = [Problem(file, None, "", "not a .tir property file: no [SECTION] header found")]
    elif problems and not set(doc.sections) & _TIR_SECTIONS:
        problems = [Problem(file, None, "", f"not a .tir property file: none of its sections "
                                            f"({', '.join(token(s, 40) for s in list(doc.sections)[:4])}) is a .tir section such as "
                                            f"[MDI_HEADER], [UNITS] or [MODEL] ({len(problems)} unreadable lines)")]
    if problems:
        raise ConfigError(problems)
    return doc


def decode_text(data: bytes) -> tuple[str, str, bool]:
    """``(text, encoding, bom)`` of a ``.tir`` file's bytes: UTF-8 when they are valid UTF-8 (``ascii``
    when they are plain ASCII), else Latin-1, which reads any byte: the characters are those the
    bytes meant, and writing them back in ``encoding`` gives the same bytes."""
    bom = data.startswith(b"\xef\xbb\xbf")
    body = data[3:] if bom else data
    try:
        text = body.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1"), "latin-1", False
    return text, ("ascii" if text.isascii() and not bom else "utf-8"), bom


def _cut_number(line: str) -> tuple[str, str] | None:
    """``(key, number)`` when a line ends in an unquoted number with nothing after it (``KEY = 1.2``, or
    a table row ``1.0 0.5``: ``key`` empty), or is a bare key (``QSY``: ``number`` empty): the shape
    of a file cut in the middle of a line."""
    text = line.rstrip(" \t\x1a")
    if not text or _cut_comment(text)[1] or text.rstrip().endswith(("$", "!")):
        return None
    if "=" in text and not text.lstrip().startswith(("{", "(", "'")):
        key, _, rest = text.partition("=")
        rest = rest.strip()
        return (key.strip().upper(), rest) if _NUMBER.match(rest) else None
    toks = text.split()
    if toks and all(_is_number(t) for t in toks):
        return "", toks[-1]
    if _KEY.match(text.strip()):  # a key cut before its '= value'
        return text.strip().upper(), ""
    return None


def read_tir(path: str | Path) -> TirDocument:
    """Read and parse a ``.tir`` file (see :func:`parse_tir`); missing or unreadable files are ConfigErrors."""
    from tirecli.io.files import read_input_bytes
    from tirecli.limits import MAX_TIR_BYTES

    return parse_tir(read_input_bytes(path, "a .tir file", MAX_TIR_BYTES), str(path))


# --------------------------------------------------------------------------- writing


def format_number(v) -> str:
    """A number as ``.tir`` text: integers as written, floats by their shortest exact repr."""
    if isinstance(v, bool):
        raise TypeError("booleans are not .tir values")
    if isinstance(v, int):
        return str(v)
    return repr(float(v))


def format_value(v) -> str:
    """A value as ``.tir`` text: text in single quotes (in double quotes when it holds an apostrophe,
    as the reader accepts both), numbers by :func:`format_number`. ValueError for text that no quoting
    reads back the same (both quote characters, a line break)."""
    if isinstance(v, str):
        if "\n" in v or "\r" in v:
            raise ValueError("a text value cannot span lines in a .tir file")
        if "'" not in v:
            return f"'{v}'"
        if '"' not in v:
            return f'"{v}"'
        raise ValueError("a text value holding both quote characters (' and \") cannot be written to a .tir file")
    return format_number(v)


def format_tir(doc: TirDocument, descriptions: dict | None = None) -> str:
    """``.tir`` text of a document (LF line ends). ``descriptions`` (section -> key -> text)
    supplies an inline ``$`` comment where the document has none. ConfigError naming the key for a
    value no ``.tir`` file can hold (see :func:`format_value`)."""
    out = list(doc.preamble)
    for name, sec in doc.sections.items():
        if not name:
            raise ConfigError(doc.problem(sec.line or None, "", "keys outside any [SECTION] cannot be written to a .tir file"))
        rule = "$" + "-" * max(4, 68 - len(name)) + name.lower()
        out += [rule, f"[{name}]"]
        for key, e in sec.entries.items():
            try:
                val = format_value(e.value)
            except ValueError as exc:
                raise ConfigError(doc.problem(e.line or None, key, str(exc))) from None
            note = e.comment or (descriptions or {}).get(name, {}).get(key, "")
            line = f"{key:<25s}= {val:<20s}"
            out.append((line + f" ${note}") if note else line.rstrip())
        if sec.table is not None:
            if sec.table.header:
                out.append("{" + sec.table.header + "}")
            for row in sec.table.rows:
                out.append(" " + "  ".join(format_number(x) for x in row))
    return "\n".join(out) + "\n"


def encode_tir(doc: TirDocument, text: str) -> bytes:
    """The bytes of ``.tir`` text in the document's encoding (:func:`decode_text`; ASCII text is the same
    in all of them, a YAML form gives UTF-8 unless it says ``encoding: latin-1``). ConfigError naming
    the key of a character the encoding cannot hold."""
    enc = "latin-1" if doc.encoding == "latin-1" else "utf-8"
    try:
        data = text.encode(enc)
    except UnicodeEncodeError as exc:
        bad = text[exc.start]
        line = text.count("\n", 0, exc.start) + 1
        raise ConfigError(doc.problem(None, "encoding", f"the character {bad!r} (line {line} of the written file) "
                                                        f"cannot be written in {enc}")) from None
    return data


def write_tir(path: str | Path, doc: TirDocument, descriptions: dict | None = None) -> Path:
    """Write a document as a ``.tir`` file (in its encoding, see :func:`encode_tir`; through a
    temporary file: the file is complete or absent)."""
    from tirecli.io.atomic import atomic_write

    path = Path(path)
    data = encode_tir(doc, format_tir(doc, descriptions))
    with atomic_write(path, mode="wb") as fh:
        fh.write(data)
    return path


# --------------------------------------------------------------------------- YAML form


def to_yaml_data(doc: TirDocument) -> dict:
    """The YAML form of a document: ``format``, ``source``, ``preamble``, ``sections``, ``tables``,
    ``descriptions`` (plain data for :func:`tirecli.io.yamlio.dump_yaml`)."""
    data = {"format": YAML_FORMAT, "source": Path(doc.file).name}
    if doc.encoding == "latin-1":  # written back in it; UTF-8 and ASCII files need no note
        data["encoding"] = "latin-1"
    if doc.preamble:
        data["preamble"] = list(doc.preamble)
    data["sections"] = {name: {k: e.value for k, e in sec.entries.items()} for name, sec in doc.sections.items()}
    tables = {name: {"header": sec.table.header, "rows": [list(r) for r in sec.table.rows]}
              for name, sec in doc.sections.items() if sec.table is not None}
    if tables:
        data["tables"] = tables
    desc = {name: {k: e.comment for k, e in sec.entries.items() if e.comment} for name, sec in doc.sections.items()}
    desc = {k: v for k, v in desc.items() if v}
    if desc:
        data["descriptions"] = desc
    return data


def is_yaml_form(data) -> bool:
    """Whether parsed YAML data is the YAML form of a ``.tir`` file."""
    return isinstance(data, dict) and data.get("format") == YAML_FORMAT


def from_yaml_data(data, origins, file: str) -> TirDocument:
    """A :class:`TirDocument` from the YAML form (lines taken from ``origins``); ConfigError on
    anything that is not a mapping of sections of ``KEY: number-or-text``."""
    problems = []
    doc = TirDocument(file=file)

    def line_of(path):
        return origins.of(path)[1]

    if not is_yaml_form(data):
        raise ConfigError(Problem(file, line_of(()), "format", f"expected 'format: {YAML_FORMAT}' (the YAML form of a .tir file)"))
    enc = data.get("encoding", "utf-8")
    if enc not in ("utf-8", "latin-1"):
        problems.append(Problem(file, line_of(("encoding",)), "encoding",
                                f"unknown encoding {str(enc)[:40]!r} (expected utf-8 or latin-1)"))
    else:
        doc.encoding = "latin-1" if enc == "latin-1" else "utf-8"
    pre = data.get("preamble", [])
    if not isinstance(pre, list) or not all(isinstance(x, str) and "\n" not in x and "\r" not in x for x in pre):
        problems.append(Problem(file, line_of(("preamble",)), "preamble", "expected a list of comment lines"))
    else:
        doc.preamble = [x if x.startswith("!") else "! " + x.lstrip("$") for x in pre]
    sections = data.get("sections")
    if not isinstance(sections, dict) or not sections:
        raise ConfigError(Problem(file, line_of(("sections",)), "sections", "expected a mapping of sections"))
    desc = data.get("descriptions") or {}
    for name, entries in sections.items():
        sname = str(name).upper()
        if not _SECTION.match(f"[{sname}]") or " " in sname:
            problems.append(Problem(file, line_of(("sections", name)), f"sections.{name}",
                                    "not a .tir section name (letters, digits, _ and -)"))
            continue
        sec = doc.sections[sname] = TirSection(name=sname, line=line_of(("sections", name)) or 0)
        if entries is None:
            continue
        if not isinstance(entries, dict):
            problems.append(Problem(file, line_of(("sections", name)), f"sections.{name}", "expected a mapping of KEY: value"))
            continue
        for key, v in entries.items():
            path = ("sections", name, key)
            if not _KEY.match(str(key)):
                problems.append(Problem(file, line_of(path), f"sections.{name}.{key}", "not a .tir key name"))
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float, str)):
                problems.append(Problem(file, line_of(path), f"sections.{name}.{key}", "expected a number or a text"))
                continue
            if isinstance(v, float) and not math.isfinite(v):
                problems.append(Problem(file, line_of(path), f"sections.{name}.{key}",
                                        f"expected a finite number, got {v}"))
                continue
            if isinstance(v, str):
                try:
                    format_value(v)
                except ValueError as exc:
                    problems.append(Problem(file, line_of(path), f"sections.{name}.{key}", str(exc)))
                    continue
            comment = str((desc.get(name) or {}).get(key, "") or "")
            sec.entries[str(key).upper()] = TirEntry(value=v, line=line_of(path) or 0, comment=comment)
    for name, tab in (data.get("tables") or {}).items():
        sname = str(name).upper()
        path = ("tables", name)
        rows = tab.get("rows") if isinstance(tab, dict) else None
        if not isinstance(rows, list) or not all(isinstance(r, list) and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in r) for r in rows):
            problems.append(Problem(file, line_of(path), f"tables.{name}", "expected {header, rows: [[finite numbers]]}"))
            continue
        sec = doc.sections.setdefault(sname, TirSection(name=sname, line=line_of(path) or 0))
        sec.table = TirTable(header=str(tab.get("header", "")), rows=[[float(x) for x in r] for r in rows],
                             line=line_of(path) or 0)
    if problems:
        raise ConfigError(problems)
    return doc


def read_tir_yaml(path: str | Path) -> TirDocument:
    """Read the YAML form of a ``.tir`` file."""
    from tirecli.io.yamlio import load_yaml

    data, origins = load_yaml(path)
    return from_yaml_data(data, origins, str(path))


def read_any(path: str | Path) -> TirDocument:
    """A ``.tir`` file, or its YAML form when the name ends in ``.yaml``/``.yml``."""
    if str(path).lower().endswith((".yaml", ".yml")):
        return read_tir_yaml(path)
    return read_tir(path)
