"""A small declarative schema for YAML inputs: types, units, ranges, did-you-mean.

Each spec checks a value at a key path and appends a :class:`~tirecli.errors.Problem` per
fault (unknown key, missing key, wrong type, out of range, NaN/inf), so one run reports every
problem of a file at once. The same specs document the format (``tirecli params show``,
README) so units live in one place.
"""
from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field
from typing import Any, Callable

from tirecli import limits
from tirecli.errors import ConfigError, control_character, token
from tirecli.io.yamlio import KeyPath, Origins

MISSING = object()
#: Memory of one point of a checked grid (a float in a list) [bytes].
_BYTES_PER_POINT = 32


class Context:
    """Collects problems while a document is checked."""

    def __init__(self, origins: Origins):
        self.origins = origins
        self.problems: list = []

    def fail(self, path: KeyPath, message: str) -> None:
        self.problems.append(self.origins.problem(path, message))

    def raise_if_any(self) -> None:
        if self.problems:
            raise ConfigError(self.problems)


def _type_name(value: Any) -> str:
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean ({value})"
    if isinstance(value, (int, float)):
        return f"the number {token(value)}"
    if isinstance(value, str):
        return f"the text {token(value)}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return type(value).__name__


def _number_hint(value) -> str:
    """Why a text that looks numeric is not read as a number (it is never guessed)."""
    import re

    if not isinstance(value, str):
        return ""
    t = value.strip()
    if re.fullmatch(r"[-+]?0[0-9_]+", t):
        return " (a leading zero is not read as a number: write it without, e.g. 10 or 8)"
    if re.fullmatch(r"[-+]?[0-9][0-9_]*(:[0-5]?[0-9])+(\.[0-9_]*)?", t):
        return " (base-60 times such as 1:30 are not read as numbers: write the value in the unit, e.g. 90)"
    try:
        float(t)
    except ValueError:
        return ""
    return " (in quotes: write the number without them)"


@dataclass
class Spec:
    """Base of all specs."""

    doc: str = ""
    default: Any = MISSING

    @property
    def required(self) -> bool:
        return self.default is MISSING

    def check(self, value: Any, path: KeyPath, ctx: Context) -> Any:  # pragma: no cover
        raise NotImplementedError

    def accepts(self, value: Any) -> bool:
        """Whether ``value`` has the right type for this spec (ranges aside); used by AnyOf."""
        return True

    def default_value(self) -> Any:
        """The value an omitted optional key takes (in the same form as a checked value)."""
        return self.default

    def describe(self) -> str:
        return self.doc


@dataclass
class Num(Spec):
    """A finite real number with optional bounds and a unit.

    ``unit`` is printed as ``[unit]``; ``eq`` names the paper's equation or table.
    """

    unit: str = "-"
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    integer: bool = False
    eq: str = ""

    def bounds_text(self) -> str:
        parts = []
        if self.gt is not None:
            parts.append(f"> {self.gt:g}")
        if self.ge is not None:
            parts.append(f">= {self.ge:g}")
        if self.lt is not None:
            parts.append(f"< {self.lt:g}")
        if self.le is not None:
            parts.append(f"<= {self.le:g}")
        return " and ".join(parts)

    def check(self, value, path, ctx):
        kind = "a whole number" if self.integer else "a number"
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            ctx.fail(path, f"expected {kind} [{self.unit}], got {_type_name(value)}{_number_hint(value)}")
            return MISSING
        if isinstance(value, float) and not math.isfinite(value):
            ctx.fail(path, f"expected a finite number [{self.unit}], got {value}")
            return MISSING
        if isinstance(value, int) and abs(value) > 1e308:  # float() would overflow
            ctx.fail(path, f"expected a finite number [{self.unit}], got an integer of about "
                           f"{int(value.bit_length() * 0.30103) + 1} digits (beyond the range of a double)")
            return MISSING
        if self.integer and not float(value).is_integer():
            ctx.fail(path, f"expected a whole number, got {value}")
            return MISSING
        v = int(value) if self.integer else float(value)
        bad = ((self.gt is not None and not v > self.gt) or (self.ge is not None and not v >= self.ge)
               or (self.lt is not None and not v < self.lt) or (self.le is not None and not v <= self.le))
        if bad:
            ctx.fail(path, f"out of range: must be {self.bounds_text()}, got {value:g}")
            return MISSING
        return v

    def accepts(self, value) -> bool:
        return isinstance(value, (int, float)) and not isinstance(value, bool)

    def describe(self) -> str:
        b = self.bounds_text()
        return f"{self.doc} [{self.unit}]" + (f" ({b})" if b else "")


@dataclass
class Str(Spec):
    """A text value, optionally restricted to ``choices`` (case-sensitive), of at most ``max_len`` characters
    (:data:`tirecli.limits.MAX_TEXT_CHARS` unless given; titles and labels take ``MAX_TITLE_CHARS``).

    Free text holds no control character but tab and line feed (:func:`tirecli.errors.control_character`):
    it is drawn in figures and written to SVG files (XML 1.0 cannot hold C0 controls, not even escaped) and
    to the terminal, so a control character is refused here, at its key, rather than altered on the way."""

    choices: tuple | None = None
    max_len: int = limits.MAX_TEXT_CHARS

    def accepts(self, value) -> bool:
        return isinstance(value, str)

    def check(self, value, path, ctx):
        if not isinstance(value, str):
            ctx.fail(path, f"expected text, got {_type_name(value)}")
            return MISSING
        too_long = limits.text_problem(value, self.max_len) if self.choices is None else None
        if too_long is not None:
            ctx.fail(path, too_long)
            return MISSING
        control = control_character(value) if self.choices is None else None
        if control is not None:
            ctx.fail(path, f"contains the control character {control[1]} (at character {control[0] + 1}): texts are "
                           "drawn in figures and written to SVG files and the terminal, where control characters "
                           "are not allowed; remove it (tabs and line breaks are fine)")
            return MISSING
        if self.choices is not None and value not in self.choices:
            same = [c for c in self.choices if c.lower() == value.lower()]  # 'FM' for 'fm': case counts
            hint = same or difflib.get_close_matches(value, self.choices, n=1)
            if not hint:
                folded = difflib.get_close_matches(value.lower(), [c.lower() for c in self.choices], n=1)
                hint = [c for c in self.choices if folded and c.lower() == folded[0]][:1]
            dym = f"; did you mean {hint[0]!r}?" if hint else ""
            ctx.fail(path, f"unknown value {token(value)}{dym} (expected one of: {', '.join(self.choices)})")
            return MISSING
        return value


@dataclass
class Bool(Spec):
    def accepts(self, value) -> bool:
        return isinstance(value, bool)

    def check(self, value, path, ctx):
        if not isinstance(value, bool):
            ctx.fail(path, f"expected true or false, got {_type_name(value)}")
            return MISSING
        return value


@dataclass
class Nullable(Spec):
    """``null`` (meaning "none", kept as None) or a value of ``spec``."""

    spec: Spec = field(default_factory=Spec)

    def accepts(self, value) -> bool:
        return value is None or self.spec.accepts(value)

    def check(self, value, path, ctx):
        return None if value is None else self.spec.check(value, path, ctx)

    def describe(self) -> str:
        return self.spec.describe() + " or null"


@dataclass
class ListOf(Spec):
    """A list whose items follow ``item``; a single scalar is accepted as a one-item list."""

    item: Spec = field(default_factory=Spec)
    min_len: int = 1
    max_len: int | None = None

    def accepts(self, value) -> bool:
        return isinstance(value, list)

    def check(self, value, path, ctx):
        if not isinstance(value, list):
            if isinstance(value, (int, float, str)) and not isinstance(value, bool):
                value = [value]
            else:
                ctx.fail(path, f"expected a list, got {_type_name(value)}")
                return MISSING
        if len(value) < self.min_len:
            ctx.fail(path, f"expected at least {self.min_len} item(s), got {len(value)}")
            return MISSING
        if self.max_len is not None and len(value) > self.max_len:
            ctx.fail(path, f"expected at most {self.max_len} item(s), got {len(value)}")
            return MISSING
        out = [self.item.check(v, path + (i,), ctx) for i, v in enumerate(value)]
        return MISSING if any(o is MISSING for o in out) else out


@dataclass
class AnyOf(Spec):
    """The first of several specs that accepts the value (problems of the best match are kept)."""

    options: tuple = ()
    what: str = ""

    def accepts(self, value) -> bool:
        return any(o.accepts(value) for o in self.options)

    def check(self, value, path, ctx):
        typed = [o for o in self.options if o.accepts(value)]
        if len(typed) == 1:  # the value's type picks the option: report its own problems
            opt = typed[0]
            if not self.what or not isinstance(opt, Str) or opt.choices is None or value in opt.choices:
                return opt.check(value, path, ctx)
            # a text that is none of the option's choices: say every form the value may take
            hint = difflib.get_close_matches(value, opt.choices, n=1)
            ctx.fail(path, f"expected {self.what}, got {token(value)}" + (f"; did you mean {hint[0]!r}?" if hint else ""))
            return MISSING
        best = None
        for opt in self.options:
            sub = Context(ctx.origins)
            out = opt.check(value, path, sub)
            if not sub.problems:
                return out
            if best is None or len(sub.problems) < len(best):
                best = sub.problems
        if self.what:
            if not isinstance(value, (dict, list)):  # a scalar of none of the forms: name them once
                ctx.fail(path, f"expected {self.what}, got {token(value)}")
            else:
                ctx.fail(path, f"expected {self.what}; " + (best[0].message if best else ""))
        else:
            ctx.problems.extend(best or [])
        return MISSING


@dataclass
class Map(Spec):
    """A mapping with known keys; unknown keys are errors with a did-you-mean.

    ``post`` is called with the checked dict for cross-field rules (e.g. ``mu_c <= mu_s``),
    normally only when the map itself had no problem. With ``post_partial`` it is also called
    when other keys were faulty (so every problem of a file is reported at once); such a
    ``post`` must skip rules whose values are ``MISSING``.
    """

    fields: dict = field(default_factory=dict)
    post: Callable | None = None
    post_partial: bool = False
    open_keys: Spec | None = None  # spec for arbitrary extra keys, if allowed

    def accepts(self, value) -> bool:
        return isinstance(value, dict)

    def default_value(self) -> Any:
        """A mapping default (e.g. ``{}``) gets the fields' own defaults for the keys it leaves out."""
        if isinstance(self.default, dict):
            out = dict(self.default)
            for key, spec in self.fields.items():
                if key not in out and not spec.required:
                    out[key] = spec.default_value()
            return out
        return self.default

    def check(self, value, path, ctx):
        if not isinstance(value, dict):
            ctx.fail(path, f"expected a mapping of keys, got {_type_name(value)}")
            return MISSING
        out: dict = {}
        n0 = len(ctx.problems)
        for key, v in value.items():
            if key in self.fields:
                continue
            if self.open_keys is not None:
                out[key] = self.open_keys.check(v, path + (key,), ctx)
                continue
            names = list(self.fields)
            hint = difflib.get_close_matches(str(key), names, n=1, cutoff=0.6)
            dym = f"; did you mean {hint[0]!r}?" if hint else ""
            ctx.fail(path + (key,), f"unknown key{dym} (expected one of: {', '.join(names)})")
        for key, spec in self.fields.items():
            if key in value:
                out[key] = spec.check(value[key], path + (key,), ctx)
            elif spec.required:
                what = spec.describe()
                ctx.fail(path, f"missing required key {key!r}" + (f" ({what})" if what else ""))
                out[key] = MISSING
            else:
                out[key] = spec.default_value()
        if self.post is not None and (self.post_partial or len(ctx.problems) == n0):
            self.post(out, path, ctx)
        return out


def collect(*steps: Callable) -> list:
    """Run each step; gather the problems of every step that raises ConfigError into one error.

    Lets a command report a bad schema key and a bad parameter value of one file together.
    """
    results, problems, seen = [], [], set()
    for step in steps:
        try:
            results.append(step())
        except ConfigError as err:
            for p in err.problems:  # two steps may find the same problem (e.g. a missing group)
                what = (p.file, p.line, p.key, p.message.split(" (")[0])
                if what not in seen:
                    seen.add(what)
                    problems.append(p)
            results.append(None)
    if problems:
        raise ConfigError(problems)
    return results


def check_document(data: Any, spec: Spec, origins: Origins, path: KeyPath = ()) -> Any:
    """Check ``data`` against ``spec``; raise one :class:`ConfigError` listing every problem."""
    ctx = Context(origins)
    out = spec.check(data, path, ctx)
    ctx.raise_if_any()
    return out


@dataclass
class Raw(Spec):
    """Any value, checked elsewhere (e.g. a parameter group resolved by the parameter sets);
    ``kind``: the kind of parameter set of such a group (its parameters' units), if one."""

    kind: str = ""

    def check(self, value, path, ctx):
        return value


@dataclass
class Grid(Spec):
    """A list of numbers, or ``{start, stop, num}`` (inclusive linear grid), with bounds and unit.

    ``num`` is checked against the sample budget (:func:`tirecli.limits.max_samples`) before the grid
    is made; the study checks the product of its grids.
    """

    unit: str = "-"
    ge: float | None = None
    le: float | None = None
    gt: float | None = None

    def accepts(self, value) -> bool:
        return isinstance(value, (dict, list, int, float)) and not isinstance(value, bool)

    def default_value(self):
        if isinstance(self.default, dict):  # {start, stop, num} -> the grid, as check() returns it
            import numpy as np

            d = self.default
            return [float(x) for x in np.linspace(d["start"], d["stop"], d["num"])]
        return self.default

    def check(self, value, path, ctx):
        num = Num(unit=self.unit, ge=self.ge, le=self.le, gt=self.gt)
        if isinstance(value, dict):
            spec = Map(fields={"start": num, "stop": num,
                               "num": Num(unit="-", integer=True, ge=1, doc="number of points")})
            out = spec.check(value, path, ctx)
            if out is MISSING or any(v is MISSING for v in out.values()):
                return MISSING
            over = limits.over_budget_message(out["num"], f"a grid of {out['num']:,} points", _BYTES_PER_POINT)
            if over is not None:
                ctx.fail(path + ("num",), over)
                return MISSING
            import numpy as np

            return [float(x) for x in np.linspace(out["start"], out["stop"], out["num"])]
        return ListOf(item=num).check(value, path, ctx)

    def describe(self) -> str:
        return f"{self.doc} [{self.unit}]: a list, or {{start, stop, num}}"
