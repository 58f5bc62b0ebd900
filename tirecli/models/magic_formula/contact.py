"""Vertical deflection, vertical stiffness and contact-patch size of a Magic Formula tyre (static maps).

docs/models/magic_formula_tyre.md §17.3-§17.4; mfeval's forms (``Solver.calculateRhoRl61``,
``calculateRhoRl62``, ``calculateContactPatch``; outputs ``rho``, ``Cz``, ``2a``, ``2b``):

- deflection (book A3.3, paper eq. 4): ``Fz = f_corr (Q_FZ1 rho/R0 + Q_FZ2 (rho/R0)^2) Fz0`` with
  ``Q_FZ1 = sqrt((C_z0 R0/Fz0)^2 - 4 Q_FZ2)`` and
  ``f_corr = (1 + Q_V2 (R0/V0)|Omega| - (Q_FCX Fx/Fz0)^2 - (Q_FCY Fy/Fz0)^2)(1 + PFZ1 dpi)``;
  MF 5.2 / 6.1 solve this quadratic for ``rho``, MF 6.2 adds the camber and lateral-force terms of
  the MF-Swift 6.2 manual (``Q_FCY2``, ``Q_CAM1-3``, ``Q_FYS1-3``) and is solved for the loaded radius;
  the vertical stiffness reported is the secant ``C_z = Fz / rho`` [N/m];
- contact patch half-length and half-width (paper eqs. 9, 10): ``a = R0 (Q_RA2 r + Q_RA1 sqrt(r))``,
  ``b = W (Q_RB2 r + Q_RB1 r^(1/3))`` with ``r = Fz/(C_z0' R0)``, ``C_z0' = VERTICAL_STIFFNESS (1 + PFZ1 dpi)``;
  MF 5.2 (MF-Tyre 5.2 manual): ``a = R0 (Q_A2 Fz/Fz0 + Q_A1 sqrt(Fz/Fz0))``, ``b = W/2``, and when a file
  gives neither ``Q_A1`` nor ``Q_A2`` mfeval's empirical values from ``y = log10(R0 C_z0/Fz0)``:
  ``Q_A1 = -0.0388 y^3 + 0.2509 y^2 - 0.6283 y + 0.6279``, ``Q_A2 = 1.693 Q_A1^2``. The load is the
  unclipped one, held at ``(R0 - RIM_RADIUS - BOTTOM_OFFST) C_z0'`` once the rim would bottom.

What a file does not give is absent (NaN, :func:`available`); coefficients of a formula that are not
given count 0 (tirecli's rule for model coefficients), its base values are required.
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula.radius import free_spinning_radius, has_radius, nominal_vertical_stiffness
from tirecli.models.magic_formula.tire import MFTire

_MF62_KEYS = ("Q_FCY2", "Q_CAM1", "Q_CAM2", "Q_CAM3", "Q_FYS1", "Q_FYS2", "Q_FYS3")


def _has(t: MFTire, key: str) -> bool:
    return bool(t.coef.get(key))


def available(t: MFTire) -> dict:
    """Which of ``Cz, a, b`` the tyre gives: ``{name: bool}`` (all False for PAC89)."""
    if t.family != "mf" or not _has(t, "VERTICAL_STIFFNESS"):
        return {"Cz": False, "a": t.family == "mf" and t.is_52 and bool({"Q_A1", "Q_A2"} & set(t.coef)),
                "b": t.family == "mf" and t.is_52 and _has(t, "WIDTH")}
    c = t.coef
    speed = not c.get("Q_V2") or (has_radius(t) and bool(t.reference_speed))
    cz = speed and (has_radius(t) if t.version == "6.2" else True)
    if t.is_52:
        return {"Cz": cz, "a": True, "b": _has(t, "WIDTH")}
    return {"Cz": cz, "a": "Q_RA1" in c or "Q_RA2" in c,
            "b": _has(t, "WIDTH") and ("Q_RB1" in c or "Q_RB2" in c)}


def _q_fz1(t: MFTire):
    c = t.coef
    return np.sqrt(np.maximum((c["VERTICAL_STIFFNESS"] * c["UNLOADED_RADIUS"] / c["FNOMIN"]) ** 2
                              - 4.0 * c.get("Q_FZ2", 0.0), 0.0))


def _f_corr(t: MFTire, omega, fx, fy_term, p):
    """``f_corr`` of the deflection equation: speed, force and pressure factors (``fy_term`` the scaled
    lateral force part ``Q_FCY Fy/Fz0`` or its MF 6.2 form)."""
    c = t.coef
    fz0, r0 = c["FNOMIN"], c["UNLOADED_RADIUS"]
    speed = 0.0
    if c.get("Q_V2"):
        speed = c["Q_V2"] * (r0 / t.reference_speed) * np.abs(omega)
    f = 1.0 + speed - np.square(c.get("Q_FCX", 0.0) * fx / fz0) - np.square(fy_term)
    return f * (nominal_vertical_stiffness(t, p) / c["VERTICAL_STIFFNESS"])


def _fz62(t: MFTire, rl, r_omega, gamma, omega, fx, fy, p):
    """MF 6.2 vertical force [N] and deflection ``rho_z`` [m] at the loaded radius ``rl`` (MF-Swift 6.2
    manual, as mfeval's ``calculateFz62``)."""
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    ratio = rl / r_omega
    sfyg = (c.get("Q_FYS1", 0.0) + c.get("Q_FYS2", 0.0) * ratio + c.get("Q_FYS3", 0.0) * np.square(ratio)) * gamma
    rho_fr = np.maximum(r_omega - rl, 0.0)
    q1, q2 = c.get("Q_CAM1", 0.0), c.get("Q_CAM2", 0.0)
    rtw = (1.075 - 0.5 * c.get("ASPECT_RATIO", 0.0)) * c.get("WIDTH", 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        rho_g = (np.square((q1 * rl + q2 * np.square(rl)) * gamma) * (rtw / 8.0) * np.abs(np.tan(gamma))
                 / np.square((q1 * r_omega + q2 * np.square(r_omega)) * gamma)
                 - c.get("Q_CAM3", 0.0) * rho_fr * np.abs(gamma))
    rho_g = np.where(np.isfinite(rho_g), rho_g, 0.0)
    rho = np.maximum(rho_fr + rho_g, 0.0)
    x = rho / r0
    fy_term = np.power(x, c.get("Q_FCY2", 0.0)) * c.get("Q_FCY", 0.0) * (fy - sfyg) / fz0
    f = _f_corr(t, omega, fx, fy_term, p)
    return f * (_q_fz1(t) * x + c.get("Q_FZ2", 0.0) * np.square(x)) * fz0, rho


def deflection(t: MFTire, fz, fx=0.0, fy=0.0, omega=0.0, gamma=0.0, p=None, *, fz_target=None,
               iterations: int = 80):
    """Vertical deflection ``rho`` [m] and secant vertical stiffness ``C_z = Fz/rho`` [N/m] (§17.3).

    Parameters
    ----------
    t : MFTire
        An MF 6.x or 5.2 tyre with ``VERTICAL_STIFFNESS`` (and the speed and radius keys it needs, see
        :func:`available`).
    fz : array_like
        Vertical load [N] (mfeval: the load raised to ``FZMIN``; the stiffness is ``fz/rho``).
    fx, fy : array_like
        Longitudinal and lateral force at the point [N] (they soften the tyre through ``Q_FCX``, ``Q_FCY``).
    omega : array_like
        Wheel speed [rad/s] (through ``Q_V2``; MF 6.2 also through the free radius ``R_Omega``).
    gamma : array_like
        Inclination [rad] (MF 6.2 only).
    p : array_like or None
        Inflation pressure [Pa] (None: no pressure effect).
    fz_target : array_like or None
        MF 6.2: load the deflection is solved for (mfeval: the unclipped load; default ``fz``).
    iterations : int
        Bisection steps of the MF 6.2 solve (80 halve the bracket below 1e-24 R0).

    Returns
    -------
    (ndarray, ndarray)
        ``rho`` [m], ``C_z`` [N/m]; at zero load ``C_z`` is the limit of ``Fz/rho`` (mfeval writes 0 there).
    """
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    fz, fx, fy, omega, gamma = (np.asarray(a, dtype=float) for a in (fz, fx, fy, omega, gamma))
    q1, q2 = _q_fz1(t), c.get("Q_FZ2", 0.0)
    if t.version == "6.2":
        target = fz if fz_target is None else np.asarray(fz_target, dtype=float)
        shape = np.broadcast_shapes(*(np.shape(a) for a in (fz, target, fx, fy, omega, gamma)),
                                    np.shape(p) if p is not None else ())
        r_omega = np.broadcast_to(free_spinning_radius(t, omega), shape)
        lo = r_omega - r0  # deflection R0: far beyond any load (a bracket, Fz(R_l) falls with R_l)
        hi = np.array(r_omega, dtype=float)
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            f_mid, _ = _fz62(t, mid, r_omega, gamma, omega, fx, fy, p)
            above = f_mid > target  # too much deflection: raise the loaded radius
            lo = np.where(above, mid, lo)
            hi = np.where(above, hi, mid)
        _, rho = _fz62(t, 0.5 * (lo + hi), r_omega, gamma, omega, fx, fy, p)
        f0 = _f_corr(t, omega, 0.0, 0.0, p)
    else:
        f = _f_corr(t, omega, fx, c.get("Q_FCY", 0.0) * fy / fz0, p)
        rhs = fz / (fz0 * f)
        if q2 == 0.0:
            x = rhs / q1
        else:
            x = (-q1 + np.sqrt(np.maximum(q1 * q1 + 4.0 * q2 * rhs, 0.0))) / (2.0 * q2)
        rho = np.maximum(x * r0, 0.0)
        f0 = f
    with np.errstate(divide="ignore", invalid="ignore"):
        cz = np.where(rho > 0, fz / rho, f0 * q1 * fz0 / r0)
    return rho, cz


def contact_patch(t: MFTire, fz, p=None):
    """Contact-patch half-length ``a`` and half-width ``b`` [m] (paper eqs. 9, 10; MF-Tyre 5.2 manual).

    Parameters
    ----------
    t : MFTire
        An MF 6.x or 5.2 tyre.
    fz : array_like
        Vertical load [N], unclipped (negative counts 0); held at the rim-bottoming load when the
        file gives ``RIM_RADIUS``.
    p : array_like or None
        Inflation pressure [Pa] (None: no pressure effect).

    Returns
    -------
    (ndarray, ndarray)
        ``a``, ``b`` [m] (mfeval writes the full length ``2a`` and width ``2b``); NaN where the file
        lacks the coefficients (:func:`available`).
    """
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    fz = np.maximum(np.asarray(fz, dtype=float), 0.0)
    shape = np.broadcast_shapes(np.shape(fz), np.shape(p) if p is not None else ())
    have = available(t)
    ncz = nominal_vertical_stiffness(t, p) if _has(t, "VERTICAL_STIFFNESS") else None
    if ncz is not None and "RIM_RADIUS" in c:
        fz_max = (r0 - c["RIM_RADIUS"] - c.get("BOTTOM_OFFST", 0.0)) * ncz
        fz = np.where(r0 - fz / ncz < c["RIM_RADIUS"] + c.get("BOTTOM_OFFST", 0.0), fz_max, fz)
    a = b = np.nan
    if t.is_52:
        q_a1, q_a2 = c.get("Q_A1", 0.0), c.get("Q_A2", 0.0)
        if q_a1 == 0.0 and q_a2 == 0.0 and ncz is not None:
            y = np.log10(r0 * c["VERTICAL_STIFFNESS"] / fz0)
            q_a1 = -0.0388 * y ** 3 + 0.2509 * y ** 2 - 0.6283 * y + 0.6279
            q_a2 = 1.693 * q_a1 ** 2
        if have["a"]:
            a = r0 * (q_a2 * fz / fz0 + q_a1 * np.sqrt(fz / fz0))
        if have["b"]:
            b = c["WIDTH"] / 2.0
    else:
        r = fz / (ncz * r0) if ncz is not None else np.nan
        if have["a"]:
            a = r0 * (c.get("Q_RA2", 0.0) * r + c.get("Q_RA1", 0.0) * np.sqrt(r))
        if have["b"]:
            b = c["WIDTH"] * (c.get("Q_RB2", 0.0) * r + c.get("Q_RB1", 0.0) * np.cbrt(r))
    return (np.broadcast_to(np.asarray(a, dtype=float), shape).copy(),
            np.broadcast_to(np.asarray(b, dtype=float), shape).copy())


__all__ = ["available", "deflection", "contact_patch"]
