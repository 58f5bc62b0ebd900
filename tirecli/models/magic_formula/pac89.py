"""The simple Magic Formula of Bakker, Pacejka & Lidner (SAE 890087), "PAC89" (docs/models/magic_formula_tyre.md §13.2).

Per-load B, C, D, E and shifts from the coefficients ``A0..A13`` (lateral), ``B0..B10``
(longitudinal) and ``C0..C17`` (aligning), in the units of the form: ``Fz`` in **kN**, ``kappa``
in **percent**, ``alpha`` and ``gamma`` in **degrees**; forces in N, ``Mz`` in N m. The
coefficients are written, as in Adams and Chrono's ``ChPac89Tire``, for a "modified SAE" frame
with ``alpha`` taken as the ISO slip angle; the results are returned in ISO-W
(``Fx``, ``-Fy``, ``-Mz``), as Chrono does. Forces are uncombined (each from its own slip), as in
the '89 form; ``Mx`` and ``My`` are not part of it and are returned as 0.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.models.magic_formula.curve import sin_curve

_DEG = 180.0 / math.pi


def _b(bcd, c, d):
    cd = c * d
    return np.divide(bcd, cd, out=np.zeros(np.broadcast(bcd, cd).shape), where=cd != 0) if np.ndim(cd) or np.ndim(bcd) \
        else (bcd / cd if cd else 0.0)


def factors(t, fz, gamma=0.0):
    """B, C, D, E, SH, SV of ``Fx``, ``Fy`` and ``Mz`` (PAC89 units: kN, %, deg) at load ``fz`` [N].

    Returns a dict ``{"fx": {...}, "fy": {...}, "mz": {...}}`` (§13.2).
    """
    a = [t.coef[f"A{i}"] for i in range(14)]
    b = [t.coef[f"B{i}"] for i in range(11)]
    c = [t.coef[f"C{i}"] for i in range(18)]
    F = np.asarray(fz, dtype=float) / 1000.0
    g = np.asarray(gamma, dtype=float) * _DEG
    F2 = F * F
    out = {}
    d = b[1] * F2 + b[2] * F
    bcd = (b[3] * F2 + b[4] * F) * np.exp(-b[5] * F)
    out["fx"] = dict(C=b[0], D=d, B=_b(bcd, b[0], d), E=b[6] * F2 + b[7] * F + b[8], SH=b[9] * F + b[10], SV=0.0)
    d = a[1] * F2 + a[2] * F
    bcd = a[3] * np.sin(2.0 * np.arctan(F / a[4])) * (1.0 - a[5] * np.abs(g))
    out["fy"] = dict(C=a[0], D=d, B=_b(bcd, a[0], d), E=a[6] * F + a[7], SH=a[8] * g + a[9] * F + a[10],
                     SV=a[11] * F * g + a[12] * F + a[13])
    d = c[1] * F2 + c[2] * F
    bcd = (c[3] * F2 + c[4] * F) * (1.0 - c[6] * np.abs(g)) * np.exp(-c[5] * F)
    out["mz"] = dict(C=c[0], D=d, B=_b(bcd, c[0], d), E=(c[7] * F2 + c[8] * F + c[9]) * (1.0 - c[10] * np.abs(g)),
                     SH=c[11] * g + c[12] * F + c[13], SV=(c[14] * F2 + c[15] * F) * g + c[16] * F + c[17])
    return out


def evaluate_pac89(t, kappa, alpha, gamma, fz, need=("fx", "fy", "mz", "mx", "my")) -> dict:
    """``Fx``, ``Fy`` [N], ``Mz`` [N m] of the PAC89 form in ISO-W; ``Mx = My = 0`` (§13.2).

    Parameters: ``kappa`` [-], ``alpha``, ``gamma`` [rad], ``fz`` [N] (converted to %, deg, kN).
    """
    f = factors(t, fz, gamma)
    out = {}
    shape = np.broadcast(kappa, alpha, gamma, fz).shape
    if "fx" in need:
        p = f["fx"]
        out["fx"] = sin_curve(p["B"], p["C"], p["D"], p["E"], 100.0 * np.asarray(kappa) + p["SH"]) + p["SV"]
    a_deg = np.asarray(alpha) * _DEG
    if "fy" in need:
        p = f["fy"]
        out["fy"] = -(sin_curve(p["B"], p["C"], p["D"], p["E"], a_deg + p["SH"]) + p["SV"])
    if "mz" in need:
        p = f["mz"]
        out["mz"] = -(sin_curve(p["B"], p["C"], p["D"], p["E"], a_deg + p["SH"]) + p["SV"])
    for k in ("mx", "my"):
        if k in need:
            out[k] = np.zeros(shape)
    return out
