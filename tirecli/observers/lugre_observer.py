"""The nonlinear road-adhesion / vehicle-speed observer of OBS on the lumped LuGre quarter car.

Pure, vectorized model code (no I/O, no plotting), restating ``docs/models/observer_model.md``:

- the design plant in OBS coordinates ``x = (eta, chi, z)`` (OBS (19)-(22)), with ``theta`` in the
  OBS convention (``theta_obs`` multiplies ``sigma0 |vr| / g``; ``theta_obs = 1/theta_fm``,
  :mod:`tirecli.conventions`) and ``sigma2`` in the vehicle equation only (OBS (3)-(4)): its
  parameters, matrices and nonlinearities (:class:`ObserverPlant`); its dynamics ``rhs(t, x, u, p)``
  are :mod:`tirecli.observers.plant`;
- the observer of Theorem 1 (docs/models/observer_model.md §3): output injection ``K = (k1, k2, k3)``,
  adaptation gain ``gamma``, nonlinear injection gain ``alpha`` (:class:`ObserverGains`); its dynamics
  are :mod:`tirecli.observers.observer`;
- the design checks: observability (§4), the transfer function ``G(s) = C (sI - A + KC)^-1 B``
  and its SPR conditions (§6), the error-dynamics poles, the Lipschitz sizes (§5) and the
  gain bound (17).

Units: ``eta = r m v + J omega`` and ``chi = J omega + r F_n sigma1 z`` are angular momenta
[kg m^2/s]; ``z`` [m]; the output ``y = omega`` [rad/s]; the torque ``u`` [N m].
"""
from __future__ import annotations

from dataclasses import asdict, dataclass
from functools import lru_cache

import numpy as np

from tirecli.models.lugre import LuGreParams, stribeck
from tirecli.models.vehicle import QuarterCarParams


@dataclass(frozen=True)
class ObserverGains:
    """Observer gains (OBS (14), Theorem 1; parameter-set kind ``observer``).

    Attributes
    ----------
    k1, k2 : float
        Output injection on ``eta`` and ``chi`` [kg m^2/s].
    k3 : float
        Output injection on ``z`` [m] (negative for passivity, docs/models/observer_model.md §6).
    gamma : float
        Adaptation gain of ``theta_hat`` [s/m].
    alpha : float
        Nonlinear injection gain [m] (OBS (17); a constant tuning value here).
    """

    k1: float
    k2: float
    k3: float
    gamma: float
    alpha: float

    @property
    def K(self) -> np.ndarray:
        """The output-injection vector ``K = (k1, k2, k3)``."""
        return np.array([self.k1, self.k2, self.k3], dtype=float)

    def as_dict(self) -> dict:
        return asdict(self)

    def replace(self, **kw) -> "ObserverGains":
        return ObserverGains(**{**self.as_dict(), **kw})


@dataclass(frozen=True)
class ObserverPlant:
    """The design plant of OBS: quarter car with the lumped LuGre tire, constant ``kappa``.

    ``m v' = F_n (sigma0 z + sigma1 z') + F_n sigma2 vr`` (OBS (3)),
    ``J omega' = -r F_n (sigma0 z + sigma1 z') - sigma_w omega + u`` (OBS (4)),
    ``z' = vr - theta_obs sigma0 |vr|/g(vr) z - kappa r |omega| z`` (OBS (1), (5)),
    i.e. :func:`tirecli.models.quarter_car.rhs` with ``sigma2_in_wheel=False``; in OBS coordinates
    :func:`tirecli.observers.plant.rhs`.
    """

    tire: LuGreParams
    car: QuarterCarParams

    # ----------------------------------------------------------------- constants
    @property
    def kappa(self) -> float:
        """Constant lumped coefficient ``kappa = kappa0/L`` [1/m] (OBS: 10 1/m)."""
        return self.tire.kappa0 / self.tire.L

    @property
    def c_eta(self) -> float:
        """``F_n sigma2 / m`` [1/s]: the decay of ``eta`` (A[0, 0] = -c_eta)."""
        return self.car.F_n * self.tire.sigma2 / self.car.m

    @property
    def E(self) -> np.ndarray:
        """Output coefficient ``E`` of OBS (6) (docs/models/observer_model.md §3)."""
        t, c = self.tire, self.car
        q = 1.0 + c.J / (c.m * c.r ** 2)
        return np.array([c.F_n * t.sigma2 * c.r ** 2 * q - t.sigma_w, -t.sigma_w, c.r * q])

    @property
    def P(self) -> float:
        """``r F_n sigma1`` [N s]: the bristle-damping coupling in ``chi`` and ``C``."""
        return self.car.r * self.car.F_n * self.tire.sigma1

    @property
    def Q(self) -> float:
        """``r F_n sigma0`` [N]: the bristle-stiffness torque per unit deflection."""
        return self.car.r * self.car.F_n * self.tire.sigma0

    def matrices(self):
        """``(A, B, R, E, C)`` of OBS (6) for the lumped LuGre plant (docs/models/observer_model.md §3)."""
        c = self.car
        A = np.array([[-self.c_eta, 0.0, 0.0],
                      [0.0, 0.0, -self.Q],
                      [-1.0 / (c.r * c.m), 0.0, 0.0]])
        B = np.array([0.0, 0.0, -1.0])
        R = np.array([1.0, 1.0, 0.0])
        C = np.array([0.0, 1.0, -self.P]) / c.J
        return A, B, R, self.E, C

    # ----------------------------------------------------------------- coordinates
    def to_obs_coords(self, v, omega, z):
        """``(eta, chi, z)`` from ``(v, omega, z)``: OBS (19)."""
        c = self.car
        v, omega, z = (np.asarray(a, dtype=float) for a in (v, omega, z))
        return c.r * c.m * v + c.J * omega, c.J * omega + self.P * z, z

    def from_obs_coords(self, eta, chi, z):
        """``(v, omega, z)`` from ``(eta, chi, z)``: OBS (20)."""
        c = self.car
        eta, chi, z = (np.asarray(a, dtype=float) for a in (eta, chi, z))
        omega = (chi - self.P * z) / c.J
        return (eta - c.J * omega) / (c.r * c.m), omega, z

    def speed_from_eta(self, eta, y):
        """Vehicle speed ``v = (eta - J y)/(r m)`` [m/s] from ``eta`` and the wheel speed ``y`` (docs/models/observer_model.md §3)."""
        c = self.car
        return (np.asarray(eta, dtype=float) - c.J * np.asarray(y, dtype=float)) / (c.r * c.m)

    # ----------------------------------------------------------------- nonlinearities (OBS (18))
    def a_phi(self, y, eta):
        """``sigma0 |vr| / g(vr)`` [1/s] with ``vr = r y - v(eta, y)`` (OBS appendix)."""
        vr = self.car.r * np.asarray(y, dtype=float) - self.speed_from_eta(eta, y)
        return self.tire.sigma0 * np.abs(vr) / stribeck(vr, self.tire)

    def phi(self, y, eta, z):
        """``phi = sigma0 |vr|/g(vr) z`` [m/s] (OBS (18))."""
        return self.a_phi(y, eta) * np.asarray(z, dtype=float)

    def psi(self, y, z):
        """``psi = kappa r |y| z`` [m/s] (OBS (18))."""
        return self.kappa * self.car.r * np.abs(np.asarray(y, dtype=float)) * np.asarray(z, dtype=float)

    # ----------------------------------------------------------------- fast mode
    def fast_rate(self, gains: ObserverGains, theta_hat=1.0):
        """Rate ``lambda_f = C K_eff`` [1/s] of the observer's fast output-error mode.

        ``K_eff = (k1, k2, k3 - alpha (1 + theta_hat))`` collects the linear and the nonlinear
        injection; ``y~' = -lambda_f y~ + ...`` (about 3.9e6 1/s for the OBS gains).
        """
        k3e = gains.k3 - gains.alpha * (1.0 + np.asarray(theta_hat, dtype=float))
        return (gains.k2 - self.P * k3e) / self.car.J


def plant_from(tire: LuGreParams, car: QuarterCarParams) -> ObserverPlant:
    """The OBS design plant of a tire and a vehicle parameter set."""
    return ObserverPlant(tire=tire, car=car)


# --------------------------------------------------------------------------- design checks


def observability(plant: ObserverPlant) -> dict:
    """Observability of ``(A, C)`` (docs/models/observer_model.md §4).

    Returns ``matrix`` O = (C; CA; CA^2), ``det`` and its closed form
    ``r F_n^2 sigma0 (F_n sigma1 sigma2 - m sigma0) / (J^3 m^2)``, the ``factor``
    ``F_n sigma1 sigma2 - m sigma0`` and the numerical ``rank``.
    """
    A, _, _, _, C = plant.matrices()
    O = np.vstack([C, C @ A, C @ A @ A])
    t, c = plant.tire, plant.car
    factor = c.F_n * t.sigma1 * t.sigma2 - c.m * t.sigma0
    closed = c.r * c.F_n ** 2 * t.sigma0 / (c.J ** 3 * c.m ** 2) * factor
    # An entry no larger than the rounding error of the products that formed it is zero: the
    # bound is the same products taken in absolute values. Then the rank of the row-scaled
    # matrix (the rows differ by orders of magnitude).
    aA, aC = np.abs(A), np.abs(C)
    bound = np.vstack([aC, aC @ aA, aC @ aA @ aA])
    O_clean = np.where(np.abs(O) <= 64 * np.finfo(float).eps * bound, 0.0, O)
    scaled = O_clean / np.maximum(np.linalg.norm(O_clean, axis=1, keepdims=True), 1e-300)
    rank = int(np.linalg.matrix_rank(scaled, tol=1e-9))
    return {"matrix": O, "det": float(np.linalg.det(O)), "det_closed_form": float(closed),
            "factor": float(factor), "rank": rank}


def error_matrix(plant: ObserverPlant, gains: ObserverGains) -> np.ndarray:
    """``A - K C``: the linear part of the error dynamics (OBS (12), (15))."""
    A, _, _, _, C = plant.matrices()
    return A - np.outer(gains.K, C)


def error_poles(plant: ObserverPlant, gains: ObserverGains) -> np.ndarray:
    """Eigenvalues of ``A - K C`` [1/s], sorted from the fastest (docs/models/observer_model.md §6)."""
    ev = np.linalg.eigvals(error_matrix(plant, gains))
    return ev[np.argsort(ev.real)]


def slow_pole_estimate(plant: ObserverPlant, gains: ObserverGains) -> float:
    """Singular-perturbation estimate of the slow speed-error pole [1/s] (docs/models/observer_model.md §6).

    ``-(F_n sigma2/m + k1/(r m |k3|))`` (= -0.0294 1/s for the OBS gains: time constant 34 s).
    """
    c = plant.car
    return -(plant.c_eta + gains.k1 / (c.r * c.m * abs(gains.k3))) if gains.k3 != 0 else float("nan")


def transfer_function(plant: ObserverPlant, gains: ObserverGains) -> dict:
    """``G(s) = C (sI - A + KC)^-1 B = k_c (s^2 + a1 s + a0)/(s^3 + b2 s^2 + b1 s + b0)`` (docs/models/observer_model.md §6).

    Computed for any ``K`` from ``det(sI - M + B C) - det(sI - M)`` (``M = A - KC``); for ``k2 = 0``
    the coefficients equal the closed forms of docs/models/observer_model.md §6. Also returns the zeros, the poles and
    the coefficients ``(c0, c1, c2)`` of ``Re G(jw) |D(jw)|^2 / k_c = c0 + c1 w^2 + c2 w^4``.
    """
    _, B, _, _, C = plant.matrices()
    M = error_matrix(plant, gains)
    den = np.poly(M)
    num = np.poly(M - np.outer(B, C)) - den  # C adj(sI - M) B
    num = num[1:]  # degree <= 2
    kc = float(num[0])
    a1, a0 = (float(num[1] / kc), float(num[2] / kc)) if kc != 0 else (float("nan"), float("nan"))
    b2, b1, b0 = (float(v) for v in den[1:])
    return {
        "k_c": kc, "a1": a1, "a0": a0, "b2": b2, "b1": b1, "b0": b0,
        "re_coeffs": (a0 * b0, a1 * b1 - a0 * b2 - b0, b2 - a1),
        "zeros": np.roots([1.0, a1, a0]) if kc != 0 else np.array([]),
        "poles": np.roots(den),
    }


@dataclass
class Condition:
    """One design condition: ``ok`` with the value it rests on and what it means."""

    id: str
    ok: bool
    value: float
    requirement: str
    meaning: str

    def record(self) -> dict:
        return {"id": self.id, "ok": bool(self.ok), "value": self.value, "requirement": self.requirement,
                "meaning": self.meaning}


def design_conditions(plant: ObserverPlant, gains: ObserverGains) -> list[Condition]:
    """Observability, gain-sign and SPR conditions of OBS §IV (docs/models/observer_model.md §4, §6).

    Each :class:`Condition` failing is a warning: the theorem's guarantees do not hold (the
    observer may still work in simulation, as OBS's alpha = 20 does for (17)).
    """
    t, c, g = plant.tire, plant.car, gains
    obs = observability(plant)
    tf = transfer_function(plant, gains)
    poles = error_poles(plant, gains)
    k3_min = c.J * t.sigma0 / (c.r * c.F_n * t.sigma1 ** 2)
    c0, c1, c2 = tf["re_coeffs"]
    coeffs = [tf["a1"], tf["a0"], tf["b2"], tf["b1"], tf["b0"]]
    return [
        Condition("observability", obs["rank"] == 3, obs["det"], "rank (C; CA; CA^2) = 3, i.e. F_n sigma1 sigma2 != m sigma0",
                  "(A, C) observable (A1, docs/models/observer_model.md §4)"),
        Condition("k1-positive", g.k1 > 0, g.k1, "k1 > 0", "OBS §IV-h gain sign (docs/models/observer_model.md §6)"),
        Condition("k3-negative", g.k3 < -k3_min, g.k3, f"k3 < -J sigma0/(r F_n sigma1^2) = {-k3_min:.4g} m",
                  "b2 > a1: the w^4 coefficient of Re G is positive (docs/models/observer_model.md §6)"),
        Condition("hurwitz", bool(np.all(poles.real < 0)), float(np.max(poles.real)), "all eig(A - K C) < 0",
                  "A - K C Hurwitz (A3)"),
        Condition("hf-gain", tf["k_c"] > 0, tf["k_c"], "k_c = r F_n sigma1/J > 0", "relative degree 1, positive high-frequency gain"),
        Condition("coefficients", bool(min(coeffs) > 0), float(min(coeffs)), "a1, a0, b2, b1, b0 > 0",
                  "sufficient SPR condition (docs/models/observer_model.md §6)"),
        Condition("spr", bool(c0 > 0 and c1 >= 0 and c2 > 0), float(min(c0, c1, c2)),
                  "Re G(jw) |D|^2/k_c = c0 + c1 w^2 + c2 w^4 with c0, c2 > 0, c1 >= 0",
                  "G(s) strictly positive real: P(A-KC) + (A-KC)'P = -Q, PB = C' (A3)"),
        Condition("gamma-positive", g.gamma > 0, g.gamma, "gamma > 0", "theta_hat adapts (Theorem 1)"),
        Condition("alpha-positive", g.alpha > 0, g.alpha, "alpha > 0", "nonlinear injection present (Theorem 1)"),
    ]


def lipschitz_sizes(plant: ObserverPlant, vr_max: float, omega_max: float, z_max: float) -> dict:
    """Lipschitz constants of ``phi`` and ``psi`` on a trajectory's range (docs/models/observer_model.md §5).

    ``L_psi = kappa r |omega|_max``; ``L_phi = k_z + k_eta`` with ``k_z = sigma0 |vr|_max/mu_c`` and
    ``k_eta = |z|_max/(r m) (sigma0/mu_c + sigma0 |vr|_max (mu_s - mu_c)/(v_s mu_c^2))`` (``alpha = 1``).
    """
    t, c = plant.tire, plant.car
    kz = t.sigma0 * vr_max / t.mu_c
    keta = z_max / (c.r * c.m) * (t.sigma0 / t.mu_c + t.sigma0 * vr_max * (t.mu_s - t.mu_c) / (t.v_s * t.mu_c ** 2))
    return {"k_z": kz, "k_eta": keta, "L_phi": kz + keta, "L_psi": plant.kappa * c.r * omega_max}


def alpha_bound(lambda_min_q: float, theta_max: float, L_phi: float, L_psi: float, margin: float = 0.0) -> float:
    """Sufficient nonlinear gain of OBS (17): ``(theta_max L_phi^2 + L_psi^2) / (2 (lambda_min(Q) - eps))`` [m]."""
    den = 2.0 * (lambda_min_q - margin)
    return float("inf") if den <= 0 else (theta_max * L_phi ** 2 + L_psi ** 2) / den


@lru_cache(maxsize=32)
def passivity_margin(plant: ObserverPlant, gains: ObserverGains) -> dict:
    """Best ``lambda_min(Q)`` found over ``P = P' > 0`` with ``P B = C'`` (A3; docs/models/observer_model.md §6).

    ``P B = C'`` fixes the third column of ``P`` to ``(0, -1/J, r F_n sigma1/J)``; the free entries
    ``p11, p12, p22`` are searched (Nelder-Mead, :func:`_nelder_mead`, from a few starts) to
    maximise ``lambda_min(Q)``, ``Q = -(P (A-KC) + (A-KC)' P)``. docs/models/observer_model.md §6 quotes about 1.1e-6 for
    the OBS gains, which makes the sufficient bound (17) on ``alpha`` astronomically large.
    Returns ``lambda_min_q`` (0 when no admissible ``P`` was found) and ``P`` (cached per
    plant and gains; do not modify the result).
    """
    M = error_matrix(plant, gains)
    J = plant.car.J

    def build(q):
        p11, p12, p22 = q
        Pm = np.array([[p11, p12, 0.0], [p12, p22, -1.0 / J], [0.0, -1.0 / J, plant.P / J]])
        return Pm, -(Pm @ M + M.T @ Pm)

    def cost(q):
        Pm, Q = build(q)
        return -min(np.linalg.eigvalsh(Q)[0], 1e3 * np.linalg.eigvalsh(Pm)[0])

    best_x, best_f = None, np.inf
    for x0 in ([1e-3, 0.0, 1e-2], [1.0, 0.0, 1.0], [1e-6, 0.0, 1e-3]):
        x, fx = _nelder_mead(cost, np.array(x0, dtype=float))
        if fx < best_f:
            best_x, best_f = x, fx
    Pm, Q = build(best_x)
    ok = np.linalg.eigvalsh(Pm)[0] > 0
    return {"lambda_min_q": float(np.linalg.eigvalsh(Q)[0]) if ok else 0.0, "P": Pm}


def _nelder_mead(f, x0, iters: int = 3000, xtol: float = 1e-14, ftol: float = 1e-16):
    """Minimise ``f`` from ``x0`` by the Nelder-Mead simplex (standard coefficients 1, 2, 1/2, 1/2).

    A small self-contained version: importing ``scipy.optimize`` costs more than the search.
    """
    n = len(x0)
    simplex = [x0] + [x0 + np.eye(n)[i] * (0.05 * x0[i] if x0[i] != 0 else 2.5e-4) for i in range(n)]
    vals = [f(x) for x in simplex]
    for _ in range(iters):
        order = np.argsort(vals)
        simplex = [simplex[i] for i in order]
        vals = [vals[i] for i in order]
        if (max(np.max(np.abs(x - simplex[0])) for x in simplex[1:]) <= xtol
                and max(abs(v - vals[0]) for v in vals[1:]) <= ftol):
            break
        centroid = np.mean(simplex[:-1], axis=0)
        xr = centroid + (centroid - simplex[-1])
        fr = f(xr)
        if fr < vals[0]:
            xe = centroid + 2.0 * (centroid - simplex[-1])
            fe = f(xe)
            simplex[-1], vals[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < vals[-2]:
            simplex[-1], vals[-1] = xr, fr
        else:
            xc = centroid + 0.5 * ((xr if fr < vals[-1] else simplex[-1]) - centroid)
            fc = f(xc)
            if fc < min(fr, vals[-1]):
                simplex[-1], vals[-1] = xc, fc
            else:
                simplex = [simplex[0]] + [simplex[0] + 0.5 * (x - simplex[0]) for x in simplex[1:]]
                vals = [vals[0]] + [f(x) for x in simplex[1:]]
    i = int(np.argmin(vals))
    return simplex[i], vals[i]


def linearized_error_matrix(plant: ObserverPlant, gains: ObserverGains, theta_obs: float, y: float, v: float,
                            z: float) -> np.ndarray:
    """Error dynamics (OBS (15)-(16)) linearised at ``x_hat = x``, ``theta_hat = theta`` (theta known).

    ``A - K_eff C - e3 e3' (theta a_phi + kappa r |y|) - e3 e1' theta z d a_phi/d eta`` at the
    operating point ``(y [rad/s], v [m/s], z [m])``; ``K_eff = (k1, k2, k3 - alpha (1 + theta))``.
    Its slowest eigenvalue is the speed-error mode along a trajectory (a few % off the
    ``A - K C`` value of docs/models/observer_model.md §6, which leaves out the friction terms).
    """
    t, c = plant.tire, plant.car
    A, _, _, _, C = plant.matrices()
    keff = np.array([gains.k1, gains.k2, gains.k3 - gains.alpha * (1.0 + theta_obs)])
    M = A - np.outer(keff, C)
    vr = c.r * y - v
    g = float(stribeck(vr, t))
    a_phi = t.sigma0 * abs(vr) / g
    x = abs(vr) / t.v_s
    dg = -(t.mu_s - t.mu_c) * t.alpha * x ** (t.alpha - 1.0) * np.exp(-(x ** t.alpha)) / t.v_s if vr != 0 else 0.0
    da_dvr = np.sign(vr) * t.sigma0 * (g - abs(vr) * dg) / g ** 2
    M[2, 2] -= theta_obs * a_phi + plant.kappa * c.r * abs(y)
    M[2, 0] -= theta_obs * z * da_dvr * (-1.0 / (c.r * c.m))
    return M
