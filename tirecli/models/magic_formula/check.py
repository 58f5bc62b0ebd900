"""Sanity checks of Magic Formula coefficients, in the spirit of mfeval's coefficient check.

The Magic Formula is well behaved only within limits (docs/models/magic_formula_tyre.md §5, §6, §13.1): shape
factors ``C > 0`` (and below 2, else the force changes sign at large slip), peaks ``D`` with a
fixed sign (``D <= 0`` for ``Fx`` flips the curve), curvatures ``E <= 1`` (``E > 1`` makes the
curve unstable: it turns back), weighting-function slopes ``B_xa, B_yk > 0``, a slip stiffness
``K_xk > 0``, a cornering stiffness that keeps its sign. :func:`check_coefficients` evaluates
these over the tyre's load, camber, pressure, slip and slip-angle ranges (the nominal point where
a range is missing) and also reports ranges that exclude the nominal point.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.models.magic_formula.curve import _cos_atan
from tirecli.models.magic_formula.pure import fx0_factors, fy0_factors
from tirecli.models.magic_formula.state import basic
from tirecli.models.magic_formula.tire import CONVENTIONS, MFTire


@dataclass(frozen=True)
class Finding:
    """One result of the check: ``level`` is ``error`` or ``warning``; ``key`` the coefficient(s)."""

    level: str
    key: str
    message: str

    def __str__(self) -> str:
        return f"{self.level}: {self.key}: {self.message}"


def _grid(t: MFTire, var: str, default, num: int):
    lo, hi = t.range(var)
    if math.isfinite(lo) and math.isfinite(hi):
        return np.linspace(lo, hi, num)
    return np.asarray(default, dtype=float)


def _where(values, grid) -> str:
    i = int(np.argmax(values)) if np.ndim(values) else 0
    return f" (at {grid[i]:g})" if np.ndim(values) and len(grid) > 1 else ""


def check_coefficients(t: MFTire) -> list[Finding]:
    """Findings for a tyre (empty list: nothing to report). Errors make curves unusable."""
    out: list[Finding] = []
    c = t.coef

    def err(key, msg):
        out.append(Finding("error", key, msg))

    def warn(key, msg):
        out.append(Finding("warning", key, msg))

    if t.family == "pac89":
        _check_pac89(t, err)
        return out
    fz0 = c["FNOMIN"]
    fz = _grid(t, "fz", [fz0], 9)
    fz = fz[fz > 0] if (fz > 0).any() else np.array([fz0])
    lo, hi = t.range("fz")
    if not (lo <= fz0 <= hi):
        err("FNOMIN", f"the load range [{lo:g}, {hi:g}] N excludes the nominal load {fz0:g} N")
    for var, key in (("kappa", "KPUMIN/KPUMAX"), ("alpha", "ALPMIN/ALPMAX"), ("gamma", "CAMMIN/CAMMAX")):
        lo, hi = t.range(var)
        if not (lo <= 0.0 <= hi):
            err(key, f"the {var} range [{lo:g}, {hi:g}] excludes the nominal point {var} = 0")
    pnom = t.nominal_pressure
    if pnom:
        lo, hi = t.range("p")
        if not (lo <= pnom <= hi):
            err("PRESMIN/PRESMAX", f"the pressure range [{lo:g}, {hi:g}] Pa excludes NOMPRES = {pnom:g} Pa")
        inf = c.get("INFLPRES", pnom)
        if not (lo <= inf <= hi):
            warn("INFLPRES", f"INFLPRES = {inf:g} Pa is outside the pressure range [{lo:g}, {hi:g}] Pa")
    gam = _grid(t, "gamma", [0.0], 5)
    pres = _grid(t, "p", [pnom], 3) if pnom else [None]
    kap = _grid(t, "kappa", np.linspace(-1, 1, 41), 41)
    alp = _grid(t, "alpha", np.linspace(-0.5, 0.5, 41), 41)
    cv = CONVENTIONS["mfeval"]
    F, G, P = np.meshgrid(fz, gam, np.asarray([p if p is not None else np.nan for p in pres]), indexing="ij")
    F, G, P = F.ravel(), G.ravel(), P.ravel()
    P = None if pnom is None else P
    with np.errstate(all="ignore"):  # overflow is reported below as a finding, not a numpy warning
        b = basic(t, cv, 0.0, 0.0, G, F, 1.0, P)
        fx = fx0_factors(t, cv, b, F, G)
        fy = fy0_factors(t, cv, b, F, b.g_star)
    # coefficients so large that the factors overflow: every later comparison with NaN would pass
    for keys, obj, attrs in (("PCX1..PKX3", fx, ("C", "D", "mu", "K", "E0")),
                             ("PCY1..PKY7", fy, ("C", "mu", "K", "E0", "Ec", "Ea"))):
        bad = [a for a in attrs if hasattr(obj, a) and not np.all(np.isfinite(np.asarray(getattr(obj, a), dtype=float)))]
        if bad:
            err(keys, f"the factors {', '.join(bad)} are not finite over the load/camber/pressure range "
                      "(coefficients too large to evaluate)")
    for name, C in (("PCX1", fx.C), ("PCY1", fy.C), ("QCZ1", c["QCZ1"]), ("RCX1", c["RCX1"]), ("RCY1", c["RCY1"])):
        if not C > 0:
            err(name, f"shape factor C = {C:g} must be > 0")
        elif C >= 2 and name in ("PCX1", "PCY1"):
            warn(name, f"shape factor C = {C:g} >= 2: the force changes sign at large slip")
    if (fx.D <= 0).any():
        err("PDX1/PDX2/PDX3", f"peak D_x = mu_x Fz <= 0 over the load/camber/pressure range (min mu_x {np.min(fx.mu):.4g})")
    if (fx.K <= 0).any():
        err("PKX1/PKX2/PKX3", f"slip stiffness K_xk <= 0 over the load range (min {np.min(fx.K):.4g} N)")
    muy = np.asarray(fy.mu)
    if (muy > 0).any() and (muy < 0).any():
        err("PDY1/PDY2/PDY3", "mu_y changes sign over the load/camber/pressure range (D_y crosses 0)")
    elif (muy < 0).all():
        warn("PDY1", "mu_y < 0 (book sign set, docs/models/magic_formula_tyre.md §5.2): valid, but unusual for TNO files")
    kya = np.asarray(fy.K)
    if (kya == 0).any() or ((kya > 0).any() and (kya < 0).any()):
        err("PKY1/PKY2/PKY4", "cornering stiffness K_ya reaches 0 or changes sign over the load range")
    elif (kya > 0).all():
        warn("PKY1", "cornering stiffness K_ya > 0: not an ISO-W file (PKY1 < 0 expected, §2.2)?")
    def at(i):
        parts = [f"Fz = {F[i]:g} N"]
        if np.ndim(G) and np.ptp(G) > 0:
            parts.append(f"gamma = {G[i]:g} rad")
        if P is not None and np.ptp(P) > 0:
            parts.append(f"p = {P[i]:g} Pa")
        return ", ".join(parts)

    def worst(values):
        v = np.broadcast_to(np.asarray(values, dtype=float), F.shape)
        i = int(np.argmax(v))
        return float(v[i]), i

    ex, i = worst(np.maximum(fx.E0 * (1.0 - c["PEX4"]), fx.E0 * (1.0 + c["PEX4"])))
    if ex > 1:
        err("PEX1..PEX4", f"curvature E_x = {ex:.4g} > 1 at {at(i)} (the curve turns back; §5.1)")
    ey, i = worst(np.maximum(fy.E0 * (fy.Ec - fy.Ea), fy.E0 * (fy.Ec + fy.Ea)))
    if ey > 1:
        err("PEY1..PEY5", f"curvature E_y = {ey:.4g} > 1 at {at(i)} (the curve turns back; §5.2)")
    exa, i = worst(c["REX1"] + c["REX2"] * b.dfz)
    if exa > 1:
        err("REX1/REX2", f"curvature E_xa = {exa:.4g} > 1 at {at(i)} (§6.1)")
    eyk, i = worst(c["REY1"] + c["REY2"] * b.dfz)
    if eyk > 1:
        err("REY1/REY2", f"curvature E_yk = {eyk:.4g} > 1 at {at(i)} (§6.2)")
    # trail curvature E_t over the slip-angle range (§5.3): needs B_t, C_t and alpha_t
    dfz = b.dfz[:, None]
    gz = np.asarray(b.g_star * (c["LGAZ"] if t.is_52 else 1.0))[:, None]
    gt = gz if t.is_52 else np.asarray(G)[:, None]
    bt = ((c["QBZ1"] + c["QBZ2"] * dfz + c["QBZ3"] * dfz ** 2) * (1.0 + c["QBZ4"] * gt + c["QBZ5"] * np.abs(gt))
          * c["LKY"] / c["LMUY"])
    at_ = alp[None, :] + c["QHZ1"] + c["QHZ2"] * dfz + (c["QHZ3"] + c["QHZ4"] * dfz) * gz
    et = ((c["QEZ1"] + c["QEZ2"] * dfz + c["QEZ3"] * dfz ** 2)
          * (1.0 + (c["QEZ4"] + c["QEZ5"] * gz) * (2.0 / math.pi) * np.arctan(bt * c["QCZ1"] * at_)))
    if np.max(et) > 1:
        j = np.unravel_index(int(np.argmax(et)), et.shape)
        warn("QEZ1..QEZ5", f"trail curvature E_t = {np.max(et):.4g} > 1 at {at(j[0])}, alpha = {alp[j[1]]:g} rad "
                           "(the mfeval convention clips it to 1; §5.3)")
    bxa = c["RBX1"] * _cos_atan(c["RBX2"] * kap) * c["LXAL"]
    if (bxa <= 0).any() or c["RBX1"] <= 0:
        err("RBX1/RBX2", "slope B_xa of the Fx reduction with alpha must be > 0 (§6.1)")
    byk = c["RBY1"] * _cos_atan(c["RBY2"] * (alp - c["RBY3"])) * c["LYKA"]
    if (byk <= 0).any() or c["RBY1"] <= 0:
        err("RBY1/RBY2", "slope B_yk of the Fy reduction with kappa must be > 0 (§6.2)")
    if c["QBZ1"] <= 0:
        warn("QBZ1", f"trail slope factor QBZ1 = {c['QBZ1']:g} <= 0")
    return out


def _check_pac89(t, err) -> None:
    from tirecli.models.magic_formula.pac89 import factors

    fz = np.linspace(0.25, 2.0, 8) * 4000.0
    lo, hi = t.range("fz")
    if math.isfinite(lo) and math.isfinite(hi) and hi > 0:
        fz = np.linspace(max(lo, 0.05 * hi), hi, 8)
    f = factors(t, fz)
    for name, keys in (("fx", "B0..B8"), ("fy", "A0..A7"), ("mz", "C0..C10")):
        p = f[name]
        if not p["C"] > 0:
            err(keys.split("..")[0], f"shape factor C of {name} = {p['C']:g} must be > 0")
        if name != "mz" and (np.asarray(p["D"]) <= 0).any():
            err(keys, f"peak D of {name} <= 0 somewhere in {fz.min():g}..{fz.max():g} N")
        if (np.asarray(p["E"]) > 1).any():
            err(keys, f"curvature E of {name} > 1 somewhere in {fz.min():g}..{fz.max():g} N (the curve turns back)")
