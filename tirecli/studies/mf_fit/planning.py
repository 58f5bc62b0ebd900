"""Plan an ``mf-fit`` study: the config checked, the data read, the start tyre read, the fit planned.

Everything that can be wrong with a fit is found here, before any least squares and before anything is
written: a bad key, a data file that cannot be read (unknown unit, missing channel, a short row, a NaN
or text cell, an MDF4 file without the channels; the readers' one-line errors), data holding no sweep
of what is asked, a start tyre that is not MF 6.1 or 6.2, options the fit refuses.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tirecli.config.loader import Config
from tirecli.errors import ConfigError, DataError, UsageError
from tirecli.studies.mf_fit.spec import SPEC
from tirecli.studies.study import Plan

#: Memory of one point through the fit: the data, the per-point table and its CSV text [bytes].
BYTES_PER_POINT = 2000
#: The channel table's columns the fit needs (the readers name a file lacking one).
REQUIRED = ("kappa", "alpha", "fz")


@dataclass
class Source:
    """One data item: its label, the table read or generated, and whether it is SYNTHETIC."""

    label: str
    frame: object
    synthetic: bool
    generator: str | None = None  # the generating tyre of a synthetic item


@dataclass
class FitDetail:
    """What the run needs beyond the checked config (``Plan.detail``)."""

    fit: object            # tirecli.numerics.mf_fit.FitPlan
    frame: object          # the points of every item, one table (``file``: the item's number)
    sources: list
    start_doc: object      # the start tyre's TirDocument (the fitted .tir is written from it)
    start_label: str
    reference: object      # MFTire or None
    reference_label: str


def _path(ref: str, base_dir: Path) -> str:
    """A data file as the config names it, read relative to the config's folder."""
    p = Path(ref)
    if p.is_absolute() or Path(base_dir).resolve() == Path.cwd().resolve():
        return ref
    return str(Path(base_dir) / p)


def _tire(ref: str, config: Config, key: tuple):
    """``(document, MFTire)`` of a tyre named in the config; a bad name is a problem at ``key``."""
    from tirecli.parameters.mf import read_document, tire_data

    try:
        doc, label = read_document(ref, config.base_dir)
        return doc, tire_data(doc).tire(label)
    except ConfigError as err:  # a .tir whose content is refused: the file's own lines
        raise err
    except UsageError as err:
        raise ConfigError(config.origins.problem(key, str(err))) from None


def _synthetic(item: dict, config: Config, key: tuple) -> Source:
    from tirecli.studies.rig_data import RigPlan, synthetic_rig_data

    _, tire = _tire(item["tire"], config, key + ("tire",))
    if tire.family != "mf":
        raise ConfigError(config.origins.problem(key + ("tire",), f"a {tire.version} tyre: SYNTHETIC rig data "
                                                                  "need a Magic Formula 5.2 or 6.x tyre"))
    plan = RigPlan(loads=tuple(item["loads"]), pressures=tuple(item["pressures"]), points=int(item["points"]))
    data = synthetic_rig_data(tire, item["tire"], plan, item["noise"], int(item["seed"]), source="<synthetic>")
    label = (f"SYNTHETIC data generated from {item['tire']} (as 'tirecli data synth', noise {item['noise']:g}, "
             f"seed {int(item['seed'])})")
    return Source(label, data.frame, True, item["tire"])


def read_sources(checked: dict, config: Config) -> list[Source]:
    """Every data item of the config, read (files through :func:`tirecli.io.readers.read_measured`) or
    generated; a reader's error names the file (one line)."""
    from tirecli.io.readers import read_measured

    out = []
    for i, item in enumerate(checked["data"]):
        if isinstance(item, dict):
            out.append(_synthetic(item["synthetic"], config, ("data", i, "synthetic")))
            continue
        data = read_measured(_path(item, config.base_dir), mapping=checked["map"] or None,
                             units=checked["units"] or None, convention=checked["convention"], rate=checked["rate"],
                             require=REQUIRED)
        out.append(Source(item, data.frame, data.synthetic))
    return out


def combine(sources: list[Source], start) -> tuple[object, list[str]]:
    """One table of every item's points (``file``: the item's number from 1; ``run`` numbers made distinct
    across items); a pressure or speed column that some items lack is filled with the start tyre's
    INFLPRES or LONGVL there. Returns ``(frame, notes)``."""
    import pandas as pd

    notes = []
    frames = []
    offset = 0.0
    have = {k: [k in s.frame.columns for s in sources] for k in ("p", "vx", "gamma")}
    for i, s in enumerate(sources, 1):
        f = s.frame.copy()
        f.insert(0, "file", i)
        if "run" in f.columns:
            f["run"] = f["run"] + offset
            offset = float(np.nanmax(f["run"])) if len(f) else offset
        for k, default, what in (("p", start.default_pressure, "INFLPRES"), ("vx", start.reference_speed, "LONGVL"),
                                 ("gamma", 0.0, "")):
            if any(have[k]) and k not in f.columns and default is not None:
                f[k] = float(default)
                notes.append(f"{s.label}: no {k} column: " + (f"the start tyre's {what} {default:g}" if what else "0"))
        frames.append(f)
    frame = pd.concat(frames, ignore_index=True) if len(frames) > 1 else frames[0].reset_index(drop=True)
    frame.attrs = {}
    return frame, notes


def fit_options(checked: dict):
    """The :class:`~tirecli.numerics.mf_fit.FitOptions` of the config's ``options``."""
    from tirecli.numerics.mf_fit import FitOptions

    o = checked["options"]
    kw = dict(loss=o["loss"], f_scale=o["f_scale"], convention=o["mf_convention"], ranges=o["ranges"],
              weights={k: float(v) for k, v in o["weights"].items() if v != 1.0},
              bounds={k: (float(v[0]), float(v[1])) for k, v in o["bounds"].items()}, fix=frozenset(o["fix"]))
    if o["parts"]:
        kw["parts"] = tuple(dict.fromkeys(o["parts"]))
    return FitOptions(**kw)


def _option_problem(config: Config, message: str) -> ConfigError:
    head = message.split(":", 1)[0].split(" ")[0]
    key = ("options", head) if head in ("bounds", "fix", "weights", "parts", "loss", "f_scale") else ("options",)
    return ConfigError(config.origins.problem(key, message))


def plan(config: Config) -> Plan:
    """Check an mf-fit config completely, read its data and start tyre, and plan the fit (no least squares)."""
    from tirecli.config.schema import collect
    from tirecli.limits import Estimate
    from tirecli.numerics.mf_fit import plan_fit
    from tirecli.parameters.mf_fitted import check_start

    (checked,) = collect(lambda: config.checked(SPEC))
    doc, start = _tire(checked["start"], config, ("start",))
    try:
        check_start(doc)
    except UsageError as err:
        raise ConfigError(config.origins.problem(("start",), str(err))) from None
    reference, ref_label = None, ""
    if checked["reference"] is not None:
        ref_label = checked["reference"]["tire"]
        _, reference = _tire(ref_label, config, ("reference", "tire"))
        if reference.family != "mf":
            raise ConfigError(config.origins.problem(("reference", "tire"), f"a {reference.version} tyre, not a "
                                                                            "Magic Formula tyre"))
    options = fit_options(checked)
    sources = read_sources(checked, config)
    frame, notes = combine(sources, start)
    n = len(frame)
    try:
        fp = plan_fit(frame, start, options)
    except DataError as err:
        raise DataError(f"{_data_label(sources)}: {err}") from None
    except UsageError as err:  # the options (the start tyre was checked above)
        raise _option_problem(config, str(err)) from None
    asked = checked["options"]["parts"]
    if asked:  # parts named by the user: each must have data to run on
        idle = [p for p in dict.fromkeys(asked) if not any(s.run for s in fp.stages if s.stage.part == p)]
        if idle:
            why = "; ".join(f"{s.stage.title}: {s.reason}" for s in fp.stages if s.stage.part in idle)
            raise DataError(f"{_data_label(sources)}: no sweep for the asked part(s) {', '.join(idle)}: {why}")
    # a point's memory: its data and table, and its row of the largest Jacobian of a least-squares step
    est = Estimate().add(n, (("data",),), "the points of the fit (data/fit.csv)",
                         BYTES_PER_POINT + fp.jacobian_bytes / max(n, 1))
    est.check(config.origins)
    fp.notes[:0] = notes
    detail = FitDetail(fp, frame, sources, doc, checked["start"], reference, ref_label)
    return Plan("mf-fit", config, checked, {}, est, detail)


def _data_label(sources) -> str:
    names = [s.label if not s.synthetic or s.generator is None else f"SYNTHETIC data of {s.generator}" for s in sources]
    return ", ".join(names[:3]) + (f" and {len(names) - 3} more" if len(names) > 3 else "")


__all__ = ["plan", "FitDetail", "Source", "read_sources", "combine", "fit_options"]
