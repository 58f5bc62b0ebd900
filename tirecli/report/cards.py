"""What a report card shows besides its figure: links to its files and how wide it is drawn.

:func:`card_files` lists, for one figure, the files a reader may want (its PNG and SVG, or the CSV
of a table; the data CSVs and the run record ``studies/STUDY.json`` of its study), as report-relative
links. :func:`image_size` reads a written PNG's size and resolution from its header, so the page can
show each figure at its drawn size (a wide figure, such as the six-panel Magic Formula sweeps,
spans the card) without rendering it again.
"""
from __future__ import annotations

import struct
from pathlib import Path

#: CSS pixels per inch of figure: the page shows a figure drawn W inches wide W * 110 px wide, at most
#: the width of its column (the fonts of tirecli's figures, 8-10 pt, then read like the page's small text).
PX_PER_INCH = 110
#: Figures wider than this (inches) span the card and the text "the paper shows" goes below them: beside
#: that text (on a 1280 px screen) a wider figure would be shrunk below its drawn size.
WIDE_INCHES = 8.0


#: Colours of the PNG the page embeds (:func:`page_png`).
PAGE_COLOURS = 256


def page_png(data: bytes) -> bytes:
    """The PNG the page embeds for a figure's PNG file ``data``: the same pixels reduced to a palette of
    :data:`PAGE_COLOURS` colours (Pillow's maximum-coverage palette, no dithering; zlib level 6).
    tirecli's figures are lines, text and a few colour maps: the report's 31 figures shrink from 5.5 MB
    to 1.9 MB, no channel of any pixel moves by more than 20 of 255 (white stays white, most lines
    keep their exact colour; only anti-aliased edges move) and nothing differs to the eye; the page
    links each full-colour file. ``data`` itself when the palette image is not smaller (or Pillow
    cannot read it)."""
    import io

    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(io.BytesIO(data)) as im:
            pal = im.convert("RGB").quantize(colors=PAGE_COLOURS, method=Image.Quantize.MAXCOVERAGE,
                                             dither=Image.Dither.NONE)
            dpi = im.info.get("dpi")
        buf = io.BytesIO()
        pal.save(buf, "PNG", compress_level=6, **({"dpi": dpi} if dpi else {}))
    except (OSError, UnidentifiedImageError, ValueError):
        return data
    return buf.getvalue() if buf.tell() < len(data) else data


def page_image(data: bytes) -> str:
    """The base64 text of :func:`page_png` of a PNG file's bytes (what the page's ``<img>`` holds)."""
    import base64

    return base64.b64encode(page_png(data)).decode("ascii")


def image_size(path: str | Path) -> tuple[int, int, float] | None:
    """(width px, height px, dots per inch) of a PNG file, from its IHDR and pHYs chunks; None if
    the file is not a PNG. The resolution defaults to 150 dpi when the file does not record one."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
            if head != b"\x89PNG\r\n\x1a\n":
                return None
            width = height = None
            dpi = 150.0
            while True:
                hdr = fh.read(8)
                if len(hdr) < 8:
                    break
                length, kind = struct.unpack(">I4s", hdr)
                if kind == b"IHDR":
                    width, height = struct.unpack(">II", fh.read(8))
                    fh.seek(length - 8 + 4, 1)
                elif kind == b"pHYs":
                    ppu_x, _, unit = struct.unpack(">IIB", fh.read(9))
                    if unit == 1 and ppu_x > 0:  # pixels per metre
                        dpi = ppu_x * 0.0254
                    fh.seek(4, 1)
                elif kind in (b"IDAT", b"IEND"):
                    break
                else:
                    fh.seek(length + 4, 1)
    except OSError:
        return None
    if width is None:
        return None
    return width, height, dpi


def card_files(root: Path, files: list[str], study: str | None, data: list[str] = (), ran: bool = True) -> dict:
    """Links and display size of a card.

    Parameters
    ----------
    root : Path
        The report folder (``files`` are relative to it).
    files : list of str
        The figure's own files (``figures/ID.png``, ``.svg``, or ``figures/ID.csv`` of a table).
    study : str or None
        Its study; ``data`` the names of the study's data frames (``data/STUDY/NAME.csv``).
    ran : bool
        Whether the study ran (its run record ``studies/STUDY.json`` then exists).

    Returns
    -------
    dict
        ``links``: list of ``{"label", "href"}``; ``png``: the PNG's path or None; ``width_px`` and
        ``height_px``: the size to show it at (CSS px) or None; ``wide``: span the card.
    """
    links = []
    png = None
    for f in files:
        ext = Path(f).suffix.lstrip(".").lower()
        if ext == "png":
            png = f
        label = {"png": "PNG", "svg": "SVG", "csv": "table CSV", "pdf": "PDF"}.get(ext, ext.upper())
        links.append({"label": label, "href": f})
    if study and ran:
        for name in data:
            links.append({"label": f"{name}.csv", "href": f"data/{study}/{name}.csv"})
        links.append({"label": "run record (JSON)", "href": f"studies/{study}.json"})
    out = {"links": links, "png": png, "width_px": None, "height_px": None, "wide": False}
    size = image_size(Path(root) / png) if png else None
    if size:
        w, h, dpi = size
        inches = w / dpi
        out["width_px"] = round(inches * PX_PER_INCH)
        out["height_px"] = round(h / dpi * PX_PER_INCH)
        out["wide"] = inches > WIDE_INCHES
    return out
