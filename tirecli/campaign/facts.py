"""One point of a campaign: run its study and pick facts by name.

No figures are drawn and no file is written: a lumped braking takes milliseconds, and the
campaign's cost must be its runs. The facts of a run are its study's (``Study.facts``, by name:
``NAME[LABEL]`` for the case ``LABEL`` of a study with several cases, the plain ``NAME`` too when
there is one case; see each study's documentation), with their units (``Study.fact_units``); a study
with a fast campaign path (``Study.point``, e.g. simulate's facts without its time series) runs it.
"""
from __future__ import annotations

import contextlib
import signal
import threading
import time
import traceback


class UnknownFact(KeyError):
    """An output name that is not a fact of the run (``fact``)."""

    def __init__(self, message: str, fact: str):
        super().__init__(message)
        self.fact = fact

    def __str__(self) -> str:  # the message itself (a KeyError's str() is its repr, in quotes)
        return str(self.args[0])


def run_point(config, wanted=None, keep: bool = False) -> tuple[dict, object]:
    """Run one point's study: ``(facts, frame or None)``; ``wanted`` the fact names needed (None: all),
    ``keep``: the study's primary frame too."""
    from tirecli.studies import registry

    plan = registry.plan(config)
    study = registry.get(plan.study)
    if study.point is not None:
        with registry.formulas_located(config):
            facts, frame = study.point(plan, wanted, keep)
    else:
        result = registry.run(plan)
        facts = study.facts(result)
        frame = None
        if keep and result.data:
            frame = result.data[study.primary_frame or next(iter(result.data))]
    if wanted is not None:
        missing = [w for w in wanted if w not in facts]
        if missing:
            import difflib

            facts = run_point(config)[0]  # every fact, to name them

            hint = difflib.get_close_matches(missing[0], list(facts), n=1)
            raise UnknownFact(f"no fact named {missing[0]!r}" + (f"; did you mean {hint[0]!r}?" if hint else "")
                           + f" (facts of this run: {', '.join(list(facts)[:30])}{' ...' if len(facts) > 30 else ''})", missing[0])
        facts = {w: facts[w] for w in wanted}
    return facts, frame


def error_text(exc: BaseException) -> str:
    """One line for a failed point: the message of a tirecli error, else the type and message."""
    from tirecli.errors import TirecliError

    msg = str(exc).strip().splitlines()
    text = msg[0] if msg else ""
    if isinstance(exc, (TirecliError, PointTimeout, UnknownFact)):
        return text or type(exc).__name__
    if isinstance(exc, KeyError):
        text = str(exc.args[0]) if exc.args else text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class PointTimeout(Exception):
    """A point ran longer than the campaign's ``timeout``."""


@contextlib.contextmanager
def _time_limit(seconds):
    """Raise :class:`PointTimeout` in the block after ``seconds`` of wall time (an interval timer:
    only in a process's main thread, so not on Dask workers, which run tasks in threads)."""
    if not seconds or threading.current_thread() is not threading.main_thread() or not hasattr(signal, "setitimer"):
        yield
        return

    def expire(signum, frame):
        raise PointTimeout(f"timeout: the point ran longer than {seconds:g} s (campaign timeout:)")

    old = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


def run_batch(payload, batch) -> list:
    """Run the points of ``batch`` (``[(index, id, overrides), ...]``) of a campaign whose shared part
    is ``payload`` (``{"base", "fixed", "outputs", "keep"}``); a record per point, a failure recorded
    with its error (the campaign goes on)."""
    from tirecli.campaign.spec import point_config

    out = []
    for index, pid, overrides in batch:
        t0 = time.perf_counter()
        rec = {"point": index, "id": pid, "status": "ok", "error": "", "facts": {}, "frame": None}
        try:
            with _time_limit(payload.get("timeout")):
                cfg = point_config(payload["base"], payload["fixed"] + overrides)
                rec["facts"], rec["frame"] = run_point(cfg, payload["outputs"], payload["keep"])
        except Exception as exc:  # noqa: BLE001 - a failing point is recorded, the campaign goes on
            rec.update(status="failed", error=error_text(exc), trace=traceback.format_exc(limit=6),
                       unknown=getattr(exc, "fact", None))
        rec["seconds"] = time.perf_counter() - t0
        out.append(rec)
    return out


def column_units(campaign, study: str) -> dict:
    """``{column: unit}`` of the results' varied inputs of ``campaign`` (a
    :class:`~tirecli.campaign.spec.Campaign`; units from the base study's config schema and parameter
    sets) and outputs (the study's fact units) whose unit is known."""
    from tirecli.parameters.kinds import unit_at
    from tirecli.studies import registry
    from tirecli.studies.facts import fact_unit

    entry = registry.get(study)
    units = {k: unit_at(entry.spec, campaign.overrides[k][0]) for k in campaign.design.keys}
    units.update({o: fact_unit(entry, o) for o in campaign.outputs})
    return {k: u for k, u in units.items() if u}


__all__ = ["UnknownFact", "run_point", "run_batch", "column_units", "error_text"]
