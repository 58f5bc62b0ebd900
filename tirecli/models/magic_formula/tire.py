"""A Magic Formula tyre (coefficients in SI, version, side) and the evaluation conventions.

:class:`MFTire` holds a *complete* flat coefficient map (upper-case ``.tir`` keys, SI units):
:func:`complete_coefficients` fills in tirecli's defaults (docs/models/magic_formula_tyre.md §12.5
item 9: every ``L*`` scaling factor 1 except ``LMUV`` 0, ``PKY4`` 2, the turn-slip defaults of
§8, everything else 0) and lists the required keys that are missing. Reading files and turning
problems into messages is the job of :mod:`tirecli.io.tir` and :mod:`tirecli.parameters.mf`.

:class:`Convention` gathers every point of §10 where public implementations disagree.
``mfeval`` is the "Recommended here" column of §10 (the default); ``teasit`` is the set of
switches of §15.2 that reproduces the public golden data of §15.4.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

#: Model versions: MF 6.1 (and 6.2, same steady-state equations), MF 5.2 / PAC2002, PAC89.
VERSIONS = ("6.1", "6.2", "5.2", "pac89")
#: How each version is named in messages, summaries and run.json.
VERSION_NAMES = {"6.1": "MF 6.1", "6.2": "MF 6.2 (MF 6.1 steady-state equations)", "5.2": "MF 5.2 / PAC2002",
                 "pac89": "PAC89 (Bakker-Pacejka-Lidner 1989)"}

#: Required coefficients per equation family (§12.5 item 9; §13.2 for PAC89).
REQUIRED = {
    "mf": ("FNOMIN", "UNLOADED_RADIUS", "PCX1", "PDX1", "PKX1", "PCY1", "PDY1", "PKY1", "PKY2"),
    "pac89": ("A0", "A1", "A2", "A3", "A4", "B0", "B1", "B2", "B3", "B4", "C0", "C1", "C2", "C3", "C4"),
}

#: Input-range keys: an absent bound means "no limit" (not 0).
RANGE_KEYS = {
    "fz": ("FZMIN", "FZMAX"), "kappa": ("KPUMIN", "KPUMAX"), "alpha": ("ALPMIN", "ALPMAX"),
    "gamma": ("CAMMIN", "CAMMAX"), "p": ("PRESMIN", "PRESMAX"),
}

_SCALING_61 = ("LFZO LCX LMUX LEX LKX LHX LVX LCY LMUY LEY LKY LKYC LKZC LHY LVY LTR LRES LXAL LYKA "
               "LVYKA LS LMX LVMX LMY").split()
_SCALING_52 = ("LFZO LCX LMUX LEX LKX LHX LVX LCY LMUY LEY LKY LHY LVY LTR LRES LXAL LYKA LVYKA LS LMX "
               "LVMX LMY LGAX LGAY LGAZ").split()

#: Every scaling factor (lambda, §4); all default to 1 except ``LMUV`` (0).
SCALING_KEYS = frozenset(_SCALING_61 + _SCALING_52 + ["LMP", "LSGKP", "LSGAL", "LGYR"])

_FX_61 = "PCX1 PDX1 PDX2 PDX3 PEX1 PEX2 PEX3 PEX4 PKX1 PKX2 PKX3 PHX1 PHX2 PVX1 PVX2 PPX1 PPX2 PPX3 PPX4".split()
_FX_COMB_61 = "RBX1 RBX2 RBX3 RCX1 REX1 REX2 RHX1".split()
_FY_61 = ("PCY1 PDY1 PDY2 PDY3 PEY1 PEY2 PEY3 PEY4 PEY5 PKY1 PKY2 PKY3 PKY4 PKY5 PKY6 PKY7 PHY1 PHY2 "
          "PVY1 PVY2 PVY3 PVY4 PPY1 PPY2 PPY3 PPY4 PPY5").split()
_FY_COMB_61 = "RBY1 RBY2 RBY3 RBY4 RCY1 REY1 REY2 RHY1 RHY2 RVY1 RVY2 RVY3 RVY4 RVY5 RVY6".split()
_MZ_61 = ("QBZ1 QBZ2 QBZ3 QBZ4 QBZ5 QBZ9 QBZ10 QCZ1 QDZ1 QDZ2 QDZ3 QDZ4 QDZ6 QDZ7 QDZ8 QDZ9 QDZ10 QDZ11 "
          "QEZ1 QEZ2 QEZ3 QEZ4 QEZ5 QHZ1 QHZ2 QHZ3 QHZ4 SSZ1 SSZ2 SSZ3 SSZ4 PPZ1 PPZ2").split()
_MX_61 = [f"QSX{i}" for i in range(1, 15)] + ["PPMX1"]
_MY_61 = [f"QSY{i}" for i in range(1, 9)]

#: Turn-slip coefficients with mfeval's defaults when the section is missing (§8).
TURNSLIP_DEFAULTS = {
    "PDXP1": 0.4, "PDXP2": 0.0, "PDXP3": 0.0, "PKYP1": 1.0, "PDYP1": 0.4, "PDYP2": 0.0, "PDYP3": 0.0,
    "PDYP4": 0.0, "PHYP1": 1.0, "PHYP2": 0.15, "PHYP3": 0.0, "PHYP4": -4.0, "PECP1": 0.5, "PECP2": 0.0,
    "QDTP1": 10.0, "QCRP1": 0.2, "QCRP2": 0.1, "QBRP1": 0.1, "QDRP1": 1.0, "LMP": 1.0,
}

#: Keys each equation family reads (the evaluator's view of a file).
MODEL_KEYS = {
    "6.1": (["FNOMIN", "UNLOADED_RADIUS", "LONGVL", "VXLOW", "NOMPRES", "INFLPRES", "LMUV"] + _SCALING_61
            + _FX_61 + _FX_COMB_61 + _FY_61 + _FY_COMB_61 + _MZ_61 + _MX_61 + _MY_61),
    "5.2": (["FNOMIN", "UNLOADED_RADIUS", "LONGVL", "VXLOW", "LMUV"] + _SCALING_52
            + [k for k in _FX_61 if not k.startswith("PPX")] + [k for k in _FX_COMB_61 if k != "RBX3"]
            + [k for k in _FY_61 if not k.startswith("PPY") and k not in ("PEY5", "PKY5", "PKY6", "PKY7")]
            + ["PHY3"] + [k for k in _FY_COMB_61 if k != "RBY4"]
            + [k for k in _MZ_61 if k not in ("QDZ10", "QDZ11", "PPZ1", "PPZ2")]
            + ["QSX1", "QSX2", "QSX3"] + ["QSY1", "QSY2", "QSY3", "QSY4"]),
    "pac89": [f"A{i}" for i in range(14)] + [f"B{i}" for i in range(11)] + [f"C{i}" for i in range(18)],
}
MODEL_KEYS["6.2"] = MODEL_KEYS["6.1"]

#: Keys of the effective rolling radius (§7.3); optional: without them ``R_e`` is not available.
RADIUS_KEYS = ("Q_RE0", "Q_V1", "BREFF", "DREFF", "FREFF", "VERTICAL_STIFFNESS", "PFZ1")

#: Keys with no default: absent means "not given" (ranges: no limit; speeds/pressures: see below).
OPTIONAL_NO_DEFAULT = {k for pair in RANGE_KEYS.values() for k in pair} | {
    "LONGVL", "VXLOW", "NOMPRES", "INFLPRES"}


def family(version: str) -> str:
    """``"mf"`` for the MF 6.x / 5.2 equations, ``"pac89"`` for the simple form of §13.2."""
    return "pac89" if version == "pac89" else "mf"


def default_value(key: str) -> float:
    """tirecli's default for a missing coefficient (§12.5 item 9, §8): ``L*`` 1 (``LMUV`` 0), ``PKY4`` 2, else 0."""
    if key in TURNSLIP_DEFAULTS:
        return TURNSLIP_DEFAULTS[key]
    if key == "LMUV":
        return 0.0
    if key == "PKY4":
        return 2.0
    if key in SCALING_KEYS:
        return 1.0
    return 0.0


def complete_coefficients(values: dict, version: str, turn_slip: bool = True) -> tuple[dict, list, list]:
    """Complete a flat coefficient map for ``version``.

    Returns ``(coef, missing_required, defaulted)``: ``coef`` holds every given value plus the
    tirecli's default for every model key not given (ranges, ``LONGVL``, ``VXLOW``, ``NOMPRES`` and
    ``INFLPRES`` stay absent: "not given" is meaningful for them); ``missing_required`` lists the
    required keys absent from ``values``; ``defaulted`` lists the model keys that took a default
    (turn-slip keys excluded unless ``turn_slip``).
    """
    fam = family(version)
    coef = {k: float(v) for k, v in values.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    missing = [k for k in REQUIRED[fam] if k not in coef]
    defaulted = []
    keys = list(MODEL_KEYS[version]) + (list(TURNSLIP_DEFAULTS) if fam == "mf" and version != "5.2" else [])
    for k in keys:
        if k in coef or k in OPTIONAL_NO_DEFAULT or k in REQUIRED[fam]:
            continue
        coef[k] = default_value(k)
        quiet = k == "LMUV" or (k == "PKY4" and version == "5.2")  # fixed values (docs/models/magic_formula_tyre.md §3, §9)
        if not quiet and (turn_slip or k not in TURNSLIP_DEFAULTS):
            defaulted.append(k)
    if fam == "mf" and "INFLPRES" not in coef and "NOMPRES" in coef:
        coef["INFLPRES"] = coef["NOMPRES"]
    return coef, missing, defaulted


@dataclass(frozen=True)
class MFTire:
    """A Magic Formula tyre ready for evaluation.

    Attributes
    ----------
    coef : dict
        Complete flat coefficient map, SI units (N, m, s, Pa, rad), upper-case ``.tir`` keys
        (see :func:`complete_coefficients`).
    version : str
        ``"6.1"``, ``"6.2"`` (same steady-state equations as 6.1), ``"5.2"`` (MF 5.2 / PAC2002,
        §9) or ``"pac89"`` (§13.2).
    side : str
        Side the tyre was measured on (``TYRESIDE``): ``"left"``, ``"right"`` or ``"unknown"``.
    name : str
        Label for messages and legends.
    """

    coef: dict
    version: str = "6.1"
    side: str = "unknown"
    name: str = ""
    meta: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        if self.version not in VERSIONS:
            raise ValueError(f"unknown Magic Formula version {self.version!r} (expected one of {VERSIONS})")

    def __getitem__(self, key: str) -> float:
        return self.coef[key]

    def get(self, key: str, default=None):
        return self.coef.get(key, default)

    @property
    def family(self) -> str:
        return family(self.version)

    @property
    def is_52(self) -> bool:
        return self.version == "5.2"

    def range(self, var: str) -> tuple[float, float]:
        """Valid range ``(lo, hi)`` of input ``var`` (``fz``, ``kappa``, ``alpha``, ``gamma``, ``p``);
        ``-inf``/``inf`` where the file gives no bound (``fz`` is never below 0)."""
        lo_key, hi_key = RANGE_KEYS[var]
        lo = self.coef.get(lo_key, -math.inf)
        hi = self.coef.get(hi_key, math.inf)
        if var == "fz":
            lo = max(lo, 0.0) if lo is not None else 0.0
        return lo, hi

    @property
    def nominal_pressure(self) -> float | None:
        """``NOMPRES`` [Pa], or None for MF 5.2 / PAC89 / files without it (pressure has no effect)."""
        return self.coef.get("NOMPRES") if self.family == "mf" and not self.is_52 else None

    @property
    def default_pressure(self) -> float | None:
        """Pressure used when none is given [Pa]: ``INFLPRES`` (falling back to ``NOMPRES``)."""
        return self.coef.get("INFLPRES", self.coef.get("NOMPRES"))

    @property
    def reference_speed(self) -> float | None:
        """``LONGVL`` [m/s] (reference speed V0), or None when the file has none."""
        return self.coef.get("LONGVL")


@dataclass(frozen=True)
class Convention:
    """Switches for every point of docs/models/magic_formula_tyre.md §10 where implementations disagree.

    Attributes
    ----------
    name : str
        ``mfeval`` or ``teasit``.
    alpha_star : str
        ``"alpha"`` (alpha* = alpha), ``"tan"`` (alpha* = tan(alpha) sgn(Vcx) everywhere, book
        4.E3) or ``"mixed"`` (teasit: raw alpha in Fy0, tan(alpha) in G_xa, G_yk, D_Vyk, M_z).
    gamma_sin : bool
        gamma* = sin(gamma) (book 4.E4) instead of gamma.
    a_mu : float
        A_mu of the digressive friction scaling lambda' (book 4.E8): 1 (mfeval) or 10.
    eps : float
        Singularity guard epsilon (book 4.E6a), added with the sign of the guarded quantity.
    sgn_zero : float
        Value of sgn(0) in the curvature asymmetries and the equivalent slips: +1 or 0 (MATLAB).
    e_clip : bool
        Apply E <= 1 to E_x, E_y, E_t, E_xa, E_yk.
    ey_sign_of_alpha : bool
        E_y asymmetry uses sgn(alpha) (teasit) instead of sgn(alpha_y).
    camber_trail_book : bool
        B_t camber factor with gamma* and D_t with q_Dz3 |gamma*| (book / teasit) instead of
        q_Dz3 gamma (paper A58/A60, mfeval).
    mzr_zero_camber : bool
        S_Hf and B_r take S_Hy, S_Vy, K'_ya, B_y from F_y0 at gamma = 0 (teasit).
    eq_slip_paper : bool
        Equivalent slips arctan(sqrt(tan^2 + ...)) (paper A54/A55) instead of sqrt(alpha^2 + ...).
    fyp_gyk_zero_camber : bool
        F'_y = G_yk(gamma = 0) F_y0(gamma = 0) (teasit) instead of G_yk(gamma) F_y0(gamma = 0).
    s_mfeval : bool
        Moment arm s with F_y/F_z0 and the camber term, trail t times LFZO (mfeval); otherwise
        F_y/F'_z0 and no camber term (teasit).
    mzr_cos_combined : bool
        Multiply the combined-slip M_zr by cos(alpha') (teasit).
    mz_pure_at_kappa0 : bool
        At kappa = 0 exactly, M_z = M_z0 without s F_x (teasit).
    my_leading_fz : bool
        M_y with F_z as leading factor (teasit) instead of F_z0 (paper A48, mfeval).
    mx_book : bool
        M_x in the teasit variant of book 4.E69 (square outside the arctangent, no QSX12-14).
    backward_my : bool
        M_y zero at V_cx = 0 and flipped for V_cx < 0 (mfeval).
    """

    name: str
    alpha_star: str = "alpha"
    gamma_sin: bool = False
    a_mu: float = 1.0
    eps: float = 1e-6
    sgn_zero: float = 1.0
    e_clip: bool = True
    ey_sign_of_alpha: bool = False
    camber_trail_book: bool = False
    mzr_zero_camber: bool = False
    eq_slip_paper: bool = True
    fyp_gyk_zero_camber: bool = False
    s_mfeval: bool = True
    mzr_cos_combined: bool = False
    mz_pure_at_kappa0: bool = False
    my_leading_fz: bool = False
    mx_book: bool = False
    backward_my: bool = True

    def with_alpha_star(self) -> "Convention":
        """The same convention with the book's alpha* = tan(alpha) sgn(Vcx) and gamma* = sin(gamma)
        everywhere (mfeval's "alpha star" mode)."""
        return replace(self, alpha_star="tan", gamma_sin=True)


#: The two named conventions (§10 "Recommended here" and §15.2).
CONVENTIONS = {
    "mfeval": Convention(name="mfeval"),
    "teasit": Convention(
        name="teasit", alpha_star="mixed", gamma_sin=True, a_mu=10.0, eps=2.220446049250313e-16,
        sgn_zero=0.0, e_clip=False, ey_sign_of_alpha=True, camber_trail_book=True, mzr_zero_camber=True,
        eq_slip_paper=False, fyp_gyk_zero_camber=True, s_mfeval=False, mzr_cos_combined=True,
        mz_pure_at_kappa0=True, my_leading_fz=True, mx_book=True, backward_my=False,
    ),
}


def get_convention(conv) -> Convention:
    """A :class:`Convention` from its name (``mfeval``, ``teasit``) or itself."""
    if isinstance(conv, Convention):
        return conv
    try:
        return CONVENTIONS[conv]
    except KeyError:
        raise ValueError(f"unknown convention {conv!r} (expected one of: {', '.join(CONVENTIONS)})") from None
