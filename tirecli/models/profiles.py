"""Input profiles over time: torque, brake pressure, adhesion theta, prescribed slip or speed.

A profile is a vectorized function of time ``t`` [s] with a JSON ``record()`` written into every
run's outputs (the shape of a brake release changes the results: docs/models/lugre_friction.md §7). Kinds:

- :class:`Constant` — one value;
- :class:`Table` — piecewise-linear through ``(t_i, y_i)``, held constant outside (steps are two
  points at the same time; ramps are two points);
- :class:`Transitions` — a level that changes at given times to new levels, each change a
  ``step``, a ``linear`` ramp or a ``half-cosine`` (smooth) transition over its duration:
  ``y = y_a + (y_b - y_a) S((t - t0)/d)`` with ``S(x) = (1 - cos(pi clip(x, 0, 1)))/2``
  (docs/models/observer_model.md §7);
- :class:`Expression` — a formula of ``t`` (numpy functions, evaluated safely: no names other
  than ``t``, ``pi``, ``e`` and the functions of :data:`EXPRESSION_FUNCTIONS`; the language, and where a
  formula switches, are :mod:`tirecli.models.formulas`).

Every profile also has ``at(t)`` (fast evaluation at one float time, for time-stepping loops) and
``breakpoints(t_end)`` (times where the profile or its slope jumps; integrators end steps there).

The forms a config gives (a number, ``table``, ``initial``/``changes``, ``csv``, ``expr``), their schema
and the profiles built from them are :mod:`tirecli.config.profiles`; this module is pure (no file access,
no config schema).
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np

from tirecli.errors import token
from tirecli.models.formulas import (EXPRESSION_FUNCTIONS, FormulaError, _compile, expression_problem,  # noqa: F401
                                     formula_frequency, formula_path, switch_times)

SHAPES = ("step", "linear", "half-cosine")


def smoothstep_cos(x):
    """Half-cosine transition ``S(x) = (1 - cos(pi clip(x, 0, 1)))/2`` [-] (docs/models/observer_model.md §7)."""
    return 0.5 * (1.0 - np.cos(np.pi * np.clip(x, 0.0, 1.0)))


@dataclass(frozen=True)
class Constant:
    """A constant profile ``y(t) = value``."""

    value: float

    def __call__(self, t):
        return np.full(np.shape(t), self.value, dtype=float) if np.ndim(t) else float(self.value)

    def at(self, t: float) -> float:
        return float(self.value)

    def breakpoints(self, t_end: float | None = None) -> tuple:
        return ()

    def record(self) -> dict:
        return {"kind": "constant", "value": self.value}


@dataclass(frozen=True)
class Table:
    """Piecewise-linear profile through ``(t_i, y_i)``; constant before the first and after the last point.

    Two points at the same time make a step (the later value holds from that time on).
    """

    t: tuple
    y: tuple
    source: str = ""
    column: str = field(default="", compare=False)

    def __call__(self, t):
        tt = np.asarray(self.t, dtype=float)
        yy = np.asarray(self.y, dtype=float)
        # np.interp takes the right-most value at repeated abscissae (a step at t_i)
        out = np.interp(t, tt, yy)
        return out if np.ndim(t) else float(out)

    def at(self, t: float) -> float:
        """The value at one time ``t`` [s] (same as ``self(t)``, without numpy overhead)."""
        tt, yy = self.t, self.y
        if t <= tt[0]:
            return float(yy[0])
        i = bisect.bisect_right(tt, t)
        if i >= len(tt):
            return float(yy[-1])
        t0, t1 = tt[i - 1], tt[i]
        return float(yy[i - 1] + (yy[i] - yy[i - 1]) * (t - t0) / (t1 - t0))

    def breakpoints(self, t_end: float | None = None) -> tuple:
        return tuple(sorted(set(float(x) for x in self.t)))

    def record(self) -> dict:
        rec = {"kind": "table", "t": list(self.t), "value": list(self.y)}
        if self.source:
            rec["source"] = self.source
        return rec


@dataclass(frozen=True)
class Change:
    """One level change of :class:`Transitions`: from time ``at`` over ``duration`` to ``to``."""

    at: float
    to: float
    duration: float = 0.0
    shape: str = "half-cosine"


@dataclass(frozen=True)
class Transitions:
    """A level with changes (steps, linear ramps or half-cosine transitions), see module doc."""

    initial: float
    changes: tuple = ()

    def __call__(self, t):
        tarr = np.asarray(t, dtype=float)
        y = np.full(tarr.shape, self.initial, dtype=float)
        level = self.initial
        for c in self.changes:
            if c.shape == "step" or c.duration <= 0.0:
                frac = (tarr >= c.at).astype(float)
            elif c.shape == "linear":
                frac = np.clip((tarr - c.at) / c.duration, 0.0, 1.0)
            else:
                frac = smoothstep_cos((tarr - c.at) / c.duration)
            y = y + (c.to - level) * frac
            level = c.to
        return y if np.ndim(t) else float(y)

    def at(self, t: float) -> float:
        """The value at one time ``t`` [s] (same as ``self(t)``, without numpy overhead)."""
        y = level = self.initial
        for c in self.changes:
            if t >= c.at:
                if c.shape == "step" or c.duration <= 0.0 or t >= c.at + c.duration:
                    frac = 1.0
                elif c.shape == "linear":
                    frac = (t - c.at) / c.duration
                else:
                    frac = 0.5 * (1.0 - math.cos(math.pi * (t - c.at) / c.duration))
                y += (c.to - level) * frac
            level = c.to
        return float(y)

    def breakpoints(self, t_end: float | None = None) -> tuple:
        out = set()
        for c in self.changes:
            out.add(float(c.at))
            if c.duration > 0.0 and c.shape != "step":
                out.add(float(c.at + c.duration))
        return tuple(sorted(out))

    def record(self) -> dict:
        return {"kind": "transitions", "initial": self.initial,
                "changes": [{"at": c.at, "duration": c.duration, "to": c.to, "shape": c.shape} for c in self.changes]}


@dataclass(frozen=True)
class Expression:
    """A profile given by a formula of time ``t`` [s], e.g. ``"20 - 4*t"`` or ``"0.1*sin(2*pi*t)"``.

    Only ``t``, ``pi``, ``e``, numbers, arithmetic, comparisons (true = 1) and the functions of
    :data:`EXPRESSION_FUNCTIONS` are allowed (checked by :func:`expression_problem`).
    """

    text: str
    _code: object = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        problem = expression_problem(self.text)
        if problem is not None:
            raise ValueError(f"formula {token(self.text)}: {problem}")
        import ast

        object.__setattr__(self, "_code", _compile(ast.parse(self.text, mode="eval")))

    def __call__(self, t):
        """The formula's value at ``t`` [s] (scalar or array); UsageError (exit 2) naming the
        formula and the time where it cannot be evaluated or is not finite."""
        tarr = np.asarray(t, dtype=float)
        out = self._eval(tarr)
        bad = ~np.isfinite(out)
        if bad.any():
            raise FormulaError(self.text, f"gives {float(np.asarray(out)[bad].flat[0])} at "
                                          f"t = {_first(tarr[bad] if tarr.ndim else tarr):g} s")
        return np.array(out) if np.ndim(t) else float(out)

    def values(self, t) -> np.ndarray:
        """The formula's values at the times ``t`` [s] as a float array, NaN or infinite where it is
        so (no error: :func:`check_over_run` reports where); UsageError if it cannot be evaluated."""
        return np.array(self._eval(np.atleast_1d(np.asarray(t, dtype=float))))

    def _eval(self, tarr: np.ndarray) -> np.ndarray:
        """The formula at the times ``tarr`` (broadcast to their shape, read-only); UsageError naming
        the first time if it cannot be evaluated (a division by zero of integers, a complex value)."""
        env = {"__builtins__": {}, "t": tarr, "pi": np.pi, "e": np.e, **EXPRESSION_FUNCTIONS}
        try:
            with np.errstate(all="ignore"):
                return np.broadcast_to(_real(eval(self._code, env)), tarr.shape)  # noqa: S307 - checked AST
        except (ArithmeticError, ValueError, TypeError) as exc:
            why = ("a value overflows (beyond 1e308)" if isinstance(exc, OverflowError) else
                   "division by zero" if isinstance(exc, ZeroDivisionError) else exc)
            raise FormulaError(self.text, f"cannot be evaluated at t = {_first(tarr):g} s: {why}") from None

    def at(self, t: float) -> float:
        """The value at ``t`` [s]; at one of its switch times the right limit (the value that holds from
        that time on, as for a step of a table), so a run that restarts there starts with it."""
        t = float(t)
        for bps in self.__dict__.get("_bp_cache", {}).values():
            i = bisect.bisect_left(bps, t - 1e-12 * max(1.0, abs(t)))
            if i < len(bps) and abs(bps[i] - t) <= 1e-12 * max(1.0, abs(t)):
                return float(self(t + 1e-9 * max(abs(t), 1e-3)))
        return float(self(t))

    def breakpoints(self, t_end: float | None = None) -> tuple:
        """Times in ``[0, t_end]`` [s] where the formula switches: jumps and kinks of its comparisons,
        ``abs``, ``sign``, ``heaviside``, ``minimum``, ``maximum``, ``clip``, ``where`` and ``%``
        (:func:`switch_times`). ``t_end`` defaults to 1000 s."""
        key = 1000.0 if t_end is None else float(t_end)
        cache = self.__dict__.setdefault("_bp_cache", {})
        if key not in cache:
            cache[key] = switch_times(self.text, key)
        return cache[key]

    def frequency(self, t_end: float | None = None) -> float:
        """Frequency [Hz] of the fastest oscillation (sine, cosine) of the formula over ``[0, t_end]``
        (:func:`tirecli.models.formulas.formula_frequency`; 0 without them). ``t_end`` defaults to 1000 s."""
        key = 1000.0 if t_end is None else float(t_end)
        cache = self.__dict__.setdefault("_hz_cache", {})
        if key not in cache:
            cache[key] = formula_frequency(self.text, key)
        return cache[key]

    def record(self) -> dict:
        return {"kind": "expression", "expr": self.text}


def _real(value) -> np.ndarray:
    """A formula's value as floats; ValueError for a complex one (``(-8)**(1/3)``: never its real part)."""
    arr = np.asarray(value)
    if np.iscomplexobj(arr):
        raise ValueError("the value is a complex number (a fractional power of a negative number?)")
    return arr.astype(float)


def _first(t) -> float:
    return float(np.asarray(t, dtype=float).flat[0])


@dataclass(frozen=True)
class Limits:
    """The admissible values of a profile: its unit and bounds (``lo <= y``, ``y <= hi``, ``y > gt``;
    None: no bound). Every value must also be finite."""

    unit: str = "-"
    lo: float | None = None
    hi: float | None = None
    gt: float | None = None

    def text(self) -> str:
        parts = [f"> {self.gt:g}" if self.gt is not None else "", f">= {self.lo:g}" if self.lo is not None else "",
                 f"<= {self.hi:g}" if self.hi is not None else ""]
        return " and ".join(p for p in parts if p) or "finite"

    def bad(self, y) -> np.ndarray:
        """Mask of the values outside the limits (NaN and infinities included)."""
        y = np.asarray(y, dtype=float)
        with np.errstate(invalid="ignore"):
            out = ~np.isfinite(y)
            if self.lo is not None:
                out |= y < self.lo
            if self.hi is not None:
                out |= y > self.hi
            if self.gt is not None:
                out |= ~(y > self.gt)
        return out


#: Points of the uniform grid on which a profile is checked over a run (besides the output grid
#: and the breakpoints); the largest output grid used for the check.
CHECK_POINTS = 20001
CHECK_MAX_GRID = 4_000_000


#: The last few grids of :func:`run_times` (a campaign checks thousands of points of one run length).
_RUN_TIMES: dict = {}
_RUN_TIMES_KEEP, _RUN_TIMES_MAX_SIZE = 8, 200_000


def run_times(t_end: float, dt: float | None = None, breakpoints=()) -> np.ndarray:
    """The times [s] at which an input is checked over a run ``[0, t_end]``: the output grid (step
    ``dt``, when given and at most :data:`CHECK_MAX_GRID` points), a uniform grid of
    :data:`CHECK_POINTS` points, ``t_end``, and every breakpoint with a time just before and just
    after it (both sides of a jump). The array is read-only: the grids of the last few
    ``(t_end, dt, breakpoints)`` are kept (sorting them is most of the cost of checking a short run)."""
    key = (float(t_end), None if dt is None else float(dt), tuple(float(b) for b in breakpoints))
    t = _RUN_TIMES.get(key)
    if t is None:
        t = _run_times(*key)
        t.flags.writeable = False
        if t.size <= _RUN_TIMES_MAX_SIZE:
            if len(_RUN_TIMES) >= _RUN_TIMES_KEEP:
                _RUN_TIMES.clear()
            _RUN_TIMES[key] = t
    return t


def _run_times(t_end: float, dt: float | None, breakpoints: tuple) -> np.ndarray:
    parts = [np.linspace(0.0, t_end, CHECK_POINTS), [t_end]]
    if dt is not None and dt > 0 and t_end / dt < CHECK_MAX_GRID:
        parts.append(np.arange(int(np.floor(t_end / dt + 1e-9)) + 1) * float(dt))
    bps = np.asarray([b for b in breakpoints if 0.0 <= b <= t_end], dtype=float)
    if bps.size:
        eps = 1e-9 * np.maximum(1.0, np.abs(bps))
        parts += [bps, np.clip(bps - eps, 0.0, t_end), np.clip(bps + eps, 0.0, t_end)]
    return np.unique(np.concatenate([np.asarray(p, dtype=float) for p in parts]))


def check_over_run(profile, limits: Limits | None, t_end: float, dt: float | None = None) -> tuple | None:
    """Where ``profile`` leaves ``limits`` (or is not finite) in ``[0, t_end]``, at the times of
    :func:`run_times`: None if nowhere, else ``(sub_key, message)`` for the earliest such time, with
    ``sub_key`` the key of the profile's form (``expr``, ``csv``, ``table``, ``changes``) and the
    message naming the time and the value (and for a CSV profile its file, row and column)."""
    if isinstance(profile, Constant):
        return None
    lim = limits or Limits()
    bps = profile.breakpoints(t_end)
    t = run_times(t_end, dt, bps)
    y = profile.values(t) if isinstance(profile, Expression) else np.asarray(profile(t), dtype=float)
    bad = np.flatnonzero(lim.bad(y))
    unit = f" [{lim.unit}]" if lim.unit not in ("", "-") else ""
    must = f"must be {lim.text()}{unit} at every time of the run (0 .. {float(t_end):g} s)"
    if isinstance(profile, Table) and profile.source:
        rows = np.flatnonzero(lim.bad(profile.y))
        if rows.size:
            i = int(rows[0])
            return "csv", (f"{profile.source}: column {profile.column or 'value'!r} row {i + 1} (t = {profile.t[i]:g} s): "
                           f"{_num(profile.y[i])} is out of range: {must}")
        return None
    if not bad.size:
        return None
    i = int(bad[0])

    def value(tm):
        return float((profile.values(tm) if isinstance(profile, Expression) else
                      np.asarray(profile(np.array([tm])), dtype=float)).ravel()[0])

    at = f"{_num(y[i])} at t = {t[i]:.9g} s"
    if i > 0:  # the first time out of range, between the last good sample and this one
        a, b = float(t[i - 1]), float(t[i])
        for _ in range(60):
            if b - a <= 1e-12 * max(1.0, b):
                break
            m = 0.5 * (a + b)
            a, b = (a, m) if lim.bad(value(m)) else (m, b)
        if t[i] - b > 1e-9 * max(1.0, b):
            yb = value(b)
            if np.isfinite(y[i]) and np.isfinite(yb):
                at += f" (it leaves its range at t = {b:.9g} s)"
            else:  # not finite from there on: that is the time to name
                at = f"{_num(yb)} at t = {b:.9g} s"
    if isinstance(profile, Expression):
        return "expr", f"the formula gives {at}: {must}"
    key = "table" if isinstance(profile, Table) else "changes"
    return key, f"the profile is {at}: {must}"


def _num(v) -> str:
    v = float(v)
    return "NaN (not a number)" if v != v else f"{v:g}"
