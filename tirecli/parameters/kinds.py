"""The kinds of parameter sets and the schema of each parameter: unit, meaning, source equation.

This is the one place where parameter names, units and admissible ranges are defined; the
model dataclasses (e.g. :class:`tirecli.models.lugre.LuGreParams`) are built from sets
checked here, and ``tirecli params show`` prints these units.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from tirecli.config.schema import MISSING, AnyOf, Context, Grid, ListOf, Map, Nullable, Num, Raw, Spec
from tirecli.io.yamlio import KeyPath


@dataclass(frozen=True)
class Kind:
    """A kind of parameter set (``lugre``, ``quarter_car``, ...).

    Attributes
    ----------
    name : str
        Value of ``kind:`` in a parameter-set file.
    title : str
        What the set describes.
    fields : dict
        Parameter name -> :class:`~tirecli.config.schema.Num` (unit, range, doc, equation).
    post : callable or None
        Cross-field check ``post(values, path, ctx)``.
    post_partial : bool
        Run ``post`` even when other values of the set are faulty (it must then skip
        values that are ``MISSING``), so all problems of a file are reported together.
    model : str
        ``"module:Class"`` of the model's parameter object, built from the checked values
        (imported lazily).
    """

    name: str
    title: str
    fields: dict
    post: Callable | None = None
    post_partial: bool = False
    model: str = ""

    def build(self, values: dict):
        """The model's parameter object for checked ``values``."""
        import importlib

        module, _, name = self.model.partition(":")
        return getattr(importlib.import_module(module), name)(**values)

    def spec(self, partial: bool = False) -> Map:
        """Schema of the values; ``partial`` makes every key optional (overrides)."""
        fields = self.fields
        if partial:
            fields = {k: Num(**{**f.__dict__, "default": None}) for k, f in fields.items()}
        return Map(fields=fields, post=None if partial else self.post, post_partial=self.post_partial)


KINDS: dict[str, Kind] = {}


def register_kind(kind: Kind) -> Kind:
    """Add a kind of parameter set (used by model packages that bring their own sets)."""
    KINDS[kind.name] = kind
    return kind


def _lugre_post(values: dict, path, ctx: Context) -> None:
    # called even when other values are faulty (Map.post_partial): skip if either is MISSING
    if any(values.get(k, MISSING) in (MISSING, None) for k in ("mu_c", "mu_s")):
        return
    if values["mu_c"] > values["mu_s"]:
        ctx.fail(path + ("mu_c",), f"out of range: must be <= mu_s ({values['mu_s']:g}), got {values['mu_c']:g}")


LUGRE = register_kind(Kind(
    name="lugre",
    title="LuGre tire/road friction (distributed and lumped)",
    fields={
        "sigma0": Num(unit="1/m", gt=0, doc="normalised rubber longitudinal stiffness", eq="FM eqs. (1)-(2)"),
        "sigma1": Num(unit="s/m", ge=0, doc="normalised rubber longitudinal damping", eq="FM eq. (2)"),
        "sigma2": Num(unit="s/m", ge=0, doc="normalised viscous relative damping", eq="FM eq. (2)"),
        "mu_c": Num(unit="-", gt=0, doc="normalised Coulomb friction level", eq="FM after eq. (1)"),
        "mu_s": Num(unit="-", gt=0, doc="normalised static friction level (>= mu_c)", eq="FM after eq. (1)"),
        "v_s": Num(unit="m/s", gt=0, doc="Stribeck velocity", eq="FM after eq. (1)"),
        "L": Num(unit="m", gt=0, doc="contact-patch length", eq="FM eq. (1)"),
        "alpha": Num(unit="-", gt=0, doc="Stribeck exponent (shape of g)", eq="FM after eq. (1)"),
        "kappa0": Num(unit="-", gt=0, default=2.0,
                      doc="constant lumped distribution coefficient kappa*L", eq="FM eq. (8); OBS kappa = 10 1/m"),
        "sigma_w": Num(unit="kg m^2/s", ge=0, default=1.0,
                       doc="rotational viscous friction of the wheel", eq="OBS eq. (4)"),
    },
    post=_lugre_post,
    post_partial=True,
    model="tirecli.models.lugre:LuGreParams",
))


QUARTER_CAR = register_kind(Kind(
    name="quarter_car",
    title="quarter-car vehicle (one wheel, a quarter of the mass)",
    fields={
        "r": Num(unit="m", gt=0, doc="effective rolling radius", eq="OBS §II"),
        "m": Num(unit="kg", gt=0, doc="vehicle mass carried by the wheel (a quarter)", eq="OBS §II"),
        "J": Num(unit="kg m^2", gt=0, doc="wheel rotational inertia", eq="OBS §II"),
        "F_n": Num(unit="N", gt=0, doc="normal load on the wheel", eq="OBS §II"),
    },
    model="tirecli.models.vehicle:QuarterCarParams",
))


OBSERVER = register_kind(Kind(
    name="observer",
    title="gains of the nonlinear adhesion/speed observer (OBS Theorem 1, eq. (14))",
    fields={
        "k1": Num(unit="kg m^2/s", doc="output injection on eta = r m v + J omega (angular-momentum state)",
                  eq="OBS (14), K = [k1, k2, k3]"),
        "k2": Num(unit="kg m^2/s", default=0.0, doc="output injection on chi = J omega + r F_n sigma1 z",
                  eq="OBS (14); OBS takes k2 = 0"),
        "k3": Num(unit="m", doc="output injection on the bristle deflection z (< 0 for passivity)",
                  eq="OBS (14), §IV-h"),
        "gamma": Num(unit="s/m", ge=0, doc="adaptation gain of theta_hat (0 freezes theta_hat)",
                     eq="OBS (14), Theorem 1"),
        "alpha": Num(unit="m", ge=0, doc="nonlinear injection gain alpha(y) (a constant here)",
                     eq="OBS (14), (17)"),
    },
    model="tirecli.observers.lugre_observer:ObserverGains",
))


def _mf_fields() -> dict:
    """One optional number per numeric key of the ``.tir`` catalogue (units from the file's
    dimension; an absent key stays absent, the Magic Formula layer applies tirecli's defaults, docs/models/magic_formula_tyre.md §12.5 item 9)."""
    from tirecli.parameters.mf_catalogue import CATALOGUE

    positive = {"FNOMIN", "UNLOADED_RADIUS", "LONGVL", "NOMPRES", "INFLPRES"}
    return {k: Num(unit=i.unit, doc=i.meaning, eq=f"[{i.section}]", default=None, gt=0 if k in positive else None)
            for k, i in CATALOGUE.items() if not i.is_text}


MAGIC_FORMULA = register_kind(Kind(
    name="magic_formula",
    title="Magic Formula tyre (MF 6.1 / 6.2 / 5.2 / PAC89 coefficients, .tir keys, SI)",
    fields=_mf_fields(),
    model="tirecli.parameters.mf:tire_from_values",
))


MCPS = register_kind(Kind(
    name="mcps",
    title="MCPS dynamic tire model: anisotropic Dahl rubber friction over the patch, flexible belt (Sorine & Szymanski 2000)",
    fields={
        "w": Num(unit="m", gt=0, doc="contact-patch width", eq="MCPS §3.1, Fig. 2"),
        "l_ref": Num(unit="m", gt=0, doc="contact-patch length at the reference load fz_ref", eq="MCPS §3.1, Fig. 2"),
        "fz_ref": Num(unit="N", gt=0, doc="reference load of l_ref", eq="patch law l = l_ref (Fz/fz_ref)^l_exponent"),
        "l_exponent": Num(unit="-", ge=0, le=2, doc="exponent of the patch length against load",
                          eq="l = l_ref (Fz/fz_ref)^l_exponent; pressure P = Fz/(w l)"),
        "r_x": Num(unit="N/m^3", gt=0, doc="rubber stiffness per unit area along X", eq="MCPS §2.3, K = U r"),
        "r_y": Num(unit="N/m^3", gt=0, doc="rubber stiffness per unit area along Y", eq="MCPS §2.3, K = U r"),
        "mu_x": Num(unit="-", gt=0, doc="friction coefficient along X", eq="MCPS §2.3, F_k = P U mu"),
        "mu_y": Num(unit="-", gt=0, doc="friction coefficient along Y", eq="MCPS §2.3, F_k = P U mu"),
        "alpha_x": Num(unit="-", gt=1, doc="overshoot factor alpha along X (> 1; overshoot iff alpha > beta)", eq="MCPS eqs. (5)-(6)"),
        "alpha_y": Num(unit="-", gt=1, doc="overshoot factor alpha along Y (> 1)", eq="MCPS eqs. (5)-(6)"),
        "alpha_z": Num(unit="-", gt=1, doc="torsional overshoot factor alpha_z (> 1)", eq="MCPS eqs. (7)-(8)"),
        "beta_x": Num(unit="-", gt=1, doc="overshoot factor beta along X (> 1)", eq="MCPS eqs. (5)-(6)"),
        "beta_y": Num(unit="-", gt=1, doc="overshoot factor beta along Y (> 1)", eq="MCPS eqs. (5)-(6)"),
        "beta_z": Num(unit="-", gt=1, doc="torsional overshoot factor beta_z (> 1)", eq="MCPS eqs. (7)-(8)"),
        "c_Mz": Num(unit="-", ge=0, doc="weight of the lever-arm torque xi f_y in M_z", eq="MCPS eq. (10)"),
        "c_Sz": Num(unit="-", gt=0, doc="empirical factor of the torsional stiffness S_z", eq="MCPS eq. (8)"),
        "c_muz": Num(unit="-", gt=0, doc="empirical factor of the torsional sliding torque M_kz", eq="MCPS eq. (8)"),
        "m_b": Num(unit="kg", gt=0, doc="belt mass (x, y translation)", eq="MCPS eq. (17)"),
        "J_b": Num(unit="kg m^2", gt=0, doc="belt yaw inertia (twist delta)", eq="MCPS eq. (17)"),
        "k_x": Num(unit="N/m", gt=0, doc="belt-rim longitudinal stiffness", eq="MCPS eq. (17), Fig. 6"),
        "k_y": Num(unit="N/m", gt=0, doc="belt-rim lateral stiffness", eq="MCPS eq. (17), Fig. 6"),
        "k_delta": Num(unit="N m/rad", gt=0, doc="belt-rim twist stiffness", eq="MCPS eqs. (17), (20), Fig. 6"),
        "c_x": Num(unit="N s/m", ge=0, doc="belt-rim longitudinal damping", eq="MCPS eq. (17)"),
        "c_y": Num(unit="N s/m", ge=0, doc="belt-rim lateral damping", eq="MCPS eq. (17)"),
        "c_delta": Num(unit="N m s/rad", ge=0, doc="belt-rim twist damping", eq="MCPS eq. (17)"),
        "U": Num(unit="m^2", gt=0, doc="area of the single rubber slider of Fig. 3", eq="MCPS §2.3, Fig. 1"),
    },
    model="tirecli.models.mcps.params:MCPSParams",
))


def _mf_simple_fields() -> dict:
    """B, C, D, E of the Magic Formula basic curve for each channel x (Fx), y (Fy), z (Mz)."""
    out = {}
    for ch, what, bunit, dunit, dmean in (("x", "longitudinal", "-", "-", "peak over load D_x/Fz"),
                                          ("y", "lateral", "1/rad", "-", "peak over load D_y/Fz"),
                                          ("z", "aligning-torque", "1/rad", "m", "peak over load D_z/Fz")):
        out[f"B{ch}"] = Num(unit=bunit, gt=0, doc=f"{what} stiffness factor B_{ch}", eq="Magic Formula basic curve")
        # the combined-slip rule normalises each slip by its curve's peak, which needs C > 1 (x and y)
        out[f"C{ch}"] = Num(unit="-", gt=0 if ch == "z" else 1,
                            doc=f"{what} shape factor C_{ch}" + ("" if ch == "z" else " (> 1: the curve has a peak)"),
                            eq="Magic Formula basic curve")
        out[f"D{ch}"] = Num(unit=dunit, gt=0, doc=f"{what} {dmean}", eq="Magic Formula basic curve")
        out[f"E{ch}"] = Num(unit="-", le=1, doc=f"{what} curvature factor E_{ch} (<= 1)", eq="Magic Formula basic curve")
    return out


MF_SIMPLE = register_kind(Kind(
    name="mf_simple",
    title="Magic Formula basic curve with fixed B, C, D, E per channel (the MCPS comparison's simple fallback)",
    fields=_mf_simple_fields(),
    model="tirecli.models.magic_formula.simple:SimpleMF",
))


def unit_at(spec: Spec, path: KeyPath) -> str | None:
    """The unit of the number at key ``path`` under ``spec`` (``("tire", "sigma0")`` -> ``"1/m"``):
    a :class:`~tirecli.config.schema.Num`'s or ``Grid``'s, or a parameter's of a ``Raw`` group with a
    ``kind`` (its unit in :data:`KINDS`);
    None when the key is no number or its unit is not one (forms with different units)."""
    if isinstance(spec, (Num, Grid)):
        return spec.unit if all(isinstance(p, int) for p in path) and len(path) <= isinstance(spec, Grid) else None
    if isinstance(spec, Nullable):
        return unit_at(spec.spec, path)
    if isinstance(spec, ListOf):
        return unit_at(spec.item, path[1:] if path and isinstance(path[0], int) else path)
    if isinstance(spec, AnyOf):
        units = {unit_at(o, path) for o in spec.options} - {None}
        return units.pop() if len(units) == 1 else None
    if isinstance(spec, Map) and path:
        sub = spec.fields.get(path[0], spec.open_keys)
        return None if sub is None else unit_at(sub, path[1:])
    if isinstance(spec, Raw) and spec.kind and len(path) == 1:
        field_spec = KINDS[spec.kind].fields.get(path[0]) if spec.kind in KINDS else None
        return None if field_spec is None else field_spec.unit
    return None
