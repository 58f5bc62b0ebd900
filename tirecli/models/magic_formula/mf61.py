"""MF 6.1 (and MF 5.2 / PAC2002) steady-state forces and moments, vectorized (pure numpy).

Implements docs/models/magic_formula_tyre.md §3-§7 and §9 (book Pacejka 2012 eqs. 4.E1-4.E78; Besselink et al.
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


def _guard(x, eps: float):
    """``x + eps sgn(x)`` (book 4.E6a): a denominator kept away from zero with its own sign."""
    return x + np.copysign(eps, x)


def _scale(x, s: float):
    """``x * s``, skipping the work when the factor is exactly 1 (scaling factors, zeta)."""
    return x if s == 1.0 else x * s


def _lin(a0: float, a1: float, x):
    """``a0 + a1 x`` (a load polynomial), a plain number when ``a1 = 0``."""
    return a0 if a1 == 0.0 else a0 + a1 * x


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


def _is_zero(x) -> bool:
    return np.ndim(x) == 0 and x == 0


def _own(a, b) -> bool:
    return isinstance(a, np.ndarray) and a.ndim > 0 and np.size(b) <= a.size


def _imul(a, b):
    """``a * b``, in place when ``a`` is a full-size array owned by the caller."""
    return np.multiply(a, b, out=a) if _own(a, b) else a * b


def _iadd(a, b):
    return np.add(a, b, out=a) if _own(a, b) else a + b


def _isub(a, b):
    return np.subtract(a, b, out=a) if _own(a, b) else a - b


# --------------------------------------------------------------------------- shared state


def basic(t: MFTire, cv: Convention, kappa, alpha, gamma, fz, vx, p):
    """Normalised quantities shared by every output (§3): ``dfz``, ``dpi``, alpha*, gamma*, lambdas.

    Returns a namespace with ``dfz`` (4.E2a), ``dpi`` (4.E2b; a plain 0 without pressure
    effect), ``a_fy`` (alpha used in Fy0), ``a_star`` (alpha* used in combined slip and Mz),
    ``g_star`` (gamma*), ``lmux_s``/``lmuy_s`` (lambda*, 4.E7), ``lmux_p``/``lmuy_p`` (lambda',
    4.E8) and ``sgn_vx``.
    """
    c = t.coef
    fz0p = c["FNOMIN"] * c["LFZO"]
    b = SimpleNamespace()
    b.fz0p = fz0p
    b.dfz = fz * (1.0 / fz0p) - 1.0
    b.dfz2 = None
    pi0 = t.nominal_pressure
    dpi = 0.0 if (pi0 is None or p is None) else (p - pi0) * (1.0 / pi0)
    b.dpi = 0.0 if not np.any(dpi) else dpi
    b.has_dpi = not _is_zero(b.dpi)
    backward = bool(np.any(vx < 0))
    b.backward = backward
    b.sgn_vx = _sgn(vx, 1.0) if backward else 1.0
    tan_a = None
    a_tan = None
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


def _dfz2(b):
    if b.dfz2 is None:
        b.dfz2 = np.square(b.dfz)
    return b.dfz2


def _quad(a0, a1, a2, b):
    """``a0 + a1 dfz + a2 dfz^2``."""
    y = _lin(a0, a1, b.dfz)
    return y if a2 == 0.0 else y + a2 * _dfz2(b)


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


# --------------------------------------------------------------------------- combined slip


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
    cam = b.has_camber
    m = SimpleNamespace()
    gz = _scale(g, c["LGAZ"]) if t.is_52 else g
    gt = gz if (t.is_52 or cv.camber_trail_book) else b.gamma  # camber in Bt, Dt
    src = fy_f0 if (cv.mzr_zero_camber and fy_f0 is not None) else fy_f
    m.Kp = src.Kp
    shf = src.SH + src.SV / src.Kp if not _is_zero(src.SV) else src.SH
    m.alpha_r = b.a_star + shf
    sht = _lin(c["QHZ1"], c["QHZ2"], dfz)
    if cam and (c["QHZ3"] or c["QHZ4"]):
        sht = sht + _lin(c["QHZ3"], c["QHZ4"], dfz) * gz
    m.alpha_t = b.a_star + sht
    bt = _quad(c["QBZ1"], c["QBZ2"], c["QBZ3"], b)
    if cam and (c["QBZ4"] or c["QBZ5"]):
        bt = bt * (1.0 + c["QBZ4"] * gt + c["QBZ5"] * np.abs(gt))
    m.Bt = bt * (c["LKY"] / b.lmuy_s)
    m.Ct = c["QCZ1"]
    dt = fz_mz * ((t.coef["UNLOADED_RADIUS"] / fz0p) * c["LTR"]) * _lin(c["QDZ1"], c["QDZ2"], dfz)
    if b.has_dpi and not t.is_52:
        dt = dt * (1.0 - c["PPZ1"] * dpi)
    if cam and (c["QDZ3"] or c["QDZ4"]):
        q3 = np.abs(gt) if (cv.camber_trail_book and not t.is_52) else gt
        dt = dt * (1.0 + c["QDZ3"] * q3 + c["QDZ4"] * np.square(gt))
    if ts is not None:
        dt = dt * ts.zeta5
    m.Dt = dt * b.sgn_vx if b.backward else dt
    et = _quad(c["QEZ1"], c["QEZ2"], c["QEZ3"], b)
    q45 = c["QEZ4"] if not (cam and c["QEZ5"]) else c["QEZ4"] + c["QEZ5"] * gz
    if not _is_zero(q45):
        et = et * (1.0 + q45 * _2_PI * np.arctan((m.Ct * m.Bt) * m.alpha_t))
    m.Et = _clip_e(et, cv)
    br = c["QBZ9"] * c["LKY"] / b.lmuy_s
    m.Br = br + c["QBZ10"] * src.B * src.C if c["QBZ10"] else br
    m.Cr = 1.0
    r0 = t.coef["UNLOADED_RADIUS"]
    if ts is not None:  # zeta0 = 0 removes the camber part of D_r below
        m.Br = m.Br * ts.zeta6
    inner = _scale(_lin(c["QDZ6"], c["QDZ7"], dfz), c["LRES"])
    if ts is not None:
        inner = inner * ts.zeta2
    if cam and ts is None:
        if t.is_52:
            inner = inner + _lin(c["QDZ8"], c["QDZ9"], dfz) * gz
        else:
            gam = _lin(c["QDZ8"], c["QDZ9"], dfz)
            if b.has_dpi:
                gam = gam * (1.0 + c["PPZ2"] * dpi)
            if c["QDZ10"] or c["QDZ11"]:
                gam = gam + _lin(c["QDZ10"], c["QDZ11"], dfz) * np.abs(g)
            inner = inner + gam * g * c["LKZC"]
    dr = (fz_mz * r0) * inner * (b.cos_a * b.lmuy_s)
    m.Dr = dr * b.sgn_vx if b.backward else dr
    return m


def equivalent_slip(angle, ratio2, cv: Convention):
    """Equivalent slip angle of combined-slip ``Mz`` [rad] (A54/A55 paper form or book 4.E77/4.E78).

    ``ratio2 = (K_xk/K'_ya)^2 kappa^2``; paper: ``arctan(sqrt(tan^2(angle) + ratio2)) sgn(angle)``,
    book: ``sqrt(angle^2 + ratio2) sgn(angle)``.
    """
    if _is_zero(ratio2) and not np.any(np.abs(angle) >= 0.5 * np.pi):
        return angle  # no longitudinal slip: the equivalent slip is the slip angle itself
    if cv.eq_slip_paper:
        r = np.arctan(np.sqrt(np.square(np.tan(angle)) + ratio2))
    else:
        r = np.sqrt(np.square(angle) + ratio2)
    if cv.sgn_zero == 1.0:
        return np.copysign(r, angle + 0.0)
    return r * np.sign(angle)


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
                    combined=True):
    """Every requested output of one block of points (MF 6.1 / 5.2, combined or pure slip).

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
    combined : bool
        Combined slip (§6, default). False: the pure-slip ``Fx0(kappa)``, ``Fy0(alpha)`` and
        ``Mz0(alpha)`` (§5.3, 4.E31) each from its own slip ("uncombined", ADAMS USE_MODE 3).

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
    b = basic(t, cv, kappa, alpha, gamma, fz, vx, p)
    ts = None
    if phit is not None:
        ts = turnslip.spin(t, cv, b, kappa, alpha, gamma, fz, vx, phit)
    out = {}
    fx = fxf = fyf = fy0 = gyk = svyk = L = None
    if "fx" in need:
        fxf = fx0_factors(t, cv, b, fz, gamma, 1.0 if ts is None else ts.zeta1, red)
        fx0 = fx0_curve(t, cv, fxf, kappa)
        if b.backward:
            fx0 = fx0 * b.sgn_vx
        fx = fx0 * g_xa(t, cv, b, kappa, b.g_star) if combined else fx0
        out["fx"] = fx
    if "fy" in need:
        L = fy0_load(t, cv, b, fz)
        fyf = fy0_factors(t, cv, b, fz, b.g_star, ts, red, L)
        fy0 = fy0_curve(t, cv, b, fyf, alpha)
        if b.backward and cv.alpha_star == "tan":
            fy0 = fy0 * b.sgn_vx
        if combined:
            gyk = g_yk(t, cv, b, kappa, b.g_star)
            svyk = sv_yk(t, b, kappa, fz, fyf.mu, b.g_star, 1.0 if ts is None else ts.zeta2, red)
        else:
            gyk, svyk = 1.0, 0.0
        fy = gyk * fy0
        if not _is_zero(svyk):
            fy = fy + svyk
        out["fy"] = fy
    if "mz" in need and combined:
        out["mz"] = _mz(t, cv, b, kappa, alpha, vx, fz, fz_mz, fxf, fyf, L, fy0, gyk, svyk, fx, out["fy"], red, ts)
    elif "mz" in need:
        out["mz"] = _mz0(t, cv, b, alpha, vx, fz, fz_mz, fyf, L, fy0, red, ts)
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


def _cos_alpha_prime(b, alpha, vx, eps):
    """``cos(alpha') = Vcx / (Vc + eps)`` with ``Vc = |Vcx| sqrt(1 + tan^2 alpha) = |Vcx| / |cos alpha|``
    (4.E6, 4.E6a); also stores ``cos(alpha)`` in ``b`` (the factor of D_r, §5.3)."""
    ca = np.cos(alpha)
    b.cos_a = ca
    aca = np.abs(ca)
    if np.ndim(vx) == 0:
        if eps < 1e-12:
            return aca if vx > 0 else aca * np.sign(vx)
        return aca * (vx / (abs(vx) + eps * aca))
    return aca * (vx / (np.abs(vx) + eps * aca))


def _fy0_zero_camber(t, cv, b, fz, alpha, red, L, always=False):
    """Factors and value of Fy0 at zero camber and no turn slip (M'z, 4.E32, 4.E74), or
    ``(None, None)`` when the camber is zero anyway."""
    if not b.has_camber or (t.is_52 and not always):
        return None, None
    f0 = fy0_factors(t, cv, b, fz, 0.0, None, red, L)
    y0 = fy0_curve(t, cv, b, f0, alpha)
    if b.backward and cv.alpha_star == "tan":
        y0 = y0 * b.sgn_vx
    return f0, y0


def _mz0(t, cv, b, alpha, vx, fz, fz_mz, fyf, L, fy0, red, ts):
    """Pure-slip aligning moment ``Mz0 = -t0 Fy0(gamma=0) + Mzr0`` [N m] (§5.3, 4.E31-4.E47)."""
    cos_ap = _cos_alpha_prime(b, alpha, vx, cv.eps)
    fyf0, fy00 = _fy0_zero_camber(t, cv, b, fz, alpha, red, L, always=True)
    m = mz_factors(t, cv, b, fz if fz_mz is None else fz_mz, fyf, fyf0, ts)
    if ts is not None:
        turnslip.mz_zetas(t, cv, b, fz, fyf, 1.0, m, ts)
    trail = _imul(_imul(cos_curve(m.Bt, m.Ct, m.Et, m.alpha_t), m.Dt), cos_ap)
    mzr = np.arctan(m.Br * m.alpha_r)
    if np.ndim(m.Cr) or m.Cr != 1.0:
        mzr = mzr * m.Cr
    mzr = _imul(_imul(np.cos(mzr), m.Dr), cos_ap)
    if red is not None:
        trail = trail * red
        mzr = mzr * red
    return _isub(mzr, _imul(trail, fy0 if fy00 is None else fy00))


def _mz(t, cv, b, kappa, alpha, vx, fz, fz_mz, fxf, fyf, L, fy0, gyk, svyk, fx, fy, red, ts, fy0_zero=None):
    """Combined-slip aligning moment ``Mz`` [N m] (§6.3, 4.E71-4.E78, A54-A56; §9 for MF 5.2).

    ``fy0_zero``: :func:`_fy0_zero_camber` of the same points when the caller has it (the Magic Formula
    fit evaluates Mz many times with the Fy0 coefficients fixed); None: computed here."""
    c = t.coef
    cos_ap = _cos_alpha_prime(b, alpha, vx, cv.eps)
    fz_m = fz if fz_mz is None else fz_mz
    fyf0, fy00 = _fy0_zero_camber(t, cv, b, fz, alpha, red, L) if fy0_zero is None else fy0_zero
    need_g0 = fy00 is not None
    m = mz_factors(t, cv, b, fz_m, fyf, fyf0, ts)
    if ts is not None:
        turnslip.mz_zetas(t, cv, b, fz, fyf, gyk, m, ts)
    # equivalent slips (A54/A55 or 4.E77/4.E78) with the stiffness ratio K_xk / K'_ya (with camber)
    ratio2 = 0.0 if _is_zero(kappa) else np.square((fxf.K / fyf.Kp) * kappa)
    at_eq = equivalent_slip(m.alpha_t, ratio2, cv)
    ar_eq = equivalent_slip(m.alpha_r, ratio2, cv)
    trail = _imul(_imul(cos_curve(m.Bt, m.Ct, m.Et, at_eq), m.Dt), cos_ap)
    if cv.s_mfeval and c["LFZO"] != 1.0:
        trail = _imul(trail, c["LFZO"])
    mzr = np.arctan(m.Br * ar_eq)
    if np.ndim(m.Cr) or m.Cr != 1.0:
        mzr = mzr * m.Cr
    mzr = _imul(np.cos(mzr), m.Dr)
    if cv.mzr_cos_combined:
        mzr = _imul(mzr, cos_ap)
    if red is not None:
        trail = trail * red
        mzr = mzr * red
    if t.is_52:
        fyp = fy - svyk if not _is_zero(svyk) else fy
    else:
        f0 = fy00 if need_g0 else fy0
        if need_g0 and cv.fyp_gyk_zero_camber and c["RBY4"]:
            fyp = g_yk(t, cv, b, kappa, 0.0) * f0
        else:
            fyp = gyk * f0
    mzr = _isub(mzr, _imul(trail, fyp))  # M_zr + M'z with M'z = -t F'y
    r0 = c["UNLOADED_RADIUS"]
    if cv.s_mfeval:
        s = c["SSZ1"] + c["SSZ2"] / c["FNOMIN"] * fy
        if b.has_camber and (c["SSZ3"] or c["SSZ4"]):
            gs = _scale(b.g_star, c["LGAZ"]) if t.is_52 else b.gamma
            s = s + _lin(c["SSZ3"], c["SSZ4"], b.dfz) * gs
    else:
        s = c["SSZ1"] + c["SSZ2"] / b.fz0p * fy
    s = s * (r0 * c["LS"])
    if cv.mz_pure_at_kappa0:
        s = s * (kappa != 0)
    mzr = _iadd(mzr, _imul(s, fx))
    return mzr


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
