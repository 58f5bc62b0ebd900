"""MF 6.1 (and MF 5.2 / PAC2002) steady-state forces and moments, vectorized (pure numpy).

Implements magic_formula.md §3-§7 and §9 (book Pacejka 2012 eqs. 4.E1-4.E78; Besselink et al.
2010 eqs. A48-A60), with the variants of §10 chosen by a
:class:`~tirecli.models.magic_formula.tire.Convention`:

- pure slip ``Fx0`` (4.E9-4.E18), ``Fy0`` (4.E19-4.E30), ``Mz0`` (4.E31-4.E49);
- combined slip ``Fx = G_xa Fx0`` (4.E50-4.E57), ``Fy = G_yk Fy0 + S_Vyk`` (4.E58-4.E67),
  ``Mz = -t F'y + M_zr + s Fx`` (4.E71-4.E78, A54-A56);
- ``Mx`` (§7.1), ``My`` (§7.2);
- MF 5.2 / PAC2002 substitutions (§9): no pressure terms, camber scaled per channel by
  ``LGAX``/``LGAY``/``LGAZ``, ``K_ya`` with ``PKY4``, camber side force through ``PHY3`` and
  ``PVY3``/``PVY4``, ``M'z = -t (Fy - S_Vyk)``.

Inputs (already limited, see :mod:`~tirecli.models.magic_formula.inputs`) are 1-D arrays of
one length or scalars: ``kappa`` [-], ``alpha`` [rad], ``gamma`` [rad], ``fz`` [N], ``vx``
[m/s], ``p`` [Pa]. Everything is ISO-W (:mod:`~tirecli.models.magic_formula.axes`).
Subexpressions shared between outputs are computed once, and large temporaries are updated in
place; this module holds the equations only (no broadcasting, chunking or I/O).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from tirecli.models.magic_formula import turnslip
from tirecli.models.magic_formula.tire import Convention, MFTire

_2_PI = 2.0 / math.pi


# --------------------------------------------------------------------------- helpers


def _sgn(x, zero: float):
    """sgn(x) with sgn(0) = ``zero`` (+1: mfeval's ``x >= 0 ? 1 : -1``; 0: MATLAB ``sign``)."""
    if zero == 1.0:
        return np.copysign(1.0, x + 0.0)  # + 0.0 turns -0.0 into +0.0
    return np.sign(x)


def _inplace_ok(base, *others) -> bool:
    return np.ndim(base) > 0 and all(np.size(o) <= np.size(base) for o in others)


def _curve_angle(B, E, x):
    """``arctan(Bx - E(Bx - arctan(Bx)))`` [rad]: the inner angle of the Magic Formula (§5)."""
    bx = np.multiply(B, x)
    if not _inplace_ok(bx, E):
        return np.arctan(bx - E * (bx - np.arctan(bx)))
    a = np.arctan(bx)
    np.subtract(bx, a, out=a)
    np.multiply(a, E, out=a)
    np.subtract(bx, a, out=a)
    return np.arctan(a, out=a)


def sin_curve(B, C, D, E, x):
    """The Magic Formula ``y = D sin(C arctan(Bx - E(Bx - arctan Bx)))`` (§5, §13.1)."""
    a = _curve_angle(B, E, x)
    if not _inplace_ok(a, C, D):
        return D * np.sin(C * a)
    np.multiply(a, C, out=a)
    np.sin(a, out=a)
    return np.multiply(a, D, out=a)


def cos_curve(B, C, E, x):
    """The cosine version ``cos(C arctan(Bx - E(Bx - arctan Bx)))`` (weighting functions, trail)."""
    a = _curve_angle(B, E, x)
    if not _inplace_ok(a, C):
        return np.cos(C * a)
    np.multiply(a, C, out=a)
    return np.cos(a, out=a)


def _cos_atan(x):
    """``cos(arctan(x)) = 1/sqrt(1 + x^2)`` (exact identity, cheaper than two trig calls)."""
    return 1.0 / np.sqrt(1.0 + np.square(x))


def _clip_e(E, cv: Convention):
    return np.minimum(E, 1.0) if cv.e_clip else E


# --------------------------------------------------------------------------- shared state


def basic(t: MFTire, cv: Convention, kappa, alpha, gamma, fz, vx, p):
    """Normalised quantities shared by every output (§3): ``dfz``, ``dpi``, alpha*, gamma*, lambdas.

    Returns a namespace with ``dfz`` (4.E2a), ``dpi`` (4.E2b), ``a_fy`` (alpha used in Fy0),
    ``a_star`` (alpha* used in combined slip and Mz), ``g_star`` (gamma*), ``lmux_s``/``lmuy_s``
    (lambda*, 4.E7) and ``lmux_p``/``lmuy_p`` (lambda', 4.E8), ``sgn_vx``.
    """
    c = t.coef
    fz0p = c["FNOMIN"] * c["LFZO"]
    b = SimpleNamespace()
    b.fz0p = fz0p
    b.dfz = fz * (1.0 / fz0p) - 1.0
    pi0 = t.nominal_pressure
    b.dpi = 0.0 if (pi0 is None or p is None) else (p - pi0) * (1.0 / pi0)
    backward = bool(np.any(vx < 0))
    b.backward = backward
    b.sgn_vx = _sgn(vx, 1.0) if backward else 1.0
    tan_a = None
    if cv.alpha_star in ("tan", "mixed"):
        tan_a = np.tan(alpha)
        a_tan = tan_a * b.sgn_vx if backward else tan_a
    b.a_fy = a_tan if cv.alpha_star == "tan" else alpha
    b.a_star = alpha if cv.alpha_star == "alpha" else a_tan
    b.g_star = np.sin(gamma) if cv.gamma_sin else gamma
    b.gamma = gamma
    b.has_camber = bool(np.any(gamma != 0))
    lmux, lmuy = c["LMUX"], c["LMUY"]
    if c.get("LMUV", 0.0):
        v0 = t.reference_speed
        ta = np.tan(alpha) if tan_a is None else tan_a
        vs = np.abs(vx) * np.sqrt(np.square(kappa) + np.square(ta))  # |V_s| = |Vx| sqrt(kappa^2 + tan^2)
        den = 1.0 + c["LMUV"] * vs / v0
        b.lmux_s, b.lmuy_s = lmux / den, lmuy / den
    else:
        b.lmux_s, b.lmuy_s = lmux, lmuy
    am = cv.a_mu
    if am == 1.0:
        b.lmux_p, b.lmuy_p = b.lmux_s, b.lmuy_s
    else:
        b.lmux_p = am * b.lmux_s / (1.0 + (am - 1.0) * b.lmux_s)
        b.lmuy_p = am * b.lmuy_s / (1.0 + (am - 1.0) * b.lmuy_s)
    return b


# --------------------------------------------------------------------------- Fx0


def fx0_factors(t: MFTire, cv: Convention, b, fz, gamma, zeta1=1.0, red=None):
    """Factors of the pure longitudinal force (§5.1, 4.E11-4.E18; §9 for MF 5.2).

    Returns ``C`` (4.E11), ``mu`` (4.E13), ``D`` [N] (4.E12), ``K`` = K_xk [N] (4.E15), ``B``
    (4.E16), ``SH`` [-] (4.E17), ``SV`` [N] (4.E18, low-speed factor ``red`` applied to both
    shifts) and ``E0``, the curvature before its drive/brake asymmetry ``1 - PEX4 sgn(kappa_x)``.
    """
    c = t.coef
    dfz, dpi = b.dfz, b.dpi
    gx = gamma * c["LGAX"] if t.is_52 else gamma
    f = SimpleNamespace()
    f.C = c["PCX1"] * c["LCX"]
    mu = (c["PDX1"] + c["PDX2"] * dfz) * (1.0 - c["PDX3"] * np.square(gx)) * b.lmux_s
    if not t.is_52 and np.any(dpi):
        mu = mu * (1.0 + c["PPX3"] * dpi + c["PPX4"] * np.square(dpi))
    f.mu = mu
    f.D = mu * fz * zeta1
    K = fz * (c["PKX1"] + c["PKX2"] * dfz) * np.exp(c["PKX3"] * dfz) * c["LKX"]
    if not t.is_52 and np.any(dpi):
        K = K * (1.0 + c["PPX1"] * dpi + c["PPX2"] * np.square(dpi))
    f.K = K
    f.B = K / (f.C * f.D + cv.eps * _sgn(f.D, 1.0))
    f.SH = (c["PHX1"] + c["PHX2"] * dfz) * c["LHX"]
    f.SV = fz * (c["PVX1"] + c["PVX2"] * dfz) * c["LVX"] * b.lmux_p * zeta1
    if red is not None:
        f.SH = f.SH * red
        f.SV = f.SV * red
    f.E0 = (c["PEX1"] + c["PEX2"] * dfz + c["PEX3"] * np.square(dfz)) * c["LEX"]
    return f


def fx0_curve(t: MFTire, cv: Convention, f, kappa):
    """``Fx0`` [N] from its factors (4.E9-4.E10, 4.E14): ``D sin(C atan(B kx - E(...))) + SV``."""
    kx = kappa + f.SH
    pex4 = t.coef["PEX4"]
    E = f.E0 * (1.0 - pex4 * _sgn(kx, cv.sgn_zero)) if pex4 else f.E0
    E = _clip_e(E, cv)
    y = sin_curve(f.B, f.C, f.D, E, kx)
    return y + f.SV


# --------------------------------------------------------------------------- Fy0


def fy0_factors(t: MFTire, cv: Convention, b, fz, g_star, ts=None, red=None):
    """Factors of the pure lateral force (§5.2, 4.E20-4.E30; §9 for MF 5.2) at camber ``g_star``.

    Returns ``C`` (4.E21), ``mu`` (4.E23), ``D`` [N] (4.E22), ``K`` = K_ya [N/rad] (4.E25),
    ``Kp`` = K'_ya (4.E39), ``B`` (4.E26), ``SH`` [rad] (4.E27), ``SV`` [N] (4.E29), ``SVg`` [N]
    (4.E28), ``Kg0`` = K_yg0 [N/rad] (4.E30), and the curvature parts ``E0`` (load part) and
    ``Ec`` (camber part ``1 + PEY5 g*^2``) with the asymmetry ``Ea = PEY3 + PEY4 g*``. ``ts`` holds
    the turn-slip zeta factors (§8), None without turn slip.
    """
    c = t.coef
    dfz, dpi, fz0p, eps = b.dfz, b.dpi, b.fz0p, cv.eps
    f = SimpleNamespace()
    z0, z2, z3 = (1.0, 1.0, 1.0) if ts is None else (0.0, ts.zeta2, ts.zeta3)
    f.C = c["PCY1"] * c["LCY"]
    if t.is_52:
        g = g_star * c["LGAY"]
        g2 = np.square(g)
        f.K = (c["PKY1"] * fz0p * np.sin(c["PKY4"] * np.arctan(fz / (c["PKY2"] * fz0p)))
               * (1.0 - c["PKY3"] * np.abs(g)) * c["LKY"])
        f.Kp = f.K + eps * _sgn(f.K, 1.0)
        f.Kg0 = None
        f.SVg = fz * (c["PVY3"] + c["PVY4"] * dfz) * g * b.lmuy_p
        f.SH = (c["PHY1"] + c["PHY2"] * dfz) * c["LHY"] + c["PHY3"] * g
        f.SV = fz * (c["PVY1"] + c["PVY2"] * dfz) * c["LVY"] * b.lmuy_p + f.SVg
        f.mu = (c["PDY1"] + c["PDY2"] * dfz) * (1.0 - c["PDY3"] * g2) * b.lmuy_s
        f.Ec = 1.0
    else:
        g = g_star
        g2 = np.square(g)
        pp = np.any(dpi)
        den = c["PKY2"] + c["PKY5"] * g2
        if pp:
            den = den * (1.0 + c["PPY2"] * dpi)
        kya = c["PKY1"] * fz0p * np.sin(c["PKY4"] * np.arctan(fz * (1.0 / fz0p) / den)) * c["LKY"]
        if pp:
            kya = kya * (1.0 + c["PPY1"] * dpi)
        if c["PKY3"]:
            kya = kya * (1.0 - c["PKY3"] * np.abs(g))
        f.K = kya * z3
        f.Kp = f.K + eps * _sgn(f.K, 1.0)
        kg0 = fz * (c["PKY6"] + c["PKY7"] * dfz) * c["LKYC"]
        if pp:
            kg0 = kg0 * (1.0 + c["PPY5"] * dpi)
        f.Kg0 = kg0
        f.SVg = fz * (c["PVY3"] + c["PVY4"] * dfz) * g * c["LKYC"] * b.lmuy_p * z2
        sh = (c["PHY1"] + c["PHY2"] * dfz) * c["LHY"]
        if ts is None:
            sh = sh + (kg0 * g - f.SVg) / f.Kp
        else:
            sh = sh + turnslip.zeta4(t, cv, b, fz, f, ts) - 1.0
        f.SH = sh
        f.SV = fz * (c["PVY1"] + c["PVY2"] * dfz) * c["LVY"] * b.lmuy_p * z2 + f.SVg
        mu = (c["PDY1"] + c["PDY2"] * dfz) * (1.0 - c["PDY3"] * g2) * b.lmuy_s
        if pp:
            mu = mu * (1.0 + c["PPY3"] * dpi + c["PPY4"] * np.square(dpi))
        f.mu = mu
        f.Ec = 1.0 + c["PEY5"] * g2
    if red is not None:
        f.SH = f.SH * red
        f.SV = f.SV * red
    f.D = f.mu * fz * z2
    f.B = f.K / (f.C * f.D + eps * _sgn(f.D, 1.0))
    f.E0 = (c["PEY1"] + c["PEY2"] * dfz) * c["LEY"]
    f.Ea = c["PEY3"] + c["PEY4"] * g
    return f


def fy0_curve(t: MFTire, cv: Convention, b, f, alpha_raw):
    """``Fy0`` [N] from its factors (4.E19-4.E20, 4.E24) at ``alpha* = b.a_fy``."""
    ay = b.a_fy + f.SH
    s = _sgn(alpha_raw if cv.ey_sign_of_alpha else ay, cv.sgn_zero)
    E = _clip_e(f.E0 * (f.Ec - f.Ea * s), cv)
    return sin_curve(f.B, f.C, f.D, E, ay) + f.SV


# --------------------------------------------------------------------------- combined slip


def g_xa(t: MFTire, cv: Convention, b, kappa, g_star):
    """Weighting function ``G_xa`` [-] of ``Fx`` under side slip (§6.1, 4.E51-4.E57)."""
    c = t.coef
    bxa = c["RBX1"]
    if not t.is_52 and c["RBX3"]:
        bxa = bxa + c["RBX3"] * np.square(g_star)
    bxa = bxa * _cos_atan(c["RBX2"] * kappa) * c["LXAL"] if c["RBX2"] else bxa * c["LXAL"]
    cxa = c["RCX1"]
    exa = _clip_e(c["REX1"] + c["REX2"] * b.dfz, cv)
    shxa = c["RHX1"]
    num = cos_curve(bxa, cxa, exa, b.a_star + shxa)
    return num / cos_curve(bxa, cxa, exa, shxa)


def g_yk(t: MFTire, cv: Convention, b, kappa, g_star):
    """Weighting function ``G_yk`` [-] of ``Fy`` under longitudinal slip (§6.2, 4.E59-4.E65)."""
    c = t.coef
    byk = c["RBY1"]
    if not t.is_52 and c["RBY4"]:
        byk = byk + c["RBY4"] * np.square(g_star)
    byk = byk * _cos_atan(c["RBY2"] * (b.a_star - c["RBY3"])) * c["LYKA"]
    cyk = c["RCY1"]
    eyk = _clip_e(c["REY1"] + c["REY2"] * b.dfz, cv)
    shyk = c["RHY1"] + c["RHY2"] * b.dfz
    num = cos_curve(byk, cyk, eyk, kappa + shyk)
    return num / cos_curve(byk, cyk, eyk, shyk)


def sv_yk(t: MFTire, b, kappa, fz, mu_y, g_star, zeta2=1.0, red=None):
    """The kappa-induced side force ``S_Vyk`` [N] (§6.2, 4.E66-4.E67)."""
    c = t.coef
    if not (c["RVY1"] or c["RVY2"] or c["RVY3"]):
        return 0.0
    g = g_star * c["LGAY"] if t.is_52 else g_star
    d = mu_y * fz * (c["RVY1"] + c["RVY2"] * b.dfz + c["RVY3"] * g) * _cos_atan(c["RVY4"] * b.a_star) * zeta2
    s = d * np.sin(c["RVY5"] * np.arctan(c["RVY6"] * kappa)) * c["LVYKA"]
    return s * red if red is not None else s


# --------------------------------------------------------------------------- Mz


def mz_factors(t: MFTire, cv: Convention, b, fz_mz, fy_f, fy_f0, ts=None):
    """Trail and residual-torque factors of ``Mz`` (§5.3, 4.E33-4.E47; A58, A60).

    ``fy_f`` are the Fy0 factors at the actual camber, ``fy_f0`` at zero camber (the source of
    S_Hf, B_r under ``mzr_zero_camber``). Returns ``alpha_t``, ``alpha_r`` [rad], ``Bt``, ``Ct``,
    ``Dt`` [m] (trail peak, without cos(alpha')), ``Et``, ``Br``, ``Cr``, ``Dr`` [N m], ``Kp``.
    """
    c = t.coef
    dfz, dpi, fz0p = b.dfz, b.dpi, b.fz0p
    g = b.g_star
    m = SimpleNamespace()
    gz = g * c["LGAZ"] if t.is_52 else g
    gt = gz if (t.is_52 or cv.camber_trail_book) else b.gamma  # camber in Bt, Dt
    src = fy_f0 if (cv.mzr_zero_camber and fy_f0 is not None) else fy_f
    m.Kp = src.Kp
    shf = src.SH + src.SV / src.Kp
    m.alpha_r = b.a_star + shf
    m.alpha_t = b.a_star + (c["QHZ1"] + c["QHZ2"] * dfz + (c["QHZ3"] + c["QHZ4"] * dfz) * gz)
    m.Bt = ((c["QBZ1"] + c["QBZ2"] * dfz + c["QBZ3"] * np.square(dfz))
            * (1.0 + c["QBZ4"] * gt + c["QBZ5"] * np.abs(gt)) * c["LKY"] / b.lmuy_s)
    m.Ct = c["QCZ1"]
    dt = fz_mz * (t.coef["UNLOADED_RADIUS"] / fz0p) * (c["QDZ1"] + c["QDZ2"] * dfz) * c["LTR"]
    if not t.is_52 and np.any(dpi):
        dt = dt * (1.0 - c["PPZ1"] * dpi)
    q3 = np.abs(gt) if (cv.camber_trail_book and not t.is_52) else gt
    dt = dt * (1.0 + c["QDZ3"] * q3 + c["QDZ4"] * np.square(gt))
    if ts is not None:
        dt = dt * ts.zeta5
    m.Dt = dt * b.sgn_vx if b.backward else dt
    et = (c["QEZ1"] + c["QEZ2"] * dfz + c["QEZ3"] * np.square(dfz))
    if c["QEZ4"] or c["QEZ5"]:
        et = et * (1.0 + (c["QEZ4"] + c["QEZ5"] * gz) * _2_PI * np.arctan(m.Bt * m.Ct * m.alpha_t))
    m.Et = _clip_e(et, cv)
    m.Br = c["QBZ9"] * c["LKY"] / b.lmuy_s + c["QBZ10"] * src.B * src.C
    m.Cr = 1.0
    r0 = t.coef["UNLOADED_RADIUS"]
    z0, z2 = (1.0, 1.0) if ts is None else (0.0, ts.zeta2)
    if ts is not None:
        m.Br = m.Br * ts.zeta6
    if t.is_52:
        inner = (c["QDZ6"] + c["QDZ7"] * dfz) * c["LRES"] + (c["QDZ8"] + c["QDZ9"] * dfz) * gz
    else:
        cam = c["QDZ8"] + c["QDZ9"] * dfz
        if np.any(dpi):
            cam = cam * (1.0 + c["PPZ2"] * dpi)
        if c["QDZ10"] or c["QDZ11"]:
            cam = cam + (c["QDZ10"] + c["QDZ11"] * dfz) * np.abs(g)
        inner = (c["QDZ6"] + c["QDZ7"] * dfz) * c["LRES"] * z2 + cam * g * c["LKZC"] * z0
    dr = fz_mz * r0 * inner * b.lmuy_s * b.cos_a
    if b.backward:
        dr = dr * b.sgn_vx
    m.Dr = dr
    return m


def _tan_or(x, paper: bool):
    return np.tan(x) if paper else x


def equivalent_slip(angle, ratio2, cv: Convention):
    """Equivalent slip angle of combined-slip ``Mz`` [rad] (A54/A55 paper form or book 4.E77/4.E78).

    ``ratio2 = (K_xk/K'_ya)^2 kappa^2``; paper: ``arctan(sqrt(tan^2(angle) + ratio2)) sgn(angle)``,
    book: ``sqrt(angle^2 + ratio2) sgn(angle)``.
    """
    if cv.eq_slip_paper:
        r = np.arctan(np.sqrt(np.square(np.tan(angle)) + ratio2))
    else:
        r = np.sqrt(np.square(angle) + ratio2)
    return r * _sgn(angle, cv.sgn_zero)


# --------------------------------------------------------------------------- Mx, My


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


# --------------------------------------------------------------------------- all outputs


def evaluate_kernel(t: MFTire, cv: Convention, kappa, alpha, gamma, fz, vx, p, need=("fx", "fy", "mz", "mx", "my"),
                    red=None, fz_mz=None, fz_scale_mx=None, fz_scale_my=None, my_window=None, phit=None,
                    kappa_my=None):
    """Every requested output of one block of points (MF 6.1 / 5.2, combined slip).

    Parameters
    ----------
    kappa, alpha, gamma, fz, vx, p : ndarray or float
        Limited inputs (1-D arrays of one length, or scalars): slip [-], slip angle [rad],
        inclination [rad], load [N], speed [m/s], pressure [Pa] (None: nominal).
    need : iterable of str
        Outputs to compute among ``fx, fy, mz, mx, my`` (dependencies are added).
    red : ndarray or None
        Low-speed smooth factor of the shifts, trail and residual torque (§11), None above VXLOW.
    fz_mz : ndarray or None
        Load used in the trail and residual torque (raised to FZMIN by the limits, §11).
    fz_scale_mx, fz_scale_my : ndarray or None
        Low-load factors of Mx and My below FZMIN (§11).
    my_window : ndarray or None
        Factor of My near standstill (mfeval's sine ramp in kappa, §11).
    phit : ndarray or None
        Turn slip phi_t [1/m] (§8); None: no turn slip (all zeta = 1).
    kappa_my : ndarray or None
        Unreduced slip for the standstill window of My (unused here, kept for symmetry).

    Returns
    -------
    dict
        ``fx``, ``fy`` [N], ``mz``, ``mx``, ``my`` [N m] for the requested outputs.
    """
    need = set(need)
    if "mz" in need:
        need |= {"fx", "fy"}
    if "mx" in need:
        need.add("fy")
    if "my" in need and t.coef.get("QSY2"):
        need.add("fx")
    c = t.coef
    b = basic(t, cv, kappa, alpha, gamma, fz, vx, p)
    ts = None
    if phit is not None:
        ts = turnslip.spin(t, cv, b, kappa, alpha, gamma, fz, vx, phit)
    out = {}
    if "mz" in need:
        ca = np.cos(alpha)
        b.cos_a = ca
        eps_v = cv.eps
        # cos(alpha') = Vcx / (Vc + eps), Vc = |Vcx| sqrt(1 + tan^2 alpha) (4.E6, 4.E6a)
        aca = np.abs(ca)
        b.cos_ap = aca * (vx / (np.abs(vx) + eps_v * aca))
    fx = None
    if "fx" in need:
        fxf = fx0_factors(t, cv, b, fz, gamma, 1.0 if ts is None else ts.zeta1, red)
        fx0 = fx0_curve(t, cv, fxf, kappa)
        if b.backward:
            fx0 = fx0 * b.sgn_vx
        fx = fx0 * g_xa(t, cv, b, kappa, b.g_star)
        out["fx"] = fx
    if "fy" in need:
        fyf = fy0_factors(t, cv, b, fz, b.g_star, ts, red)
        fy0 = fy0_curve(t, cv, b, fyf, alpha)
        if b.backward and cv.alpha_star == "tan":
            fy0 = fy0 * b.sgn_vx
        gyk = g_yk(t, cv, b, kappa, b.g_star)
        svyk = sv_yk(t, b, kappa, fz, fyf.mu, b.g_star, 1.0 if ts is None else ts.zeta2, red)
        fy = gyk * fy0 + svyk
        out["fy"] = fy
    if "mz" in need:
        out["mz"] = _mz(t, cv, b, kappa, alpha, fz, fz_mz, fxf, fyf, fy0, gyk, svyk, fx, fy, red, ts)
    if "mx" in need:
        out["mx"] = overturning(t, cv, b, fz, gamma, out["fy"], fz_scale_mx)
    if "my" in need:
        my = rolling(t, cv, b, fz, gamma, vx, p, fx, fz_scale_my)
        if cv.backward_my and (b.backward or np.any(vx == 0)):
            my = my * np.sign(vx)
        if my_window is not None:
            my = my * my_window
        out["my"] = my
    return out


def _mz(t, cv, b, kappa, alpha, fz, fz_mz, fxf, fyf, fy0, gyk, svyk, fx, fy, red, ts):
    """Combined-slip aligning moment ``Mz`` [N m] (§6.3, 4.E71-4.E78, A54-A56; §9 for MF 5.2)."""
    c = t.coef
    fz_m = fz if fz_mz is None else fz_mz
    need_g0 = b.has_camber and not t.is_52
    fyf0 = fy00 = None
    if need_g0:
        fyf0 = fy0_factors(t, cv, b, fz, 0.0, None, red)
        fy00 = fy0_curve(t, cv, b, fyf0, alpha)
        if b.backward and cv.alpha_star == "tan":
            fy00 = fy00 * b.sgn_vx
    m = mz_factors(t, cv, b, fz_m, fyf, fyf0, ts)
    if ts is not None:
        turnslip.mz_zetas(t, cv, b, fz, fyf, gyk, m, ts)
    # equivalent slips (A54/A55 or 4.E77/4.E78) with the stiffness ratio K_xk / K'_ya (with camber)
    ratio2 = np.square(fxf.K / fyf.Kp * kappa)
    at_eq = equivalent_slip(m.alpha_t, ratio2, cv)
    ar_eq = equivalent_slip(m.alpha_r, ratio2, cv)
    trail = cos_curve(m.Bt, m.Ct, m.Et, at_eq) * m.Dt * b.cos_ap
    if cv.s_mfeval:
        trail = trail * c["LFZO"]
    mzr = m.Dr * np.cos(m.Cr * np.arctan(m.Br * ar_eq))
    if cv.mzr_cos_combined:
        mzr = mzr * b.cos_ap
    if red is not None:
        trail = trail * red
        mzr = mzr * red
    if t.is_52:
        fyp = fy - svyk
    else:
        f0 = fy00 if need_g0 else fy0
        if need_g0 and cv.fyp_gyk_zero_camber and c["RBY4"]:
            fyp = g_yk(t, cv, b, kappa, 0.0) * f0
        else:
            fyp = gyk * f0
    r0 = c["UNLOADED_RADIUS"]
    gz = b.g_star * c["LGAZ"] if t.is_52 else b.g_star
    if cv.s_mfeval:
        s = r0 * (c["SSZ1"] + c["SSZ2"] * fy / c["FNOMIN"] + (c["SSZ3"] + c["SSZ4"] * b.dfz) * (gz if t.is_52 else b.gamma)) * c["LS"]
    else:
        s = r0 * (c["SSZ1"] + c["SSZ2"] * fy / b.fz0p) * c["LS"]
    if cv.mz_pure_at_kappa0:
        s = s * (kappa != 0)
    return mzr - trail * fyp + s * fx


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
