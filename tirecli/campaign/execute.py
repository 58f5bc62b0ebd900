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

import contextlib
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


def pool_options(payload) -> dict:
    """The ``initializer`` and ``initargs`` of a campaign's process pool (:func:`_init_worker`), taken in the
    process and thread that starts the workers."""
    from tirecli.parallel import fork_point

    return {"initializer": _init_worker, "initargs": (payload, fork_point())}


def _init_worker(payload, point) -> None:
    """A pool worker: it ends with the campaign's process however that ends
    (:func:`tirecli.parallel.die_with_parent`: no worker computes on after a SIGKILL of the campaign); Ctrl-C
    is the parent's to handle (it stops the pool), SIGTERM ends the worker; one thread per evaluation
    (:func:`pin_threads`)."""
    global _PAYLOAD
    from tirecli.parallel import die_with_parent

    die_with_parent(point)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    pin_threads()
    _PAYLOAD = payload


def _pool_batch(batch):
    return run_batch(_PAYLOAD, batch)


def _dask_batch(payload, batch):
    """A batch on a Dask worker (its threads pinned once: :func:`pin_threads`), under the campaign's sample
    budget (a Dask worker is no fork of this process: the budget travels with the payload)."""
    from tirecli import limits

    pin_threads()
    with limits.budget(payload.get("max_samples")):
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
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=_mp_context(), **pool_options(payload))
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


#: Address schemes of a Dask scheduler that ``--scheduler`` accepts, and the default port of one.
SCHEMES = ("tcp", "tls", "ws", "wss")
DASK_PORT = 8786
#: Seconds to reach the scheduler's port, then to receive its handshake.
CONNECT_SECONDS = 3.0


def check_scheduler(address: str | None) -> str | None:
    """The ``--scheduler`` option, checked before anything runs: ``local``, or the address of a Dask
    scheduler that answers as one (``tcp://HOST:PORT``; ``HOST:PORT`` means tcp). Returns the address
    to use (None: no scheduler). UsageError (exit 2, naming the address) within a few seconds for an
    empty or unreadable address, a scheme that is not a Dask one, Dask not installed, a host that
    does not resolve, a port that refuses or does not answer, and a port that answers but not with a
    Dask scheduler's handshake (any other server: it would make the Dask client wait for ever)."""
    if address is None:
        return None
    text = address.strip()
    shown = repr(address) if len(address) <= 80 else repr(address[:77] + "...")
    expected = f"expected 'local' or a Dask scheduler's address such as tcp://HOST:{DASK_PORT}"
    if not text:
        raise UsageError(f"--scheduler {shown}: empty; {expected}")
    if text == "local":
        _need_dask()
        return text
    host, port, scheme = _parse_address(text, shown, expected)
    _need_dask()
    if scheme == "tcp":
        _probe_dask(host, port, shown)
    else:  # encrypted or websocket transport: the port is reachable (the handshake is Dask's own)
        with _connected(host, port, shown):
            pass
    return f"{scheme}://{'[' + host + ']' if ':' in host else host}:{port}"


def _parse_address(text: str, shown: str, expected: str) -> tuple[str, int, str]:
    from urllib.parse import urlsplit

    if "://" not in text:
        if ":" not in text:
            raise UsageError(f"--scheduler {shown}: {expected}")
        text = "tcp://" + text
    try:
        parts = urlsplit(text)
        port = parts.port
    except ValueError:
        raise UsageError(f"--scheduler {shown}: cannot read the address ({expected})") from None
    scheme = parts.scheme.lower()
    if scheme not in SCHEMES:
        raise UsageError(f"--scheduler {shown}: {scheme or 'no'} is not a Dask address scheme "
                         f"(expected {', '.join(s + '://' for s in SCHEMES)} or 'local')")
    if not parts.hostname or parts.path not in ("", "/") or parts.query or parts.fragment:
        raise UsageError(f"--scheduler {shown}: cannot read the address ({expected})")
    if port == 0:
        raise UsageError(f"--scheduler {shown}: port 0 is not a port to connect to")
    return parts.hostname, port or DASK_PORT, scheme


def _need_dask() -> None:
    require_scheduler()


@contextlib.contextmanager
def _connected(host: str, port: int, shown: str):
    """A TCP connection to ``host:port`` within :data:`CONNECT_SECONDS` (UsageError naming why not)."""
    import socket

    try:
        sock = socket.create_connection((host, port), timeout=CONNECT_SECONDS)
    except socket.gaierror:
        raise UsageError(f"--scheduler {shown}: cannot connect (host {host!r} not found)") from None
    except (TimeoutError, socket.timeout):
        raise UsageError(f"--scheduler {shown}: cannot connect (no answer within {CONNECT_SECONDS:g} s)") from None
    except OSError as exc:
        raise UsageError(f"--scheduler {shown}: cannot connect ({(exc.strerror or str(exc)).lower()})") from None
    try:
        yield sock
    finally:
        sock.close()


def _probe_dask(host: str, port: int, shown: str) -> None:
    """A Dask scheduler speaks first: on a new connection it sends its handshake, a message in Dask's
    framing (8 bytes little-endian: the message's length, then 8 bytes: its number of frames). Anything
    else within :data:`CONNECT_SECONDS` (silence, an HTTP or SSH server) is not a Dask scheduler."""
    import select
    import struct
    import time

    not_dask = f"--scheduler {shown}: something answers there, but not a Dask scheduler"
    with _connected(host, port, shown) as sock:
        head = b""
        deadline = time.monotonic() + CONNECT_SECONDS
        while len(head) < 16:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([sock], [], [], left)[0]:
                raise UsageError(f"{not_dask} (no Dask handshake within {CONNECT_SECONDS:g} s)")
            try:
                chunk = sock.recv(16 - len(head))
            except OSError as exc:
                raise UsageError(f"{not_dask} ({(exc.strerror or str(exc)).lower()})") from None
            if not chunk:
                raise UsageError(f"{not_dask} (it closed the connection)")
            head += chunk
    length, frames = struct.unpack("<QQ", head)
    if not (16 <= length <= 1 << 20 and 1 <= frames <= 64):
        raise UsageError(f"{not_dask} (its first bytes are no Dask handshake)")


def dask_client(scheduler: str, jobs: int):
    """A Dask client: ``local`` starts a LocalCluster of ``jobs`` single-threaded workers, an address
    (checked first by :func:`check_scheduler`) connects to that scheduler. UsageError when
    dask.distributed is not installed or the scheduler cannot be reached."""
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


__all__ = ["run_batches", "batch_size", "dask_client", "check_scheduler"]
