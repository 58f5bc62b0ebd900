"""The observer's design plant in OBS coordinates (OBS (1)-(6), (19)-(22); docs/models/observer_model.md §1, §3).

python-control shape, pure and vectorized (state axis first; trailing axes broadcast):

- **state** ``x = (eta, chi, z)``: ``eta = r m v + J omega`` and ``chi = J omega + r F_n sigma1 z``
  [kg m^2/s] (OBS (19)), ``z`` the mean bristle deflection [m];
- **input** ``u = (torque, theta_obs)`` (:class:`PlantInput`): wheel torque [N m] (> 0 drives) and road
  adhesion in the OBS convention [-] (``theta_obs = 1/theta_fm``, :mod:`tirecli.conventions`);
- **parameters** ``p``: :class:`~tirecli.observers.lugre_observer.ObserverPlant` (lumped LuGre tire with
  constant ``kappa``, quarter car, ``sigma2`` in the vehicle equation only);
- **outputs**: the measured wheel speed ``y = C x`` [rad/s] with ``v`` [m/s], ``omega`` [rad/s] and
  ``vr`` [m/s] (OBS (20)).

In ``(v, omega, z)`` it is :func:`tirecli.models.quarter_car.rhs` with ``sigma2_in_wheel=False``
(tests/test_observer_design.py). The observer that estimates it: :mod:`tirecli.observers.observer`.
Fast kernel that inlines it: :func:`tirecli.numerics.observer.fast.simulate_fast` (parity:
tests/test_model_parity.py).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from tirecli.observers.lugre_observer import ObserverPlant


class PlantInput(NamedTuple):
    """Input of the observer's design plant.

    Attributes
    ----------
    torque : array_like
        Wheel torque ``u`` [N m] (> 0 drives).
    theta_obs : array_like
        Road adhesion, OBS convention [-] (multiplies ``sigma0 |vr|/g``).
    """

    torque: object
    theta_obs: object = 1.0


def _column(a, nd: int) -> np.ndarray:
    return np.asarray(a, dtype=float).reshape((3,) + (1,) * nd)


def rhs(t, x, u, p: ObserverPlant):
    """Plant (6) in OBS coordinates: ``x' = A x + B (theta_obs phi + psi) + R u + E y``, ``y = C x`` (OBS (6), (18)).

    ``phi = sigma0 |vr|/g(vr) z`` and ``psi = kappa r |y| z`` [m/s] (OBS (18)); ``A, B, R, E, C`` of
    :meth:`ObserverPlant.matrices`.

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (3, ...)
        ``(eta [kg m^2/s], chi [kg m^2/s], z [m])``.
    u : sequence
        ``(torque [N m], theta_obs [-])`` (:class:`PlantInput`).
    p : ObserverPlant

    Returns
    -------
    ndarray, shape (3, ...)
        ``(d eta/dt [N m], d chi/dt [N m], dz/dt [m/s])``.
    """
    A, B, R, E, C = p.matrices()
    x = np.asarray(x, dtype=float)
    nd = x.ndim - 1
    y = np.tensordot(C, x, axes=1)
    nl = u[1] * p.phi(y, x[0], x[2]) + p.psi(y, x[2])
    return np.tensordot(A, x, axes=1) + _column(B, nd) * nl + _column(R, nd) * u[0] + _column(E, nd) * y


def outputs(t, x, u, p: ObserverPlant) -> dict:
    """Outputs at state ``x`` (arguments as :func:`rhs`).

    Returns
    -------
    dict
        ``y`` [rad/s]: the measured wheel speed ``C x``; ``v`` [m/s], ``omega`` [rad/s]: the state in
        physical coordinates (OBS (20)); ``vr`` [m/s]: the relative velocity ``r omega - v``.
    """
    v, omega, _ = p.from_obs_coords(*np.asarray(x, dtype=float))
    return {"y": omega, "v": v, "omega": omega, "vr": p.car.r * omega - v}
