"""Combined-slip weighting of MF 6.1 / 5.2: ``Fx = G_xa Fx0`` and ``Fy = G_yk Fy0 + S_Vyk``, vectorized.

docs/models/magic_formula_tyre.md §6.1-§6.2 (book 4.E50-4.E67): the weighting functions ``G_xa``,
``G_yk`` and the kappa-induced side force ``S_Vyk``.
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula.curve import _clip_e, _cos_atan, _is_zero, _lin, _scale, cos_curve
from tirecli.models.magic_formula.tire import Convention, MFTire


def g_xa(t: MFTire, cv: Convention, b, kappa, g_star):
    """Weighting function ``G_xa`` [-] of ``Fx`` under side slip (§6.1, 4.E51-4.E57)."""
    c = t.coef
    bxa = _weighting_slope(t, c["RBX1"], c.get("RBX3", 0.0), g_star, c["RBX2"], kappa, c["LXAL"])
    return _weighting(bxa, c["RCX1"], _clip_e(_lin(c["REX1"], c["REX2"], b.dfz), cv), b.a_star, c["RHX1"])


def g_yk(t: MFTire, cv: Convention, b, kappa, g_star):
    """Weighting function ``G_yk`` [-] of ``Fy`` under longitudinal slip (§6.2, 4.E59-4.E65)."""
    c = t.coef
    byk = _weighting_slope(t, c["RBY1"], c.get("RBY4", 0.0), g_star, c["RBY2"], b.a_star - c["RBY3"], c["LYKA"])
    return _weighting(byk, c["RCY1"], _clip_e(_lin(c["REY1"], c["REY2"], b.dfz), cv), kappa,
                      _lin(c["RHY1"], c["RHY2"], b.dfz))


def _weighting_slope(t, r1, r_cam, g_star, r2, arg, scale):
    """``B = (r1 + r_cam g*^2) cos(arctan(r2 arg)) lambda`` of G_xa (4.E54) and G_yk (4.E62)."""
    B = r1
    if not t.is_52 and r_cam and not _is_zero(g_star):
        B = B + r_cam * np.square(g_star)
    if r2:
        B = B * _cos_atan(r2 * arg)
    return _scale(B, scale)


def _weighting(B, C, E, x, shift):
    """``cos(C atan(B x_s - E(...))) / cos(C atan(B S_H - E(...)))`` with ``x_s = x + S_H``: the
    combined-slip weighting functions G_xa (4.E51-4.E52) and G_yk (4.E59-4.E60), 1 at ``x = 0``."""
    if _is_zero(shift):
        return cos_curve(B, C, E, x)
    return cos_curve(B, C, E, x + shift) / cos_curve(B, C, E, shift)


def sv_yk(t: MFTire, b, kappa, fz, mu_y, g_star, zeta2=1.0, red=None):
    """The kappa-induced side force ``S_Vyk`` [N] (§6.2, 4.E66-4.E67)."""
    c = t.coef
    if not (c["RVY1"] or c["RVY2"] or c["RVY3"]) or not c["RVY5"] or not c["RVY6"]:
        return 0.0
    d = _lin(c["RVY1"], c["RVY2"], b.dfz)
    if c["RVY3"] and not _is_zero(g_star):
        d = d + c["RVY3"] * (_scale(g_star, c["LGAY"]) if t.is_52 else g_star)
    d = mu_y * fz * d
    if c["RVY4"]:
        d = d * _cos_atan(c["RVY4"] * b.a_star)
    if np.ndim(zeta2) or zeta2 != 1.0:
        d = d * zeta2
    s = d * (np.sin(c["RVY5"] * np.arctan(c["RVY6"] * kappa)) * c["LVYKA"])
    return s * red if red is not None else s
