"""Wheel-speed measurement for the observer: ideal, sampled with zero-order hold, noisy, quantised.

The observer of OBS measures the wheel speed ``y = omega``. Options (all seeded, reproducible):

- ideal: the continuous ``omega(t)``;
- ``rate`` [Hz]: sampled at ``t_k = k / rate`` and held (zero-order hold) until the next sample;
- ``noise_std`` [rad/s]: Gaussian noise added to each sample (``numpy.random.default_rng(seed)``);
- ``teeth`` (encoder teeth per revolution), as an ABS sensor gives:
  ``method: count`` counts tooth edges in each sample period,
  ``y_k = 2 pi (n_k - n_{k-1}) / (teeth T_s)`` (resolution ``2 pi / (teeth T_s)``);
  ``method: period`` times the last tooth interval, ``y_k = (2 pi / teeth) / (t_e - t_e')``
  (``t_e, t_e'`` the last two edges before ``t_k``, time-stamped by a ``clock`` [Hz] if given), a
  noise-free but delayed (half a tooth interval on average) and stepwise measurement.

A sampled measurement is *synthetic measured data* when it carries noise or quantisation.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

METHODS = ("count", "period")


@dataclass(frozen=True)
class Sensor:
    """Wheel-speed sensor model (see module doc).

    Attributes
    ----------
    rate : float or None
        Sampling rate [Hz]; ``None`` = ideal continuous measurement.
    noise_std : float
        Standard deviation of the additive Gaussian noise [rad/s].
    seed : int
        Seed of the noise generator.
    teeth : int or None
        Encoder teeth per wheel revolution; ``None`` = no quantisation.
    method : str
        ``count`` (edges per sample period) or ``period`` (time of the last tooth interval).
    clock : float or None
        Timer frequency [Hz] that time-stamps the edges of the ``period`` method (``None`` = exact).
    """

    rate: float | None = None
    noise_std: float = 0.0
    seed: int = 0
    teeth: int | None = None
    method: str = "period"
    clock: float | None = None

    @property
    def ideal(self) -> bool:
        return self.rate is None

    @property
    def synthetic(self) -> bool:
        """True when the measured signal is generated noise or quantisation (labelled synthetic)."""
        return not self.ideal and (self.noise_std > 0.0 or self.teeth is not None)

    @property
    def period(self) -> float:
        return 1.0 / self.rate if self.rate else 0.0

    def sample_times(self, duration: float) -> np.ndarray:
        """Sampling instants ``k / rate`` in ``[0, duration]`` [s] (empty when ideal)."""
        if self.ideal:
            return np.empty(0)
        n = int(math.floor(duration * self.rate * (1.0 + 1e-12))) + 1
        return np.arange(n) / self.rate

    def resolution(self) -> float | None:
        """Speed quantum [rad/s] of the ``count`` method, ``2 pi / (teeth T_s)``; None otherwise."""
        if self.teeth is None or self.method != "count" or self.ideal:
            return None
        return 2.0 * math.pi * self.rate / self.teeth

    def record(self) -> dict:
        if self.ideal:
            return {"kind": "ideal", "description": "continuous wheel speed omega(t)"}
        rec = {"kind": "sampled", "rate_hz": self.rate, "hold": "zero-order",
               "noise_std_rad_s": self.noise_std, "seed": self.seed}
        if self.teeth is not None:
            rec["encoder"] = {"teeth": self.teeth, "method": self.method, "clock_hz": self.clock,
                              "resolution_rad_s": self.resolution()}
        return rec

    def sampler(self, n_samples: int, omega0: float) -> "Sampler":
        """A stateful sampler for one simulation starting at wheel speed ``omega0`` [rad/s]."""
        return Sampler(self, n_samples, omega0)


class Sampler:
    """Produces the measured samples of :class:`Sensor` while a simulation advances.

    Call :meth:`advance` after every integration step (it tracks the wheel angle and the tooth
    edges) and :meth:`sample` at every sampling instant.
    """

    def __init__(self, sensor: Sensor, n_samples: int, omega0: float):
        self.sensor = sensor
        rng = np.random.default_rng(sensor.seed)
        self.noise = rng.normal(0.0, sensor.noise_std, n_samples).tolist() if sensor.noise_std > 0 else None
        self.k = 0
        self.angle = 0.0
        if sensor.teeth is not None:
            self.pitch = 2.0 * math.pi / sensor.teeth
            # steady rolling before t = 0: an edge at t = 0 and the previous one a pitch earlier
            self.last_edge = 0.0
            self.prev_edge = -self.pitch / omega0 if omega0 > 0 else -math.inf
            self.count_prev = 0
            self.held = omega0

    def advance(self, t0: float, t1: float, w0: float, w1: float) -> None:
        """Advance the wheel angle over ``[t0, t1]`` with ``omega`` linear between ``w0`` and ``w1``."""
        if self.sensor.teeth is None:
            return
        h = t1 - t0
        a0 = self.angle
        a1 = a0 + 0.5 * h * (w0 + w1)
        self.angle = a1
        p = self.pitch
        k0, k1 = math.floor(a0 / p), math.floor(a1 / p)
        if k1 <= k0 or self.sensor.method != "period":
            return
        # times of the last two edges crossed in this step (angle quadratic in time)
        acc = (w1 - w0) / (2.0 * h)
        for k in range(max(k0 + 1, k1 - 1), k1 + 1):
            c = k * p - a0
            disc = w0 * w0 + 4.0 * acc * c
            tau = 2.0 * c / (w0 + math.sqrt(disc)) if disc > 0 and w0 + math.sqrt(disc) > 0 else c / max(w0, 1e-12)
            self.prev_edge, self.last_edge = self.last_edge, t0 + min(max(tau, 0.0), h)

    def advance_angle(self, angle1: float, edge_time) -> None:
        """Advance to the exact wheel angle ``angle1`` [rad]; ``edge_time(a)`` gives the time [s] the angle was ``a``.

        The adaptive integrators carry the angle as a state and root-find the tooth edges on their
        interpolant (instead of :meth:`advance`'s linear ``omega`` within a step).
        """
        if self.sensor.teeth is None:
            return
        a0 = self.angle
        self.angle = angle1
        p = self.pitch
        k0, k1 = math.floor(a0 / p), math.floor(angle1 / p)
        if k1 <= k0 or self.sensor.method != "period":
            return
        for k in range(max(k0 + 1, k1 - 1), k1 + 1):
            self.prev_edge, self.last_edge = self.last_edge, float(edge_time(k * p))

    def sample(self, t: float, omega: float) -> float:
        """The measured wheel speed at sampling instant ``t`` [s] (true speed ``omega`` [rad/s])."""
        s = self.sensor
        if s.teeth is None:
            y = omega
        elif s.method == "count":
            count = math.floor(self.angle / self.pitch)
            y = (count - self.count_prev) * self.pitch * s.rate if self.k > 0 else omega
            self.count_prev = count
        else:
            t1, t0 = self.last_edge, self.prev_edge
            if s.clock:
                t1, t0 = math.floor(t1 * s.clock) / s.clock, math.floor(t0 * s.clock) / s.clock
            if t1 > t0:
                self.held = self.pitch / (t1 - t0)
            y = self.held
        if self.noise is not None and self.k < len(self.noise):
            y += self.noise[self.k]
        self.k += 1
        return y
