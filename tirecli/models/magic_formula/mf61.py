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
place; these modules hold the equations only (no broadcasting, chunking or I/O). This module is the
kernel (:func:`evaluate_kernel`); the equations are, by concept:

:mod:`~.curve` (the Magic Formula curve and numeric helpers), :mod:`~.state` (the shared normalised
quantities, §3), :mod:`~.pure` (``Fx0``, ``Fy0``, §5.1-§5.2), :mod:`~.combined` (``G_xa``, ``G_yk``,
``S_Vyk``, §6.1-§6.2), :mod:`~.aligning` (``Mz0``, ``Mz``, §5.3, §6.3), :mod:`~.moments` (``Mx``, ``My``, §7).
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula import turnslip
from tirecli.models.magic_formula.aligning import _mz, _mz0
from tirecli.models.magic_formula.combined import g_xa, g_yk, sv_yk
from tirecli.models.magic_formula.curve import _is_zero
from tirecli.models.magic_formula.moments import overturning, rolling
from tirecli.models.magic_formula.pure import fx0_curve, fx0_factors, fy0_curve, fy0_factors, fy0_load
from tirecli.models.magic_formula.state import basic
from tirecli.models.magic_formula.tire import Convention, MFTire


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
