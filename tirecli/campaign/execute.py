"""Where a campaign's points run: in this process, on a local process pool, or on a Dask cluster.

Points travel in batches (:func:`batch_size`: about half a second of work each), so the
scheduling cost stays small against a braking of a few milliseconds; the shared part of every
point (the base config, the fixed overrides, the outputs) is sent to each worker once. Results
come back to this process, which alone writes files: workers of a remote cluster need no access
to the output directory (but they read the files the base study refers to, at the same paths).

* ``jobs == 1`` and no scheduler: in this process.
* no scheduler: a :class:`concurrent.futures.ProcessPoolExecutor` of ``jobs`` processes (default
  the CPU count).
* ``scheduler="local"``: a Dask ``LocalCluster`` of ``jobs`` single-threaded worker processes.
* ``scheduler="tcp://HOST:PORT"``: the Dask scheduler at that address (``dask[distributed]``).

Ctrl-C stops the workers; the records received so far are kept by the caller.
"""
from __future__ import annotations

import math
import multiprocessing
import os
import signal
import sys
from collections import deque

from tirecli.campaign.facts import run_batch
from tirecli.errors import UsageError

#: Seconds of work a batch aims at.
BATCH_SECONDS = 0.5

_PAYLOAD = None


def batch_size(n_points: int, workers: int, seconds_per_point: float, given: int | None = None) -> int:
    """Points per task: ``given``, else about :data:`BATCH_SECONDS` of work, and at least four
    tasks per worker (the load stays balanced) when there are enough points."""
    if given:
        return int(given)
    by_time = max(1, int(BATCH_SECONDS / max(seconds_per_point, 1e-5)))
    by_balance = max(1, math.ceil(n_points / (4 * max(workers, 1))))
    return max(1, min(by_time, by_balance))


#: Environment of a worker process: one thread per numeric library (the workers share the cores).
ONE_THREAD = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                               "VECLIB_MAXIMUM_THREADS", "NUMEXPR_NUM_THREADS")}
_PINNED = False


def pin_threads() -> None:
    """Make this worker process use one thread per evaluation: tirecli's own thread pool
    (:data:`tirecli.parallel.LIMIT`), the BLAS already loaded (OpenBLAS, through its
    ``*_set_num_threads``; the environment variables of :data:`ONE_THREAD` for libraries loaded
    later). N workers on N cores then run N threads, not N times the core count."""
    global _PINNED
    if _PINNED:
        return
    _PINNED = True
    os.environ.update(ONE_THREAD)
    from tirecli import parallel

    parallel.LIMIT = 1
    try:
        import ctypes

        with open("/proc/self/maps", encoding="ascii", errors="replace") as fh:  # noqa: PTH123 - a system file
            paths = {line.split()[-1] for line in fh if len(line.split()) >= 6}
        libs = [p for p in paths if "openblas" in os.path.basename(p).lower() and ".so" in os.path.basename(p)]
        for path in libs:
            lib = ctypes.CDLL(path)
            for name in ("openblas_set_num_threads", "openblas_set_num_threads64_", "scipy_openblas_set_num_threads64_",
                         "scipy_openblas_set_num_threads"):
                if hasattr(lib, name):
                    getattr(lib, name)(1)
                    break
    except (OSError, AttributeError, ValueError):  # not Linux, or no OpenBLAS: nothing loaded to pin
        pass


def _init_worker(payload) -> None:
    """A pool worker: Ctrl-C is the parent's to handle (it stops the pool), SIGTERM ends the worker;
    one thread per evaluation (:func:`pin_threads`)."""
    global _PAYLOAD
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    pin_threads()
    _PAYLOAD = payload


def _pool_batch(batch):
    return run_batch(_PAYLOAD, batch)


def _dask_batch(payload, batch):
    """A batch on a Dask worker (its threads pinned once: :func:`pin_threads`)."""
    pin_threads()
    return run_batch(payload, batch)


def _mp_context():
    """``fork`` where it is safe and cheap (Linux: the workers start with tirecli imported),
    else ``spawn``."""
    if sys.platform.startswith("linux"):
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("spawn")


def run_batches(payload, batches: list, jobs: int, scheduler: str | None, on_records, describe=None) -> dict:
    """Run ``batches`` and pass each one's records to ``on_records(records)`` as they finish (in this
    process). Returns a description of the executor (``{"executor", "workers", ...}``)."""
    if scheduler:
        return _run_dask(payload, batches, jobs, scheduler, on_records)
    if jobs <= 1 or len(batches) <= 1:
        for b in batches:
            on_records(run_batch(payload, b))
        return {"executor": "in-process", "workers": 1}
    return _run_pool(payload, batches, jobs, on_records)


def _run_pool(payload, batches, jobs, on_records) -> dict:
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    workers = min(jobs, len(batches))
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=_mp_context(), initializer=_init_worker,
                               initargs=(payload,))
    todo = deque(batches)
    running = set()
    try:
        while todo or running:
            while todo and len(running) < 2 * workers:  # a few batches ahead: memory stays flat
                running.add(pool.submit(_pool_batch, todo.popleft()))
            done, running = wait(running, return_when=FIRST_COMPLETED)
            for fut in done:
                on_records(fut.result())
    except BaseException:
        _stop_pool(pool)
        raise
    pool.shutdown(wait=True)
    return {"executor": "process pool", "workers": workers}


def _stop_pool(pool) -> None:
    """Stop a process pool now: queued batches cancelled, running workers terminated."""
    procs = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        try:
            p.terminate()
        except Exception:  # noqa: BLE001 - already gone
            pass
    for p in procs:
        p.join(timeout=2)


def require_scheduler() -> None:
    """UsageError (one line, how to install it) when Dask's distributed is not installed: checked
    before a campaign with ``--scheduler`` does any work."""
    from tirecli.errors import require

    require("distributed", "--scheduler")


def dask_client(scheduler: str, jobs: int):
    """A Dask client: ``local`` starts a LocalCluster of ``jobs`` single-threaded workers, an address
    connects to that scheduler. UsageError when dask.distributed is not installed or the scheduler
    cannot be reached."""
    require_scheduler()
    from distributed import Client, LocalCluster
    import logging

    if scheduler == "local":
        import dask

        # the workers' statistical profiler samples the running task every 10 ms: a few per cent of a
        # pure-Python braking, for a dashboard this cluster does not have
        with dask.config.set({"distributed.worker.profile.enabled": False}):
            cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, dashboard_address=None,
                                   silence_logs=logging.ERROR)
        return Client(cluster), cluster
    if "://" not in scheduler:
        raise UsageError(f"--scheduler {scheduler!r}: expected 'local' or an address such as tcp://HOST:8786")
    try:
        return Client(scheduler, timeout="10s"), None
    except (OSError, TimeoutError) as exc:
        raise UsageError(f"--scheduler {scheduler}: cannot connect ({exc})") from None


def _run_dask(payload, batches, jobs, scheduler, on_records) -> dict:
    from distributed import as_completed

    client, cluster = dask_client(scheduler, jobs)
    futures = []
    try:
        workers = len(client.scheduler_info().get("workers", {})) or jobs
        shared = client.scatter(payload, broadcast=True)
        futures = [client.submit(_dask_batch, shared, b, pure=False) for b in batches]
        for fut in as_completed(futures):
            on_records(fut.result())
            fut.release()
    except BaseException:
        for f in futures:
            f.cancel()
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return {"executor": "dask local cluster" if cluster is not None else "dask", "scheduler": scheduler,
            "workers": workers}


__all__ = ["run_batches", "batch_size", "dask_client"]
