"""Input limits and low-speed handling of the Magic Formula (docs/models/magic_formula_tyre.md §11, mfeval's logic).

Two switches, both on by default as in mfeval:

``limits``
    Inputs are clipped to the tyre's ranges (``FZMIN..FZMAX`` with ``Fz >= 0``, ``KPUMIN..KPUMAX``,
    ``ALPMIN..ALPMAX``, ``CAMMIN..CAMMAX``, ``PRESMIN..PRESMAX``; an absent bound is no limit). The
    trail and residual torque use ``Fz`` raised to ``FZMIN``; ``Mx`` and ``My`` scale ``Fz`` by
    ``(Fz/FZMIN)^2`` and ``Fz/FZMIN`` below ``FZMIN``. With turn slip, ``phi_t`` is multiplied by
    ``cos(alpha)`` (mfeval, found empirically to match TNO).
``low_speed``
    For ``|Vx| <= VXLOW``: the shifts, trail and residual torque are multiplied by the smooth
    factor ``1 - (1 + cos(pi Vx/VXLOW))/2``; ``kappa`` and ``phi_t`` by ``|Vx|/VXLOW``; ``alpha`` by
    ``(|Vx| + |V_sy|)/VXLOW`` where that sum is below ``VXLOW``. ``My`` is ramped by a sine in
    ``kappa`` near the locked wheel (between ``-1 - VXLOW - h`` and ``h = VXLOW/|Vx| - 1``) and
    flipped below that window. Without ``VXLOW`` in the tyre there is no low-speed handling.

Negative loads are always raised to 0 (``Fz`` is a compression). :func:`prepare` reports, per
category, how many points each rule touched. One simplification against mfeval: ``My`` uses
the clipped load (mfeval uses the unclipped one above ``FZMAX``).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

#: Names of the counters of :func:`prepare`, with what each counts.
COUNTERS = {
    "fz_negative": "negative loads raised to 0",
    "fz": "loads clipped to [FZMIN, FZMAX] (0 below)",
    "kappa": "slips clipped to [KPUMIN, KPUMAX]",
    "alpha": "slip angles clipped to [ALPMIN, ALPMAX]",
    "gamma": "inclinations clipped to [CAMMIN, CAMMAX]",
    "p": "pressures clipped to [PRESMIN, PRESMAX]",
    "fz_low": "loads below FZMIN (trail, residual torque, Mx, My use the low-load rules)",
    "low_speed": "points with |Vx| <= VXLOW (shifts, kappa, trail reduced)",
    "alpha_low_speed": "slip angles reduced because |Vx| + |Vsy| < VXLOW",
    "my_standstill": "points where My is ramped or flipped near the locked wheel",
}


#: Names of the counters of :func:`outside_ranges`: inputs evaluated outside the tyre's ranges.
OUTSIDE = {
    "fz": "loads outside [FZMIN, FZMAX], evaluated anyway (limits off: extrapolated)",
    "kappa": "slips outside [KPUMIN, KPUMAX], evaluated anyway (limits off: extrapolated)",
    "alpha": "slip angles outside [ALPMIN, ALPMAX], evaluated anyway (limits off: extrapolated)",
    "gamma": "inclinations outside [CAMMIN, CAMMAX], evaluated anyway (limits off: extrapolated)",
    "p": "pressures outside [PRESMIN, PRESMAX], evaluated anyway (limits off: extrapolated)",
    "fz_extreme": "loads above 10 x FNOMIN with no FZMAX in the tyre (far beyond any fit: extrapolated)",
}


def outside_ranges(t, vals, limits: bool, n: int = 1) -> dict:
    """Points evaluated outside the tyre's ranges: ``{name: count}`` of :data:`OUTSIDE` (nonzero only).

    ``vals`` are the inputs ``(kappa, alpha, gamma, fz, vx, p, phit)`` as :func:`evaluate` holds them
    (floats or 1-D arrays). With ``limits`` on, inputs are clipped (counted by :func:`prepare`), so
    only the loads of a tyre without ``FZMAX`` can be far out; with limits off every range counts.
    ``n`` is the number of points (a scalar input counts for all of them).
    """

    def count(x, mask) -> int:
        return _count(mask) * (n if np.ndim(x) == 0 else 1)

    kappa, alpha, gamma, fz, _vx, p, _phit = vals
    out = {}
    if not limits:
        for name, x in (("fz", fz), ("kappa", kappa), ("alpha", alpha), ("gamma", gamma), ("p", p)):
            if x is None or (name == "p" and not t.nominal_pressure):
                continue
            lo, hi = t.range(name)
            if name == "fz":
                lo = t.coef.get("FZMIN", -math.inf)
            x = np.asarray(x, dtype=float)
            k = count(x, (x < lo) | (x > hi))
            if k:
                out[name] = k
    fnom = t.coef.get("FNOMIN")
    if "FZMAX" not in t.coef and fnom:
        k = count(fz, np.asarray(fz, dtype=float) > 10.0 * fnom)
        if k:
            out["fz_extreme"] = k
    return out


def _count(mask) -> int:
    return int(np.count_nonzero(mask))


def _clip(x, lo, hi, name, counts):
    n = 0
    if lo > -math.inf:
        n += _count(x < lo)
    if hi < math.inf:
        n += _count(x > hi)
    counts[name] = n
    return np.clip(x, lo, hi) if n else x


def prepare(t, kappa, alpha, gamma, fz, vx, p, phit=None, limits=True, low_speed=True, need_my=True):
    """Apply the limits and the low-speed rules to one block of inputs (1-D arrays or scalars).

    Returns a namespace with the processed ``kappa, alpha, gamma, fz, vx, p, phit``, the keyword
    arguments ``kernel`` for :func:`~tirecli.models.magic_formula.mf61.evaluate_kernel` (``red``,
    ``fz_mz``, ``fz_scale_mx``, ``fz_scale_my``, ``my_window``) and ``counts`` (see
    :data:`COUNTERS`).
    """
    c = t.coef
    counts = {}
    kw = {}
    counts["fz_negative"] = _count(fz < 0)
    if counts["fz_negative"]:
        fz = np.maximum(fz, 0.0)
    kappa_raw = kappa
    vxlow = c.get("VXLOW") or 0.0
    if low_speed and vxlow > 0:
        avx = np.abs(vx)
        low = avx <= vxlow
        counts["low_speed"] = n_low = _count(low)
        if n_low:
            lin = np.where(low, avx / vxlow, 1.0)
            kw["red"] = np.where(low, 0.5 * (1.0 - np.cos(math.pi * vx / vxlow)), 1.0)
            kappa = kappa * lin
            if phit is not None:
                phit = phit * lin
        slow = avx < vxlow
        n_alpha = 0
        if np.any(slow):
            ssum = avx + np.abs(np.tan(alpha) * vx)
            m = ssum < vxlow
            n_alpha = _count(m & (alpha != 0))
            if np.any(m):
                alpha = np.where(m, alpha * ssum / vxlow, alpha)
        counts["alpha_low_speed"] = n_alpha
        # My near the locked wheel / standstill (mfeval): sine ramp between lo and hi, flip below lo
        counts["my_standstill"] = 0
        if need_my:
            with np.errstate(over="ignore", divide="ignore"):  # |vx| -> 0: the window grows without bound
                hi = np.where(avx > 0, vxlow / np.where(avx > 0, avx, 1.0) - 1.0, math.inf)
            lo = -1.0 - vxlow - hi
            in_win = (kappa_raw >= lo) & (kappa_raw <= hi) & (avx > 0)
            below = (kappa_raw < lo) & (avx > 0)
            counts["my_standstill"] = _count(in_win) + _count(below)
        if counts["my_standstill"]:
            ramp = np.sin(0.5 * math.pi * (kappa_raw + 1.0) / np.where(in_win, hi + 1.0, 1.0))
            kw["my_window"] = np.where(in_win, ramp, np.where(below, -1.0, 1.0))
    if limits:
        alpha = _clip(alpha, *t.range("alpha"), "alpha", counts)
        gamma = _clip(gamma, *t.range("gamma"), "gamma", counts)
        fzmin = c.get("FZMIN", 0.0) or 0.0
        counts["fz"] = _count(fz > c["FZMAX"]) if "FZMAX" in c else 0
        if counts["fz"]:
            fz = np.minimum(fz, c["FZMAX"])
        if p is not None and t.nominal_pressure:
            p = _clip(p, *t.range("p"), "p", counts)
        kappa = _clip(kappa, *t.range("kappa"), "kappa", counts)
        if fzmin > 0:
            below = fz < fzmin
            counts["fz_low"] = _count(below)
            if counts["fz_low"]:
                kw["fz_mz"] = np.where(fz > 0, np.maximum(fz, fzmin), 0.0)
                ratio = np.minimum(fz / fzmin, 1.0)
                kw["fz_scale_mx"] = np.square(ratio)
                kw["fz_scale_my"] = ratio
        if phit is not None:
            phit = phit * np.cos(alpha)
    return SimpleNamespace(kappa=kappa, alpha=alpha, gamma=gamma, fz=fz, vx=vx, p=p, phit=phit,
                           kernel=kw, counts=counts)


def describe_counts(counts: dict) -> list[str]:
    """Lines naming every input rule that touched points (:data:`COUNTERS`; ``tirecli mf eval``, run.json)."""
    return [f"{n} point(s): {COUNTERS.get(k, k)}" for k, n in counts.items() if n]


def describe_outside(outside: dict) -> list[str]:
    """Lines naming the inputs evaluated outside the tyre's ranges (:data:`OUTSIDE`; flagged: extrapolated results)."""
    return [f"{n} point(s): {OUTSIDE.get(k, k)}" for k, n in outside.items() if n]
