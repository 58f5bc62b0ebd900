"""The Magic Formula at given points: the one evaluation behind ``tirecli mf eval --points CSV`` and the
``mf-eval`` study (:mod:`tirecli.studies.mf_eval`).

A point is ``kappa, alpha, gamma, fz`` (ISO-W, SI) with optional ``p`` [Pa] and ``vx`` [m/s]; a point
without them takes the tyre's defaults (:func:`point_defaults`). :func:`evaluate_points` gives the forces
and moments (``fx, fy, mz, mx, my``) and mfeval's further outputs the tyre's coefficients give
(:data:`EXTRA_COLUMNS`, docs/models/magic_formula_tyre.md §17), and raises :class:`PointError` at the
first point with a non-finite output: a result never holds an empty cell.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The inputs of a point (``p``, ``vx`` optional) and its outputs, ISO-W, SI.
INPUT_COLUMNS = ("kappa", "alpha", "gamma", "fz", "p", "vx")
OUTPUT_COLUMNS = ("fx", "fy", "mz", "mx", "my")
#: mfeval's further outputs, after the forces where the tyre gives them (docs/models/magic_formula_tyre.md §17).
EXTRA_COLUMNS = ("sigmax", "sigmay", "Kxk", "Kya", "Cx", "Cy", "Cz", "re", "a", "b")
#: The unit of every output.
UNITS = {"fx": "N", "fy": "N", "mz": "N m", "mx": "N m", "my": "N m", "sigmax": "m", "sigmay": "m", "Kxk": "N",
         "Kya": "N/rad", "Cx": "N/m", "Cy": "N/m", "Cz": "N/m", "re": "m", "a": "m", "b": "m"}


class PointError(Exception):
    """No finite output at a point: ``index`` (0-based), ``text`` (which outputs, the point's inputs, why)
    and ``at_fault`` (True: an input beyond what the tyre can evaluate; False: the tyre's coefficients)."""

    def __init__(self, index: int, text: str, at_fault: bool):
        super().__init__(text)
        self.index, self.text, self.at_fault = index, text, at_fault


def point_defaults(tire) -> tuple[float | None, float | None]:
    """``(p, vx)`` of a point that gives none: the tyre's INFLPRES, else NOMPRES [Pa] (None for a tyre
    without a pressure model), and LONGVL [m/s] (None when the tyre gives none)."""
    return (tire.default_pressure if tire.nominal_pressure else None), tire.reference_speed


def needs_speed(tire, vx) -> bool:
    """Whether points without speeds (``vx`` None) lack one: a Magic Formula tyre without LONGVL."""
    return vx is None and tire.family == "mf" and tire.reference_speed is None


@dataclass
class Points:
    """The outputs at the points (:func:`evaluate_points`).

    Attributes
    ----------
    p, vx : ndarray, float or None
        The pressure and speed evaluated: the points' own, else the default (a number), else None.
    p_default, vx_default : float or None
        The defaults used, None where the points gave the column (or the tyre has none).
    result : MFResult
        ``fx, fy, mz, mx, my`` and the rule counts (:func:`tirecli.models.magic_formula.evaluate`).
    extras : dict
        ``{name: array}`` of the :data:`EXTRA_COLUMNS` the tyre gives, in that order.
    omitted : dict
        ``{name: what it needs}`` of those it does not give.
    """

    p: object
    vx: object
    p_default: float | None
    vx_default: float | None
    result: object
    extras: dict
    omitted: dict

    def outputs(self) -> dict:
        """``{name: array}``: the forces and moments, then the extras."""
        return {**{k: getattr(self.result, k) for k in OUTPUT_COLUMNS}, **self.extras}


def evaluate_points(tire, cols: dict, convention: str = "mfeval", side: str | None = None, limits: bool = True,
                    threads: int | None = None, extras: bool = True) -> Points:
    """The Magic Formula ``tire`` at the points ``cols`` (``{kappa, alpha, gamma, fz[, p, vx]: array}``).

    ``p``/``vx`` missing (or None) take :func:`point_defaults`; the caller checks :func:`needs_speed`
    first. :class:`PointError` at the first point where an output (or, with ``extras``, an extra output)
    is not finite.
    """
    from tirecli.models.magic_formula import evaluate
    from tirecli.models.magic_formula.engine import nonfinite_point

    p_def, vx_def = point_defaults(tire)
    p_in, vx_in = cols.get("p"), cols.get("vx")
    p = p_in if p_in is not None else p_def
    vx = vx_in if vx_in is not None else vx_def
    res = evaluate(tire, cols["kappa"], cols["alpha"], cols["gamma"], cols["fz"], vx, p,
                   convention=convention, side=side, limits=limits, threads=threads)
    found = nonfinite_point(tire, res, {"kappa": cols["kappa"], "alpha": cols["alpha"], "gamma": cols["gamma"],
                                        "fz": cols["fz"], "vx": vx, "p": p}, limits)
    if found is not None:
        raise PointError(*found)
    more, omitted = _extra_columns(tire, cols, vx, p, res, convention, side, limits) if extras else ({}, {})
    return Points(p, vx, p_def if p_in is None else None, vx_def if vx_in is None else None, res, more, omitted)


def _extra_columns(tire, cols, vx, p, res, convention, side, limits) -> tuple[dict, dict]:
    """The :data:`EXTRA_COLUMNS` the tyre gives at the points (``{name: array}``), and the omitted ones
    with what they need (``{name: reason}``); :class:`PointError` at a non-finite value."""
    from tirecli.models.magic_formula.axes import needs_mirror
    from tirecli.models.magic_formula.extras import available, evaluate_extras, missing_reason

    have = available(tire)
    omitted = {k: missing_reason(tire, k) for k in EXTRA_COLUMNS if not have[k]}
    gamma = cols["gamma"]
    if needs_mirror(tire.side, side):  # the file's side: every extra is even in gamma, Cz in (Fy, gamma)
        gamma = -gamma
    ext = evaluate_extras(tire, cols["kappa"], cols["alpha"], gamma, cols["fz"], vx, p, fx=res.fx,
                          fy=-res.fy if res.mirrored else res.fy, convention=convention, limits=limits)
    for k, v in ext.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise PointError(int(bad[0]), f"the tyre's coefficients give no finite {k} there ({bad.size} row(s))", False)
    return ext, omitted


__all__ = ["evaluate_points", "point_defaults", "needs_speed", "Points", "PointError", "INPUT_COLUMNS",
           "OUTPUT_COLUMNS", "EXTRA_COLUMNS", "UNITS"]
