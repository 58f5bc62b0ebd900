"""``tirecli observe``: the adhesion/speed observer running alongside the quarter car (OBS Fig. 2)."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import List, Optional

from tirecli.cli.common import (ConfigArg, JunitOpt, MaxSamplesOpt, OutOpt, SetOpt, StrictOpt, echo, finish, result_line,
                                run)


def _fmt(x, spec=".4g") -> str:
    return "-" if x is None or x != x else format(x, spec)


def metrics_table(result) -> list[str]:
    """Lines of the metrics table of an observe result (per case: phases, settling, speed, excitation)."""
    lines = []
    for rec in result.meta["runs"]:
        m = rec["metrics"]
        lines.append(f"case {rec['label']!r} ({rec['integrator']}):")
        lines.append(f"  {'phase [s]':<14}{'rms':>10}{'max':>10}{'rms excl':>10}{'max excl':>10}   |theta_hat - theta|, OBS convention")
        for k, ph in enumerate(m["phases"] + [m["all_excl_crossings"]]):
            name = f"{ph['start']:g}-{ph['end']:g}"
            if k == len(m["phases"]):
                name = f"all {name}"     # the whole run, not one more phase
            lines.append(f"  {name:<14}{_fmt(ph['rms']):>10}{_fmt(ph['max']):>10}{_fmt(ph['rms_excl']):>10}{_fmt(ph['max_excl']):>10}")
        cr = ", ".join(f"{t:.3f}" for t in m["crossings_s"]) or "none"
        lines.append(f"  v_r zero crossings [s]: {cr} (excluded: +-{result.meta['metric_settings']['crossing_margin']:g} s)")
        tol = result.meta["metric_settings"]["settle_tolerance"]
        for s in m["settling"]:
            # t = 0 is listed when the estimate starts off (theta_hat(0) != theta(0) or a speed error)
            when = "from the start (initial estimate off)" if s["at"] == 0 else f"change at {s['at']:g} s"
            lines.append(f"  {when}: " + (f"|theta_hat - theta| stays >= {tol:g} to the end of the run"
                                                             if s["time"] is None else
                                                             f"|theta_hat - theta| < {tol:g} after {s['time']:.3f} s"))
        lines.append(f"  max |v_hat - v| = {m['max_abs_v_error']:.3g} m/s; excitation |v_r| > "
                     f"{result.meta['metric_settings']['excitation_threshold']:g} m/s: {100 * m['excitation_share']:.1f}% of the time; "
                     f"slip in [{m['slip_range'][0]:.4f}, {m['slip_range'][1]:.4f}]")
    return lines


def observe(config: Path = ConfigArg, out: Optional[str] = OutOpt, set_: Optional[List[str]] = SetOpt,
            junit: Optional[str] = JunitOpt, strict: bool = StrictOpt,
            max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Simulate the quarter car with the nonlinear adhesion/speed observer (OBS Theorem 1).

    Writes run.json (metrics, design checks, warnings), data/observer.csv (t, theta, theta_hat
    in the OBS convention, theta_fm, v, v_hat, omega, vr, slip, ...), data/metrics.csv and the
    figures (OBS Fig. 2 by default) as PNG and SVG. Design or excitation problems are printed as
    'warning:' lines; they do not change the exit code.
    """
    summary = run("observe", config, set_, out, junit, max_samples_=max_samples_)
    res = summary.result
    for line in metrics_table(res):
        result_line(line)
    for a in res.meta.get("assumed", []):
        echo(f"assumed: {a}")
    for w in res.meta.get("warnings", []):
        sys.stderr.write(f"warning: {w}\n")
    finish(summary, "observe", config, junit, strict, overridden=bool(set_))
