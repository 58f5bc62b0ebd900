"""Reading a sweep result (:mod:`tirecli.studies.sweep`): one curve of its ``sweep`` frame and that
curve's root-found peak in its ``peaks`` frame. Used by the sweep figures and their reference checks;
cheap to import (numpy only).
"""
from __future__ import annotations

import numpy as np

#: Rows compared at a time by :func:`curve` (a large sweep's frame is not copied per curve).
_SELECT_BLOCK = 65536


def curve(df, model=None, speed=None, theta=None, direction="braking"):
    """``(|s|, |mu|)`` of one curve of a sweep frame, sorted by ``|s|``."""
    sel = (df["direction"] == direction).to_numpy(dtype=bool, copy=True)
    if model is not None:
        sel &= (df["model"] == model).to_numpy()
    for col, value in (("speed", speed), ("theta", theta)):
        if value is not None:  # np.isclose(column, value), a block at a time (no temporaries as long as the frame)
            x, tol = df[col].to_numpy(), 1e-8 + 1e-5 * abs(value)
            for lo in range(0, x.size, _SELECT_BLOCK):
                sel[lo:lo + _SELECT_BLOCK] &= np.abs(x[lo:lo + _SELECT_BLOCK] - value) <= tol
    s = np.abs(df["slip"].to_numpy()[sel])  # only the two columns drawn are selected (large sweeps)
    mu = np.abs(df["mu"].to_numpy()[sel])
    order = np.argsort(s, kind="stable")
    return s[order], mu[order]


def curve_peak(result, model, speed, theta=1.0, direction="braking"):
    """``(|s|, |mu|, |mu(1)|)`` of one curve's root-found peak (``data/peaks.csv``), or None.

    The peak is found on the model function (:mod:`tirecli.models.steady_peaks`), not on the
    sweep's grid; ``|mu(1)|`` is the sliding level at ``|s| = 1``.
    """
    pk = result.data.get("peaks")
    if pk is None or pk.empty:
        return None
    sel = ((pk["model"] == model) & np.isclose(pk["speed"], speed) & np.isclose(pk["theta"], theta)
           & (pk["direction"] == direction))
    if not sel.any():
        return None
    r = pk[sel].iloc[0]
    return abs(float(r["slip_peak"])), abs(float(r["mu_peak"])), abs(float(r["mu_slide"]))


def first_model(df):
    """The label of the first model of a sweep frame (the paper figures draw it)."""
    return df["model"].iloc[0]
