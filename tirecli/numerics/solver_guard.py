"""Guards around scipy's adaptive solvers: their work against the sample budget, and their failures as one line.

:class:`WorkGuard` counts the right-hand-side evaluations of a run, weighted by what one costs with the
method at hand (:data:`CALL_WORK`, in evaluations of LSODA's cost), and stops the run with a
:class:`~tirecli.errors.RunError` (the work so far, the option that raises the budget) when the work
passes the sample budget (:func:`tirecli.limits.max_samples`), or when, past a twentieth of it, its pace
so far projects beyond it: no run grinds on for minutes. The pre-run estimate of the same work is
:mod:`tirecli.numerics.observer_work`.

:func:`quiet` runs a solver with numpy's floating-point warnings off and Python's warnings recorded
(scipy's LSODA reports its failures as ``UserWarning``\\ s); :func:`failure_message` turns a failure into
one line naming the solver, why, and what to try: the user never sees a library's warning.

A leaf of numerics: numpy and :mod:`tirecli.limits`, :mod:`tirecli.errors` only.
"""
from __future__ import annotations

import contextlib
import re
import warnings

import numpy as np

from tirecli.errors import RunError
from tirecli.limits import max_samples, over_budget_message

#: Cost of one right-hand-side evaluation, in evaluations of LSODA's cost (measured per evaluation on the
#: observer system: LSODA 0.07 ms, Radau 0.17 ms, BDF 0.23 ms: their Newton iterations and LU
#: factorisations run in Python).
CALL_WORK = {"lsoda": 1.0, "radau": 2.4, "bdf": 3.3, "dop853": 1.0}
#: Evaluations between two checks of the work.
CHECK_EVERY = 1000
#: The pace of a run is projected to its end once its work passes this share of the budget.
PROJECT_AFTER = 0.05


class WorkGuard:
    """The weighted evaluations of one run over ``[t0, t_end]`` [s], checked against ``limit`` (default the
    sample budget); ``wrap(fun)`` counts every call of ``fun``, ``use(method)`` changes the weight."""

    def __init__(self, method: str, t0: float, t_end: float, limit: float | None = None):
        self.t0, self.t_end = float(t0), float(t_end)
        self.limit = float(max_samples() if limit is None else limit)
        self.work = 0.0
        self.calls = 0
        self.t_far = self.t0
        self.method = method.lower()
        self.use(method)

    def use(self, method: str) -> None:
        """Weigh the next evaluations as ``method``'s (LSODA redoing a stalled segment with BDF)."""
        self.weight = CALL_WORK.get(method.lower(), max(CALL_WORK.values()))

    def wrap(self, fun):
        def counted(t, x):
            self.calls += 1
            self.work += self.weight
            if t > self.t_far:
                self.t_far = t
            if self.calls % CHECK_EVERY == 0:
                self.check()
            return fun(t, x)
        return counted

    def check(self) -> None:
        """RunError when the work has passed the limit, or its pace so far projects beyond it."""
        done = self.t_far - self.t0
        span = self.t_end - self.t0
        projected = self.work * span / done if done > 0 else np.inf
        if self.work > self.limit or (self.work > PROJECT_AFTER * self.limit and projected > self.limit):
            what = (f"at its pace up to t = {self.t_far:.4g} s of {self.t_end:g} s ({self.work:,.0f} evaluations of "
                    f"LSODA's cost so far), the {self.method} solver")
            need = max(projected, self.work)
            msg = over_budget_message(need, what, 0.0)   # None when a limit below the budget was given
            msg = (msg.replace("would need", "would need about", 1) if msg is not None else
                   f"{what} would need about {need:,.0f} evaluations, more than its limit of {self.limit:,.0f}")
            raise RunError(msg + "; stiff or lightly damped gains and fine measurements make a run expensive")


@contextlib.contextmanager
def quiet():
    """Run a solver with numpy's floating-point warnings off; yields the list of Python warnings it raised."""
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
        warnings.simplefilter("always")
        yield caught


#: What else to try when a method fails.
_ALTERNATIVES = {"lsoda": "radau or bdf", "radau": "bdf or lsoda", "bdf": "radau or lsoda", "fixed": "lsoda or radau"}


def failure_message(method: str, t: float, caught=(), detail: str = "", sampled: bool = False) -> str:
    """One line for a failed run: the solver, where, why (from its warnings or ``detail``, without the library's
    text around it) and what to try."""
    why = ""
    for w in caught:
        text = str(w.message)
        m = re.match(r"\s*\w+:\s*(.*?)\s*(\(|\.|$)", text)
        why = (m.group(1) if m else text).strip().lower()
        if why:
            break
    why = why or detail.strip().rstrip(".").lower()
    alt = _ALTERNATIVES.get(method.lower(), "another method")
    fixed = " (or fixed, with a sampled measurement)" if sampled and method.lower() != "fixed" else ""
    return (f"the {method} solver failed at t = {t:.6g} s" + (f" ({why[:120]})" if why else "")
            + f": try solver.method: {alt}{fixed}, a looser solver.rtol, or smaller observer gains; the inputs or gains "
            "may be beyond what the model can follow")
