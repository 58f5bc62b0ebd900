"""``tirecli simulate``: transient runs (quarter car or tire alone)."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, run_command


def simulate(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
             junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
             max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Transient runs: quarter-car brakings with LuGre tires, or the MCPS tire's time-domain studies.

    'study: simulate' writes run.json (cases, events: wheel lock, stop, peak |slip|, stopping distance
    and time), data/timeseries.csv (case, t, v, omega, slip, vr, mu, torque, ...), data/events.csv,
    with a measurement block data/measured.csv (synthetic samples). The MCPS studies write
    data/slider.csv ('mcps-slider', Fig. 3), data/standstill.csv and data/patch.csv
    ('mcps-standstill', Figs. 4-5) or data/relaxation.csv ('mcps-relaxation'), with their facts in
    run.json. Figures as PNG and SVG.
    """
    run_command("simulate", config, set_, out, junit, strict, max_samples_)
