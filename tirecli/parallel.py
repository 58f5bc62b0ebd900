"""A shared worker-thread pool for large vectorized evaluations (numpy releases the GIL in its loops),
and the cores a process may use (:func:`default_jobs`).

Used by the Magic Formula evaluator and the fast CSV formatter: work is split into blocks that fit
the CPU cache and the blocks run on these threads. Results never depend on the number of threads.
A leaf module: it imports nothing from tirecli, so every layer may use it.
"""
from __future__ import annotations

import collections
import os
import threading
from concurrent.futures import ThreadPoolExecutor

_POOL: ThreadPoolExecutor | None = None
_SIZE = 0
_LOCK = threading.Lock()
#: The most threads an evaluation of this process uses (None: no limit beyond :func:`default_threads`'s);
#: a campaign's worker processes set 1 (the workers share the cores already).
LIMIT: int | None = None


def default_jobs() -> int:
    """The cores this process may use (its CPU affinity; the CPU count where that is unknown): the default
    number of worker processes of a report or a campaign."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(os.cpu_count() or 1, 1)


#: Worker processes per core a report or a campaign may be given (``--jobs``): more only adds memory.
JOBS_PER_CORE = 4


def max_jobs() -> int:
    """The most worker processes ``--jobs`` may ask for: :data:`JOBS_PER_CORE` per core of :func:`default_jobs`
    (at least 8)."""
    return max(8, JOBS_PER_CORE * default_jobs())


def helper_process_ok() -> bool:
    """Whether this process may hand work to a forked helper process and go on meanwhile: on Linux
    (``fork``), with more than one core (:func:`default_jobs`), and only in the command's own process:
    not in a worker process of a report or a campaign (their cores are shared already, a daemonic
    worker may not start processes, and a worker ended by its parent would leave the helper behind;
    a campaign's pinned worker also has :data:`LIMIT` 1)."""
    import multiprocessing
    import sys

    return (sys.platform.startswith("linux") and default_jobs() > 1 and LIMIT != 1
            and multiprocessing.parent_process() is None and not multiprocessing.current_process().daemon)


#: Seconds between two looks of a worker or helper process at its parent (:func:`die_with_parent`).
WATCH_SECONDS = 0.5
#: ``prctl`` option: the signal a process gets when its parent (the thread that forked it) ends.
_PR_SET_PDEATHSIG = 1


def fork_point() -> tuple[int, bool]:
    """What :func:`die_with_parent` needs to know of the process about to start workers or a helper: its id,
    and whether this is its main thread (which ends only with the process)."""
    return os.getpid(), threading.current_thread() is threading.main_thread()


def die_with_parent(point: tuple[int, bool]) -> None:
    """In a worker or helper process just started by the process of ``point`` (:func:`fork_point`, taken there):
    end within a second of that parent's death however it dies (SIGKILL, out of memory), so that no worker
    computes on for nobody.

    On Linux the kernel sends SIGKILL when the parent ends (``prctl(PR_SET_PDEATHSIG)``, through ctypes), when
    the parent started this process from its main thread (the signal follows the thread that forked, and
    another thread may end before the process); everywhere a daemon thread looks at the parent every
    :data:`WATCH_SECONDS` and ends this process when it has gone (its parent id is no longer the parent's).
    A parent that died before this call ends this process at once."""
    import signal
    import sys
    import time

    parent, from_main = point
    if from_main and sys.platform.startswith("linux"):
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
        except (OSError, AttributeError, TypeError):  # no C library to call: the watch below does it
            pass
    if os.getppid() != parent:  # the parent ended before the signal was asked for
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(WATCH_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="tirecli-parent-watch", daemon=True).start()


def _drop_after_fork() -> None:
    """In a forked child: the parent's pool has no threads here (work given to it would wait for ever);
    the child starts its own when it first needs one."""
    global _POOL, _SIZE, _LOCK
    _POOL, _SIZE, _LOCK = None, 0, threading.Lock()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_drop_after_fork)


def default_threads() -> int:
    """Worker threads for large evaluations: the CPU count (at most 8, and at most :data:`LIMIT`)."""
    return max(1, min(os.cpu_count() or 1, 8, LIMIT or 8))


def thread_pool(n: int) -> ThreadPoolExecutor:
    """The process-wide pool with ``n`` workers (re-created when ``n`` changes)."""
    global _POOL, _SIZE
    with _LOCK:
        if _POOL is None or _SIZE != n:
            if _POOL is not None:
                _POOL.shutdown(wait=False)
            _POOL = ThreadPoolExecutor(max_workers=n, thread_name_prefix="tirecli")
            _SIZE = n
        return _POOL


def ordered_map(fn, items, threads: int | None = None):
    """``fn(item)`` of each of ``items``, yielded in their order, computed on the shared pool
    (:func:`thread_pool` of ``threads`` workers, default :func:`default_threads`) at most one item more
    than the workers ahead of the consumer, so memory holds a few results whatever the number of
    items. With one thread or one item, in the calling thread."""
    items = list(items)
    nthreads = default_threads() if threads is None else max(1, int(threads))
    if len(items) < 2 or nthreads < 2:
        yield from map(fn, items)
        return
    pool = thread_pool(nthreads)
    pending: collections.deque = collections.deque()
    for item in items:
        if len(pending) > nthreads:
            yield pending.popleft().result()
        pending.append(pool.submit(fn, item))
    while pending:
        yield pending.popleft().result()
