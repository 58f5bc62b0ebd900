"""Parameters of the MCPS tire model and the quantities derived from them.

Units are SI; the schema (units, ranges, meaning, equation) is the ``mcps`` kind of
:mod:`tirecli.parameters.kinds`; the default values are the built-in set ``sorine2000-mcps``
(all assumed: the paper prints none). Equations: Sorine & Szymanski 2000 [MCPS];
``docs/models/mcps_tire.md``.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from tirecli.models.mcps.law import DahlLaw, second_order


@dataclass(frozen=True)
class Patch:
    """Contact-patch geometry at one load.

    Attributes
    ----------
    fz : float
        Vertical load [N].
    l : float
        Patch length along X_W [m]: ``l_ref (fz/fz_ref)^l_exponent``.
    w : float
        Patch width along Y_W [m].
    P : float
        Uniform contact pressure [Pa]: ``fz/(w l)``.
    """

    fz: float
    l: float
    w: float
    P: float


@dataclass(frozen=True)
class MCPSParams:
    """MCPS tire parameters (SI).

    Parameters
    ----------
    w : float
        Patch width [m].
    l_ref : float
        Patch length at ``fz_ref`` [m].
    fz_ref : float
        Reference load [N].
    l_exponent : float
        Exponent of the patch length against load [-].
    r_x, r_y : float
        Rubber stiffness per unit area along X, Y [N/m^3] (MCPS §2.3: ``K = U r``).
    mu_x, mu_y : float
        Friction coefficients along X, Y [-] (``F_k = P U mu``).
    alpha_x, alpha_y, alpha_z, beta_x, beta_y, beta_z : float
        Overshoot factors [-] (> 1) of the second-order law (MCPS eqs. 5-8).
    c_Mz : float
        Weight of the lever-arm torque ``xi f_y`` in ``M_z`` [-] (MCPS eq. 10).
    c_Sz, c_muz : float
        Empirical factors of the torsional stiffness and sliding torque [-] (MCPS eq. 8).
    m_b : float
        Belt mass [kg] (MCPS eq. 17).
    J_b : float
        Belt yaw inertia [kg m^2].
    k_x, k_y : float
        Belt-rim stiffnesses [N/m].
    k_delta : float
        Belt-rim twist stiffness [N m/rad].
    c_x, c_y : float
        Belt-rim dampings [N s/m].
    c_delta : float
        Belt-rim twist damping [N m s/rad].
    U : float
        Area of the single slider of MCPS Fig. 3 [m^2].
    """

    w: float
    l_ref: float
    fz_ref: float
    l_exponent: float
    r_x: float
    r_y: float
    mu_x: float
    mu_y: float
    alpha_x: float
    alpha_y: float
    alpha_z: float
    beta_x: float
    beta_y: float
    beta_z: float
    c_Mz: float
    c_Sz: float
    c_muz: float
    m_b: float
    J_b: float
    k_x: float
    k_y: float
    k_delta: float
    c_x: float
    c_y: float
    c_delta: float
    U: float

    def with_values(self, **values) -> "MCPSParams":
        """A copy with some values changed (e.g. calibrated rubber parameters; units as the attributes).

        Parameters
        ----------
        **values : float
            New values by attribute name [SI units of the attribute].
        """
        return replace(self, **values)

    def with_patch_length(self, l_ref: float) -> "MCPSParams":
        """The set with patch length ``l_ref`` [m] at ``fz_ref`` and the same stationary curves without yaw.

        With ``lam = l_ref/self.l_ref``: ``r_x, r_y -> r/lam^2`` and ``c_Mz -> c_Mz/lam``. The stationary
        ``Fx, Fy, Mz`` under pure and combined slip (MCPS eqs. 10, 14, 16-18, no yaw) depend on the patch
        length only through ``w r l^2`` and ``c_Mz l`` (the per-length constants give ``z`` of
        docs/models/mcps_tire.md §6 unchanged), so these curves cannot determine ``l``: a calibration to
        them fits the trail factor ``c_Mz`` at a given ``l``. The curvature, standstill and relaxation
        responses do change with ``l``.

        Parameters
        ----------
        l_ref : float
            Patch length at ``fz_ref`` [m].
        """
        lam = float(l_ref) / self.l_ref
        return replace(self, l_ref=float(l_ref), r_x=self.r_x / lam**2, r_y=self.r_y / lam**2, c_Mz=self.c_Mz / lam)

    def patch(self, fz: float) -> Patch:
        """Patch geometry at load ``fz`` (docs/models/mcps_tire.md §9: ``l = l_ref (fz/fz_ref)^l_exponent``, ``P = fz/(w l)``).

        Parameters
        ----------
        fz : float
            Vertical load [N].
        """
        fz = float(fz)
        l = self.l_ref * (fz / self.fz_ref) ** self.l_exponent
        return Patch(fz=fz, l=l, w=self.w, P=fz / (self.w * l))

    def patch_law(self, fz: float) -> DahlLaw:
        """Second-order law per unit patch length at load ``fz`` (MCPS eqs. 5-8; docs/models/mcps_tire.md §5):
        ``K' = w r``, ``F'_k = mu P w``, ``S'_z = c_Sz r_y w^3/12``, ``M'_kz = c_muz mu_y P w^2/4``.

        Parameters
        ----------
        fz : float
            Vertical load [N].
        """
        pa = self.patch(fz)
        w, P = pa.w, pa.P
        return second_order(
            K=[w * self.r_x, w * self.r_y], Fk=[self.mu_x * P * w, self.mu_y * P * w],
            alpha=[self.alpha_x, self.alpha_y], beta=[self.beta_x, self.beta_y],
            Sz=self.c_Sz * self.r_y * w**3 / 12.0, Mkz=self.c_muz * self.mu_y * P * w**2 / 4.0,
            alpha_z=self.alpha_z, beta_z=self.beta_z)

    def slider_law(self, pressure: float) -> DahlLaw:
        """Second-order law of one slider of area ``U`` under ``pressure`` (MCPS §2.3, eqs. 7-8):
        ``K = U r``, ``F_k = P U mu``, ``S_z = c_Sz U^2 r_y``, ``M_kz = c_muz P mu_y U^(3/2)``.

        Parameters
        ----------
        pressure : float
            Contact pressure ``P`` [Pa].
        """
        U, P = self.U, float(pressure)
        return second_order(
            K=[U * self.r_x, U * self.r_y], Fk=[P * U * self.mu_x, P * U * self.mu_y],
            alpha=[self.alpha_x, self.alpha_y], beta=[self.beta_x, self.beta_y],
            Sz=self.c_Sz * U**2 * self.r_y, Mkz=self.c_muz * P * self.mu_y * U**1.5,
            alpha_z=self.alpha_z, beta_z=self.beta_z)

    def stiffnesses(self, fz: float) -> dict:
        """Linear stiffnesses at load ``fz`` (docs/models/mcps_tire.md §5-§7), SI:

        - ``D_xsigma = w r_x l^2/2`` [N]: slip stiffness dFx/dkappa (solid carcass = complete model);
        - ``D_yalpha = w r_y l^2/2`` [N/rad]: cornering stiffness -dFy/dalpha, solid carcass;
        - ``D_zalpha = c_Mz w r_y l^3/12`` [N m/rad]: aligning stiffness dMz/dalpha, solid carcass;
        - ``D_yphi = w r_y l^3/12`` [N m]: curvature force stiffness -dFy/dphi, solid carcass;
        - ``D_zphi = c_Sz w r_y w^2 l^2/24`` [N m^2]: curvature torque stiffness -dMz/dphi, solid carcass;
        - ``D_yalphaF``, ``D_zalphaF``: eq. (20), with the belt twist: ``D k_delta/(k_delta + D_zalpha)``;
        - ``D_yphiF``, ``D_zphiF``: curvature stiffnesses with the twist (linear theory, docs/models/mcps_tire.md §7);
        - ``C_z`` [N m/rad]: small yaw stiffness at standstill, eq. (11), and ``C_zF`` with the twist;
        - ``Mz_inf`` [N m]: asymptotic sliding torque at standstill, eq. (12) (frame term off).

        Parameters
        ----------
        fz : float
            Vertical load [N].
        """
        pa = self.patch(fz)
        l, w = pa.l, pa.w
        dxs = w * self.r_x * l**2 / 2.0
        dya = w * self.r_y * l**2 / 2.0
        dza = self.c_Mz * w * self.r_y * l**3 / 12.0
        dyp = w * self.r_y * l**3 / 12.0
        dzp = self.c_Sz * w * self.r_y * w**2 * l**2 / 24.0
        kd = self.k_delta
        cz = self.r_y * l * w / 12.0 * (self.c_Mz * l**2 + self.c_Sz * w**2)
        return {
            "D_xsigma": dxs, "D_yalpha": dya, "D_zalpha": dza, "D_yphi": dyp, "D_zphi": dzp,
            "D_yalphaF": dya * kd / (kd + dza), "D_zalphaF": dza * kd / (kd + dza),
            "D_yphiF": dyp + dya * dzp / (kd + dza), "D_zphiF": dzp * kd / (kd + dza),
            "C_z": cz, "C_zF": 1.0 / (1.0 / cz + 1.0 / kd),
            "Mz_inf": self.mu_y * pa.fz / 4.0 * (self.c_muz * w + self.c_Mz * l),
        }


__all__ = ["MCPSParams", "Patch"]
