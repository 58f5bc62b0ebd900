"""The measured points of a Magic Formula fit: checks, sweeps, load/camber/pressure levels.

Input: a table (a pandas DataFrame or a mapping of columns) with one row per measured point and the
columns of ``tirecli mf eval`` (ISO-W, SI):

- inputs ``kappa`` [-], ``alpha`` [rad], ``gamma`` [rad], ``fz`` [N] (> 0), ``p`` [Pa], ``vx`` [m/s];
  ``gamma`` may be absent (0), ``p`` and ``vx`` too (the start tyre's ``INFLPRES`` and ``LONGVL``);
- measured ``fx``, ``fy`` [N], ``mz`` [N m] (at least one; a NaN cell is a channel not measured at that
  point); ``mx``, ``my``, ``run`` are carried along;
- optional ``weight`` (>= 0): the point's weight in the sums of squares.

A point belongs to the pure longitudinal sweeps when ``|alpha| <= alpha_tol``, to the pure lateral sweeps
when ``|kappa| <= kappa_tol`` (a free-rolling point at zero slip angle belongs to both), and to the
combined sweeps otherwise. Loads, inclinations and pressures are grouped into levels: sorted values
split where two neighbours differ by more than the tolerance (:func:`levels`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import DataError

INPUTS = ("kappa", "alpha", "gamma", "fz", "p", "vx")
CHANNELS = ("fx", "fy", "mz")
EXTRA = ("mx", "my", "run")
SWEEPS = ("longitudinal", "lateral", "combined")


@dataclass
class Levels:
    """Levels of one input: ``centres`` (sorted medians) and each point's level ``index``; ``count`` is the
    number of distinct levels, a level spread wider than twice the tolerance counting as several."""

    centres: np.ndarray
    index: np.ndarray
    count: int

    def nearest(self, value: float) -> int:
        """Index of the level nearest ``value``."""
        return int(np.argmin(np.abs(self.centres - value)))


def levels(x: np.ndarray, tol: float) -> Levels:
    """Group values into levels (gap clustering with tolerance ``tol``)."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return Levels(np.empty(0), np.empty(0, dtype=int), 0)
    order = np.argsort(x, kind="stable")
    xs = x[order]
    lab = np.zeros(x.size, dtype=int)
    lab[1:] = np.cumsum(np.diff(xs) > tol)
    index = np.empty(x.size, dtype=int)
    index[order] = lab
    k = int(lab[-1]) + 1
    bounds = np.flatnonzero(np.diff(lab)) + 1
    parts = np.split(xs, bounds)
    centres = np.array([float(np.median(p)) for p in parts])
    count = sum(1 + int((p[-1] - p[0]) // (2 * tol)) if tol > 0 else 1 for p in parts)
    assert len(centres) == k
    return Levels(centres, index, int(count))


@dataclass
class Census:
    """What a set of points holds: load, camber and pressure levels, and the slip signs."""

    n: int
    loads: Levels
    cambers: Levels
    pressures: Levels | None
    met: dict = field(default_factory=dict)  # need (stages.NEEDS key) -> bool

    def describe(self) -> str:
        parts = [f"{self.n} point(s)", "loads " + _fmt_levels(self.loads.centres, "N", 0)]
        parts.append("inclinations " + _fmt_levels(np.degrees(self.cambers.centres), "deg", 2))
        if self.pressures is not None:
            parts.append("pressures " + _fmt_levels(self.pressures.centres / 1e5, "bar", 3))
        return ", ".join(parts)


def _fmt_levels(c, unit: str, nd: int) -> str:
    shown = ", ".join(f"{v:.{nd}f}" for v in c[:8]) + (f" ... ({len(c)} levels)" if len(c) > 8 else "")
    return f"{shown} {unit}" if len(c) else "none"


@dataclass
class FitData:
    """The checked points of a fit (SI arrays of one length).

    Attributes
    ----------
    inputs : dict
        ``kappa, alpha, gamma, fz, vx`` and ``p`` (None when the tyre has no pressure effect).
    channels : dict
        Measured ``fx``, ``fy``, ``mz`` present in the data (NaN: not measured at that point).
    weight : ndarray
        Point weights (1 without a ``weight`` column).
    extra : dict
        ``mx``, ``my``, ``run`` when given (carried to the per-point table).
    sweep : dict
        ``longitudinal``, ``lateral``, ``combined`` -> boolean mask of the points; and the selections
        ``alpha`` (slip angle non-zero), ``kappa`` (slip non-zero), ``all``.
    notes : list of str
        What was assumed (defaulted columns).
    """

    n: int
    inputs: dict
    channels: dict
    weight: np.ndarray
    extra: dict
    sweep: dict
    notes: list

    def subset(self, mask) -> dict:
        """The inputs at the masked points."""
        return {k: (None if v is None else v[mask]) for k, v in self.inputs.items()}


def _column(df, name: str) -> np.ndarray:
    """A numeric column as float; DataError naming the column and the first row that is not a number."""
    raw = df[name]
    values = np.asarray(raw)
    if values.dtype.kind in "biuf":
        return values.astype(float)
    out = np.empty(len(values))
    for i, v in enumerate(values):
        try:
            if isinstance(v, (bool, np.bool_)):
                raise TypeError
            out[i] = float(v)
        except (TypeError, ValueError):
            raise DataError(f"column {name!r}, row {i + 1}: not a number ({str(v)[:40]!r})") from None
    return out


def check_data(df, tire, options) -> FitData:
    """Check the point table against the start tyre and the options; DataError (one line) for a table
    that cannot be fitted: a missing or non-numeric column, NaN or infinite inputs, loads <= 0, slips
    that look like percent or degrees, no measured channel, negative weights."""
    try:
        columns = list(df.columns)
    except AttributeError:
        columns = list(df)
    cols = {str(c).lower(): c for c in columns}
    for name in ("kappa", "alpha", "fz"):
        if name not in cols:
            raise DataError(f"the data have no {name!r} column (expected the columns kappa, alpha, gamma, fz, p, vx "
                            f"and measured fx, fy, mz; found {', '.join(map(str, columns[:12]))})")
    n = len(df[cols["kappa"]])
    if n == 0:
        raise DataError("the data hold no points")
    notes = []
    x = {}
    for name in INPUTS:
        if name in cols:
            x[name] = _column(df, cols[name])
            bad = ~np.isfinite(x[name])
            if bad.any():
                i = int(np.argmax(bad))
                raise DataError(f"column {name!r}, row {i + 1}: {x[name][i]!r} (every input must be a finite number)")
    if "gamma" not in x:
        x["gamma"] = np.zeros(n)
        notes.append("no gamma column: inclination 0")
    if "vx" not in x:
        v0 = tire.reference_speed
        if v0 is None:
            raise DataError("the data have no 'vx' column and the start tyre has no reference speed LONGVL")
        x["vx"] = np.full(n, float(v0))
        notes.append(f"no vx column: the start tyre's LONGVL {v0:g} m/s")
    if tire.nominal_pressure is None:
        x["p"] = None
        if "p" in cols:
            notes.append("the start tyre has no NOMPRES: pressure has no effect and the p column is not used")
    elif "p" not in x:
        x["p"] = np.full(n, float(tire.default_pressure))
        notes.append(f"no p column: the start tyre's INFLPRES {tire.default_pressure:g} Pa")
    if (x["fz"] <= 0).any():
        i = int(np.argmax(x["fz"] <= 0))
        raise DataError(f"column 'fz', row {i + 1}: {x['fz'][i]:g} N (loads must be > 0, compression, ISO-W)")
    if np.abs(x["kappa"]).max() > 10:
        raise DataError(f"column 'kappa' reaches {np.abs(x['kappa']).max():g}: slip ratio expected as a fraction "
                        "(-1 locked), not in percent")
    for name, lim in (("alpha", math.pi / 2), ("gamma", math.pi / 4)):
        if np.abs(x[name]).max() > lim:
            raise DataError(f"column {name!r} reaches {np.abs(x[name]).max():g} rad: angles expected in radians, "
                            "not degrees")
    if x["p"] is not None and (x["p"] <= 0).any():
        i = int(np.argmax(x["p"] <= 0))
        raise DataError(f"column 'p', row {i + 1}: {x['p'][i]:g} Pa (pressures must be > 0)")
    weights = options.weights or {}
    ch = {}
    for name in CHANNELS:
        if name in cols and weights.get(name, 1.0) > 0:
            v = _column(df, cols[name])
            if np.isinf(v).any():
                i = int(np.argmax(np.isinf(v)))
                raise DataError(f"column {name!r}, row {i + 1}: infinite value")
            if np.isfinite(v).any():
                ch[name] = v
    if not ch:
        raise DataError("the data hold no measured fx, fy or mz (at least one channel with values is needed)")
    w = np.ones(n)
    if "weight" in cols:
        w = _column(df, cols["weight"])
        if not np.isfinite(w).all() or (w < 0).any():
            i = int(np.argmax(~np.isfinite(w) | (w < 0)))
            raise DataError(f"column 'weight', row {i + 1}: {w[i]!r} (weights must be finite and >= 0)")
    extra = {}
    for name in EXTRA:
        if name in cols:
            extra[name] = np.asarray(df[cols[name]])
    pure_long = np.abs(x["alpha"]) <= options.alpha_tol
    pure_lat = np.abs(x["kappa"]) <= options.kappa_tol
    sweep = {"longitudinal": pure_long, "lateral": pure_lat, "combined": ~pure_long & ~pure_lat}
    sweep.update({"alpha": ~pure_long, "kappa": ~pure_lat, "all": np.ones(n, bool)})
    return FitData(n=n, inputs=x, channels=ch, weight=w, extra=extra, sweep=sweep, notes=notes)


def census(data: FitData, mask: np.ndarray, options, tire) -> Census:
    """Levels and the data needs (:data:`~.stages.NEEDS`) met by the masked points."""
    x = data.subset(mask)
    fz0 = tire.coef["FNOMIN"]
    loads = levels(x["fz"], options.load_tol * fz0)
    cambers = levels(x["gamma"], options.camber_tol)
    pressures = None if x["p"] is None else levels(x["p"], options.pressure_tol)
    c = Census(n=int(np.count_nonzero(mask)), loads=loads, cambers=cambers, pressures=pressures)
    sweep_c = cambers.count >= 2 and bool(np.any(np.abs(cambers.centres) > options.camber_tol))
    np_ = 0 if pressures is None else pressures.count
    c.met = {
        "loads2": loads.count >= 2, "loads3": loads.count >= 3, "camber": sweep_c,
        "camber_loads": sweep_c and _sweep_at_levels(x["gamma"], loads.index, options.camber_tol) >= 2,
        "pressures2": np_ >= 2, "pressures3": np_ >= 3,
        "camber_pressures": sweep_c and pressures is not None
        and _sweep_at_levels(x["gamma"], pressures.index, options.camber_tol) >= 2,
        "pressure_loads": np_ >= 2 and loads.count >= 2,
        "kappa_both": bool(np.any(x["kappa"] > options.kappa_tol) and np.any(x["kappa"] < -options.kappa_tol)),
        "alpha_both": bool(np.any(x["alpha"] > options.alpha_tol) and np.any(x["alpha"] < -options.alpha_tol)),
    }
    return c


def _sweep_at_levels(gamma, index, tol) -> int:
    """Number of levels (of load or pressure) at which the inclination takes two or more levels."""
    n = 0
    for k in np.unique(index):
        g = gamma[index == k]
        if g.size and g.max() - g.min() > tol:
            n += 1
    return n
