"""Transient Magic Formula: first-order relaxation of the slips (the single contact point lag).

docs/models/magic_formula_tyre.md §18. The contact point lags the wheel: with the relaxation lengths
``sigma_kappa``, ``sigma_alpha`` of :mod:`.relaxation` (mfeval's ``sigmax``, ``sigmay``, evaluated at the
current load, inclination and pressure), the transient slips ``kappa'``, ``alpha'`` obey the linear
single-contact-point model (Pacejka, *Tire and Vehicle Dynamics*, 3rd ed. 2012, ch. 7; MF-Tyre's
``USE_MODE`` +10 "linear transients"; Adams/Tire, transient behaviour of the Pacejka models)::

    sigma_kappa dkappa'/dt + |Vx| kappa' = |Vx| kappa
    sigma_alpha dalpha'/dt + |Vx| alpha' = |Vx| alpha

and the forces and moments are the steady-state Magic Formula (:func:`~.engine.evaluate`) at
``(kappa', alpha')``. In the rolled distance ``s`` (``ds/dt = |Vx|``) the lag is
``dx/ds = (u - x)/sigma``: at constant slip and load the state approaches the slip as
``1 - exp(-s/sigma)`` whatever the speed history (:func:`step_response`).

One model shape (python-control style): state ``x = [kappa', alpha']`` (:data:`STATES`), inputs
:data:`INPUTS`, parameters :class:`TransientMF`; :func:`rhs` and :func:`outputs`. The integrator for
arbitrary input histories is :func:`tirecli.numerics.mf_transient.simulate`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.models.magic_formula import relaxation
from tirecli.models.magic_formula.tire import MFTire

#: State names: transient longitudinal slip kappa' [-] and transient slip angle alpha' [rad].
STATES = ("kappa_t", "alpha_t")
#: Input names, in the order of an input array: kappa [-], alpha [rad], gamma [rad], fz [N], vx [m/s], p [Pa].
INPUTS = ("kappa", "alpha", "gamma", "fz", "vx", "p")
#: Smallest relaxation length used [m]: a vanishing one (no load) makes the lag instantaneous.
SIGMA_FLOOR = 1e-9


@dataclass(frozen=True)
class TransientMF:
    """Parameters of the transient Magic Formula.

    Attributes
    ----------
    tire : MFTire
        An MF 6.x or 5.2 tyre that gives its relaxation lengths (:func:`~.relaxation.available`).
    convention : str
        ``mfeval`` (default) or ``teasit``: variant of the steady-state equations (§10).
    limits : bool
        Clip the inputs to the tyre's ranges (§11).
    sigma_source : str
        Rule of the relaxation lengths: ``version`` (mfeval's, default), ``stiffness`` or ``pt``
        (:func:`~.relaxation.relaxation_lengths`).
    """

    tire: MFTire
    convention: str = "mfeval"
    limits: bool = True
    sigma_source: str = "version"

    def __post_init__(self):
        have = relaxation.available(self.tire, self.sigma_source)
        if not (have["sigmax"] and have["sigmay"]):
            rule = relaxation.sigma_source(self.tire, self.sigma_source)
            need = "PTX1, PTY1 and PTY2" if rule == "pt" else "LONGITUDINAL_STIFFNESS and LATERAL_STIFFNESS"
            other = "; sigma_source='pt' uses its PTX/PTY" if rule != "pt" and all(
                relaxation.available(self.tire, "pt")[k] for k in ("sigmax", "sigmay")) else ""
            name = f"{self.tire.name} " if self.tire.name else ""
            raise ValueError(f"the tyre {name}gives no relaxation lengths by the {rule!r} rule "
                             f"(it needs {need}){other}")


def _input(u, name: str, default=None):
    """Input ``name`` of ``u`` (a mapping or an array in the order of :data:`INPUTS`)."""
    if isinstance(u, dict) or hasattr(u, "keys"):
        v = u.get(name, default)
    else:
        i = INPUTS.index(name)
        v = u[i] if len(u) > i else default
    return None if v is None else np.asarray(v, dtype=float)


def relaxation_at(u, p: TransientMF):
    """Relaxation lengths ``(sigma_kappa, sigma_alpha)`` [m] at the inputs ``u`` (load, inclination, pressure),
    floored at :data:`SIGMA_FLOOR`."""
    fz = _input(u, "fz")
    gamma = _input(u, "gamma", 0.0)
    pres = _input(u, "p")
    sx, sy = relaxation.relaxation_lengths(p.tire, fz, gamma, pres, source=p.sigma_source,
                                           convention=p.convention, limits=p.limits)
    return np.maximum(sx, SIGMA_FLOOR), np.maximum(sy, SIGMA_FLOOR)


def rhs(t, x, u, p: TransientMF):
    """Time derivative of the transient slips (Pacejka 2012 ch. 7, the linear single-contact-point model).

    ``dkappa'/dt = |Vx| (kappa - kappa') / sigma_kappa``, ``dalpha'/dt = |Vx| (alpha - alpha') / sigma_alpha``.

    Parameters
    ----------
    t : float
        Time [s] (unused: the model is time-invariant).
    x : array_like, shape (2, ...)
        State ``[kappa' [-], alpha' [rad]]``; trailing dimensions are independent points.
    u : mapping or array_like
        Inputs at ``t``: ``kappa`` [-], ``alpha`` [rad], ``gamma`` [rad] (default 0), ``fz`` [N] (> 0),
        ``vx`` [m/s], ``p`` [Pa] (default the tyre's ``INFLPRES``); a mapping, or an array in the
        order of :data:`INPUTS`.
    p : TransientMF
        The tyre and its options.

    Returns
    -------
    ndarray, shape (2, ...)
        ``[dkappa'/dt [1/s], dalpha'/dt [rad/s]]``.
    """
    x = np.asarray(x, dtype=float)
    sx, sy = relaxation_at(u, p)
    speed = np.abs(_input(u, "vx"))
    return np.stack(np.broadcast_arrays(speed * (_input(u, "kappa") - x[0]) / sx,
                                        speed * (_input(u, "alpha") - x[1]) / sy))


def outputs(t, x, u, p: TransientMF, names=("fx", "fy", "mz", "mx", "my")) -> dict:
    """Forces and moments of the transient Magic Formula: the steady-state MF at the transient slips.

    Parameters
    ----------
    t : float
        Time [s] (unused).
    x : array_like, shape (2, ...)
        State ``[kappa' [-], alpha' [rad]]``.
    u : mapping or array_like
        Inputs at ``t`` (see :func:`rhs`).
    p : TransientMF
    names : iterable of str
        Outputs of :func:`~.engine.evaluate` wanted.

    Returns
    -------
    dict
        ``fx``, ``fy`` [N], ``mz``, ``mx``, ``my`` [N m] (those of ``names``), ``kappa_t`` [-],
        ``alpha_t`` [rad] (the state), ``sigma_kappa``, ``sigma_alpha`` [m].
    """
    from tirecli.models.magic_formula.engine import evaluate

    x = np.asarray(x, dtype=float)
    res = evaluate(p.tire, x[0], x[1], _input(u, "gamma", 0.0), _input(u, "fz"), _input(u, "vx"), _input(u, "p"),
                   convention=p.convention, limits=p.limits, low_speed=False, outputs=names)
    sx, sy = relaxation_at(u, p)
    return {**res.as_dict(), "kappa_t": x[0], "alpha_t": x[1], "sigma_kappa": sx, "sigma_alpha": sy}


def step_response(s, sigma, step, start=0.0):
    """Closed-form response of the lag to a slip step at constant load (any speed history).

    ``x(s) = step + (start - step) exp(-s/sigma)``: the solution of ``dx/ds = (step - x)/sigma`` from
    ``x(0) = start`` (Pacejka 2012 ch. 7), with ``s`` the distance rolled since the step.

    Parameters
    ----------
    s : array_like
        Rolled distance since the step [m] (>= 0).
    sigma : array_like
        Relaxation length [m] (> 0).
    step : array_like
        Slip after the step [-] or [rad].
    start : array_like
        Transient slip at the step [-] or [rad].

    Returns
    -------
    ndarray
        Transient slip [-] or [rad].
    """
    s, sigma = np.asarray(s, dtype=float), np.asarray(sigma, dtype=float)
    return step + (np.asarray(start, dtype=float) - step) * np.exp(-s / sigma)


__all__ = ["STATES", "INPUTS", "SIGMA_FLOOR", "TransientMF", "relaxation_at", "rhs", "outputs", "step_response"]
