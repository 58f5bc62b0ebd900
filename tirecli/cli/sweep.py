"""``tirecli sweep``: steady-state sweeps."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, run_command

FormatOpt = typer.Option("csv", "--format", metavar="csv|parquet",
                         help="Format of the data files: csv (data/NAME.csv) or parquet (data/NAME.parquet, "
                              "smaller and faster for large sweeps; pyarrow, in the default install).")


def sweep(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
          junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
          max_samples_: Optional[str] = MaxSamplesOpt, data_format: str = FormatOpt) -> None:
    """Steady-state friction sweep: mu over slip x speed x theta x model variant.

    Writes run.json, data/sweep.csv (long format: model, v, theta, slip, mu, ...), for LuGre
    tires data/peaks.csv (the root-found peak and sliding level of each curve) and the figures
    as PNG and SVG; with --format parquet the data files are .parquet.
    """
    run_command("sweep", config, set_, out, junit, strict, max_samples_, data_format=data_format)
