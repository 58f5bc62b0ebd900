"""The one gate for input files and output locations: every problem is one line naming the path (exit 2).

Reading (:func:`read_input_bytes`, :func:`read_input_text`): only regular files are read. A
directory, a FIFO, a device (``/dev/zero``), a socket, an empty file, a missing file, a name too
long, a permission problem or a symlink loop is a :class:`~tirecli.errors.ConfigError` naming the
file; the file is stat-ed before it is opened and opened without blocking, so nothing waits on a
FIFO or reads an endless device.

Files tirecli keeps for itself (the report's study cache, run records, a campaign's stored points)
are read through the same gate (:func:`read_own_file`): anything but a regular file of sane size
inside its folder reads as absent, never blocks and is never followed out of the folder.

Every input file read is recorded (:func:`note_input`, :func:`inputs_read`): an output never
overwrites or removes one.

Writing (:func:`check_output_dir`, :func:`check_output_file`): an output location is checked
before a run starts (missing parents are created when the files are written, by
:mod:`tirecli.io.staging`): a parent that is a file, a read-only location, a target that is a
directory (``run.json`` as a directory) or a device, and names too long are
:class:`~tirecli.errors.UsageError` naming the path.
"""
from __future__ import annotations

import contextlib
import errno
import os
import stat
import tempfile
from pathlib import Path

from tirecli.errors import ConfigError, Problem, UsageError

#: Longest path text printed whole in a message; longer ones are shortened in the middle.
_SHOW_PATH = 160


_INPUTS: set[str] = set()
_TRACKERS: list[set] = []


def note_input(path: str | Path) -> None:
    """Record that ``path`` is an input of this run (every reader of :mod:`tirecli.io` calls this)."""
    try:
        real = os.path.realpath(path)
    except (OSError, ValueError):  # a NUL byte or an unusable name: the reader reports it
        return
    _INPUTS.add(real)
    for seen in _TRACKERS:
        seen.add(real)


@contextlib.contextmanager
def tracked_inputs():
    """Yield a set that collects the real paths of the input files read inside the block (a
    campaign hashes the files its base study reads into the points' identities)."""
    seen: set = set()
    _TRACKERS.append(seen)
    try:
        yield seen
    finally:
        _TRACKERS.remove(seen)


def inputs_read() -> frozenset[str]:
    """Real paths of the input files read since :func:`forget_inputs` (the start of the command)."""
    return frozenset(_INPUTS)


def forget_inputs() -> None:
    _INPUTS.clear()


def show_path(path) -> str:
    """The path as given, shortened in the middle when absurdly long (a message stays one readable line)."""
    text = os.fsdecode(path) if isinstance(path, bytes) else str(path)
    if len(text) > _SHOW_PATH:
        text = f"{text[:100]}...{text[-40:]}"
    return text.encode("utf-8", "backslashreplace").decode("utf-8")


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def os_reason(exc: OSError) -> str:
    """A short reason for an ``OSError`` from the file system (never the file's content)."""
    reasons = {
        errno.ENOENT: "file not found",
        errno.ENOTDIR: "not found (a part of the path is a file, not a directory)",
        errno.ENAMETOOLONG: "file name too long",
        errno.EACCES: "permission denied",
        errno.EPERM: "permission denied",
        errno.ELOOP: "too many levels of symbolic links",
        errno.EROFS: "read-only file system",
        errno.ENOSPC: "no space left on the device",
        errno.EISDIR: "is a directory",
        errno.ENXIO: "not a regular file (no such device or address)",
        errno.ENODEV: "not a regular file (no such device)",
    }
    if exc.errno in reasons:
        return reasons[exc.errno]
    return exc.strerror or type(exc).__name__


def _input_error(path, message: str) -> ConfigError:
    return ConfigError(Problem(show_path(path), None, "", message))


def _check_name(path) -> None:
    text = str(path)
    if not text.strip():
        raise ConfigError(Problem("<command line>", None, "", "empty file name"))
    if "\x00" in text:
        raise _input_error(text.replace("\x00", "\\0"), "file name contains a NUL byte")


def input_status(path) -> os.stat_result | None:
    """``os.stat`` of an input path; None when there is nothing at ``path``; ConfigError for other problems."""
    _check_name(path)
    try:
        return os.stat(path)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise _input_error(path, os_reason(exc)) from None


def exists(path) -> bool:
    """Whether something is at ``path`` (a file name too long, a permission problem ... count as
    something, so the reader is called and names the problem); never raises."""
    text = str(path)
    if not text or "\x00" in text:
        return bool(text)
    try:
        os.stat(text)
    except (FileNotFoundError, NotADirectoryError):
        return os.path.islink(text)  # a broken link: let the reader say so
    except (OSError, ValueError):
        return True
    return True


def read_input_bytes(path: str | Path, expected: str, max_bytes: int | None = None) -> bytes:
    """The bytes of a regular input file; ``ConfigError`` (exit 2) naming the file otherwise.

    Parameters
    ----------
    expected : str
        What the file should be, for the message (e.g. ``"a YAML file"``).
    max_bytes : int or None
        Largest size accepted (:mod:`tirecli.limits`); never more than this is read, so a huge file is
        refused without filling the memory.
    """
    _check_name(path)
    note_input(path)
    return _read_regular(path, expected, max_bytes)


def read_own_file(path: str | Path, max_bytes: int, within: str | Path | None = None,
                  follow: bool = False) -> bytes | None:
    """The bytes of a file tirecli keeps for itself (a cache entry, a run record, a campaign's stored
    points), through the same gate as every input, or None when it is anything else: not a regular
    file (a FIFO, a device, a directory), a symbolic link (unless ``follow``), a path that leads out
    of the directory ``within``, larger than ``max_bytes``, unreadable, or empty. Never blocks,
    never reads more than ``max_bytes``, never raises: the caller treats None as absent (a cache
    entry is then computed again)."""
    try:
        _check_name(path)
        if within is not None:
            top = os.path.realpath(within)
            if os.path.commonpath([os.path.realpath(path), top]) != top:
                return None
        return _read_regular(path, "a file", max_bytes, follow=follow)
    except (ConfigError, OSError, ValueError):
        return None


def _read_regular(path, expected: str, max_bytes: int | None, follow: bool = True) -> bytes:
    """Read a regular file without blocking (a FIFO or a device is refused before it is opened, and
    again after: it may have been swapped in between); ConfigError naming the file otherwise."""
    try:
        st = os.stat(path) if follow else os.lstat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            raise _input_error(path, "file not found (a broken symbolic link)") from None
        raise _input_error(path, "file not found") from None
    except OSError as exc:
        raise _input_error(path, os_reason(exc)) from None
    if not follow and stat.S_ISLNK(st.st_mode):
        raise _input_error(path, f"is a symbolic link, expected {expected}")
    _require_regular(path, st, expected)
    if max_bytes is not None and st.st_size > max_bytes:
        raise _input_error(path, too_large(Path(path), expected, max_bytes))
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise _input_error(path, os_reason(exc)) from None
    try:
        _require_regular(path, os.fstat(fd), expected)  # replaced since the stat: check again
        chunks, size = [], 0
        while True:
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
            if max_bytes is not None and size > max_bytes:  # grew since the stat
                raise _input_error(path, too_large(Path(path), expected, max_bytes))
    except OSError as exc:
        raise _input_error(path, f"cannot read ({os_reason(exc)})") from None
    finally:
        os.close(fd)
    data = b"".join(chunks)
    if not data:
        raise _input_error(path, f"is an empty file, expected {expected}")
    return data


def _is_devnull(st: os.stat_result) -> bool:
    try:
        null = os.stat(os.devnull)
    except OSError:
        return False
    return stat.S_ISCHR(st.st_mode) and st.st_rdev == null.st_rdev


def _require_regular(path, st: os.stat_result, expected: str) -> None:
    mode = st.st_mode
    if stat.S_ISREG(mode):
        return
    if stat.S_ISDIR(mode):
        raise _input_error(path, f"is a directory, expected {expected}")
    if _is_devnull(st):  # reads as an empty file
        raise _input_error(path, f"is an empty file (the null device), expected {expected}")
    raise _input_error(path, f"is {_kind(mode)}, not a regular file (expected {expected})")


def decode_text(data: bytes, path, expected: str, encoding: str = "utf-8") -> str:
    """Text of an input file's bytes; ConfigError naming the line of a byte that does not decode,
    or a binary file (NUL bytes)."""
    if b"\x00" in data:
        line = data.count(b"\n", 0, data.index(b"\x00")) + 1
        raise ConfigError(Problem(show_path(path), line, "", f"binary file (NUL byte), expected {expected}"))
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ConfigError(Problem(show_path(path), line, "",
                                  f"not {encoding.upper().replace('-SIG', '')} text (byte 0x{data[exc.start]:02x} "
                                  f"at column {col}), expected {expected}")) from None


def read_input_text(path: str | Path, expected: str, encoding: str = "utf-8", max_bytes: int | None = None) -> str:
    """:func:`read_input_bytes` (at most ``max_bytes``) decoded with ``encoding`` (see :func:`decode_text`)."""
    return decode_text(read_input_bytes(path, expected, max_bytes), path, expected, encoding)


def too_large(path: Path, expected: str, max_bytes: int) -> str:
    """The message for an input file over its size cap (its size when it has one)."""
    from tirecli.limits import bytes_text

    try:
        size = path.stat().st_size
    except OSError:
        size = 0
    what = f"{bytes_text(size)[1:]}, " if size > max_bytes else ""
    return f"too large for {expected} ({what}at most {bytes_text(max_bytes)[1:]})"


# --------------------------------------------------------------------------- output locations


def _output_error(option: str, path, message: str) -> UsageError:
    where = f"{option} {show_path(path)}" if option else show_path(path)
    return UsageError(f"{where}: {message}")


def _nearest_existing(path: Path, option: str, target: Path) -> tuple[Path, bool]:
    """The deepest existing ancestor of ``path`` (``path`` itself included) and whether it is ``path``."""
    cur = path
    while True:
        try:
            st = os.stat(cur)
        except (FileNotFoundError, NotADirectoryError):
            parent = cur.parent
            if parent == cur:
                raise _output_error(option, target, "no existing directory on the path") from None
            cur = parent
            continue
        except OSError as exc:
            raise _output_error(option, target, os_reason(exc) if cur == target
                                else f"{show_path(cur)}: {os_reason(exc)}") from None
        if not stat.S_ISDIR(st.st_mode):
            if cur == target:
                return cur, True
            raise _output_error(option, target, f"{show_path(cur)} is a file, not a directory")
        return cur, cur == path


def _probe_writable(directory: Path, option: str, target: Path) -> None:
    """Create and remove a temporary file in ``directory`` (the only reliable test, also as root)."""
    try:
        fd, name = tempfile.mkstemp(prefix=".tirecli-probe-", dir=directory)
    except OSError as exc:
        what = "read-only location" if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS) else os_reason(exc)
        detail = "" if Path(directory) == target else f" ({show_path(directory)})"
        raise _output_error(option, target, f"cannot write there: {what}{detail}") from None
    os.close(fd)
    try:
        os.unlink(name)
    except OSError:
        pass


def _check_names(path, option: str) -> None:
    text = str(path)
    if not text.strip():
        raise UsageError(f"{option} '': empty; give the path to write to")
    if "\x00" in text:
        raise _output_error(option, text.replace("\x00", "\\0"), "the name contains a NUL byte")
    path = Path(text)
    try:
        max_name = os.pathconf(_nearest_dir_text(path), "PC_NAME_MAX")
    except (OSError, ValueError):
        max_name = 255
    for part in path.parts:
        if len(os.fsencode(part)) > max_name:
            raise _output_error(option, path, f"file name too long ({len(part)} characters, at most {max_name})")


def _nearest_dir_text(path: Path) -> str:
    cur = path.parent
    while not os.path.isdir(cur) and cur != cur.parent:
        cur = cur.parent
    return str(cur)


def check_output_dir(out: str | Path, option: str = "--out", files=(), dirs=()) -> Path:
    """Check an output directory before a run: it (or its nearest existing parent, where it will be
    created) is a writable directory, ``files`` (paths relative to ``out``) are not directories or
    devices there and ``dirs`` are directories or absent. Nothing is created; UsageError naming the
    path otherwise."""
    _check_names(out, option)  # before Path(): Path('') is the current directory
    out = Path(out)
    base, _ = _nearest_existing(out, option, out)
    if base == out and not out.is_dir():
        raise _output_error(option, out, "exists and is not a directory")
    _probe_writable(base, option, out)
    if base == out:
        check_output_files(out, files, option)
        for rel in dirs:
            if (out / rel).exists() and not (out / rel).is_dir():
                raise _output_error(option, out, f"{show_path(out / rel)} exists and is not a directory")
    return out


def check_output_files(out: Path, files, option: str = "--out") -> None:
    """Each of ``files`` (relative to ``out``) that exists is a regular file and its parents are directories."""
    for rel in files:
        p = Path(out) / rel
        try:
            st = os.lstat(p)
        except (FileNotFoundError, NotADirectoryError):
            parent = p.parent
            while parent != Path(out) and parent != parent.parent:
                if parent.exists() and not parent.is_dir():
                    raise _output_error(option, out, f"{show_path(parent)} exists and is not a directory")
                parent = parent.parent
            continue
        except OSError as exc:
            raise _output_error(option, out, f"{show_path(p)}: {os_reason(exc)}") from None
        if stat.S_ISDIR(st.st_mode):
            raise _output_error(option, out, f"{show_path(p)} is a directory (expected a file or nothing there)")
        if not (stat.S_ISREG(st.st_mode) or stat.S_ISLNK(st.st_mode)):
            raise _output_error(option, out, f"{show_path(p)} is {_kind(st.st_mode)}, not a regular file")


def check_output_file(path: str | Path, option: str = "--out") -> Path:
    """Check an output file's location before a run: not a directory or a device, its directory (or the
    nearest existing parent, where the directories will be created) writable. Nothing is created."""
    _check_names(path, option)  # before Path(): Path('') is the current directory
    path = Path(path)
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        st = None
    except OSError as exc:
        raise _output_error(option, path, os_reason(exc)) from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise _output_error(option, path, "is a directory (expected a file name)")
        if not stat.S_ISREG(st.st_mode):
            raise _output_error(option, path, f"is {_kind(st.st_mode)}, not a regular file")
    base, _ = _nearest_existing(path.parent if str(path.parent) else Path("."), option, path)
    _probe_writable(base, option, path)
    return path
