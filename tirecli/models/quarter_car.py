"""Quarter car with a LuGre tire: the plant of FM's brakings and OBS's observer (python-control shape).

``m dv/dt = F``, ``J domega/dt = -r F_w - sigma_w omega + u`` with ``F = mu F_n`` from the tire
model: the lumped tire (FM eqs. (8)-(9), :mod:`tirecli.models.lugre_lumped`) or the distributed
tire in its exact reduction (FM eqs. (1)-(2), :mod:`tirecli.models.lugre_pde`);
docs/models/lugre_friction.md §7, docs/models/observer_model.md §1. FM's brakings use the
consistent form ``F_w = F``; OBS's design plant keeps ``sigma2`` in the vehicle equation only
(``F_w = F - sigma2 vr F_n``, docs/models/observer_model.md §1 [reconstructed]): the switch
``sigma2_in_wheel`` selects between the two.

- **state** ``x = (v, omega, *tire states)``: vehicle speed [m/s], wheel speed [rad/s], then the
  tire model's state (lumped: ``z`` [m]; distributed: ``Y, Phi, X, S_0 ..``);
- **input** ``u = (torque, theta[, z_points])`` (:class:`CarInput`): wheel torque [N m] (> 0 drives),
  road adhesion [-] (FM convention) and, for the distributed tire, its tracked deflections [m];
- **parameters** ``p``: :class:`QuarterCar`;
- **outputs**: the tire's outputs (``mu``, ``zdot``, ``kappa0``, ...) with ``vr`` [m/s] and ``F`` [N].

The wheel's *locked* mode (``omega = 0`` held by the brake) and the tire alone with prescribed
kinematics are modes of the integrator (:mod:`tirecli.numerics.ros2`), not of this model: locked,
``domega/dt = 0``; prescribed, the tire model's own ``rhs``. Fast kernels that inline this model:
:class:`tirecli.numerics.lumped.LumpedStepper` (lumped tire) and
:class:`tirecli.numerics.characteristics.CharacteristicsStepper` (distributed tire); parity:
tests/test_model_parity.py.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tirecli.models import lugre_lumped, lugre_pde
from tirecli.models.lugre_lumped import LumpedTire
from tirecli.models.lugre_pde import DistributedTire
from tirecli.models.vehicle import QuarterCarParams


class CarInput(NamedTuple):
    """Input of the quarter car.

    Attributes
    ----------
    torque : array_like
        Wheel torque ``u`` [N m] (> 0 drives, < 0 brakes).
    theta : array_like
        Road adhesion [-], FM convention.
    z_points : array_like or None
        Distributed tire only: its tracked deflections [m] (:class:`tirecli.models.lugre_pde.DistributedInput`).
    """

    torque: object
    theta: object = 1.0
    z_points: object = None


@dataclass(frozen=True)
class QuarterCar:
    """Parameters of the quarter car with a LuGre tire.

    Attributes
    ----------
    tire : LumpedTire or DistributedTire
        The tire model and its parameters (``tire.params.sigma_w`` [kg m^2/s] is the wheel bearing's
        viscous friction).
    car : QuarterCarParams
        Rolling radius [m], quarter mass [kg], wheel inertia [kg m^2], normal load [N].
    sigma2_in_wheel : bool
        True: ``sigma2 vr`` acts on the wheel too (FM); False: vehicle equation only (OBS (3)-(4)).
    """

    tire: LumpedTire | DistributedTire
    car: QuarterCarParams
    sigma2_in_wheel: bool = True


def _tire_model(p: QuarterCar):
    """The module (``rhs``, ``outputs``, ``friction``) of the quarter car's tire model."""
    return lugre_pde if isinstance(p.tire, DistributedTire) else lugre_lumped


def _kinematics(x, u, p: QuarterCar):
    """``(state array, vr [m/s], tire input)`` at ``x``, ``u``."""
    x = np.asarray(x, dtype=float)
    romega = p.car.r * x[1]
    vr = romega - x[0]
    return x, vr, (vr, romega, u[1]) + tuple(u[2:])


def rhs(t, x, u, p: QuarterCar):
    """Time derivative of the quarter car's state (module doc; FM §7, OBS (3)-(5)).

    Parameters
    ----------
    t : float
        Time [s] (unused: the system is autonomous given ``u``).
    x : array_like, shape (2 + n, ...)
        State ``(v [m/s], omega [rad/s], *tire states)`` (``n`` tire states: lumped ``(z [m],)``).
    u : sequence
        ``(torque [N m], theta [-][, z_points [m]])`` (:class:`CarInput`).
    p : QuarterCar

    Returns
    -------
    ndarray, shape (2 + n, ...)
        ``(dv/dt [m/s^2], domega/dt [rad/s^2], *d(tire states)/dt)`` with ``m dv/dt = F``,
        ``J domega/dt = -r F_w - sigma_w omega + u``, ``F = mu F_n``.
    """
    x, vr, tu = _kinematics(x, u, p)
    model, car, tire = _tire_model(p), p.car, p.tire.params
    dtire = model.rhs(t, x[2:], tu, p.tire)
    F = model.friction(x[2:], dtire, tu, p.tire) * car.F_n
    Fw = F if p.sigma2_in_wheel else F - tire.sigma2 * vr * car.F_n
    dv = F / car.m
    domega = (-car.r * Fw - tire.sigma_w * x[1] + u[0]) / car.J
    out = np.empty((2 + len(dtire),) + dtire.shape[1:])
    out[0], out[1], out[2:] = dv, domega, dtire
    return out


def outputs(t, x, u, p: QuarterCar) -> dict:
    """Outputs at state ``x`` and input ``u`` (arguments as :func:`rhs`; FM eqs. (2), (9), docs/models/lugre_friction.md §7).

    Returns
    -------
    dict
        The tire model's outputs (``mu`` [-], ``zdot`` [m/s], ``kappa0`` [-]; distributed also ``zbar``,
        ``z_trailing`` [m]) with ``vr`` [m/s], the relative velocity ``r omega - v``, and ``F`` [N], the
        longitudinal tire force ``mu F_n`` on the vehicle.
    """
    x, vr, tu = _kinematics(x, u, p)
    out = dict(_tire_model(p).outputs(t, x[2:], tu, p.tire))
    out["vr"] = vr
    out["F"] = out["mu"] * p.car.F_n
    return out
