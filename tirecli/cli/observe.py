"""``tirecli observe``: the adhesion/speed observer running alongside the quarter car (OBS Fig. 2)."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, run_command


def observe(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
            junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
            max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Simulate the quarter car with the nonlinear adhesion/speed observer (OBS Theorem 1).

    Writes run.json (metrics, design checks, warnings), data/observer.csv (t, theta, theta_hat
    in the OBS convention, theta_fm, v, v_hat, omega, vr, slip, ...), data/metrics.csv and the
    figures (OBS Fig. 2 by default) as PNG and SVG. Design or excitation problems are printed as
    'warning:' lines; they do not change the exit code.
    """
    run_command("observe", config, set_, out, junit, strict, max_samples_)
