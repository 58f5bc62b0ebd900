"""The commit of a staged run (:func:`tirecli.io.staging.staged_dir`): the run records, the moves in
their order, and the journal that lets the next run complete a commit cut short.

The commit marker (``run.json``; ``summary.json`` for the report) is the record of a complete run: the
earlier run's marker is removed first, the new files are moved in, the files the earlier run listed in its
marker and this run does not write are removed, and the new marker comes last (:func:`_roll_forward`).

A commit is journaled: before the first file moves, ``.DIR.tirecli-commit`` (beside the lock) records
what the commit will do (the staging directory, the markers and files of the earlier run it removes).
A run killed in the middle of its commit (SIGKILL, a power cut) leaves a folder without a marker and
the rest of its files staged; the next run into ``DIR`` completes that commit first (every step of it
can be done again), says so on stderr (``note: --out DIR: a run (pid N, ...) was killed while moving
its results into place; its move was completed ...``) and goes on from there. So after a kill at any
instant ``DIR`` holds the previous complete run, the new complete run, or a state the next run
completes.
"""
from __future__ import annotations

import contextlib
import errno
import json
import logging
import os
import re
import shutil
import socket
import sys
import time
from pathlib import Path

from tirecli.io.atomic import TMP, atomic_write
from tirecli.io.files import read_own_file

#: The journal of a commit in progress (``.DIR.tirecli-commit`` beside the lock): what a run killed while moving
#: its files into place left to do, so that the next run completes it.
JOURNAL = "tirecli-commit"
#: Commit markers: the JSON record a run writes last, listing its outputs (``outputs``).
MARKERS = ("run.json", "summary.json")


def _inside(real: Path, rel: str) -> bool:
    """Whether ``rel`` (from a run record) names a path inside ``real`` (no ``..``, no absolute path,
    no symlink leading out)."""
    if not isinstance(rel, str) or not rel or os.path.isabs(rel) or ".." in Path(rel).parts:
        return False
    full = os.path.realpath(real / rel)
    return os.path.commonpath([full, str(real)]) == str(real)


def _record_cap() -> int:
    """Largest run record read back [bytes] (a commit marker, a campaign's summary): a data CSV's cap."""
    from tirecli.limits import csv_max_bytes

    return csv_max_bytes()


def read_record(path: Path, within: Path):
    """The JSON of a run record tirecli wrote (a commit marker, a campaign's ``summary.json``), read through
    the input gate (:func:`tirecli.io.files.read_own_file`: a regular file inside ``within``); None when it
    is absent, not a regular file or not JSON."""
    data = read_own_file(path, _record_cap(), within=within)
    try:
        return json.loads(data.decode("utf-8")) if data is not None else None
    except (ValueError, UnicodeDecodeError):
        return None


def listed_outputs(real: Path) -> set[str]:
    """The files the earlier tirecli run in ``real`` listed in its commit marker(s), with the
    markers themselves (paths relative to ``real``)."""
    listed = set()
    for marker in MARKERS:
        record = read_record(real / marker, real)
        if not isinstance(record, dict) or record.get("tool") != "tirecli":
            continue
        listed.add(marker)
        outputs = record.get("outputs")
        if isinstance(outputs, dict):  # run.json: {data: [...], figures: [...], files: [...]}
            outputs = [rel for group in ("data", "figures", "files") for rel in (outputs.get(group) or [])]
        listed.update(rel for rel in (outputs if isinstance(outputs, list) else []) if _inside(real, rel))
    return listed


def _unlink_output(real: Path, rel: str) -> bool:
    """Remove an earlier output ``rel`` of ``real`` and the directories it leaves empty; whether it was there."""
    path = real / rel
    if path.is_file() or path.is_symlink():
        path.unlink()
        _prune(path.parent, real)
        return True
    return False


def _roll_forward(root: Path, real: Path, marker: str | None, markers, stale, files=None) -> list[str]:
    """The moves of a commit, in their order: the earlier run's ``markers`` removed (from here until the new
    marker is in place, ``real`` says it is incomplete), the files staged under ``root`` moved in, the earlier
    run's ``stale`` outputs removed, the new ``marker`` last. Each step can be done again (a file moved is no
    longer staged, a file removed is gone), so a commit cut short is completed by running it again
    (:func:`_recover`). Returns the earlier outputs removed (markers the run rewrites not counted)."""
    files = sorted(str(p.relative_to(root)) for p in root.rglob("*") if p.is_file()) if files is None else files
    removed = []
    for rel in markers:
        if _unlink_output(real, rel) and rel not in files:
            removed.append(rel)
    for rel in files:
        if rel != marker and (root / rel).exists():
            (real / rel).parent.mkdir(parents=True, exist_ok=True)
            _move(root / rel, real / rel)
    for rel in stale:
        if _unlink_output(real, rel):
            removed.append(rel)
    if marker is not None:
        _move(root / marker, real / marker)
    return removed


def _write_journal(path: Path, root: Path, marker: str | None, markers, stale) -> None:
    record = {"tool": "tirecli", "staging": root.name, "marker": marker, "markers": list(markers),
              "stale": list(stale), "pid": os.getpid(), "host": socket.gethostname(), "started": time.time(),
              "command": "tirecli " + " ".join(sys.argv[1:])}
    with atomic_write(path) as fh:
        fh.write(json.dumps(record) + "\n")


#: Where tirecli reports what it found and did on its own (the commit of a killed run completed); without a
#: logging configuration the message goes to stderr as it is.
_log = logging.getLogger("tirecli")


def _recover(home: Path, prefix: str, real: Path, target: Path) -> None:
    """Complete the commit of a run killed while moving its files into ``real`` (its journal is there; called
    under the lock, so that run is dead): ``real`` then holds that run's complete results, and a note says so."""
    journal = home / (prefix + JOURNAL)
    if not os.path.lexists(journal):
        return
    record = read_record(journal, home)
    own = re.compile(re.escape(prefix + TMP) + r"(?:\d+-)?[a-z0-9_]{8}")
    staging = str(record.get("staging", "")) if isinstance(record, dict) else ""
    root = home / staging
    who = _who(record)
    marker = record.get("marker") if isinstance(record, dict) else None
    if not own.fullmatch(staging) or not root.is_dir() or not isinstance(marker, (str, type(None))):
        _log.warning(f"note: --out {target}: a run ({who}) was killed while moving its results into place, and "
                     "what it left to do is gone: the folder may hold files of two runs until this run replaces them")
    elif marker is not None and not (root / marker).exists():
        pass  # it had finished: only its journal was left
    else:
        lists = [record.get(k) if isinstance(record.get(k), list) else [] for k in ("markers", "stale")]
        markers, stale = ([rel for rel in rels if _inside(real, rel)] for rels in lists)
        _roll_forward(root, real, marker if marker is None or _inside(real, marker) else None, markers, stale)
        _log.warning(f"note: --out {target}: a run ({who}) was killed while moving its results into place; "
                     f"its move was completed, so {target} held that run's complete results")
    with contextlib.suppress(OSError):
        os.unlink(journal)


def _who(record) -> str:
    """``pid N, started TIME: COMMAND`` of a journal's run."""
    try:
        started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(float(record["started"])))
        command = str(record.get("command", ""))
        return f"pid {int(record['pid'])}, started {started}: {command if len(command) <= 80 else command[:77] + '...'}"
    except (TypeError, ValueError, KeyError, OverflowError):
        return "a run whose record cannot be read"


def _move(src: Path, dst: Path) -> None:
    """``os.replace``, or a copy through a temporary file beside ``dst`` when ``dst`` lies on
    another file system (a mount point or symlink inside the output directory)."""
    try:
        os.replace(src, dst)
    except OSError as exc:
        if exc.errno != errno.EXDEV:
            raise
        with open(src, "rb") as fin, atomic_write(dst, "wb") as fout:
            shutil.copyfileobj(fin, fout)


def _prune(directory: Path, top: Path) -> None:
    """Remove directories left empty by removing a file, up to (not including) ``top``."""
    while directory != top and top in directory.parents:
        try:
            directory.rmdir()
        except OSError:
            return
        directory = directory.parent
