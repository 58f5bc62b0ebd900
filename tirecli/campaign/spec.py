"""The campaign file, its design (a grid and/or samples) and its points.

::

    campaign: braking-sensitivity
    base: fm-fig4.yaml                  # any study config (a path relative to this file, a built-in
                                        # config name, or an inline mapping)
    set: {measurement: null}            # fixed overrides of every point (any --set key)
    vary:                               # a full grid over keys that --set accepts
      tire.mu_s: [1.2, 1.55, 1.8]
      vehicle.m: {start: 300, stop: 450, num: 4}
    sample:                             # and/or samples (every sample at every grid point)
      n: 1000
      seed: 1
      method: random                    # random | latin-hypercube | saltelli
      tire.sigma0: {normal: [181.54, 10]}
      input.theta: {uniform: [0.4, 1.0]}
    outputs: [peak_abs_slip, stopping_distance, v_final]
    keep: facts                         # facts | timeseries
    checks: [{output: stopping_distance, max: 40}]

Every point is the base config with the fixed and varied overrides applied exactly as ``--set``
would (:func:`tirecli.config.loader.set_value`); :func:`tirecli.campaign.check.check_points` checks all of them
before anything runs, and a problem names the campaign file's line of the key. A point is identified by
:func:`point_id`, a hash of its resolved config document and of the contents of the files the base
reads (parameter sets, data files).
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tirecli import limits
from tirecli.config.budget import run_spec
from tirecli.config.loader import Config, load_config, parse_key_path, set_value
from tirecli.config.schema import MISSING, Bool, Context, Grid, ListOf, Map, Nullable, Num, Raw, Spec, Str
from tirecli.errors import ConfigError, Problem, UsageError, require, token
from tirecli.io.yamlio import Origins, format_key

METHODS = ("random", "latin-hypercube", "saltelli")
KEEP = ("facts", "timeseries")
#: Distribution name -> (number of parameters, their meaning) (``{normal: [mean, sd]}``).
DISTRIBUTIONS = {
    "uniform": (2, "[low, high]"),
    "normal": (2, "[mean, standard deviation]"),
    "lognormal": (2, "[mu, sigma] of the logarithm"),
    "triangular": (3, "[low, mode, high]"),
    "truncnormal": (4, "[mean, standard deviation, low, high]"),
    "choice": (None, "[value, value, ...] (equally likely)"),
}
STATISTICS = ("all", "mean", "median", "p1", "p5", "p10", "p90", "p95", "p99")
SAMPLE_KEYS = ("n", "seed", "method")
#: Points a campaign may have (a guard against a typo such as num: 1000000).
MAX_POINTS = 10_000_000


@dataclass
class Distribution(Spec):
    """``{KIND: [parameters]}`` of one sampled key (:data:`DISTRIBUTIONS`)."""

    def check(self, value, path, ctx):
        forms = ", ".join(f"{{{k}: {v[1]}}}" for k, v in DISTRIBUTIONS.items())
        if not isinstance(value, dict) or len(value) != 1:
            ctx.fail(path, f"expected one distribution, one of: {forms}")
            return MISSING
        (kind, args), = value.items()
        if kind not in DISTRIBUTIONS:
            import difflib

            hint = difflib.get_close_matches(str(kind), list(DISTRIBUTIONS), n=1)
            ctx.fail(path + (kind,), "unknown distribution" + (f"; did you mean {hint[0]!r}?" if hint else "")
                     + f" (expected one of: {', '.join(DISTRIBUTIONS)})")
            return MISSING
        n, what = DISTRIBUTIONS[kind]
        if not isinstance(args, list) or (n is not None and len(args) != n) or not args:
            ctx.fail(path + (kind,), f"expected a list {what}")
            return MISSING
        if kind == "choice":
            return (kind, list(args))
        nums = ListOf(item=Num()).check(args, path + (kind,), ctx)
        if nums is MISSING:
            return MISSING
        bad = {
            "uniform": lambda a: None if a[0] < a[1] else "low must be below high",
            "normal": lambda a: None if a[1] > 0 else "the standard deviation must be > 0",
            "lognormal": lambda a: None if a[1] > 0 else "sigma must be > 0",
            "triangular": lambda a: None if a[0] <= a[1] <= a[2] and a[0] < a[2] else "expected low <= mode <= high, low < high",
            "truncnormal": lambda a: None if a[1] > 0 and a[2] < a[3] else "expected a standard deviation > 0 and low < high",
        }[kind](nums)
        if bad:
            ctx.fail(path + (kind,), bad)
            return MISSING
        return (kind, nums)


def ppf(dist: tuple, u: np.ndarray) -> list:
    """Values of the distribution ``(kind, parameters)`` at the probabilities ``u`` in (0, 1)."""
    from scipy import stats

    kind, a = dist
    u = np.asarray(u, dtype=float)
    inner = np.clip(u, 1e-12, 1.0 - 1e-12)  # the unbounded tails: no infinite values
    if kind == "uniform":
        x = a[0] + (a[1] - a[0]) * u
    elif kind == "normal":
        x = stats.norm.ppf(inner, a[0], a[1])
    elif kind == "lognormal":
        x = np.exp(stats.norm.ppf(inner, a[0], a[1]))
    elif kind == "triangular":
        x = stats.triang.ppf(u, (a[1] - a[0]) / (a[2] - a[0]), loc=a[0], scale=a[2] - a[0])
    elif kind == "truncnormal":
        x = stats.truncnorm.ppf(u, (a[2] - a[0]) / a[1], (a[3] - a[0]) / a[1], loc=a[0], scale=a[1])
    else:  # choice
        idx = np.minimum((u * len(a)).astype(int), len(a) - 1)
        return [copy.deepcopy(a[i]) for i in idx]
    return [float(v) for v in x]


CHECK = Map(fields={
    "output": Str(doc="an output name (outputs:)"),
    "max": Num(default=None, doc="upper bound"),
    "min": Num(default=None, doc="lower bound"),
    "statistic": Str(choices=STATISTICS, default="all",
                     doc="all (every point), mean, median or a percentile pNN of the output over the points"),
    "id": Str(default=None, doc="name of the check (default OUTPUT-max / OUTPUT-min)"),
    "description": Str(default="", doc="what the check means, in words"),
}, post=lambda v, p, ctx: ctx.fail(p, "give max and/or min") if v["max"] is None and v["min"] is None else None)

SPEC = Map(fields={
    "campaign": Str(doc="name of the campaign"),
    "title": Str(default="", doc="title"),
    "description": Str(default="", doc="free description"),
    "base": Raw(doc="the base study: a config file (relative to this file), a built-in config name, or a mapping"),
    "set": Map(open_keys=Raw(), default=None, doc="fixed overrides of every point: {KEY: VALUE}"),
    "unset": ListOf(item=Str(), default=[], min_len=0, doc="keys removed from the base (their defaults apply)"),
    "vary": Map(open_keys=Raw(), default=None, doc="grid: {KEY: [values] or {start, stop, num}}"),
    "sample": Map(fields={
        "n": Num(integer=True, ge=1, le=MAX_POINTS, doc="number of samples (saltelli: base sample N, N (D + 2) runs)"),
        "seed": Num(integer=True, ge=0, default=0, doc="random seed"),
        "method": Str(choices=METHODS, default="random", doc="random | latin-hypercube | saltelli"),
    }, open_keys=Distribution(), default=None),
    "outputs": ListOf(item=Str(), doc="names of the scalar facts of each run to tabulate"),
    "keep": Str(choices=KEEP, default="facts", doc="facts, or timeseries too (Parquet, one partition per point)"),
    "checks": ListOf(item=CHECK, default=[], min_len=0, doc="campaign-level checks on the outputs"),
    "batch": Nullable(spec=Num(integer=True, ge=1), default=None, doc="points per task (default: about half a second of work)"),
    "figures": Bool(default=True, doc="draw the analysis figures"),
    "timeout": Nullable(spec=Num(unit="s", gt=0), default=None,
                        doc="a point running longer fails with a timeout (process pool and in-process runs)"),
    "run": run_spec(),  # run.max_samples: the campaign's sample budget (its points x the samples of each run)
})


@dataclass
class Override:
    """One override of a point: key path, value, and where it was written (file, line)."""

    key: str
    path: tuple
    value: Any
    origin: tuple
    remove: bool = False  # ``unset:``: delete the key from the base


@dataclass
class Design:
    """The points of a campaign.

    Attributes
    ----------
    keys : list of str
        The varied keys (grid keys, then sampled keys): the columns of the results.
    grid_keys, sample_keys : list of str
    points : list of tuple
        One tuple of values (in ``keys`` order) per point, grid outer and samples inner.
    cell : ndarray of int
        The grid cell of each point (0 without a grid).
    unit : ndarray or None
        The samples' probabilities in the unit cube, ``(points, sample keys)`` (for the analysis).
    """

    keys: list
    grid_keys: list
    sample_keys: list
    points: list
    cell: np.ndarray
    unit: np.ndarray | None
    method: str | None = None
    n: int = 0
    seed: int = 0
    grid_values: dict = field(default_factory=dict)
    distributions: dict = field(default_factory=dict)

    def record(self) -> dict:
        rec = {"points": len(self.points), "grid": {k: self.grid_values[k] for k in self.grid_keys},
               "grid_cells": int(self.cell.max()) + 1 if len(self.cell) else 0}
        if self.sample_keys:
            rec["sample"] = {"method": self.method, "n": self.n, "seed": self.seed,
                             "runs_per_cell": len(self.points) // max(rec["grid_cells"], 1),
                             "distributions": {k: {d[0]: d[1]} for k, d in self.distributions.items()}}
        return rec


@dataclass
class Campaign:
    """A checked campaign file."""

    name: str
    title: str
    description: str
    label: str
    base: Config
    fixed: list
    overrides: dict  # varied key -> (path, origin)
    design: Design
    outputs: list
    keep: str
    checks: list
    batch: int | None
    figures: bool
    timeout: float | None
    document: dict
    origins: Origins
    #: The sample budget of the campaign and of each of its runs (``--max-samples``, else ``run.max_samples``;
    #: None: the default): run them under :func:`tirecli.limits.budget` of it.
    max_samples: int | None = None

    def point_overrides(self, values: tuple) -> list:
        """The overrides of the point with ``values`` (in ``design.keys`` order)."""
        return [Override(k, self.overrides[k][0], v, self.overrides[k][1]) for k, v in zip(self.design.keys, values)]


def _plain(obj):
    """A structural copy of YAML data (dicts, lists, scalars): much faster than ``copy.deepcopy``."""
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_plain(v) for v in obj]
    return obj


def _remove(data, origins: Origins, o) -> None:
    node = data
    for part in o.path[:-1]:
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            raise UsageError(f"unset {o.key}: the base has no {format_key(o.path)}") from None
    if not isinstance(node, dict) or o.path[-1] not in node:
        raise UsageError(f"unset {o.key}: the base has no {format_key(o.path)}")
    del node[o.path[-1]]
    origins.drop(o.path)


def point_config(base: Config, overrides) -> Config:
    """The base config with ``overrides`` (a list of :class:`Override`) applied, as ``--set`` does
    (an override with ``remove`` deletes its key)."""
    data = _plain(base.data)
    origins = Origins(default_file=base.origins.default_file, where=dict(base.origins.where))
    for o in overrides:
        if o.remove:
            _remove(data, origins, o)
        else:
            set_value(data, origins, o.path, o.value, f"{o.key}", o.origin)
    return Config(data=data, origins=origins, base_dir=base.base_dir, label=base.label)


def document_hash(config: Config) -> str:
    """SHA-256 of a config document (canonical JSON)."""
    blob = json.dumps(config.data, sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()


def point_id(doc_hash: str, inputs_digest: str = "") -> str:
    """A point's identity: 16 hex digits of the SHA-256 of its resolved config document (base with
    overrides, :func:`document_hash`) and of the contents of the files the base reads (``inputs_digest``)."""
    return hashlib.sha256(f"{doc_hash}\n{inputs_digest}".encode()).hexdigest()[:16]


def _load_base(raw, origins: Origins, campaign_dir: Path, label: str) -> Config:
    from tirecli.config.loader import _finish
    from tirecli.studies.configs import builtin_config, builtin_config_names

    if isinstance(raw, dict):
        sub = Origins(default_file=origins.default_file)
        sub.where.update({p[1:]: v for p, v in origins.where.items() if p[:1] == ("base",)})
        return _finish(_plain(raw), sub, campaign_dir, label, ())
    if not isinstance(raw, str) or not raw.strip():
        raise ConfigError(origins.problem(("base",), "expected a study config file, a built-in config name or a mapping"))
    path = Path(raw)
    full = path if path.is_absolute() else campaign_dir / path
    if not full.exists() and raw in builtin_config_names():
        return builtin_config(raw)
    if not full.exists():
        import difflib

        hint = difflib.get_close_matches(raw, builtin_config_names(), n=1)
        raise ConfigError(origins.problem(("base",), f"no such file {full}" + (f" and no built-in config {raw!r}; did you mean {hint[0]!r}?" if hint else "")))
    return load_config(full)


def _grid_values(key: str, raw, origins: Origins, ctx: Context):
    path = ("vary", key)
    if isinstance(raw, dict) and set(raw) <= {"start", "stop", "num"}:
        return Grid().check(raw, path, ctx)
    if isinstance(raw, list):
        if not raw:
            ctx.fail(path, "expected at least one value")
            return MISSING
        return raw
    return [raw]


def _design(doc: dict, origins: Origins, ctx: Context, budget=None) -> Design:
    """The design of the campaign document ``doc``; ``budget(points)`` (optional) is called with the number of
    points before any is made, to refuse a design over the sample budget."""
    grid = {}
    for key, raw in (doc["vary"] or {}).items():
        vals = _grid_values(key, raw, origins, ctx)
        if vals is not MISSING:
            grid[key] = [_plain(v) for v in vals]
    sample = doc["sample"]
    dists = {k: v for k, v in (sample or {}).items() if k not in SAMPLE_KEYS}
    if sample is not None and not dists:
        ctx.fail(("sample",), "no key to sample: add KEY: {uniform: [low, high]} (or normal, ...)")
    both = set(grid) & set(dists)
    for k in sorted(both):
        ctx.fail(("sample", k), "also under vary: a key is either varied on the grid or sampled")
    if not grid and not dists and not ctx.problems:
        ctx.fail((), "nothing to vary: give vary: and/or sample:")
    ctx.raise_if_any()
    if any(v is MISSING for v in dists.values()):
        ctx.raise_if_any()
    grid_keys, sample_keys = list(grid), list(dists)
    # the number of points before any is made (a grid of 10^6 x 10^6 must not be built to be refused)
    n_cells = math.prod(len(grid[k]) for k in grid_keys)
    n_samples = 1
    if sample_keys:
        n_samples = sample["n"] * (len(sample_keys) + 2 if sample["method"] == "saltelli" else 1)
    total = n_cells * n_samples
    if total > MAX_POINTS:
        raise ConfigError(origins.problem(("vary",) if grid_keys else ("sample",),
                                          f"{total:,} points: more than {MAX_POINTS:,}"))
    if sample_keys and sample["method"] == "saltelli":
        require("SALib", "method: saltelli")  # before the budget checks a point's run
    if budget is not None:
        budget(total)
    cells = list(itertools.product(*[grid[k] for k in grid_keys])) if grid_keys else [()]
    unit = None
    samples: list = [()]
    method, n, seed = None, 0, 0
    if sample_keys:
        method, n, seed = sample["method"], sample["n"], sample["seed"]
        d = len(sample_keys)
        unit = unit_sample(method, n, d, seed, sample_keys)
        cols = [ppf(dists[k], unit[:, j]) for j, k in enumerate(sample_keys)]
        samples = list(zip(*cols))
    points = [tuple(c) + tuple(s) for c in cells for s in samples]
    cell = np.repeat(np.arange(n_cells), len(samples))
    if unit is not None:
        unit = np.tile(unit, (n_cells, 1))
    return Design(keys=grid_keys + sample_keys, grid_keys=grid_keys, sample_keys=sample_keys, points=points,
                  cell=cell, unit=unit, method=method, n=n, seed=seed, grid_values=grid, distributions=dists)


def unit_sample(method: str, n: int, d: int, seed: int, names=None) -> np.ndarray:
    """Points in the unit cube ``[0, 1)^d``: ``random`` (numpy's default generator), ``latin-hypercube``
    (scipy.stats.qmc) or ``saltelli`` (SALib's Saltelli/Sobol' scheme without second-order terms:
    ``n (d + 2)`` rows in SALib's order, for :func:`tirecli.campaign.analysis.sobol_indices`)."""
    rng = np.random.default_rng(seed)
    if method == "random":
        return rng.random((n, d))
    if method == "latin-hypercube":
        from scipy.stats import qmc

        return qmc.LatinHypercube(d=d, rng=rng).random(n)
    import warnings


    require("SALib", "method: saltelli")  # before any point is made
    from SALib.sample import sobol

    problem = {"num_vars": d, "names": list(names or [f"x{i}" for i in range(d)]), "bounds": [[0.0, 1.0]] * d}
    with warnings.catch_warnings():  # SALib's note that n is best a power of 2: documented
        warnings.simplefilter("ignore")
        return np.asarray(sobol.sample(problem, n, calc_second_order=False, seed=seed), dtype=float)


def _check_outputs_checked(doc: dict, ctx: Context) -> None:
    """Each campaign check names one of the outputs: a check on an output the campaign does not compute
    would have no value to check (and pass)."""
    outputs, checks = doc.get("outputs"), doc.get("checks")
    if not isinstance(outputs, list) or not isinstance(checks, list):
        return
    for j, check in enumerate(checks):
        name = check.get("output") if isinstance(check, dict) else MISSING
        if isinstance(name, str) and name not in outputs:
            ctx.fail(("checks", j, "output"), f"{token(name)} is not one of the campaign's outputs "
                                              f"({', '.join(map(str, outputs))}): add it to outputs: or check another")


def load_campaign(path: str | Path, max_samples: int | None = None) -> Campaign:
    """Read and check a campaign file (the design too, not the points: :func:`check_points`); its points count
    against the sample budget (``max_samples``, else the file's ``run.max_samples``, else the default)."""
    from tirecli.config.loader import TIR_USE
    from tirecli.io.yamlio import load_yaml_document, require_kind

    path = Path(path)
    data, origins = load_yaml_document(path, "a campaign file", TIR_USE)
    if not isinstance(data, dict):
        raise ConfigError(Problem(str(path), 1, "", "expected a YAML mapping of keys at the top level"))
    require_kind(data, origins, "a campaign file", {*SPEC.fields, "study"},
                 "a campaign key (campaign, base, vary, sample, outputs, ...)")
    if "campaign" not in data and "study" in data:
        raise ConfigError(origins.problem(("study",), f"a study config, not a campaign (run it with 'tirecli "
                                          f"{data.get('study')}', or name it as base: of a campaign file)"))
    ctx = Context(origins)
    doc = SPEC.check(data, (), ctx)
    _check_outputs_checked(doc, ctx)
    ctx.raise_if_any()
    base = _load_base(doc["base"], origins, path.parent, str(path))
    fixed, problems = _fixed_overrides(doc, origins)

    def budget(points: int) -> None:
        if not problems:
            _check_budget(base, fixed, points, origins)

    if max_samples is None and doc["run"] is not None:
        max_samples = doc["run"]["max_samples"]
    with limits.budget(max_samples):
        design = _design(doc, origins, Context(origins), budget)
    overrides = {}
    for key in design.keys:
        where = ("vary", key) if key in design.grid_keys else ("sample", key)
        try:
            kp = parse_key_path(key)
        except UsageError as err:
            problems.append(origins.problem(where, str(err).replace("--set: ", "")))
            continue
        overrides[key] = (kp, origins.of(where))
    for k in (doc["set"] or {}):
        if k in design.keys:
            problems.append(origins.problem(("set", k), "also varied: a key is either fixed (set) or varied"))
    if problems:
        raise ConfigError(problems)
    return Campaign(name=doc["campaign"], title=doc["title"], description=doc["description"], label=str(path),
                    base=base, fixed=fixed, overrides=overrides, design=design, outputs=list(doc["outputs"]),
                    keep=doc["keep"], checks=doc["checks"], batch=doc["batch"], figures=doc["figures"],
                    timeout=doc["timeout"], document=data, origins=origins, max_samples=max_samples)


def _fixed_overrides(doc: dict, origins: Origins) -> tuple[list, list]:
    """The overrides of every point (``set:`` and ``unset:``, removals first) and the problems of their keys."""
    fixed, problems = [], []
    for key in doc["set"] or {}:
        try:
            fixed.append(Override(key, parse_key_path(key), _plain(doc["set"][key]), origins.of(("set", key))))
        except UsageError as err:
            problems.append(origins.problem(("set", key), str(err).replace("--set: ", "")))
    for j, key in enumerate(doc["unset"]):
        try:
            fixed.insert(0, Override(key, parse_key_path(key), None, origins.of(("unset", j)), remove=True))
        except UsageError as err:
            problems.append(origins.problem(("unset", j), str(err).replace("--set: ", "")))
    return fixed, problems


def point_samples(base: Config, fixed: list) -> float:
    """The samples one point's run needs, as its study estimates them for the base with the fixed overrides
    (:func:`tirecli.limits.recorded_estimates`; at least 1: the point's row of the results). A base the study
    refuses counts 1 (each point's own check then names the problem)."""
    from tirecli.studies.registry import check as check_study

    with limits.recorded_estimates() as seen, limits.budget(limits.MAX_MAX_SAMPLES):
        try:
            check_study(point_config(base, fixed))
        except (ConfigError, UsageError):
            pass
    return max([1.0, *seen])


def _check_budget(base: Config, fixed: list, points: int, origins: Origins) -> None:
    """Count the campaign's points against the sample budget like every other run, before its design is made:
    ``points`` x the samples of one point's run (:func:`point_samples`); over the budget, ConfigError at the
    sample size (or the grid) with the estimate and the option that raises it."""
    per_point = point_samples(base, fixed)
    what = f"{points:,} point(s) x {limits.count_text(per_point)} samples per run"
    limits.Estimate().add(points * per_point, (("sample", "n"), ("sample",), ("vary",)), what, 0.0).check(origins)


def inputs_digest(paths, exclude=()) -> str:
    """SHA-256 over the contents of the files ``paths`` (sorted), except ``exclude``."""
    import os

    from tirecli.io.files import read_own_file

    skip = {os.path.realpath(p) for p in exclude}
    h = hashlib.sha256()
    for p in sorted(set(paths) - skip):  # read as they were (a FIFO or a device swapped in since hashes as unreadable)
        data = read_own_file(p, limits.csv_max_bytes(), follow=True)
        h.update(b"?" if data is None else data)
    return h.hexdigest()


def value_text(v) -> Any:
    """A varied value as a results cell: numbers as numbers, anything else as compact JSON."""
    if isinstance(v, bool) or v is None or isinstance(v, (dict, list)):
        return json.dumps(v, sort_keys=True)
    if isinstance(v, (int, float)):
        return float(v) if not isinstance(v, float) or math.isfinite(v) else float("nan")
    return str(v)


__all__ = ["Campaign", "Design", "Override", "load_campaign", "point_config", "point_id",
           "unit_sample", "ppf", "DISTRIBUTIONS", "METHODS", "value_text", "format_key"]
