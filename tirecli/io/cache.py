"""The report's study cache: the outputs of a built-in study and of its figures, kept between reports.

``tirecli report`` keeps what each study and figure wrote (data CSVs, the study's run record, the
figure files and the card's facts: caption, parameters, check records) under a cache directory
outside the report (:func:`default_dir`: ``$TIRECLI_CACHE_DIR``, else ``$XDG_CACHE_HOME/tirecli``,
else ``~/.cache/tirecli``; ``--cache`` chooses another). A later report whose study has the same key
copies those files instead of running the study and drawing its figures again.

Only plain files are kept (CSV, JSON, PNG, SVG): nothing is unpickled or executed, so a cache
entry can at worst be wrong, never run code. An entry records the SHA-256 of each of its files and
is used only if every file is present and matches; anything unreadable or inconsistent is a miss
(the study runs again and the entry is replaced). Cached files are read through the input gate
(:func:`tirecli.io.files.read_own_file`): a FIFO, a device, a link (to ``/dev/zero`` or out of the
cache) or a file over the size cap in place of an entry's file is a miss too, never a wait or a read
without end. Entries are written as a temporary directory
renamed into place, files through :func:`tirecli.io.atomic.atomic_write`: a reader sees a whole
entry or none, also with two reports sharing one ``--cache``.

Layout::

    CACHE/v1/STUDY/KEY/manifest.json       key, the built-in data the study read (with hashes), files
    CACHE/v1/STUDY/KEY/files/...           data/NAME.csv, study.json
    CACHE/v1/STUDY/KEY/fig-ID-FKEY/        card.json and the figure's files
    CACHE/v1/timings.json                  seconds each study and its figures took (the slowest start first)

``KEY`` hashes the resolved config, the built-in configs it names, tirecli's version and source
code, and the versions of Python and the numerical libraries; the manifest adds the hash of every
built-in parameter set the study read (and each card those its figure and checks read), so a
changed parameter re-runs only the studies that read it.
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

from tirecli import limits
from tirecli.io.atomic import atomic_write, clean_temps, temp_prefix
from tirecli.io.files import read_own_file

#: Bumped when the layout or the meaning of an entry changes (older entries are then ignored).
FORMAT = 1
#: Entries kept per study (the newest; older ones are of earlier code, configs or parameters).
KEEP = 3
#: The environment variable that names the cache folder (``--cache`` takes precedence).
ENV = "TIRECLI_CACHE_DIR"
#: The cache folder that earlier versions kept inside the report's folder (the report now names one it
#: finds there, and never removes it).
OLD_NAME = ".tirecli-cache"


def default_dir() -> Path | None:
    """The study cache's folder when ``--cache`` is not given: ``$TIRECLI_CACHE_DIR``, else
    ``$XDG_CACHE_HOME/tirecli`` (an absolute path), else ``~/.cache/tirecli``; None when there is no
    home directory (the report then runs without a cache)."""
    env = os.environ.get(ENV, "").strip()
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME", "").strip()
    if xdg and os.path.isabs(xdg):
        return Path(xdg) / "tirecli"
    try:
        return Path.home() / ".cache" / "tirecli"
    except (RuntimeError, KeyError, OSError):
        return None


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over tirecli's Python source (relative path and bytes of each ``.py`` file): a change
    of any code invalidates every entry, whatever the version number says."""
    from tirecli import _version

    root = Path(_version.__file__).resolve().parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode() + b"\0")
        h.update(path.read_bytes() + b"\0")
    return h.hexdigest()


def resource_digest(res) -> str | None:
    """SHA-256 of a file or package resource (None if it cannot be read)."""
    try:
        return sha256(res.read_bytes())
    except OSError:
        return None


def key_of(parts: dict) -> str:
    """A short hex key of a JSON-able description."""
    return sha256(json.dumps(parts, sort_keys=True, default=str).encode())[:24]


def _entry_cap() -> int:
    """Largest cached file read [bytes]: a data CSV's cap at the budget in force (a larger one is a miss)."""
    return limits.csv_max_bytes()


def _read(path: Path, root: Path) -> bytes | None:
    """The bytes of a cached file through the input gate (:func:`tirecli.io.files.read_own_file`): a
    regular file inside the cache ``root`` (no link, FIFO or device, nothing leading out of the cache),
    of at most :func:`_entry_cap` bytes; None otherwise (a miss: the study runs again)."""
    return read_own_file(path, _entry_cap(), within=root)


def _read_json(path: Path, root: Path):
    data = _read(path, root)
    try:
        return None if data is None else json.loads(data.decode("utf-8"))
    except (ValueError, UnicodeDecodeError):
        return None


def _valid_files(root: Path, files, cache: Path, keep: dict | None = None) -> bool:
    """Whether ``files`` (relative path -> SHA-256) are all present under ``root`` with those hashes (read
    through the gate of the cache folder ``cache``: :func:`_read`); ``keep`` (path -> bytes) receives the
    contents checked, so that a copy needs no second read."""
    if not isinstance(files, dict):
        return False
    for rel, digest in files.items():
        if not _safe_rel(rel):
            return False
        data = _read(root / rel, cache)
        if data is None or sha256(data) != digest:
            return False
        if keep is not None:
            keep[root / rel] = data
    return True


def _deps_hold(deps, deps_now) -> bool:
    """Whether the built-in sets recorded in ``deps`` (name -> SHA-256) are unchanged (``deps_now(name)``:
    the current SHA-256 of set ``name``)."""
    return isinstance(deps, dict) and all(deps_now(name) == digest for name, digest in deps.items())


def _safe_rel(rel) -> bool:
    return isinstance(rel, str) and bool(rel) and not os.path.isabs(rel) and ".." not in Path(rel).parts


class StudyCache:
    """The cache of one study under ``root`` (``CACHE``): see the module docstring."""

    def __init__(self, root: str | Path, study: str, key: str):
        self.base = Path(root) / f"v{FORMAT}"
        self.dir = self.base / study / key
        self.study, self.key = study, key
        self._checked: dict[Path, bytes] = {}  # contents read and checked by manifest() and figure(), until copied

    # ------------------------------------------------------------------ reading

    def manifest(self, deps_now) -> dict | None:
        """The study entry's manifest when the entry is complete and the built-in data it read are
        unchanged (``deps_now(name)``: the current SHA-256 of built-in set ``name``); else None."""
        m = _read_json(self.dir / "manifest.json", self.base)
        if not isinstance(m, dict) or m.get("format") != FORMAT or m.get("key") != self.key:
            return None
        if not _deps_hold(m.get("deps"), deps_now) or not isinstance(m.get("record"), dict):
            return None
        if not _valid_files(self.dir / "files", m.get("files"), self.base, self._checked):
            return None
        return m

    def figure(self, fid: str, fkey: str, deps_now) -> dict | None:
        """The cached card of figure ``fid`` (``fkey``: formats and resolution), its files checked and
        the built-in sets read for it (``card['deps']``, as in :meth:`manifest`) unchanged; or None."""
        d = self.dir / f"fig-{fid}-{fkey}"
        card = _read_json(d / "card.json", self.base)
        if not isinstance(card, dict) or card.get("id") != fid or not _deps_hold(card.get("deps"), deps_now):
            return None
        if not _valid_files(d, card.get("hashes"), self.base, self._checked):
            return None
        return card

    def copy_study(self, manifest: dict, dest: Path) -> None:
        """Copy the study's files into the report folder ``dest`` (``data/STUDY/...``, ``studies/STUDY.json``)."""
        for rel in sorted(manifest["files"]):
            self._copy(self.dir / "files" / rel, dest / _study_target(self.study, rel))

    def copy_figure(self, card: dict, fid: str, fkey: str, dest: Path) -> None:
        """Copy the figure's files into ``dest/figures``."""
        for rel in sorted(card["hashes"]):
            self._copy(self.dir / f"fig-{fid}-{fkey}" / rel, dest / "figures" / rel)

    def _copy(self, src: Path, dst: Path) -> None:
        """Write ``src`` to ``dst``: the bytes checked by :meth:`manifest` or :meth:`figure` (read now if not checked)."""
        data = self._checked.pop(src, None)
        if data is None:
            data = _read(src, self.base)
        if data is None:  # changed since it was checked: the entry is no longer whole
            raise OSError(f"cache entry {src} changed while in use")
        dst.parent.mkdir(parents=True, exist_ok=True)
        _write(dst, data)

    # ------------------------------------------------------------------ writing

    def store_study(self, record: dict, deps: dict, src: Path, data_names: list[str]) -> None:
        """Keep the study's files (read from the report folder ``src``) with its run ``record``
        (facts the cards need) and ``deps`` (built-in set -> SHA-256), unless a valid entry with
        these deps is there (it keeps its figures). Any failure is ignored: the cache is an optimisation."""
        valid = self.manifest(lambda name: deps.get(name, "")) is not None
        self._checked.clear()
        if valid:
            return
        with contextlib.suppress(OSError):
            rels = [f"data/{n}.csv" for n in data_names] + ["study.json"]
            with self._new_dir(self.dir) as tmp:
                files = {}
                for rel in rels:
                    data = (src / _study_target(self.study, rel)).read_bytes()
                    (tmp / "files" / rel).parent.mkdir(parents=True, exist_ok=True)
                    _write(tmp / "files" / rel, data)
                    files[rel] = sha256(data)
                _write(tmp / "manifest.json", _dump({"format": FORMAT, "key": self.key, "study": self.study,
                                                     "deps": deps, "files": files, "record": record}))
            self._prune()

    def _prune(self, keep: int = KEEP) -> None:
        """Remove the oldest entries of the study beyond ``keep`` (those of earlier code or configs),
        and temporary folders of writers killed over an hour ago."""
        import time

        entries = []
        for d in self.dir.parent.iterdir():
            with contextlib.suppress(OSError):
                if d.name.startswith("."):
                    if time.time() - d.stat().st_mtime > 3600:
                        shutil.rmtree(d, ignore_errors=True)
                elif d.is_dir() and d != self.dir:
                    entries.append((d.stat().st_mtime, d))
        for _, d in sorted(entries, key=lambda e: e[0], reverse=True)[keep - 1:]:
            shutil.rmtree(d, ignore_errors=True)

    def store_figure(self, card: dict, fid: str, fkey: str, src: Path) -> None:
        """Keep a figure's card (JSON-able facts) and its files (``card['files']``, read under ``src``)."""
        if not self.dir.is_dir():
            return
        with contextlib.suppress(OSError):
            with self._new_dir(self.dir / f"fig-{fid}-{fkey}") as tmp:
                hashes = {}
                for rel in card["files"]:
                    data = (src / rel).read_bytes()
                    _write(tmp / Path(rel).name, data)
                    hashes[Path(rel).name] = sha256(data)
                _write(tmp / "card.json", _dump(dict(card, hashes=hashes)))

    @contextlib.contextmanager
    def _new_dir(self, target: Path):
        """A temporary directory beside ``target``, renamed to ``target`` (replacing an older entry)."""
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=temp_prefix(f".{target.name[:40]}."), dir=target.parent))
        try:
            yield tmp
            old = None
            if target.exists():
                old = Path(tempfile.mkdtemp(prefix=f".{target.name[:40]}.old-", dir=target.parent))
                os.rename(target, old / "entry")
            os.rename(tmp, target)
            if old is not None:
                shutil.rmtree(old, ignore_errors=True)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


def _study_target(study: str, rel: str) -> str:
    """Where a cached study file goes in the report: ``data/NAME.csv`` -> ``data/STUDY/NAME.csv``,
    ``study.json`` -> ``studies/STUDY.json``."""
    return f"studies/{study}.json" if rel == "study.json" else f"data/{study}/{rel[len('data/'):]}"


def _dump(obj) -> str:
    return json.dumps(obj, indent=1, sort_keys=True) + "\n"


def _write(path: Path, data: bytes | str) -> None:
    with atomic_write(path, "wb") as fh:
        fh.write(data.encode("utf-8") if isinstance(data, str) else data)


def read_timings(root: str | Path) -> dict:
    """Seconds each study (with its figures) took when it last ran (study -> seconds); empty when unknown
    (or ``root`` is None: no cache)."""
    if root is None:
        return {}
    data = _read_json(Path(root) / f"v{FORMAT}" / "timings.json", Path(root))
    return {k: float(v) for k, v in data.items() if isinstance(v, (int, float))} if isinstance(data, dict) else {}


def write_timings(root: str | Path, timings: dict) -> None:
    """Record the seconds of the studies that ran (merged with the earlier record); errors ignored;
    nothing without a cache (``root`` None). Temporary files and entries of reports killed while writing
    into the cache (their process dead) are removed."""
    if root is None:
        return
    clean_temps(Path(root) / f"v{FORMAT}", recursive=True)
    with contextlib.suppress(OSError):
        path = Path(root) / f"v{FORMAT}" / "timings.json"
        merged = dict(read_timings(root), **{k: round(float(v), 3) for k, v in timings.items()})
        path.parent.mkdir(parents=True, exist_ok=True)
        _write(path, _dump(merged))


def read_bytes(path: str | Path) -> bytes:
    """The bytes of a file (a figure written by this run, to embed in the page)."""
    return Path(path).read_bytes()


def memo_text(root: str | Path | None, parts: dict, make) -> str:
    """``make()`` (a text), kept under ``root`` by the key of ``parts`` (e.g. a documentation page
    rendered to HTML); a stored text is used only if its recorded SHA-256 matches. ``root`` None:
    no cache."""
    if root is None:
        return make()
    path = Path(root) / f"v{FORMAT}" / "memo" / f"{key_of(dict(parts, code=code_fingerprint()))}.txt"
    with contextlib.suppress(ValueError, UnicodeDecodeError, AttributeError):
        head, _, text = _read(path, Path(root)).decode("utf-8").partition("\n")
        if head == sha256(text.encode("utf-8")):
            return text
    text = make()
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        _write(path, sha256(text.encode("utf-8")) + "\n" + text)
    return text
