"""Output safety: every file tirecli writes appears complete or not at all, and an output
directory never mixes two runs.

* :func:`atomic_write` writes one file through a unique temporary file in the target's directory
  (``.NAME.tirecli-tmp-XXXXXXXX``), then ``os.replace``: a reader sees the old file or the new one,
  never a part, and two writers never share a temporary file.
* :func:`staged_dir` runs a study into a fresh temporary directory beside ``DIR``
  (``.DIR.tirecli-tmp-XXXXXXXX``) and moves its files into ``DIR`` at the end (a new ``DIR``: one
  rename). The commit marker (``run.json``; ``summary.json`` for the report) is the record of a
  complete run: the earlier run's marker is removed first, the new files are moved in, the files
  the earlier run listed in its marker and this run does not write are removed, and the new marker
  comes last. So ``DIR`` holds one run's outputs, never two; a file this run read (its config, a
  parameter set, a data file: :func:`tirecli.io.files.inputs_read`) is never removed or
  overwritten (a run that would overwrite one is refused before anything moves), and files no
  tirecli run listed are never touched.
* A commit is journaled: before the first file moves, ``.DIR.tirecli-commit`` (beside the lock) records
  what the commit will do (the staging directory, the markers and files of the earlier run it removes).
  A run killed in the middle of its commit (SIGKILL, a power cut) leaves a folder without a marker and
  the rest of its files staged; the next run into ``DIR`` completes that commit first (every step of it
  can be done again), says so on stderr (``note: --out DIR: a run (pid N, ...) was killed while moving
  its results into place; its move was completed ...``) and goes on from there. So after a kill at any
  instant ``DIR`` holds the previous complete run, the new complete run, or a state the next run
  completes.
* :func:`staged_file` does the same for a single output file (``mf eval``, ``tir convert``).
* Both hold a lock file ``.NAME.tirecli-lock`` beside the target for the whole run: a second run
  into the same target is refused naming the process that holds it. The lock is an advisory
  ``flock`` on that file, which the kernel releases when its process ends, so a lock file left by
  a killed run is stale and taken over; the file holds the holder's pid, host, start time and
  command (one JSON line).
* Ctrl-C (or SIGTERM) or a failure leaves the target byte-identical: the staging is removed,
  Ctrl-C becomes :class:`~tirecli.errors.Interrupted` (exit 130, ``interrupted: previous results
  in DIR kept``), a run failure carries the note that the previous results were kept. Ctrl-C is
  held back during the final renames (milliseconds), so the move into place is never cut in half.

A run killed with SIGKILL leaves its lock file (stale: the next run takes it over and removes it at its
end), its staging directory and the temporary files it was writing (named ``.NAME.tirecli-tmp-PID-XXXXXXXX``,
PID the process that made them): the next run into the same target removes them when that process is dead
(:func:`clean_temps`), the report's study cache when it next writes its timings.

When the target's parent directory is not writable (``--out .`` below a read-only directory) or
``DIR`` is a mount point, the lock and the staging directory live inside ``DIR`` instead
(``DIR/.tirecli-lock``, ``DIR/.tirecli-tmp-XXXXXXXX``); a file whose place inside ``DIR`` is on
another file system is copied there through a temporary file.
"""
from __future__ import annotations

import contextlib
import errno
import functools
import json
import logging
import os
import re
import shutil
import signal
import socket
import sys
import tempfile
import threading
import time
from pathlib import Path

from tirecli.errors import Interrupted, UsageError
from tirecli.io.files import inputs_read, read_own_file

LOCK = "tirecli-lock"
TMP = "tirecli-tmp-"
#: The journal of a commit in progress (``.DIR.tirecli-commit`` beside the lock): what a run killed while moving
#: its files into place left to do, so that the next run completes it.
JOURNAL = "tirecli-commit"
#: Commit markers: the JSON record a run writes last, listing its outputs (``outputs``).
MARKERS = ("run.json", "summary.json")

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None


def out_path(out) -> Path:
    """``--out`` as a path; UsageError for an empty value (``Path('')`` would mean the current directory)."""
    if out is None or not str(out).strip():
        raise UsageError("--out '': empty; give the path to write to")
    return Path(out)


@functools.lru_cache(maxsize=1)
def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _mode(base: int) -> int:
    """``base`` (0o666 for a file, 0o777 for a directory) under the process umask, as ``open`` and
    ``mkdir`` would give (``mkstemp`` and ``mkdtemp`` create 0600 and 0700)."""
    return base & ~_umask()


def _prefix(name: str) -> str:
    return f".{name[:50]}."  # the name's head: the temporary names stay within NAME_MAX


def temp_prefix(head: str) -> str:
    """The prefix of a temporary name tirecli makes (``mkstemp``/``mkdtemp`` add 8 random characters):
    ``HEAD`` + ``tirecli-tmp-`` + this process's id, so that a leftover of a killed run is known for
    one, and known to be dead (:func:`clean_temps`)."""
    return f"{head}{TMP}{os.getpid()}-"


#: A temporary name of tirecli's (:func:`temp_prefix`): ``.NAME.tirecli-tmp-PID-XXXXXXXX`` (or, inside an output
#: directory, ``.tirecli-tmp-PID-XXXXXXXX``).
_TEMP = re.compile(r"\.(?:.*\.)?" + re.escape(TMP) + r"(\d+)-[a-z0-9_]{8}")


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this host (another user's process counts as running)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0
    return True


#: How far :func:`clean_temps` looks below a directory: levels, and entries in all (an ``--out`` given as a
#: large folder is not walked through; tirecli writes its outputs at most a few levels deep).
CLEAN_DEPTH, CLEAN_ENTRIES = 4, 20_000


def clean_temps(directory, recursive: bool = False, older_than: float = 0.0) -> list[str]:
    """Remove the temporary files and directories tirecli left in ``directory`` (and below it, ``recursive``:
    :data:`CLEAN_DEPTH` levels, :data:`CLEAN_ENTRIES` entries at most) when killed: only names of
    :func:`temp_prefix`'s form whose process is dead (and, with ``older_than``, older than that many seconds).
    Nothing else is touched, links are not followed. Returns what was removed."""
    removed = []
    stack, seen = [(Path(directory), 0)], 0
    while stack and seen < CLEAN_ENTRIES:
        d, depth = stack.pop()
        try:
            entries = list(os.scandir(d))
        except OSError:
            continue
        seen += len(entries)
        for entry in entries:
            m = _TEMP.fullmatch(entry.name)
            if m is not None and not _alive(int(m.group(1))):
                try:
                    if older_than and time.time() - entry.stat(follow_symlinks=False).st_mtime < older_than:
                        continue
                except OSError:
                    continue
                _remove(Path(entry.path))
                removed.append(entry.path)
            elif recursive and depth < CLEAN_DEPTH and entry.is_dir(follow_symlinks=False):
                stack.append((Path(entry.path), depth + 1))
    return removed


@contextlib.contextmanager
def atomic_write(path, mode: str = "w", encoding: str = "utf-8", errors: str | None = None, newline: str | None = None):
    """Open a unique temporary file beside ``path`` for writing (text, or bytes with ``mode='wb'``);
    when the block ends it replaces ``path`` (``os.replace``). On an error or Ctrl-C it is removed
    and ``path`` is untouched."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=temp_prefix(_prefix(path.name)), dir=path.parent)
    try:
        if "b" in mode:
            fh = os.fdopen(fd, "wb")
        else:
            fh = os.fdopen(fd, "w", encoding=encoding, errors=errors, newline=newline)
        with fh:
            yield fh
        os.chmod(tmp, _mode(0o666))
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def _stops_deferred():
    """Hold Ctrl-C (and SIGTERM, when the CLI turned it into an interrupt) back for the block: files
    being moved into place, staging being removed. One that came meanwhile is raised when the block ends."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    held = [sig for sig, handler in old.items() if callable(handler)]
    caught = []
    for sig in held:
        signal.signal(sig, lambda *args: caught.append(args))
    try:
        yield
    finally:
        for sig in held:
            signal.signal(sig, old[sig])
    if caught:
        old[caught[0][0]](*caught[0])


def _remove(path: Path) -> None:
    """Remove a file or directory tree, quietly (a leftover is cleaned up by the next run)."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        with contextlib.suppress(OSError):
            path.unlink()


# --------------------------------------------------------------------------- the lock


def _try_lock(fd: int) -> bool:
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        else:  # pragma: no cover - Windows: lock the first byte
            import msvcrt

            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    except OSError:
        return False
    return True


def _holder(fd: int) -> str:
    """Who holds a lock: ``pid N on HOST, started TIME: COMMAND`` from its lock file."""
    for _ in range(20):  # the holder writes its record just after taking the lock
        try:
            os.lseek(fd, 0, os.SEEK_SET)
            info = json.loads(os.read(fd, 4096).decode("utf-8"))
            started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(float(info["started"])))
            command = str(info.get("command", ""))
            command = command if len(command) <= 80 else command[:77] + "..."
            return f"pid {int(info['pid'])} on {info.get('host', '?')}, started {started}: {command}"
        except (OSError, ValueError, KeyError, TypeError):
            time.sleep(0.05)
    return "a process whose lock record cannot be read"


class _Lock:
    """An exclusive, non-blocking lock on ``path`` for the output ``target``; UsageError when a live
    process holds it. The lock file is removed on release."""

    def __init__(self, path: Path, target: Path):
        self.path, self.target, self.fd = path, target, -1

    def __enter__(self) -> _Lock:
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise UsageError(f"--out {self.target}: cannot create the lock file {self.path} "
                                 f"({exc.strerror})") from None
            if not _try_lock(fd):
                who = _holder(fd)
                os.close(fd)
                raise UsageError(f"--out {self.target}: in use by another tirecli run ({who}); "
                                 "wait for it to finish or choose another --out")
            try:  # the holder before us may have removed the file after we opened it: lock the new one
                same = os.path.samestat(os.fstat(fd), os.stat(self.path))
            except OSError:
                same = False
            if same:
                break
            os.close(fd)
        else:  # pragma: no cover - another process keeps replacing the lock file
            raise UsageError(f"--out {self.target}: cannot take the lock {self.path}")
        record = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time(),
                  "command": "tirecli " + " ".join(sys.argv[1:])}
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, (json.dumps(record) + "\n").encode("utf-8"))
        self.fd = fd
        return self

    def __exit__(self, *exc) -> None:
        with contextlib.suppress(OSError):
            os.unlink(self.path)
        os.close(self.fd)


# --------------------------------------------------------------------------- where to stage


def _home(target: Path, real: Path, is_dir: bool) -> tuple[Path, str]:
    """Directory for the lock and the staging, and the prefix of their names: beside the target,
    or inside the target directory when its parent is not writable or on another file system
    (a mount point: renames do not cross file systems)."""
    if real.exists() and is_dir and not real.is_dir():
        raise UsageError(f"--out {target}: exists and is not a directory")
    if real.is_dir() and not is_dir:
        raise UsageError(f"--out {target}: is a directory")
    if real.exists() and not is_dir and not real.is_file():  # a device or FIFO: never replaced by a file
        raise UsageError(f"--out {target}: not a regular file")
    if real.exists() and not os.access(real, os.W_OK | (os.X_OK if is_dir else 0)):
        raise UsageError(f"--out {target}: not writable")
    beside = os.access(real.parent, os.W_OK | os.X_OK)
    if is_dir and real.is_dir() and (not beside or os.stat(real).st_dev != os.stat(real.parent).st_dev):
        return real, "."
    if beside:
        return real.parent, _prefix(real.name or "root")
    raise UsageError(f"--out {target}: cannot write in {target.parent} (permission denied)")


def _missing_parents(real: Path) -> list[Path]:
    """The ancestors of ``real`` that do not exist yet, deepest last."""
    missing = []
    for up in real.parents:
        if up.exists():
            break
        missing.insert(0, up)
    return missing


def _clean_leftovers(home: Path, prefix: str) -> None:
    """Remove the staging (and the commit journal's temporary file) left by a run that was killed (called under
    the lock: no live run owns one; only names exactly as :func:`temp_prefix` and ``mkdtemp``/``mkstemp`` make
    them, of an earlier tirecli too, without the process id)."""
    heads = (prefix, _prefix(prefix + JOURNAL))
    own = re.compile("(?:" + "|".join(re.escape(h + TMP) for h in heads) + r")(?:\d+-)?[a-z0-9_]{8}")
    for name in os.listdir(home):
        if own.fullmatch(name):
            _remove(home / name)


def _has_content(real: Path) -> bool:
    """Whether the output directory holds anything (besides a lock and staging of tirecli's own)."""
    own = ("." + LOCK, "." + TMP, "." + JOURNAL)
    return real.is_dir() and any(not name.startswith(own) for name in os.listdir(real))


@contextlib.contextmanager
def _claimed(out, is_dir: bool):
    """Check the output path ``out``, create its missing parents and hold its lock: yields
    ``(target, real path, home, prefix)`` (see :func:`_home`). Parents created for a run that
    committed nothing are removed again."""
    target = out_path(out)
    real = Path(os.path.realpath(target))
    try:
        created = _missing_parents(real)
        real.parent.mkdir(parents=True, exist_ok=True)
        home, prefix = _home(target, real, is_dir)
    except OSError as exc:  # a path component too long, a file where a directory should be, ...
        raise UsageError(f"--out {target}: cannot create it ({exc.strerror or exc})") from None
    try:
        with _Lock(home / (prefix + LOCK), target):
            _recover(home, prefix, real, target)
            _clean_leftovers(home, prefix)
            if is_dir and real.is_dir():  # files a killed run was writing into the folder (a campaign's, a copy)
                clean_temps(real, recursive=True)
            yield target, real, home, prefix
    finally:
        if not real.exists():
            for up in reversed(created):
                with contextlib.suppress(OSError):
                    up.rmdir()


@contextlib.contextmanager
def _guarded(target: Path, kept: str | None, cleanup):
    """Failure handling of a staged run: ``cleanup`` removes the staging; Ctrl-C becomes
    :class:`Interrupted` saying what was kept; an OSError on the way to the target a UsageError
    naming it; any other failure carries ``kept`` as ``tirecli_note`` (printed by the CLI).

    The block sets ``state['committed']`` once its files are in place.
    """
    state = {"committed": False}
    try:
        yield state
    except KeyboardInterrupt:
        with _stops_deferred():
            cleanup()
        if state["committed"]:
            raise Interrupted(f"interrupted after the run had finished: {target} written") from None
        raise Interrupted(f"interrupted: {kept or f'nothing written to {target}'}") from None
    except BaseException as exc:
        with _stops_deferred():
            cleanup()
        if isinstance(exc, OSError) and exc.filename is not None and not isinstance(exc, UsageError):
            raise UsageError(f"--out {target}: cannot write {exc.filename} ({exc.strerror or exc})") from None
        if kept and isinstance(exc, Exception) and not isinstance(exc, UsageError):
            with contextlib.suppress(AttributeError):
                exc.tirecli_note = kept
        raise


# --------------------------------------------------------------------------- a directory of outputs


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


class Stage:
    """A run's staging directory: write the outputs under :attr:`root`; they land in :attr:`target`.

    Attributes
    ----------
    target : Path
        The output directory as given (``--out``).
    root : Path
        Where to write now (a temporary directory).
    removed, kept : list of str
        After the commit: files of the earlier run removed, and those kept as inputs of this run.
    """

    def __init__(self, target: Path, real: Path, root: Path, marker: str, journal: Path | None = None):
        self.target, self.real, self.root, self.marker = target, real, root, marker
        self.journal = journal
        self.removed: list[str] = []
        self.kept: list[str] = []

    def final(self, path) -> Path:
        """Where a file written under :attr:`root` will be."""
        return self.target / Path(path).relative_to(self.root)

    def files(self) -> list[str]:
        """Relative paths of the files written so far."""
        return sorted(str(p.relative_to(self.root)) for p in self.root.rglob("*") if p.is_file())

    def commit(self) -> None:
        """Move the staged files into the target: the earlier run's marker is removed first, then the
        new files move in, the earlier run's other outputs go, and the new marker comes last."""
        files = self.files()
        inputs = inputs_read()
        if not self.real.exists():  # a new directory: one rename puts it in place
            with contextlib.suppress(OSError):
                os.rename(self.root, self.real)
                return
            self.real.mkdir(exist_ok=True)
        self._check(files, inputs)
        listed = listed_outputs(self.real)
        self.kept = sorted(rel for rel in listed - set(files) if os.path.realpath(self.real / rel) in inputs)
        markers = [m for m in MARKERS if m in listed and m not in self.kept]
        stale = sorted(listed - set(files) - set(self.kept) - set(markers))
        for p in sorted(self.root.rglob("*")):
            if p.is_dir():
                (self.real / p.relative_to(self.root)).mkdir(parents=True, exist_ok=True)
        marker = self.marker if self.marker in files else None
        if self.journal is not None:  # from here on, a run killed leaves what remains to do to the next run
            _write_journal(self.journal, self.root, marker, markers, stale)
        self.removed = _roll_forward(self.root, self.real, marker, markers, stale, files)
        if self.journal is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.journal)

    def _check(self, files: list[str], inputs: frozenset) -> None:
        """Refuse, before anything moves, a commit that would overwrite an input of this run or a
        directory, or needs a directory where a file is."""
        keep_inputs(self.target, files, inputs=inputs)
        for rel in files:
            dst = self.real / rel
            for up in reversed(Path(rel).parents[:-1]):
                if (self.real / up).exists() and not (self.real / up).is_dir():
                    raise UsageError(f"--out {self.target}: {self.target / up} is not a directory")
            if dst.is_dir() and not dst.is_symlink():
                raise UsageError(f"--out {self.target}: {self.target / rel} is a directory")


def keep_inputs(out, files=(), dirs=(), inputs: frozenset | None = None) -> None:
    """Refuse (UsageError, before anything is written) a run whose outputs in ``out`` would overwrite one of its
    inputs (:func:`tirecli.io.files.inputs_read`, or ``inputs``): a file of ``files`` (relative to ``out``)
    that is an input, or an input inside one of the folders ``dirs`` the run writes and prunes."""
    inputs = inputs_read() if inputs is None else inputs
    target = Path(out)
    real = Path(os.path.realpath(target))
    for rel in files:
        if os.path.realpath(real / rel) in inputs:
            raise UsageError(f"--out {target}: the run would overwrite its input {target / rel}; choose another --out")
    for rel in dirs:
        top = os.path.realpath(real / rel)
        for path in sorted(inputs):
            if os.path.commonpath([path, top]) == top:
                shown = target / rel / os.path.relpath(path, top)
                raise UsageError(f"--out {target}: the run would overwrite its input {shown} (it writes {target / rel}); "
                                 "choose another --out")


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


@contextlib.contextmanager
def staged_dir(out, marker: str = "run.json"):
    """Run into the output directory ``out`` safely: yields a :class:`Stage` to write into; on
    success its files are moved into ``out`` (``marker`` last), on an error or Ctrl-C ``out`` is
    left byte-identical (see the module docstring)."""
    with _claimed(out, is_dir=True) as (target, real, home, prefix):
        kept = f"previous results in {target} kept" if _has_content(real) else None
        root = Path(tempfile.mkdtemp(prefix=temp_prefix(prefix), dir=home))
        os.chmod(root, _mode(0o777))
        stage = Stage(target, real, root, marker, journal=home / (prefix + JOURNAL))
        with _guarded(target, kept, lambda: _remove(root)) as state:
            yield stage
            with _stops_deferred():
                stage.commit()
                state["committed"] = True
                _remove(root)


@contextlib.contextmanager
def staged_file(out):
    """Write the single output file ``out`` safely: yields a temporary path (in ``out``'s
    directory) to write; on success it replaces ``out``, on an error or Ctrl-C ``out`` is left as
    it was. The run holds the lock of ``out`` throughout; an input of the run is never overwritten."""
    with _claimed(out, is_dir=False) as (target, real, home, prefix):
        kept = f"previous {target} kept" if real.exists() else None
        fd, tmp = tempfile.mkstemp(prefix=temp_prefix(prefix), dir=home)
        os.close(fd)
        tmp = Path(tmp)
        with _guarded(target, kept, lambda: _remove(tmp)) as state:
            yield tmp
            if str(real) in inputs_read():
                raise UsageError(f"--out {target}: the run would overwrite its input {target}; choose another --out")
            with _stops_deferred():
                os.chmod(tmp, _mode(0o666))
                os.replace(tmp, real)
                state["committed"] = True


@contextlib.contextmanager
def locked_dir(out):
    """Hold the lock of the output directory ``out`` (created when missing, and removed again when
    the block fails and nothing was written in it) for the block; yields
    ``(target, real path)``. For outputs written as they come (a campaign's finished points, each
    file through :func:`atomic_write`) rather than staged as one run: an interruption keeps what
    was written. A second run into ``out`` is refused naming the holder."""
    with _claimed(out, is_dir=True) as (target, real, home, prefix):
        created = not real.exists()
        try:
            real.mkdir(exist_ok=True)
        except OSError as exc:
            raise UsageError(f"--out {target}: cannot create it ({exc.strerror or exc})") from None
        try:
            yield target, real
        except BaseException:
            if created:  # a run that failed before writing anything leaves no empty folder behind
                with contextlib.suppress(OSError):
                    real.rmdir()  # only when empty: what was written is kept
            raise
