"""``tirecli sweep``: steady-state sweeps."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, JunitOpt, OutOpt, SetOpt, StrictOpt, finish, run


def sweep(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
          junit: Optional[str] = JunitOpt, strict: bool = StrictOpt) -> None:
    """Steady-state friction sweep: mu over slip x speed x theta x model variant.

    Writes run.json, data/sweep.csv (long format: model, v, theta, slip, mu, ...), for LuGre
    tires data/peaks.csv (the root-found peak and sliding level of each curve) and the figures
    as PNG and SVG.
    """
    summary = run("sweep", config, set_, out, junit)
    finish(summary, "sweep", config, junit, strict, overridden=bool(set_))
