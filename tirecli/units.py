"""Unit strings of measured data and their SI equivalents, stated once (a leaf: imports nothing from tirecli).

Measured tyre data name their units as text (TYDEX ``**MEASURCHANNELS``, MDF channel units, a CSV's
``--units fz=kN``). :func:`si` maps such a text to ``(SI unit, factor, offset)`` with
``value_SI = factor * value + offset`` (the offset is non-zero for temperatures only). The spelling
is forgiving about case where it is unambiguous (``KPA``, ``Km/h``), blanks (``N m``, ``Nm``,
``N*m``, ``N.m``), the degree sign (``°``, ``deg``, ``degree``) and brackets (``[N]``); an unknown
unit is a ``KeyError`` that the reader turns into an error naming the channel.

Dimensionless spellings (``-``, ``1``, an empty unit) map to ``"-"`` with factor 1: a channel with no
unit is read as SI.
"""
from __future__ import annotations

import math
import re

#: ``unit text (normalised) -> (SI unit, factor)``; see :func:`normalise` for the normalisation.
_TABLE: dict[str, tuple[str, float]] = {}


def _add(si_unit: str, factor: float, *names: str) -> None:
    for name in names:
        _TABLE[name] = (si_unit, float(factor))


_DEG = math.pi / 180.0
# dimensionless
_add("-", 1.0, "", "-", "1", "none", "ratio")
_add("-", 0.01, "%")
# angles
_add("rad", 1.0, "rad", "radian", "radians")
_add("rad", 1e-3, "mrad")
_add("rad", _DEG, "deg", "degree", "degrees", "°", "grad")
# forces
_add("N", 1.0, "n", "newton", "newtons")
_add("N", 1e3, "kn")
_add("N", 10.0, "dan")
_add("N", 4.4482216152605, "lbf", "lb")
_add("N", 9.80665, "kgf")
# moments
_add("N m", 1.0, "nm", "newtonmeter", "newtonmetre")
_add("N m", 1e3, "knm")
_add("N m", 10.0, "danm")
_add("N m", 0.1129848290276167, "lbfin", "inlbf", "inlb", "lbin")
_add("N m", 1.3558179483314004, "lbfft", "ftlbf", "ftlb", "lbft")
# pressures
_add("Pa", 1.0, "pa")
_add("Pa", 1e2, "hpa", "mbar")
_add("Pa", 1e3, "kpa")
_add("Pa", 1e5, "bar")
_add("Pa", 1e6, "mpa")
_add("Pa", 6894.757293168361, "psi")
# speeds
_add("m/s", 1.0, "m/s", "ms-1", "mps")
_add("m/s", 1 / 3.6, "km/h", "kmh", "kph", "kmph")
_add("m/s", 0.44704, "mph")
# lengths
_add("m", 1.0, "m", "meter", "metre", "meters", "metres")
_add("m", 1e-3, "mm")
_add("m", 1e-2, "cm")
_add("m", 0.0254, "in", "inch", "inches")
# time
_add("s", 1.0, "s", "sec", "second", "seconds")
_add("s", 1e-3, "ms", "msec")
_add("s", 60.0, "min")
_add("s", 3600.0, "h", "hr")
# angular speeds
_add("rad/s", 1.0, "rad/s", "rads-1")
_add("rad/s", _DEG, "deg/s", "°/s")
_add("rad/s", 2 * math.pi / 60.0, "rpm", "1/min", "u/min", "min-1", "rev/min")
# frequency, stiffness, mass, acceleration (channels some rigs log beside the forces)
_add("1/s", 1.0, "1/s", "hz", "s-1")
_add("N/m", 1.0, "n/m")
_add("N/m", 1e3, "n/mm", "kn/m")
_add("kg", 1.0, "kg")
_add("m/s^2", 1.0, "m/s^2", "m/s2", "ms-2")
_add("m/s^2", 9.80665, "g")
# temperatures (affine: see _OFFSETS)
_add("K", 1.0, "k", "kelvin", "degc", "°c", "celsius", "c")
_OFFSETS = {"degc": 273.15, "°c": 273.15, "celsius": 273.15, "c": 273.15}

#: Spellings whose case matters (``ms`` milliseconds, ``Ms``/``MS`` not units; ``mN`` is not ``MN``).
_CASED = {"Pa": "pa", "kPa": "kpa", "MPa": "mpa", "hPa": "hpa", "N": "n", "kN": "kn", "daN": "dan",
          "Nm": "nm", "kNm": "knm", "ms": "ms", "m": "m", "mm": "mm", "s": "s", "K": "k", "g": "g", "h": "h",
          "C": "c", "min": "min", "Hz": "hz"}


def normalise(text: str) -> str:
    """The lookup key of a unit text: brackets, blanks and ``*``/``.``/``·`` between symbols removed,
    ``deg`` spellings of the degree sign kept, lower case except where case decides (``ms``)."""
    t = str(text).strip()
    if len(t) >= 2 and t[0] + t[-1] in ("[]", "()", "{}", "''", '""'):
        t = t[1:-1].strip()
    t = t.replace("\u00b7", "").replace("*", "")
    t = re.sub(r"(?<=[A-Za-z])\.(?=[A-Za-z])", "", t)  # N.m -> Nm (a point between letters only)
    t = re.sub(r"\s+", "", t)
    if t in _CASED:
        return _CASED[t]
    return t.lower()


def known(text: str) -> bool:
    """Whether ``text`` is a unit :func:`si` knows."""
    return normalise(text) in _TABLE


def si(text: str) -> tuple[str, float, float]:
    """``(SI unit, factor, offset)`` of a unit text, ``value_SI = factor * value + offset``.

    Raises
    ------
    KeyError
        For a unit not in the table (the caller names the channel).
    """
    key = normalise(text)
    unit, factor = _TABLE[key]
    return unit, factor, _OFFSETS.get(key, 0.0)


def dimension(text: str) -> str:
    """The SI unit of ``text`` (``"rad"`` for ``deg``); KeyError when unknown."""
    return si(text)[0]


def names() -> list[str]:
    """A short list of accepted unit spellings, for messages and the docs."""
    return ["-", "%", "rad", "deg", "N", "kN", "N m", "Nm", "kN m", "Pa", "kPa", "bar", "psi", "m/s", "km/h",
            "mph", "m", "mm", "s", "ms", "rad/s", "rpm", "K", "degC"]


__all__ = ["si", "known", "normalise", "dimension", "names"]
