"""Overturning moment ``Mx`` and rolling-resistance moment ``My`` of MF 6.1 / 5.2, vectorized.

docs/models/magic_formula_tyre.md §7.1 (``Mx``) and §7.2 (``My``), with the MF 5.2 forms of §9 (the
aligning moment ``Mz`` is in :mod:`~tirecli.models.magic_formula.aligning`).
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula.tire import Convention, MFTire


def overturning(t: MFTire, cv: Convention, b, fz, gamma, fy, fz_scale=None):
    """Overturning moment ``Mx`` [N m] (§7.1): draft-paper eq. 49 (mfeval) or the teasit 4.E69
    variant; MF 5.2: ``R0 Fz (QSX1 LVMX - QSX2 gamma + QSX3 Fy/Fz0) LMX``. ``fz_scale`` is the
    low-load factor ``(Fz/FZMIN)^2`` of the limits (None: none)."""
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    fze = fz * fz_scale if fz_scale is not None else fz
    if t.is_52:
        return r0 * fze * (c["QSX1"] * c["LVMX"] - c["QSX2"] * gamma + c["QSX3"] * fy / fz0) * c["LMX"]
    if not any(c[f"QSX{i}"] for i in range(1, 15)):
        return np.zeros(np.broadcast(fz, fy).shape) if np.ndim(fy) or np.ndim(fz) else 0.0
    g = b.g_star if cv.mx_book else gamma
    q2 = c["QSX2"] * g
    if np.any(b.dpi):
        q2 = q2 * (1.0 + c["PPMX1"] * b.dpi)
    fyn = fy / fz0
    fzn = fze / fz0
    if cv.mx_book:
        q4 = np.cos(c["QSX5"] * np.square(np.arctan(c["QSX6"] * fzn)))
    else:
        q4 = np.cos(c["QSX5"] * np.arctan(np.square(c["QSX6"] * fzn)))
    inner = (c["QSX1"] * c["LVMX"] - q2 + c["QSX3"] * fyn
             + c["QSX4"] * q4 * np.sin(c["QSX7"] * g + c["QSX8"] * np.arctan(c["QSX9"] * fyn))
             + c["QSX10"] * np.arctan(c["QSX11"] * fzn) * g)
    mx = r0 * fze * c["LMX"] * inner
    if not cv.mx_book and (c["QSX12"] or c["QSX13"] or c["QSX14"]):
        mx = mx + r0 * c["LMX"] * (fy * (c["QSX13"] + c["QSX14"] * np.abs(gamma))
                                   - fze * c["QSX12"] * gamma * np.abs(gamma))
    return mx


def rolling(t: MFTire, cv: Convention, b, fz, gamma, vx, p, fx, fz_scale=None):
    """Rolling-resistance moment ``My`` [N m] (§7.2): paper A48 (mfeval: ``-R0 Fz0 ...``), teasit
    (``-R0 Fz ...``) or MF 5.2 (``-R0 Fz LMY (QSY1 + QSY2 Fx/Fz0 + QSY3 |Vx/V0| + QSY4 (Vx/V0)^4)``).
    Negative for forward rolling. ``fz_scale`` is the low-load factor ``Fz/FZMIN`` of the limits."""
    c = t.coef
    r0, fz0 = c["UNLOADED_RADIUS"], c["FNOMIN"]
    fze = fz * fz_scale if fz_scale is not None else fz
    v0 = t.reference_speed
    speed = 0.0
    if c["QSY3"] or c["QSY4"]:
        if not v0:
            raise ValueError("QSY3/QSY4 need the reference speed LONGVL, which the tyre does not give")
        vn = vx / v0
        speed = c["QSY3"] * np.abs(vn) + c["QSY4"] * np.square(np.square(vn))
    inner = c["QSY1"] + speed
    if c["QSY2"]:
        inner = inner + c["QSY2"] * fx / fz0
    if t.is_52:
        return -r0 * fze * c["LMY"] * inner
    if c["QSY5"] or c["QSY6"]:
        inner = inner + (c["QSY5"] + c["QSY6"] * fze / fz0) * np.square(gamma)
    lead = fze if cv.my_leading_fz else fz0
    my = -r0 * lead * c["LMY"] * inner
    if c["QSY7"]:
        my = my * (fze / fz0) ** c["QSY7"]
    pi0 = t.nominal_pressure
    if c["QSY8"] and pi0 and p is not None:
        my = my * (p / pi0) ** c["QSY8"]
    return my
