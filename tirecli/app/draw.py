"""The draw-and-check loop: a result's figures drawn, and the reference checks of those asked for.

One loop (:func:`draw_figures`) for the run commands (:func:`draw`: an error stops the run) and for the
report (each figure a card: an error is the card's, recorded as a failed check). A figure's checks are
its study's (``Study.checks``, :mod:`tirecli.studies.registry`); figures only draw
(:mod:`tirecli.figures.registry`).
"""
from __future__ import annotations

import traceback
from dataclasses import dataclass, field
from typing import Any, Callable, Iterator

from tirecli.errors import UsageError
from tirecli.figures import registry as figures
from tirecli.studies import registry as studies
from tirecli.studies.base import Check, StudyResult


@dataclass
class Drawn:
    """One figure of a result: the drawn figure (a matplotlib Figure or a
    :class:`~tirecli.figures.registry.Table`; None when it failed), its checks (ids ``FIGURE/CHECK``), and
    the error (type, message and traceback) when it could not be drawn or checked."""

    id: str
    figure: Any = None
    checks: list = field(default_factory=list)
    error: str | None = None


def listed_figures(result: StudyResult) -> list:
    """The figure ids the result's config lists under ``figures:`` (empty without a config or the key)."""
    listed = result.config.data.get("figures") if result.config is not None else None
    return list(listed) if isinstance(listed, list) else []


def figure_checks(result: StudyResult, figure_id: str) -> list[Check]:
    """The reference checks of figure ``figure_id`` on ``result`` (its study's), ids ``FIGURE/CHECK``."""
    fn = studies.get(result.study).checks_for(figure_id)
    out = list(fn(result)) if fn is not None else []
    for c in out:
        c.id = f"{figure_id}/{c.id}"
    return out


def draw_figures(result: StudyResult, ids, asked=None, catch: bool = False,
                 before: Callable[[str], None] | None = None) -> Iterator[Drawn]:
    """Draw the figures ``ids`` of ``result`` one by one, with the checks of those in ``asked`` (default:
    all of ``ids``).

    A figure's checks compare the run with what the paper shows for *its* scenario, so they run only for
    figures asked for by name. ``catch``: an error drawing or checking a figure is the figure's (its
    :class:`Drawn` has the error and a failed check ``figure-drawn``; the report's cards); otherwise it
    is raised, a figure of another kind of run as a problem at its place in the config's ``figures:``.
    ``before(id)`` is called before each figure.
    """
    asked = set(ids) if asked is None else set(asked)
    for fid in ids:
        if before is not None:
            before(fid)
        if not catch:
            fdef = figures.get(fid)
            try:
                fig = fdef.draw(result)
            except UsageError as exc:  # a figure of another kind of run: name the config line
                raise _figure_problem(result, fid, exc) from None
            yield Drawn(fid, fig, figure_checks(result, fid) if fid in asked else [])
            continue
        try:
            fig = figures.get(fid).draw(result)
            checks = figure_checks(result, fid) if fid in asked else []
        except Exception as exc:  # noqa: BLE001 - an error card and a failed check
            failed = Check("figure-drawn", f"figure {fid} drawn", float("nan"), 0.0, 0.0, "-", "report")
            failed.id = f"{fid}/{failed.id}"
            yield Drawn(fid, None, [failed], f"{type(exc).__name__}: {exc}\n" + traceback.format_exc(limit=4))
            continue
        yield Drawn(fid, fig, checks)


def draw(result: StudyResult, ids=None, progress=None) -> tuple[dict, list]:
    """Draw the figures ``ids`` (default: the result's) of a run: ``({id: figure}, checks)``.

    The checks are those of the figures asked for by name: ``ids`` given, or listed under the config's
    ``figures:`` (every built-in paper config lists its figures). A custom config without ``figures:``
    gets the study's default figures and its own facts, and no paper checks.
    """
    asked = set(ids) if ids else set(listed_figures(result))
    ids = list(ids or result.figures)
    figs, checks = {}, []
    if progress is not None:
        progress.start(len(ids), "figures")
    try:
        for d in draw_figures(result, ids, asked):
            figs[d.id] = d.figure
            checks += d.checks
            if progress is not None:
                progress.advance(1)
    finally:
        if progress is not None:
            progress.close()
    return figs, checks


def checks_of(result: StudyResult, ids=None) -> list[Check]:
    """The reference checks :func:`draw` finds, without drawing: those of the figures asked for by name
    (``ids``, else the config's ``figures:``) among the result's."""
    asked = set(ids) if ids else set(listed_figures(result))
    return [c for fid in list(ids or result.figures) if fid in asked for c in figure_checks(result, fid)]


def _figure_problem(result: StudyResult, fid: str, exc: UsageError) -> UsageError:
    """The error of figure ``fid`` at its place in the config's ``figures:`` list, if it is there."""
    from tirecli.errors import ConfigError

    listed = listed_figures(result)
    if fid in listed:
        return ConfigError(result.config.origins.problem(("figures", listed.index(fid)), f"{fid}: {exc}"))
    return UsageError(f"figure {fid}: {exc}" if fid not in str(exc) else str(exc))


def close_figures(figs: dict) -> None:
    """Release the drawn figures' memory."""
    for fig in figs.values():
        if hasattr(fig, "clf"):
            fig.clf()


__all__ = ["Drawn", "draw", "draw_figures", "figure_checks", "checks_of", "listed_figures", "close_figures"]
