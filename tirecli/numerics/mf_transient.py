"""Integrator of the transient Magic Formula and its slip-step responses.

Implements :func:`tirecli.models.magic_formula.transient.rhs` (state ``[kappa', alpha']``): in the rolled
distance ``s`` the model is the linear lag ``dx/ds = (u - x)/sigma``, so over one sample interval with the
relaxation length ``sigma`` held it has an exact solution. :func:`simulate` steps with it:

- ``hold="previous"`` (default): the slips, load, inclination and pressure are held at the interval's
  first sample (a step in the input is a change between two samples), and
  ``x_{k+1} = u_k + (x_k - u_k) exp(-z_k)``, ``z_k = Delta s_k / sigma_k``;
- ``hold="linear"``: the slips are straight in ``s`` between samples,
  ``x_{k+1} = exp(-z) x_k + (1 - exp(-z)) u_k + (u_{k+1} - u_k)(1 - (1 - exp(-z))/z)``.

``Delta s_k`` is the trapezoidal integral of ``|vx|``: exact for a speed straight in time (without a sign
change) within the interval. Each step is therefore exact for those input classes whatever the step
size, and unconditionally stable however short the relaxation length is against the distance per
sample (the lag is stiff at low load, where ``sigma`` vanishes): an explicit Runge-Kutta step would need
``Delta s < 2.8 sigma``; an implicit Euler step would be stable but first-order accurate. The recurrence
``x_{k+1} = d_k x_k + f_k`` is evaluated without a loop over samples (:func:`linear_recurrence`).

:func:`step_responses` gives the responses to a slip-ratio step and a slip-angle step at constant speed
and load, normalised by their steady state against the rolled distance, and the distances where the
slip state and the force reach 63.2 % (``1 - 1/e``) and 95 % of their change.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.models.magic_formula import transient as T

#: Levels of the response distances: 63.2 % (1 - 1/e: the relaxation length for the slip state) and 95 %.
LEVELS = (1.0 - math.exp(-1.0), 0.95)
#: Largest decay exponent of one interval: exp(-50) ~ 2e-22, the state has forgotten its start.
Z_MAX = 50.0
_BLOCK = 500.0  # decay exponent summed within one block of the recurrence (exp(550) is finite)


def _recurrence(z, f, x0):
    """:func:`linear_recurrence` given the exponents ``z_k = -log d_k`` (each <= :data:`Z_MAX`), all of
    shape (n - 1, m); ``x0`` of shape (m,)."""
    z = np.asarray(z, dtype=float)
    f = np.asarray(f, dtype=float)
    n1, m = f.shape
    x = np.empty((n1 + 1, m))
    x[0] = x0
    for col in range(m):
        c = np.concatenate(([0.0], np.cumsum(z[:, col])))
        edges = np.flatnonzero(np.diff(np.floor(c / _BLOCK))) + 1  # first sample of each later block
        for b, e in zip(np.concatenate(([0], edges)), np.concatenate((edges, [n1]))):
            if e <= b:  # the block [b, e] gives x[b + 1 .. e]
                continue
            cl = c[b + 1:e + 1] - c[b]  # < 500 + Z_MAX: exp(cl) is finite
            acc = np.cumsum(np.exp(cl) * f[b:e, col])  # sum_j f_j / D_{j+1}
            x[b + 1:e + 1, col] = np.exp(-cl) * (x[b, col] + acc)
    return x


def linear_recurrence(d, f, x0):
    """``x_{k+1} = d_k x_k + f_k`` for ``0 < d_k <= 1``, without a Python loop over samples.

    Within blocks whose summed ``-log d`` stays below 500 the solution is
    ``x_k = D_k (x_b + sum_j f_j / D_{j+1})`` with ``D_k`` the product of the ``d`` from the block's
    start ``b`` (never overflowing); the blocks are chained. Factors below ``exp(-Z_MAX)`` count as
    ``exp(-Z_MAX)`` (a change of less than 2e-22 relative).

    Parameters
    ----------
    d : array_like, shape (n - 1,) or (n - 1, m)
        Decay factors.
    f : array_like, shape (n - 1, m)
        Forcing terms.
    x0 : array_like, shape (m,)
        Initial state.

    Returns
    -------
    ndarray, shape (n, m)
    """
    f = np.asarray(f, dtype=float)
    with np.errstate(divide="ignore"):
        z = np.minimum(-np.log(np.asarray(d, dtype=float)), Z_MAX)
    return _recurrence(np.broadcast_to(z.reshape(z.shape + (1,) * (f.ndim - z.ndim)), f.shape), f, x0)


def rolled_distance(t, vx):
    """Distance rolled since ``t[0]`` [m]: the trapezoidal integral of ``|vx|`` over the samples.

    Parameters
    ----------
    t : array_like, shape (n,)
        Times [s], increasing.
    vx : array_like, shape (n,)
        Forward speed at the samples [m/s].
    """
    t = np.asarray(t, dtype=float)
    av = np.abs(np.broadcast_to(np.asarray(vx, dtype=float), t.shape))
    return np.concatenate(([0.0], np.cumsum(0.5 * (av[1:] + av[:-1]) * np.diff(t))))


@dataclass
class TransientRun:
    """Result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Times [s].
    s : ndarray, shape (n,)
        Rolled distance since ``t[0]`` [m].
    x : ndarray, shape (n, 2)
        Transient slips ``[kappa' [-], alpha' [rad]]``.
    sigma : ndarray, shape (n, 2)
        Relaxation lengths ``[sigma_kappa, sigma_alpha]`` at the samples [m].
    outputs : dict
        Forces and moments at the transient slips (``fx``, ``fy`` [N], ``mz``, ``mx``, ``my`` [N m]),
        empty when not asked for.
    """

    t: np.ndarray
    s: np.ndarray
    x: np.ndarray
    sigma: np.ndarray
    outputs: dict = field(default_factory=dict)


def _inputs(u: dict, n: int) -> dict:
    out = {}
    for name in T.INPUTS:
        v = u.get(name)
        if v is None:
            if name in ("kappa", "alpha", "fz", "vx"):
                raise ValueError(f"the transient Magic Formula needs the input {name!r}")
            out[name] = None if name == "p" else np.zeros(n)
            continue
        out[name] = np.broadcast_to(np.asarray(v, dtype=float), (n,))
    return out


def simulate(p: T.TransientMF, t, u: dict, x0=None, *, hold: str = "previous",
             outputs=("fx", "fy", "mz", "mx", "my")) -> TransientRun:
    """Transient Magic Formula over sampled inputs, exact per interval (see the module docstring).

    Parameters
    ----------
    p : TransientMF
        The tyre and its options.
    t : array_like, shape (n,)
        Sample times [s], strictly increasing.
    u : dict
        Inputs at the samples (arrays of shape (n,) or scalars): ``kappa`` [-], ``alpha`` [rad],
        ``gamma`` [rad] (default 0), ``fz`` [N], ``vx`` [m/s], ``p`` [Pa] (default ``INFLPRES``).
    x0 : array_like, shape (2,), or None
        Initial ``[kappa', alpha']``; default the inputs' slips at ``t[0]`` (a steady start).
    hold : {"previous", "linear"}
        How the slips vary between samples (``previous``: held, a step happens at a sample; ``linear``:
        straight in the rolled distance). Load, inclination and pressure, hence ``sigma``, are held.
    outputs : iterable of str
        Forces and moments to evaluate at the transient slips (empty: none).

    Returns
    -------
    TransientRun
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 1 or np.any(np.diff(t) <= 0):
        raise ValueError("t must be a 1-D array of strictly increasing times")
    if hold not in ("previous", "linear"):
        raise ValueError(f"hold {hold!r}: expected 'previous' or 'linear'")
    n = t.size
    ui = _inputs(u, n)
    slips = np.stack([ui["kappa"], ui["alpha"]], axis=1)
    sigma = np.stack(T.relaxation_at(ui, p), axis=1) * np.ones((n, 1))
    s = rolled_distance(t, ui["vx"])
    z = np.minimum(np.diff(s)[:, None] / sigma[:-1], Z_MAX)
    one_minus_d = -np.expm1(-z)
    f = one_minus_d * slips[:-1]
    if hold == "linear":
        with np.errstate(divide="ignore", invalid="ignore"):
            w = np.where(z > 1e-4, 1.0 - one_minus_d / z, z * (0.5 - z * (1.0 / 6.0 - z / 24.0)))
        f = f + (slips[1:] - slips[:-1]) * w
    start = slips[0] if x0 is None else np.asarray(x0, dtype=float)
    x = _recurrence(z, f, start)
    outs = {}
    if outputs:
        u_now = {k: v for k, v in ui.items() if v is not None}
        res = T.outputs(None, x.T, u_now, p, names=tuple(outputs))
        outs = {k: res[k] for k in outputs}
    return TransientRun(t=t, s=s, x=x, sigma=sigma, outputs=outs)


@dataclass
class StepResponse:
    """Response of the transient Magic Formula to one slip step at constant speed and load.

    Attributes
    ----------
    slip : str
        ``kappa`` (slip-ratio step, force ``fx``) or ``alpha`` (slip-angle step, force ``fy``).
    step : float
        Slip after the step [-] or [rad] (from 0).
    sigma : float
        Relaxation length [m].
    s, t : ndarray
        Rolled distance since the step [m] and time [s].
    state : ndarray
        Transient slip [-] or [rad] (:func:`simulate`).
    closed_form : ndarray
        ``step (1 - exp(-s/sigma))`` (:func:`~tirecli.models.magic_formula.transient.step_response`).
    force : ndarray
        ``fx`` or ``fy`` [N] at the transient slip.
    force_start, force_steady : float
        The force before the step (slip 0: not 0 for a tyre with shifts) and in the new steady state [N].
    state_norm, force_norm : ndarray
        ``state/step`` and ``(force - force_start)/(force_steady - force_start)`` [-].
    distances : dict
        ``{"state": {level: s}, "force": {level: s}}`` [m]: the first rolled distance where the
        normalised response reaches each level of :data:`LEVELS` (NaN if it never does).
    """

    slip: str
    step: float
    sigma: float
    s: np.ndarray
    t: np.ndarray
    state: np.ndarray
    closed_form: np.ndarray
    force: np.ndarray
    force_start: float
    force_steady: float
    state_norm: np.ndarray
    force_norm: np.ndarray
    distances: dict


def _force_at(p, slip, x, fz, vx, gamma, pres):
    """``fx`` (``slip="kappa"``) or ``fy`` [N] of the transient model at the transient slip(s) ``x`` (the
    other slip 0)."""
    x = np.atleast_1d(np.asarray(x, dtype=float))
    zero = np.zeros_like(x)
    name = "fx" if slip == "kappa" else "fy"
    state = np.stack([x, zero] if slip == "kappa" else [zero, x])
    return T.outputs(None, state, {"fz": fz, "vx": vx, "gamma": gamma, "p": pres}, p, names=(name,))[name]


def _force_distance(p, slip, step, sigma, level, f0, fss, fz, vx, gamma, pres, grid: int = 2049):
    """First rolled distance where the normalised force reaches ``level``: the first crossing on a fine
    grid of slips, refined by bisection; then ``s = -sigma log(1 - x/step)`` (the state's closed form)."""
    xs = np.linspace(0.0, step, grid)
    g = (_force_at(p, slip, xs, fz, vx, gamma, pres) - f0) / (fss - f0)
    hit = np.flatnonzero(g >= level)
    if not hit.size:
        return math.nan
    i = int(hit[0])
    if i == 0:
        return 0.0
    lo, hi = xs[i - 1], xs[i]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        gm = (float(_force_at(p, slip, mid, fz, vx, gamma, pres)[0]) - f0) / (fss - f0)
        if gm >= level:
            hi = mid
        else:
            lo = mid
    frac = 0.5 * (lo + hi) / step
    return math.inf if frac >= 1.0 else -sigma * math.log1p(-frac)


def step_responses(p: T.TransientMF, fz: float, vx: float, kappa_step: float = 0.02, alpha_step: float = 0.02, *,
                   distance: float | None = None, samples: int = 401, gamma: float = 0.0,
                   pressure: float | None = None, levels=LEVELS) -> dict:
    """Responses to a slip-ratio step and a slip-angle step (each from 0, the other slip 0) at constant
    speed and load, normalised by their steady state, with their 63.2 % and 95 % distances.

    Parameters
    ----------
    p : TransientMF
        The tyre and its options.
    fz : float
        Vertical load [N].
    vx : float
        Forward speed [m/s] (non-zero).
    kappa_step : float
        Slip ratio after the longitudinal step [-] (0 or None: no longitudinal step).
    alpha_step : float
        Slip angle after the lateral step [rad] (0 or None: no lateral step).
    distance : float or None
        Rolled distance covered [m] (default 5 times the larger relaxation length).
    samples : int
        Samples over the distance.
    gamma : float
        Inclination [rad].
    pressure : float or None
        Inflation pressure [Pa] (default ``INFLPRES``).
    levels : tuple of float
        Fractions of the change whose distances are given.

    Returns
    -------
    dict
        ``{"kappa": StepResponse, "alpha": StepResponse}`` (the steps asked for).
    """
    if not vx:
        raise ValueError("a step response needs a non-zero speed")
    u0 = {"fz": fz, "gamma": gamma, "p": pressure}
    sx, sy = (float(v) for v in T.relaxation_at(u0, p))
    if distance is None:
        distance = 5.0 * max(sx, sy)
    s = np.linspace(0.0, distance, samples)
    t = s / abs(vx)
    out = {}
    for slip, step, sigma in (("kappa", kappa_step, sx), ("alpha", alpha_step, sy)):
        if not step:
            continue
        u = {"kappa": step if slip == "kappa" else 0.0, "alpha": step if slip == "alpha" else 0.0,
             "gamma": gamma, "fz": fz, "vx": vx, "p": pressure}
        name = "fx" if slip == "kappa" else "fy"
        run = simulate(p, t, u, x0=[0.0, 0.0], outputs=(name,))
        state = run.x[:, 0 if slip == "kappa" else 1]
        f0 = float(_force_at(p, slip, 0.0, fz, vx, gamma, pressure)[0])
        fss = float(_force_at(p, slip, step, fz, vx, gamma, pressure)[0])
        force = run.outputs[name]
        with np.errstate(divide="ignore", invalid="ignore"):
            force_norm = (force - f0) / (fss - f0)
        dist = {"state": {lv: -sigma * math.log1p(-lv) for lv in levels},
                "force": {lv: (_force_distance(p, slip, float(step), sigma, lv, f0, fss, fz, vx, gamma, pressure)
                               if fss != f0 else math.nan) for lv in levels}}
        out[slip] = StepResponse(slip=slip, step=float(step), sigma=sigma, s=s, t=t, state=state,
                                 closed_form=T.step_response(s, sigma, float(step)), force=force,
                                 force_start=f0, force_steady=fss, state_norm=state / step, force_norm=force_norm,
                                 distances=dist)
    return out


__all__ = ["LEVELS", "Z_MAX", "linear_recurrence", "rolled_distance", "TransientRun", "simulate", "StepResponse",
           "step_responses"]
