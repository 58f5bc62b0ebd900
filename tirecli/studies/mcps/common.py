"""What the MCPS studies share: the MCPS parameter set of a config, the Magic Formula side, limits and helpers
(see :mod:`tirecli.studies.mcps`)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Map, Raw, Str
from tirecli.errors import ConfigError

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


def refine_peak(x, y, i):
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



def meta_summary(result) -> list[str]:
    """The lines of ``meta["summary"]``, indented: what the CLI prints after an MCPS run."""
    return [f"  {line}" for line in result.meta.get("summary", [])]
