"""The config of an ``mf-fit`` study: Magic Formula 6.1 coefficients fitted to measured points.

::

    study: mf-fit
    data:                                   # one or more files (.tdx, .csv, .parquet, .mf4), or SYNTHETIC data
      - examples/data/synthetic-externdata-205-60r15.tdx
      # - {synthetic: {tire: externdata-205-60r15, noise: 0.01, seed: 1}}   # generated as 'tirecli data synth'
    start: pacejka2006-205-60r15            # start tyre: a .tir path (or its YAML form) or a built-in name
    map: {}                                 # reader options of every file: --map FILE_COLUMN=NAME
    units: {}                               # --units NAME=UNIT
    convention: null                        # axis convention of the files: iso, sae, adapted-iso
    rate: null                              # MDF files: resample rate [Hz]
    options:
      parts: [longitudinal, lateral, aligning, combined]
      loss: linear                          # or soft_l1, huber, cauchy, arctan (robust)
      f_scale: 0.02                         # where a robust loss starts to discount (fraction of the peak)
      weights: {fx: 1, fy: 1, mz: 1}
      bounds: {PDX1: [0.8, 1.6]}            # coefficient -> [low, high]
      fix: [PEX4]                           # coefficients kept at the start values
      mf_convention: mfeval                 # or teasit (docs/models/magic_formula_tyre.md §10)
      ranges: data                          # the fitted tyre's input ranges: those of the data, or the start's
    reference:                              # optional: a tyre the fitted curves are checked against
      tire: externdata-205-60r15            # (the generating tyre of SYNTHETIC data)
      tolerance: {fx: 2, fy: 2, mz: 5, combined: 2}   # [% of the peak]

``tirecli mf fit DATA... --start TIRE --out DIR`` builds this config from its arguments; ``tirecli mf fit
CONFIG.yaml`` runs a written one.
"""
from __future__ import annotations

from tirecli.config.schema import AnyOf, ListOf, Map, Nullable, Num, Str
from tirecli.conventions import AXIS_CONVENTIONS
from tirecli.numerics.mf_fit.result import LOSSES
from tirecli.numerics.mf_fit.stages import PARTS
from tirecli.studies.base import common_fields

#: A data item generated as `tirecli data synth` does (SYNTHETIC).
SYNTHETIC = Map(fields={
    "tire": Str(doc="generating Magic Formula tyre: a built-in name or a .tir path"),
    "noise": Num(unit="-", ge=0, le=1, default=0.01, doc="noise: standard deviation as a fraction of each channel's peak"),
    "seed": Num(unit="-", integer=True, ge=0, default=1, doc="seed of the noise"),
    "points": Num(unit="-", integer=True, ge=3, le=100_000, default=41, doc="samples per sweep"),
    "loads": ListOf(item=Num(unit="N", gt=0), min_len=0, default=[], doc="loads of the pure sweeps (default 0.5, 1, 1.5 FNOMIN)"),
    "pressures": ListOf(item=Num(unit="Pa", gt=0), min_len=0, default=[], doc="further pressures of pure sweeps"),
})

DATA_ITEM = AnyOf(options=(Str(doc="a data file"), Map(fields={"synthetic": SYNTHETIC})),
                  what="a data file (.tdx, .csv, .parquet or .mf4) or {synthetic: {tire: NAME, ...}}")

CHANNEL_WEIGHTS = Map(fields={ch: Num(unit="-", ge=0, default=1.0, doc=f"weight of {ch}") for ch in ("fx", "fy", "mz")},
                      default={})

OPTIONS = Map(fields={
    "parts": ListOf(item=Str(choices=tuple(PARTS)), default=None, doc="parts of the fit (default: all)"),
    "loss": Str(choices=LOSSES, default="linear", doc="least squares (linear) or a robust loss"),
    "f_scale": Num(unit="-", gt=0, le=10, default=0.02, doc="residual where a robust loss starts to discount, "
                                                              "as a fraction of the channel's peak"),
    "weights": CHANNEL_WEIGHTS,
    "bounds": Map(open_keys=ListOf(item=Num(unit="-"), min_len=2, max_len=2), default={},
                  doc="coefficient -> [low, high]"),
    "fix": ListOf(item=Str(), min_len=0, default=[], doc="coefficients kept at their start values"),
    "mf_convention": Str(choices=("mfeval", "teasit"), default="mfeval",
                         doc="Magic Formula variant (docs/models/magic_formula_tyre.md §10)"),
    "ranges": Str(choices=("data", "start"), default="data", doc="input ranges of the fitted tyre"),
}, default={})

REFERENCE = Map(fields={
    "tire": Str(doc="a Magic Formula tyre (built-in name or .tir path) the fitted curves are compared with"),
    "tolerance": Map(fields={k: Num(unit="%", gt=0, default=d, doc=f"largest gap of {k} [% of the peak]")
                             for k, d in (("fx", 2.0), ("fy", 2.0), ("mz", 5.0), ("combined", 2.0))}, default={}),
})

SPEC = Map(fields=common_fields() | {
    "data": ListOf(item=DATA_ITEM, doc="measured data: files, or {synthetic: ...}"),
    "start": Str(doc="start tyre: a .tir path (or its YAML form) or a built-in name (MF 6.1 or 6.2)"),
    "map": Map(open_keys=Str(), default={}, doc="FILE_COLUMN -> NAME of every file (--map)"),
    "units": Map(open_keys=Str(), default={}, doc="NAME -> UNIT of every file (--units)"),
    "convention": Str(choices=AXIS_CONVENTIONS, default=None, doc="axis convention of the files"),
    "rate": Nullable(spec=Num(unit="Hz", gt=0), default=None, doc="MDF files: resample onto this rate"),
    "options": OPTIONS,
    "reference": Nullable(spec=REFERENCE, default=None, doc="a tyre to check the fitted curves against"),
})

__all__ = ["SPEC", "OPTIONS", "SYNTHETIC", "REFERENCE"]
