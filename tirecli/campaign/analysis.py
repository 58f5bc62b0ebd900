"""What a campaign's results say: statistics of each output, grid effects, sensitivity, checks.

* Statistics of each numeric output over the points that ran (count, mean, standard deviation,
  min, percentiles 5/50/95, max).
* Grids: the main effect of each grid key (the output's mean over the other keys at each of its
  values, with the min-max band) and the interaction of each pair of grid keys.
* Samples: Spearman rank correlation of each output with each sampled input (the tornado chart:
  inputs ranked by |rho|); with ``method: saltelli``, Sobol' first- and total-order indices with
  95 % confidence intervals by SALib (``SALib.analyze.sobol``, no second-order terms), per grid cell.
* Campaign checks (:class:`tirecli.studies.base.Check`): ``{output, max and/or min, statistic}``
  with ``statistic: all`` (default) bounding every point (a point without a value fails the check),
  or ``mean``, ``median``, ``pNN`` bounding that statistic; plus ``points-ran``: no point failed.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from tirecli.studies.base import Check


def numeric_outputs(results: pd.DataFrame, outputs: list) -> list:
    """The outputs whose column is numeric."""
    return [o for o in outputs if o in results and pd.api.types.is_numeric_dtype(results[o])]


def statistics(results: pd.DataFrame, outputs: list) -> dict:
    ok = results[results["status"] == "ok"] if "status" in results else results
    out = {}
    for o in numeric_outputs(results, outputs):
        x = ok[o].to_numpy(dtype=float)
        fin = x[np.isfinite(x)]
        rec = {"count": int(fin.size), "missing": int(x.size - fin.size)}
        if fin.size:
            p5, p50, p95 = np.percentile(fin, [5, 50, 95])
            rec.update(mean=float(fin.mean()), std=float(fin.std(ddof=1)) if fin.size > 1 else 0.0,
                       min=float(fin.min()), p5=float(p5), median=float(p50), p95=float(p95), max=float(fin.max()))
        out[o] = rec
    return out


def spearman(x: np.ndarray, y: np.ndarray) -> float:
    """Spearman's rank correlation of the finite pairs (NaN with fewer than 3 or a constant)."""
    from scipy.stats import spearmanr

    m = np.isfinite(x) & np.isfinite(y)
    if m.sum() < 3 or np.ptp(x[m]) == 0 or np.ptp(y[m]) == 0:
        return float("nan")
    return float(spearmanr(x[m], y[m]).statistic)


def tornado(results: pd.DataFrame, inputs: list, outputs: list) -> dict:
    """``{output: [{input, rho}, ...]}`` ranked by |rho| (numeric inputs only)."""
    out = {}
    for o in numeric_outputs(results, outputs):
        y = results[o].to_numpy(dtype=float)
        rows = []
        for k in inputs:
            if k in results and pd.api.types.is_numeric_dtype(results[k]):
                rows.append({"input": k, "rho": spearman(results[k].to_numpy(dtype=float), y)})
        out[o] = sorted(rows, key=lambda r: -abs(r["rho"]) if math.isfinite(r["rho"]) else 0.0)
    return out


def sobol_indices(design, results: pd.DataFrame, outputs: list) -> dict:
    """Sobol' first (S1) and total (ST) indices with 95 % confidence half-widths, per output and grid
    cell: ``{output: [{cell, input, S1, S1_conf, ST, ST_conf}, ...]}``; an output with a failed or
    empty point in a cell gets a note instead (the estimator needs every run)."""
    import warnings

    from tirecli.errors import require

    require("SALib", "method: saltelli (Sobol' indices)")
    from SALib.analyze import sobol

    keys = design.sample_keys
    problem = {"num_vars": len(keys), "names": list(keys), "bounds": [[0.0, 1.0]] * len(keys)}
    out = {}
    for o in numeric_outputs(results, outputs):
        rows, notes = [], []
        for cell in np.unique(design.cell):
            y = results[o].to_numpy(dtype=float)[design.cell == cell]
            if y.size != design.n * (len(keys) + 2) or not np.all(np.isfinite(y)):
                notes.append(f"cell {int(cell)}: {int((~np.isfinite(y)).sum())} point(s) without a value: no indices")
                continue
            if np.ptp(y) == 0:
                notes.append(f"cell {int(cell)}: the output does not vary")
                continue
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                si = sobol.analyze(problem, y, calc_second_order=False, seed=design.seed)
            for j, k in enumerate(keys):
                rows.append({"cell": int(cell), "input": k, "S1": float(si["S1"][j]), "S1_conf": float(si["S1_conf"][j]),
                             "ST": float(si["ST"][j]), "ST_conf": float(si["ST_conf"][j])})
        out[o] = {"indices": rows, "notes": notes}
    return out


def _statistic(x: np.ndarray, stat: str) -> float:
    if stat == "mean":
        return float(np.mean(x))
    if stat == "median":
        return float(np.median(x))
    return float(np.percentile(x, float(stat[1:])))


def campaign_checks(results: pd.DataFrame, checks: list, n_failed: int) -> list:
    """The campaign's checks (module doc) as :class:`Check` objects, ``points-ran`` first."""
    out = [Check("points-ran", "every point ran (failed points)", float(n_failed), 0.0, 0.0, "points",
                 "campaign", bound="max")]
    ok = results[results["status"] == "ok"]
    for c in checks:
        name = c["output"]
        x = ok[name].to_numpy(dtype=float) if name in ok and pd.api.types.is_numeric_dtype(ok[name]) else np.array([])
        stat = c["statistic"]
        for bound in ("max", "min"):
            ref = c[bound]
            if ref is None:
                continue
            cid = c["id"] or f"{name}-{bound}" + ("" if stat == "all" else f"-{stat}")
            if c["id"] and c["max"] is not None and c["min"] is not None:
                cid = f"{c['id']}-{bound}"
            sign = "<=" if bound == "max" else ">="
            if stat == "all":
                missing = int((~np.isfinite(x)).sum()) if x.size else 0
                value = float("nan") if not x.size or missing else float(np.max(x) if bound == "max" else np.min(x))
                what = f"every point: {name} {sign} {ref:g}" + (f" ({missing} point(s) without a value)" if missing else "")
            else:
                fin = x[np.isfinite(x)]
                value = _statistic(fin, stat) if fin.size else float("nan")
                what = f"{stat} of {name} over the points {sign} {ref:g}"
            out.append(Check(cid, c["description"] or what, value, float(ref), 0.0, "-", "campaign", bound=bound))
    return out


__all__ = ["statistics", "tornado", "sobol_indices", "campaign_checks", "numeric_outputs", "spearman"]
