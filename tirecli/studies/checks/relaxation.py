"""Reference checks of the relaxation comparison (``relaxation-compare``, study ``relaxation``).

- transient Magic Formula: the slip state against the closed form of the first-order lag
  ``u (1 - exp(-s/sigma))`` (docs/models/magic_formula_tyre.md §18), and the 63.2 % / 95 % force distances read
  off the samples against those found through that closed form;
- MCPS, slip-angle step: the ``mcps-relaxation`` study's own checks (exact characteristic solution of the
  solid carcass, the reference numbers of docs/models/mcps_tire.md §7 in the default scenario);
- MCPS, slip-ratio step: the solid carcass against its exact characteristic solution
  (:func:`tirecli.numerics.mcps_transient.rigid_step_exact`), its distances against those of the exact
  solution, the complete carcass tending to the stationary solution;
- distributed LuGre: against its closed form (:func:`tirecli.models.lugre_pde.uniform_step_response`), the
  settled 95 % distance against the closed form's, and exactly steady after one patch transit.
"""
from __future__ import annotations

import math

import numpy as np

from tirecli.studies.base import Check

MF_DOC = "docs/models/magic_formula_tyre.md §18"
MCPS_DOC = "docs/models/mcps_tire.md §7"
LUGRE_DOC = "docs/models/magic_formula_tyre.md §18.1 (distributed LuGre closed form)"


def _rows(result, step, model):
    df = result.data["relaxation"]
    return df[(df["step"] == step) & (df["model"] == model)]


def _crossing(fn, lo, hi, level, first=True, n=20001):
    """The first (or, ``first=False``, last) ``s`` in ``[lo, hi]`` where ``|fn(s) - 1|`` crosses ``1 - level``
    (``first``: where ``fn`` rises through ``level``), from a fine grid refined by Brent's method."""
    from scipy.optimize import brentq

    s = np.linspace(lo, hi, n)
    if first:
        g = lambda x: fn(x) - level  # noqa: E731
    else:
        g = lambda x: np.abs(fn(x) - 1.0) - (1.0 - level)  # noqa: E731
    v = g(s)
    idx = np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))
    if idx.size == 0:
        return float("nan")
    i = int(idx[0] if first else idx[-1])
    return float(brentq(lambda x: float(g(np.array([x]))[0]), s[i], s[i + 1], xtol=1e-12))


def _mf_checks(result):
    out = []
    sc, facts = result.meta["scenario"], result.meta["facts"]
    for step, u in (("kappa", sc["kappa"]), ("alpha", sc["alpha_rad"])):
        g = _rows(result, step, "mf")
        s = g["s"].to_numpy()
        sigma = facts[step]["mf"]["sigma_m"]
        dev = float(np.max(np.abs(g["slip_state"].to_numpy() / u - (1.0 - np.exp(-s / sigma)))))
        out.append(Check(f"mf-lag-{step}", f"transient Magic Formula, {step} step: max |x/u - (1 - exp(-s/sigma))| of "
                         f"the slip state (sigma = {sigma:.4g} m)", dev, 0.0, 1e-6, "-",
                         f"{MF_DOC} (closed form of the first-order lag)", bound="max"))
        ds = float(s[1] - s[0])
        f = facts[step]["mf"]
        for lev in ("63", "95"):
            exact = f[f"s{lev}_exact_m"]
            out.append(Check(f"mf-s{lev}-{step}", f"transient Magic Formula, {step} step: {lev} % distance of the force "
                             "read off the samples", f[f"s{lev}_m"] if f[f"s{lev}_m"] is not None else float("nan"),
                             exact, 3.0 * ds**2 / sigma, "m", f"{MF_DOC} (through the closed form of the slip state; "
                             "tolerance: linear interpolation over the sample spacing)"))
    return out


def _mcps_checks(result):
    from tirecli.numerics.mcps_transient import rigid_step_exact
    from tirecli.studies.checks.mcps import relaxation_checks

    out = [Check(f"mcps-alpha-{c.id}", f"MCPS, slip-angle step (the mcps-relaxation run): {c.description}", c.value,
                 c.reference, c.tolerance, c.unit, c.source, c.bound)
           for c in relaxation_checks(result.payload["mcps_alpha"])]
    sc, facts = result.meta["scenario"], result.meta["facts"]
    p, fz, k = result.payload["params"], sc["fz_N"], sc["kappa"]
    sx = -k / (1.0 + k)
    if "mcps-rigid" in facts["kappa"]:
        g = _rows(result, "kappa", "mcps-rigid")
        s = g["s"].to_numpy()
        fx, _, _ = rigid_step_exact(p, fz, sx, 0.0, s * (1.0 + k))
        out.append(Check("mcps-kappa-exact-rigid", "MCPS solid carcass, slip-ratio step: max |Fx - exact characteristic "
                         "solution|", float(np.max(np.abs(g["force"].to_numpy() - fx))), 0.0, 0.05, "N", MCPS_DOC))
        f = facts["kappa"]["mcps-rigid"]
        fx_inf = float(rigid_step_exact(p, fz, sx, 0.0, [1e3])[0][0])
        l = p.patch(fz).l / (1.0 + k)
        for lev, tol in (("63", 2e-4), ("95", 2e-4)):
            level = 1.0 - math.exp(-1.0) if lev == "63" else 0.95
            ref = _crossing(lambda x: rigid_step_exact(p, fz, sx, 0.0, x * (1.0 + k))[0] / fx_inf, 0.0, l, level)
            out.append(Check(f"mcps-kappa-rigid-s{lev}", f"MCPS solid carcass, slip-ratio step: {lev} % distance against "
                             "the exact solution's", f[f"s{lev}_m"] if f[f"s{lev}_m"] is not None else float("nan"), ref,
                             tol, "m", f"{MCPS_DOC} (exact by characteristics)"))
    if "mcps-complete" in facts["kappa"] and sc["distance_m"] >= 4.0:
        g = _rows(result, "kappa", "mcps-complete")
        f = facts["kappa"]["mcps-complete"]
        out.append(Check("mcps-kappa-steady-complete", f"MCPS complete carcass, slip-ratio step: |Fx - Fx_inf| after "
                         f"{sc['distance_m']:g} m (the transient tends to the stationary solution, MCPS eq. 18)",
                         abs(float(g["force"].to_numpy()[-1]) - f["steady_N"]), 0.0, 0.01, "N", MCPS_DOC))
    return out


def _lugre_checks(result):
    from tirecli.models.lugre_pde import uniform_step_response

    facts = result.meta["facts"]["kappa"]
    if "lugre" not in facts:
        return []
    sc, lp = result.meta["scenario"], result.payload["lugre"]
    V, k = sc["speed_m_per_s"], sc["kappa"]
    g = _rows(result, "kappa", "lugre")
    s = g["s"].to_numpy()
    mu_exact, _, _ = uniform_step_response(s / V, V * k, V * (1.0 + k), lp)
    mu = g["force"].to_numpy() / sc["fz_N"]
    f = facts["lugre"]
    mu_inf = f["steady_N"] / sc["fz_N"]
    ref95 = _crossing(lambda x: uniform_step_response(x / V, V * k, V * (1.0 + k), lp)[0] / mu_inf, 0.0,
                      f["transit_m"], 0.95, first=False)
    after = s > f["transit_m"] + 1e-9
    return [
        Check("lugre-closed-form", "distributed LuGre, slip-ratio step: max |mu - closed form| (exact along the "
              "characteristics)", float(np.max(np.abs(mu - mu_exact))), 0.0, 1e-6, "-", LUGRE_DOC, bound="max"),
        Check("lugre-s95-settled", "distributed LuGre: distance from which the force stays within 5 % of its steady "
              "state, against the closed form's", f["s95_settled_m"] if f["s95_settled_m"] is not None else float("nan"),
              ref95, 1e-4, "m", LUGRE_DOC),
        Check("lugre-transit", "distributed LuGre: max |F/F_steady - 1| after one patch transit (every element entered "
              "after the step: exactly steady)", float(np.max(np.abs(g["ratio"].to_numpy()[after] - 1.0))) if after.any()
              else float("nan"), 0.0, 1e-6, "-", LUGRE_DOC, bound="max"),
    ]


def relaxation_checks(result):
    """The checks of ``relaxation-compare`` (module doc)."""
    return _mf_checks(result) + _mcps_checks(result) + _lugre_checks(result)


__all__ = ["relaxation_checks"]
