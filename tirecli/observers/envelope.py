"""Where an observer run operates, before it runs: the slip speed and the size of ``phi`` the scenario
drives the tyre to, and the rates of the observer's modes there (docs/models/observer_model.md §3, §6).

An integrator's work and accuracy depend on the fastest modes of plant + observer, which depend on the
state; these closed forms give their size at the operating point a scenario reaches, so a run can be
estimated (and refused) before it starts (:mod:`tirecli.numerics.observer_work`):

- **the knee** of the steady friction curve at speed ``v``: the slip speed where the bristles' transport
  ``theta_obs sigma0 |vr|/g(vr)`` equals their relaxation ``kappa r |omega| ~ kappa v``, i.e.
  ``|vr| = kappa v g(vr) / (theta_obs sigma0)`` (solved by fixed-point iteration); below it the friction
  grows about linearly with ``vr``, above it saturates at ``g/theta_obs``. A run that uses the tyre's grip
  (OBS Fig. 2: ``|vr|`` up to 1.9 m/s, knee 1.5 m/s) operates near it;
- **spin-up**: a driving torque above the largest the tyre transmits, ``r F_n mu_s / theta_obs``, spins the
  wheel up at least at ``(u - r F_n mu_s/theta_obs)/J``, until the wheel's viscous friction ``sigma_w omega``
  takes the excess: the slip speed reaches about the smaller of ``r/J`` times the integral of the excess over
  the run and ``r (u - r F_n mu_s/theta_obs)/sigma_w`` (OBS Fig. 2 plant at 5000 N m: 1.1 km/s; the plant has
  no brake lock, so a braking excess turns the wheel backwards alike, ``|vr| >= v``);
- in steady state ``z = vr / (theta_obs sigma0 |vr|/g + kappa r |omega|)``, so
  ``phi = sigma0 |vr|/g z`` (OBS (18)) is ``vr/(2 theta_obs)`` at the knee and tends to ``vr/theta_obs``
  beyond;
- **the adaptation loop**: linearised at ``y~ = 0``, the output error and the adhesion error obey
  ``y~' = -lambda_f y~ + (P phi/J) theta~`` and ``theta~' = -gamma phi y~`` (OBS (14)), so
  ``s^2 + lambda_f s + gamma phi^2 P/J = 0``: natural frequency ``omega_a = phi sqrt(gamma P/J)`` and
  damping ratio ``zeta = lambda_f / (2 omega_a)``. For ``zeta < 1`` the loop rings at
  ``omega_a sqrt(1 - zeta^2)`` (OBS Fig. 2 at the knee, ``phi = 0.74`` m/s: ``zeta = 96`` with the OBS gains,
  no ringing; ``zeta = 0.043`` with ``gamma = 1e12``, ``4.3e-11`` with ``gamma = 1e30``).

Pure (numpy); tests: tests/robustness/test_hazards.py (the loop's roots against the eigenvalues of the
full system's Jacobian).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tirecli.models.lugre import stribeck
from tirecli.observers.lugre_observer import ObserverGains, ObserverPlant


def knee_slip_speed(plant: ObserverPlant, v: float, theta_obs: float = 1.0) -> float:
    """Slip speed [m/s] at the knee of the steady friction curve at vehicle speed ``v`` [m/s] (module doc)."""
    t = plant.tire
    vr = plant.kappa * abs(v) * t.mu_s / (theta_obs * t.sigma0)
    for _ in range(20):
        vr = plant.kappa * abs(v) * float(stribeck(vr, t)) / (theta_obs * t.sigma0)
    return vr


def steady_phi(plant: ObserverPlant, vr: float, v: float, theta_obs: float = 1.0) -> float:
    """``|phi|`` [m/s] (OBS (18)) in the steady bristle state at slip speed ``vr`` and speed ``v`` [m/s]."""
    t = plant.tire
    vr = abs(vr)
    if vr == 0.0:
        return 0.0
    a_phi = t.sigma0 * vr / float(stribeck(vr, t))
    return a_phi * vr / (theta_obs * a_phi + plant.kappa * abs(v + vr))


def torque_capacity(plant: ObserverPlant, theta_obs: float = 1.0) -> float:
    """The largest wheel torque [N m] the tyre transmits: ``r F_n mu_s / theta_obs``."""
    return plant.car.r * plant.car.F_n * plant.tire.mu_s / theta_obs


@dataclass(frozen=True)
class Envelope:
    """The operating point of a run (module doc).

    Attributes
    ----------
    vr : float
        Slip speed [m/s] the run reaches: the knee, or the spin-up (lock) one when the torque exceeds the tyre's.
    phi : float
        ``|phi|`` [m/s] there.
    knee : float
        Slip speed of the knee [m/s].
    capacity : float
        The largest torque the tyre transmits [N m].
    torque_max : float
        The largest ``|u|`` of the run [N m].
    spin : bool
        Whether the torque exceeds the capacity (the wheel spins up or locks).
    theta_max, theta_min : float
        The largest and smallest ``theta_obs`` of the run [-] (least and most grip).
    """

    vr: float
    phi: float
    knee: float
    capacity: float
    torque_max: float
    spin: bool
    theta_max: float = 1.0
    theta_min: float = 1.0


def operating_envelope(plant: ObserverPlant, v0: float, t, torque, theta_obs) -> Envelope:
    """The :class:`Envelope` of a run from its initial speed ``v0`` [m/s] and its torque [N m] and adhesion
    ``theta_obs`` [-] at the times ``t`` [s] (increasing, covering the run)."""
    t, u, th = (np.asarray(a, dtype=float) for a in (t, torque, theta_obs))
    th_min = float(np.min(th)) if th.size else 1.0
    knee = knee_slip_speed(plant, v0, th_min)
    cap = torque_capacity(plant, th_min)
    u_max = float(np.max(np.abs(u))) if u.size else 0.0
    vr = knee
    if u.size > 1:
        excess = np.maximum(np.abs(u) - cap, 0.0)   # the plant has no brake lock: a braking excess turns the wheel back
        spin_up = plant.car.r / plant.car.J * float(np.sum(0.5 * (excess[1:] + excess[:-1]) * np.diff(t)))
        if plant.tire.sigma_w > 0:   # the wheel's viscous friction takes the excess at omega = excess/sigma_w
            spin_up = min(spin_up, plant.car.r * float(np.max(excess)) / plant.tire.sigma_w)
        vr = max(vr, spin_up)
        if float(np.min(u)) < -cap:
            vr = max(vr, abs(v0))           # at least locked: vr = -v
    spin = vr > knee
    return Envelope(vr=vr, phi=steady_phi(plant, vr, v0, th_min), knee=knee, capacity=cap, torque_max=u_max, spin=spin,
                    theta_max=float(np.max(th)) if th.size else 1.0, theta_min=th_min)


def adaptation_loop(plant: ObserverPlant, gains: ObserverGains, phi: float, theta_hat: float = 1.0) -> tuple[float, float]:
    """``(omega_a [rad/s], zeta [-])`` of the adaptation loop at ``|phi|`` [m/s] (module doc); ``zeta`` is
    ``inf`` when the loop does not oscillate at all (``gamma phi = 0``)."""
    lam = float(plant.fast_rate(gains, theta_hat))
    w2 = abs(gains.gamma) * phi * phi * plant.P / plant.car.J
    if not w2 > 0.0:
        return 0.0, math.inf
    wa = math.sqrt(w2)
    return wa, lam / (2.0 * wa)
