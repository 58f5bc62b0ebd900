"""Matplotlib's font cache: whether it exists yet, and building it.

The first use of matplotlib on a machine scans the system's fonts and writes the list to
``fontlist-vNNN.json`` in matplotlib's cache folder (``matplotlib.get_cachedir()``); every later
use reads that file. On this project's 2-core test machine (38 fonts) the scan costs 0.25-0.6 s of
CPU, on a desktop with thousands of fonts many seconds. :func:`font_cache_missing` tells a command
that it is about to pay it (so it can say so once), :func:`build_font_cache` pays it in this process
(before worker processes fork, which then inherit the list instead of each scanning the fonts).
"""
from __future__ import annotations

from pathlib import Path


def font_cache_missing() -> bool:
    """Whether matplotlib has no font list in its cache folder yet (its first use will build it)."""
    import matplotlib

    try:
        return not any(Path(matplotlib.get_cachedir()).glob("fontlist-v*.json"))
    except OSError:
        return False


def build_font_cache() -> None:
    """Build (or read) matplotlib's font list in this process."""
    import matplotlib.font_manager  # noqa: F401 - its import scans the fonts, or reads the cached list
