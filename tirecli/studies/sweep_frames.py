"""The frames of a LuGre steady-state sweep: ``sweep`` (mu over slip x speed x theta x variant) and ``peaks``
(one row per curve); their columns are described in :mod:`tirecli.studies.sweep`.

Used by the ``sweep`` study and by the Magic Formula sweep's LuGre comparison (:mod:`tirecli.studies.mf_sweep`).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from tirecli.conventions import speeds_from_slip, theta_obs_from_fm
from tirecli.models import lugre
from tirecli.models.steady_peaks import curve_peaks

if TYPE_CHECKING:  # pandas is imported when a frame is made, not when a config is checked
    import pandas as pd


#: Grid points evaluated at a time by :func:`sweep_frame` (the model's temporaries stay a few MB).
BLOCK_POINTS = 65536


def sweep_frame(variants, p, slips, speeds, thetas_fm, progress=None, block: int | None = None) -> pd.DataFrame:
    """Evaluate every variant over slip x speed x theta; long-format frame (:mod:`tirecli.studies.sweep`).

    Rows: for each variant, theta, held speed, the slips in order. The points are evaluated in blocks
    of ``block`` (default :data:`BLOCK_POINTS`) into the frame's columns, so memory holds the frame
    and one block's temporaries; every point is computed on its own, so the values do not depend
    on the block size. The slip x speed columns (``speed, v, romega, slip``, the direction) are
    computed for the first (variant, theta) and copied for the others. A column with one value in
    every row (``theta`` and ``theta_obs`` of a single adhesion, ``kappa0`` and ``Z`` without lumped
    models) is stored once (a read-only broadcast view); ``model`` and ``direction`` are categoricals.
    """
    import pandas as pd

    slips = np.asarray(slips, dtype=float)
    speeds = np.asarray(speeds, dtype=float)
    block = max(int(block or BLOCK_POINTS), 1)
    grid = slips.size * speeds.size  # rows of one (variant, theta)
    n = grid * len(variants) * len(thetas_fm)
    order = ("speed", "v", "romega", "theta", "theta_obs", "slip", "mu", "kappa0", "Z")
    const = _constant_columns(variants, p, thetas_fm)
    stored = [c for c in order if c not in const]
    cols = dict(zip(stored, np.empty((len(stored), n))))  # the frame's float columns, filled in place
    labels = [v.label for v in variants]
    model = np.empty(n, dtype=np.min_scalar_type(-len(variants)))  # code of the variant's label (sorted labels)
    rank = {label: k for k, label in enumerate(sorted(labels))}
    braking = np.empty(n, dtype=bool)
    first = slice(0, grid)  # the rows of the first (variant, theta)
    if progress is not None:
        progress.start(max(n // block, 1), "sweep")
    at = 0
    for var in variants:
        k0 = var.lumped_kappa0(p) if var.model == "lumped" else None
        for th in thetas_fm:
            group = slice(at, at + grid)
            model[group] = rank[var.label]
            if "theta" in cols:
                cols["theta"][group] = th
                cols["theta_obs"][group] = float(theta_obs_from_fm(th))
            if at:  # the slip x speed columns of the first (variant, theta)
                for c in ("speed", "v", "romega", "slip"):
                    cols[c][group] = cols[c][first]
                braking[group] = braking[first]
            for lo in range(0, grid, block):
                hi = min(lo + block, grid)
                rows = slice(at + lo, at + hi)
                if not at:
                    idx = np.arange(lo, hi)
                    S, V = slips[idx % slips.size], speeds[idx // slips.size]  # rows: speed, then slip
                    cols["speed"][rows], cols["slip"][rows] = V, S
                    cols["v"][rows], cols["romega"][rows] = speeds_from_slip(S, V)
                    braking[rows] = S <= 0.0
                v, romega = cols["v"][rows], cols["romega"][rows]
                vr = romega - v
                cols["mu"][rows] = var.mu_ss(vr, romega, p, th)
                if var.model == "lumped":
                    x = lugre.patch_ratio(vr, romega, p, th)
                    if "kappa0" in cols:
                        cols["kappa0"][rows] = lugre.kappa0_of_x(x) if k0 == "Z" else float(k0)
                    with np.errstate(divide="ignore"):
                        cols["Z"][rows] = p.L / x  # x = L/Z; 0 -> inf (no slip), inf -> 0 (locked wheel)
                else:
                    for c in ("kappa0", "Z"):
                        if c in cols:
                            cols[c][rows] = np.nan
                if progress is not None:
                    progress.advance(1)
            at += grid
    if progress is not None:
        progress.close()
    # text columns as categoricals of their few values (a byte per row, no string per row); categories
    # sorted, so that they order as the texts do
    data = {"model": pd.Categorical.from_codes(model, categories=_texts(sorted(labels))),
            "direction": pd.Categorical.from_codes(1 - braking.view(np.int8),
                                                   categories=_texts(["braking", "driving"]))}
    for c in order:
        data[c] = cols[c] if c in cols else np.broadcast_to(np.float64(const[c]), n)
    return pd.DataFrame(data, copy=False)


def _constant_columns(variants, p, thetas_fm) -> dict:
    """The float columns of :func:`sweep_frame` that hold one value in every row: ``{name: value}``."""
    const = {}
    if len(thetas_fm) == 1:
        const["theta"] = float(thetas_fm[0])
        const["theta_obs"] = float(theta_obs_from_fm(thetas_fm[0]))
    k0 = {v.lumped_kappa0(p) if v.model == "lumped" else "nan" for v in variants}  # "nan": distributed
    if len(k0) == 1 and "Z" not in k0:  # every variant distributed, or lumped with the same constant
        const["kappa0"] = float(k0.pop())
    if all(v.model != "lumped" for v in variants):
        const["Z"] = np.nan
    return const


def _texts(values):
    """The categories of a text column of :func:`sweep_frame` (pandas' text dtype)."""
    import pandas as pd

    return pd.Index(np.array(values, dtype=object), dtype="str")


PEAK_COLUMNS = ["model", "variant", "load", "lambda", "kappa0", "direction", "speed", "theta", "theta_obs",
                "slip_peak", "mu_peak", "mu_slide"]


def peaks_frame(variants, p, slips, speeds, thetas_fm, progress=None) -> pd.DataFrame:
    """One row per curve of a sweep: its identifying columns and its root-found peak (:mod:`tirecli.studies.sweep`).

    A direction has curves when the sweep has slips of that sign (``s < 0`` braking, ``s > 0``
    driving). Peaks are taken over the whole range ``0 < |s| <= 1`` whatever the sweep's grid
    (:func:`tirecli.models.steady_peaks.curve_peaks`).
    """
    import pandas as pd

    slips = np.asarray(slips, dtype=float)
    speeds = np.asarray(speeds, dtype=float)
    directions = [d for d, sign in (("braking", -1.0), ("driving", 1.0)) if np.any(slips * sign > 0.0)]
    rows = []
    if progress is not None:
        progress.start(len(variants) * len(thetas_fm), "peaks")
    for var in variants:
        k0 = var.lumped_kappa0(p) if var.model == "lumped" else None
        ident = {"model": var.label, "variant": var.model, "load": var.load,
                 "lambda": float(var.lam) if var.load == "exponential" else np.nan,
                 "kappa0": k0 if k0 == "Z" or k0 is None else float(k0)}
        for th in thetas_fm:
            for direction in directions:
                sign = -1.0 if direction == "braking" else 1.0
                pk = curve_peaks(var, p, speeds, th, braking=direction == "braking")
                for j, speed in enumerate(speeds):
                    rows.append(ident | {
                        "direction": direction, "speed": float(speed), "theta": float(th),
                        "theta_obs": float(theta_obs_from_fm(th)),
                        "slip_peak": sign * float(pk.slip[j]), "mu_peak": sign * float(pk.mu[j]),
                        "mu_slide": sign * float(pk.mu_slide[j]),
                    })
            if progress is not None:
                progress.advance(1)
    if progress is not None:
        progress.close()
    df = pd.DataFrame(rows, columns=PEAK_COLUMNS)
    df["kappa0"] = df["kappa0"].astype(object)
    return df


def peak_records(peaks: pd.DataFrame) -> list[dict]:
    """The rows of a peaks frame as JSON-ready dicts (NaN and empty cells become null)."""
    out = []
    for row in peaks.to_dict(orient="records"):
        out.append({k: (None if v is None or (isinstance(v, float) and not np.isfinite(v)) else v)
                    for k, v in row.items()})
    return out


__all__ = ["sweep_frame", "peaks_frame", "peak_records", "PEAK_COLUMNS", "BLOCK_POINTS"]
