"""The MCPS belt on the rim: linear springs and dampers (MCPS eq. 17; docs/models/mcps_tire.md §7).

python-control shape, pure and vectorized (state axis first; trailing axes broadcast):

- **state** ``x = (x, y, delta, xdot, ydot, delta_dot)``: belt displacement relative to the rim
  [m, m, rad] and its rates [m/s, m/s, rad/s];
- **input** ``u = (FWx, FWy, MW)`` (:class:`BeltInput`): the patch load in the wheel frame [N, N, N m]
  (MCPS eq. 16, :func:`tirecli.models.mcps.tire.wheel_forces`);
- **parameters** ``p``: :class:`~tirecli.models.mcps.params.MCPSParams` (``m_b``, ``J_b``, ``k_*``, ``c_*``);
- **outputs**: the forces the belt's springs and dampers put on the rim ``k q + c qdot``
  (``rim_fx``, ``rim_fy`` [N], ``rim_mz`` [N m]).

The slider velocities the belt imposes on the patch are :func:`tirecli.models.mcps.tire.belt_velocities`.
Fast kernel that inlines it: the trapezoidal belt step of
:func:`tirecli.numerics.mcps_transient.simulate_rolling` (``_belt_matrices``); parity:
tests/test_model_parity.py.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np


class BeltInput(NamedTuple):
    """Input of the belt: the patch load in the wheel frame R_W (MCPS eq. 16).

    Attributes
    ----------
    fx, fy : array_like
        Road-on-tire force on the belt [N].
    mz : array_like
        Road-on-tire torque about the rim centre [N m].
    """

    fx: object
    fy: object
    mz: object


def rhs(t, x, u, p):
    """Belt dynamics on the rim (MCPS eq. 17).

    ``m_b xdd = -c_x xd - k_x x + FWx``, ``m_b ydd = -c_y yd - k_y y + FWy``,
    ``J_b dd = -c_delta dd - k_delta delta + MW``.

    Parameters
    ----------
    t : float
        Time [s] (unused: autonomous given ``u``).
    x : array_like, shape (6, ...)
        ``(x, y, delta, xdot, ydot, delta_dot)`` [m, m, rad, m/s, m/s, rad/s].
    u : sequence
        ``(FWx [N], FWy [N], MW [N m])`` (:class:`BeltInput`).
    p : MCPSParams

    Returns
    -------
    ndarray, shape (6, ...)
        ``(xdot, ydot, delta_dot [m/s, m/s, rad/s], xdd, ydd [m/s^2], dd [rad/s^2])``.
    """
    x_, y, de, xd, yd, dd = np.asarray(x, dtype=float)
    fx, fy, mz = u
    return np.array(np.broadcast_arrays(xd, yd, dd,
                                        (-p.c_x * xd - p.k_x * x_ + fx) / p.m_b,
                                        (-p.c_y * yd - p.k_y * y + fy) / p.m_b,
                                        (-p.c_delta * dd - p.k_delta * de + mz) / p.J_b))


def outputs(t, x, u, p) -> dict:
    """The forces the belt puts on the rim at state ``x`` (arguments as :func:`rhs`; MCPS eq. 17).

    Returns
    -------
    dict
        ``rim_fx = k_x x + c_x xdot``, ``rim_fy = k_y y + c_y ydot`` [N], ``rim_mz = k_delta delta +
        c_delta delta_dot`` [N m].
    """
    x_, y, de, xd, yd, dd = np.asarray(x, dtype=float)
    return {"rim_fx": p.k_x * x_ + p.c_x * xd, "rim_fy": p.k_y * y + p.c_y * yd,
            "rim_mz": p.k_delta * de + p.c_delta * dd}
