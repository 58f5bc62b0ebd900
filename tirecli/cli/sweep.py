"""``tirecli sweep``: steady-state sweeps."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, OutOpt, SetOpt, overrides, progress, report_run


def sweep(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt) -> None:
    """Steady-state friction sweep: mu over slip x speed x theta x model variant.

    Writes run.json, data/sweep.csv (long format: model, v, theta, slip, mu, ...), for LuGre
    tires data/peaks.csv (the root-found peak and sliding level of each curve) and the figures
    as PNG and SVG.
    """
    from tirecli.app import run_config

    summary = run_config("sweep", config, overrides(set_), out, progress())
    report_run(summary, "sweep", overridden=bool(set_))
