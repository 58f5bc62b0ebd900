"""The nonlinear road-adhesion / vehicle-speed observer of OBS Theorem 1 (OBS (14); docs/models/observer_model.md §3).

python-control shape, pure and vectorized (state axis first; trailing axes broadcast):

- **state** ``x = (eta_hat, chi_hat, z_hat, theta_hat)``: estimates of the plant's OBS coordinates
  [kg m^2/s, kg m^2/s, m] (:mod:`tirecli.observers.plant`) and of the adhesion, OBS convention [-];
- **input** ``u = (y, torque)`` (:class:`ObserverInput`): the measured wheel speed [rad/s] and the wheel
  torque [N m];
- **parameters** ``p``: :class:`Observer` (the design plant and the gains);
- **outputs**: the output error ``y_tilde = y - C x_hat`` [rad/s] and the estimates ``v_hat`` [m/s],
  ``omega_hat`` [rad/s], ``z_hat`` [m], ``theta_hat`` [-].

Explicit form (docs/models/observer_model.md §3), ``y~ = y - (chi_hat - P z_hat)/J``::

    eta_hat'   = -c_eta eta_hat + E_1 y + u + k1 y~
    chi_hat'   = -Q z_hat - sigma_w y + u + k2 y~
    z_hat'     = -eta_hat/(r m) + E_3 y - theta_hat phi_hat - psi_hat - alpha (1 + theta_hat) y~ + k3 y~
    theta_hat' = gamma y~ (phi_hat + alpha y~)

with ``phi_hat = sigma0 |vr_hat|/g(vr_hat) z_hat``, ``vr_hat = r y - v(eta_hat, y)``, ``psi_hat = kappa r |y| z_hat``.
Fast kernels that inline it: :func:`tirecli.numerics.observer.adaptive.scalar_rhs` (the full system for
the adaptive methods) and :func:`~tirecli.numerics.observer.fast.simulate_fast` (its slow manifold);
parity: tests/test_model_parity.py.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant


@dataclass(frozen=True)
class Observer:
    """Parameters of the observer.

    Attributes
    ----------
    plant : ObserverPlant
        The design plant (tire, quarter car; its ``A``, ``E``, ``P``, ``Q`` and nonlinearities).
    gains : ObserverGains
        ``k1, k2`` [kg m^2/s], ``k3`` [m], ``gamma`` [s/m], ``alpha`` [m] (OBS (14), (17)).
    """

    plant: ObserverPlant
    gains: ObserverGains


class ObserverInput(NamedTuple):
    """Input of the observer.

    Attributes
    ----------
    y : array_like
        Measured wheel speed [rad/s].
    torque : array_like
        Wheel torque ``u`` [N m].
    """

    y: object
    torque: object


def _output_error(x, y, plant: ObserverPlant):
    """``y~ = y - C x_hat = y - (chi_hat - P z_hat)/J`` [rad/s]."""
    return y - (x[1] - plant.P * x[2]) / plant.car.J


def rhs(t, x, u, p: Observer):
    """The observer of Theorem 1 in explicit form (module doc; OBS (14)).

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (4, ...)
        ``(eta_hat [kg m^2/s], chi_hat [kg m^2/s], z_hat [m], theta_hat [-])``.
    u : sequence
        ``(y [rad/s], torque [N m])`` (:class:`ObserverInput`).
    p : Observer

    Returns
    -------
    ndarray, shape (4, ...)
        ``(d eta_hat/dt [N m], d chi_hat/dt [N m], d z_hat/dt [m/s], d theta_hat/dt [1/s])``.
    """
    plant, g = p.plant, p.gains
    c, t_ = plant.car, plant.tire
    eta, chi, z, theta_hat = np.asarray(x, dtype=float)
    y = np.asarray(u[0], dtype=float)
    E = plant.E
    ytil = _output_error((eta, chi, z), y, plant)
    phih = plant.phi(y, eta, z)
    psih = plant.psi(y, z)
    deta = -plant.c_eta * eta + E[0] * y + u[1] + g.k1 * ytil
    dchi = -plant.Q * z - t_.sigma_w * y + u[1] + g.k2 * ytil
    dz = (-eta / (c.r * c.m) + E[2] * y - theta_hat * phih - psih
          - g.alpha * (1.0 + theta_hat) * ytil + g.k3 * ytil)
    dth = g.gamma * ytil * (phih + g.alpha * ytil)
    return np.array(np.broadcast_arrays(deta, dchi, dz, dth))


def outputs(t, x, u, p: Observer) -> dict:
    """Outputs of the observer (arguments as :func:`rhs`).

    Returns
    -------
    dict
        ``y_tilde`` [rad/s]: output error ``y - C x_hat``; ``v_hat`` [m/s]: speed estimate
        ``(eta_hat - J y)/(r m)`` (docs/models/observer_model.md §3); ``omega_hat`` [rad/s]: ``C x_hat``;
        ``z_hat`` [m]; ``theta_hat`` [-] (OBS convention).
    """
    plant = p.plant
    x = np.asarray(x, dtype=float)
    y = np.asarray(u[0], dtype=float)
    omega_hat = (x[1] - plant.P * x[2]) / plant.car.J
    return {"y_tilde": y - omega_hat, "v_hat": plant.speed_from_eta(x[0], y), "omega_hat": omega_hat, "z_hat": x[2],
            "theta_hat": x[3]}
