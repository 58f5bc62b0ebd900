"""Gaps between a model curve and a reference curve over a drawn range (the numbers a comparison states).

A comparison figure draws two curves over one range, e.g. MCPS and a Magic Formula tyre's
``Fy(alpha)`` at ``alpha`` in 0-12 deg. :func:`curve_gap` reduces the pair to the numbers the
project states with every comparison: the largest absolute gap and where it occurs, the RMS gap over
the drawn points, and both relative to the reference's peak magnitude. Pure functions of arrays, in
the units of the curves (N, N m; the abscissa in its own unit: slip [-], slip angle [rad], Fx [N]).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np


@dataclass(frozen=True)
class CurveGap:
    """Gap of a model curve to a reference curve over the drawn points.

    Attributes
    ----------
    max : float
        Largest ``|model - reference|`` over the points [unit of the curves].
    at : float
        Abscissa of the largest gap (the first one when several points tie) [unit of the abscissa].
    model, reference : float
        The two curves' values at ``at``.
    rms : float
        Root mean square of ``model - reference`` over the points (equal weights: the drawn grids
        are even).
    peak : float
        Peak magnitude of the reference, ``max |reference|`` over the points unless given.
    max_rel, rms_rel : float
        ``max / peak`` and ``rms / peak`` [-] (inf when ``peak`` is 0).
    points : int
        Points compared.
    skipped : int
        Reference points outside the model's abscissa range (only with ``model_x``); not compared.
    """

    max: float
    at: float
    model: float
    reference: float
    rms: float
    peak: float
    max_rel: float
    rms_rel: float
    points: int
    skipped: int = 0

    def as_dict(self) -> dict:
        """Plain floats and ints by name (run.json facts)."""
        return asdict(self)


def curve_gap(x, model, reference, *, model_x=None, peak: float | None = None) -> CurveGap:
    """Gap of ``model`` to ``reference`` over the drawn points.

    Parameters
    ----------
    x : array_like, shape (n,)
        Abscissa of the reference points (slip, slip angle, Fx ...).
    model : array_like
        The model curve: at ``x`` (shape (n,)), or at ``model_x`` when given.
    reference : array_like, shape (n,)
        The reference curve at ``x``.
    model_x : array_like or None
        Abscissa of the model points when it differs from ``x`` (e.g. ``Fy`` against ``Fx``, where
        each model has its own ``Fx``): strictly monotone; the model is interpolated linearly onto
        the reference points inside its range, and points outside are skipped (counted).
    peak : float or None
        Reference peak magnitude for the relative gaps (default ``max |reference|`` over the points
        compared).

    Returns
    -------
    CurveGap

    Raises
    ------
    ValueError
        Shapes that do not match, a non-finite value, no point to compare, or a ``model_x`` that is
        not strictly monotone.
    """
    x = np.asarray(x, dtype=float).ravel()
    ref = np.asarray(reference, dtype=float).ravel()
    mod = np.asarray(model, dtype=float).ravel()
    if ref.shape != x.shape:
        raise ValueError(f"reference has {ref.size} points, its abscissa {x.size}")
    skipped = 0
    if model_x is not None:
        mx = np.asarray(model_x, dtype=float).ravel()
        if mx.shape != mod.shape:
            raise ValueError(f"model has {mod.size} points, its abscissa {mx.size}")
        if not (np.all(np.isfinite(mx)) and np.all(np.isfinite(mod))):
            raise ValueError("the model curve is not finite")
        d = np.diff(mx)
        if mx.size < 2 or not (np.all(d > 0) or np.all(d < 0)):
            raise ValueError("model_x must be strictly monotone (at least two points)")
        if d[0] < 0:
            mx, mod = mx[::-1], mod[::-1]
        inside = (x >= mx[0]) & (x <= mx[-1])
        skipped = int(np.count_nonzero(~inside))
        x, ref = x[inside], ref[inside]
        mod = np.interp(x, mx, mod)
    elif mod.shape != x.shape:
        raise ValueError(f"model has {mod.size} points, the reference {x.size}")
    if x.size == 0:
        raise ValueError("no point to compare")
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(ref)) and np.all(np.isfinite(mod))):
        raise ValueError("the curves are not finite")
    diff = mod - ref
    i = int(np.argmax(np.abs(diff)))
    pk = float(np.max(np.abs(ref))) if peak is None else float(abs(peak))
    mx_gap = float(abs(diff[i]))
    rms = float(np.sqrt(np.mean(diff * diff)))
    rel = (lambda v: v / pk) if pk > 0 else (lambda v: float("inf") if v > 0 else 0.0)
    return CurveGap(max=mx_gap, at=float(x[i]), model=float(mod[i]), reference=float(ref[i]), rms=rms, peak=pk,
                    max_rel=float(rel(mx_gap)), rms_rel=float(rel(rms)), points=int(x.size), skipped=skipped)


__all__ = ["CurveGap", "curve_gap"]
