"""Fast exact text for large float columns (the CSV output of ``tirecli mf eval``).

Python's ``repr`` is exact but costs about 1 us per float on a slow machine, too slow for
millions of values. :func:`format_rows` writes every finite double in scientific notation with
the fewest of 15, 16 or 17 significant digits that read back to the same double, trailing zeros
removed (``-6.26e+00``, ``4e+03``, ``-4.8376495139982391e+03``, zero as ``0``): the digits of
``repr``, vectorized with numpy. Seventeen correctly rounded significant digits always read
back exactly; a shorter candidate is accepted only when it lies inside the rounding interval of
the double. Rounding and the interval test are done in extended precision (x86 ``long double``,
64-bit mantissa), whose error (5e-20 relative) is far below the half-ulp margin. Where ``long double`` is no wider than ``double`` every value is
checked by parsing it back and any mismatch is redone with ``repr``. NaN becomes an empty cell,
infinities ``inf``/``-inf``.

Rows are built in one byte matrix of 24-byte slots per value (separator, sign, first digit,
point | four groups of four digits | ``e``, exponent sign, two exponent digits), written as six
32-bit words from lookup tables; a filler byte marks unused bytes (the sign of positive numbers,
trailing zeros) and one ``bytes.replace`` removes them. Blocks of rows are formatted on the shared thread
pool (numpy releases the GIL). Exponents beyond two digits, NaN and infinities are rare and take
a slower exact path (``repr``).
"""
from __future__ import annotations

import numpy as np

_W = 24  # separator, sign, digit, '.', 16 digits, 'e', sign, 2 exponent digits


def _words(texts) -> np.ndarray:
    """Little-endian 32-bit words holding 4-byte texts (so a uint32 view writes them in order)."""
    return np.frombuffer(b"".join(t.encode("latin-1") for t in texts), dtype="<u4").copy()


_DIGITS4 = _words(f"{i:04d}" for i in range(10000))
_TRIM4 = _words(f"{i:04d}".rstrip("0").ljust(4, chr(1)) for i in range(10000))  # trailing zeros -> filler
_GROUPS = np.concatenate([_DIGITS4, _TRIM4])  # index c + 10000 * (every later group is zero)
_EXP = _words(f"e{'-' if k < 0 else '+'}{abs(k):02d}" for k in range(-99, 100))  # index k + 99
_HEAD = {sep: _words(f"{sep}{chr(1) if neg == 0 else '-'}{dig}." for neg in (0, 1) for dig in range(10))
         for sep in ("\n", ",")}  # index 10 neg + first digit
_FILL = 1  # filler byte, removed at the end
_EXTENDED = np.finfo(np.longdouble).nmant >= 63
_P10_OFF = 360
with np.errstate(over="ignore"):  # (long double no wider than double: inf beyond 1e308, no warning at import)
    _P10 = np.longdouble(10) ** np.arange(-_P10_OFF, _P10_OFF + 1, dtype=np.longdouble)
    _P10D = _P10.astype(np.float64)  # inf beyond 1e308, 0 below the smallest double
_BLOCK = 65536


def _scaled17(a):
    """``(e, y, d, D)`` of positive finite ``a``: decimal exponent ``e``, ``y = a * 10^(16 - e)`` (``a`` in
    units of its 17th significant digit, in long double: error ~0.01 unit), ``d = rint(y)`` in [1e16, 1e17)
    and ``D``, ``d`` as uint64."""
    e = np.floor(np.log10(a)).astype(np.int64)
    al = a.astype(np.longdouble)
    y = al * _P10[_P10_OFF + 16 - e]
    d = np.rint(y)
    D = d.astype(np.uint64)
    for _ in range(2):  # log10 can be off by one next to powers of ten
        hi = D >= np.uint64(10 ** 17)
        lo = D < np.uint64(10 ** 16)
        if not (hi.any() or lo.any()):
            break
        e = e + hi - lo
        y = al * _P10[_P10_OFF + 16 - e]
        d = np.rint(y)
        D = d.astype(np.uint64)
    return e, y, d, D


def _digits(a):
    """``(D, e)``: the 17-digit integer ``D`` (``10^16 <= D < 10^17``, shorter results padded with
    zeros) and decimal exponent with ``a ~= D * 10^(e - 16)``, using 15, 16 or 17 significant
    digits: the fewest that read back to ``a`` (``a > 0`` finite)."""
    e, y, d, D = _scaled17(a)
    frac = (y - d).astype(np.float64)  # y = D + frac, |frac| <= 0.5
    # half the gaps to the neighbouring doubles, in units of the 17th digit, less the error of y
    # (computed in double: 1e-16 relative is nothing against the 0.02-unit margin; where the
    # scale overflows, near the ends of the double range, no shorter form is tried)
    with np.errstate(over="ignore", invalid="ignore"):
        scale = _P10D[_P10_OFF + 16 - e]
        g_up = np.spacing(a) * scale * 0.5 - 0.02
        g_dn = np.spacing(np.nextafter(a, 0.0)) * scale * 0.5 - 0.02
        bad = ~(np.isfinite(g_up) & np.isfinite(g_dn))
        if bad.any():
            g_up[bad] = -1.0
            g_dn[bad] = -1.0
    best = D
    E = e
    done = np.zeros(a.size, dtype=bool)
    for step in (100, 10):  # 15, then 16 significant digits
        c = (D + np.uint64(step // 2)) // np.uint64(step) * np.uint64(step)
        diff = (c.astype(np.int64) - D.astype(np.int64)) - frac  # candidate - y, in units
        ok = ~done & (((diff >= 0) & (diff < g_up)) | ((diff < 0) & (-diff < g_dn)))
        if ok.any():
            best = np.where(ok, c, best)
            done |= ok
    top = best >= np.uint64(10 ** 17)  # rounded up to 10^17: one more decade
    if top.any():
        best = np.where(top, np.uint64(10 ** 16), best)
        E = E + top
    return best, E


def _fill(x, w, sep: str) -> np.ndarray:
    """Write the text of the floats ``x`` (1-D) into the word matrix view ``w`` (n, 6).

    Returns the indices of the values left for the slow path (|exponent| >= 100, inf); NaN is an
    empty cell.
    """
    a = np.abs(x)
    zero = a == 0
    nan = np.isnan(a)
    odd = np.isinf(a)
    special = zero.any() or nan.any() or odd.any()
    d, e = _digits(np.where(zero | nan | odd, 1.0, a) if special else a)
    d0 = d // np.uint64(10 ** 16)
    r = d - d0 * np.uint64(10 ** 16)
    chunks = []
    for p in (10 ** 12, 10 ** 8, 10 ** 4):
        c = r // np.uint64(p)
        r = r - c * np.uint64(p)
        chunks.append(c.astype(np.intp))
    chunks.append(r.astype(np.intp))
    later_zero = np.ones(a.size, dtype=bool)  # every later group of digits is zero
    for k in range(3, -1, -1):
        c = chunks[k]
        w[:, 1 + k] = _GROUPS[c + 10000 * later_zero]
        later_zero &= c == 0
    head = _HEAD[sep][d0.astype(np.intp) + 10 * (x < 0)]
    w[:, 0] = np.where(later_zero, (head & np.uint32(0x00FFFFFF)) | np.uint32(_FILL << 24), head)  # no point without fraction digits
    big = np.abs(e) >= 100
    w[:, 5] = _EXP[np.where(big, 0, e) + 99]
    for sel, text in ((zero, ord("0")), (nan, _FILL)):  # "0" or an empty cell: separator, then fillers
        if sel.any():
            m = w[sel].view(np.uint8)
            m[:, 1] = text
            m[:, 2:] = _FILL
            w[sel] = m.view(w.dtype)
    return np.flatnonzero(odd | (big & ~nan))


def _runs(x):
    """The runs of equal values of the float array ``x`` (equal bits: ``-0.0`` is not ``0.0``), so that a
    column that repeats its values (a constant; a sweep's speeds, adhesion, unused NaN columns) is
    formatted once per run: ``(first, ids)`` with ``x[first]`` the value of each run and ``ids`` the
    run of each value (``x[first][ids]`` is ``x``), or None when nearly every value is a run of its own
    (more than 7 in 8)."""
    if x.size < 2:
        return None
    bits = x.view(np.uint64)
    change = bits[1:] != bits[:-1]
    if np.count_nonzero(change) >= x.size - x.size // 8:
        return None
    first = np.concatenate([[0], np.flatnonzero(change) + 1])
    ids = np.concatenate([[0], np.cumsum(change, dtype=np.intp)])
    return first, ids


def _fill_column(x, w, sep: str) -> np.ndarray:
    """:func:`_fill`, each run of equal values (:func:`_runs`) formatted once."""
    runs = _runs(x)
    if runs is None:
        return _fill(x, w, sep)
    first, ids = runs
    part = np.empty((first.size, w.shape[1]), dtype=w.dtype)
    slow = _fill(x[first], part, sep)
    w[...] = part[ids]
    if not slow.size:
        return slow
    marked = np.zeros(first.size, dtype=bool)
    marked[slow] = True
    return np.flatnonzero(marked[ids])


def _rows_block(cols, lo, hi, prefix=None) -> bytes:
    """Rows ``lo:hi`` as text, each row starting with a newline (so the first split item is empty).

    ``prefix`` (a :class:`_Prefix`) puts its text of each row before the columns (then a comma)."""
    n = hi - lo
    head = 0 if prefix is None else prefix.words
    w = np.empty((n, head + 6 * len(cols)), dtype="<u4")
    if prefix is not None:
        prefix.fill(w[:, :head].view(np.uint8), lo, hi)
    slow = [_fill_column(c[lo:hi], w[:, head + 6 * i:head + 6 * i + 6], "\n" if i == 0 and not head else ",")
            for i, c in enumerate(cols)]
    text = _unfilled(w)
    bad = np.unique(np.concatenate(slow))
    if len(bad):  # rebuild the few rows with a special value exactly
        rows = text.split(b"\n")
        for i in bad:
            start = b"" if prefix is None else _unfilled(w[i, :head])[1:] + b","
            rows[i + 1] = start + b",".join(_exact(float(c[lo + i])) for c in cols)
        text = b"\n".join(rows)
    return text


def _unfilled(w) -> bytes:
    """The bytes of the array ``w`` without the filler bytes (a numpy compress: faster than
    ``bytes.replace`` when the fillers are many, and without the GIL)."""
    m = w.view(np.uint8).ravel()
    return m[m != _FILL].tobytes()


class _Prefix:
    """The text put before the formatted columns of each row: a line of an input text, then ``lead``;
    laid out in the first ``words`` 32-bit words of a row of :func:`_rows_block` (the line's newline,
    the line, ``lead``, fillers).

    ``text`` holds the lines: row ``i``'s starts with the newline at ``text[nl[i]]`` and ends before
    ``ends[i]``."""

    def __init__(self, text: bytes, nl, ends, lead: bytes = b""):
        self.nl = np.asarray(nl, dtype=np.intp)
        self.lens = np.asarray(ends, dtype=np.intp) - self.nl  # with the newline
        self.width = int(self.lens.max(initial=1))
        src = np.frombuffer(text, dtype=np.uint8)
        self.windows = np.lib.stride_tricks.sliding_window_view(  # row i: windows[nl[i]] (copied by rows)
            np.concatenate([src, np.full(self.width, _FILL, dtype=np.uint8)]), self.width)
        self.lead = np.frombuffer(lead, dtype=np.uint8)
        self.words = -(-(self.width + len(lead)) // 4)

    def fill(self, m, lo: int, hi: int) -> None:
        """Write rows ``lo:hi`` into the byte matrix ``m`` (``hi - lo`` rows, ``4 * words`` columns)."""
        line = m[:, :self.width]
        line[...] = self.windows[self.nl[lo:hi]]
        np.copyto(line, np.uint8(_FILL), where=np.arange(self.width) >= self.lens[lo:hi, None])  # the next lines
        m[:, self.width:self.width + self.lead.size] = self.lead
        m[:, self.width + self.lead.size:] = _FILL


def _exact(v: float) -> bytes:
    if v != v:
        return b""
    return repr(v).encode()


def _blocks(cols, threads, prefix=None):
    """The texts of the rows of ``cols`` (see :func:`_rows_block`), block by block in order, formatted
    on the shared thread pool (:func:`tirecli.parallel.ordered_map`)."""
    from tirecli.parallel import ordered_map

    n = cols[0].size if cols else 0

    def block(s):
        text = _rows_block(cols, s, min(s + _BLOCK, n), prefix)
        if not _EXTENDED:
            text = b"".join(b"\n" + r for r in _verified(cols, text.split(b"\n")[1:], s))
        return text

    return ordered_map(block, range(0, n, _BLOCK), threads)


def format_rows(columns, threads: int | None = None) -> list[bytes]:
    """One ``bytes`` line per row: the columns' exact texts joined by commas (the texts :func:`write_table`
    writes, as a list).

    Parameters
    ----------
    columns : sequence of array_like
        Float columns of equal length.
    threads : int or None
        Worker threads (default: the shared pool's thread count).
    """
    cols = [np.ascontiguousarray(c, dtype=float).ravel() for c in columns]
    if not cols or cols[0].size == 0:
        return []
    return (b"".join(_blocks(cols, threads))[1:] + b"\n").split(b"\n")[:-1]  # each block starts each row with a newline


def _verified(cols, rows, lo: int = 0):
    """``rows`` (texts of rows ``lo, lo + 1, ...``) with every cell of the columns (the last cells of a
    row) that does not read back to its value redone with ``repr``."""
    fixed = []
    k = len(cols)
    for i, row in enumerate(rows):
        cells = row.split(b",")
        for j in range(k):
            v = cols[j][lo + i]
            at = len(cells) - k + j
            if np.isfinite(v) and float(cells[at]) != v:
                cells[at] = _exact(float(v))
        fixed.append(b",".join(cells))
    return fixed


def format_exact(x) -> list[bytes]:
    """Exact text of each float (see the module docstring), as a list of ``bytes``."""
    return format_rows([x])


# --------------------------------------------------------------------------- files


def text_facts(data: bytes) -> tuple[bytes, dict]:
    """The text of a file's bytes without its final line ends (``\\r\\n`` read as ``\\n``), and facts
    about it found with fast byte searches: ``comment`` (a ``#``), ``quote`` (a ``"``), ``blank`` (an
    empty line), ``trailing`` (blanks at a line end), ``lines`` (the number of lines), ``newlines`` (their
    positions)."""
    if b"\r" in data[:65536]:
        data = data.replace(b"\r\n", b"\n")
    body = data.rstrip(b"\n")
    arr = np.frombuffer(body, dtype=np.uint8)
    nl = np.flatnonzero(arr == 10)
    before = arr[nl[nl > 0] - 1]
    facts = {
        "comment": b"#" in body, "quote": b'"' in body,
        "blank": not body or body[:1] == b"\n" or bool((np.diff(nl) == 1).any()),
        "trailing": bool(np.isin(before, (9, 13, 32)).any()) or body[-1:] in (b" ", b"\t", b"\r"),
        "lines": nl.size + 1 if body else 0, "newlines": nl,
    }
    return body, facts


def write_table(path, header: str, columns, lines=None, lead: bytes = b"", threads: int | None = None) -> None:
    """Write ``header`` then one line per row: the columns' exact texts (see :func:`format_rows`) joined by
    commas, after the row's line of an input text and ``lead`` when ``lines`` is given.

    ``lines`` is ``(text, nl, ends)``: row ``i``'s line is ``text[nl[i] + 1:ends[i]]``, after the newline
    at ``nl[i]`` (copied verbatim; no line may hold the filler byte 0x01). Blocks of rows are formatted on the shared thread pool while the
    previous ones are written. Written through a unique temporary file
    (:func:`tirecli.io.atomic.atomic_write`), so a failure leaves nothing."""
    from tirecli.io.atomic import atomic_write

    cols = [np.ascontiguousarray(c, dtype=float).ravel() for c in columns]
    prefix = None if lines is None else _Prefix(*lines, lead=lead)
    with atomic_write(path, "wb") as fh:
        fh.write(header.encode())
        for text in _blocks(cols, threads, prefix):  # each row starts with its newline
            fh.write(text)
        fh.write(b"\n")


# --------------------------------------------------------------------------- repr-identical text


_WR = 24  # widest repr of a double: '-0.00012345678901234567' (23) or '-1.2345678901234567e-308' (24)
_MARGIN = 0.02  # decisions closer than this (in units of the 17th digit) to a boundary are redone with repr
_TZ4 = np.array([4] + [len(f"{c:04d}") - len(f"{c:04d}".rstrip("0")) for c in range(1, 10000)],
                dtype=np.int8)  # trailing zeros of the 4-digit group c


def _repr_digits(a):
    """``(D, e, unsure)`` for finite ``a > 0``: ``D`` the 17-digit integer of the shortest digits of
    ``repr(a)`` padded with zeros, ``e`` the decimal exponent of the first digit; ``unsure`` marks the
    values where a rounding decision came within the error of the extended-precision arithmetic
    (their text is taken from ``repr`` instead)."""
    e, y, d, D = _scaled17(a)
    frac = (y - d).astype(np.float64)
    unsure = (D < np.uint64(10 ** 16)) | (D >= np.uint64(10 ** 17))
    with np.errstate(over="ignore", invalid="ignore"):
        scale = _P10D[_P10_OFF + 16 - e]
        g_up = np.spacing(a) * scale * 0.5
        g_dn = np.spacing(np.nextafter(a, 0.0)) * scale * 0.5
    unsure |= ~(np.isfinite(g_up) & np.isfinite(g_dn))
    best = D
    g_max = np.maximum(g_up, g_dn)
    low = (D % np.uint64(10 ** 4)).astype(np.int64)  # the last four digits
    left = None  # the values without a shorter candidate yet (None: all)
    for step in (100, 10):  # 15, then 16 significant digits; the nearest candidate of each length
        rem = low % step
        r = rem + frac  # y above the candidate below, in units
        up = r > step / 2
        diff = np.where(up, step - r, -r)  # candidate - y
        dist = np.abs(diff)
        gap = np.where(diff >= 0, g_up, g_dn)
        ok = dist < gap
        doubt = ((np.abs(r - step / 2) < _MARGIN) & (g_max > step / 2 - _MARGIN)) | (np.abs(dist - gap) < _MARGIN)
        if left is not None:  # which is nearer? inside the interval?
            ok &= left
            doubt &= left
        unsure |= doubt
        best = np.where(ok, D - rem.astype(np.uint64) + up * np.uint64(step), best)
        left = ~ok if left is None else left & ~ok
    unsure |= left & (np.abs(frac) > 0.5 - _MARGIN)  # 17 digits, rounded near a half
    top = best >= np.uint64(10 ** 17)
    if top.any():
        best = np.where(top, np.uint64(10 ** 16), best)
        e = e + top
    return best, e, unsure


def _layouts() -> np.ndarray:
    """Gather table of :func:`repr_matrix`: row ``class`` gives, for each of the 24 text bytes, the
    column of the source row (:func:`_source`)."""
    ZERO, POINT, E, MINUS, NUL, X0, XS = 17, 18, 19, 20, 22, 23, 26
    table = np.full((2, _NCLASS, _WR), NUL, dtype=np.intp)
    for neg in (0, 1):
        for cls in range(_NCLASS):
            text = [MINUS] if neg else []
            if cls < _NFIXED:
                e, k = cls // 17 - 4, cls % 17 + 1
                if e >= 0:
                    text += list(range(e + 1)) + [POINT] + list(range(e + 1, max(k, e + 2)))
                else:
                    text += [ZERO, POINT] + [ZERO] * (-e - 1) + list(range(k))
            else:
                k, three = (cls - _NFIXED) // 2 + 1, (cls - _NFIXED) % 2
                text += [0] + ([POINT] + list(range(1, k)) if k > 1 else []) + [E, XS]
                text += [X0, X0 + 1, X0 + 2] if three else [X0 + 1, X0 + 2]
            # digit i (0-16) is in source column 16 (the first) or i - 1 (the others: four aligned words)
            table[neg, cls, :len(text)] = [c if c >= 17 else 16 if c == 0 else c - 1 for c in text]
    return table.reshape(2 * _NCLASS, _WR)


_NFIXED = 20 * 17  # fixed notation: decimal exponent -4..15 x 1..17 digits
_NCLASS = _NFIXED + 17 * 2  # and scientific: 1..17 digits x 2 or 3 exponent digits
_LAYOUT = _layouts()
_W4 = np.array([int.from_bytes(bytes([48 + d]) + b"0.e", "little") for d in range(10)], dtype=np.uint32)
_W5 = np.array([int.from_bytes(b"-+\0" + f"{k:03d}"[:1].encode(), "little") for k in range(1000)], dtype=np.uint32)
_W6 = np.array([int.from_bytes(f"{k:03d}"[1:].encode() + sign + b"\0", "little") for sign in (b"+", b"-")
                for k in range(1000)], dtype=np.uint32)


def _source(D, e) -> np.ndarray:
    """The source rows of :func:`_gather` for the 17-digit integers ``D`` and decimal exponents ``e``
    (``|e| < 1000``), and the number of significant digits of each: ``(src, k)``. A row is 28 bytes,
    written as seven little-endian 32-bit words: the digits 2 to 17 (four words), the first digit,
    ``0 . e - + NUL``, the three digits of ``|e|``, the exponent's sign, a spare byte."""
    n = D.size
    src = np.empty((n, 7), dtype="<u4")
    hi = (D // np.uint64(10 ** 8)).astype(np.uint32)  # the first 9 digits (32-bit arithmetic from here)
    lo = (D - hi.astype(np.uint64) * np.uint64(10 ** 8)).astype(np.uint32)
    d0 = hi // np.uint32(10 ** 8)
    hi = hi - d0 * np.uint32(10 ** 8)
    groups = (hi // np.uint32(10 ** 4), hi % np.uint32(10 ** 4), lo // np.uint32(10 ** 4), lo % np.uint32(10 ** 4))
    for j, c in enumerate(groups):
        src[:, j] = _DIGITS4[c]
    src[:, 4] = _W4[d0]
    ae = np.minimum(np.abs(e), 999)
    src[:, 5] = _W5[ae]
    src[:, 6] = _W6[ae + 1000 * (e < 0)]
    tz = np.zeros(n, dtype=np.intp)  # trailing zeros of the digits 2-17
    later_zero = np.ones(n, dtype=bool)
    for c in groups[::-1]:
        tz += _TZ4[c] * later_zero
        later_zero &= c == 0
    return src.view(np.uint8), 17 - tz


def _gather(src, cls) -> np.ndarray:
    """``m[i] = src[i, _LAYOUT[cls[i]]]``, class by class (a real column has a few dozen classes)."""
    order = np.argsort(cls, kind="stable")  # a radix sort of 16-bit keys
    sorted_cls = cls[order]
    cuts = np.flatnonzero(sorted_cls[1:] != sorted_cls[:-1]) + 1
    s = src[order]
    m = np.empty((cls.size, _WR), dtype=np.uint8)
    out = np.empty_like(m)
    for lo, hi in zip(np.concatenate([[0], cuts]), np.concatenate([cuts, [cls.size]])):
        out[lo:hi] = s[lo:hi][:, _LAYOUT[sorted_cls[lo]]]
    m[order] = out
    return m


def repr_matrix(x) -> np.ndarray:
    """The text of ``repr(float(v))`` of every value of ``x`` as rows of a ``(n, 24)`` byte matrix,
    zero bytes after the text (NaN: an empty text). Byte for byte the text of ``repr`` (fixed
    notation for decimal exponents -4 to 15, else ``d.ddde+XX``), vectorized: the digits of
    :func:`_repr_digits`, gathered into place by a table of the 2 x 374 layouts (sign, notation,
    exponent, number of digits); the few values near a rounding boundary and the infinities are
    formatted with ``repr``. Where ``long double`` is no wider than ``double`` (its error would be
    units of the 17th digit: wrong digits), every text is taken from ``repr``."""
    x = np.ascontiguousarray(x, dtype=float).ravel()
    n = x.size
    if n == 0:
        return np.zeros((0, _WR), dtype=np.uint8)
    if not _EXTENDED:
        m = np.zeros((n, _WR), dtype=np.uint8)
        some = np.flatnonzero(~np.isnan(x))
        texts = np.array([repr(v).encode() for v in x[some].tolist()], dtype=f"S{_WR}")
        m[some] = texts.view(np.uint8).reshape(some.size, _WR)
        return m
    a = np.abs(x)
    regular = np.isfinite(x) & (a != 0)
    D, e, unsure = _repr_digits(np.where(regular, a, 1.0))
    src, k = _source(D, e)
    ae = np.abs(e)
    fixed = (e >= -4) & (e < 16)
    cls = np.where(fixed, (e + 4) * 17 + (k - 1), _NFIXED + (k - 1) * 2 + (ae >= 100))
    cls = np.where(fixed | (ae < 1000), cls, 0) + _NCLASS * np.signbit(x)
    m = _gather(src, cls.astype(np.int16))
    zero = np.flatnonzero(a == 0)
    if zero.size:
        m[zero] = 0
        m[zero, :4] = np.where(np.signbit(x[zero])[:, None], np.frombuffer(b"-0.0", dtype=np.uint8),
                               np.frombuffer(b"0.0\0", dtype=np.uint8))
    m[np.isnan(x)] = 0
    slow = np.flatnonzero((unsure & regular) | np.isinf(x))
    if slow.size:
        texts = np.array([repr(v).encode() for v in x[slow].tolist()], dtype=f"S{_WR}")
        m[slow] = texts.view(np.uint8).reshape(slow.size, _WR)
    return m


#: Runs of a float column (:func:`_runs`) at most formatted one by one with ``repr`` (below, cheaper than
#: the vectorized :func:`repr_matrix`).
_FEW_RUNS = 64


class _ZeroByte(Exception):
    """A text holds a zero byte (the padding of the byte matrices): format the chunk with ``cells``."""


def _column_matrix(values, cells) -> np.ndarray:
    """The CSV text of one column as an ``(n, width)`` byte matrix, zero bytes after each text.

    Floats: :func:`repr_matrix` (each run of equal values formatted once: :func:`_runs`; a few runs by
    ``cells``); integers, booleans: ``cells(values)`` (the slow, exact text); other values (text,
    categoricals) formatted once per distinct value.
    """
    codes = None
    if values.dtype.kind == "f":
        x = np.asarray(values, dtype=float)
        runs = _runs(x)
        if runs is not None and runs[0].size <= _FEW_RUNS:  # a few values: formatted by cells (repr)
            texts = cells(x[runs[0]])
            codes = runs[1]
        else:
            m = repr_matrix(x if runs is None else x[runs[0]])
            used = np.flatnonzero(m.any(axis=0))  # the texts are left-aligned: drop the all-padding tail
            m = m[:, :int(used[-1]) + 1 if used.size else 0]
            return m if runs is None else m[runs[1]]
    elif values.dtype.kind in "iub":
        texts = cells(values)
    elif getattr(values.dtype, "name", "") == "category":  # a pandas Categorical: its codes index its categories
        codes = values.codes
        texts = cells(np.asarray(values.categories, dtype=object)) + [""]  # code -1 (missing): an empty cell
    else:
        import pandas as pd

        if isinstance(values, np.ndarray):
            values = np.asarray(values, dtype=object)
        codes, uniq = pd.factorize(values, use_na_sentinel=True)
        texts = cells(np.asarray(uniq, dtype=object)) + [""]  # code -1 (None, NaN): an empty cell
    enc = [t.encode() for t in texts]
    if any(b"\0" in t for t in enc):
        raise _ZeroByte
    width = max(max(map(len, enc), default=0), 1)
    mat = np.array(enc, dtype=f"S{width}").view(np.uint8).reshape(len(enc), width)
    return mat if codes is None else mat[codes]


def _csv_block(columns, lo: int, hi: int, cells) -> np.ndarray:
    """Rows ``lo:hi`` of ``columns`` as CSV text (the bytes of a uint8 array), each row ending with a newline."""
    n = hi - lo
    parts = []
    for j, col in enumerate(columns):
        if j:
            parts.append(np.broadcast_to(np.uint8(44), (n, 1)))  # ','
        parts.append(_column_matrix(col[lo:hi], cells))
    parts.append(np.broadcast_to(np.uint8(10), (n, 1)))  # '\n'
    m = np.concatenate(parts, axis=1).ravel()
    return m[m != 0]  # without the padding


def csv_chunks(columns, n: int, rows: int, cells):
    """The CSV text of ``n`` rows of ``columns`` (arrays), ``rows`` rows at a time (in order, each a
    ``bytes`` or a uint8 array), formatted on the shared thread pool
    (:func:`tirecli.parallel.ordered_map`); ``cells(values)`` gives the exact texts of an array
    of integers or objects (quoting them as needed). A text holding a zero byte cannot be laid out in
    a byte matrix and is formatted by ``cells`` alone."""
    from tirecli.parallel import ordered_map

    def block(lo):
        hi = min(lo + rows, n)
        try:
            return _csv_block(columns, lo, hi, cells)
        except _ZeroByte:
            cols = [cells(np.asarray(c[lo:hi], dtype=None if c.dtype.kind in "fiub" else object)) for c in columns]
            return "".join(",".join(r) + "\n" for r in zip(*cols)).encode()

    return ordered_map(block, range(0, n, rows))


def field_counts(body: bytes):
    """``(counts, lines)`` of a CSV text without quotes: the fields of each non-blank line (commas + 1)
    and the line's index among all lines (blank lines, of ASCII blanks only, are skipped), found
    with numpy byte searches instead of a CSV parser (identical counts when no cell is quoted)."""
    arr = np.frombuffer(body, dtype=np.uint8)
    ends = np.flatnonzero(arr == 10)
    starts = np.concatenate([[0], ends + 1])
    ends = np.concatenate([ends, [arr.size]])

    def per_line(positions):  # how many of the sorted byte positions fall in each line
        return np.searchsorted(positions, ends) - np.searchsorted(positions, starts)

    counts = per_line(np.flatnonzero(arr == 44)) + 1
    blank = ends == starts
    if any(c in body for c in (b" ", b"\t", b"\r", b"\x0b", b"\x0c")):  # lines of blanks only are blank too
        blank = per_line(np.flatnonzero((arr == 32) | ((arr >= 9) & (arr <= 13)))) == ends - starts
    keep = np.flatnonzero(~blank)
    return counts[keep], keep
