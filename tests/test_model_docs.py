"""Every model function documents its arguments with their units and the equation it implements (pvlib style).

ARCHITECTURE.md "One model shape": static maps ``f(inputs..., p)`` and dynamic models ``rhs(t, x, u, p)`` /
``outputs(t, x, u, p)`` carry numpy-style docstrings with each argument's ``[unit]`` and the paper equation
(or the section of docs/models/ that restates it).
"""
from __future__ import annotations

import importlib
import inspect
import re

import pytest

MODULES = ["tirecli.models.lugre", "tirecli.models.lugre_lumped", "tirecli.models.lugre_pde",
           "tirecli.models.quarter_car", "tirecli.models.steady_peaks", "tirecli.models.variants",
           "tirecli.models.vehicle", "tirecli.models.mcps.law", "tirecli.models.mcps.tire",
           "tirecli.models.mcps.belt", "tirecli.models.mcps.params", "tirecli.observers.plant",
           "tirecli.observers.observer"]
#: Argument types without a unit: parameter objects, flags, names, callables.
NO_UNIT = re.compile(r"(LuGreParams|DahlLaw|FrictionVariant|MCPSParams|PatchReduction|QuarterCar|LumpedTire|"
                     r"DistributedTire|ObserverPlant|Observer|sequence|callable|bool|str)\b")
EQUATION = re.compile(r"\beqs?\. |§|\(\d+\)")
#: Functions that implement no equation (utilities).
NO_EQUATION = {"tirecli.models.mcps.params.MCPSParams.with_values"}


def _functions():
    for name in MODULES:
        mod = importlib.import_module(name)
        for fname, obj in vars(mod).items():
            if fname.startswith("_") or getattr(obj, "__module__", None) != name:
                continue
            if inspect.isfunction(obj):
                yield f"{name}.{fname}", obj
            elif inspect.isclass(obj):
                for mname, meth in vars(obj).items():
                    if not mname.startswith("_") and inspect.isfunction(meth):
                        yield f"{name}.{fname}.{mname}", meth


def _parameters(doc: str) -> dict | None:
    """``{name: type and description}`` of the Parameters section (None without one)."""
    m = re.search(r"^Parameters\n-+\n(.*?)(?=^\S[^\n]*\n-+\n|\Z)", doc, re.S | re.M)
    if not m:
        return None
    out, names = {}, []
    for line in m.group(1).splitlines():
        head = re.match(r"^([*\w][\w, *]*?)(?: : (.*))?$", line)
        if head and not line.startswith(" "):
            names = [n.strip().lstrip("*") for n in head.group(1).split(",")]
            for n in names:
                out[n] = head.group(2) or ""
        else:
            for n in names:
                out[n] += " " + line.strip()
    return out


@pytest.mark.parametrize("qualname, fn", list(_functions()), ids=lambda x: x if isinstance(x, str) else "")
def test_model_function_documents_units_and_equation(qualname, fn):
    doc = inspect.getdoc(fn) or ""
    args = [a for a in inspect.signature(fn).parameters if a not in ("self", "cls")]
    if not args:
        return
    if qualname not in NO_EQUATION:
        assert EQUATION.search(doc), f"{qualname}: no equation or docs/models section cited"
    if "arguments as :func:`rhs`" in doc:      # outputs(t, x, u, p): documented once, at rhs
        return
    entries = _parameters(doc)
    assert entries is not None, f"{qualname}: no Parameters section"
    for a in args:
        assert a in entries, f"{qualname}: argument {a!r} not documented"
        if not NO_UNIT.match(entries[a]):
            assert "[" in entries[a], f"{qualname}: argument {a!r} has no [unit]"
