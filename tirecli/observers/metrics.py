"""Metrics of an observer run (docs/models/observer_model.md §7-§8): tracking error per phase, settling, excitation.

Pure functions of arrays; times in s, speeds in m/s, adhesion in the OBS convention.
"""
from __future__ import annotations

import numpy as np


def time_weights(t) -> np.ndarray:
    """Trapezoid weights of a (possibly non-uniform) time grid [s]; they sum to ``t[-1] - t[0]``."""
    t = np.asarray(t, dtype=float)
    if len(t) < 2:
        return np.ones_like(t)
    dt = np.diff(t)
    w = np.zeros_like(t)
    w[:-1] += 0.5 * dt
    w[1:] += 0.5 * dt
    return w


def zero_crossings(t, x, skip_start: float = 0.0) -> np.ndarray:
    """Times [s] where ``x`` changes sign strictly (linear interpolation), after ``skip_start``.

    A start from exactly 0 (pure rolling, ``v_r(0) = 0``) is not a crossing.
    """
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    nz = np.flatnonzero(x != 0.0)
    if len(nz) < 2:
        return np.empty(0)
    xs, ts = x[nz], t[nz]
    i = np.flatnonzero(np.sign(xs[:-1]) != np.sign(xs[1:]))
    tc = ts[i] - xs[i] * (ts[i + 1] - ts[i]) / (xs[i + 1] - xs[i])
    return tc[tc > skip_start]


def _stats(err, w, sel):
    if not np.any(sel) or w[sel].sum() <= 0:
        return float("nan"), float("nan")
    return float(np.sqrt(np.sum(w[sel] * err[sel] ** 2) / np.sum(w[sel]))), float(np.max(np.abs(err[sel])))


def phase_errors(t, err, phases, crossings=(), margin: float = 0.5) -> list[dict]:
    """RMS and max of ``err`` on each phase ``[phases[i], phases[i+1])``, also without ``+-margin`` around crossings.

    Returns one dict per phase: ``start, end, rms, max, rms_excl, max_excl`` (the last phase
    includes its end point).
    """
    t, err = np.asarray(t, dtype=float), np.asarray(err, dtype=float)
    w = time_weights(t)
    keep = np.ones(len(t), dtype=bool)
    for tc in crossings:
        keep &= np.abs(t - tc) > margin
    out = []
    for k, (a, b) in enumerate(zip(phases[:-1], phases[1:])):
        sel = (t >= a) & ((t < b) if k < len(phases) - 2 else (t <= b))
        rms, mx = _stats(err, w, sel)
        rms_x, mx_x = _stats(err, w, sel & keep)
        out.append({"start": float(a), "end": float(b), "rms": rms, "max": mx, "rms_excl": rms_x, "max_excl": mx_x})
    return out


def settle_times(t, err, changes, tol: float = 0.05, end: float | None = None) -> list[dict]:
    """Time after each change until ``|err| < tol`` for good (until the next change or the end).

    ``changes`` are the start times [s] of the adhesion changes (and 0 for an initial error).
    Returns ``at`` (change time), ``settled_at`` (absolute time, None if never settled) and
    ``time`` (= settled_at - at; 0 when the error never left the band).
    """
    t, err = np.asarray(t, dtype=float), np.abs(np.asarray(err, dtype=float))
    end = float(t[-1]) if end is None else end
    bounds = list(changes) + [end]
    out = []
    for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:])):
        sel = (t >= a) & ((t < b) if k < len(bounds) - 2 else (t <= b))
        ts, es = t[sel], err[sel]
        if len(ts) == 0:
            out.append({"at": float(a), "settled_at": None, "time": None})
            continue
        outside = np.flatnonzero(es >= tol)
        if len(outside) == 0:
            out.append({"at": float(a), "settled_at": float(a), "time": 0.0})
        elif outside[-1] == len(ts) - 1:
            out.append({"at": float(a), "settled_at": None, "time": None})
        else:
            i = outside[-1]
            # interpolate the last exit from the band
            e0, e1 = es[i], es[i + 1]
            tt = ts[i] + (e0 - tol) / (e0 - e1) * (ts[i + 1] - ts[i]) if e0 != e1 else ts[i + 1]
            out.append({"at": float(a), "settled_at": float(tt), "time": float(tt - a)})
    return out


def excitation_share(t, vr, threshold: float) -> float:
    """Share of time [-] with ``|v_r| > threshold`` (A4 needs v_r != 0 persistently)."""
    w = time_weights(t)
    return float(np.sum(w * (np.abs(np.asarray(vr, dtype=float)) > threshold)) / max(np.sum(w), 1e-300))


def decay_rate(t, x, t0: float, t1: float) -> float:
    """Exponential rate [1/s] of ``|x|`` between ``t0`` and ``t1`` (least squares on ``log |x|``)."""
    t, x = np.asarray(t, dtype=float), np.abs(np.asarray(x, dtype=float))
    sel = (t >= t0) & (t <= t1) & (x > 0)
    if sel.sum() < 2:
        return float("nan")
    return float(np.polyfit(t[sel], np.log(x[sel]), 1)[0])
