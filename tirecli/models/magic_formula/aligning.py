"""Aligning moment of MF 6.1 / 5.2: pure-slip ``Mz0`` and combined-slip ``Mz``, vectorized.

docs/models/magic_formula_tyre.md §5.3 and §6.3 (book 4.E31-4.E49, 4.E71-4.E78; Besselink et al. 2010
A54-A60; §9 for MF 5.2): ``Mz = -t F'y + M_zr + s Fx`` from the trail and residual-torque factors
(:func:`mz_factors`) and the equivalent slips (:func:`equivalent_slip`).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from tirecli.models.magic_formula import turnslip
from tirecli.models.magic_formula.combined import g_yk
from tirecli.models.magic_formula.curve import _clip_e, _iadd, _imul, _is_zero, _isub, _lin, _scale, cos_curve
from tirecli.models.magic_formula.pure import fy0_curve, fy0_factors
from tirecli.models.magic_formula.state import _quad
from tirecli.models.magic_formula.tire import Convention, MFTire

_2_PI = 2.0 / math.pi


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
