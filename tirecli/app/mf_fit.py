"""Application layer of ``tirecli mf fit``: the command line made into an ``mf-fit`` study config.

``tirecli mf fit DATA... --start TIRE --out DIR [options]`` builds the config the study takes
(:mod:`tirecli.studies.mf_fit.spec`) from its arguments; ``tirecli mf fit CONFIG.yaml`` runs a written
one (the command's options then override its keys). Either way the run is the one path of every study
(:func:`tirecli.app.run.run_config`): planned completely before anything is written, results written
atomically into ``--out``.
"""
from __future__ import annotations

import json
from pathlib import Path

from tirecli.errors import UsageError, token

#: Suffixes of a config file given as the only DATA.
CONFIG_SUFFIXES = (".yaml", ".yml")


def is_config(data: list[str]) -> bool:
    """Whether the command's DATA is one study config (``.yaml``/``.yml``) rather than data files."""
    return len(data) == 1 and str(data[0]).lower().endswith(CONFIG_SUFFIXES)


def parse_bounds(values) -> dict:
    """``["PDX1=0.8,1.6"]`` -> ``{"PDX1": [0.8, 1.6]}`` (UsageError naming ``--bound``)."""
    out = {}
    for text in values or []:
        name, _, rest = str(text).partition("=")
        parts = rest.split(",")
        try:
            lo, hi = (float(p) for p in parts)
        except ValueError:
            raise UsageError(f"--bound {token(text, 40)}: expected NAME=LOW,HIGH, e.g. --bound PDX1=0.8,1.6") from None
        out[name.strip()] = [lo, hi]
    return out


def parse_weights(values) -> dict:
    """``["fy=0.5"]`` -> ``{"fy": 0.5}`` (UsageError naming ``--weight``)."""
    out = {}
    for text in values or []:
        name, _, rest = str(text).partition("=")
        try:
            out[name.strip()] = float(rest)
        except ValueError:
            raise UsageError(f"--weight {token(text, 40)}: expected CHANNEL=WEIGHT, e.g. --weight mz=0.5") from None
    return out


def _words(text: str | None) -> list[str] | None:
    return None if text is None else [w.strip() for w in str(text).split(",") if w.strip()]


def settings(start=None, reader=None, parts=None, loss=None, f_scale=None, weights=None, bounds=None, fix=None,
             mf_convention=None, ranges=None, reference=None) -> dict:
    """The config keys the command's options give (``None``: not given), as ``key path -> value``."""
    reader = reader or {}
    out = {("start",): start, ("map",): reader.get("mapping"), ("units",): reader.get("units"),
           ("convention",): reader.get("convention"), ("rate",): reader.get("rate"),
           ("options", "parts"): _words(parts), ("options", "loss"): loss, ("options", "f_scale"): f_scale,
           ("options", "weights"): parse_weights(weights) or None, ("options", "bounds"): parse_bounds(bounds) or None,
           ("options", "fix"): _words(fix), ("options", "mf_convention"): mf_convention,
           ("options", "ranges"): ranges, ("reference",): None if reference is None else {"tire": reference}}
    return {k: v for k, v in out.items() if v is not None}


def config_of(data: list[str], values: dict, overrides=()):
    """The ``mf-fit`` config of ``tirecli mf fit DATA...`` (``values``: :func:`settings`)."""
    from tirecli.config.loader import config_from_mapping

    if "start" not in {k[0] for k in values}:
        raise UsageError("missing option --start TIRE: the start tyre (a .tir file or a built-in name, MF 6.1 or 6.2)")
    from tirecli.studies.mf_fit import FIGURES

    # the figures named: their reference checks run (fitted.tir passes tir check; with --reference, the curves)
    doc: dict = {"study": "mf-fit", "data": [str(d) for d in data], "figures": list(FIGURES)}
    for path, value in values.items():
        node = doc
        for key in path[:-1]:
            node = node.setdefault(key, {})
        node[path[-1]] = value
    return config_from_mapping(doc, label="tirecli mf fit", base_dir=Path.cwd(), overrides=overrides)


def as_overrides(values: dict) -> list[str]:
    """``--set`` texts of :func:`settings` (for a written config: the command's options override its keys)."""
    return [f"{'.'.join(path)}={json.dumps(value)}" for path, value in values.items()]


def default_out(data: list[str]) -> Path:
    from tirecli.app.run import DEFAULT_OUT

    return DEFAULT_OUT / f"mf-fit-{Path(str(data[0])).stem}"


__all__ = ["is_config", "settings", "config_of", "as_overrides", "default_out", "parse_bounds", "parse_weights"]
