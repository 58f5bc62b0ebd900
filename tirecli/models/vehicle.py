"""Quarter-car vehicle parameters (docs/models/lugre_friction.md §7, docs/models/observer_model.md §1).

The quarter-car motion ``m dv/dt = F``, ``J domega/dt = -r F - sigma_w omega + u`` is built on
these parameters by the transient models.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class QuarterCarParams:
    """Quarter-car parameters.

    Attributes
    ----------
    r : float
        Effective rolling radius [m].
    m : float
        Vehicle mass carried by the wheel (a quarter of the vehicle) [kg].
    J : float
        Wheel rotational inertia [kg m^2].
    F_n : float
        Normal load on the wheel [N].
    """

    r: float
    m: float
    J: float
    F_n: float

    def as_dict(self) -> dict:
        return asdict(self)
