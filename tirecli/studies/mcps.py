"""MCPS studies (Sorine & Szymanski 2000): the multi-DOF dynamic tire model against the Magic Formula.

``tirecli compare CONFIG`` runs ``study: mcps-stationary`` (MCPS Figs. 7-11); ``tirecli simulate
CONFIG`` runs the time-domain studies ``mcps-slider`` (Fig. 3), ``mcps-standstill`` (Figs. 4-5) and
``mcps-relaxation`` (force build-up after a slip-angle step). Models: :mod:`tirecli.models.mcps`;
solvers: :mod:`tirecli.numerics.mcps_stationary`, :mod:`tirecli.numerics.mcps_transient`,
:mod:`tirecli.numerics.mcps_calibrate`. Axes ISO-W, road on tire, SI (rad, not degrees, in configs
and CSVs; figures draw degrees). Users' guide: ``docs/models/mcps_tire.md``.

``mcps-stationary``::

    study: mcps-stationary
    tire: sorine2000-mcps             # MCPS set (default), a set file, or {set: ..., r_x: 6e7}
    mf: externdata-205-60r15          # built-in MF tyre (default), a .tir path, simple, none,
                                      # or {tire: ..., convention: mfeval}
    carcass: complete                 # complete (default), rigid, or a list of both
    fz: 4000                          # [N] a number or a list
    kappa: {start: 0, stop: 0.12, num: 49}        # [-] pure longitudinal slip (alpha = 0)
    alpha: {start: 0, stop: 0.2094, num: 49}      # [rad] pure side slip (kappa = 0)
    combined: {alpha: [0.0175, 0.0349], kappa: {start: -0.1, stop: 0.1, num: 81}}   # every pair
    curvature: {start: 0, stop: 0.1, num: 21}     # [1/m] path curvature at kappa = alpha = 0
    calibrate: false                  # true: fit the rubber parameters to the MF curves first

Output ``data/stationary.csv``: ``model`` (mcps, mf), ``carcass``, ``calibrated``, ``family``
(kappa, alpha, combined, curvature), ``fz, kappa, alpha, phi, fx, fy, mz`` and the belt
deflections ``x, y, delta`` of the MCPS rows (empty for the Magic Formula).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import AnyOf, Bool, Grid, ListOf, Map, Nullable, Num, Raw, Str, collect
from tirecli.errors import ConfigError, RunError, token
from tirecli.limits import MAX_TITLE_CHARS, Estimate, cap_hint, compute_cap
from tirecli.studies.base import StudyResult, common_fields, register_study

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

DEFAULT_TIRE = "sorine2000-mcps"
#: Default Magic Formula side: the ExternData sample tyre (MF 6.1, 205/60R15, 4000 N), a stand-in.
DEFAULT_MF = "externdata-205-60r15"
SIMPLE_MF = "mcps-simple-mf"
CARCASSES = ("complete", "rigid")
FAMILIES = ("kappa", "alpha", "combined", "curvature")
DEG = math.pi / 180.0
#: Largest number of stationary points (slips x loads x carcasses) one run may ask for.
MAX_STATIONARY_POINTS = 200_000
#: Largest number of curvature points (each integrates the patch along its length) of one run.
MAX_CURVATURE_POINTS = 5_000
#: Largest element-steps (cells x transport steps) of one relaxation case.
MAX_ELEMENT_STEPS = 2.0e8
#: Largest exact steps of one slider or standstill run, and slider-steps of a standstill run.
MAX_STEPS = 200_000
MAX_SLIDER_STEPS = 5.0e7
#: Largest number of rows of data/patch.csv.
MAX_PATCH_ROWS = 2_000_000
#: Memory per row of the MCPS studies' frames (and CSV text) [bytes] (the sample budget, tirecli.limits).
BYTES_PER_ROW = 1000


def _lin(start, stop, num):
    return [float(x) for x in np.linspace(start, stop, num)]


def tire_set(config: Config):
    """The MCPS parameter set of a config's ``tire:`` (default ``sorine2000-mcps``); a mapping without
    ``set`` overrides the default set (so ``--set tire.r_x=6e7`` works on a config without ``tire:``)."""
    from tirecli.parameters.sets import resolve_group

    raw = config.data.get("tire")
    if isinstance(raw, dict) and "set" not in raw:
        raw = {"set": DEFAULT_TIRE, **raw}
    return resolve_group(raw, config.origins, ("tire",), "mcps", config.base_dir, DEFAULT_TIRE)


def reference_tire(ps) -> bool:
    """Whether the set is the unmodified default (the reference values of docs/models/mcps_tire.md apply)."""
    return ps.name == DEFAULT_TIRE and not ps.overridden


# --------------------------------------------------------------------------- the Magic Formula side


@dataclass
class MFSide:
    """The Magic Formula tyre beside MCPS (or none).

    Attributes
    ----------
    kind : str
        ``tir`` (a real tyre through the project's evaluator), ``simple`` (fixed-coefficient basic
        curve, docs/models/mcps_tire.md §8) or ``none``.
    name : str
        Set name (``externdata-205-60r15``, a file stem, ``mcps-simple-mf``).
    ps : ParameterSet or None
    model : MFTire or SimpleMF or None
    convention : str
        ``mfeval`` or ``teasit`` (real tyres).
    """

    kind: str
    name: str = ""
    ps: Any = None
    model: Any = None
    convention: str = "mfeval"
    outside: dict = None

    def __post_init__(self):
        self.outside = {} if self.outside is None else self.outside

    @property
    def label(self) -> str:
        if self.kind == "none":
            return "no Magic Formula"
        if self.kind == "simple":
            return "Magic Formula, simple form (assumed B, C, D, E)"
        stand_in = " (stand-in)" if self.name == DEFAULT_MF else ""
        return f"Magic Formula {self.name}{stand_in}"

    def evaluate(self, kappa, alpha, fz):
        """``Fx, Fy, Mz`` [N, N, N m] at broadcast ``kappa`` [-], ``alpha`` [rad], ``fz`` [N]
        (ISO-W, road on tire; combined slip; steady state, zero camber, input limits off)."""
        if self.kind == "simple":
            return self.model.evaluate(kappa, alpha, fz)
        from tirecli.models.magic_formula import evaluate

        t = self.model
        vx = t.reference_speed if t.family == "mf" and t.reference_speed else 16.7
        r = evaluate(t, kappa, alpha, 0.0, fz, vx, convention=self.convention, limits=False, low_speed=False,
                     outputs=("fx", "fy", "mz"), combined=True)
        for k, n in r.outside.items():  # extrapolated beyond the file's ranges: flagged in run.json
            self.outside[k] = self.outside.get(k, 0) + n
        return r.fx, r.fy, r.mz

    def record(self) -> dict:
        return {"kind": self.kind, "name": self.name, "label": self.label,
                "convention": self.convention if self.kind == "tir" else None,
                "settings": "steady state, camber 0, input limits and low-speed rules off, speed LONGVL, "
                            "pressure INFLPRES (else NOMPRES); Mz by the combined-slip formula"
                if self.kind == "tir" else None}


_MF_MAP = Map(fields={
    "tire": Raw(default=None, doc="a built-in Magic Formula tyre, a .tir path, simple, or {set: ..., overrides}"),
    "convention": Str(choices=("mfeval", "teasit"), default="mfeval", doc="Magic Formula variant: mfeval (default) or teasit"),
})


def mf_side(config: Config) -> MFSide:
    """Resolve the config's ``mf:`` (default :data:`DEFAULT_MF`)."""
    from tirecli.config.schema import check_document
    from tirecli.parameters.sets import resolve_group, resolve_tire

    raw = config.data.get("mf", DEFAULT_MF)
    path = ("mf",)
    convention = None
    if isinstance(raw, dict) and "tire" in raw:
        checked = check_document(raw, _MF_MAP, config.origins, path)
        convention = raw.get("convention")
        raw, path = checked["tire"], path + ("tire",)
    if raw is None or raw == "none":
        side = MFSide("none")
    else:
        ref = raw if isinstance(raw, str) else (raw.get("set") if isinstance(raw, dict) else None)
        try:
            if ref in ("simple", SIMPLE_MF):
                raw = SIMPLE_MF if isinstance(raw, str) else {**raw, "set": SIMPLE_MF}
                ps = resolve_group(raw, config.origins, path, "mf_simple", config.base_dir)
                side = MFSide("simple", ps.name, ps, ps.model())
            elif not isinstance(raw, (str, dict)):
                raise ConfigError(config.origins.problem(path, "expected a Magic Formula tyre (a built-in name or a "
                                                               ".tir path), simple, none, or {tire: ..., convention: ...}"))
            else:
                ps, t = resolve_tire(raw, config.origins, path, config.base_dir)
                side = MFSide("tir", ps.name, ps, t, convention or "mfeval")
        except ConfigError as err:  # a file's own problem (not found, unreadable) names the key that led to it
            raise ConfigError([pr if pr.key else config.origins.problem(path, f"{pr.file}: {pr.message}")
                               for pr in err.problems]) from None
    if convention is not None and side.kind != "tir":
        raise ConfigError(config.origins.problem(("mf", "convention"), f"applies to a .tir tyre, not to "
                                                                       f"{'the simple form' if side.kind == 'simple' else 'none'}"))
    return side


# --------------------------------------------------------------------------- mcps-stationary


CALIBRATE = AnyOf(options=(
    Bool(),
    Map(fields={
        "points": Num(unit="-", integer=True, ge=5, le=400, default=40, doc="points of each fit (even grid)"),
        "kappa_max": Num(unit="-", gt=0, le=1, default=0.12, doc="largest slip of the Fx fit"),
        "alpha_max": Num(unit="rad", gt=0, le=0.7, default=12 * DEG, doc="largest slip angle of the Fy and Mz fits"),
        "load": Num(unit="N", gt=0, default=None, doc="load of the fit (default: the first fz)"),
        "rounds": Num(unit="-", integer=True, ge=1, le=10, default=1,
                      doc="alternations of the Fy and Mz fits (c_Mz changes the twist and so Fy); 1: one pass"),
    }),
), default=False, what="true, false or {points, kappa_max, alpha_max, load, rounds}")

STATIONARY = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set: a name, a file, or {set: ..., overrides} (default sorine2000-mcps)"),
    "mf": Raw(default=None, doc="Magic Formula side: a built-in tyre, a .tir path, simple, none, or {tire, convention}"),
    "carcass": AnyOf(options=(Str(choices=CARCASSES), ListOf(item=Str(choices=CARCASSES), max_len=2)),
                     default="complete", what="complete, rigid, or a list of them"),
    "fz": Grid(unit="N", gt=0, default=[4000.0], doc="vertical load(s)"),
    "kappa": Grid(unit="-", gt=-1.0, le=10.0, default=None, doc="longitudinal slip of the pure-slip family (alpha = 0)"),
    "alpha": Grid(unit="rad", ge=-1.5, le=1.5, default=None, doc="slip angle of the side-slip family (kappa = 0)"),
    "combined": Map(fields={
        "alpha": Grid(unit="rad", ge=-1.5, le=1.5, doc="slip angles of the combined family"),
        "kappa": Grid(unit="-", gt=-1.0, le=10.0, doc="slips of the combined family"),
    }, default=None),
    "curvature": Grid(unit="1/m", ge=-20.0, le=20.0, default=None, doc="path curvature at kappa = alpha = 0"),
    "calibrate": CALIBRATE,
    "frame_term": Bool(default=False, doc="frame-rotation term in the stationary patch (acts only with a curvature)"),
})


def _points(checked) -> list:
    """``(family, kappa, alpha, phi)`` arrays of every family the config asks for (Figs. 7-9 grids when none)."""
    fams = []
    if not any(checked[k] is not None for k in FAMILIES):
        checked["kappa"] = _lin(0.0, 0.12, 49)
        checked["alpha"] = _lin(0.0, 12 * DEG, 49)
    if checked["kappa"] is not None:
        k = np.asarray(checked["kappa"], dtype=float)
        fams.append(("kappa", k, np.zeros_like(k), np.zeros_like(k)))
    if checked["alpha"] is not None:
        a = np.asarray(checked["alpha"], dtype=float)
        fams.append(("alpha", np.zeros_like(a), a, np.zeros_like(a)))
    if checked["combined"] is not None:
        A, K = np.meshgrid(np.asarray(checked["combined"]["alpha"], dtype=float),
                           np.asarray(checked["combined"]["kappa"], dtype=float), indexing="ij")
        fams.append(("combined", K.ravel(), A.ravel(), np.zeros(K.size)))
    if checked["curvature"] is not None:
        c = np.asarray(checked["curvature"], dtype=float)
        fams.append(("curvature", np.zeros_like(c), np.zeros_like(c), c))
    return fams


def plan_stationary(config: Config):
    """Check an ``mcps-stationary`` config completely: ``(checked, tire set, params, MF side, families)``."""
    checked, tire, mf = collect(lambda: config.checked(STATIONARY), lambda: tire_set(config), lambda: mf_side(config))
    carc = checked["carcass"]
    checked["carcass"] = [carc] if isinstance(carc, str) else list(dict.fromkeys(carc))
    fams = _points(checked)
    n = sum(f[1].size for f in fams) * len(checked["fz"]) * len(checked["carcass"])
    cap = compute_cap(MAX_STATIONARY_POINTS)
    if n > cap:
        raise ConfigError(config.origins.problem((), f"{n} stationary points (slips x loads x carcasses) exceed the "
                                                     f"budget of {cap:.0f}: use coarser grids " + cap_hint()))
    Estimate().add(n, tuple(("combined", k) for k in ("alpha", "kappa")) + tuple((k,) for k in FAMILIES) + (("fz",),),
                   f"the stationary points ({n:,}: slips x {len(checked['fz'])} load(s) x "
                   f"{len(checked['carcass'])} carcass(es))", BYTES_PER_ROW).check(config.origins)
    nc = sum(f[1].size for f in fams if f[0] == "curvature") * len(checked["fz"]) * len(checked["carcass"])
    cap = compute_cap(MAX_CURVATURE_POINTS)
    if nc > cap:
        raise ConfigError(config.origins.problem(("curvature",), f"{nc} curvature points (x loads x carcasses) exceed "
                                                                 f"the budget of {cap:.0f} (each integrates "
                                                                 "the patch along its length): use a coarser grid " + cap_hint()))
    cal = checked["calibrate"]
    if cal is True:
        cal = {"points": 40, "kappa_max": 0.12, "alpha_max": 12 * DEG, "load": None, "rounds": 1}
    checked["calibrate"] = cal or None
    if checked["calibrate"] and mf.kind == "none":
        raise ConfigError(config.origins.problem(("calibrate",), "calibration fits MCPS to the Magic Formula curves: "
                                                                 "give an 'mf:' tyre (not none)"))
    return checked, tire, tire.model(), mf, fams


def _solve_all(p, fz, fams, carcass, frame_term, what: str):
    """Stationary MCPS solutions of every family at one load; RunError when a fixed point fails."""
    from tirecli.numerics.mcps_stationary import solve

    k = np.concatenate([f[1] for f in fams])
    a = np.concatenate([f[2] for f in fams])
    c = np.concatenate([f[3] for f in fams])
    st = solve(p, fz, k, a, c, carcass=carcass, frame_term=frame_term)
    bad = np.flatnonzero(~st.converged | ~np.isfinite(st.fx) | ~np.isfinite(st.fy) | ~np.isfinite(st.mz))
    if bad.size:
        i = bad[0]
        raise RunError(f"{what}: the belt fixed point (MCPS eq. 18) did not converge at fz = {fz:g} N, kappa = "
                       f"{k[i]:g}, alpha = {a[i]:g} rad, curvature = {c[i]:g} 1/m (max |G| = {st.residual[i]:.3g}; "
                       f"{bad.size} point(s)); check the belt stiffnesses k_x, k_y, k_delta of 'tire:'; nothing was written")
    return st


def _rows(model, carcass, calibrated, fams, fz, fx, fy, mz, x=None, y=None, d=None) -> pd.DataFrame:
    import pandas as pd

    n = sum(f[1].size for f in fams)
    nan = np.full(n, np.nan)
    return pd.DataFrame({
        "model": model, "carcass": carcass, "calibrated": calibrated,
        "family": np.concatenate([[f[0]] * f[1].size for f in fams]) if n else np.array([], dtype=object),
        "fz": np.full(n, float(fz)),
        "kappa": np.concatenate([f[1] for f in fams]), "alpha": np.concatenate([f[2] for f in fams]),
        "phi": np.concatenate([f[3] for f in fams]),
        "fx": np.asarray(fx, dtype=float), "fy": np.asarray(fy, dtype=float), "mz": np.asarray(mz, dtype=float),
        "x": nan if x is None else x, "y": nan if y is None else y, "delta": nan if d is None else d,
    })


def calibrated_set(ps, p_cal, report: dict, mf: MFSide, fz: float):
    """The calibrated parameters as a :class:`ParameterSet` and its YAML document (``calibrated.yaml``)."""
    from tirecli.parameters.sets import ParameterSet

    fitted = {k: v for g in report.values() for k, v in g["parameters"].items()}
    values = {k: float(getattr(p_cal, k)) for k in ps.values}
    doc_values = {}
    for k, v in values.items():
        if k in fitted:
            doc_values[k] = {"value": v, "note": f"calibrated to {mf.name} at {fz:g} N by tirecli compare"}
        elif k in ps.assumed:
            doc_values[k] = {"value": v, "assumed": ps.assumed[k]}
        else:
            doc_values[k] = v
    name = f"{ps.name}-calibrated"
    doc = {"name": name, "kind": "mcps",
           "title": f"{ps.title} -- rubber parameters calibrated to {mf.label} at {fz:g} N",
           "citation": f"{ps.citation} Calibrated by tirecli compare (least squares, docs/models/mcps_tire.md §8).",
           "values": doc_values}
    out = ParameterSet(name=name, kind="mcps", values=values,
                       source={k: ("tirecli compare (calibrated)" if k in fitted else ps.source.get(k, "")) for k in values},
                       assumed={k: v for k, v in ps.assumed.items() if k not in fitted},
                       notes={k: f"calibrated to {mf.name} at {fz:g} N" for k in fitted},
                       title=doc["title"], citation=doc["citation"])
    return out, doc


@register_study("mcps-stationary", check=plan_stationary, spec=STATIONARY)
def run_stationary(config: Config, progress=None) -> StudyResult:
    """Stationary MCPS (complete and/or solid carcass) against a Magic Formula tyre (MCPS Figs. 7-11)."""
    from tirecli.io.yamlio import dump_yaml
    from tirecli.numerics.mcps_calibrate import calibrate

    checked, ps, p, mf, fams = plan_stationary(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    loads = [float(f) for f in checked["fz"]]
    carcasses = checked["carcass"]
    frame = checked["frame_term"]
    cal = checked["calibrate"]
    total = len(loads) * (len(carcasses) + (1 if mf.kind != "none" else 0)) + (2 if cal else 0)
    if progress is not None:
        progress.start(total, "stationary")
    frames, sets, files, facts = [], {"tire": ps}, {}, {}
    calibration = None
    p_cal = None
    if cal:
        fzc = float(cal["load"] or loads[0])
        npt = int(cal["points"])
        grid = {"kappa": np.linspace(0.0, cal["kappa_max"], npt + 1)[1:], "alpha": np.linspace(0.0, cal["alpha_max"], npt + 1)[1:]}
        targets = {"fx": lambda k: mf.evaluate(k, 0.0, fzc)[0], "fy": lambda a: mf.evaluate(0.0, a, fzc)[1],
                   "mz": lambda a: mf.evaluate(0.0, a, fzc)[2]}
        p_cal, report = calibrate(p, fzc, targets, grid, carcass=carcasses[0], rounds=int(cal["rounds"]))
        failed = [(g, r["failure"]) for g, r in report.items() if r.get("failure")]
        if failed:  # never a calibrated.yaml holding start values or a fit that did not converge
            g, why = failed[0]
            raise RunError(f"calibration of {g} to {mf.name} at {fzc:g} N did not converge: {why}; nothing was "
                           "written (no calibrated.yaml)")
        calibration = {"load": fzc, "carcass": carcasses[0], "grid": {"kappa": [float(grid["kappa"][0]), float(cal["kappa_max"]), npt],
                                                                       "alpha": [float(grid["alpha"][0]), float(cal["alpha_max"]), npt]},
                       "groups": report, "target": mf.label}
        cps, doc = calibrated_set(ps, p_cal, report, mf, fzc)
        sets["calibrated"] = cps
        files["calibrated.yaml"] = dump_yaml(doc)
        if progress is not None:
            progress.advance(2)
    for fz in loads:
        for carcass in carcasses:
            st = _solve_all(p, fz, fams, carcass, frame, f"tire {ps.label}")
            frames.append(_rows("mcps", carcass, False, fams, fz, st.fx, st.fy, st.mz, st.x, st.y, st.delta))
            if progress is not None:
                progress.advance(1)
        if p_cal is not None:
            st = _solve_all(p_cal, fz, fams, carcasses[0], frame, "calibrated tire")
            frames.append(_rows("mcps", carcasses[0], True, fams, fz, st.fx, st.fy, st.mz, st.x, st.y, st.delta))
        if mf.kind != "none":
            k = np.concatenate([f[1] for f in fams])
            a = np.concatenate([f[2] for f in fams])
            fx, fy, mz = mf.evaluate(k, a, fz)
            frames.append(_rows("mf", "", False, fams, fz, fx, fy, mz))
            if progress is not None:
                progress.advance(1)
        facts[f"{fz:g} N"] = {k: float(v) for k, v in p.stiffnesses(fz).items()}
    if progress is not None:
        progress.close()
    df = pd.concat(frames, ignore_index=True)
    bad = ~np.isfinite(df[["fx", "fy", "mz"]].to_numpy()).all(axis=1)
    if bad.any():
        row = df[bad].iloc[0]
        text = (f"non-finite forces for {row['model']} at fz = {row['fz']:g} N, kappa = {row['kappa']:g}, "
                f"alpha = {row['alpha']:g} rad")
        if row["model"] == "mf" and mf.kind == "tir":  # a load the tyre cannot evaluate is the config's fault
            t = mf.model
            hi, fnom = t.coef.get("FZMAX"), t.coef.get("FNOMIN")
            if (hi is not None and row["fz"] > hi) or (fnom and row["fz"] > 10 * fnom):
                limit = f"above FZMAX = {hi:g} N" if hi is not None and row["fz"] > hi else \
                    f"{row['fz'] / fnom:.3g} x FNOMIN ({fnom:g} N)"
                raise ConfigError(config.origins.problem(("fz",), f"{text}: the load is {limit} of {mf.name}, beyond "
                                                                  "what the tyre can evaluate; nothing was written"))
        raise RunError(f"{text}; nothing was written")
    fam_names = [f[0] for f in fams]
    default_figs = []
    if "kappa" in fam_names:
        default_figs.append("mcps-fig7")
    if "alpha" in fam_names:
        default_figs += ["mcps-fig8", "mcps-fig9"]
    if "combined" in fam_names:
        default_figs.append("mcps-fig10")
    if "curvature" in fam_names:
        default_figs.append("mcps-fig11")
    if cal:
        default_figs.append("mcps-calibration")
    if mf.ps is not None:
        sets["mf"] = mf.ps
    from tirecli.models.magic_formula.inputs import describe_outside

    flags = [f"{mf.name}: {line}" for line in describe_outside(mf.outside)]
    lines = [f"stiffnesses at {fz}: D_xsigma {v['D_xsigma']:.6g} N, D_yalpha {v['D_yalpha']:.6g} N/rad "
             f"(complete model {v['D_yalphaF']:.6g}), D_zalpha {v['D_zalpha']:.6g} N m/rad (complete {v['D_zalphaF']:.6g})"
             for fz, v in facts.items()]
    if calibration:
        for g, r in calibration["groups"].items():
            bounds = [n for n, b in r["at_bound"].items() if b]
            vals = ", ".join(f"{n} = {v:.4g}" for n, v in r["parameters"].items())
            stage = "" if abs(r["max_gap_stage"] - r["max_gap"]) < 1e-6 * max(1.0, r["max_gap"]) else \
                f", {r['max_gap_stage']:.4g} right after its own fit"
            lines.append(f"calibration of {g} to {mf.name} at {calibration['load']:g} N: {vals}; max gap of the final set "
                         f"{r['max_gap']:.4g} {r['unit']} (before {r['max_gap_before']:.4g}{stage}), rms {r['rms_gap']:.4g}"
                         + (f"; at a bound: {', '.join(bounds)}" if bounds else ""))
    return StudyResult(
        study="mcps-stationary", config=config, parameter_sets=sets, data={"stationary": df},
        meta={
            "title": checked["title"] or "MCPS stationary characteristics against the Magic Formula",
            "model": "MCPS (Sorine & Szymanski 2000): stationary patch (eq. 14), complete model by the belt "
                     "fixed point (eq. 18), solid carcass by eq. (14) alone",
            "axes": "ISO-W, road on tire, SI: kappa = (r omega - Vx)/|Vx| (> 0 driving), tan(alpha) = Vy/|Vx| "
                    "(alpha > 0 gives Fy < 0, Mz > 0), phi = yaw rate/Vx [1/m]",
            "carcass": carcasses, "families": fam_names, "loads": loads, "frame_term": frame,
            "mf": mf.record(), "stiffnesses": facts, "calibration": calibration,
            "points": int(len(df)), "summary": lines, "mf_outside_ranges": dict(mf.outside), "flags": flags,
        },
        figures=checked["figures"] or default_figs,
        payload={"params": p, "params_calibrated": p_cal, "mf": mf, "checked": checked},
        files=files,
    )


# --------------------------------------------------------------------------- mcps-slider (Fig. 3)

SLIDER = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set (the slider uses U, r, mu, alpha, beta, c_Sz, c_muz)"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="load whose patch pressure P = fz/(w l) acts on the slider"),
    "amplitude": Num(unit="m", gt=0, default=None, doc="amplitude of u_x (default 8 F_k/K)"),
    "rotation": Num(unit="rad", gt=0, default=None, doc="amplitude of psi (default 8 M_kz/S_z)"),
    "period": Num(unit="s", gt=0, le=1e6, default=2.0, doc="period T of the sinusoidal motion"),
    "periods": Num(unit="-", integer=True, ge=1, le=50, default=2, doc="number of periods"),
    "compare_period": Nullable(spec=Num(unit="s", gt=0, le=1e6), default=0.5,
                               doc="period of a second run, integrated in time, showing rate independence (null: none)"),
    "samples": Num(unit="-", integer=True, ge=16, le=100_000, default=400, doc="samples per period (rounded to a multiple of 4)"),
    "frame_term": Bool(default=False, doc="rotate the force states with the slider (docs/models/mcps_tire.md §4: off for Fig. 3)"),
})


def plan_slider(config: Config):
    checked, ps = collect(lambda: config.checked(SLIDER), lambda: tire_set(config))
    steps = int(checked["periods"]) * int(checked["samples"])
    cap = compute_cap(MAX_STEPS)
    if steps > cap:
        raise ConfigError(config.origins.problem(("samples",), f"{steps} steps (periods x samples) exceed the budget "
                                                               f"of {cap:.0f}: fewer samples per period " + cap_hint()))
    runs_ = 2 if checked["compare_period"] else 1
    Estimate().add(runs_ * (steps + 1), (("samples",), ("periods",)),
                   f"data/slider.csv ({runs_} run(s) x {steps:,} steps)", BYTES_PER_ROW).check(config.origins)
    return checked, ps, ps.model()


def _refine_peak(x, y, i):
    """Parabolic refinement of a sampled extremum at index ``i``: ``(x*, y*)``."""
    if i <= 0 or i >= len(y) - 1:
        return float(x[i]), float(y[i])
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = y0 - 2 * y1 + y2
    if den == 0:
        return float(x[i]), float(y1)
    d = 0.5 * (y0 - y2) / den
    if abs(d) > 1:
        return float(x[i]), float(y1)
    return float(x[i] + d * (x[i + 1] - x[i - 1]) / 2.0), float(y1 - 0.25 * (y0 - y2) * d)


@register_study("mcps-slider", check=plan_slider, spec=SLIDER)
def run_slider(config: Config, progress=None) -> StudyResult:
    """One rubber slider under sinusoidal translation and rotation (MCPS Fig. 3; docs/models/mcps_tire.md §4)."""
    from tirecli.numerics.mcps_transient import integrate_slider_in_time, simulate_slider

    checked, ps, p = plan_slider(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    P = p.patch(checked["fz"]).P
    law = p.slider_law(P)
    K, Fk = float(law.K[0]), float(law.Fk[0])
    A = checked["amplitude"] or 8.0 * Fk / K
    Psi = checked["rotation"] or 8.0 * law.Mkz / law.Sz
    nper = int(checked["periods"])
    spp = 4 * max(4, int(round(checked["samples"] / 4)))
    periods = [checked["period"]] + ([checked["compare_period"]] if checked["compare_period"] else [])
    if progress is not None:
        progress.start(len(periods), "slider")
    frames = []
    runs = {}
    phase = np.linspace(0.0, nper, nper * spp + 1)   # every run on the same phase grid
    ux = A * np.sin(2 * np.pi * phase)
    psi = Psi * np.sin(2 * np.pi * phase)
    for k, T in enumerate(periods):
        t = phase * T
        if k == 0:   # exact increments (MCPS eq. 9 between samples)
            f, m = simulate_slider(law, ux, np.zeros_like(ux), psi, checked["frame_term"])
        else:        # integrated in time (DOP853): checks the exact steps and the rate independence
            f, m = integrate_slider_in_time(law, A, Psi, T, phase, checked["frame_term"])
        runs[T] = (phase, t, ux, psi, f, m)
        frames.append(pd.DataFrame({"period": T, "method": "exact increments" if k == 0 else "time integration (DOP853)",
                                    "t": t, "ux": ux, "psi": psi, "fx": f[:, 0], "fy": f[:, 1], "m": m}))
        if progress is not None:
            progress.advance(1)
    if progress is not None:
        progress.close()
    phase, t, ux, psi, f, m = runs[periods[0]]
    q = phase <= 0.25 + 1e-12
    i = int(np.argmax(f[q, 0]))
    u_pk, f_pk = _refine_peak(ux[q], f[q, 0], i)
    j = int(np.argmax(m[q]))
    p_pk, m_pk = _refine_peak(psi[q], m[q], j)
    sec = phase >= nper - 1 - 1e-12
    facts = {
        "pressure_Pa": P, "K_N_per_m": K, "Fk_N": Fk, "Sz_Nm_per_rad": law.Sz, "Mkz_Nm": law.Mkz,
        "amplitude_m": A, "rotation_rad": Psi,
        "first_peak_force_N": f_pk, "first_peak_path_m": u_pk,
        "first_peak_torque_Nm": m_pk, "first_peak_angle_rad": p_pk,
        "last_period_max_force_N": float(f[sec, 0].max()), "last_period_min_force_N": float(f[sec, 0].min()),
        "reversal_limit_force_N": float((2 * _g_max(p.alpha_x, p.beta_x) - 1) * Fk),
    }
    if len(periods) > 1:
        other = runs[periods[1]]
        facts["rate_independence_max_diff_N"] = float(np.max(np.abs(other[4] - f)))
        facts["rate_independence_max_diff_Nm"] = float(np.max(np.abs(other[5] - m)))
    lines = [f"slider: K = {K:.5g} N/m, F_k = {Fk:.5g} N, S_z = {law.Sz:.4g} N m/rad, M_kz = {law.Mkz:.4g} N m",
             f"first loading: force peak {f_pk:.5g} N at u = {1e3 * u_pk:.4g} mm; torque peak {m_pk:.4g} N m at "
             f"{p_pk:.4g} rad; last period force in [{facts['last_period_min_force_N']:.4g}, "
             f"{facts['last_period_max_force_N']:.4g}] N"]
    if len(periods) > 1:
        lines.append(f"rate independence: T = {periods[0]:g} s (exact increments) and {periods[1]:g} s (integrated in "
                     f"time) differ by at most {facts['rate_independence_max_diff_N']:.2g} N")
    return StudyResult(
        study="mcps-slider", config=config, parameter_sets={"tire": ps}, data={"slider": pd.concat(frames, ignore_index=True)},
        meta={"title": checked["title"] or "MCPS rubber slider: friction force and torque loops",
              "scenario": {"ux": f"{A:.6g} sin(2 pi t/T) m", "psi": f"{Psi:.6g} sin(2 pi t/T) rad",
                           "periods_s": periods, "cycles": nper, "frame_term": checked["frame_term"],
                           "pressure_Pa": P},
              "signs": "fx, m: the friction force and torque the slider transmits to the road (MCPS eq. 9); "
                       "the road's reaction on the slider is the opposite",
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-fig3"],
        payload={"params": p, "law": law, "periods": periods},
    )


def _g_max(alpha, beta):
    from tirecli.models.mcps.law import overshoot_peak

    return overshoot_peak(alpha, beta)[1]


# --------------------------------------------------------------------------- mcps-standstill (Figs. 4-5)

STANDSTILL = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="vertical load"),
    "amplitude": Num(unit="rad", gt=0, le=6.3, default=0.45, doc="yaw amplitude A of the cycle 0 -> A -> -A -> A"),
    "yaw_rate": Num(unit="rad/s", gt=0, le=1e4, default=1.0, doc="|yaw rate| (the response does not depend on it)"),
    "cycles": Num(unit="-", integer=True, ge=1, le=20, default=2, doc="full yaw cycles after the first quarter"),
    "frame_term": Bool(default=True, doc="rotate the slider states with the wheel (docs/models/mcps_tire.md §4: on)"),
    "nodes": Num(unit="-", integer=True, ge=2, le=200, default=24, doc="Gauss nodes per half patch (resultants)"),
    "grid": Num(unit="-", integer=True, ge=3, le=1001, default=81, doc="points of the lateral force distribution (data/patch.csv)"),
    "samples": Num(unit="-", integer=True, ge=20, le=20_000, default=400, doc="samples per yaw leg of 2 A"),
    "patch_samples": Num(unit="-", integer=True, ge=4, le=2000, default=40, doc="times per leg of 2 A in data/patch.csv"),
})


def plan_standstill(config: Config):
    checked, ps = collect(lambda: config.checked(STANDSTILL), lambda: tire_set(config))
    legs = 0.5 + 2 * int(checked["cycles"])
    steps = legs * int(checked["samples"])
    sliders = 2 * int(checked["nodes"]) + int(checked["grid"])
    rows = legs * int(checked["patch_samples"]) * int(checked["grid"])
    cap, slider_cap = compute_cap(MAX_STEPS), compute_cap(MAX_SLIDER_STEPS)
    if steps > cap or steps * sliders > slider_cap:
        raise ConfigError(config.origins.problem(("samples",), f"{steps:.0f} steps of {sliders} sliders exceed the budget "
                                                               f"({cap:.0f} steps, {slider_cap:.0e} slider-steps): "
                                                               "fewer samples, cycles, nodes or grid points " + cap_hint()))
    row_cap = compute_cap(MAX_PATCH_ROWS)
    if rows > row_cap:
        raise ConfigError(config.origins.problem(("patch_samples",), f"data/patch.csv would hold {rows:.0f} rows (budget "
                                                                     f"{row_cap:.0f}): fewer patch_samples or grid points " + cap_hint()))
    (Estimate().add(steps, (("samples",), ("cycles",)), f"data/standstill.csv ({steps:,.0f} steps)", BYTES_PER_ROW)
     .add(rows, (("patch_samples",), ("grid",), ("cycles",)), f"data/patch.csv ({rows:,.0f} rows)", BYTES_PER_ROW)
     .check(config.origins))
    return checked, ps, ps.model()


@register_study("mcps-standstill", check=plan_standstill, spec=STANDSTILL)
def run_standstill(config: Config, progress=None) -> StudyResult:
    """Blocked wheel yawing back and forth at standstill (MCPS §3.1, Figs. 4-5)."""
    from tirecli.numerics.mcps_transient import (asymptotic_standstill_torque, gauss_patch, simulate_standstill,
                                                 triangle_yaw)

    checked, ps, p = plan_standstill(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    fz = checked["fz"]
    pa = p.patch(fz)
    law = p.patch_law(fz)
    A, rate, cyc = checked["amplitude"], checked["yaw_rate"], int(checked["cycles"])
    frame = checked["frame_term"]
    if progress is not None:
        progress.start(3, "standstill")
    t, psi, leg = triangle_yaw(A, rate, cyc, int(checked["samples"]))
    xi_q, w_q = gauss_patch(pa.l, int(checked["nodes"]))
    xi_g = np.linspace(-pa.l / 2.0, pa.l / 2.0, int(checked["grid"]))
    r = simulate_standstill(law, p.c_Mz, t, psi, xi_q, w_q, xi_g, frame)
    if progress is not None:
        progress.advance(1)
    cycle = np.where(leg == 0, 0, (leg + 1) // 2)  # leg 0: first quarter; legs 1, 2 cycle 1; 3, 4 cycle 2 ...
    st = pd.DataFrame({"t": t, "psi": psi, "leg": leg, "cycle": cycle, "mz": r["mz"], "fx": r["fx"], "fy": r["fy"]})
    every = max(1, int(round(int(checked["samples"]) / int(checked["patch_samples"]))))
    keep = np.arange(0, t.size, every)
    if keep[-1] != t.size - 1:
        keep = np.append(keep, t.size - 1)
    fy_tire = -r["fy_grid"]  # the road's force density on the tire (ISO-W), like every tire force of the run
    patch = pd.DataFrame({"t": np.repeat(t[keep], xi_g.size), "psi": np.repeat(psi[keep], xi_g.size),
                          "xi": np.tile(xi_g, keep.size), "fy": fy_tire[keep].ravel()})
    # facts: small-yaw stiffness (exact step of 1 mrad from rest) and first-loading torques
    probe = np.array([0.0, 1e-3, 0.01, 0.05, 0.1])
    pr = simulate_standstill(law, p.c_Mz, probe / rate, probe, xi_q, w_q, (), frame)
    sti = p.stiffnesses(fz)
    mz = r["mz"]
    facts = {
        "C_z_eq11_Nm_per_rad": sti["C_z"], "C_z_secant_1mrad_Nm_per_rad": float(-pr["mz"][1] / 1e-3),
        "C_z_with_belt_twist_Nm_per_rad": sti["C_zF"],
        "first_loading_mz_Nm": {f"{x:g} rad": float(v) for x, v in zip(probe[2:], pr["mz"][2:])},
        "Mz_inf_eq12_Nm": sti["Mz_inf"],
        "Mz_inf_frame_term_Nm": asymptotic_standstill_torque(law, pa.l, p.c_Mz, True),
        "Mz_inf_no_frame_term_Nm": asymptotic_standstill_torque(law, pa.l, p.c_Mz, False),
        "Fky_per_length_N_per_m": float(law.Fk[1]),
    }
    end2 = np.flatnonzero(leg == 1)  # legs: 0 (0 -> A), 1 (A -> -A), 2 (-A -> A), ...
    if end2.size:
        facts["mz_at_minus_A_Nm"] = float(mz[end2[-1]])
    first = cycle <= 1
    i = int(np.argmax(np.abs(mz[first])))
    ps_, mz_ = _refine_peak(psi[first], np.abs(mz[first]), i) if 0 < i < first.sum() - 1 else (psi[i], abs(mz[i]))
    facts["max_abs_mz_first_cycle_Nm"] = float(mz_)
    facts["psi_of_max_abs_mz_rad"] = float(ps_)
    facts["leg_of_max_abs_mz"] = int(leg[first][i])
    fyg = np.abs(r["fy_grid"])
    facts["max_fy_first_loading_over_Fky"] = float(fyg[leg == 0].max() / law.Fk[1])
    facts["max_fy_first_cycle_over_Fky"] = float(fyg[first].max() / law.Fk[1])
    last = cycle == cyc
    # the last full cycle: from the start of its first leg (the end of the previous cycle)
    lo = np.flatnonzero(last)[0] - 1
    seg = slice(lo, None)
    facts["loop_energy_last_cycle_J"] = float(-np.trapezoid(mz[seg], psi[seg]))
    prev = cycle == cyc - 1
    if cyc >= 2 and prev.any():
        lo2 = np.flatnonzero(prev)[0] - 1
        hi2 = np.flatnonzero(prev)[-1] + 1
        facts["loop_energy_previous_cycle_J"] = float(-np.trapezoid(mz[lo2:hi2], psi[lo2:hi2]))
    if progress is not None:
        progress.advance(2)
        progress.close()
    lines = [f"C_z = {facts['C_z_eq11_Nm_per_rad']:.6g} N m/rad (eq. 11; secant after 1 mrad "
             f"{facts['C_z_secant_1mrad_Nm_per_rad']:.6g}); asymptotic torque {facts['Mz_inf_eq12_Nm']:.6g} N m "
             f"(eq. 12), {facts['Mz_inf_frame_term_Nm']:.6g} N m with the frame term",
             f"yaw cycle +-{A:g} rad: Mz = {facts.get('mz_at_minus_A_Nm', float('nan')):.5g} N m at psi = -A; max |Mz| "
             f"{facts['max_abs_mz_first_cycle_Nm']:.5g} N m at psi = {facts['psi_of_max_abs_mz_rad']:.3g} rad; "
             f"energy of the last cycle {facts['loop_energy_last_cycle_J']:.4g} J"]
    return StudyResult(
        study="mcps-standstill", config=config, parameter_sets={"tire": ps},
        data={"standstill": st, "patch": patch},
        meta={"title": checked["title"] or "MCPS blocked wheel at standstill: patch forces and torsional torque",
              "scenario": {"amplitude_rad": A, "yaw_rate_rad_per_s": rate, "cycles": cyc,
                           "path": "psi triangular 0 -> +A -> -A -> +A ...", "frame_term": frame, "fz_N": fz,
                           "patch": {"l_m": pa.l, "w_m": pa.w, "P_Pa": pa.P},
                           "quadrature": f"Gauss-Legendre, {checked['nodes']} nodes per half patch"},
              "signs": "mz, fx, fy and patch.csv fy: road on tire (ISO-W, eq. 10); patch.csv fy is a force per unit "
                       "patch length [N/m]",
              "assumed": [f"yaw amplitude {A:g} rad (the scan's '-45 <= psi <= 45' read as +-0.45 rad: its decimal points are "
                          "lost and the figure's axis is in rad, ticks -0.4 to 0.4)"]
              if abs(A - 0.45) < 1e-12 else [],
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-fig4", "mcps-fig5"],
        payload={"params": p, "law": law, "patch": pa, "xi_grid": xi_g, "fy_grid": fy_tire, "t": t, "psi": psi},
    )


# --------------------------------------------------------------------------- mcps-relaxation

LOCKABLE = ("x", "y", "delta")
CASE = AnyOf(options=(
    Str(choices=CARCASSES),
    Map(fields={
        "carcass": Str(choices=CARCASSES, doc="complete or rigid"),
        "locked": ListOf(item=Str(choices=LOCKABLE), min_len=0, max_len=3, default=[], doc="belt DOFs held at 0"),
        "label": Str(default="", doc="name in legends and CSV", max_len=MAX_TITLE_CHARS),
    }),
), what="complete, rigid, or {carcass, locked: [x, y, delta], label}")

RELAXATION = Map(fields=common_fields() | {
    "tire": Raw(kind="mcps", default=None, doc="MCPS parameter set"),
    "fz": Num(unit="N", gt=0, default=4000.0, doc="vertical load"),
    "alpha": Num(unit="rad", ge=-1.5, le=1.5, default=1.0 * DEG, doc="slip angle after the step (not 0)"),
    "speed": Num(unit="m/s", gt=0, le=200, default=20.0, doc="forward speed Vx = r omega"),
    "carcass": AnyOf(options=(CASE, ListOf(item=CASE, max_len=8)), default="complete",
                     what="a carcass case or a list of them"),
    "distance": Num(unit="m", gt=0, le=1000, default=4.0, doc="rolled distance to simulate"),
    "cells": Num(unit="-", integer=True, ge=10, le=20_000, default=100,
                 doc="patch cells (raised automatically at low speed to resolve the belt)"),
    "frame_term": Bool(default=True, doc="rotate the element states with the belt twist (docs/models/mcps_tire.md §4: on)"),
})


@dataclass
class RelaxCase:
    label: str
    carcass: str
    locked: tuple


def plan_relaxation(config: Config):
    checked, ps = collect(lambda: config.checked(RELAXATION), lambda: tire_set(config))
    if checked["alpha"] == 0:
        raise ConfigError(config.origins.problem(("alpha",), "must not be 0: the relaxation is the build-up of the "
                                                             "side force after a slip-angle step"))
    raw = checked["carcass"]
    items = raw if isinstance(raw, list) else [raw]
    cases = []
    for it in items:
        if isinstance(it, str):
            cases.append(RelaxCase(it, it, ()))
        else:
            locked = tuple(sorted({LOCKABLE.index(x) for x in it["locked"]}))
            if it["carcass"] == "rigid" and locked:
                raise ConfigError(config.origins.problem(("carcass",), "'locked' applies to the complete carcass only"))
            label = it["label"] or (it["carcass"] + ("" if not locked else ", " + "+".join(LOCKABLE[j] for j in locked) + " locked"))
            cases.append(RelaxCase(label, it["carcass"], locked))
    labels = [c.label for c in cases]
    if len(set(labels)) != len(labels):
        raise ConfigError(config.origins.problem(("carcass",), "two cases share a label; give each a distinct 'label'"))
    p = ps.model()
    est = Estimate()
    cap = compute_cap(MAX_ELEMENT_STEPS)
    for c in cases:
        n = _cells(p, checked, c)
        steps = checked["distance"] / (p.patch(checked["fz"]).l / n)
        est.add(steps + 1, (("distance",), ("cells",), ("speed",)), f"data/relaxation.csv (case {c.label!r}: "
                f"{steps:,.0f} steps of {n} cells)", BYTES_PER_ROW)
        if n * steps > cap:
            raise ConfigError(config.origins.problem((), f"case {token(c.label)}: the run needs {n} cells x {steps:.3g} steps "
                                                         f"(speed {checked['speed']:g} m/s, distance {checked['distance']:g} m), "
                                                         f"over the budget of {cap:.0e} element-steps (short "
                                                         "relaxation lengths at large slip angles and the belt's fast modes at "
                                                         "low speed need small steps): shorten 'distance' or raise 'speed' " + cap_hint()))
    est.check(config.origins)
    return checked, ps, p, cases


def _cells(p, checked, case) -> int:
    """Patch cells of a case (:func:`tirecli.numerics.mcps_transient.cells_needed`)."""
    from tirecli.numerics.mcps_transient import cells_needed

    return cells_needed(p, checked["fz"], checked["speed"], checked["cells"], case.carcass, case.locked,
                        slip=(0.0, math.tan(checked["alpha"])))


def crossings(s, ratio, level):
    """First and last rolled distance [m] where ``ratio`` rises through ``level`` (linear between
    samples); None when never reached."""
    above = ratio >= level
    idx = np.flatnonzero(~above[:-1] & above[1:])
    if idx.size == 0:
        return None, None

    def at(i):
        r0, r1 = ratio[i], ratio[i + 1]
        return float(s[i] + (level - r0) * (s[i + 1] - s[i]) / (r1 - r0))

    return at(idx[0]), at(idx[-1])


@register_study("mcps-relaxation", check=plan_relaxation, spec=RELAXATION)
def run_relaxation(config: Config, progress=None) -> StudyResult:
    """Force build-up after a slip-angle step at constant speed (docs/models/mcps_tire.md §7, scenario assumed)."""
    from tirecli.numerics.mcps_stationary import solve
    from tirecli.numerics.mcps_transient import simulate_rolling

    checked, ps, p, cases = plan_relaxation(config)
    import pandas as pd  # once the config is checked: a refused run fails at once

    fz, a, V, dist = checked["fz"], checked["alpha"], checked["speed"], checked["distance"]
    frames, facts = [], {}
    sti = p.stiffnesses(fz)
    pa = p.patch(fz)
    for c in cases:
        n = _cells(p, checked, c)
        st = solve(p, fz, [0.0], [a], [0.0], carcass=c.carcass, locked=c.locked)
        if not st.converged.all():
            raise RunError(f"case {token(c.label)}: the stationary fixed point (MCPS eq. 18) did not converge at alpha = {a:g} "
                           "rad; nothing was written")
        fy_inf, mz_inf = float(st.fy[0]), float(st.mz[0])
        run = simulate_rolling(p, fz, V, V * math.tan(a), V, 0.0, dist, cells=n, carcass=c.carcass, locked=c.locked,
                               frame_term=checked["frame_term"], progress=progress)
        ratio = run.fy / fy_inf
        frames.append(pd.DataFrame({"case": c.label, "carcass": c.carcass, "s": run.s, "t": run.t, "fy": run.fy,
                                    "mz": run.mz, "fx": run.fx, "ratio": ratio, "x": run.x, "y": run.y,
                                    "delta": run.delta, "rim_fy": run.rim_fy}))
        f = {"fy_inf_N": fy_inf, "mz_inf_Nm": mz_inf, "cells": n, "step_m": pa.l / n,
             "final_fy_minus_fy_inf_N": float(run.fy[-1] - fy_inf)}
        for lev in (0.63, 0.95, 0.99):
            first, last_ = crossings(run.s, ratio, lev)
            f[f"s{int(round(lev * 100))}_first_m"] = first
            f[f"s{int(round(lev * 100))}_last_m"] = last_
        f["monotone"] = bool(np.all(np.diff(np.abs(run.fy)) >= -1e-3 * abs(fy_inf)))  # no dip above 0.1 % of Fy_inf
        f["lag_integral_m"] = float(np.trapezoid(1.0 - ratio, run.s))
        if c.carcass == "complete" and not c.locked:
            e = sti["D_zalpha"] / p.k_delta
            f["lag_integral_linear_theory_m"] = float(pa.l / 3.0 - sti["D_yphi"] / sti["D_yalpha"] * e + (
                sti["D_yalpha"] / p.k_y - e * (pa.l / 2.0 + p.c_delta * V / p.k_delta + sti["D_zphi"] / p.k_delta)) / (1.0 + e))
        facts[c.label] = f
    df = pd.concat(frames, ignore_index=True)
    if not np.isfinite(df[["fy", "mz", "fx"]].to_numpy()).all():
        raise RunError("the rolling run produced non-finite forces; nothing was written")
    lines = []
    for lab, f in facts.items():
        d = ", ".join(f"{k[1:3]} % at {f[k]:.4g} m" if f[k] is not None else f"{k[1:3]} % not reached"
                      for k in ("s63_first_m", "s95_first_m", "s99_first_m"))
        extra = "" if f["monotone"] else f" (not monotone: last 95 % crossing at {f['s95_last_m']:.4g} m)" \
            if f["s95_last_m"] is not None else " (not monotone)"
        lines.append(f"{lab}: Fy -> {f['fy_inf_N']:.5g} N; first crossings {d}{extra}")
    return StudyResult(
        study="mcps-relaxation", config=config, parameter_sets={"tire": ps}, data={"relaxation": df},
        meta={"title": checked["title"] or "MCPS relaxation: side-force build-up after a slip-angle step",
              "scenario": {"alpha_rad": a, "speed_m_per_s": V, "distance_m": dist, "fz_N": fz,
                           "start": "free rolling (element states and belt at rest), step of Vy = Vx tan(alpha) at t = 0; "
                                    "Vx = r omega constant; no yaw",
                           "frame_term": checked["frame_term"],
                           "numerics": "Lagrangian tread elements (CFL = 1), exact per-component element steps, "
                                       "trapezoidal belt with a predictor-corrector coupling"},
              "assumed": ["slip-angle step from free rolling at constant speed (the paper shows no relaxation "
                          "run; docs/models/mcps_tire.md §7)"],
              "signs": "fy, mz, fx: road on tire in R_W about the rim centre (ISO-W, eq. 16); ratio = fy/fy_inf; "
                       "rim_fy = k_y y + c_y ydot, the force the belt puts on the rim",
              "cases": [{"label": c.label, "carcass": c.carcass, "locked": [LOCKABLE[j] for j in c.locked]} for c in cases],
              "facts": facts, "summary": lines},
        figures=checked["figures"] or ["mcps-relaxation"],
        payload={"params": p, "cases": cases},
    )


__all__ = ["run_stationary", "run_slider", "run_standstill", "run_relaxation", "mf_side", "MFSide", "crossings"]
