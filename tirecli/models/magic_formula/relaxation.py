"""Slip stiffnesses, carcass stiffnesses and relaxation lengths of a Magic Formula tyre (static maps).

docs/models/magic_formula_tyre.md §17.1-§17.2; the formulas are mfeval's (``Solver.calculateRelax``,
outputs ``Cx``, ``Cy``, ``sigmax``, ``sigmay``, ``Kya``, ``Kxk``):

- slip stiffnesses ``K_xk`` (book 4.E15) and ``K_ya`` (4.E25, with camber; §9 for MF 5.2), taken from
  the kernel's factors (:func:`~tirecli.models.magic_formula.pure.pure_slip_factors`, not restated here);
- overall carcass stiffnesses (Besselink et al. 2010 eqs. 17, 18)
  ``C_x = LONGITUDINAL_STIFFNESS (1 + PCFX1 dfz + PCFX2 dfz^2)(1 + PCFX3 dpi)`` and likewise ``C_y``
  with ``LATERAL_STIFFNESS``, ``PCFY1-3``;
- relaxation lengths, MF 6.1 / 6.2 (paper eq. 19): ``sigma_kappa = |K_xk / C_x|``,
  ``sigma_alpha = |K_ya / C_y|``; MF 5.2 (MF-Tyre 5.2 equation manual):
  ``sigma_kappa = (PTX1 + PTX2 dfz) exp(-PTX3 dfz) LSGKP R0 Fz / Fz0`` and
  ``sigma_alpha = PTY1 sin(2 arctan(Fz / (PTY2 Fz0'))) (1 - PKY3 |gamma|) R0 LFZO LSGAL``.

What a tyre does not give is absent, never invented: ``C_x`` needs ``LONGITUDINAL_STIFFNESS``, ``C_y``
``LATERAL_STIFFNESS``, the MF 5.2 lengths ``PTX1`` and ``PTY1``, ``PTY2`` (the other coefficients of
each formula default to 0, the scaling factors ``LSGKP``, ``LSGAL`` to 1). An absent value is NaN in
the arrays and ``False`` in :func:`available`. Inputs are limited like the force evaluation
(:func:`~tirecli.models.magic_formula.inputs.prepare`: ``Fz`` to ``FZMAX``, ``gamma``, ``p`` to their
ranges), as mfeval does.
"""
from __future__ import annotations

import numpy as np

from tirecli.models.magic_formula import inputs as _inputs
from tirecli.models.magic_formula.tire import MFTire

#: How the relaxation lengths are found: by the file's version (mfeval's rule), from the carcass
#: stiffnesses (MF 6.x) or from ``PTX``/``PTY`` (MF 5.2).
SIGMA_SOURCES = ("version", "stiffness", "pt")


def _pt_keys_given(t: MFTire) -> tuple[bool, bool]:
    c = t.coef
    return "PTX1" in c, ("PTY1" in c and bool(c.get("PTY2")))


def sigma_source(t: MFTire, source: str = "version") -> str:
    """The rule that gives ``t``'s relaxation lengths: ``"stiffness"`` (MF 6.x, paper eq. 19) or ``"pt"``
    (MF 5.2, ``PTX``/``PTY``). ``source="version"`` picks by the file's version, as mfeval does."""
    if source not in SIGMA_SOURCES:
        raise ValueError(f"unknown relaxation-length source {source!r} (expected one of {SIGMA_SOURCES})")
    if t.family != "mf":
        raise ValueError(f"relaxation lengths need an MF 6.x or 5.2 tyre (this one is {t.version})")
    if source == "version":
        return "pt" if t.is_52 else "stiffness"
    return source


def available(t: MFTire, source: str = "version") -> dict:
    """Which of ``Kxk, Kya, Cx, Cy, sigmax, sigmay`` the tyre gives: ``{name: bool}`` (all False for PAC89)."""
    if t.family != "mf":
        return dict.fromkeys(("Kxk", "Kya", "Cx", "Cy", "sigmax", "sigmay"), False)
    c = t.coef
    cx, cy = "LONGITUDINAL_STIFFNESS" in c, "LATERAL_STIFFNESS" in c
    if sigma_source(t, source) == "pt":
        sx, sy = _pt_keys_given(t)
    else:
        sx, sy = cx, cy
    return {"Kxk": True, "Kya": True, "Cx": cx, "Cy": cy, "sigmax": sx, "sigmay": sy}


def limited_inputs(t: MFTire, fz, gamma=0.0, p=None, limits: bool = True):
    """``(fz, gamma, p)`` as the force evaluation sees them (§11): negative loads raised to 0 and, with
    ``limits``, ``Fz`` clipped to ``FZMAX``, ``gamma`` and ``p`` to their ranges. ``p`` None: the tyre's
    default pressure (None without pressure effect)."""
    fz = np.asarray(fz, dtype=float)
    gamma = np.asarray(gamma, dtype=float)
    if t.nominal_pressure is None:
        p = None
    elif p is None:
        p = t.default_pressure
    if p is not None:
        p = np.asarray(p, dtype=float)
    pr = _inputs.prepare(t, 0.0, 0.0, gamma, fz, 0.0, p, limits=limits, low_speed=False, need_my=False)
    return pr.fz, pr.gamma, pr.p


def _dfz_dpi(t: MFTire, fz, p):
    c = t.coef
    fz0p = c["FNOMIN"] * c["LFZO"]
    dfz = fz / fz0p - 1.0
    pi0 = t.nominal_pressure
    dpi = 0.0 if (pi0 is None or p is None) else (p - pi0) / pi0
    return dfz, dpi


def slip_stiffness(t: MFTire, fz, gamma=0.0, p=None, *, convention="mfeval", limits: bool = True):
    """Longitudinal slip stiffness ``K_xk`` [N] and cornering stiffness ``K_ya`` [N/rad] (book 4.E15, 4.E25).

    The kernel's own values (:func:`~tirecli.models.magic_formula.pure.pure_slip_factors`), with the
    camber and pressure dependence, at the limited inputs. ``K_ya`` carries the file's sign (negative
    for the usual ISO-W files, where a positive slip angle gives a negative side force).

    Parameters
    ----------
    t : MFTire
        An MF 6.x or 5.2 tyre.
    fz : array_like
        Vertical load [N].
    gamma : array_like
        Inclination angle [rad].
    p : array_like or None
        Inflation pressure [Pa] (default ``INFLPRES``; no effect in MF 5.2).
    convention : str
        ``mfeval`` or ``teasit`` (gamma* = sin(gamma) in the latter).
    limits : bool
        Limit the inputs to the tyre's ranges (§11).

    Returns
    -------
    (ndarray, ndarray)
        ``K_xk`` [N], ``K_ya`` [N/rad].
    """
    from tirecli.models.magic_formula.pure import pure_slip_factors

    if t.family != "mf":
        raise ValueError(f"slip stiffnesses need an MF 6.x or 5.2 tyre (this one is {t.version})")
    fz, gamma, p = limited_inputs(t, fz, gamma, p, limits)
    shape = np.broadcast_shapes(np.shape(fz), np.shape(gamma), np.shape(p) if p is not None else ())
    with np.errstate(all="ignore"):
        f = pure_slip_factors(t, fz, gamma, p, convention)
    return (np.broadcast_to(np.asarray(f["fx"]["K"], dtype=float), shape).copy(),
            np.broadcast_to(np.asarray(f["fy"]["K"], dtype=float), shape).copy())


def carcass_stiffness(t: MFTire, fz, p=None, *, limits: bool = True):
    """Overall longitudinal and lateral carcass stiffnesses ``C_x``, ``C_y`` [N/m] (paper eqs. 17, 18).

    ``C_x = LONGITUDINAL_STIFFNESS (1 + PCFX1 dfz + PCFX2 dfz^2)(1 + PCFX3 dpi)``, ``C_y`` alike with
    ``LATERAL_STIFFNESS`` and ``PCFY1-3``; ``dfz = Fz/Fz0' - 1`` (4.E2a), ``dpi`` (4.E2b; 0 for MF 5.2).

    Parameters
    ----------
    t : MFTire
    fz : array_like
        Vertical load [N].
    p : array_like or None
        Inflation pressure [Pa] (default ``INFLPRES``).
    limits : bool
        Limit ``Fz`` and ``p`` to the tyre's ranges (§11).

    Returns
    -------
    (ndarray, ndarray)
        ``C_x``, ``C_y`` [N/m]; NaN where the file gives no ``LONGITUDINAL_STIFFNESS`` /
        ``LATERAL_STIFFNESS``.
    """
    c = t.coef
    fz, _, p = limited_inputs(t, fz, 0.0, p, limits)
    dfz, dpi = _dfz_dpi(t, fz, p)
    shape = np.broadcast_shapes(np.shape(fz), np.shape(dpi))
    out = []
    for key, pre in (("LONGITUDINAL_STIFFNESS", "PCFX"), ("LATERAL_STIFFNESS", "PCFY")):
        if key not in c:
            out.append(np.full(shape, np.nan))
            continue
        k1, k2, k3 = (c.get(f"{pre}{i}", 0.0) for i in (1, 2, 3))
        val = c[key] * (1.0 + k1 * dfz + k2 * np.square(dfz)) * (1.0 + k3 * dpi)
        out.append(np.broadcast_to(np.asarray(val, dtype=float), shape).copy())
    return out[0], out[1]


def relaxation_lengths(t: MFTire, fz, gamma=0.0, p=None, *, source: str = "version", convention="mfeval",
                       limits: bool = True, stiffness=None, carcass=None):
    """Longitudinal and lateral relaxation lengths ``sigma_kappa``, ``sigma_alpha`` [m] (mfeval's ``sigmax``, ``sigmay``).

    MF 6.1 / 6.2 (Besselink et al. 2010 eq. 19): ``sigma_kappa = |K_xk / C_x|``, ``sigma_alpha = |K_ya / C_y|``
    (:func:`slip_stiffness`, :func:`carcass_stiffness`). MF 5.2 (MF-Tyre 5.2 equation manual, as in
    mfeval): ``sigma_kappa = (PTX1 + PTX2 dfz) exp(-PTX3 dfz) LSGKP R0 Fz/Fz0`` and
    ``sigma_alpha = PTY1 sin(2 arctan(Fz/(PTY2 Fz0'))) (1 - PKY3 |gamma|) R0 LFZO LSGAL``.

    Parameters
    ----------
    t : MFTire
        An MF 6.x or 5.2 tyre.
    fz : array_like
        Vertical load [N].
    gamma : array_like
        Inclination angle [rad].
    p : array_like or None
        Inflation pressure [Pa] (default ``INFLPRES``; no effect in MF 5.2).
    source : {"version", "stiffness", "pt"}
        ``version`` (default): the rule of the file's version, as mfeval; ``stiffness`` or ``pt`` force
        one rule (e.g. ``pt`` for an MF 6.1 file that still carries MF 5.2 ``PTX``/``PTY`` values but no
        carcass stiffnesses).
    convention : str
        Convention of the slip stiffnesses (``mfeval`` or ``teasit``).
    limits : bool
        Limit the inputs to the tyre's ranges (§11).
    stiffness, carcass : (array, array) or None
        ``(K_xk, K_ya)`` and ``(C_x, C_y)`` already computed at these inputs (saves recomputing them).

    Returns
    -------
    (ndarray, ndarray)
        ``sigma_kappa``, ``sigma_alpha`` [m]; NaN where the file lacks the coefficients (:func:`available`).
    """
    rule = sigma_source(t, source)
    c = t.coef
    if rule == "stiffness":
        kxk, kya = stiffness if stiffness is not None else slip_stiffness(t, fz, gamma, p, convention=convention,
                                                                         limits=limits)
        cx, cy = carcass if carcass is not None else carcass_stiffness(t, fz, p, limits=limits)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.abs(kxk / cx), np.abs(kya / cy)
    fz, gamma, _ = limited_inputs(t, fz, gamma, None, limits)
    shape = np.broadcast_shapes(np.shape(fz), np.shape(gamma))
    dfz, _ = _dfz_dpi(t, fz, None)
    r0, fz0, lfzo = c["UNLOADED_RADIUS"], c["FNOMIN"], c["LFZO"]
    has_x, has_y = _pt_keys_given(t)
    if has_x:
        sx = ((c["PTX1"] + c.get("PTX2", 0.0) * dfz) * np.exp(-c.get("PTX3", 0.0) * dfz) * c.get("LSGKP", 1.0)
              * r0 * fz / fz0)
    else:
        sx = np.nan
    if has_y:
        sy = (c["PTY1"] * np.sin(2.0 * np.arctan(fz / (c["PTY2"] * fz0 * lfzo))) * (1.0 - c.get("PKY3", 0.0)
              * np.abs(gamma)) * r0 * lfzo * c.get("LSGAL", 1.0))
    else:
        sy = np.nan
    return (np.broadcast_to(np.asarray(sx, dtype=float), shape).copy(),
            np.broadcast_to(np.asarray(sy, dtype=float), shape).copy())


__all__ = ["SIGMA_SOURCES", "sigma_source", "available", "limited_inputs", "slip_stiffness", "carcass_stiffness",
           "relaxation_lengths"]
