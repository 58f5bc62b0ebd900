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

Tyre axis conventions (docs/data.md "Axis conventions")
-------------------------------------------------------
Measured tyre forces, moments and slips come in one of three conventions; tirecli converts them to
ISO-W (the TYDEX W axes of ``.tir`` files and ``tirecli mf eval``: x forward, y left, z up, the forces
and moments the road exerts on the tyre, so ``Fz > 0`` under load) with :func:`axes_to_iso`:

- ``iso``: ISO-W itself; nothing changes.
- ``sae``: SAE J670 (x forward, y right, z down), a rotation by 180 degrees about x: ``alpha``,
  ``Fy``, ``Fz``, ``My``, ``Mz`` change sign (``Fz < 0`` under load); ``kappa``, ``gamma``, ``Fx``, ``Mx``
  do not.
- ``adapted-iso``: ISO-W axes with the slip angle and the inclination counted the other way, so that a
  positive ``alpha`` and a positive ``gamma`` give a positive side force: ``alpha`` and ``gamma`` change sign,
  every force and moment keeps its ISO-W sign (``Fz > 0`` under load).

Each map is its own inverse (:func:`axes_from_iso` is :func:`axes_to_iso`).
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


def wheel_torque_from_brake(brake_torque):
    """The wheel torque ``u`` of the quarter car and the observer [N m] (> 0 drives, < 0 brakes) from a brake
    torque [N m] counted positive when it brakes: ``u = -brake_torque``."""
    return -np.asarray(brake_torque, dtype=float)


#: Axis conventions of measured tyre data (:func:`axes_to_iso`).
AXIS_CONVENTIONS = ("iso", "sae", "adapted-iso")

#: Quantities whose sign each convention reverses against ISO-W (the others keep it).
_FLIPPED = {
    "iso": frozenset(),
    "sae": frozenset({"alpha", "fy", "fz", "my", "mz"}),
    "adapted-iso": frozenset({"alpha", "gamma"}),
}

#: Quantities an axis convention can touch (slips, angles, forces, moments at the contact point).
AXIS_QUANTITIES = ("kappa", "alpha", "gamma", "fx", "fy", "fz", "mx", "my", "mz")


def axis_sign(name: str, convention: str) -> float:
    """``+1.0`` or ``-1.0``: the factor taking quantity ``name`` from ``convention`` to ISO-W (and back).

    ``name`` is one of :data:`AXIS_QUANTITIES` (any other name, e.g. a time or a pressure: ``+1``).
    """
    if convention not in _FLIPPED:
        raise ValueError(f"unknown axis convention {convention!r}; expected one of {', '.join(AXIS_CONVENTIONS)}")
    return -1.0 if name in _FLIPPED[convention] else 1.0


def flipped(convention: str) -> tuple[str, ...]:
    """The quantities whose sign ``convention`` reverses against ISO-W, in :data:`AXIS_QUANTITIES` order."""
    axis_sign("fx", convention)  # checks the name
    return tuple(q for q in AXIS_QUANTITIES if q in _FLIPPED[convention])


def axes_to_iso(values: dict, convention: str) -> dict:
    """Convert a mapping ``name -> value`` given in ``convention`` to ISO-W (a new dict; arrays are not
    changed in place; names outside :data:`AXIS_QUANTITIES` and ``None`` values pass through)."""
    out = {}
    for k, v in values.items():
        s = axis_sign(k, convention)
        out[k] = v if v is None or s > 0 else -np.asarray(v, dtype=float)
    return out


#: The inverse of :func:`axes_to_iso` (every map is an involution).
axes_from_iso = axes_to_iso


def iso_to_sae(fx=None, fy=None, fz=None, mx=None, my=None, mz=None, alpha=None) -> dict:
    """Convert ISO-W quantities to SAE J670 (and back: the map is its own inverse).

    ``Fy`` [N], ``Fz`` [N], ``My`` [N m], ``Mz`` [N m] and ``alpha`` [rad] change sign; ``Fx`` [N]
    and ``Mx`` [N m] (and ``kappa``, ``gamma``) do not. ``None`` entries are passed through; the other
    values are returned as float arrays.
    """
    vals = {"fx": fx, "fy": fy, "fz": fz, "mx": mx, "my": my, "mz": mz, "alpha": alpha}
    out = {}
    for k, v in vals.items():
        a = None if v is None else np.asarray(v, dtype=float)
        out[k] = a if a is None or axis_sign(k, "sae") > 0 else -a
    return out


sae_to_iso = iso_to_sae
