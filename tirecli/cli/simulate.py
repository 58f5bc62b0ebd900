"""``tirecli simulate``: transient runs (quarter car or tire alone)."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import ConfigArg, JunitOpt, OutOpt, SetOpt, StrictOpt, finish, result_line, run


def simulate(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
             junit: Optional[str] = JunitOpt, strict: bool = StrictOpt) -> None:
    """Transient runs: quarter-car brakings with LuGre tires, or the MCPS tire's time-domain studies.

    'study: simulate' writes run.json (cases, events: wheel lock, stop, peak |slip|, stopping distance
    and time), data/timeseries.csv (case, t, v, omega, slip, vr, mu, torque, ...), data/events.csv,
    with a measurement block data/measured.csv (synthetic samples). The MCPS studies write
    data/slider.csv ('mcps-slider', Fig. 3), data/standstill.csv and data/patch.csv
    ('mcps-standstill', Figs. 4-5) or data/relaxation.csv ('mcps-relaxation'), with their facts in
    run.json. Figures as PNG and SVG.
    """
    summary = run("simulate", config, set_, out, junit)
    for line in summary.result.meta.get("summary", []):
        result_line(f"  {line}")
    for ev in summary.result.meta.get("events", []):
        locks = ", ".join(f"{a:.4f}-{b:.4f} s" if b is not None else f"from {a:.4f} s" for a, b in ev["wheel_lock"]) or "none"
        stop = f"stop at {ev['stop_time']:.3f} s after {ev['stopping_distance']:.2f} m" if ev["stop_time"] is not None \
            else f"v = {ev['v_final']:.3g} m/s at {ev['t_final']:.3g} s"
        result_line(f"  {ev['case']}: peak |s| {ev['peak_abs_slip']:.4f} at {ev['t_peak_abs_slip']:.3f} s, "
             f"peak |mu| {ev['peak_abs_mu']:.4f}, wheel lock: {locks}, {stop}")
    finish(summary, "simulate", config, junit, strict, overridden=bool(set_))
