"""SYNTHETIC tyre rig data: the sweeps a force-and-moment rig measures, generated from a Magic Formula tyre.

:func:`synthetic_rig_data` evaluates a tyre (:func:`tirecli.models.magic_formula.evaluate`, ISO-W, SI,
combined slip) over the sweeps of :class:`RigPlan` and adds seeded Gaussian noise to the forces and
moments; it returns the channel table of :mod:`tirecli.io.measured`, labelled SYNTHETIC (comments and
header). The same plan, tyre and seed give the same values, bit for bit.

Sweeps, in this order, each its own measurement number ``run`` (at the tyre's nominal pressure and
``LONGVL`` unless said otherwise):

1. pure longitudinal: ``kappa`` from ``-kappa_max`` to ``kappa_max`` at each load;
2. pure lateral: ``alpha`` from ``-alpha_max`` to ``alpha_max`` at each load;
3. camber: the pure lateral sweep at the nominal load at each inclination of ``cambers``;
4. combined: the ``kappa`` sweep at the nominal load at each slip angle of ``combined_alphas``;
5. pressure: the pure longitudinal and lateral sweeps at the nominal load at each further pressure of
   ``pressures``.

With ``layout="grid"`` (the full factorial a fit of every load, camber and pressure term needs): a pure
longitudinal and a pure lateral sweep at every combination of the loads, the inclinations (zero and
``cambers``) and the pressures (every one of ``pressures``; the nominal pressure when it is empty), then
the combined sweeps at every load (zero inclination, the first pressure). ``combined_kappa`` replaces
the ``kappa`` values of the combined sweeps when given.

Slips, loads, cambers and pressures are kept inside the tyre's ranges (``KPUMIN/KPUMAX``,
``ALPMIN/ALPMAX``, ``FZMIN/FZMAX``, ``CAMMIN/CAMMAX``, ``PRESMIN/PRESMAX``), so no value of the data is
a clipped evaluation. Noise: for each of ``fx, fy, mz, mx, my`` independent normal values of standard
deviation ``noise`` times the channel's largest magnitude over the data set (``noise = 0.01``: 1 % of
the peak). Loads, slips and the other inputs are exact.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.io.measured import CANONICAL, Channel, MeasuredData, check_budget
from tirecli.io.output import SYNTHETIC_NOTE

_DEG = math.pi / 180.0


@dataclass(frozen=True)
class RigPlan:
    """The sweeps of a synthetic rig data set (SI units; see the module docstring).

    Attributes
    ----------
    loads : tuple of float
        Loads of the pure sweeps [N] (empty: 0.5, 1 and 1.5 times ``FNOMIN``).
    cambers : tuple of float
        Inclinations of the camber sweeps [rad] (each a lateral sweep at ``FNOMIN``).
    combined_alphas : tuple of float
        Slip angles of the combined sweeps [rad] (each a ``kappa`` sweep at ``FNOMIN``).
    pressures : tuple of float
        Further pressures [Pa] of pure sweeps at ``FNOMIN`` (empty: the nominal pressure only).
    kappa_max : float
        Largest slip ratio of a longitudinal sweep [-].
    alpha_max : float
        Largest slip angle of a lateral sweep [rad].
    points : int
        Samples per sweep.
    dt : float
        Time between samples [s].
    layout : str
        ``rig`` (the sweeps above) or ``grid`` (the full factorial; module docstring).
    combined_kappa : tuple
        ``kappa`` values of the combined sweeps (empty: those of the longitudinal sweeps).
    """

    loads: tuple = ()
    cambers: tuple = (2 * _DEG, 4 * _DEG)
    combined_alphas: tuple = (3 * _DEG, 6 * _DEG)
    pressures: tuple = ()
    kappa_max: float = 0.25
    alpha_max: float = 12 * _DEG
    points: int = 41
    dt: float = 0.1
    layout: str = "rig"
    combined_kappa: tuple = ()

    def __post_init__(self):
        if self.layout not in ("rig", "grid"):
            raise ValueError(f"RigPlan layout {self.layout!r}: expected 'rig' or 'grid'")

    def sweeps(self) -> int:
        """Number of sweeps (before the tyre's ranges are known)."""
        loads = len(self.loads) or 3
        if self.layout == "grid":
            levels = loads * (1 + len(self.cambers)) * max(len(self.pressures), 1)
            return 2 * levels + loads * len(self.combined_alphas)
        return 2 * loads + len(self.cambers) + len(self.combined_alphas) + 2 * len(self.pressures)

    def samples(self) -> int:
        """Number of rows (before the tyre's ranges are known)."""
        return self.sweeps() * self.points


def _inside(value: float, tire, var: str) -> float:
    lo, hi = tire.range(var)
    return float(min(max(value, lo), hi))


def _sweep(tire, name: str, limit: float, points: int) -> np.ndarray:
    """``points`` values from ``-limit`` to ``limit``, kept within the tyre's range of ``name``."""
    lo, hi = tire.range(name)
    return np.linspace(max(-limit, lo), min(limit, hi), points)


def plan_rows(tire, plan: RigPlan) -> list[dict]:
    """The sweeps of ``plan`` for ``tire``: dicts of ``kind`` and the input arrays/values."""
    fnom = float(tire.coef["FNOMIN"])
    loads = [_inside(f, tire, "fz") for f in (plan.loads or (0.5 * fnom, fnom, 1.5 * fnom))]
    nominal = _inside(fnom, tire, "fz")
    p0 = tire.default_pressure if tire.nominal_pressure else None
    kap = _sweep(tire, "kappa", plan.kappa_max, plan.points)
    alp = _sweep(tire, "alpha", plan.alpha_max, plan.points)
    zero = np.zeros(plan.points)
    if plan.layout == "grid":
        return _grid_rows(tire, plan, loads, p0, kap, alp)
    out = []
    for f in loads:
        out.append(dict(kind="pure longitudinal", kappa=kap, alpha=zero, gamma=0.0, fz=f, p=p0))
    for f in loads:
        out.append(dict(kind="pure lateral", kappa=zero, alpha=alp, gamma=0.0, fz=f, p=p0))
    for g in plan.cambers:
        out.append(dict(kind="camber", kappa=zero, alpha=alp, gamma=_inside(g, tire, "gamma"), fz=nominal, p=p0))
    for a in plan.combined_alphas:
        out.append(dict(kind="combined", kappa=kap, alpha=np.full(plan.points, _inside(a, tire, "alpha")), gamma=0.0,
                        fz=nominal, p=p0))
    for p in plan.pressures:
        pp = _inside(p, tire, "p")
        out.append(dict(kind="pressure", kappa=kap, alpha=zero, gamma=0.0, fz=nominal, p=pp))
        out.append(dict(kind="pressure", kappa=zero, alpha=alp, gamma=0.0, fz=nominal, p=pp))
    return out


def _grid_rows(tire, plan: RigPlan, loads, p0, kap, alp) -> list[dict]:
    """The sweeps of the ``grid`` layout (module docstring)."""
    pressures = [_inside(p, tire, "p") for p in plan.pressures] if p0 is not None and plan.pressures else [p0]
    cambers = list(dict.fromkeys([0.0, *(_inside(g, tire, "gamma") for g in plan.cambers)]))
    zero = np.zeros(plan.points)
    out = []
    for p in pressures:
        for g in cambers:
            for f in loads:
                out.append(dict(kind="pure longitudinal", kappa=kap, alpha=zero, gamma=g, fz=f, p=p))
                out.append(dict(kind="pure lateral", kappa=zero, alpha=alp, gamma=g, fz=f, p=p))
    ck = np.asarray(plan.combined_kappa, dtype=float) if len(plan.combined_kappa) else kap
    for f in loads:
        for a in plan.combined_alphas:
            out.append(dict(kind="combined", kappa=ck, alpha=np.full(ck.size, _inside(a, tire, "alpha")), gamma=0.0,
                            fz=f, p=pressures[0]))
    return out


def synthetic_rig_data(tire, label: str, plan: RigPlan = RigPlan(), noise: float = 0.0, seed: int = 1,
                       source: str = "<synthetic>") -> MeasuredData:
    """The SYNTHETIC channel table of ``plan`` for ``tire`` (see the module docstring).

    Parameters
    ----------
    tire : MFTire
        The generating tyre (its ``FNOMIN``, ``LONGVL`` and nominal pressure set the sweeps).
    label : str
        The tyre's name, for the comments.
    noise : float
        Standard deviation of the noise on the forces and moments, as a fraction of each channel's
        largest magnitude (0: exact values).
    seed : int
        Seed of the noise (``numpy.random.default_rng``).
    """
    import pandas as pd

    from tirecli.models.magic_formula import evaluate
    from tirecli.models.magic_formula.radius import effective_rolling_radius, has_radius

    sweeps = plan_rows(tire, plan)
    sizes = [max(np.size(s["kappa"]), np.size(s["alpha"])) for s in sweeps]
    n = int(sum(sizes))
    check_budget(source, n, 16)
    vx = float(tire.reference_speed or 16.7)
    cols = {k: np.empty(n) for k in ("t", "run", "kappa", "alpha", "gamma", "fz", "p", "vx")}
    ends = np.cumsum(sizes)
    for i, s in enumerate(sweeps):
        sl = slice(int(ends[i]) - sizes[i], int(ends[i]))
        cols["run"][sl] = i + 1
        cols["kappa"][sl] = s["kappa"]
        cols["alpha"][sl] = s["alpha"]
        cols["gamma"][sl] = s["gamma"]
        cols["fz"][sl] = s["fz"]
        cols["p"][sl] = s["p"] if s["p"] is not None else np.nan
        cols["vx"][sl] = vx
    cols["t"] = np.round(np.arange(n) * plan.dt, 9)
    if np.isnan(cols["p"]).any():  # a tyre without a pressure model: no pressure channel
        del cols["p"]
    res = evaluate(tire, cols["kappa"], cols["alpha"], cols["gamma"], cols["fz"], cols["vx"], cols.get("p"),
                   limits=True)
    rng = np.random.default_rng(seed)
    for k in ("fx", "fy", "mz", "mx", "my"):
        x = np.asarray(getattr(res, k), dtype=float).copy()
        if noise > 0:
            x += rng.normal(0.0, noise * float(np.max(np.abs(x))), n)
        cols[k] = x
    if has_radius(tire):
        re, omega = effective_rolling_radius(tire, cols["fz"], cols["kappa"], cols["vx"], cols.get("p"))
        cols["re"], cols["omega"] = np.asarray(re, dtype=float), np.asarray(omega, dtype=float)
    order = [c for c in CANONICAL if c in cols]
    frame = pd.DataFrame({c: cols[c] for c in order})
    channels = {c: Channel(c, CANONICAL[c][0], CANONICAL[c][1], "tirecli data synth") for c in order}
    kinds = ", ".join(f"{sum(s['kind'] == k for s in sweeps)} {k}" for k in dict.fromkeys(s["kind"] for s in sweeps))
    comments = [SYNTHETIC_NOTE,
                f"tyre: {label} (Magic Formula {tire.version}), evaluated by tirecli (ISO-W axes, SI units)",
                f"sweeps: {len(sweeps)} ({kinds}), {_samples(sizes)} each, {plan.dt:g} s apart",
                f"noise: normal, standard deviation {noise:g} x each force's and moment's largest magnitude; seed {seed}"]
    header = {"MEASID": f"synthetic-{label}", "SUPPLIER": "tirecli (SYNTHETIC DATA, not measured)"}
    if tire.side in ("left", "right"):
        header["TYRESIDE"] = tire.side.upper()
    constants = {"FNOMIN": (float(tire.coef["FNOMIN"]), "N"), "LONGVL": (vx, "m/s")}
    if tire.nominal_pressure:
        constants["NOMPRES"] = (float(tire.nominal_pressure), "Pa")
    frame.attrs["label"] = (f"SYNTHETIC rig sweeps generated by tirecli from {label} (MF {tire.version}), noise "
                            f"{100 * noise:g} % of each channel's peak, seed {seed}")
    return MeasuredData(frame, channels, source, "synthetic", "iso", header, comments, constants,
                        [f"generated from {label}"])


def _samples(sizes) -> str:
    lo, hi = min(sizes), max(sizes)
    return f"{lo} samples" if lo == hi else f"{lo} to {hi} samples"


def deg(*values) -> tuple:
    """Degrees to radians (a shorthand for sweep definitions: ``cambers=deg(-3, 3)``)."""
    return tuple(v * _DEG for v in values)


__all__ = ["deg", "RigPlan", "synthetic_rig_data", "plan_rows"]
