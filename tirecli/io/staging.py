"""Staged outputs: a run's output directory (or file) is replaced as a whole, and holds one run's
outputs, never two.

* :func:`staged_dir` runs a study into a fresh temporary directory beside ``DIR``
  (``.DIR.tirecli-tmp-XXXXXXXX``) and moves its files into ``DIR`` at the end (a new ``DIR``: one
  rename). The commit marker (``run.json``; ``summary.json`` for the report) is the record of a
  complete run: the earlier run's marker is removed first, the new files are moved in, the files
  the earlier run listed in its marker and this run does not write are removed, and the new marker
  comes last. So ``DIR`` holds one run's outputs, never two; a file this run read (its config, a
  parameter set, a data file: :func:`tirecli.io.files.inputs_read`) is never removed or
  overwritten (a run that would overwrite one is refused before anything moves), and files no
  tirecli run listed are never touched.
* A commit is journaled (:mod:`tirecli.io.commit`): a run killed in the middle of its commit leaves
  what remains to do to the next run into ``DIR``, which completes it first and says so on stderr.
* :func:`staged_file` does the same for a single output file (``mf eval``, ``tir convert``).
* Both hold a lock file ``.NAME.tirecli-lock`` beside the target for the whole run
  (:mod:`tirecli.io.lock`): a second run into the same target is refused naming the process that holds it.
* Ctrl-C (or SIGTERM) or a failure leaves the target byte-identical: the staging is removed,
  Ctrl-C becomes :class:`~tirecli.errors.Interrupted` (exit 130, ``interrupted: previous results
  in DIR kept``), a run failure carries the note that the previous results were kept. Ctrl-C is
  held back during the final renames (milliseconds), so the move into place is never cut in half.

A run killed with SIGKILL leaves its lock file (stale: the next run takes it over and removes it at its
end), its staging directory and the temporary files it was writing (named ``.NAME.tirecli-tmp-PID-XXXXXXXX``,
PID the process that made them): the next run into the same target removes them when that process is dead
(:func:`tirecli.io.atomic.clean_temps`), the report's study cache when it next writes its timings.

When the target's parent directory is not writable (``--out .`` below a read-only directory) or
``DIR`` is a mount point, the lock and the staging directory live inside ``DIR`` instead
(``DIR/.tirecli-lock``, ``DIR/.tirecli-tmp-XXXXXXXX``); a file whose place inside ``DIR`` is on
another file system is copied there through a temporary file.
"""
from __future__ import annotations

import contextlib
import os
import re
import signal
import tempfile
import threading
from pathlib import Path

from tirecli.errors import Interrupted, UsageError
from tirecli.io.atomic import TMP, _mode, _prefix, _remove, clean_temps, temp_prefix
from tirecli.io.commit import JOURNAL, MARKERS, _recover, _roll_forward, _write_journal, listed_outputs
from tirecli.io.files import inputs_read
from tirecli.io.lock import LOCK, _Lock


def out_path(out) -> Path:
    """``--out`` as a path; UsageError for an empty value (``Path('')`` would mean the current directory)."""
    if out is None or not str(out).strip():
        raise UsageError("--out '': empty; give the path to write to")
    return Path(out)


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
