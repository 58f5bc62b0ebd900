"""Sign and slip conventions of tirecli, stated once.

Every other module imports its slip, sign and adhesion conversions from here.

Quantities (SI units throughout)
--------------------------------
- ``v``       longitudinal speed of the wheel centre (vehicle speed) [m/s]
- ``omega``   wheel angular speed [rad/s]
- ``r``       effective rolling radius [m]
- ``vr``      relative (slip) velocity of the tread w.r.t. the road, ``vr = r*omega - v`` [m/s]
- ``F``       longitudinal tire/road force on the wheel, **positive when it accelerates
  the vehicle** [N]; ``mu = F / F_n`` [-]

Signs (docs/models/lugre_friction.md §1)
-------------------
- ``vr > 0`` (tread faster than the ground, ``r*omega > v``): driving / traction, ``F > 0``.
- ``vr < 0`` (``v > r*omega``): braking, ``F < 0``.
- In steady state the bristle deflection ``z``, ``F`` and ``vr`` share one sign.

Slip ratio (FM, remark after eq. (6); OBS §II-c)
------------------------------------------------
For forward motion (``v >= 0``, ``omega >= 0``):

- braking (``v > r*omega``): ``s = r*omega/v - 1`` in ``[-1, 0)``;
- driving (``r*omega > v``): ``s = 1 - v/(r*omega)`` in ``(0, 1]``.

Compactly ``s = vr / max(v, r*omega)``; ``s`` has the sign of ``vr`` and ``s = 0`` when both
speeds are zero. Published curves plot ``|mu|`` against ``|s|``. A steady-state curve holds a
second coordinate fixed: the vehicle speed ``v`` for braking, the wheel circumferential speed
``r*omega`` for driving (see :func:`speeds_from_slip`).

The Magic Formula uses the ISO-W practical slip ``kappa = (r_e*Omega - V_cx)/|V_cx|`` instead
(docs/models/magic_formula_tyre.md §2.2); :func:`kappa_from_slip` converts between the two.

Road adhesion theta (docs/models/lugre_friction.md §5)
---------------------------------
- FM convention ``theta_fm``: the Stribeck level is scaled, ``g -> theta_fm * g``;
  1 = nominal (dry), < 1 = less grip. **This is the canonical stored value.**
- OBS convention ``theta_obs``: theta multiplies the sliding term ``sigma0 |vr| / g``;
  1 = nominal, > 1 = less grip.
- They are exactly equivalent: ``theta_obs = 1 / theta_fm``.
"""
from __future__ import annotations

import numpy as np

#: The two theta conventions, by name.
THETA_CONVENTIONS = ("fm", "obs")

#: The two kinematic regimes of a steady-state curve.
DIRECTIONS = ("braking", "driving")


def relative_velocity(v, omega, r):
    """Relative (slip) velocity ``vr = r*omega - v`` [m/s] (docs/models/lugre_friction.md §1).

    Parameters
    ----------
    v : array_like
        Vehicle speed [m/s].
    omega : array_like
        Wheel angular speed [rad/s].
    r : float
        Rolling radius [m].
    """
    return r * np.asarray(omega, dtype=float) - np.asarray(v, dtype=float)


def slip_from_speeds(v, omega, r):
    """Signed slip ratio ``s = vr / max(v, r*omega)`` [-] (FM after eq. (6); OBS §II-c).

    Braking gives ``s in [-1, 0)``, driving ``s in (0, 1]``; ``s = 0`` where ``v = r*omega``,
    including the standstill ``v = omega = 0``.

    Parameters
    ----------
    v : array_like
        Vehicle speed [m/s], ``>= 0``.
    omega : array_like
        Wheel angular speed [rad/s], ``>= 0``.
    r : float
        Rolling radius [m].
    """
    v = np.asarray(v, dtype=float)
    rw = r * np.asarray(omega, dtype=float)
    vr = rw - v
    den = np.maximum(np.abs(v), np.abs(rw))
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(den > 0.0, vr / np.where(den > 0.0, den, 1.0), 0.0)
    return s


def slip_of(v: float, omega: float, r: float) -> float:
    """:func:`slip_from_speeds` of one pair of floats, without arrays: the same value, bit for bit
    (the same operations; 0 where ``max(|v|, |r omega|)`` is not positive or either speed is NaN)."""
    v, rw = float(v), r * float(omega)
    if v != v or rw != rw:
        return 0.0
    den = max(abs(v), abs(rw))
    return (rw - v) / den if den > 0.0 else 0.0


def speeds_from_slip(s, speed):
    """Vehicle and wheel speeds ``(v, r*omega)`` [m/s] for a slip ``s`` at a held speed.

    The held coordinate follows the papers' steady-state curves (docs/models/lugre_friction.md §1): for braking
    (``s <= 0``) ``speed`` is the vehicle speed ``v`` and ``r*omega = v (1 + s)``; for
    driving (``s > 0``) ``speed`` is the wheel speed ``r*omega`` and ``v = r*omega (1 - s)``.

    Parameters
    ----------
    s : array_like
        Signed slip [-], in ``[-1, 1]``.
    speed : array_like
        Held speed [m/s]: ``v`` where braking, ``r*omega`` where driving.

    Returns
    -------
    v, romega : ndarray
        Vehicle speed and wheel circumferential speed [m/s].
    """
    s, speed = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(speed, dtype=float))
    braking = s <= 0.0
    v = np.where(braking, speed, speed * (1.0 - s))
    romega = np.where(braking, speed * (1.0 + s), speed)
    return v, romega


def omega_from_slip(s, v, r):
    """Wheel angular speed ``omega`` [rad/s] giving slip ``s`` at vehicle speed ``v`` [m/s].

    Braking (``s <= 0``): ``r omega = v (1 + s)``; driving (``0 < s < 1``): ``r omega = v/(1 - s)``
    (``s = 1`` at ``v > 0`` has no finite wheel speed: ``inf``). Inverse of
    :func:`slip_from_speeds` at fixed ``v``.
    """
    s, v = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(v, dtype=float))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(s <= 0.0, v * (1.0 + s), v / (1.0 - s)) / r


def kappa_from_slip(s):
    """ISO-W practical slip ``kappa = (r*omega - v)/|v|`` [-] from the LuGre slip ``s``.

    Braking slips are identical (``kappa = s``); a driving slip ``s = 1 - v/(r omega)`` maps
    to ``kappa = s / (1 - s)`` (infinite at ``s = 1``, a wheel spinning at standstill).
    """
    s = np.asarray(s, dtype=float)
    with np.errstate(divide="ignore"):
        return np.where(s <= 0.0, s, s / (1.0 - s))


def slip_from_kappa(kappa):
    """LuGre slip ``s = vr / max(v, r omega)`` [-] from the ISO-W practical slip ``kappa``."""
    kappa = np.asarray(kappa, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(kappa <= 0.0, kappa, kappa / (1.0 + kappa))


def theta_obs_from_fm(theta_fm):
    """Adhesion in the OBS convention from the FM one: ``theta_obs = 1/theta_fm`` (docs/models/lugre_friction.md §5)."""
    return 1.0 / np.asarray(theta_fm, dtype=float)


def theta_fm_from_obs(theta_obs):
    """Adhesion in the FM convention from the OBS one: ``theta_fm = 1/theta_obs`` (docs/models/lugre_friction.md §5)."""
    return 1.0 / np.asarray(theta_obs, dtype=float)


def to_theta_fm(theta, convention):
    """Convert ``theta`` given in ``convention`` ("fm" or "obs") to the canonical FM value."""
    if convention == "fm":
        return np.asarray(theta, dtype=float)
    if convention == "obs":
        return theta_fm_from_obs(theta)
    raise ValueError(f"unknown theta convention {convention!r}; expected one of {THETA_CONVENTIONS}")
