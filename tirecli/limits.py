"""Every limit of tirecli in one place: input caps and the sample budget of a run.

Nothing a user gives may hang the tool or exhaust memory; each limit is checked before the work or
the allocation it protects, and a refusal is one line (exit 2) naming the file, line and key.

Input caps (fixed: 10 to 1000 times what real inputs need; a refusal must come within 2 s):

- files: YAML configs and parameter sets, ``.tir`` files: :data:`MAX_YAML_BYTES`, :data:`MAX_TIR_BYTES`;
  data CSVs: :data:`CSV_BYTES_PER_SAMPLE` bytes per sample of the budget (256 MB at the default), lines
  of at most :data:`MAX_CSV_LINE_BYTES`, rows counted as samples (one per
  :data:`CSV_VALUES_PER_SAMPLE` columns);
- YAML: :data:`MAX_YAML_NODES` values (aliases counted expanded, so alias bombs are refused and a
  recursive alias is an error), :data:`MAX_YAML_DEPTH` levels of nesting, keys of at most
  :data:`MAX_KEY_CHARS` and any value of at most :data:`MAX_SCALAR_CHARS` characters;
- text: titles and labels :data:`MAX_TITLE_CHARS`, other texts (descriptions, assumed, citations,
  file names) :data:`MAX_TEXT_CHARS` characters;
- formulas (``expr:`` profiles): :data:`MAX_FORMULA_CHARS` characters, :data:`MAX_FORMULA_DEPTH` levels
  of nested operations, evaluated in floating point
  (``9**9**9`` is ``inf``, an error, not a 370-million-digit integer), at most
  :data:`MAX_FORMULA_SWITCHES` switches over a run.

The sample budget: a *sample* is one stored point of a run: a row of an output table (a grid point of
a sweep, an output time of a run, a measurement sample, a point of ``mf eval``) or a step a solver
stores or must take (for the observer's adaptive solvers, an evaluation of the model at LSODA's cost:
:mod:`tirecli.numerics.observer_work`, checked again while they run). Each study estimates its samples from the config before allocating anything;
above the budget (:data:`DEFAULT_MAX_SAMPLES`, raised with ``--max-samples N`` or the config key
``run.max_samples: N``) it refuses with the estimate, and whatever the budget it refuses a run whose
estimated memory exceeds the memory available.

A leaf module: it imports nothing from tirecli but :mod:`tirecli.errors`; the config's ``run:`` block
(its schema, the budget a config asks for) is read by :mod:`tirecli.config.budget`.
"""
from __future__ import annotations

import contextlib
import contextvars
import math
from dataclasses import dataclass, field

from tirecli.errors import ConfigError, Problem, UsageError

# --------------------------------------------------------------------------- input caps

#: Largest YAML file (configs, parameter sets, the YAML form of a tyre) [bytes]; the largest shipped is 3 kB.
MAX_YAML_BYTES = 1_000_000
#: Largest ``.tir`` file [bytes]; real ones are 20-60 kB (parsing takes about 1 s per MB).
MAX_TIR_BYTES = 500_000
#: Values of one YAML document, aliases counted where they are used (a billion-laughs bomb expands to 10^9);
#: the largest shipped document has a few hundred. 20,000 values are read in a quarter of a second.
MAX_YAML_NODES = 20_000
#: Nesting levels of one YAML document (configs nest 6 levels at most).
MAX_YAML_DEPTH = 50
#: Longest key of a YAML mapping [characters] (YAML's own limit for a plain key is 1024; an explicit
#: ``? key`` has none).
MAX_KEY_CHARS = 1000
#: Longest YAML value of any kind [characters] (texts have their own, smaller caps below).
MAX_SCALAR_CHARS = 10_000
#: Longest text of a config or parameter set (description, assumed, citation, file name) [characters].
MAX_TEXT_CHARS = 2_000
#: Longest title or label (drawn in figures and legends) [characters].
MAX_TITLE_CHARS = 200
#: Longest formula of an ``expr:`` profile [characters].
MAX_FORMULA_CHARS = 500
#: Deepest nesting of the operations of a formula (``-(-(-t))`` is 4 levels; real formulas use fewer than 10).
MAX_FORMULA_DEPTH = 100
#: Most switches (jumps and kinks) a formula may have over one run.
MAX_FORMULA_SWITCHES = 10_000
#: Data CSVs may hold this many bytes per sample of the budget (256 MB at the default budget).
CSV_BYTES_PER_SAMPLE = 256
#: Longest line of a data CSV [bytes] (a row of 200 columns of 20 digits is 4 kB).
MAX_CSV_LINE_BYTES = 10_000
#: A CSV row of more columns than this counts as several samples of the budget.
CSV_VALUES_PER_SAMPLE = 16
#: Longest ``--set`` key path [parts].
MAX_KEY_PARTS = MAX_YAML_DEPTH

# --------------------------------------------------------------------------- the sample budget

#: Samples one run may store unless raised (about 1-2 GB of memory for the most expensive studies).
DEFAULT_MAX_SAMPLES = 1_000_000
#: The budget one run may be raised to (beyond, counts lose their meaning as memory estimates).
MAX_MAX_SAMPLES = 10**12
#: How to raise the budget (the option of every run command, and the config key).
OPTION = "--max-samples"
CONFIG_KEY = ("run", "max_samples")

#: ``(budget or None, whether the run has a config whose run.max_samples raises it)`` of the command running.
_LIMIT: contextvars.ContextVar = contextvars.ContextVar("tirecli_max_samples", default=(None, True))
#: The list collecting the samples of every estimate checked (:func:`recorded_estimates`), or None.
_SEEN: contextvars.ContextVar = contextvars.ContextVar("tirecli_estimates", default=None)


def max_samples() -> int:
    """The budget in force (:func:`budget` sets it for a command; :data:`DEFAULT_MAX_SAMPLES` otherwise)."""
    value = _LIMIT.get()[0]
    return DEFAULT_MAX_SAMPLES if value is None else value


@contextlib.contextmanager
def budget(limit: int | None, config_key: bool = True):
    """Run the block with the sample budget ``limit`` (None: the default); ``config_key``: a refusal also
    names ``run.max_samples`` (False for commands without a config, e.g. ``mf eval``)."""
    token = _LIMIT.set((None if limit is None else int(limit), config_key))
    try:
        yield
    finally:
        _LIMIT.reset(token)


@contextlib.contextmanager
def recorded_estimates():
    """Yield a list that receives the samples of every :class:`Estimate` checked in the block (a campaign
    counts its points against the budget at the samples its base run estimates)."""
    seen: list = []
    token = _SEEN.set(seen)
    try:
        yield seen
    finally:
        _SEEN.reset(token)


def compute_cap(cap: float) -> float:
    """A fixed compute cap (e.g. the MCPS studies' stationary points or element-steps) scaled with the budget:
    ``cap`` at the default budget, ``cap * max_samples() / DEFAULT_MAX_SAMPLES`` when the budget is raised."""
    return cap * max(1.0, max_samples() / DEFAULT_MAX_SAMPLES)


def cap_hint() -> str:
    """How to raise a compute cap (the caps scale with the sample budget)."""
    return f"(or raise {OPTION} or {'.'.join(CONFIG_KEY)}; the cap scales with it)" if _LIMIT.get()[1] \
        else f"(or raise {OPTION}; the cap scales with it)"


def _raise_hint(n: str) -> str:
    hint = f"{OPTION} {n}"
    return f"{hint} or {'.'.join(CONFIG_KEY)}: {n}" if _LIMIT.get()[1] else hint


def parse_max_samples(text: str | None, what: str = OPTION) -> int | None:
    """The value of ``--max-samples``: a whole number >= 1 (``2000000``, ``2_000_000`` or ``2e6``)."""
    if text is None:
        return None
    raw = str(text).strip().replace("_", "")
    try:
        value = float(raw) if any(c in raw for c in ".eE") else int(raw)
    except (ValueError, OverflowError):
        raise UsageError(f"{what} {str(text)[:40]!r}: expected a whole number of samples, e.g. {what} 5e6") from None
    if not (isinstance(value, int) or (math.isfinite(value) and float(value).is_integer())) \
            or not 1 <= value <= MAX_MAX_SAMPLES:
        raise UsageError(f"{what} {str(text)[:40]!r}: expected a whole number of samples from 1 to {MAX_MAX_SAMPLES:.0e}")
    return int(value)


def count_text(n: float) -> str:
    """A sample count for a message: ``3,600,001`` (or ``3.6e+15`` when astronomically large)."""
    if not math.isfinite(n):
        return "infinitely many"
    return f"{int(math.ceil(n)):,}" if n < 1e15 else f"{n:.2g}"


def bytes_text(n: float) -> str:
    """A memory size for a message: ``~1.4 GB``."""
    if not math.isfinite(n):
        return "unbounded memory"
    for unit, size in (("PB", 1e15), ("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            v = n / size
            return f"~{v:.2g} {unit}" if v < 10 else f"~{v:.0f} {unit}" if v < 1e6 else f"~{v:.1e} {unit}"
    return f"~{n:.0f} B"


def available_memory() -> float | None:
    """Memory the run may still use [bytes] (Linux ``MemAvailable``; else physical pages free; None if unknown)."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:  # noqa: PTH123 - a system file, not an input
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    import os

    try:
        return float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def steps(duration: float, step: float) -> float:
    """Points of a grid of ``step`` over ``duration`` (``duration/step + 1``, in floating point: never an
    overflow, ``inf`` for a zero step)."""
    duration, step = float(duration), float(step)
    if duration <= 0:
        return 1.0
    if not step > 0:
        return math.inf
    with contextlib.suppress(OverflowError):
        return math.floor(duration / step + 1e-9) + 1.0
    return math.inf


@dataclass
class Term:
    """One contribution to an estimate: ``samples`` points driven by the keys ``paths`` (the first of them the
    config gives is named in a refusal), each costing about ``bytes_per_sample`` of memory."""

    samples: float
    paths: tuple
    what: str
    bytes_per_sample: float


@dataclass
class Estimate:
    """The samples and memory a run will need, as a sum of :class:`Term`, checked against the budget.

    ``add`` the terms while planning, then ``check``: a ConfigError at the key of the largest term when the
    total exceeds the budget or the estimated memory exceeds the memory available.
    """

    terms: list = field(default_factory=list)

    def add(self, samples: float, paths, what: str, bytes_per_sample: float) -> "Estimate":
        paths = tuple(paths) if paths and isinstance(paths[0], tuple) else (tuple(paths),)
        self.terms.append(Term(max(float(samples), 0.0), paths, what, float(bytes_per_sample)))
        return self

    def add_product(self, axes: dict, what: str, bytes_per_sample: float) -> "Estimate":
        """A grid that is the product of the axes ``{key path: points}``; blamed on the largest axis given."""
        n = math.prod(float(v) for v in axes.values())
        paths = tuple(sorted(axes, key=lambda p: -axes[p]))
        sizes = " x ".join(f"{count_text(v)} {p[-1]}" for p, v in axes.items())
        return self.add(n, paths, f"{what} ({sizes})", bytes_per_sample)

    @property
    def samples(self) -> float:
        return sum(t.samples for t in self.terms)

    @property
    def memory(self) -> float:
        return sum(t.samples * t.bytes_per_sample for t in self.terms)

    def check(self, origins, fallback: str | None = None) -> None:
        """Refuse (ConfigError) a run over the budget or over the available memory; ``origins`` locate the
        keys (``fallback``: the file named when no ``origins``)."""
        problem = self.problem(origins, fallback)
        if problem is not None:
            raise ConfigError(problem)

    def problem(self, origins, fallback: str | None = None) -> Problem | None:
        if not self.terms:
            return None
        seen = _SEEN.get()
        if seen is not None:
            seen.append(self.samples)
        total, memory, limit = self.samples, self.memory, max_samples()
        avail = available_memory()
        over_memory = avail is not None and memory > avail
        if total <= limit and not over_memory:
            return None
        top = max(self.terms, key=lambda t: t.samples)
        path = _given(top.paths, origins)
        size = f" ({bytes_text(memory)}{f', more than the {bytes_text(avail)[1:]} of memory available' if over_memory else ''})"
        size = size if memory > 0 else ""
        need = (f"{top.what} would need {count_text(total)} samples{size}" if len(self.terms) == 1 else
                f"the run would need {count_text(total)} samples{size}, {count_text(top.samples)} of them for {top.what}")
        if over_memory or total > MAX_MAX_SAMPLES:
            msg = f"{need}; the budget is {count_text(limit)}, and this run is too large to raise it for: make it smaller"
        else:
            raise_to = _round_up(total)
            msg = f"{need}; the budget is {count_text(limit)} (raise it with {_raise_hint(raise_to)})"
        if origins is None:
            return Problem(fallback or "<input>", None, "", msg)
        return origins.problem(path, msg)


def refuse_over_budget(samples: float, what: str, bytes_per_sample: float, origins=None, paths=((),),
                       fallback: str | None = None) -> None:
    """One-term :class:`Estimate`: refuse ``samples`` samples of ``what`` over the budget (see ``Estimate.check``)."""
    Estimate().add(samples, paths, what, bytes_per_sample).check(origins, fallback)


def over_budget_message(samples: float, what: str, bytes_per_sample: float) -> str | None:
    """The budget's refusal text for ``samples`` samples of ``what`` (None within the budget); for checks
    that report through a schema context (e.g. one grid's ``num``)."""
    problem = Estimate().add(samples, ((),), what, bytes_per_sample).problem(None, "")
    return None if problem is None else problem.message


def csv_max_bytes() -> int:
    """Largest data CSV at the budget in force [bytes]."""
    return CSV_BYTES_PER_SAMPLE * max_samples()


def _given(paths, origins) -> tuple:
    """The first of ``paths`` the config or ``--set`` gives (a refusal points at what the user wrote), else the first."""
    if origins is not None:
        for p in paths:
            if tuple(p) in origins.where:
                return tuple(p)
    return tuple(paths[0])


def _round_up(n: float) -> str:
    """A budget that covers ``n``: two significant digits, rounded up (``3.7e6`` -> ``3700000``)."""
    if not math.isfinite(n) or n > MAX_MAX_SAMPLES:
        return f"{MAX_MAX_SAMPLES:.0e}".replace("+", "")
    n = int(math.ceil(n))
    digits = max(len(str(n)) - 2, 0)
    return str(-(-n // 10**digits) * 10**digits)


def text_problem(text: str, limit: int) -> str | None:
    """Why ``text`` is too long (None if it is not)."""
    if len(text) > limit:
        return f"too long: {len(text):,} characters (at most {limit:,})"
    return None


__all__ = ["DEFAULT_MAX_SAMPLES", "Estimate", "budget", "max_samples", "parse_max_samples",
           "refuse_over_budget", "over_budget_message", "steps", "available_memory", "csv_max_bytes", "text_problem"]
