"""The output-error stage of a fit (``fit.method: output-error``; see :mod:`tirecli.studies.fit`).

After the FM procedure (and the driven distributed fit, with ``model: distributed``), the coupled quarter car
is simulated from the measured brake input with the candidate parameters and fitted to the measured ``v``,
``r omega`` and ``mu`` (:func:`tirecli.numerics.identify_oe.fit_output_error`): no interpolated kinematics
enter. It starts from the last stage's values (the engine needs a start within a few per cent).
"""
from __future__ import annotations

import numpy as np

from tirecli.errors import DataError
from tirecli.numerics import identify
from tirecli.studies.fit.data import INPUTS, _window_mask
from tirecli.studies.fit.spec import MIN_SAMPLES_PER_PARAMETER

#: The ``fit`` column of frame ``parameters`` for this stage.
FIT_OE = "output-error"


def brake_input(data: dict, oc: dict) -> tuple[np.ndarray, str]:
    """``(signed wheel torque u [N m] at the samples, what it is)`` from the data's brake input (``oc``: the checked
    ``fit.output_error``); DataError when the data give none or the pressure has no gain."""
    given = [k for k in INPUTS if k in data]
    kind = oc["input"] or (given[0] if given else None)
    if kind is None or kind not in data:
        what = f"column {kind!r}" if kind else "a brake input"
        raise DataError(f"{data['source']}: fit.method output-error needs {what}: brake_pressure [Pa] (file) or "
                        "pressure [bar] times fit.output_error.pressure_gain, brake_torque [N m] (>= 0), or torque "
                        "[N m] (signed, < 0 brakes)")
    if kind == "pressure":
        gain = oc["pressure_gain"] if oc["pressure_gain"] is not None else data.get("pressure_gain")
        if gain is None:
            raise DataError(f"{data['source']}: the brake input is a pressure: give fit.output_error.pressure_gain "
                            "[N m/bar] (brake torque per unit pressure)")
        return -float(gain) * data["pressure"], f"brake pressure x {float(gain):g} N m/bar"
    if kind == "brake_torque":
        return -data["brake_torque"], "brake torque (the brake's, >= 0)"
    return data["torque"], "wheel torque (signed; < 0 brakes)"


def run_stage(data: dict, start, car, fc: dict, free_fm: list, bounds: dict, s1_bounds):
    """The output-error fit: ``(FitResult, fitted LuGreParams, frame at every sample, meta record)``."""
    import pandas as pd

    from tirecli.models.variants import FrictionVariant
    from tirecli.numerics.identify_oe import fit_output_error, torque_from_samples
    from tirecli.studies.sweep import make_variant

    oc = fc["output_error"]
    t, v, s, mu = data["t"], data["v"], data["s"], data["mu"]
    u, what = brake_input(data, oc)
    free = list(oc["parameters"] or (free_fm + (["sigma1"] if s1_bounds is not None else [])))
    use = _window_mask(t, oc["window"])
    need = MIN_SAMPLES_PER_PARAMETER * len(free) + 1
    if int(use.sum()) < need:
        raise DataError(f"{data['source']}: too few samples for the output-error fit: {int(use.sum())} in "
                        f"fit.output_error.window (of {len(t)}); need at least {need} for {len(free)} parameters")
    variant = make_variant(oc["model"]) if oc["model"] is not None else FrictionVariant(model="distributed")
    rw = identify.romega_of(s, v)
    obounds = {**bounds, **({"sigma1": tuple(s1_bounds)} if s1_bounds is not None else {})}
    try:
        res, fitted, out = fit_output_error(t, torque_from_samples(t, u, oc["hold"]), start, car, v=v, romega=rw,
                                            mu=mu, free=free, variant=variant, bounds=obounds,
                                            confidence=fc["confidence"], use=use, weighting=oc["weighting"])
    except ValueError as e:  # the data cannot be simulated (no initial speed, ...): a bad input
        raise DataError(f"{data['source']}: output-error fit: {e}") from None
    frame = pd.DataFrame({"t": t, "v": v, "romega": rw, "mu": mu, "torque": u, "v_model": out["v_model"],
                          "romega_model": out["romega_model"], "mu_model": out["mu_model"],
                          "used": use.astype(int)})
    frame["residual"] = frame["mu_model"] - frame["mu"]
    record = {**res.record(), "model": variant.record(), "input": what, "hold": oc["hold"], "window": oc["window"],
              "samples_used": int(use.sum()),
              "drive": "the coupled quarter car simulated from the brake input (no interpolated v or r omega)",
              "initial": "undeflected bristles, v0 and omega0 from the first samples unless fitted"}
    return res, fitted, frame, record


__all__ = ["FIT_OE", "brake_input", "run_stage"]
