"""Steady-state sweeps of the LuGre tire: mu over slip x speed x theta x model variant.

Config (``tirecli sweep CONFIG``)::

    study: sweep
    tire: canudas2003-table1          # built-in set, a set file, or {set: ..., sigma0: 170}
    sweep:
      slip: {start: -1, stop: 0, num: 1001}   # signed slip [-]: < 0 braking, > 0 driving
      speeds: [5, 10, 20]                     # held speed [m/s]: v braking, r*omega driving
      theta: [1.0]                            # road adhesion [-]
      theta_convention: fm                    # fm (g -> theta g, 1 = dry) or obs (1/theta_fm)
      models:                                 # default: distributed, uniform load
        - distributed                         # = {model: distributed, load: uniform}
        - {model: distributed, load: exponential, lambda: 2}
        - {model: distributed, load: parabolic}
        - {model: lumped, kappa0: 2}          # constant kappa0, or Z for FM eq. (10)
    figures: [sweep-mu-slip]

Output frames:

- ``sweep`` (long format): ``model, direction, speed, v, romega, theta, theta_obs, slip, mu,
  kappa0, Z``. ``kappa0`` [-] is the lumped coefficient used at that point (the constant, or
  ``kappa0(Z)`` of FM eq. (10) there) and ``Z = |r omega| theta g / (sigma0 |vr|)`` [m] the
  characteristic length of that point (``inf`` at ``vr = 0``, 0 for a locked wheel); both are
  empty (NaN) on the rows of distributed models. The variants (load, lambda, kappa0) are
  described in ``run.json``.
- ``peaks``: one row per curve (model, held speed, adhesion, direction with slips in the sweep):
  ``model, variant, load, lambda, kappa0, direction, speed, theta, theta_obs, slip_peak, mu_peak,
  mu_slide``. ``slip_peak`` and ``mu_peak`` are the root-found peak of ``|mu|`` over
  ``0 < |s| <= 1`` (to 1e-12 in slip, on the model function, not the sweep's grid;
  :mod:`tirecli.models.steady_peaks`), ``mu_slide`` is ``mu`` at full slide ``|s| = 1``; all three
  signed like ``slip`` and ``mu`` (negative when braking). ``lambda`` is empty unless the load is
  exponential; ``kappa0`` is the lumped constant or ``Z``, empty for distributed models. The same
  rows are ``meta.facts.peaks`` of ``run.json``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import AnyOf, Context, Grid, ListOf, Map, Num, Raw, Str, collect
from tirecli.conventions import THETA_CONVENTIONS, to_theta_fm
from tirecli.errors import ConfigError, token
from tirecli.limits import MAX_TITLE_CHARS, Estimate
from tirecli.models.variants import LOADS, MODELS, FrictionVariant
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.registry import register
from tirecli.studies.study import Lazy, Plan, Study
from tirecli.studies.sweep_frames import peak_records, peaks_frame, sweep_frame

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd


def _variant_post(v: dict, path, ctx: Context) -> None:
    if v["model"] == "distributed" and v["kappa0"] is not None:
        ctx.fail(path + ("kappa0",), "kappa0 applies to lumped models only")
    if v["load"] == "exponential" and v["lambda"] is None:
        ctx.fail(path, "missing required key 'lambda' for an exponential load (decay [-], >= 0)")
    if v["load"] != "exponential" and v["lambda"] is not None:
        ctx.fail(path + ("lambda",), "lambda applies to load: exponential only")
    if v["model"] == "lumped" and v["load"] == "exponential" and v["kappa0"] is None and v["lambda"] == 0:
        ctx.fail(path + ("lambda",), "out of range: a lumped model takes kappa = lambda/L, so lambda must be > 0 "
                                     "(lambda = 0 is the uniform load: use kappa0: Z or a constant kappa0)")
    if v["load"] == "tabulated":
        u, f = v["u"], v["f"]
        if u is None or f is None:
            ctx.fail(path, "a tabulated load needs 'u' (positions zeta/L) and 'f' (load density samples)")
            return
        if len(u) != len(f) or len(u) < 2:
            ctx.fail(path + ("f",), f"expected as many samples as in 'u' ({len(u)}, at least 2), got {len(f)}")
        elif any(b <= a for a, b in zip(u, u[1:])):
            ctx.fail(path + ("u",), "positions must increase strictly")
        elif sum(f) <= 0:
            ctx.fail(path + ("f",), "the load samples must have a positive total")
    elif v["u"] is not None or v["f"] is not None:
        ctx.fail(path + ("u" if v["u"] is not None else "f",), "u and f apply to load: tabulated only")


VARIANT = AnyOf(options=(
    Str(choices=MODELS),
    Map(fields={
        "model": Str(choices=MODELS, doc="distributed (PDE steady state) or lumped (averaged ODE)"),
        "load": Str(choices=LOADS, default="uniform", doc="normal-load density along the patch"),
        "lambda": Num(unit="-", ge=0, default=None, doc="exponential load decay (0: uniform)", eq="FM eq. (5)"),
        "kappa0": AnyOf(options=(Num(unit="-", gt=0), Str(choices=("Z",))), default=None,
                        what="a number > 0 or Z (FM eq. (10))"),
        "u": ListOf(item=Num(unit="-", ge=0, le=1), min_len=2, default=None, doc="tabulated load positions zeta/L"),
        "f": ListOf(item=Num(unit="N/m", ge=0), min_len=2, default=None, doc="tabulated load density samples"),
        "label": Str(default="", doc="name in legends and CSV", max_len=MAX_TITLE_CHARS),
    }, post=_variant_post),
), what="a model name (distributed, lumped) or a mapping {model, load, lambda, kappa0, label}")

SWEEP = Map(fields={
    "slip": Grid(unit="-", ge=-1, le=1, default={"start": -1.0, "stop": 0.0, "num": 1001},
                 doc="signed slip: < 0 braking, > 0 driving"),
    "speeds": Grid(unit="m/s", ge=0, default=[20.0], doc="held speed: v when braking, r*omega when driving"),
    "theta": Grid(unit="-", gt=0, default=[1.0], doc="road adhesion"),
    "theta_convention": Str(choices=THETA_CONVENTIONS, default="fm", doc="convention of the theta values"),
    "models": ListOf(item=VARIANT, default=["distributed"], doc="model variants"),
}, default={})

SPEC = Map(fields=common_fields() | {"tire": Raw(kind="lugre", doc="LuGre parameter set: a name, a file, or {set: ..., overrides}"), "sweep": SWEEP})


def make_variant(raw) -> FrictionVariant:
    """A :class:`FrictionVariant` from a checked config entry."""
    if isinstance(raw, str):
        return FrictionVariant(model=raw)
    return FrictionVariant(
        model=raw["model"], load=raw["load"], lam=raw["lambda"] or 0.0, kappa0=raw["kappa0"],
        u=tuple(raw["u"]) if raw["u"] else None, f=tuple(raw["f"]) if raw["f"] else None, label=raw["label"],
    )


@dataclass
class LuGreSweep:
    """The detail of a LuGre sweep's plan: the model variants and the adhesion values (FM convention)."""

    variants: list
    thetas_fm: list


def plan(config: Config) -> Plan:
    """Check a sweep config of either model family completely (a Magic Formula ``tire:`` plans
    :func:`tirecli.studies.mf_sweep.plan`)."""
    from tirecli.studies import mf_sweep

    return mf_sweep.plan(config) if mf_sweep.uses_mf_tire(config) else plan_lugre(config)


def plan_lugre(config: Config) -> Plan:
    """Check a LuGre sweep config completely (detail :class:`LuGreSweep`)."""
    checked, tire = collect(lambda: config.checked(SPEC), lambda: config.group("tire", "lugre"))
    sw = checked["sweep"]
    variants = [make_variant(m) for m in sw["models"]]
    labels = [v.label for v in variants]
    if len(set(labels)) != len(labels):
        dup = next(l for l in labels if labels.count(l) > 1)
        raise ConfigError(config.origins.problem(("sweep", "models"), f"two models share the label {token(dup)}; give each a distinct 'label'"))
    thetas_fm = [float(t) for t in to_theta_fm(sw["theta"], sw["theta_convention"])]
    est = sweep_estimate(len(variants), len(thetas_fm), len(sw["speeds"]), len(sw["slip"]))
    est.check(config.origins)
    return Plan("sweep", config, checked, {"tire": tire}, est, LuGreSweep(variants, thetas_fm))


#: Memory per row of a sweep [bytes], an upper bound: the frame's float columns (at most 72 bytes; a
#: column constant over the sweep is stored once) and its two categorical text columns (2 bytes); the
#: model's temporaries, the figure's selections of its curves, the CSV text and the Parquet row groups
#: are per block (:data:`~tirecli.studies.sweep_frames.BLOCK_POINTS`, :data:`tirecli.io.output.CSV_CHUNK_ROWS`,
#: :data:`tirecli.io.output.PARQUET_GROUP_ROWS`), a few MB whatever the sweep. Measured: 10^6 rows
#: (constant theta, kappa0, Z) peak at ~240 MB of which ~130 MB are the libraries.
BYTES_PER_ROW = 160


def sweep_estimate(models: int, thetas: int, speeds: int, slips: int) -> Estimate:
    """The sample budget's estimate of a sweep: one sample per grid point the config asks for
    (models x theta x speeds x slip; the one row per curve of ``peaks`` is not counted)."""
    return Estimate().add_product({("sweep", "models"): models, ("sweep", "theta"): thetas,
                                   ("sweep", "speeds"): speeds, ("sweep", "slip"): slips}, "the sweep", BYTES_PER_ROW)


def _require_finite(config: Config, df: pd.DataFrame, peaks: pd.DataFrame) -> None:
    """ConfigError naming the speed and theta where a curve is not finite (never an empty mu cell):
    speeds or adhesion so far out that the steady state overflows."""
    for frame, cols in ((df, ["mu"]), (peaks, ["mu_peak", "mu_slide"])):  # (no slip_peak at speed 0)
        vals = frame[cols].to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(vals).all(axis=1))
        if bad.size:
            row = frame.iloc[int(bad[0])]
            at = f"speed = {row['speed']:g} m/s, theta = {row['theta']:g}"
            if "slip" in frame.columns:
                at += f", slip = {row['slip']:g}"
            raise ConfigError(config.origins.problem(("sweep", "speeds"), f"model {row['model']}: mu is not finite at "
                                                     f"{at} (a speed or adhesion beyond what the steady state can "
                                                     "evaluate); nothing was written"))


def run(plan_: Plan, progress=None) -> StudyResult:
    """Run a planned sweep of either model family (see module doc)."""
    if not isinstance(plan_.detail, LuGreSweep):
        from tirecli.studies import mf_sweep

        return mf_sweep.run(plan_, progress)
    config, checked, tire = plan_.config, plan_.checked, plan_.sets["tire"]
    variants, thetas_fm = plan_.detail.variants, plan_.detail.thetas_fm
    p = tire.model()
    sw = checked["sweep"]
    with np.errstate(all="ignore"):  # overflow at absurd speeds/theta: reported below with the point
        df = sweep_frame(variants, p, sw["slip"], sw["speeds"], thetas_fm, progress)
        peaks = peaks_frame(variants, p, sw["slip"], sw["speeds"], thetas_fm, progress)
    _require_finite(config, df, peaks)
    return StudyResult(
        study="sweep",
        config=config,
        parameter_sets={"tire": tire},
        data={"sweep": df, "peaks": peaks},
        meta={
            "variants": [v.record() for v in variants],
            "facts": {"peaks": peak_records(peaks),
                      "peaks_note": "one row per curve: slip_peak, mu_peak root-found on the model function "
                                    "(0 < |s| <= 1, to 1e-12 in slip), mu_slide = mu at |s| = 1; signed like "
                                    "slip and mu (negative when braking); also data/peaks.csv"},
            "theta_convention_input": sw["theta_convention"],
            "theta_stored": "fm (g -> theta*g; theta_obs = 1/theta)",
            "held_speed": "v for braking (slip < 0), r*omega for driving (slip > 0)",
            "points": int(len(df)),
            "title": checked["title"],
        },
        figures=checked["figures"] or ["sweep-mu-slip"],
        payload={"params": p, "variants": variants, "thetas_fm": thetas_fm,
                 "theta_convention": sw["theta_convention"]},
    )


#: Units of the facts of a sweep (``mu_peak[i]``: curve ``i`` of ``data/peaks.csv``).
FACT_UNITS = {"slip_peak": "-", "mu_peak": "-", "mu_slide": "-"}

STUDY = register(Study(
    name="sweep", command="sweep", spec=SPEC, plan=plan, run=run, figures=("sweep-mu-slip",),
    checks={
        "fm-fig1-left": Lazy("tirecli.studies.checks.steady", "fig1_left_checks"),
        "fm-fig1-right": Lazy("tirecli.studies.checks.steady", "fig1_right_checks"),
        "obs-fig1": Lazy("tirecli.studies.checks.steady", "obs_fig1_checks"),
        "fm-fig6-surface": Lazy("tirecli.studies.checks.steady", "fig6_surface_checks"),
        "mf-lugre-compare": Lazy("tirecli.studies.checks.magic_formula", "compare_checks"),
        "mf-tire-*": Lazy("tirecli.studies.checks.magic_formula", "tire_checks"),
    },
    fact_units=FACT_UNITS,
))
