"""Model variants of the LuGre tire: distributed (load density) or lumped (kappa0 choice).

A :class:`FrictionVariant` names one of the paper's model choices, so sweeps, transient runs
and figures refer to the same thing:

- ``distributed`` with a normal-load density: ``uniform`` (FM eq. (3)), ``exponential``
  (FM eq. (5), decay ``lam``), ``parabolic`` (docs/models/lugre_friction.md §3.2) or ``tabulated`` samples;
- ``lumped`` (FM eqs. (8)-(9)) with ``kappa0`` a constant, ``"Z"`` for ``kappa0(Z)`` of
  FM eq. (10), or ``lam`` for an exponential load (``kappa = lam/L``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tirecli.models import lugre

MODELS = ("distributed", "lumped")
LOADS = ("uniform", "exponential", "parabolic", "tabulated")


@dataclass(frozen=True)
class FrictionVariant:
    """One LuGre model variant.

    Attributes
    ----------
    model : str
        ``"distributed"`` or ``"lumped"``.
    load : str
        Normal-load density: ``uniform``, ``exponential``, ``parabolic`` or ``tabulated``.
    lam : float
        Exponential load decay ``lambda`` [-] (FM eq. (5)).
    kappa0 : float, str or None
        Lumped only: constant ``kappa0`` [-], ``"Z"`` for FM eq. (10), or ``None`` for the
        parameter set's ``kappa0`` (``lam`` for an exponential load).
    u, f : tuple or None
        Tabulated load: positions ``zeta/L`` [-] and load density samples (any scale).
    label : str
        Name used in tables, legends and CSV ``model`` columns.
    """

    model: str = "distributed"
    load: str = "uniform"
    lam: float = 0.0
    kappa0: float | str | None = None
    u: tuple | None = None
    f: tuple | None = None
    label: str = ""

    def __post_init__(self):
        if not self.label:
            object.__setattr__(self, "label", self.default_label())

    def default_label(self) -> str:
        if self.model == "lumped":
            if self.kappa0 == "Z":
                return "lumped kappa0(Z)"
            if self.load == "exponential" and self.kappa0 is None:
                return f"lumped kappa=lambda/L (lambda={self.lam:g})"
            if self.kappa0 is None:
                return "lumped kappa0 (set)"
            return f"lumped kappa0={self.kappa0:g}"
        if self.load == "exponential":
            return f"distributed exponential (lambda={self.lam:g})"
        return f"distributed {self.load}"

    def density(self):
        """Normal-load density per unit ``zeta/L`` [-] (unit mass): FM eqs. (3), (5), docs/models/lugre_friction.md §3.2."""
        if self.load == "uniform":
            return lugre.uniform_density
        if self.load == "parabolic":
            return lugre.parabolic_density
        if self.load == "exponential":
            lam = self.lam
            return lambda u: lugre.exponential_density(u, lam)
        if self.load == "tabulated":
            return lugre.tabulated_density(self.u, self.f)
        raise ValueError(f"unknown load {self.load!r}")

    def lumped_kappa0(self, p: lugre.LuGreParams):
        """The lumped coefficient ``kappa0`` [-] (FM eq. (8)): a number or ``"Z"`` (FM eq. (10)).

        ``self.kappa0`` when set, else ``lam`` for an exponential load (``kappa = lambda/L``), else ``p.kappa0``.

        Parameters
        ----------
        p : LuGreParams
            Tire parameters (its ``kappa0`` [-]).
        """
        if self.kappa0 is not None:
            return self.kappa0
        if self.load == "exponential":
            return self.lam
        return p.kappa0

    def mu_ss(self, vr, romega, p: lugre.LuGreParams, theta=1.0):
        """Steady-state friction ``mu`` [-] of this variant (FM eqs. (4), (6), (2); (8)-(10)).

        Parameters
        ----------
        vr : array_like
            Relative velocity ``r omega - v`` [m/s].
        romega : array_like
            Wheel circumferential speed ``r omega`` [m/s].
        p : LuGreParams
            Tire parameters, SI units.
        theta : array_like
            Road adhesion [-], FM convention.
        """
        if self.model == "lumped":
            return lugre.mu_ss_lumped(vr, romega, p, self.lumped_kappa0(p), theta)
        if self.load == "uniform":
            return lugre.mu_ss_uniform(vr, romega, p, theta)
        if self.load == "exponential":
            return lugre.mu_ss_exponential(vr, romega, p, self.lam, theta)
        return lugre.mu_ss_density(vr, romega, p, self.density(), theta)

    def shape_slope(self, x, p: lugre.LuGreParams):
        """Slope ``dS/dx`` [-] of this variant's shape ``S(x)``, ``x = L/Z``, where
        ``|mu| = theta g S(x) + sigma2 |vr|`` (the steady states of :meth:`mu_ss`):

        - uniform load, and lumped ``kappa0(Z)`` (equal to it, FM eq. (10)): ``h'(x)``;
        - exponential load (FM eq. (6)): ``lam/(1 - e^-lam) h'(lam + x)``;
        - other densities: ``int_0^1 w(u) u e^{-x u} du``;
        - lumped, constant ``kappa0`` (FM eqs. (8)-(9)): ``S = x/(x + kappa0)``, ``S' = kappa0/(x + kappa0)^2``.

        Parameters
        ----------
        x : array_like
            Dimensionless patch length ``x = L/Z`` [-], >= 0.
        p : LuGreParams
            Tire parameters (its ``kappa0`` [-] for the lumped variants).
        """
        x = np.asarray(x, dtype=float)
        if self.model == "lumped":
            k0 = self.lumped_kappa0(p)
            if k0 == "Z":
                return lugre.h_uniform_slope(x)
            with np.errstate(over="ignore"):
                return np.where(np.isinf(x), 0.0, k0 / np.square(x + k0))
        if self.load == "uniform" or (self.load == "exponential" and self.lam < 1e-8):
            return lugre.h_uniform_slope(x)
        if self.load == "exponential":
            lam = self.lam
            return lam / -np.expm1(-lam) * lugre.h_uniform_slope(lam + x)
        return lugre.density_shape_slope(x, self.density())

    def record(self) -> dict:
        out = {"model": self.model, "load": self.load, "label": self.label}
        if self.load == "exponential":
            out["lambda"] = self.lam
        if self.model == "lumped":
            out["kappa0"] = self.kappa0
        if self.load == "tabulated":
            out["u"] = list(self.u)
            out["f"] = list(self.f)
        return out
