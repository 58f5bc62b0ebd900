"""Start values of the load terms: the nominal coefficients fitted per load level, then the load functions.

A start tyre's load terms belong to its own loads and ``FNOMIN``: on data of another tyre they often
extrapolate into shapes from which a joint fit of every load does not find its way back. So before a
stage's load step (the classic procedure of Magic Formula fitting tools):

1. At every load level (camber and pressure at their reference levels), outward from the one nearest
   ``FNOMIN``, the stage's nominal coefficients are fitted alone, the identified load terms held at no
   load dependence (0; ``PKY2``, ``PKY4`` at their start values), each level starting from its neighbour
   and, as the nominal step, with peak and stiffness first (``Stage.pre``).
2. Each nominal coefficient with load terms (:data:`LOAD_FORMS`) is then a function of the load whose
   values at the levels are known: its load function (linear or quadratic in ``dfz``, the slip stiffness
   ``(PKX1 + PKX2 dfz) exp(PKX3 dfz)``, the cornering stiffness ``PKY1 Fz0' sin(PKY4 atan(Fz/(PKY2 Fz0')))``)
   is fitted to those values, for the identified coefficients only. Nominal coefficients without load
   terms take the median of their level values.

The load step then starts from these values. The functions of a form are evaluated here in the same
way the model uses them (docs/models/magic_formula_tyre.md §5, §6) but only to start the fit: the fit
itself evaluates the model.
"""
from __future__ import annotations

import numpy as np

from tirecli.numerics.mf_fit import solve
from tirecli.numerics.mf_fit.data import levels

#: Load coefficients whose neutral value is not 0 (K_ya divides by PKY2; PKY4 sets its curvature): every
#: other identified load coefficient is 0 in the fits per level.
NEUTRAL_KEEP = ("PKY2", "PKY4")

#: Nominal coefficient -> (its load coefficients, load function). The residual-torque slope
#: B_r = QBZ9 + QBZ10 B_y C_y is left out: B_y C_y changes little with the load, and a line through the
#: levels' B_r against it is as steep as their scatter makes it; QBZ10 starts at 0.
LOAD_FORMS = {
    "PDX1": (("PDX2",), "lin"), "PEX1": (("PEX2", "PEX3"), "quad"), "PKX1": (("PKX2", "PKX3"), "kx"),
    "PHX1": (("PHX2",), "lin"), "PVX1": (("PVX2",), "lin"),
    "PDY1": (("PDY2",), "lin"), "PEY1": (("PEY2",), "lin"), "PKY1": (("PKY2", "PKY4"), "ky"),
    "PHY1": (("PHY2",), "lin"), "PVY1": (("PVY2",), "lin"),
    "QBZ1": (("QBZ2", "QBZ3"), "quad"), "QDZ1": (("QDZ2",), "lin"), "QDZ6": (("QDZ7",), "lin"),
    "QEZ1": (("QEZ2", "QEZ3"), "quad"), "QHZ1": (("QHZ2",), "lin"),
    "REX1": (("REX2",), "lin"), "REY1": (("REY2",), "lin"), "RHY1": (("RHY2",), "lin"), "RVY1": (("RVY2",), "lin"),
}


def _form(kind: str, p, dfz, fz, fz0p):
    """The load function ``kind`` with coefficients ``p = (nominal, load...)`` at the levels."""
    if kind == "lin":
        return p[0] + p[1] * dfz
    if kind == "quad":
        return p[0] + p[1] * dfz + p[2] * dfz**2
    if kind == "kx":
        return (p[0] + p[1] * dfz) * np.exp(p[2] * dfz)
    return p[0] * np.sin(p[2] * np.arctan(fz / (p[1] * fz0p)))  # "ky"


def _fit_form(kind, nominal, loads, free, at_levels: dict, lv, bounds):
    """Coefficients of one load function matching the level values (only ``free`` ones move);
    ``at_levels`` are the load terms the level fits were made with."""
    names = [nominal] + list(loads)
    n = len(lv["dfz"])
    target = _form(kind, [lv["y"][nominal]] + [np.full(n, at_levels[k]) for k in loads], lv["dfz"], lv["fz"],
                   lv["fz0p"])
    full = dict(at_levels)
    full[nominal] = float(np.median(lv["y"][nominal]))
    x0 = np.array([full[k] for k in free])

    def resid(x):
        full.update(zip(free, x))
        return _form(kind, [full[k] for k in names], lv["dfz"], lv["fz"], lv["fz0p"]) - target

    lo = np.array([bounds[k][0] for k in free])
    hi = np.array([bounds[k][1] for k in free])
    typ = np.maximum(np.abs(x0), 1e-2)
    with np.errstate(all="ignore"):
        r = solve.levenberg_marquardt(resid, lambda x, f: solve.fd_jacobian(resid, x, f, lo, hi, typ), x0, lo, hi,
                                      tol=1e-12, max_nfev=200)
    if not np.all(np.isfinite(r.x)):
        return {}
    return dict(zip(free, map(float, r.x)))


def per_load_start(plan, sp, values: dict, idx, names: list, step) -> dict:
    """Start values for a stage's load step (module docstring) from the points ``idx`` of that step;
    ``names`` are the step's coefficients; ``step(plan, sp, values, idx, names, final)`` fits one step.
    Returns the values to use (empty when the points hold fewer than two usable load levels)."""
    o = plan.options
    st = sp.stage
    group = {c.name: c.group for c in st.coefs}
    nominal = [k for k in names if group.get(k) == "nominal"]
    held = {k: (values[k] if k in NEUTRAL_KEEP else 0.0) for k in names if group.get(k) == "load"}
    fz = plan.data.inputs["fz"][idx]
    fz0 = plan.start.coef["FNOMIN"]
    lv_all = levels(fz, o.load_tol * fz0)
    need = max(o.min_points, 2 * len(nominal))
    usable = [i for i in range(len(lv_all.centres)) if np.count_nonzero(lv_all.index == i) >= need]
    if len(usable) < 2 or not nominal:
        return {}
    ref = min(usable, key=lambda i: abs(lv_all.centres[i] - fz0))
    order = sorted(usable, key=lambda i: (abs(lv_all.centres[i] - lv_all.centres[ref]), lv_all.centres[i]))
    base = {**values, **held}
    fz0p = fz0 * plan.base.coef["LFZO"]
    fits = {}
    for i in order:
        sub = idx[lv_all.index == i]
        if sub.size > o.step_points:
            sub = sub[:: int(np.ceil(sub.size / o.step_points))]
        near = min((j for j in fits), key=lambda j: abs(lv_all.centres[j] - lv_all.centres[i]), default=None)
        start = {**base, **(fits[near] if near is not None else {})}
        for pre in [[k for k in p if k in nominal] for p in st.pre] + [nominal]:  # as the nominal step (Stage.pre)
            if pre:
                _, x, _, _ = step(plan, sp, start, sub, pre, False)
                start.update(zip(pre, map(float, x)))
        fits[i] = {k: start[k] for k in nominal}
    lv = {"dfz": np.array([lv_all.centres[i] / fz0p - 1.0 for i in order]),
          "fz": np.array([lv_all.centres[i] for i in order]), "fz0p": fz0p,
          "y": {k: np.array([fits[i][k] for i in order]) for k in nominal}}
    out = {k: float(np.median(lv["y"][k])) for k in nominal}
    free_loads = set(held)
    for k in nominal:
        form = LOAD_FORMS.get(k)
        if form is None or not free_loads & set(form[0]):
            continue
        loads, kind = form
        free = [k] + [j for j in loads if j in free_loads]
        at_levels = {j: (held[j] if j in held else values[j]) for j in loads}
        out.update(_fit_form(kind, k, loads, free, at_levels, lv, sp.bounds))
    return out
