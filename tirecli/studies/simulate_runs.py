"""Reading a simulate result (:mod:`tirecli.studies.simulate`): its cases and runs, the open-loop model
errors, and the labels of the cases of the built-in FM configs. Used by the transient figures and
their reference checks; cheap to import (numpy only).

``payload["runs"]`` holds each case's :class:`~tirecli.numerics.ros2.Trajectory` on the solver's
steps, ``payload["cases"]`` the planned cases.
"""
from __future__ import annotations

import numpy as np

#: Labels of the cases of the built-in FM configs (tirecli/studies/configs/fm-fig*.yaml).
BRAKINGS = ("braking #1", "braking #2", "braking #3")
LUMPED_950 = "lumped kappa0(Z), T_max = 950 N m"
LUMPED_1050 = "lumped kappa0(Z), T_max = 1050 N m"
LOCK_1100 = "T_max = 1100 N m"
STEP_RELEASE = "T_max = 1000 N m, step release at 2.6 s"
LUMPED_Z_COUPLED = "lumped kappa0(Z), coupled"


def coupled(result) -> list:
    return [c for c in result.payload["cases"] if c.mode == "coupled"]


def open_loop_of(result, driver: str) -> list:
    """Open-loop cases driven by the coupled case ``driver``."""
    return [c for c in result.payload["cases"] if c.mode == "open-loop" and c.driven_by == driver]


def run_of(result, label: str):
    return result.payload["runs"].get(label)


def open_loop_errors(result, driver: str, case) -> dict:
    """Max |mu_model - mu_truth| on the model's steps, and RMS / max at the 100 Hz samples."""
    truth = run_of(result, driver)
    tr = run_of(result, case.label)
    cont = np.abs(tr.out["mu"] - np.interp(tr.t, truth.t, truth.out["mu"]))
    ts = np.round(np.arange(int(np.floor(tr.t[-1] / 0.01 + 1e-9)) + 1) * 0.01, 12)
    d = np.interp(ts, tr.t, tr.out["mu"]) - np.interp(ts, truth.t, truth.out["mu"])
    return {"max": float(cont.max()), "rms100": float(np.sqrt(np.mean(d * d))), "max100": float(np.abs(d).max())}


def variant_tag(case) -> str:
    """The lumped coefficient of a case's tire model as text: ``Z``, the constant (``2``), or ``set``."""
    k = case.variant.kappa0
    return "Z" if k == "Z" else (f"{k:g}" if k is not None else "set")
