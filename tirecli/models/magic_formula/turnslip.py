"""Turn slip (spin) of MF 6.1: the reduction factors zeta_0 ... zeta_8 (docs/models/magic_formula_tyre.md §8).

Book Pacejka 2012 eqs. 4.75-4.106 / 4.E80-4.E91, restated in §8. Spin is

``phi = -(psi_dot - (1 - eps_gamma) Omega sin(gamma)) / V'_c``,  ``psi_dot = -phi_t V_c``,

i.e. ``phi = phi_t V_c/V'_c + (1 - eps_gamma) Omega sin(gamma)/V'_c`` with the turn slip
``phi_t`` [1/m] as input (a steady circle of radius R has ``|phi_t| = 1/R``). This is the book's
sign: with ``phi_t = 0`` the camber part of the spin gives camber thrust of the same sign as the
no-turn-slip model (``Fy < 0`` for ``gamma > 0``). mfeval's code has the opposite overall sign
(§8 caution). ``K_zgr0`` is the camber slope of the residual torque at zero camber
``Fz R0 (QDZ8 + QDZ9 dfz)(1 + PPZ2 dpi) LKZC`` (not mfeval's ``QDZ8*QDZ9`` product).
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

_2_PI = 2.0 / math.pi


def _cos_atan(x):
    return 1.0 / np.sqrt(1.0 + np.square(x))


def spin(t, cv, b, kappa, alpha, gamma, fz, vx, phit):
    """Spin ``phi`` [1/m] and the factors ``zeta1, zeta2, zeta3, zeta5, zeta6`` (4.E80-4.E91, 4.105).

    ``Omega`` [rad/s] is ``(1 + kappa) Vx / R_e`` with the effective rolling radius of §7.3 when
    the tyre has its coefficients, else the unloaded radius ``R0``.
    """
    from tirecli.models.magic_formula.radius import rolling_radius_or_r0

    c = t.coef
    r0 = c["UNLOADED_RADIUS"]
    dfz = b.dfz
    tan_a = np.tan(alpha)
    vc = np.abs(vx) * np.sqrt(1.0 + np.square(tan_a))
    vcp = vc + cv.eps
    eps_g = c["PECP1"] * (1.0 + c["PECP2"] * dfz)
    re = rolling_radius_or_r0(t, fz, kappa, vx, b.dpi)
    omega = (1.0 + kappa) * vx / re
    phi = phit * (vc / vcp) + (1.0 - eps_g) * omega * np.sin(gamma) / vcp
    s = SimpleNamespace(phi=phi, phit=phit, eps_gamma=eps_g, omega=omega)
    r0phi = r0 * phi
    bxp = c["PDXP1"] * (1.0 + c["PDXP2"] * dfz) * _cos_atan(c["PDXP3"] * kappa)
    s.zeta1 = _cos_atan(bxp * r0phi)
    byp = c["PDYP1"] * (1.0 + c["PDYP2"] * dfz) * _cos_atan(c["PDYP3"] * tan_a)
    ar = np.abs(r0phi)
    s.zeta2 = _cos_atan(byp * (ar + c["PDYP4"] * np.sqrt(ar)))
    s.zeta3 = _cos_atan(c["PKYP1"] * np.square(r0phi))
    s.zeta5 = _cos_atan(c["QDTP1"] * r0phi)
    s.zeta6 = _cos_atan(c["QBRP1"] * r0phi)
    return s


def zeta4(t, cv, b, fz, f, ts):
    """``zeta4 = 1 + S_Hyphi - S_Vyg/K'_ya`` (4.E84) with the spin shift ``S_Hyphi`` (4.E80-4.E88).

    ``f`` holds the Fy0 factors computed so far (``K``, ``Kp``, ``Kg0``, ``SVg``).
    """
    c = t.coef
    dfz, dpi, fz0p = b.dfz, b.dpi, b.fz0p
    den = c["PKY2"] * (1.0 + c["PPY2"] * dpi) if np.any(dpi) else c["PKY2"]
    kya0 = c["PKY1"] * fz0p * np.sin(c["PKY4"] * np.arctan(fz / fz0p / den)) * ts.zeta3 * c["LKY"]
    if np.any(dpi):
        kya0 = kya0 * (1.0 + c["PPY1"] * dpi)
    kya0p = kya0 + cv.eps * np.copysign(1.0, kya0 + 0.0)
    kyr0 = f.Kg0 / (1.0 - ts.eps_gamma)
    chp = c["PHYP1"]
    dhp = (c["PHYP2"] + c["PHYP3"] * dfz) * b.sgn_vx
    ehp = min(c["PHYP4"], 1.0)
    bhp = kyr0 / (chp * dhp * kya0p)
    x = bhp * t.coef["UNLOADED_RADIUS"] * ts.phi
    shp = dhp * np.sin(chp * np.arctan(x - ehp * (x - np.arctan(x)))) * b.sgn_vx
    return 1.0 + shp - f.SVg / f.Kp


def mz_zetas(t, cv, b, fz, fyf, gyk, m, ts):
    """Set ``m.Cr = zeta7`` and add ``zeta8 - 1`` to ``m.Dr`` (4.E91-4.E103; §8 moment terms)."""
    c = t.coef
    r0 = c["UNLOADED_RADIUS"]
    dfz, dpi, fz0p = b.dfz, b.dpi, b.fz0p
    mzp_inf = np.maximum(c["QCRP1"] * np.abs(fyf.mu) * r0 * fz * np.sqrt(fz / fz0p) * c["LMP"], 1e-6)
    mzp90 = mzp_inf * _2_PI * np.arctan(c["QCRP2"] * r0 * np.abs(ts.phit)) * gyk
    cdr = c["QDRP1"]
    ddr = mzp_inf / math.sin(0.5 * math.pi * cdr)
    kzgr0 = fz * r0 * (c["QDZ8"] + c["QDZ9"] * dfz) * c["LKZC"]
    if np.any(dpi):
        kzgr0 = kzgr0 * (1.0 + c["PPZ2"] * dpi)
    bdr = kzgr0 / (cdr * ddr * (1.0 - ts.eps_gamma))
    drp = ddr * np.sin(cdr * np.arctan(bdr * r0 * ts.phi))
    arg = np.clip(mzp90 / np.maximum(np.abs(drp), 1e-300), -1.0, 1.0)
    m.Cr = _2_PI * np.arccos(arg)
    m.Dr = m.Dr + drp
