"""The report's work: each built-in study with its figures, from the cache or run, on all cores.

A *unit* is one study and the report's figures of it. :func:`probe` takes a unit from the cache
(:mod:`tirecli.io.cache`) when its study, the built-in data it read and every one of its figures
are there; :func:`run_units` runs the others, in a pool of ``jobs`` processes (``jobs=1``: in this
process, no pool). A unit writes its files into the report's staging folder and returns the facts
of its cards as plain JSON data, the same whether drawn now or read from the cache, so the report
does not depend on the number of processes.

Progress: a unit says which study or figure it starts and when one is done (``note(kind, name)``);
with a pool, the workers send these through a queue and the parent refreshes the bar at least
every quarter second.
"""
from __future__ import annotations

import contextlib
import functools
import json
import queue
import signal
import sys
import threading
import time
import traceback
from pathlib import Path

from tirecli.app.results import data_comments, scenario_assumptions, write_figure, write_study
from tirecli.io import output

#: Formats the report can save its figures in (PNG is always one: the page embeds it).
FORMATS = ("png", "svg")
#: Resolution of the saved PNG [dots per inch].
DPI = 150


@functools.lru_cache(maxsize=None)
def set_digest(name: str) -> str | None:
    """SHA-256 of the file of built-in parameter set ``name`` (None if there is no such set)."""
    from tirecli.errors import ConfigError
    from tirecli.io.cache import resource_digest
    from tirecli.parameters.sets import builtin_path

    try:
        return resource_digest(builtin_path(name))
    except ConfigError:
        return None


def _named_configs(config, seen: dict) -> dict:
    """Built-in configs named anywhere in ``config`` (e.g. the simulation a fit reads), with the
    SHA-256 of their text, recursively."""
    from tirecli.studies.configs import builtin_config, builtin_config_names

    names = set(builtin_config_names())

    def walk(obj):
        if isinstance(obj, dict):
            for v in obj.values():
                yield from walk(v)
        elif isinstance(obj, list):
            for v in obj:
                yield from walk(v)
        elif isinstance(obj, str) and obj in names:
            yield obj

    for name in sorted(set(walk(config.data))):
        if name not in seen:
            sub = builtin_config(name)
            seen[name] = sub.digest()
            _named_configs(sub, seen)
    return seen


def study_key(name: str, config) -> str:
    """The cache key of a study run from ``config`` (see :mod:`tirecli.io.cache`)."""
    from tirecli._version import __version__
    from tirecli.io.cache import FORMAT, code_fingerprint, key_of

    return key_of({
        "format": FORMAT, "study": name, "config": config.digest(), "configs": _named_configs(config, {}),
        "tirecli": __version__, "code": code_fingerprint(), "python": sys.version,
        "libraries": {lib: output.lib_version(lib) for lib in ("numpy", "scipy", "pandas", "matplotlib")},
    })


def figure_key(formats) -> str:
    from tirecli.io.cache import key_of

    return key_of({"formats": list(formats), "dpi": DPI})[:12]


def _plain(obj):
    """JSON data (NaN kept) of a card's facts: what the cache stores and the page shows."""
    def default(o):
        if hasattr(o, "tolist"):
            return o.tolist()
        return str(o)

    return json.loads(json.dumps(obj, default=default))


# --------------------------------------------------------------------------- one unit


def probe(task: dict) -> dict | None:
    """The unit from the cache (its files copied into the staging folder), or None."""
    from tirecli.io.cache import StudyCache

    if not task["cache"] or not task["use_cache"]:
        return None
    t0 = time.perf_counter()
    cache = StudyCache(task["cache"], task["study"], task["key"])
    manifest = cache.manifest(set_digest)
    if manifest is None:
        return None
    cards = {}
    for fid in task["figures"]:
        card = cache.figure(fid, task["fkey"], set_digest)
        if card is None:
            return None
        cards[fid] = card
    root = Path(task["root"])
    try:
        cache.copy_study(manifest, root)
        for fid, card in cards.items():
            cache.copy_figure(card, fid, task["fkey"], root)
    except OSError:  # an entry removed meanwhile: run the study
        return None
    for card in cards.values():
        card.pop("hashes", None)
    return {"study": task["study"], "error": None, "wall": time.perf_counter() - t0, "cached": True,
            "record": manifest["record"], "cards": cards}


def run_unit(task: dict, note=None) -> dict:
    """Run the unit's study, write its data, run record and figures into the staging folder, keep
    them in the cache; returns its facts (see :func:`probe`)."""
    from tirecli.app.draw import draw_figures
    from tirecli.io.cache import StudyCache, read_bytes
    from tirecli.parameters import sets
    from tirecli.report.cards import page_image
    from tirecli.studies import registry

    note = note or (lambda kind, name: None)
    name, root = task["study"], Path(task["root"])
    note("study", name)
    t0 = time.perf_counter()
    sets.BUILTINS_READ.clear()
    try:
        res = registry.run_study(task["config"])
    except Exception as exc:  # noqa: BLE001 - reported in the page and as a failed check
        for _ in range(1 + len(task["figures"])):  # its figures will not be drawn
            note("study-done", name)
        return {"study": name, "error": f"{type(exc).__name__}: {exc}\n" + traceback.format_exc(limit=4),
                "wall": time.perf_counter() - t0, "cached": False, "record": None, "cards": {}}
    wall = time.perf_counter() - t0
    write_study(root, name, res, wall)
    note("study-done", name)
    study_reads, cards = set(sets.BUILTINS_READ), {}

    def starting(fid):
        note("figure", fid)
        sets.BUILTINS_READ.clear()

    for drawn in draw_figures(res, task["figures"], catch=True, before=starting):
        cards[drawn.id] = _plain(_card(drawn, res, root, task["formats"]))
        png = next((p for p in cards[drawn.id]["files"] if p.endswith(".png")), None)  # the page's copy, made here
        cards[drawn.id]["image"] = page_image(read_bytes(root / png)) if png else None
        # the card holds for the built-in sets read by the study and by this figure and its checks
        cards[drawn.id]["deps"] = {n: set_digest(n) for n in sorted(study_reads | sets.BUILTINS_READ)}
        note("figure-done", drawn.id)
    record = {"data": list(res.data), "wall_time_s": round(wall, 4)}
    if task["cache"]:
        cache = StudyCache(task["cache"], name, task["key"])
        cache.store_study(record, {n: set_digest(n) for n in sorted(study_reads)}, root, list(res.data))
        for fid, card in cards.items():
            if card["error"] is None:
                cache.store_figure(card, fid, task["fkey"], root)
    return {"study": name, "error": None, "wall": wall, "cached": False, "record": record, "cards": cards,
            "unit_wall": time.perf_counter() - t0}


def _card(drawn, res, root: Path, formats) -> dict:
    """The card of a drawn figure (:class:`tirecli.app.draw.Drawn`) of result ``res``, its files written
    into ``root/figures``: the card's facts."""
    from tirecli.figures.registry import REGISTRY, card_table

    card = {"id": drawn.id, "caption": REGISTRY[drawn.id].caption_for(res) if drawn.id in REGISTRY else "",
            "synthetic": res.synthetic, "assumed": scenario_assumptions(res),
            "parameters": [{"group": g, "set": ps.name, "citation": ps.citation, "rows": ps.rows()}
                           for g, ps in res.parameter_sets.items()],
            "checks": [c.record() for c in drawn.checks], "files": [], "table": None, "error": drawn.error}
    fig = drawn.figure
    table = card_table(fig)
    if table is not None:
        card["table"] = {"columns": table.columns, "rows": table.rows, "notes": table.notes}
    if fig is not None:
        paths = write_figure(root / "figures", drawn.id, fig, data_comments(res), dpi=DPI, formats=formats)
        card["files"] = [str(p.relative_to(root)) for p in paths]
    return card


# --------------------------------------------------------------------------- many units

_QUEUE = None


def _init_worker(q, point) -> None:
    """A pool worker: it ends with the report's process however that ends
    (:func:`tirecli.parallel.die_with_parent`); Ctrl-C is the parent's to handle (it ends the pool), SIGTERM
    ends the worker.

    A forked worker has none of the parent's threads: :mod:`tirecli.parallel` drops the parent's
    thread pool in every forked child (``os.register_at_fork``)."""
    global _QUEUE
    from tirecli.parallel import die_with_parent

    die_with_parent(point)
    _QUEUE = q
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    import matplotlib

    matplotlib.use("Agg")


def _run_in_worker(tasks: list[dict]) -> list[dict]:
    return [run_unit(t, note=lambda kind, name: _QUEUE.put((kind, name))) for t in tasks]


def _study_entry(task: dict):
    """The registry entry of the study of a unit's config (None if it names no known study)."""
    from tirecli.studies import registry

    data = getattr(task.get("config"), "data", None)
    name = data.get("study") if isinstance(data, dict) else None
    return registry.get(name) if isinstance(name, str) and name in registry.names() else None


def unit_group(task: dict) -> str:
    """The worker group of a unit: units whose studies share a group (``Study.group``, e.g. the brakings
    solved once per process and reused: FM's braking #2 in fm-fig4 and fm-fig6) run in one process, in
    order; any other unit is a group of its own."""
    entry = _study_entry(task)
    return f"group:{entry.group}" if entry is not None and entry.group else f"study:{task['study']}"


def run_units(tasks: list[dict], jobs: int, note, meanwhile=None) -> list[dict]:
    """Run ``tasks`` (in the given order of start) in ``jobs`` processes; their results in the same order.

    ``note(kind, name)`` is called in this process for every step (and ``("tick", "")`` at least
    every quarter second while the work runs). A failure of a unit (other than its study's or a
    figure's, which it reports) ends the pool and is raised here; so is Ctrl-C, and a worker that
    died (killed, out of memory) is a :class:`~tirecli.errors.RunError`. ``meanwhile()`` (optional) is
    called once in this process, after the workers have started (never while forking: no thread runs it).
    """
    if jobs <= 1 or len(tasks) <= 1:  # in this process, no pool
        if meanwhile is not None:
            meanwhile()
        if not tasks:
            return []
        with _ticking(note):
            return [run_unit(t, note=note) for t in tasks]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    from tirecli.errors import RunError
    from tirecli.parallel import fork_point

    _preload(tasks)
    ctx = multiprocessing.get_context("fork")  # the workers start with this process's imports (and test patches)
    q = ctx.Queue()
    pool = ProcessPoolExecutor(min(jobs, len(tasks)), mp_context=ctx, initializer=_init_worker,
                               initargs=(q, fork_point()))
    try:
        groups: dict[str, list[int]] = {}
        for i, t in enumerate(tasks):  # a group starts where its first (slowest) unit would have
            groups.setdefault(unit_group(t), []).append(i)
        order = list(groups.values())
        futures = [pool.submit(_run_in_worker, [tasks[i] for i in idx]) for idx in order]
        for f in futures:  # a group that ends wakes the loop below at once, not at its next quarter-second tick
            f.add_done_callback(functools.partial(_wake, q))
        if meanwhile is not None:  # the workers are forked by now (all of them, at the first submission)
            meanwhile()
        while True:
            _drain(q, note, timeout=0.25)
            done = [f for f in futures if f.done()]
            for f in done:
                if f.exception() is not None:
                    raise f.exception()
            if len(done) == len(futures):
                break
        _drain(q, note, timeout=0.0)
        pool.shutdown()
        results: list = [None] * len(tasks)
        for idx, f in zip(order, futures):
            for i, r in zip(idx, f.result()):
                results[i] = r
        return results
    except BrokenProcessPool:
        _stop(pool)
        raise RunError("a worker process of the report ended abruptly (killed, or out of memory?); "
                       "--jobs 1 runs the studies in the tirecli process itself") from None
    except BaseException:
        _stop(pool)
        raise
    finally:
        q.close()
        q.cancel_join_thread()


def _stop(pool) -> None:
    """End a process pool now: queued work cancelled, running workers terminated."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        p.terminate()
    for p in procs:
        p.join()


def _wake(q, _future) -> None:
    """Done-callback of a group's future: a tick into the progress queue (nothing once the queue is closed)."""
    with contextlib.suppress(ValueError, OSError):
        q.put(("tick", ""))


def _drain(q, note, timeout: float) -> None:
    """Pass the workers' messages to ``note``; a tick when none came within ``timeout``."""
    try:
        note(*q.get(timeout=timeout) if timeout > 0 else q.get_nowait())
    except queue.Empty:
        note("tick", "")
        return
    while True:
        try:
            note(*q.get_nowait())
        except queue.Empty:
            return


#: Libraries the studies import when they first run: imported once before the workers fork, not in each.
PRELOAD = ("pandas", "scipy.integrate", "scipy.interpolate", "scipy.optimize")


def _preload(tasks: list[dict]) -> None:
    """Import what every worker would import again, once, before the workers fork: matplotlib's Agg
    canvas, the modules of the tasks' studies and the libraries of :data:`PRELOAD` (about 0.8 s of CPU
    per worker)."""
    import importlib

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.backends.backend_agg  # noqa: F401
    import matplotlib.figure  # noqa: F401

    for t in tasks:
        _study_entry(t)  # imports the study's module
    for name in PRELOAD:
        importlib.import_module(name)


class _ticking:
    """While the block runs in this process, a thread calls ``note('tick', '')`` twice a second."""

    def __init__(self, note):
        self.note, self.stop = note, threading.Event()

    def __enter__(self):
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()
        return self

    def _run(self):
        while not self.stop.wait(0.5):
            self.note("tick", "")

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join()
