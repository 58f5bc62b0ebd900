"""Effective rolling radius of MF 6.1 (docs/models/magic_formula_tyre.md §7.3; mfeval's form).

``R_Omega = R0 (Q_RE0 + Q_V1 (Omega R0 / V0)^2)``,
``R_e = R_Omega - (Fz0 / C_z) (DREFF arctan(BREFF Fz/Fz0) + FREFF Fz/Fz0)``,
``C_z = VERTICAL_STIFFNESS (1 + PFZ1 dpi)``; for a given slip ``kappa`` the wheel speed is
``Omega = (1 + kappa) Vx / R_e``, solved by fixed-point iteration (the forces do not depend on
``R_e`` when ``kappa`` is an input). ``kappa = (Omega R_e - V_cx)/|V_cx|`` links the two
(:func:`tirecli.conventions.kappa_from_slip` for the LuGre slip).
"""
from __future__ import annotations

import numpy as np


def has_radius(t) -> bool:
    """True when the tyre gives the coefficients of §7.3 (``Q_RE0`` and ``VERTICAL_STIFFNESS`` > 0)."""
    c = t.coef
    return bool(c.get("Q_RE0")) and bool(c.get("VERTICAL_STIFFNESS"))


def nominal_vertical_stiffness(t, p=None):
    """``C_z = VERTICAL_STIFFNESS (1 + PFZ1 dpi)`` [N/m] (paper eq. 5; ``dpi`` 0 without pressure effect).

    Parameters
    ----------
    t : MFTire
    p : array_like or None
        Inflation pressure [Pa] (None: no pressure effect).
    """
    c = t.coef
    cz = c["VERTICAL_STIFFNESS"]
    pi0 = t.nominal_pressure
    if p is not None and pi0:
        cz = cz * (1.0 + c.get("PFZ1", 0.0) * (np.asarray(p, dtype=float) - pi0) / pi0)
    return cz


def free_spinning_radius(t, omega):
    """``R_Omega = R0 (Q_RE0 + Q_V1 (Omega R0 / V0)^2)`` [m] (paper eq. 1): the free radius grown by the
    wheel speed ``omega`` [rad/s] (``V0`` = ``LONGVL``)."""
    c = t.coef
    r0 = c["UNLOADED_RADIUS"]
    v0 = t.reference_speed or 1.0
    return r0 * (c["Q_RE0"] + c.get("Q_V1", 0.0) * np.square(np.asarray(omega, dtype=float) * r0 / v0))


def effective_rolling_radius(t, fz, kappa, vx, p=None, iterations: int = 30, tol: float = 1e-12):
    """Effective rolling radius ``R_e`` [m] and wheel speed ``Omega`` [rad/s] (§7.3).

    Parameters
    ----------
    t : MFTire
    fz : array_like
        Vertical load [N].
    kappa : array_like
        Longitudinal slip [-].
    vx : array_like
        Forward speed of the contact centre [m/s].
    p : array_like or None
        Inflation pressure [Pa] (None: no pressure effect).

    Raises
    ------
    ValueError
        When the tyre lacks ``Q_RE0`` or ``VERTICAL_STIFFNESS``.
    """
    if not has_radius(t):
        raise ValueError("the effective rolling radius needs Q_RE0 and VERTICAL_STIFFNESS (docs/models/magic_formula_tyre.md §7.3)")
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    fz, kappa, vx = (np.asarray(a, dtype=float) for a in (fz, kappa, vx))
    cz = nominal_vertical_stiffness(t, p)
    fzn = fz / fz0
    defl = (fz0 / cz) * (c.get("DREFF", 0.0) * np.arctan(c.get("BREFF", 0.0) * fzn) + c.get("FREFF", 0.0) * fzn)
    re = r0 * c["Q_RE0"] - defl
    omega = (1.0 + kappa) * vx / re
    for _ in range(iterations):
        re_new = free_spinning_radius(t, omega) - defl
        omega = (1.0 + kappa) * vx / re_new
        if np.all(np.abs(re_new - re) <= tol):
            re = re_new
            break
        re = re_new
    return re, omega


def rolling_radius_or_r0(t, fz, kappa, vx, dpi=0.0):
    """``R_e`` [m] when the tyre gives §7.3's coefficients, else the unloaded radius ``R0``."""
    if not has_radius(t):
        return t.coef["UNLOADED_RADIUS"]
    pi0 = t.nominal_pressure
    p = None if not pi0 else pi0 * (1.0 + dpi)
    return effective_rolling_radius(t, fz, kappa, vx, p)[0]
