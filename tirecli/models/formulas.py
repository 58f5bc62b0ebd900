"""Formulas of time (``expr:`` profiles): the admissible language, its sandboxed compilation, and where a
formula switches (jumps or kinks) over a run.

:func:`expression_problem` checks a formula (only ``t``, ``pi``, ``e``, numbers, arithmetic, comparisons
and the functions of :data:`EXPRESSION_FUNCTIONS`, at most :data:`tirecli.limits.MAX_FORMULA_CHARS`
characters and :data:`tirecli.limits.MAX_FORMULA_DEPTH` levels); :func:`_compile` gives its code, evaluated
in floating point. :func:`switch_times` finds the times it switches and refuses a formula that switches
more than :data:`tirecli.limits.MAX_FORMULA_SWITCHES` times over a run; :func:`oscillation_rate` bounds
how fast its sines and cosines change sign (from the rate of their arguments), which sizes the grids the
switches are counted on (so no periodic switching aliases away) and tells integrators how fast the input
varies. The profile built on a formula is :class:`tirecli.models.profiles.Expression`.

Pure: numpy (and scipy's ``brentq`` to refine switch times); no file access, no config schema.
"""
from __future__ import annotations

import numpy as np

from tirecli.errors import UsageError, token

#: Functions an :class:`Expression` may call (numpy, elementwise).
EXPRESSION_FUNCTIONS = {
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "log": np.log, "sqrt": np.sqrt,
    "abs": np.abs, "tanh": np.tanh, "arctan": np.arctan, "sign": np.sign, "minimum": np.minimum,
    "maximum": np.maximum, "clip": np.clip, "where": np.where, "heaviside": np.heaviside,
}
#: How many arguments each function of a formula takes (numpy's ufuncs would take an ``out`` array as an
#: extra argument and write into it).
_ARITY = {"minimum": 2, "maximum": 2, "heaviside": 2, "clip": 3, "where": 3}
_EXPRESSION_NAMES = {"t", "pi", "e"} | set(EXPRESSION_FUNCTIONS)
_EXPRESSION_NODES = ("Expression", "BinOp", "UnaryOp", "Compare", "Call", "Name", "Load", "Constant", "Add", "Sub",
                     "Mult", "Div", "Pow", "Mod", "USub", "UAdd", "Lt", "LtE", "Gt", "GtE")


def expression_problem(text: str) -> str | None:
    """Why ``text`` is not an admissible formula of ``t`` (None if it is): at most
    :data:`tirecli.limits.MAX_FORMULA_CHARS` characters of numbers, ``t``, ``pi``, ``e``, arithmetic,
    comparisons and calls of :data:`EXPRESSION_FUNCTIONS` with their number of arguments."""
    import ast  # lazily: start-up time of every command

    from tirecli.limits import MAX_FORMULA_CHARS, text_problem

    too_long = text_problem(text, MAX_FORMULA_CHARS)
    if too_long is not None:
        return f"formula {too_long}"
    allowed = tuple(getattr(ast, n) for n in _EXPRESSION_NODES)
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        return f"cannot read the formula ({exc.msg})"
    except (ValueError, RecursionError, MemoryError):  # NUL bytes, too deeply nested, a number of 5000 digits
        return "cannot read the formula"
    from tirecli.limits import MAX_FORMULA_DEPTH

    if _depth(tree) > MAX_FORMULA_DEPTH:
        return f"formula nested too deeply (more than {MAX_FORMULA_DEPTH} operations inside one another)"
    for node in ast.walk(tree):
        if not isinstance(node, allowed):
            return f"not allowed in a formula: {type(node).__name__}"
        if isinstance(node, ast.Name) and node.id not in _EXPRESSION_NAMES:
            return f"unknown name {token(node.id)} (use t, pi, e and {', '.join(sorted(EXPRESSION_FUNCTIONS))})"
        if isinstance(node, ast.Call):
            if not (isinstance(node.func, ast.Name) and node.func.id in EXPRESSION_FUNCTIONS):
                return "only the listed functions may be called"
            n = _ARITY.get(node.func.id, 1)
            if len(node.args) != n:
                return f"{node.func.id}() takes {n} argument{'s' if n > 1 else ''}, got {len(node.args)}"
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                return "only numbers are allowed as constants"
            if isinstance(node.value, int) and abs(node.value) > 1e308:
                return "a number too large (at most 1e308)"
    return None


def _depth(tree) -> int:
    """Levels of operations of a parsed formula (iteratively: a formula cannot exhaust the stack)."""
    import ast

    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, level = stack.pop()
        deepest = max(deepest, level)
        stack.extend((kid, level + 1) for kid in ast.iter_child_nodes(node))
    return deepest


def _compile(node, name: str = "<formula>"):
    """Code of a checked formula (or a part of one) evaluated in floating point: every whole number becomes a
    float, so ``9**9**9`` is ``inf`` (an error) at once instead of an integer of 370 million digits. The
    constants of ``node`` are converted in place."""
    import ast

    for c in ast.walk(node):
        if isinstance(c, ast.Constant) and isinstance(c.value, int) and not isinstance(c.value, bool):
            c.value = float(c.value)
    body = node.body if isinstance(node, ast.Expression) else node
    return compile(ast.fix_missing_locations(ast.Expression(body=body)), name, "eval")


class FormulaError(UsageError):
    """A formula that cannot be used: ``reason`` says why, without the formula, so that a study can name
    the key that gives it instead (:func:`formula_path`)."""

    def __init__(self, formula: str, reason: str):
        super().__init__(f"formula {token(formula)} {reason}")
        self.formula, self.reason = formula, reason


def formula_path(data, formula: str) -> tuple | None:
    """The key path of the first ``{expr: formula}`` in a config's ``data`` (None if none)."""
    from collections import deque

    stack = deque([((), data)])
    while stack:
        path, node = stack.popleft()
        if isinstance(node, dict):
            if node.get("expr") == formula:
                return path + ("expr",)
            stack.extend((path + (k,), v) for k, v in node.items())
        elif isinstance(node, list):
            stack.extend((path + (i,), v) for i, v in enumerate(node))
    return None


# --------------------------------------------------------------------------- where a formula switches

#: Functions of a formula whose value or slope jumps where their argument crosses a value.
_KINK_FUNCTIONS = {"abs", "sign", "heaviside", "where"}
_PAIR_FUNCTIONS = {"minimum", "maximum"}
#: Functions that oscillate: a sine's sign changes where its argument crosses a multiple of pi.
_TRIG_FUNCTIONS = {"sin", "cos", "tan"}
#: Grid points per sign change of the fastest oscillation in a switching function when its switches are
#: counted: a sine then has samples of both signs between any two of its zeros, so no periodic switching
#: is lost to aliasing (on a grid of 2 points per switch, ``sin(2 pi 15000 t)`` on ``[0, 1]`` s samples zeros only).
POINTS_PER_SWITCH = 4
#: Most points one switching function is evaluated on to count its switches (about 20 ms); a run needing
#: more is counted on :data:`COUNT_WINDOWS` windows of this many points in all, spread over the run.
MAX_COUNT_POINTS = 1_000_000
COUNT_WINDOWS = 8


def _evaluator(node):
    """``g(t)`` of a part of a checked formula (an ast node), evaluated in floating point."""
    code = _compile(node, "<switch>")
    env = {"__builtins__": {}, "pi": np.pi, "e": np.e, **EXPRESSION_FUNCTIONS}
    return lambda t: np.asarray(eval(code, {**env, "t": t}), dtype=float)  # noqa: S307 - checked AST


def _switching_functions(tree) -> list:
    """``(kind, g, node)`` of every non-smooth construct of a parsed formula (:func:`switch_times`): ``kind``
    ``sign`` (a switch where ``g`` changes sign) or ``floor`` (where ``g`` crosses an integer)."""
    import ast

    funcs = []

    def diff(a, b):
        fa, fb = _evaluator(a), _evaluator(b)
        return lambda t: fa(t) - fb(t)

    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            left = node.left
            for right in node.comparators:
                funcs.append(("sign", diff(left, right), node))
                left = right
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            name, args = node.func.id, node.args
            if name in _KINK_FUNCTIONS and args and not (name == "where" and isinstance(args[0], ast.Compare)):
                funcs.append(("sign", _evaluator(args[0]), args[0]))
            elif name in _PAIR_FUNCTIONS and len(args) >= 2:
                funcs.append(("sign", diff(args[0], args[1]), node))
            elif name == "clip" and len(args) >= 3:
                funcs.append(("sign", diff(args[0], args[1]), node))
                funcs.append(("sign", diff(args[0], args[2]), node))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod):
            a, b = _evaluator(node.left), _evaluator(node.right)
            funcs.append(("floor", lambda t, a=a, b=b: a(t) / b(t), node))
    return funcs


def oscillation_rate(node, t) -> float:
    """Sign changes per second [1/s] the sines, cosines and tangents of ``node`` (a part of a checked formula,
    an ast node) may make at the times ``t``: ``sin(a(t))`` changes sign where ``a`` crosses a multiple of pi,
    at most ``max |a'(t)| / pi`` times per second (``a'`` by differences on ``t``: exact for the usual
    ``2*pi*f*t``); the rates of several add up. 0 for a formula without them. Half the rate is the frequency
    [Hz] of the fastest oscillation."""
    import ast

    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return 0.0
    rate = 0.0
    with np.errstate(all="ignore"):
        for c in ast.walk(node):
            if isinstance(c, ast.Call) and isinstance(c.func, ast.Name) and c.func.id in _TRIG_FUNCTIONS and c.args:
                try:
                    a = np.broadcast_to(_evaluator(c.args[0])(t), t.shape)
                except (ArithmeticError, ValueError, TypeError):
                    continue
                slope = np.abs(np.diff(a)) / np.diff(t)
                slope = slope[np.isfinite(slope)]
                if slope.size:
                    rate += float(np.max(slope)) / np.pi
    return rate if np.isfinite(rate) else np.inf


#: Functions whose value is piecewise constant in their (first) argument: a sine inside only decides where they switch.
_STEP_FUNCTIONS = {"sign", "heaviside"}


def formula_frequency(text: str, t_end: float, grid: int = 20001) -> float:
    """Frequency [Hz] of the fastest oscillation of a checked formula's value over ``[0, t_end]``: its sines and
    cosines (:func:`oscillation_rate`), but not those that only decide where it switches (inside a comparison,
    the condition of ``where``, the argument of ``sign`` or ``heaviside``: :func:`switch_times` counts
    those); 0 for a formula without them."""
    import ast

    if not t_end > 0:
        return 0.0
    smooth, stack = [], [ast.parse(text, mode="eval").body]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.Compare):
            continue
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            if node.func.id in _STEP_FUNCTIONS:
                stack.extend(node.args[1:])
                continue
            if node.func.id == "where":
                stack.extend(node.args[1:])
                continue
            if node.func.id in _TRIG_FUNCTIONS:
                smooth.append(node)
                continue
        stack.extend(ast.iter_child_nodes(node))
    t = np.linspace(0.0, float(t_end), int(grid))
    return 0.5 * sum(oscillation_rate(node, t) for node in smooth)


def _changes(kind: str, vals) -> int:
    """Switches between consecutive samples: sign changes (zeros skipped) or integers crossed."""
    vals = np.asarray(vals, dtype=float)
    if kind == "floor":
        lev = np.floor(vals)
        ok = np.isfinite(lev[:-1]) & np.isfinite(lev[1:])
        return int(np.sum(np.abs(lev[1:] - lev[:-1])[ok]))
    sg = np.sign(vals)
    nz = sg[np.isfinite(vals) & (sg != 0)]
    return int(np.count_nonzero(nz[1:] != nz[:-1]))


def _windowed_count(kind: str, g, rate: float, t_end: float) -> float:
    """Switches of ``g`` over ``[0, t_end]`` estimated from :data:`COUNT_WINDOWS` windows of fine samples
    (:data:`POINTS_PER_SWITCH` per sign change at ``rate``) spread over the run."""
    m = MAX_COUNT_POINTS // COUNT_WINDOWS
    dt = 1.0 / (POINTS_PER_SWITCH * rate)
    width = (m - 1) * dt
    total = 0
    for start in np.linspace(0.0, max(t_end - width, 0.0), COUNT_WINDOWS):
        tw = start + np.arange(m) * dt
        try:
            total += _changes(kind, np.broadcast_to(g(tw), tw.shape))
        except (ArithmeticError, ValueError, TypeError):
            continue
    return total * t_end / (COUNT_WINDOWS * width)


def switch_times(text: str, t_end: float, grid: int = 20001) -> tuple:
    """Times in ``(0, t_end)`` [s] where a formula of ``t`` may jump or kink (its switches).

    Every non-smooth construct of the formula gives a *switching function* ``g(t)`` that changes sign
    there: ``a < b`` (any comparison) gives ``a - b``; ``abs(x)``, ``sign(x)``, ``heaviside(x, h)`` and
    ``where(x, ...)`` give ``x``; ``minimum(a, b)``, ``maximum(a, b)`` give ``a - b``; ``clip(x, lo,
    hi)`` gives ``x - lo`` and ``x - hi``; ``a % b`` jumps where ``a/b`` crosses an integer. Each is
    evaluated on a grid over ``[0, t_end]``: ``grid`` points, or :data:`POINTS_PER_SWITCH` per sign change
    its sines and cosines may make (:func:`oscillation_rate`), whichever is finer, so that a periodic
    switching is counted, never aliased away; where that grid would exceed :data:`MAX_COUNT_POINTS`
    points, the switches are counted on windows of it spread over the run and extrapolated. More than
    :data:`tirecli.limits.MAX_FORMULA_SWITCHES` switches in all is a :class:`FormulaError`; otherwise every
    sign change (every integer ``a/b`` crosses) is refined by Brent's method to 1e-12 s. Switches closer
    together than the grid spacing of a non-periodic formula may still be missed (a formula is not a place
    for sub-millisecond pulses over long runs).
    """
    import ast

    from tirecli.limits import MAX_FORMULA_SWITCHES

    tree = ast.parse(text, mode="eval")
    funcs = _switching_functions(tree)
    if not funcs or not t_end > 0:
        return ()
    t_end = float(t_end)
    base = np.linspace(0.0, t_end, int(grid))
    out = set()
    found = []   # (switching function, its grid, its values, grid intervals with a switch, floor kind)
    count = 0.0
    with np.errstate(all="ignore"):
        for kind, g, node in funcs:
            rate = oscillation_rate(node, base)
            need = POINTS_PER_SWITCH * rate * t_end + 1.0
            tg = base
            if need > MAX_COUNT_POINTS:
                est = _windowed_count(kind, g, rate, t_end)
                if est > MAX_FORMULA_SWITCHES:
                    raise FormulaError(text, f"switches (jumps or kinks) about {est:,.0f} times in [0, {t_end:g}] s "
                                             f"(counted on {COUNT_WINDOWS} sample windows; at most "
                                             f"{MAX_FORMULA_SWITCHES:,}): give a table or a CSV profile")
            elif need > grid:
                tg = np.linspace(0.0, t_end, int(np.ceil(need)))
            try:
                vals = np.broadcast_to(g(tg), tg.shape)
            except (ArithmeticError, ValueError, TypeError):
                continue
            count += _changes(kind, vals)
            if kind == "floor":
                lev = np.floor(vals)
                idx = np.flatnonzero(np.isfinite(lev[:-1]) & np.isfinite(lev[1:]) & (lev[:-1] != lev[1:]))
                found.append((g, tg, lev, idx))
                continue
            sg = np.sign(vals)
            nz = np.flatnonzero(np.isfinite(vals) & (sg != 0))
            gap = (nz[1:] > nz[:-1] + 1) & (sg[nz[:-1]] * sg[nz[1:]] < 0)  # zeros exactly on the grid
            out.update(tg[nz[:-1][gap] + 1].tolist())
            found.append((g, tg, None, np.flatnonzero(np.isfinite(vals[:-1]) & np.isfinite(vals[1:])
                                                      & (sg[:-1] * sg[1:] < 0))))
        if count > MAX_FORMULA_SWITCHES:
            raise FormulaError(text, f"switches (jumps or kinks) {count:,.0f} times or more in [0, "
                                     f"{t_end:g}] s (at most {MAX_FORMULA_SWITCHES:,}): give a table or a CSV profile")
        from scipy.optimize import brentq

        for g, tg, lev, idx in found:  # refine each switch to 1e-12 s
            for i in idx:
                if lev is not None:   # every integer a/b crosses in the interval
                    levels = range(int(min(lev[i], lev[i + 1])) + 1, int(max(lev[i], lev[i + 1])) + 1)
                    roots = [lambda t, g=g, k=k: float(g(np.asarray(t))) - k for k in levels]
                else:
                    roots = [lambda t, g=g: float(g(np.asarray(t)))]
                for h in roots:
                    try:
                        out.add(float(brentq(h, tg[i], tg[i + 1], xtol=1e-12)))
                    except ValueError:
                        out.add(float(tg[i + 1]))
    return tuple(sorted(x for x in out if 0.0 < x < t_end))
