"""The basic Magic Formula curve with fixed B, C, D, E (docs/models/magic_formula_tyre.md §13.1): the simple-form
fallback of the MCPS comparison (docs/models/mcps_tire.md §8), when no real ``.tir`` tyre is wanted.

``Y = D sin(C arctan(B x - E (B x - arctan B x)))`` per channel, no shifts; the peak scales with the
load (``Dx Fz``, ``Dy Fz`` [N], ``Dz Fz`` [N m]: the fields are peaks over load), ``B``, ``C``, ``E``
are fixed [assumed].
ISO-W axes, road on tire: ``Fx`` has the sign of ``kappa``, ``Fy`` the opposite sign of ``alpha``,
``Mz`` the sign of ``alpha`` (docs/models/magic_formula_tyre.md §2.2). Combined slip [assumed]: the normalised-slip
similarity method (docs/models/magic_formula_tyre.md §13.3, Beckman's variant): ``s = kappa/kappa_peak``,
``a = alpha/alpha_peak``, ``rho = hypot(s, a)``, ``Fx = (s/rho) Fx0(rho kappa_peak)``,
``Fy = (a/rho) Fy0(rho alpha_peak)``, and likewise ``Mz = (a/rho) Mz0(rho alpha_peak)``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def curve(x, B, C, D, E):
    """The basic curve ``D sin(C arctan(B x - E (B x - arctan B x)))`` (docs/models/magic_formula_tyre.md §13.1)."""
    bx = B * np.asarray(x, dtype=float)
    return D * np.sin(C * np.arctan(bx - E * (bx - np.arctan(bx))))


def peak_input(B, C, E) -> float:
    """Input ``x > 0`` of the curve's peak (where ``C arctan(...) = pi/2``); ``inf`` for ``C <= 1``."""
    if C <= 1.0:
        return math.inf
    target = math.tan(math.pi / (2.0 * C))
    from scipy.optimize import brentq

    f = lambda x: B * x - E * (B * x - math.atan(B * x)) - target  # noqa: E731
    hi = 1.0 / B
    while f(hi) < 0:
        hi *= 2.0
    return brentq(f, 0.0, hi, xtol=1e-15, rtol=1e-15)


@dataclass(frozen=True)
class SimpleMF:
    """Fixed-coefficient Magic Formula (docs/models/magic_formula_tyre.md §13.1), SI.

    Parameters
    ----------
    Bx, Cx, Ex : float
        Longitudinal stiffness factor [1/-], shape and curvature factors [-].
    Dx : float
        Longitudinal peak over load [-].
    By, Cy, Ey : float
        Lateral factors ([1/rad], [-], [-]).
    Dy : float
        Lateral peak over load [-].
    Bz, Cz, Ez : float
        Aligning-torque factors ([1/rad], [-], [-]).
    Dz : float
        Aligning-torque peak over load [m] (``Dz Fz`` in N m).
    """

    Bx: float
    Cx: float
    Dx: float
    Ex: float
    By: float
    Cy: float
    Dy: float
    Ey: float
    Bz: float
    Cz: float
    Dz: float
    Ez: float

    def pure(self, kappa, alpha, fz):
        """Pure-slip ``Fx0(kappa)``, ``Fy0(alpha)``, ``Mz0(alpha)`` [N, N, N m] (ISO-W)."""
        fx = curve(kappa, self.Bx, self.Cx, self.Dx * fz, self.Ex)
        fy = -curve(alpha, self.By, self.Cy, self.Dy * fz, self.Ey)
        mz = curve(alpha, self.Bz, self.Cz, self.Dz * fz, self.Ez)
        return fx, fy, mz

    def evaluate(self, kappa, alpha, fz):
        """Combined-slip ``Fx, Fy, Mz`` [N, N, N m] at broadcast ``kappa`` [-], ``alpha`` [rad],
        ``fz`` [N] (normalised-slip method; exactly the pure curves when one slip is zero)."""
        kappa, alpha, fz = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (kappa, alpha, fz)))
        kp = peak_input(self.Bx, self.Cx, self.Ex)
        ap = peak_input(self.By, self.Cy, self.Ey)
        s = kappa / kp
        a = alpha / ap
        rho = np.hypot(s, a)
        with np.errstate(invalid="ignore", divide="ignore"):
            ws = np.where(rho > 0, s / np.where(rho > 0, rho, 1.0), 0.0)
            wa = np.where(rho > 0, a / np.where(rho > 0, rho, 1.0), 0.0)
        fx0, fy0, mz0 = self.pure(rho * kp, rho * ap, fz)
        pure_k = alpha == 0
        pure_a = kappa == 0
        fxp, fyp, mzp = self.pure(kappa, alpha, fz)
        fx = np.where(pure_k, fxp, ws * fx0)
        fy = np.where(pure_a, fyp, wa * fy0)
        mz = np.where(pure_a, mzp, wa * mz0)
        return fx, fy, mz


__all__ = ["SimpleMF", "curve", "peak_input"]
