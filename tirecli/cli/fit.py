"""``tirecli fit``: identification of the LuGre parameters from braking data."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, run_command

DataOpt = typer.Option(None, "--data", "-d", metavar="FILE",
                       help="Data file instead of the config's data source: a .csv of columns t, v, s or romega, mu, "
                            "or measured data (.parquet, .tdx, .mf4; docs/data.md).")
MapOpt = typer.Option(None, "--map", "-m", metavar="FILE_COLUMN=NAME",
                      help="Rename a column of the data file, e.g. --map slip_ratio=s (repeatable). "
                           "Names: t [s], v [m/s], s [-] (or romega [m/s]), mu [-].")


def fit(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
        data: Optional[Path] = DataOpt, map_: Optional[List[str]] = MapOpt,
        junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
        max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Identify sigma0, sigma2, mu_c, mu_s, v_s (and alpha) from (s, mu, v) samples, then sigma1 from the transient.

    With fit.model: distributed, then all of them at once from mu(t) with the distributed model in the loop; with
    fit.method: output-error, then the coupled quarter car simulated from the brake input, fitted to v, r omega, mu.
    Writes fitted.yaml (a parameter set every command accepts: tire: {set: fitted.yaml}),
    run.json (estimates, standard errors, confidence intervals, correlation matrix, residual RMS),
    data/parameters.csv, data/correlation.csv, data/samples.csv, data/transient.csv (and data/distributed.csv,
    data/correlation_distributed.csv; data/output_error.csv, data/correlation_output_error.csv) and the figures.
    """
    from tirecli.studies.fit import overrides_for

    run_command("fit", config, set_, out, junit, strict, max_samples_,
                extra=overrides_for(str(data) if data else None, map_, config))
