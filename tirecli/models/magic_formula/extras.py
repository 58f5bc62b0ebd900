"""mfeval's outputs beside the forces: relaxation lengths, stiffnesses, rolling radius, contact patch.

:func:`evaluate_extras` gives, over broadcast arrays, the columns of :data:`EXTRA_OUTPUTS` that a tyre
can give (docs/models/magic_formula_tyre.md §17): ``sigmax``, ``sigmay`` and ``Cx``, ``Cy``
(:mod:`.relaxation`), ``Kxk``, ``Kya`` (the kernel's slip stiffnesses), ``Cz``, ``a``, ``b``
(:mod:`.contact`) and ``re`` (:mod:`.radius`). Inputs are treated as mfeval does: the stiffnesses and
relaxation lengths at the limited load, inclination and pressure; the rolling radius and the contact
patch at the unclipped load and slip; ``Cz`` at the load raised to ``FZMIN`` and at the point's forces.
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula import contact, radius, relaxation
from tirecli.models.magic_formula.tire import MFTire

#: The extra outputs, in the order ``tirecli mf eval`` writes them: name -> (unit, meaning).
EXTRA_OUTPUTS = {
    "sigmax": ("m", "longitudinal relaxation length sigma_kappa"),
    "sigmay": ("m", "lateral relaxation length sigma_alpha"),
    "Kxk": ("N", "longitudinal slip stiffness K_xk = dFx0/dkappa at kappa_x = 0 (per unit slip)"),
    "Kya": ("N/rad", "cornering stiffness K_ya = dFy0/dalpha at alpha_y = 0 (with camber; the file's sign)"),
    "Cx": ("N/m", "overall longitudinal carcass stiffness"),
    "Cy": ("N/m", "overall lateral carcass stiffness"),
    "Cz": ("N/m", "vertical stiffness Fz/rho (secant)"),
    "re": ("m", "effective rolling radius R_e"),
    "a": ("m", "contact-patch half-length"),
    "b": ("m", "contact-patch half-width"),
}


def available(t: MFTire, sigma_source: str = "version") -> dict:
    """``{name: bool}`` over :data:`EXTRA_OUTPUTS`: which the tyre's coefficients give."""
    have = dict(relaxation.available(t, sigma_source))
    have.update(contact.available(t))
    have["re"] = t.family == "mf" and radius.has_radius(t)
    return {k: bool(have.get(k, False)) for k in EXTRA_OUTPUTS}


def missing_reason(t: MFTire, name: str) -> str:
    """Why ``name`` is not available for ``t`` (the coefficients it needs), for messages and docs."""
    if t.family != "mf":
        return "a PAC89 tyre has none of these"
    need = {
        "Cx": "LONGITUDINAL_STIFFNESS", "Cy": "LATERAL_STIFFNESS",
        "sigmax": ("PTX1" if relaxation.sigma_source(t) == "pt" else "LONGITUDINAL_STIFFNESS"),
        "sigmay": ("PTY1, PTY2" if relaxation.sigma_source(t) == "pt" else "LATERAL_STIFFNESS"),
        "Cz": "VERTICAL_STIFFNESS; with Q_V2 or in MF 6.2 also Q_RE0 and LONGVL",
        "re": "Q_RE0 and VERTICAL_STIFFNESS",
        "a": "Q_A1/Q_A2 or VERTICAL_STIFFNESS" if t.is_52 else "Q_RA1/Q_RA2 and VERTICAL_STIFFNESS",
        "b": "WIDTH" if t.is_52 else "Q_RB1/Q_RB2, WIDTH and VERTICAL_STIFFNESS",
    }
    return f"needs {need.get(name, '?')}"


def evaluate_extras(t: MFTire, kappa=0.0, alpha=0.0, gamma=0.0, fz=None, vx=None, p=None, *, fx=None, fy=None,
                    outputs=None, convention="mfeval", limits: bool = True, sigma_source: str = "version") -> dict:
    """The extra outputs a tyre gives, at broadcast inputs (mfeval's columns, §17).

    Parameters
    ----------
    t : MFTire
    kappa : array_like
        Longitudinal slip [-] (used by the rolling radius).
    alpha : array_like
        Slip angle [rad] (unused: kept for the shape of the inputs).
    gamma : array_like
        Inclination angle [rad].
    fz : array_like or None
        Vertical load [N] (default ``FNOMIN``).
    vx : array_like or None
        Forward speed [m/s] (default ``LONGVL``).
    p : array_like or None
        Inflation pressure [Pa] (default ``INFLPRES``; no effect in MF 5.2).
    fx, fy : array_like or None
        Forces at the point [N] (for ``Cz``; None: computed with :func:`~.engine.evaluate`).
    outputs : iterable of str or None
        Names wanted (default: every available one).
    convention : str
        ``mfeval`` or ``teasit`` (slip stiffnesses).
    limits : bool
        Limit the inputs to the tyre's ranges (§11).
    sigma_source : str
        Rule of the relaxation lengths (:func:`~.relaxation.relaxation_lengths`).

    Returns
    -------
    dict
        ``{name: ndarray}`` in the order of :data:`EXTRA_OUTPUTS`, only for the names the tyre gives.
    """
    have = available(t, sigma_source)
    want = [k for k in EXTRA_OUTPUTS if have[k] and (outputs is None or k in set(outputs))]
    if not want:
        return {}
    c = t.coef
    fz = c["FNOMIN"] if fz is None else fz
    vx = t.reference_speed if vx is None else vx
    if t.nominal_pressure is None:
        p = None
    elif p is None:
        p = t.default_pressure
    shape = np.broadcast_shapes(*(np.shape(a) for a in (kappa, alpha, gamma, fz)),
                                *(np.shape(a) for a in (vx, p) if a is not None))
    fz_raw = np.maximum(np.asarray(fz, dtype=float), 0.0)
    fz_l, gamma_l, p_l = relaxation.limited_inputs(t, fz_raw, gamma, p, limits)
    out = {}
    with np.errstate(all="ignore"):
        if {"Kxk", "Kya", "sigmax", "sigmay", "Cx", "Cy"} & set(want):
            out["Kxk"], out["Kya"] = relaxation.slip_stiffness(t, fz_l, gamma_l, p_l, convention=convention,
                                                               limits=False)
            out["Cx"], out["Cy"] = relaxation.carcass_stiffness(t, fz_l, p_l, limits=False)
            out["sigmax"], out["sigmay"] = relaxation.relaxation_lengths(
                t, fz_l, gamma_l, p_l, source=sigma_source, limits=False, stiffness=(out["Kxk"], out["Kya"]),
                carcass=(out["Cx"], out["Cy"]))
        omega = 0.0
        if "re" in want or ("Cz" in want and radius.has_radius(t)):
            re, omega = radius.effective_rolling_radius(t, fz_raw, kappa, vx if vx is not None else 0.0, p_l)
            out["re"] = re
        if "Cz" in want:
            if fx is None or fy is None:
                from tirecli.models.magic_formula.engine import evaluate

                res = evaluate(t, kappa, alpha, gamma, fz, vx, p, convention=convention, limits=limits,
                               outputs=("fx", "fy"))
                fx, fy = res.fx, res.fy
            fz_low = np.maximum(fz_l, c.get("FZMIN", 0.0) or 0.0) if limits else fz_l
            fz_cz = fz_l if t.version == "6.2" else fz_low
            out["Cz"] = contact.deflection(t, fz_cz, fx, fy, omega, gamma_l, p_l, fz_target=fz_raw)[1]
        if {"a", "b"} & set(want):
            out["a"], out["b"] = contact.contact_patch(t, fz_raw, p_l)
    return {k: np.broadcast_to(np.asarray(out[k], dtype=float), shape).copy() for k in want}


__all__ = ["EXTRA_OUTPUTS", "available", "missing_reason", "evaluate_extras"]
