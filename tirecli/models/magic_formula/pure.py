"""Pure-slip forces of MF 6.1 / 5.2: ``Fx0`` (book 4.E9-4.E18) and ``Fy0`` (4.E19-4.E30), vectorized.

docs/models/magic_formula_tyre.md §5.1, §5.2 (and §9 for MF 5.2): each force as its factors (B, C, D, E,
shifts, stiffness) and the curve through them; :func:`pure_slip_factors` gives the factors per load
(§13.4). Inputs as in :mod:`~tirecli.models.magic_formula.mf61`.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from tirecli.models.magic_formula import turnslip
from tirecli.models.magic_formula.curve import _clip_e, _guard, _is_zero, _lin, _scale, _sgn, sin_curve
from tirecli.models.magic_formula.state import _quad, basic
from tirecli.models.magic_formula.tire import Convention, MFTire


# --------------------------------------------------------------------------- Fx0


def fx0_factors(t: MFTire, cv: Convention, b, fz, gamma, zeta1=1.0, red=None):
    """Factors of the pure longitudinal force (§5.1, 4.E11-4.E18; §9 for MF 5.2).

    Returns ``C`` (4.E11), ``mu`` (4.E13), ``D`` [N] (4.E12), ``K`` = K_xk [N] (4.E15), ``B``
    (4.E16), ``SH`` [-] (4.E17), ``SV`` [N] (4.E18, low-speed factor ``red`` applied to both
    shifts) and ``E0``, the curvature before its drive/brake asymmetry ``1 - PEX4 sgn(kappa_x)``.
    """
    c = t.coef
    dfz, dpi = b.dfz, b.dpi
    f = SimpleNamespace()
    f.C = c["PCX1"] * c["LCX"]
    mu = _lin(c["PDX1"], c["PDX2"], dfz)
    if c["PDX3"] and b.has_camber:
        gx = _scale(gamma, c["LGAX"]) if t.is_52 else gamma
        mu = mu * (1.0 - c["PDX3"] * np.square(gx))
    if b.has_dpi and not t.is_52:
        mu = mu * (1.0 + c["PPX3"] * dpi + c["PPX4"] * np.square(dpi))
    f.mu = _scale(mu, b.lmux_s) if np.ndim(b.lmux_s) == 0 else mu * b.lmux_s
    f.D = _scale(f.mu * fz, zeta1) if np.ndim(zeta1) == 0 else f.mu * fz * zeta1
    K = fz * _lin(c["PKX1"], c["PKX2"], dfz)
    if c["PKX3"]:
        K = K * np.exp(c["PKX3"] * dfz)
    if b.has_dpi and not t.is_52:
        K = K * (1.0 + c["PPX1"] * dpi + c["PPX2"] * np.square(dpi))
    f.K = _scale(K, c["LKX"])
    f.B = f.K / _guard(f.C * f.D, cv.eps)
    f.SH = _scale(_lin(c["PHX1"], c["PHX2"], dfz), c["LHX"])
    if c["PVX1"] or c["PVX2"]:
        sv = fz * _lin(c["PVX1"], c["PVX2"], dfz) * (c["LVX"] * b.lmux_p)
        f.SV = sv * zeta1 if np.ndim(zeta1) else _scale(sv, zeta1)
    else:
        f.SV = 0.0
    if red is not None:
        f.SH = f.SH * red
        f.SV = f.SV * red
    f.E0 = _scale(_quad(c["PEX1"], c["PEX2"], c["PEX3"], b), c["LEX"])
    return f


def fx0_curve(t: MFTire, cv: Convention, f, kappa):
    """``Fx0`` [N] from its factors (4.E9-4.E10, 4.E14): ``D sin(C atan(B kx - E(...))) + SV``."""
    kx = kappa + f.SH
    pex4 = t.coef["PEX4"]
    if pex4:
        asym = np.copysign(pex4, kx + 0.0) if cv.sgn_zero == 1.0 else pex4 * np.sign(kx)
        E = f.E0 * (1.0 - asym)
    else:
        E = f.E0
    y = sin_curve(f.B, f.C, f.D, _clip_e(E, cv), kx)
    return y if _is_zero(f.SV) else y + f.SV


# --------------------------------------------------------------------------- Fy0


def fy0_load(t: MFTire, cv: Convention, b, fz):
    """The camber-independent parts of the Fy0 factors (shared by the actual-camber and the
    zero-camber evaluations of §5.3): ``C``, ``mu0``, ``sh0``, ``sv0``, ``E0``, ``kz = Fz/F'z0``,
    the cornering-stiffness scale and the peak-load denominator factor."""
    c = t.coef
    dfz, dpi = b.dfz, b.dpi
    L = SimpleNamespace()
    L.C = c["PCY1"] * c["LCY"]
    mu = _lin(c["PDY1"], c["PDY2"], dfz)
    if b.has_dpi and not t.is_52:
        mu = mu * (1.0 + c["PPY3"] * dpi + c["PPY4"] * np.square(dpi))
    L.mu0 = _scale(mu, b.lmuy_s) if np.ndim(b.lmuy_s) == 0 else mu * b.lmuy_s
    L.sh0 = _scale(_lin(c["PHY1"], c["PHY2"], dfz), c["LHY"])
    if c["PVY1"] or c["PVY2"]:
        L.sv0 = fz * _lin(c["PVY1"], c["PVY2"], dfz) * (c["LVY"] * b.lmuy_p)
    else:
        L.sv0 = 0.0
    L.E0 = _scale(_lin(c["PEY1"], c["PEY2"], dfz), c["LEY"])
    L.kz = fz * (1.0 / b.fz0p)
    kscale = c["PKY1"] * b.fz0p * c["LKY"]
    L.kscale = kscale * (1.0 + c["PPY1"] * dpi) if (b.has_dpi and not t.is_52) else kscale
    L.kden = (1.0 + c["PPY2"] * dpi) if (b.has_dpi and not t.is_52) else 1.0
    L.ksin0 = None
    return L


def _ksin0(t, L):
    """``sin(PKY4 arctan(Fz/F'z0 / (PKY2 (1 + PPY2 dpi))))`` (4.E25 at zero camber), computed once."""
    if L.ksin0 is None:
        c = t.coef
        L.ksin0 = np.sin(c["PKY4"] * np.arctan(L.kz / (c["PKY2"] * L.kden)))
    return L.ksin0


def fy0_factors(t: MFTire, cv: Convention, b, fz, g_star, ts=None, red=None, L=None):
    """Factors of the pure lateral force (§5.2, 4.E20-4.E30; §9 for MF 5.2) at camber ``g_star``.

    Returns ``C`` (4.E21), ``mu`` (4.E23), ``D`` [N] (4.E22), ``K`` = K_ya [N/rad] (4.E25),
    ``Kp`` = K'_ya (4.E39), ``B`` (4.E26), ``SH`` [rad] (4.E27), ``SV`` [N] (4.E29), ``SVg`` [N]
    (4.E28), ``Kg0`` = K_yg0 [N/rad] (4.E30), and the curvature parts ``E0`` (load part) and
    ``Ec`` (camber part ``1 + PEY5 g*^2``) with the asymmetry ``Ea = PEY3 + PEY4 g*``. ``ts`` holds
    the turn-slip zeta factors (§8), None without turn slip; ``L`` the shared load part
    (:func:`fy0_load`).
    """
    c = t.coef
    if L is None:
        L = fy0_load(t, cv, b, fz)
    dfz, eps = b.dfz, cv.eps
    f = SimpleNamespace(C=L.C, E0=L.E0)
    z0, z2, z3 = (1.0, 1.0, 1.0) if ts is None else (0.0, ts.zeta2, ts.zeta3)
    flat = _is_zero(g_star)
    if t.is_52:
        g = 0.0 if flat else _scale(g_star, c["LGAY"])
        if flat or not c["PKY3"]:
            f.K = L.kscale * _ksin0(t, L)
        else:
            f.K = L.kscale * _ksin0(t, L) * (1.0 - c["PKY3"] * np.abs(g))
        f.Kg0 = None
        f.SVg = 0.0 if flat or not (c["PVY3"] or c["PVY4"]) else fz * _lin(c["PVY3"], c["PVY4"], dfz) * g * b.lmuy_p
        f.SH = L.sh0 if flat or not c["PHY3"] else L.sh0 + c["PHY3"] * g
        f.SV = L.sv0 if _is_zero(f.SVg) else L.sv0 + f.SVg
        f.mu = L.mu0 if flat or not c["PDY3"] else L.mu0 * (1.0 - c["PDY3"] * np.square(g))
        f.Ec = 1.0
    else:
        g = g_star
        if flat:
            kya = L.kscale * _ksin0(t, L)
        else:
            g2 = np.square(g)
            if c["PKY5"]:
                kya = L.kscale * np.sin(c["PKY4"] * np.arctan(L.kz / ((c["PKY2"] + c["PKY5"] * g2) * L.kden)))
            else:
                kya = L.kscale * _ksin0(t, L)
            if c["PKY3"]:
                kya = kya * (1.0 - c["PKY3"] * np.abs(g))
        f.K = _scale(kya, z3) if np.ndim(z3) == 0 else kya * z3
        kg0 = None
        if not flat or ts is not None:  # camber stiffness K_yg0 (4.E30)
            kg0 = fz * _lin(c["PKY6"], c["PKY7"], dfz) * c["LKYC"]
            if b.has_dpi:
                kg0 = kg0 * (1.0 + c["PPY5"] * b.dpi)
        f.Kg0 = kg0
        if flat or not (c["PVY3"] or c["PVY4"]):
            f.SVg = 0.0
        else:
            f.SVg = fz * _lin(c["PVY3"], c["PVY4"], dfz) * g * (c["LKYC"] * b.lmuy_p)
            if ts is not None:
                f.SVg = f.SVg * z2
        f.Kp = _guard(f.K, eps)
        if ts is not None:
            f.SH = L.sh0 + (turnslip.zeta4(t, cv, b, fz, f, ts) - 1.0)
        elif flat:
            f.SH = L.sh0
        else:
            f.SH = L.sh0 + (kg0 * g - f.SVg) / f.Kp
        sv0 = L.sv0 if ts is None else L.sv0 * z2
        f.SV = sv0 if _is_zero(f.SVg) else sv0 + f.SVg
        f.mu = L.mu0 if flat or not c["PDY3"] else L.mu0 * (1.0 - c["PDY3"] * g2)
        f.Ec = 1.0 if flat or not c["PEY5"] else 1.0 + c["PEY5"] * g2
    if not hasattr(f, "Kp"):
        f.Kp = _guard(f.K, eps)
    if red is not None:
        f.SH = f.SH * red
        f.SV = f.SV * red
    f.D = f.mu * fz if ts is None else f.mu * fz * z2
    f.B = f.K / _guard(f.C * f.D, eps)
    f.Ea = c["PEY3"] if (flat or not c["PEY4"]) else c["PEY3"] + c["PEY4"] * (
        _scale(g_star, c["LGAY"]) if t.is_52 else g_star)
    return f


def fy0_curve(t: MFTire, cv: Convention, b, f, alpha_raw):
    """``Fy0`` [N] from its factors (4.E19-4.E20, 4.E24) at ``alpha* = b.a_fy``."""
    ay = b.a_fy + f.SH
    if _is_zero(f.Ea):
        E = f.E0 if _is_zero(f.Ec - 1.0) else f.E0 * f.Ec
    else:
        s = _sgn(alpha_raw if cv.ey_sign_of_alpha else ay, cv.sgn_zero)
        E = f.E0 * (f.Ec - f.Ea * s)
    y = sin_curve(f.B, f.C, f.D, _clip_e(E, cv), ay)
    return y if _is_zero(f.SV) else y + f.SV


def pure_slip_factors(t: MFTire, fz, gamma=0.0, p=None, convention="mfeval") -> dict:
    """Per-load B, C, D, E, S_H, S_V of the pure-slip forces (§13.4), with K and mu.

    At a fixed load (and camber, pressure), with no turn slip, ``Fx0(kappa)`` and ``Fy0(alpha)``
    are exactly the basic curve of §13.1 with these factors. ``E+``/``E-`` are the curvatures for
    a positive / negative shifted slip (they differ when ``PEX4`` or ``PEY3`` is non-zero).

    Parameters
    ----------
    t : MFTire
        An MF 6.x or 5.2 tyre.
    fz : array_like
        Vertical load [N].
    gamma : array_like
        Inclination [rad].
    p : array_like or None
        Pressure [Pa] (default ``INFLPRES``).

    Returns
    -------
    dict
        ``{"fx": {...}, "fy": {...}}`` with keys ``B`` [1/-] or [1/rad], ``C`` [-], ``D`` [N],
        ``E+``, ``E-`` [-], ``SH`` [-] or [rad], ``SV`` [N], ``K`` [N] or [N/rad], ``mu`` [-].
    """
    from tirecli.models.magic_formula.tire import get_convention

    cv = get_convention(convention)
    if p is None and t.nominal_pressure:
        p = t.default_pressure
    fz = np.asarray(fz, dtype=float)
    gamma = np.asarray(gamma, dtype=float)
    b = basic(t, cv, 0.0, 0.0, gamma, fz, 1.0, p)
    fx = fx0_factors(t, cv, b, fz, gamma)
    fy = fy0_factors(t, cv, b, fz, b.g_star)
    pex4 = t.coef["PEX4"]
    out = {
        "fx": {"B": fx.B, "C": fx.C, "D": fx.D, "E+": _clip_e(fx.E0 * (1.0 - pex4), cv),
               "E-": _clip_e(fx.E0 * (1.0 + pex4), cv), "SH": fx.SH, "SV": fx.SV, "K": fx.K, "mu": fx.mu},
        "fy": {"B": fy.B, "C": fy.C, "D": fy.D, "E+": _clip_e(fy.E0 * (fy.Ec - fy.Ea), cv),
               "E-": _clip_e(fy.E0 * (fy.Ec + fy.Ea), cv), "SH": fy.SH, "SV": fy.SV, "K": fy.K, "mu": fy.mu},
    }
    return out
