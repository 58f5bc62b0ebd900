"""Reference checks, by figure id: what a result must show against the values of ``docs/models/``.

A check function takes a :class:`~tirecli.studies.base.StudyResult` and returns a list of
:class:`~tirecli.studies.base.Check`; it computes what it needs from the result (frames, meta,
payload, parameter sets) and may call models and solvers. Figures draw only; the commands and the
report draw a figure, then run the checks registered under its id (:func:`checks_for`).

One module per family of figures (``steady``, ``transient``, ``identification``, ``observer``,
``magic_formula``, ``mcps``), imported on demand. A module imports at its top only what is cheap
(numpy, :mod:`tirecli.studies.base`): the lookup of a figure without checks imports the modules of
:data:`CHECK_MODULES` that own no prefix.
"""
from __future__ import annotations

import importlib
from typing import Callable

#: Figure id -> ``checks(result) -> list[Check]``.
CHECKS: dict[str, Callable] = {}

#: The modules that register checks, in the order :func:`checks_for` searches them.
CHECK_MODULES = ("steady", "transient", "identification", "observer", "magic_formula", "mcps")
#: Figure-id prefixes owned by one module: only it registers (and is searched for) such ids, and it
#: registers no others (an MCPS or Magic Formula run imports no LuGre check code, and the reverse).
PREFIX_MODULES = {"mf-": "magic_formula", "mcps-": "mcps"}


def _owner(figure_id: str) -> str | None:
    return next((m for prefix, m in PREFIX_MODULES.items() if figure_id.startswith(prefix)), None)


def register_checks(figure_id: str):
    """Decorator registering ``fn(result) -> list[Check]`` as the reference checks of figure ``figure_id``."""

    def deco(fn: Callable) -> Callable:
        if figure_id in CHECKS:
            raise ValueError(f"checks of figure {figure_id!r} registered twice")
        module = fn.__module__.rsplit(".", 1)[-1]
        owner = _owner(figure_id)
        if owner is not None and module != owner:
            raise ValueError(f"checks of figure {figure_id!r} belong in {__name__}.{owner}, not {fn.__module__}")
        if owner is None and module in PREFIX_MODULES.values():
            raise ValueError(f"{fn.__module__} registers checks of '{module}' figures only, not of {figure_id!r}")
        CHECKS[figure_id] = fn
        return fn

    return deco


def checks_for(figure_id: str) -> Callable | None:
    """The reference checks of figure ``figure_id`` (None if it has none), importing the check modules
    that may hold them: the module owning the id's prefix, else those owning no prefix, in order."""
    if figure_id not in CHECKS:
        owner = _owner(figure_id)
        names = [owner] if owner else [m for m in CHECK_MODULES if m not in PREFIX_MODULES.values()]
        for name in names:
            importlib.import_module(f"{__name__}.{name}")
            if figure_id in CHECKS:
                break
    return CHECKS.get(figure_id)


def load_all() -> dict[str, Callable]:
    """Import every check module (registering its checks) and return the registry."""
    for name in CHECK_MODULES:
        importlib.import_module(f"{__name__}.{name}")
    return CHECKS
