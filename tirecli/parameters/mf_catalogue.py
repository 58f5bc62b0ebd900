"""Catalogue of ``.tir`` keys: expected section, dimension (for unit conversion) and meaning.

The one place where the Magic Formula parameter names, units and meanings are written down
(docs/models/magic_formula_tyre.md §4-§9, §12.2, §13.2). Dimensions: ``-`` none, ``L`` length, ``F`` force,
``M`` mass, ``T`` time, ``P`` pressure, ``A`` angle (radians only, see
:mod:`tirecli.parameters.mf`), combinations such as ``F/L``; ``str`` marks text values;
``pac89`` marks coefficients in the PAC89 form's own units (kN, %, deg; never converted).
"""
from __future__ import annotations

from dataclasses import dataclass

_TABLE = """
[MDI_HEADER]
FILE_TYPE str file type ('tir')
FILE_VERSION - file format version
FILE_FORMAT str file format ('ASCII')
[UNITS]
LENGTH str unit of length in this file
FORCE str unit of force in this file
ANGLE str unit of angle in this file
MASS str unit of mass in this file
TIME str unit of time in this file
PRESSURE str unit of pressure in this file
[MODEL]
FITTYP - Magic Formula version number (61, 62: MF 6.1/6.2; 6, 21: MF 5.2; 5: MF-Tyre 5.0/5.1)
PROPERTY_FILE_FORMAT str property file format ('USER', 'PAC2002', 'MF_05', 'PAC89', ...)
USE_MODE - ADAMS/TNO use mode (ignored by tirecli)
TYRESIDE str side the tyre was measured on ('LEFT' or 'RIGHT')
LONGVL L/T reference (measurement) speed V0
VXLOW L/T lower speed limit of the slip calculation (low-speed handling)
ROAD_INCREMENT L increment in road sampling
ROAD_DIRECTION - direction of travelled distance
FUNCTION_NAME str ADAMS function name
USER_SUB_ID - ADAMS user subroutine id
N_TIRE_STATES - ADAMS number of tyre states
HMAX_LOCAL T local integration time step (ADAMS)
SWITCH_INTEG - integration switch (ADAMS)
TIME_SWITCH_INTEG T time when the local integrator is activated (ADAMS)
CONTACT_MODEL str contact model (Adams/Chrono)
[DIMENSION]
UNLOADED_RADIUS L free tyre radius R0
WIDTH L nominal section width
ASPECT_RATIO - nominal aspect ratio
RIM_RADIUS L nominal rim radius
RIM_WIDTH L rim width
[OPERATING_CONDITIONS]
INFLPRES P inflation pressure to simulate
NOMPRES P nominal inflation pressure of the fit (p_i0)
[INERTIA]
MASS M tyre mass
IXX M*L^2 tyre diametral moment of inertia
IYY M*L^2 tyre polar moment of inertia
BELT_MASS M belt mass
BELT_IXX M*L^2 belt diametral moment of inertia
BELT_IYY M*L^2 belt polar moment of inertia
GRAVITY L/T^2 gravity acting on the belt in z
[VERTICAL]
FNOMIN F nominal (rated) wheel load Fz0
VERTICAL_STIFFNESS F/L vertical stiffness C_z
VERTICAL_DAMPING F*T/L vertical damping
BREFF - low-load stiffness of the effective rolling radius
DREFF - peak value of the effective rolling radius
FREFF - high-load stiffness of the effective rolling radius
Q_RE0 - ratio of free tyre radius to nominal radius
Q_V1 - tyre radius increase with speed
Q_V2 - vertical stiffness increase with speed
Q_FZ1 - linear load-deflection term
Q_FZ2 - quadratic load-deflection term
Q_FCX - longitudinal force influence on vertical stiffness
Q_FCY - lateral force influence on vertical stiffness
Q_FCY2 - explicit load dependency of Q_FCY (MF 6.2)
Q_CAM - stiffness reduction due to camber
Q_CAM1 - linear camber effect on loaded radius (MF 6.2)
Q_CAM2 - quadratic camber effect on loaded radius (MF 6.2)
Q_CAM3 - camber x load effect on loaded radius (MF 6.2)
Q_FYS1 - combined camber and lateral force effect on vertical force (MF 6.2)
Q_FYS2 - combined camber and lateral force effect on vertical force (MF 6.2)
Q_FYS3 - combined camber and lateral force effect on vertical force (MF 6.2)
Q_A1 - square-root load term of the contact length (MF 5.2)
Q_A2 - linear load term of the contact length (MF 5.2)
PFZ1 - pressure effect on vertical stiffness
BOTTOM_OFFST L distance to rim when bottoming starts
BOTTOM_STIFF F/L vertical stiffness of the bottomed tyre
MC_CONTOUR_A - motorcycle contour ellipse A
MC_CONTOUR_B - motorcycle contour ellipse B
ENV_C1 - effective height of the tyre contour (MF 6.2 enveloping)
ENV_C2 - effective height of the tyre contour (MF 6.2 enveloping)
[STRUCTURAL]
LONGITUDINAL_STIFFNESS F/L overall longitudinal stiffness
LATERAL_STIFFNESS F/L overall lateral stiffness
YAW_STIFFNESS F*L overall yaw stiffness (per rad)
FREQ_LONG 1/T undamped frequency of the fore/aft and vertical mode
FREQ_LAT 1/T undamped frequency of the lateral mode
FREQ_YAW 1/T undamped frequency of the yaw and camber mode
FREQ_WINDUP 1/T undamped frequency of the wind-up mode
DAMP_LONG - damping of the fore/aft and vertical mode
DAMP_LAT - damping of the lateral mode
DAMP_YAW - damping of the yaw and camber mode
DAMP_WINDUP - damping of the wind-up mode
DAMP_RESIDUAL - residual damping (proportional to stiffness)
DAMP_VLOW - additional low-speed damping (proportional to stiffness)
Q_BVX - load and speed influence on in-plane translation stiffness
Q_BVT - load and speed influence on in-plane rotation stiffness
PCFX1 - longitudinal stiffness: linear deflection dependency
PCFX2 - longitudinal stiffness: quadratic deflection dependency
PCFX3 - longitudinal stiffness: pressure dependency
PCFY1 - lateral stiffness: linear deflection dependency
PCFY2 - lateral stiffness: quadratic deflection dependency
PCFY3 - lateral stiffness: pressure dependency
PCMZ1 - yaw stiffness: pressure dependency
[CONTACT_PATCH]
Q_RA1 - square-root term of the contact length
Q_RA2 - linear term of the contact length
Q_RB1 - root term of the contact width
Q_RB2 - linear term of the contact width
ELLIPS_SHIFT - scaling of the distance between front and rear ellipsoid
ELLIPS_LENGTH - semi-major axis of the ellipsoid
ELLIPS_HEIGHT - semi-minor axis of the ellipsoid
ELLIPS_ORDER - order of the ellipsoid
ELLIPS_MAX_STEP L maximum height of a road step
ELLIPS_NWIDTH - number of parallel ellipsoids
ELLIPS_NLENGTH - number of ellipsoids at the sides of the contact patch
[INFLATION_PRESSURE_RANGE]
PRESMIN P minimum valid inflation pressure
PRESMAX P maximum valid inflation pressure
[VERTICAL_FORCE_RANGE]
FZMIN F minimum valid wheel load
FZMAX F maximum valid wheel load
[LONG_SLIP_RANGE]
KPUMIN - minimum valid longitudinal slip
KPUMAX - maximum valid longitudinal slip
[SLIP_ANGLE_RANGE]
ALPMIN A minimum valid slip angle
ALPMAX A maximum valid slip angle
[INCLINATION_ANGLE_RANGE]
CAMMIN A minimum valid inclination angle
CAMMAX A maximum valid inclination angle
[SCALING_COEFFICIENTS]
LFZO - scale factor of the nominal (rated) load
LCX - scale factor of the Fx shape factor
LMUX - scale factor of the Fx peak friction
LEX - scale factor of the Fx curvature factor
LKX - scale factor of the Fx slip stiffness
LHX - scale factor of the Fx horizontal shift
LVX - scale factor of the Fx vertical shift
LCY - scale factor of the Fy shape factor
LMUY - scale factor of the Fy peak friction
LEY - scale factor of the Fy curvature factor
LKY - scale factor of the cornering stiffness
LKYC - scale factor of the camber force stiffness
LKZC - scale factor of the camber torque stiffness
LHY - scale factor of the Fy horizontal shift
LVY - scale factor of the Fy vertical shift
LTR - scale factor of the pneumatic trail peak
LRES - scale factor of the residual torque offset
LXAL - scale factor of the alpha influence on Fx
LYKA - scale factor of the kappa influence on Fy
LVYKA - scale factor of the kappa-induced side force
LS - scale factor of the moment arm of Fx
LMX - scale factor of the overturning moment
LVMX - scale factor of the Mx vertical shift
LMY - scale factor of the rolling resistance moment
LMP - scale factor of the parking (turn-slip) moment
LMUV - friction decay with slip speed (default 0)
LGAX - scale factor of camber for Fx (PAC2002)
LGAY - scale factor of camber for Fy (PAC2002)
LGAZ - scale factor of camber for Mz (PAC2002)
LSGKP - scale factor of the Fx relaxation length (PAC2002)
LSGAL - scale factor of the Fy relaxation length (PAC2002)
LGYR - scale factor of the gyroscopic torque (PAC2002)
[LONGITUDINAL_COEFFICIENTS]
PCX1 - shape factor C_x
PDX1 - longitudinal friction mu_x at Fz0
PDX2 - variation of mu_x with load
PDX3 - variation of mu_x with camber squared
PEX1 - curvature E_x at Fz0
PEX2 - variation of E_x with load
PEX3 - variation of E_x with load squared
PEX4 - drive/brake asymmetry of E_x
PKX1 - slip stiffness K_xk/Fz at Fz0
PKX2 - variation of K_xk/Fz with load
PKX3 - exponent of K_xk/Fz with load
PHX1 - horizontal shift S_Hx at Fz0
PHX2 - variation of S_Hx with load
PVX1 - vertical shift S_Vx/Fz at Fz0
PVX2 - variation of S_Vx/Fz with load
PPX1 - linear pressure effect on slip stiffness
PPX2 - quadratic pressure effect on slip stiffness
PPX3 - linear pressure effect on mu_x
PPX4 - quadratic pressure effect on mu_x
RBX1 - slope of the Fx reduction with alpha (combined slip)
RBX2 - decay of that slope with kappa
RBX3 - camber influence on that slope
RCX1 - shape factor of the Fx reduction
REX1 - curvature of the Fx reduction
REX2 - load variation of that curvature
RHX1 - shift of the Fx reduction
PTX1 - relaxation length SigKap0/Fz at Fz0 (PAC2002)
PTX2 - variation of SigKap0/Fz with load (PAC2002)
PTX3 - exponential load variation of SigKap0/Fz (PAC2002)
[OVERTURNING_COEFFICIENTS]
QSX1 - vertical shift of the overturning moment
QSX2 - camber-induced overturning couple
QSX3 - Fy-induced overturning couple
QSX4 - mixed load, lateral force and camber on Mx
QSX5 - load effect on Mx with lateral force and camber
QSX6 - B-factor of load with Mx
QSX7 - camber with load on Mx
QSX8 - lateral force with load on Mx
QSX9 - B-factor of lateral force with load on Mx
QSX10 - vertical force with camber on Mx
QSX11 - B-factor of vertical force with camber on Mx
QSX12 - camber-squared overturning moment
QSX13 - lateral-force-induced overturning moment
QSX14 - lateral-force-induced overturning moment with camber
PPMX1 - pressure effect on the overturning moment
[LATERAL_COEFFICIENTS]
PCY1 - shape factor C_y
PDY1 - lateral friction mu_y at Fz0
PDY2 - variation of mu_y with load
PDY3 - variation of mu_y with camber squared
PEY1 - curvature E_y at Fz0
PEY2 - variation of E_y with load
PEY3 - asymmetry of E_y
PEY4 - camber variation of the E_y asymmetry
PEY5 - camber-squared term of E_y
PKY1 - peak of K_ya/Fz0' (negative in ISO files)
PKY2 - load (in Fz0') where K_ya peaks
PKY3 - variation of K_ya with |camber|
PKY4 - curvature of K_ya against load (2 in MF 5.2)
PKY5 - camber-squared shift of the K_ya peak load
PKY6 - camber stiffness K_yg0/Fz
PKY7 - load variation of the camber stiffness
PHY1 - horizontal shift S_Hy at Fz0
PHY2 - variation of S_Hy with load
PHY3 - variation of S_Hy with camber (MF 5.2)
PVY1 - vertical shift S_Vy/Fz at Fz0
PVY2 - variation of S_Vy/Fz with load
PVY3 - variation of S_Vy/Fz with camber
PVY4 - variation of S_Vy/Fz with camber and load
PPY1 - pressure effect on K_ya magnitude
PPY2 - pressure effect on the K_ya peak load
PPY3 - linear pressure effect on mu_y
PPY4 - quadratic pressure effect on mu_y
PPY5 - pressure effect on the camber stiffness
RBY1 - slope of the Fy reduction with kappa (combined slip)
RBY2 - decay of that slope with alpha
RBY3 - alpha shift in that slope
RBY4 - camber influence on that slope
RCY1 - shape factor of the Fy reduction
REY1 - curvature of the Fy reduction
REY2 - load variation of that curvature
RHY1 - shift of the Fy reduction
RHY2 - load variation of that shift
RVY1 - kappa-induced side force S_Vyk/(mu_y Fz) at Fz0
RVY2 - load variation of S_Vyk/(mu_y Fz)
RVY3 - camber variation of S_Vyk/(mu_y Fz)
RVY4 - alpha decay of S_Vyk/(mu_y Fz)
RVY5 - kappa shape of S_Vyk/(mu_y Fz)
RVY6 - kappa slope (atan) of S_Vyk/(mu_y Fz)
PTY1 - peak of the relaxation length SigAlp0/R0 (PAC2002)
PTY2 - load where SigAlp0 peaks (PAC2002)
[ROLLING_COEFFICIENTS]
QSY1 - rolling resistance moment coefficient
QSY2 - rolling resistance depending on Fx
QSY3 - rolling resistance depending on speed
QSY4 - rolling resistance depending on speed^4
QSY5 - rolling resistance depending on camber squared
QSY6 - rolling resistance depending on load and camber squared
QSY7 - load exponent of the rolling resistance
QSY8 - pressure exponent of the rolling resistance
[ALIGNING_COEFFICIENTS]
QBZ1 - trail slope B_t at Fz0
QBZ2 - variation of B_t with load
QBZ3 - variation of B_t with load squared
QBZ4 - variation of B_t with camber
QBZ5 - variation of B_t with |camber|
QBZ9 - residual-torque slope B_r: constant part
QBZ10 - residual-torque slope B_r: part proportional to B_y C_y
QCZ1 - trail shape factor C_t
QDZ1 - peak trail D_t Fz0'/(Fz R0)
QDZ2 - variation of the peak trail with load
QDZ3 - variation of the peak trail with camber
QDZ4 - variation of the peak trail with camber squared
QDZ6 - peak residual torque D_r/(Fz R0)
QDZ7 - variation of D_r with load
QDZ8 - variation of D_r with camber
QDZ9 - variation of D_r with camber and load
QDZ10 - variation of D_r with camber squared
QDZ11 - variation of D_r with camber squared and load
QEZ1 - trail curvature E_t at Fz0
QEZ2 - variation of E_t with load
QEZ3 - variation of E_t with load squared
QEZ4 - variation of E_t with the sign of alpha_t
QEZ5 - variation of E_t with camber and the sign of alpha_t
QHZ1 - trail horizontal shift S_Ht at Fz0
QHZ2 - variation of S_Ht with load
QHZ3 - variation of S_Ht with camber
QHZ4 - variation of S_Ht with camber and load
SSZ1 - moment arm s/R0 of Fx
SSZ2 - variation of s/R0 with Fy/Fz0
SSZ3 - variation of s/R0 with camber
SSZ4 - variation of s/R0 with load and camber
PPZ1 - pressure effect on the pneumatic trail
PPZ2 - pressure effect on the residual torque
QTZ1 - gyroscopic torque constant (PAC2002)
MBELT M belt mass of the wheel (PAC2002)
[TURNSLIP_COEFFICIENTS]
PDXP1 - peak Fx reduction due to spin
PDXP2 - load variation of the peak Fx reduction due to spin
PDXP3 - kappa variation of the peak Fx reduction due to spin
PKYP1 - cornering stiffness reduction due to spin
PDYP1 - peak Fy reduction due to spin
PDYP2 - load variation of the peak Fy reduction due to spin
PDYP3 - alpha variation of the peak Fy reduction due to spin
PDYP4 - square-root term of the peak Fy reduction due to spin
PHYP1 - Fy-alpha curve lateral shift limitation
PHYP2 - maximum lateral shift of the Fy-alpha curve
PHYP3 - load variation of that maximum shift
PHYP4 - curvature of the lateral shift
PECP1 - camber reduction factor of the spin (eps_gamma)
PECP2 - load variation of eps_gamma
QDTP1 - pneumatic trail reduction due to turn slip
QCRP1 - turning moment at constant turning and zero speed
QCRP2 - turn slip moment (alpha = 90 deg) increase with spin
QBRP1 - residual (spin) torque reduction due to side slip
QDRP1 - turn slip moment peak magnitude
QDRP2 - turn slip moment curvature (unused)
"""

# PAC89 coefficient names (§13.2): lateral a0..a13, longitudinal b0..b10, aligning c0..c17.
_PAC89 = {
    "LATERAL_COEFFICIENTS": [f"A{i}" for i in range(14)],
    "LONGITUDINAL_COEFFICIENTS": [f"B{i}" for i in range(11)],
    "ALIGNING_COEFFICIENTS": [f"C{i}" for i in range(18)],
}
_PAC89_MEANING = {
    "A0": "shape factor C of Fy", "A1": "load dependency of the Fy peak D (Fz^2 term)",
    "A2": "load dependency of the Fy peak D (Fz term)", "A3": "maximum cornering stiffness",
    "A4": "load at maximum cornering stiffness", "A5": "camber reduction of cornering stiffness",
    "B0": "shape factor C of Fx", "B1": "load dependency of the Fx peak D (Fz^2 term)",
    "B2": "load dependency of the Fx peak D (Fz term)", "B3": "slip stiffness (Fz^2 term)",
    "B4": "slip stiffness (Fz term)", "B5": "exponential load decay of the slip stiffness",
    "C0": "shape factor C of Mz", "C1": "load dependency of the Mz peak D (Fz^2 term)",
    "C2": "load dependency of the Mz peak D (Fz term)",
}

#: Display units of the dimensions.
UNIT_OF = {"-": "-", "str": "text", "L": "m", "F": "N", "M": "kg", "T": "s", "P": "Pa", "A": "rad",
           "F/L": "N/m", "F*T/L": "N s/m", "M*L^2": "kg m^2", "L/T": "m/s", "L/T^2": "m/s^2",
           "1/T": "1/s", "F*L": "N m", "pac89": "PAC89 units (kN, %, deg)"}


@dataclass(frozen=True)
class KeyInfo:
    """A catalogued ``.tir`` key."""

    key: str
    section: str
    dim: str
    meaning: str

    @property
    def unit(self) -> str:
        return UNIT_OF[self.dim]

    @property
    def is_text(self) -> bool:
        return self.dim == "str"


def _build() -> tuple[dict, dict]:
    by_key: dict = {}
    by_section: dict = {}
    section = ""
    for line in _TABLE.strip().splitlines():
        if line.startswith("["):
            section = line.strip("[]")
            continue
        key, dim, meaning = line.split(" ", 2)
        info = KeyInfo(key, section, dim, meaning)
        by_section[(section, key)] = info
        if key not in by_key or section not in ("UNITS", "MDI_HEADER"):
            by_key[key] = info  # [INERTIA] MASS (a number) wins over [UNITS] MASS (a unit)
    for section, keys in _PAC89.items():
        for k in keys:
            info = KeyInfo(k, section, "pac89", _PAC89_MEANING.get(k, f"PAC89 coefficient {k.lower()} (§13.2)"))
            by_key[k] = info
            by_section[(section, k)] = info
    return by_key, by_section


#: Key -> :class:`KeyInfo`, every key tirecli knows (the Magic Formula meaning of ``MASS``).
#: ``SECTION_KEYS``: ``(section, key)`` -> :class:`KeyInfo`.
CATALOGUE, SECTION_KEYS = _build()

#: Section names in the order a ``.tir`` file lists them (docs/models/magic_formula_tyre.md §12).
SECTION_ORDER = tuple(dict.fromkeys(info.section for info in SECTION_KEYS.values()))

#: Sections whose keys are not Magic Formula parameters (units, header, vendor-specific data).
NON_MF_SECTIONS = ("MDI_HEADER", "UNITS", "GOODYEAR", "TIRE_CONDITIONS")


def descriptions() -> dict:
    """Section -> key -> meaning (inline comments for written ``.tir`` files)."""
    out: dict = {}
    for (section, key), info in SECTION_KEYS.items():
        out.setdefault(section, {})[key] = info.meaning
    return out
