"""The stages of a Magic Formula 6.1 fit: which coefficients each fits, from which sweeps, in which order.

The order is the standard one (pure longitudinal, pure lateral, aligning torque, combined slip):
each stage holds the coefficients of the stages before it fixed at their fitted values. Inside a
stage the coefficients come in groups, fitted in turn on growing data (docs/models/magic_formula_tyre.md,
"Fitting a .tir to measurements"):

``nominal``
    the nominal-load coefficients, on the data at the load level nearest ``FNOMIN`` (at the camber
    nearest 0 and the pressure nearest ``NOMPRES``);
``load``
    the load dependence, on every load (camber nearest 0, pressure nearest ``NOMPRES``);
``camber``
    the camber terms, on every camber;
``pressure``
    the pressure terms, on every pressure.

Each coefficient names what the data must hold to identify it (:data:`NEEDS`): several load levels,
a camber sweep, several pressures, slips of both signs. A coefficient whose need is not met stays
at its start value and is named with the reason.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: Data requirements of the coefficients, with the reason printed when one is not met.
NEEDS = {
    "loads2": "needs two or more load levels",
    "loads3": "needs three or more load levels",
    "camber": "needs a camber sweep (two or more inclination levels)",
    "camber_loads": "needs a camber sweep at two or more load levels",
    "pressures2": "needs two or more pressure levels",
    "pressures3": "needs three or more pressure levels",
    "camber_pressures": "needs a camber sweep at two or more pressure levels",
    "pressure_loads": "needs two or more pressure levels and two or more load levels",
    "kappa_both": "needs driving and braking slip (kappa of both signs)",
    "alpha_both": "needs slip angles of both signs",
}

#: Groups of a stage, in the order they are fitted.
GROUPS = ("nominal", "load", "camber", "pressure")


@dataclass(frozen=True)
class Coef:
    """One coefficient of a stage: its group and what the data must hold to identify it."""

    name: str
    group: str
    needs: tuple = ()


@dataclass(frozen=True)
class Stage:
    """A stage of the fit.

    Attributes
    ----------
    name : str
        ``longitudinal``, ``lateral``, ``aligning``, ``combined-fx``, ``combined-fy``, ``combined-mz``.
    title : str
        What it fits, for messages and reports.
    part : str
        The fit part the user selects it by (``longitudinal``, ``lateral``, ``aligning``, ``combined``).
    channel : str
        Measured channel it fits (``fx``, ``fy``, ``mz``).
    sweep : str
        The sweep it needs in the data (skipped without one): ``longitudinal`` (alpha ~ 0),
        ``lateral`` (kappa ~ 0) or ``combined`` (both non-zero).
    points : str
        The points it fits (:data:`POINTS`): the sweep's own, or for the combined stages every point
        where the channel feels combined slip (Fy on a slip sweep at zero slip angle is G_yk Fy0 + S_Vyk).
    kind : str
        The stage's model (:data:`~.model.KINDS`): ``fx0``, ``fy0`` (pure slip, ``evaluate(...,
        combined=False)``), ``gxa``, ``gyk``, ``mz`` (combined slip, ``evaluate(..., combined=True)``).
    coefs : tuple of Coef
    after : tuple of str
        Stages whose coefficients it relies on (it is skipped when one of them was not fitted).
    refit : tuple of str
        Stages whose identified coefficients its last step fits again, together with its own (the
        aligning torque depends on the moment arm s through s Fx at free rolling too).
    pre : tuple of tuple of str
        Coefficient sets fitted in turn before the first step, on its points: the peak and the slip
        stiffness alone, then with the shape factor and the shifts, the curvatures last (a start tyre of
        another size or load rating is far off in peak and stiffness, and the curvatures would otherwise
        bend the curve to make up for them: a local minimum).
    """

    name: str
    title: str
    part: str
    channel: str
    sweep: str
    kind: str
    coefs: tuple
    after: tuple = ()
    points: str = ""
    refit: tuple = ()
    pre: tuple = ()

    @property
    def combined(self) -> bool:
        """Whether the model is evaluated with combined slip."""
        return self.kind not in ("fx0", "fy0")

    def names(self) -> list[str]:
        return [c.name for c in self.coefs]


def _coefs(spec: dict) -> tuple:
    out = []
    for group, items in spec.items():
        for item in items.split():
            name, _, needs = item.partition(":")
            out.append(Coef(name, group, tuple(n for n in needs.split(",") if n)))
    return tuple(out)


#: The stages in the order they run.
STAGES = (
    Stage("longitudinal", "pure longitudinal force Fx0(kappa)", "longitudinal", "fx", "longitudinal", "fx0", _coefs({
        "nominal": "PCX1 PDX1 PEX1 PEX4:kappa_both PKX1 PHX1 PVX1",
        "load": "PDX2:loads2 PEX2:loads2 PEX3:loads3 PKX2:loads2 PKX3:loads3 PHX2:loads2 PVX2:loads2",
        "camber": "PDX3:camber",
        "pressure": "PPX1:pressures2 PPX2:pressures3 PPX3:pressures2 PPX4:pressures3",
    }), pre=(("PDX1", "PKX1"), ("PDX1", "PKX1", "PCX1", "PHX1", "PVX1"))),
    Stage("lateral", "pure lateral force Fy0(alpha)", "lateral", "fy", "lateral", "fy0", _coefs({
        "nominal": "PCY1 PDY1 PEY1 PEY3:alpha_both PKY1 PHY1 PVY1",
        "load": "PDY2:loads2 PEY2:loads2 PKY2:loads2 PKY4:loads3 PHY2:loads2 PVY2:loads2",
        "camber": ("PDY3:camber PEY4:camber PEY5:camber PKY3:camber PKY6:camber PVY3:camber "
                   "PKY5:camber_loads PKY7:camber_loads PVY4:camber_loads"),
        "pressure": "PPY1:pressures2 PPY2:pressure_loads PPY3:pressures2 PPY4:pressures3 PPY5:camber_pressures",
    }), pre=(("PDY1", "PKY1"), ("PDY1", "PKY1", "PCY1", "PHY1", "PVY1"))),
    Stage("aligning", "aligning torque Mz(alpha) at free rolling", "aligning", "mz", "lateral", "mz", _coefs({
        "nominal": "QBZ1 QCZ1 QDZ1 QDZ6 QEZ1 QEZ4:alpha_both QHZ1 QBZ9",
        "load": "QBZ2:loads2 QBZ3:loads3 QBZ10:loads2 QDZ2:loads2 QDZ7:loads2 QEZ2:loads2 QEZ3:loads3 QHZ2:loads2",
        "camber": ("QBZ4:camber QBZ5:camber QDZ3:camber QDZ4:camber QDZ8:camber QDZ10:camber QEZ5:camber "
                   "QHZ3:camber QDZ9:camber_loads QDZ11:camber_loads QHZ4:camber_loads"),
        "pressure": "PPZ1:pressures2 PPZ2:camber_pressures",
    }), after=("lateral",), pre=(("QDZ1", "QDZ6"), ("QDZ1", "QDZ6", "QBZ1", "QCZ1", "QHZ1"))),
    Stage("combined-fx", "combined-slip Fx: G_xa(alpha)", "combined", "fx", "combined", "gxa", _coefs({
        "nominal": "RBX1 RBX2 RCX1 REX1 RHX1",
        "load": "REX2:loads2",
        "camber": "RBX3:camber",
    }), after=("longitudinal",), points="alpha", pre=(("RBX1",), ("RBX1", "RBX2", "RHX1"))),
    Stage("combined-fy", "combined-slip Fy: G_yk(kappa) and S_Vyk", "combined", "fy", "combined", "gyk", _coefs({
        "nominal": "RBY1 RBY2 RBY3 RCY1 REY1 RHY1 RVY1 RVY4 RVY5 RVY6",
        "load": "REY2:loads2 RHY2:loads2 RVY2:loads2",
        "camber": "RBY4:camber RVY3:camber",
    }), after=("longitudinal", "lateral"), points="kappa",
          pre=(("RBY1",), ("RBY1", "RBY2", "RBY3", "RHY1"), ("RBY1", "RBY2", "RBY3", "RHY1", "RVY1"))),
    Stage("combined-mz", "combined-slip Mz: moment arm s of Fx (and Mz refitted on every point)", "combined", "mz",
          "combined", "mz", _coefs({
        "nominal": "SSZ1 SSZ2",
        "camber": "SSZ3:camber SSZ4:camber_loads",
    }), after=("aligning", "combined-fx", "combined-fy"), points="all", refit=("aligning",)),
)

#: Point selections of the stages: the sweeps' own, every point with a slip angle (``alpha``), with a
#: longitudinal slip (``kappa``), or every point (``all``).
POINTS = ("longitudinal", "lateral", "combined", "alpha", "kappa", "all")

#: The parts a user selects (``FitOptions.parts``) and their stages.
PARTS = {"longitudinal": ("longitudinal",), "lateral": ("lateral",), "aligning": ("aligning",),
         "combined": ("combined-fx", "combined-fy", "combined-mz")}

#: Every coefficient the fit can change, in stage order.
FIT_COEFFICIENTS = tuple(c.name for s in STAGES for c in s.coefs)

_INF = math.inf

#: Default bounds of coefficients with a physical constraint (every other one is free). ``"sign"``
#: bounds keep the sign of the start value: the sign of mu_y (PDY1) is not identified by pure-slip data
#: (Fy0 is the same with -D_y and -B_y), the cornering stiffness keeps its ISO-W sign, and the weighting
#: functions are even in RBX2, RBY2 and RVY4 (either sign gives the same curves); the residual torque's
#: slope B_r = QBZ9 + QBZ10 B_y C_y is bounded (a peak of the residual torque narrower than the slip-angle
#: steps of the data lets it grow without end); the curvature asymmetries (PEX4, PEY3,
#: QEZ4) keep the sign of the curvature on either side of the peak (beyond 1 they only act together with a
#: curvature near 0, a second way of writing the same curve).
DEFAULT_BOUNDS = {
    "PCX1": (0.5, 2.5), "PCY1": (0.5, 2.5), "QCZ1": (0.2, 3.0), "RCX1": (0.1, 3.0), "RCY1": (0.1, 3.0),
    "PDX1": (0.05, 5.0), "PDY1": ("sign", 0.05, 5.0), "PKX1": (0.1, 500.0), "PKY1": ("sign", 0.1, 500.0),
    "PKY2": (0.05, 50.0), "PKY4": (0.2, 5.0), "PEX1": (-50.0, 1.0), "PEY1": (-50.0, 1.0),
    "REX1": (-50.0, 1.0), "REY1": (-50.0, 1.0), "QEZ1": (-50.0, 0.5), "QBZ1": (0.01, 500.0),
    "QDZ1": (1e-4, 2.0), "RBX1": (0.01, 1000.0), "RBY1": (0.01, 1000.0),
    "RBX2": ("sign", 1e-3, 1000.0), "RBY2": ("sign", 1e-3, 1000.0), "RVY4": ("sign", 1e-3, 1000.0),
    "RVY1": (-1.0, 1.0), "RVY2": (-1.0, 1.0), "RVY3": (-10.0, 10.0), "RVY5": (-5.0, 5.0), "RVY6": (-100.0, 100.0),
    "QBZ9": (-1e3, 1e3), "QBZ10": (-1e2, 1e2), "PEX4": (-1.0, 1.0), "PEY3": (-1.0, 1.0), "QEZ4": (-1.0, 1.0),
}


def default_bounds(name: str, start: float) -> tuple[float, float]:
    """The default ``(low, high)`` of a coefficient for a start value (``(-inf, inf)`` when free)."""
    b = DEFAULT_BOUNDS.get(name)
    if b is None:
        return -_INF, _INF
    if b[0] == "sign":
        lo, hi = b[1], b[2]
        return (-hi, -lo) if start < 0 else (lo, hi)
    return b


def stage(name: str) -> Stage:
    """The stage of that name."""
    for s in STAGES:
        if s.name == name:
            return s
    raise KeyError(name)
