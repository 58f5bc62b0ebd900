"""The lumped LuGre tire as a dynamic model (FM eqs. (7)-(10); docs/models/lugre_friction.md §4).

python-control shape, pure and vectorized (state axis first; trailing axes of ``x`` and ``u``
broadcast): ``rhs(t, x, u, p) -> dx/dt`` and ``outputs(t, x, u, p) -> dict``.

- **state** ``x = (z,)``: mean bristle deflection ``z`` [m] (FM eq. (7));
- **input** ``u = (vr, romega, theta)`` (:class:`TireInput`, or any sequence in that order):
  relative velocity ``vr = r omega - v`` [m/s], wheel circumferential speed ``r omega`` [m/s] and
  road adhesion ``theta`` [-] in the FM convention (``g -> theta g``; :mod:`tirecli.conventions`);
- **parameters** ``p``: :class:`LumpedTire` (the LuGre parameters and the lumped coefficient);
- **outputs**: ``mu`` [-] (FM eq. (9)), ``zdot`` [m/s] and ``kappa0`` [-] (the coefficient in use).

The quarter car (:mod:`tirecli.models.quarter_car`) couples it to the vehicle and the wheel. Fast
kernel that inlines it: :class:`tirecli.numerics.lumped.LumpedStepper` (parity:
tests/test_model_parity.py).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tirecli.models.lugre import LuGreParams, kappa0_of_x, lumped_decay_rate, mu_of_deflection, patch_ratio


class TireInput(NamedTuple):
    """Input of a LuGre tire model (lumped or distributed) driven by its kinematics.

    Attributes
    ----------
    vr : array_like
        Relative velocity ``r omega - v`` [m/s] (< 0 braking).
    romega : array_like
        Wheel circumferential speed ``r omega`` [m/s].
    theta : array_like
        Road adhesion [-], FM convention (1 = nominal).
    """

    vr: object
    romega: object
    theta: object = 1.0


@dataclass(frozen=True)
class LumpedTire:
    """Parameters of the lumped LuGre tire.

    Attributes
    ----------
    params : LuGreParams
        Friction parameters (``sigma0`` [1/m], ``sigma1``, ``sigma2`` [s/m], ``mu_c``, ``mu_s`` [-],
        ``v_s`` [m/s], ``L`` [m], ``alpha`` [-]; ``sigma_w`` is the wheel's).
    kappa0 : float, None or "Z"
        Lumped coefficient ``kappa0 = kappa L`` [-] (FM eq. (8)): a constant, ``None`` for
        ``params.kappa0``, or ``"Z"`` for ``kappa0(Z)`` of FM eq. (10).
    """

    params: LuGreParams
    kappa0: float | str | None = None


def rhs(t, x, u, p: LumpedTire):
    """Bristle dynamics ``dz/dt = vr - (sigma0 |vr|/(theta g(vr)) + kappa0 |r omega|/L) z`` (FM eq. (8)).

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (1, ...)
        State ``(z,)``: mean bristle deflection [m].
    u : sequence
        ``(vr [m/s], romega [m/s], theta [-])`` (:class:`TireInput`).
    p : LumpedTire

    Returns
    -------
    ndarray, shape (1, ...)
        ``(dz/dt,)`` [m/s].
    """
    z = np.asarray(x, dtype=float)[0]
    vr = np.asarray(u[0], dtype=float)
    return (vr - lumped_decay_rate(vr, u[1], p.params, p.kappa0, u[2]) * z)[None]


def friction(x, dx, u, p: LumpedTire):
    """Normalised friction ``mu = sigma0 z + sigma1 dz/dt + sigma2 vr`` [-] (FM eq. (9)).

    What a coupled model (:mod:`tirecli.models.quarter_car`) needs from the tire without evaluating
    :func:`rhs` twice.

    Parameters
    ----------
    x : array_like, shape (1, ...)
        State ``(z,)`` [m].
    dx : array_like, shape (1, ...)
        Its rate ``(dz/dt,)`` [m/s] (:func:`rhs`).
    u : sequence
        ``(vr [m/s], romega [m/s], theta [-])`` (:class:`TireInput`).
    p : LumpedTire
    """
    return mu_of_deflection(np.asarray(x, dtype=float)[0], np.asarray(dx, dtype=float)[0], u[0], p.params)


def outputs(t, x, u, p: LumpedTire) -> dict:
    """Outputs of the lumped tire at state ``x`` and input ``u`` (arguments as :func:`rhs`).

    Returns
    -------
    dict
        ``mu`` [-]: normalised friction ``F/F_n`` (FM eq. (9)); ``zdot`` [m/s]: bristle rate (FM eq. (8));
        ``kappa0`` [-]: the lumped coefficient in use (``kappa0(Z)`` of FM eq. (10) at ``u`` for ``"Z"``).
    """
    dx = rhs(t, x, u, p)
    vr = np.asarray(u[0], dtype=float)
    if isinstance(p.kappa0, str):
        k0 = kappa0_of_x(patch_ratio(vr, u[1], p.params, u[2]))
    else:
        k0 = np.full(np.shape(dx[0]), float(p.params.kappa0 if p.kappa0 is None else p.kappa0))
    return {"mu": friction(x, dx, u, p), "zdot": dx[0], "kappa0": k0}
