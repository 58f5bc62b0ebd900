"""``tirecli compare``: stationary MCPS against the Magic Formula."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, run_command


def compare(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
            junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
            max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Stationary MCPS tire (complete model and/or solid carcass) against a Magic Formula tyre.

    Runs a 'study: mcps-stationary' config (MCPS Figs. 7-11): Fx(kappa), Fy and Mz(alpha), combined
    slip and the curvature response, optionally calibrating the MCPS rubber parameters to the Magic
    Formula first. Writes run.json (stiffnesses, calibration report), data/stationary.csv (model,
    carcass, calibrated, family, fz, kappa, alpha, phi, fx, fy, mz, x, y, delta; ISO-W, SI),
    calibrated.yaml when calibrating, and the figures as PNG and SVG.
    """
    run_command("compare", config, set_, out, junit, strict, max_samples_)
