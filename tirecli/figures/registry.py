"""The figure registry: every paper figure (and generic plot) as a registered function.

A figure function draws from a :class:`~tirecli.studies.base.StudyResult` and returns a
matplotlib ``Figure`` (or a :class:`Table`); it never saves and checks nothing (a figure's
reference checks are listed under its id by its study's registry entry, ``Study.checks``). Commands
draw the figures a result asks for (:mod:`tirecli.app.draw`); ``tirecli report`` runs each entry's
study config and draws them all.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable


@dataclass
class Table:
    """A table figure (e.g. a paper's parameter table): column names and rows of cells."""

    columns: list
    rows: list
    notes: list = field(default_factory=list)


def with_table(fig, table: Table):
    """A matplotlib figure that carries a :class:`Table` for its card: the report shows the table under the
    image (e.g. the numbers marked on the curves). Returns ``fig``."""
    fig.card_table = table
    return fig


def card_table(fig) -> Table | None:
    """The table of a drawn figure: the figure itself when it is a :class:`Table`, else the one it carries
    (:func:`with_table`), else None."""
    return fig if isinstance(fig, Table) else getattr(fig, "card_table", None)


@dataclass(frozen=True)
class FigureDef:
    """A registered figure.

    Attributes
    ----------
    id : str
        Identifier, e.g. ``fm-fig1-left``.
    paper : str
        ``FM``, ``OBS``, ``MF`` (Magic Formula), ``MCPS`` or ``generic``.
    label : str
        The paper's numbering, e.g. ``Fig. 1 (left)``.
    title : str
        Short title.
    caption : str or callable
        Caption in our words (what is plotted, parameters, assumptions); a callable
        ``caption(result) -> str`` describes the run at hand (its tyre, loads, scenario) and is called
        with ``None`` where no run exists. Read it with :meth:`caption_for`.
    paper_shows : str
        What the paper's figure shows, for the side-by-side reading in the report.
    study : str or None
        Built-in study config (``tirecli/studies/configs/NAME.yaml``) the report runs.
    draw : callable
        ``draw(result) -> Figure | Table``.
    order : int
        Position within its paper's section of the report.
    """

    id: str
    paper: str
    label: str
    title: str
    caption: str
    paper_shows: str
    study: str | None
    draw: Callable
    order: int = 0

    def caption_for(self, result=None) -> str:
        """The caption, for ``result`` when the caption depends on the run."""
        return self.caption(result) if callable(self.caption) else self.caption


REGISTRY: dict[str, FigureDef] = {}

PAPERS = {
    "FM": "Canudas-de-Wit, Tsiotras, Velenis, Basset, Gissinger: Dynamic friction models for "
          "longitudinal road/tire interaction, experimental results",
    "OBS": "Canudas-de-Wit, Petersen, Shiriaev: A new nonlinear observer for tire/road distributed "
           "contact friction (IEEE CDC 2003)",
    "MF": "Magic Formula tyre model (Pacejka; MF 6.1 / 5.2 / PAC89) with public .tir files",
    "MCPS": "Sorine, Szymanski: A new dynamic multi-D.O.F. tire model (IFAC Control in Transportation "
            "Systems 2000), against the Magic Formula",
    "generic": "Generic plots for any config",
}


def register(id: str, *, paper: str, label: str, title: str, caption, paper_shows: str = "",
             study: str | None = None, order: int = 0):
    """Decorator registering a draw function as figure ``id``."""

    def deco(fn: Callable) -> Callable:
        if id in REGISTRY:
            raise ValueError(f"figure {id!r} registered twice")
        REGISTRY[id] = FigureDef(id=id, paper=paper, label=label, title=title, caption=caption,
                                 paper_shows=paper_shows, study=study, draw=fn, order=order)
        return fn

    return deco


#: The modules that register figures, in the order ``get`` searches them (the LuGre steady-state
#: figures first: a sweep then imports nothing else, which keeps ``tirecli sweep`` start-up short).
FIGURE_MODULES = ("steady", "transient", "identification", "observer", "magic_formula", "mf_fit", "mcps", "relaxation")
#: Figure-id prefixes whose module ``get`` tries first (an MCPS run imports no LuGre figure code).
PREFIX_MODULES = {"mcps-": "mcps", "mf-fit-": "mf_fit", "relaxation-": "relaxation"}


def load_all() -> dict[str, FigureDef]:
    """Import every figure module (registering them) and return the registry."""
    import importlib

    for name in FIGURE_MODULES:
        importlib.import_module(f"tirecli.figures.{name}")
    return REGISTRY


def get(id: str) -> FigureDef:
    """A registered figure; ``UsageError`` with a did-you-mean if unknown.

    Figure modules are imported in the order of :data:`FIGURE_MODULES` until ``id`` is found.
    """
    import difflib
    import importlib

    from tirecli.errors import UsageError

    first = [m for prefix, m in PREFIX_MODULES.items() if id.startswith(prefix)]
    for name in first + [m for m in FIGURE_MODULES if m not in first]:
        if id in REGISTRY:
            break
        importlib.import_module(f"tirecli.figures.{name}")
    if id not in REGISTRY:
        hint = difflib.get_close_matches(id, list(REGISTRY), n=1)
        dym = f"; did you mean {hint[0]!r}?" if hint else ""
        raise UsageError(f"unknown figure {id!r}{dym} (see 'tirecli figures list')")
    return REGISTRY[id]
