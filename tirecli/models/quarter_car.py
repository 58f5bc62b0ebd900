"""Quarter car with the lumped LuGre tire: the plant of FM's brakings and OBS's observer.

``m dv/dt = F``, ``J domega/dt = -r F_w - sigma_w omega + u`` with ``F = mu F_n`` from the
lumped model (FM eqs. (8)-(9); docs/models/lugre_friction.md §7, docs/models/observer_model.md §1). FM's brakings use the consistent
form ``F_w = F``; OBS's design plant keeps ``sigma2`` in the vehicle equation only
(``F_w = F - sigma2 vr F_n``, docs/models/observer_model.md §1 [reconstructed]): the switch ``sigma2_in_wheel``
selects between the two. The right-hand side has the python-control shape ``rhs(t, x, u, p)``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.models.lugre import LuGreParams, lumped_mu, lumped_zdot
from tirecli.models.vehicle import QuarterCarParams


@dataclass(frozen=True)
class QuarterCarLumped:
    """Parameters of the quarter car with a lumped LuGre tire.

    Attributes
    ----------
    tire : LuGreParams
        Tire friction parameters (``sigma_w`` of the wheel bearing included).
    car : QuarterCarParams
        Rolling radius, quarter mass, wheel inertia, normal load.
    kappa0 : float, None or "Z"
        Lumped coefficient (FM eq. (8)/(10)); ``None`` takes ``tire.kappa0``.
    sigma2_in_wheel : bool
        True: ``sigma2 vr`` acts on the wheel too (FM); False: vehicle equation only (OBS (3)-(4)).
    """

    tire: LuGreParams
    car: QuarterCarParams
    kappa0: float | str | None = None
    sigma2_in_wheel: bool = True


def outputs(x, u, p: QuarterCarLumped):
    """Derived quantities at state ``x = (v, omega, z)`` and input ``u = (torque, theta_fm)``.

    Returns ``(vr, zdot, mu)``: relative velocity [m/s], bristle rate [m/s] and friction [-].
    """
    v, omega, z = x
    theta = u[1]
    romega = p.car.r * omega
    vr = romega - v
    zdot = lumped_zdot(z, vr, romega, p.tire, p.kappa0, theta)
    mu = lumped_mu(z, zdot, vr, p.tire)
    return vr, zdot, mu


def rhs(t, x, u, p: QuarterCarLumped):
    """Time derivative of ``x = (v [m/s], omega [rad/s], z [m])``.

    Parameters
    ----------
    t : float
        Time [s] (unused: the system is autonomous given ``u``).
    x : array_like
        State: vehicle speed, wheel speed, mean bristle deflection.
    u : tuple
        ``(torque [N m], theta_fm [-])``: wheel torque (> 0 drives) and road adhesion.
    p : QuarterCarLumped

    Returns
    -------
    ndarray
        ``(dv/dt [m/s^2], domega/dt [rad/s^2], dz/dt [m/s])``.
    """
    v, omega, z = x
    vr, zdot, mu = outputs(x, u, p)
    F = mu * p.car.F_n
    Fw = F if p.sigma2_in_wheel else F - p.tire.sigma2 * vr * p.car.F_n
    dv = F / p.car.m
    domega = (-p.car.r * Fw - p.tire.sigma_w * omega + u[0]) / p.car.J
    return np.array([dv, domega, zdot], dtype=float)
