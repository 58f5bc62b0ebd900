"""Peaks of steady-state friction curves |mu|(|s|) at a held speed (docs/models/lugre_friction.md §5, §9).

A steady-state curve of a sweep is one model variant at one held speed, one adhesion and one
direction: braking holds the vehicle speed ``v`` (``r omega = v (1 - sigma)``), driving holds the
wheel speed ``r omega`` (``v = r omega (1 - sigma)``), with ``sigma = |s|`` in ``(0, 1]``
(:func:`tirecli.conventions.speeds_from_slip`). Along it

``|mu|(sigma) = theta g(a) S(x) + sigma2 a``,  ``a = |vr| = speed sigma``,
``x = L/Z = sigma0 a L / (theta g(a) |r omega|)``,

with ``S`` the shape of the variant (FM eqs. (4), (6), (8)-(10), a load density). Its slope is

``d|mu|/dsigma = speed (theta g)'(a) S + theta g S'(x) x (1/sigma - speed (theta g)'/(theta g) + b/(1 - sigma))
+ sigma2 speed``,

``b = 1`` braking, 0 driving (:func:`abs_mu_slope`). The peak is the highest interior local maximum of ``|mu|``: a zero of this slope where it changes
sign from + to -. A scan of the model function on a fixed grid of ``sigma`` (independent of the
sweep's grid) brackets it, and bisection on the sign of the analytic slope narrows the bracket to
``xtol`` (1e-12) in slip; ``|mu|`` at the peak is then the model function itself
(:meth:`FrictionVariant.mu_ss`) at that slip. A curve without an interior maximum (``|mu|`` rises
all the way, e.g. at high speed where ``sigma2 |vr|`` dominates) has its peak at full slide,
``sigma = 1``. At high speed the sliding level may exceed an interior peak: the peak is still the
interior one (the adhesion peak of the curve), and ``mu_slide`` tells the rest. A curve that is
zero everywhere (held speed 0) has no peak (NaN slip).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.conventions import speeds_from_slip
from tirecli.models import lugre
from tirecli.models.variants import FrictionVariant

#: Scan of |s| that brackets the peak: geometric below 0.01 (peaks at small slip), then every 0.005.
SCAN = np.concatenate((np.geomspace(1e-6, 1e-2, 24, endpoint=False), np.linspace(1e-2, 1.0, 199)))
#: The slope at full slide is taken just below it (at |s| = 1 a braked wheel is locked: x = inf).
_TOP = 1.0 - 1e-9


def _kinematics(sigma, speed, braking: bool):
    """``(vr, romega)`` [m/s] at slip magnitude ``sigma`` and held ``speed`` (see module doc)."""
    s = -np.asarray(sigma, dtype=float) if braking else np.asarray(sigma, dtype=float)
    v, romega = speeds_from_slip(s, speed)
    return romega - v, romega


def abs_mu(variant: FrictionVariant, p: lugre.LuGreParams, sigma, speed, theta=1.0, braking=True):
    """``|mu|`` [-] of the steady state at slip magnitude ``sigma = |s|`` and held ``speed`` (module doc).

    ``|mu|(sigma) = theta g(a) S(x) + sigma2 a`` with the variant's shape ``S`` (FM eqs. (4), (6), (8)-(10)):
    :meth:`FrictionVariant.mu_ss <tirecli.models.variants.FrictionVariant.mu_ss>` at the kinematics of the curve.
    ``theta`` is a scalar; ``sigma`` and ``speed`` broadcast (``s = 0`` counts as braking).

    Parameters
    ----------
    variant : FrictionVariant
        The model variant (:class:`~tirecli.models.variants.FrictionVariant`).
    p : LuGreParams
        Tire parameters, SI units (:class:`~tirecli.models.lugre.LuGreParams`).
    sigma : array_like
        Slip magnitude ``|s|`` [-], in ``(0, 1]`` (``> 0`` when driving).
    speed : array_like
        Held speed [m/s]: ``v`` braking, ``r omega`` driving.
    theta : float
        Road adhesion [-], FM convention.
    braking : bool
        Braking (``s < 0``, ``r omega = v (1 - sigma)``) or driving (``s > 0``, ``v = r omega (1 - sigma)``).
    """
    vr, romega = _kinematics(sigma, speed, braking)
    return np.abs(variant.mu_ss(vr, romega, p, theta))


def abs_mu_slope(variant: FrictionVariant, p: lugre.LuGreParams, sigma, speed, theta=1.0, braking=True):
    """``d|mu|/d|s|`` [-] of a steady-state curve at ``0 < sigma < 1`` (analytic; module doc).

    ``d|mu|/dsigma = speed (theta g)'(a) S + theta g S'(x) x (1/sigma - speed (theta g)'/(theta g) + b/(1 - sigma))
    + sigma2 speed`` (the derivative of FM eqs. (4), (6), (8)-(10) along the curve; ``b = 1`` braking, 0 driving).

    Parameters
    ----------
    variant : FrictionVariant
        The model variant (:class:`~tirecli.models.variants.FrictionVariant`).
    p : LuGreParams
        Tire parameters, SI units (:class:`~tirecli.models.lugre.LuGreParams`).
    sigma : array_like
        Slip magnitude ``|s|`` [-], in ``(0, 1]`` (``> 0`` when driving).
    speed : array_like
        Held speed [m/s]: ``v`` braking, ``r omega`` driving.
    theta : float
        Road adhesion [-], FM convention.
    braking : bool
        Braking (``s < 0``, ``r omega = v (1 - sigma)``) or driving (``s > 0``, ``v = r omega (1 - sigma)``).
    """
    sigma, speed = np.broadcast_arrays(np.asarray(sigma, dtype=float), np.asarray(speed, dtype=float))
    vr, romega = _kinematics(sigma, speed, braking)
    a = speed * sigma
    g = lugre.stribeck(vr, p, theta)
    dg = lugre.stribeck_slope(a, p, theta)
    x = lugre.patch_ratio(vr, romega, p, theta)
    shape = (np.abs(variant.mu_ss(vr, romega, p, theta)) - p.sigma2 * a) / g
    with np.errstate(divide="ignore", invalid="ignore"):
        dlogx = 1.0 / sigma - speed * dg / g + (1.0 / (1.0 - sigma) if braking else 0.0)
    return speed * dg * shape + g * variant.shape_slope(x, p) * x * dlogx + p.sigma2 * speed


@dataclass
class CurvePeaks:
    """Peaks of curves at several held speeds (arrays of one length).

    Attributes
    ----------
    slip : ndarray
        ``|s|`` of the peak [-] (NaN for a curve that is zero everywhere).
    mu : ndarray
        ``|mu|`` at the peak [-].
    mu_slide : ndarray
        ``|mu|`` at full slide, ``|s| = 1`` [-] (a locked wheel when braking, ``v = 0`` when driving).
    at_slide : ndarray of bool
        The maximum is at full slide (``|mu|`` rises all the way: no interior peak).
    """

    slip: np.ndarray
    mu: np.ndarray
    mu_slide: np.ndarray
    at_slide: np.ndarray


def curve_peaks(variant: FrictionVariant, p: lugre.LuGreParams, speeds, theta=1.0, braking=True,
                xtol: float = 1e-12) -> CurvePeaks:
    """Root-found peaks of the curves ``|mu|(|s|)`` of one variant and adhesion at held ``speeds`` (module doc).

    The peak is the highest interior zero of :func:`abs_mu_slope` (the derivative of FM eqs. (4), (6),
    (8)-(10) along the curve) where it changes sign from + to -, or full slide when ``|mu|`` rises
    all the way.

    Parameters
    ----------
    variant : FrictionVariant
        The model variant.
    p : LuGreParams
        Tire parameters, SI units.
    speeds : array_like
        Held speeds [m/s] (``v`` braking, ``r omega`` driving), >= 0.
    theta : float
        Adhesion, FM convention [-].
    braking : bool
        Braking (``s < 0``) or driving (``s > 0``) curves.
    xtol : float
        Width of the final bracket of the peak slip [-].
    """
    speeds = np.asarray(speeds, dtype=float).reshape(-1)
    n, k = speeds.size, SCAN.size
    grid = abs_mu(variant, p, SCAN[None, :], speeds[:, None], theta, braking)
    mu_slide = grid[:, -1].copy()
    none = ~(grid.max(axis=1) > 0.0)  # zero everywhere (held speed 0): no peak
    # interior local maxima of the scan; the highest one is the peak
    local = np.zeros_like(grid, dtype=bool)
    local[:, 1:-1] = (grid[:, 1:-1] >= grid[:, :-2]) & (grid[:, 1:-1] > grid[:, 2:])
    masked = np.where(local, grid, -np.inf)
    i = np.argmax(masked, axis=1)
    # none inside the scan: |mu| rises to full slide, or peaks between the last two scan points
    i = np.where(np.isfinite(masked.max(axis=1)), i, k - 1)
    top = SCAN.copy()
    top[-1] = _TOP
    at_slide = (i == k - 1) & ~none
    if at_slide.any():
        rising = abs_mu_slope(variant, p, _TOP, speeds[at_slide], theta, braking) >= 0.0
        at_slide[np.flatnonzero(at_slide)[~rising]] = False
    lo = top[np.maximum(i - 1, 0)]
    hi = top[np.minimum(i + 1, k - 1)]
    inner = np.flatnonzero(~none & ~at_slide)
    sig = np.full(n, np.nan)
    s_lo = abs_mu_slope(variant, p, lo[inner], speeds[inner], theta, braking)
    s_hi = abs_mu_slope(variant, p, hi[inner], speeds[inner], theta, braking)
    sign_change = (s_lo > 0.0) & (s_hi < 0.0)
    b = inner[sign_change]
    if b.size:  # bisection on the sign of the slope, every curve at once
        a_, c_, v_ = lo[b].copy(), hi[b].copy(), speeds[b]
        for _ in range(200):
            if np.max(c_ - a_) <= xtol:
                break
            m = 0.5 * (a_ + c_)
            up = abs_mu_slope(variant, p, m, v_, theta, braking) > 0.0
            a_ = np.where(up, m, a_)
            c_ = np.where(up, c_, m)
        sig[b] = 0.5 * (a_ + c_)
    for r in inner[~sign_change]:  # no sign change at the bracket ends (a flat top): bounded search
        from scipy.optimize import minimize_scalar

        res = minimize_scalar(lambda z: -float(abs_mu(variant, p, z, speeds[r], theta, braking)),
                              bounds=(lo[r], hi[r]), method="bounded", options={"xatol": xtol})
        sig[r] = res.x
    sig[at_slide] = 1.0
    mu = np.zeros(n)
    ok = ~none
    mu[ok] = abs_mu(variant, p, sig[ok], speeds[ok], theta, braking)
    mu[at_slide] = mu_slide[at_slide]
    return CurvePeaks(slip=sig, mu=mu, mu_slide=mu_slide, at_slide=at_slide)
