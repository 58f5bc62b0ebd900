"""Application layer of ``tirecli data``: show, convert and synthesize measured tyre data.

What each command does, independent of the CLI framework (:mod:`tirecli.cli.data` only parses the
options). The files are read by :func:`tirecli.io.readers.read_measured` (the channel table of
:mod:`tirecli.io.measured`), written atomically through :func:`tirecli.io.staging.staged_file` (a file
appears complete or not at all, never over an input of the run). Errors are
:class:`~tirecli.errors.TirecliError` subclasses: exit codes in ``cli/main.py``.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from tirecli.errors import UsageError, clip, token

#: Channels listed first in ``data show``, and what their ranges are shown in besides SI.
_DEG_COLUMNS = ("alpha", "gamma")


def read_options(mapping=None, units=None, convention=None, rate=None) -> dict:
    """The reader options of a command, checked (:func:`tirecli.io.readers.read_measured`)."""
    from tirecli.conventions import AXIS_CONVENTIONS

    if convention is not None and convention not in AXIS_CONVENTIONS:
        raise UsageError(f"--convention {token(convention, 20)}: expected one of {', '.join(AXIS_CONVENTIONS)}")
    return {"mapping": mapping or None, "units": units or None, "convention": convention, "rate": rate}


def _g(x: float) -> str:
    return f"{x:.6g}"


def _range(x: np.ndarray, name: str) -> str:
    lo, hi = float(np.min(x)), float(np.max(x))
    text = _g(lo) if lo == hi else f"{_g(lo)} .. {_g(hi)}"
    if name in _DEG_COLUMNS and (lo or hi):
        text += f" ({_g(math.degrees(lo))} .. {_g(math.degrees(hi))} deg)" if lo != hi \
            else f" ({_g(math.degrees(lo))} deg)"
    return text


def describe(data) -> list:
    """What ``data show`` prints for one table: what the file is, its channels with units and ranges,
    its sweeps. Items are lines (str) or tables (lists of rows of cells, the header row first), which
    the CLI aligns."""
    from tirecli.io.sweeps import find_sweeps, summary

    kind = {"tdx": "TYDEX", "csv": "CSV", "parquet": "Parquet", "mf4": "MDF"}.get(data.format, data.format)
    head = (f"{data.source}: {kind}, {len(data):,} rows, {len(data.channels)} channels, axis convention "
            f"{data.convention} (read as ISO-W, SI)")
    if data.synthetic:
        head += "; SYNTHETIC data (the file says so)"
    lines = [clip(head, 300)]
    for k in ("MEASID", "SUPPLIER", "TYRESIDE"):
        if data.header.get(k):
            lines.append(f"  {k}: {clip(data.header[k], 100)}")
    for note in data.notes:
        lines.append(f"  note: {clip(note, 200)}")
    rows = [("channel", "unit", "from", "range")]
    for name, ch in data.channels.items():
        rows.append((clip(name, 24), ch.unit or "(none)", clip(ch.source, 40), _range(data.frame[name].to_numpy(), name)))
    lines.append("channels:")
    lines.append(rows)
    sweeps = find_sweeps(data.frame)
    count = summary(sweeps)
    lines.append(f"sweeps: {len(sweeps)}" + (f" ({', '.join(f'{n} {k}' for k, n in count.items())})" if count else ""))
    if sweeps:
        srows = [("#", "kind", "rows", "fz [N]", "gamma [deg]", "p [kPa]", "vx [m/s]", "swept")]
        for i, s in enumerate(sweeps[:200], 1):
            srows.append((str(i), s.kind, str(s.rows), _opt(s.fz, 1.0), _opt(s.gamma, 180 / math.pi),
                          _opt(s.p, 1e-3), _opt(s.vx, 1.0), _swept(s)))
        lines.append(srows)
        if len(sweeps) > 200:
            lines.append(f"  ... and {len(sweeps) - 200} more")
    return lines


def _opt(x, scale: float) -> str:
    return "-" if x is None else f"{x * scale:.4g}"


def _swept(s) -> str:
    if not s.swept:
        return ""
    scale, unit = (180 / math.pi, " deg") if s.swept == "alpha" else (1.0, "")
    text = f"{s.swept} {s.lo * scale:.3g} .. {s.hi * scale:.3g}{unit}"
    if "alpha" in s.held:
        text += f" at alpha {math.degrees(s.held['alpha']):.3g} deg"
    if "kappa" in s.held:
        text += f" at kappa {s.held['kappa']:.3g}"
    return text


def data_show(files, **options) -> list:
    """``tirecli data show FILE...``: :func:`describe` of each file, in order (every file is read before
    anything is returned, so a bad file among them is one error and nothing is shown)."""
    from tirecli.io.readers import read_measured

    opts = read_options(**options)
    return [describe(read_measured(f, **opts)) for f in files]


def _same_file(a, b) -> bool:
    try:
        return os.path.realpath(a) == os.path.realpath(b)
    except (OSError, ValueError):
        return False


def data_convert(file, to: str, out: str | None = None, **options) -> str:
    """``tirecli data convert FILE --to tdx|csv|parquet [--out FILE]``: the channel table of ``file``
    (ISO-W, SI) written as ``to``; ``out`` defaults to ``file`` with the new suffix. Refuses to write
    over the input; nothing is written when anything fails."""
    from tirecli.io.staging import staged_file
    from tirecli.io.files import check_output_file, show_path
    from tirecli.io.readers import WRITE_FORMATS, WRITE_SUFFIX, read_measured, write_measured

    if to not in WRITE_FORMATS:
        raise UsageError(f"--to {token(to, 20)}: expected one of {', '.join(WRITE_FORMATS)}")
    if to == "parquet":
        from tirecli.io.output import require_pyarrow

        require_pyarrow("--to parquet")
    target = out if out is not None else str(Path(str(file)).with_suffix(WRITE_SUFFIX[to]))
    if _same_file(target, file):
        raise UsageError(f"--out {show_path(target)}: that is the input file; choose another --out")
    check_output_file(target)
    opts = read_options(**options)
    data = read_measured(file, **opts)
    with staged_file(target) as tmp:
        write_measured(tmp, data, to)
    return f"wrote {target} ({len(data):,} rows, {len(data.channels)} channels, {to}, ISO-W, SI)"


def parse_list(text: str | None, option: str) -> tuple:
    """``"2000,4000"`` -> ``(2000.0, 4000.0)`` (positive finite numbers); UsageError naming the option."""
    if text is None:
        return ()
    out = []
    for part in str(text).split(","):
        try:
            v = float(part)
        except ValueError:
            raise UsageError(f"{option} {token(text, 40)}: expected numbers separated by commas") from None
        if not (math.isfinite(v) and v > 0):
            raise UsageError(f"{option} {token(text, 40)}: every value must be a positive number")
        out.append(v)
    return tuple(out)


def data_synth(tire_ref: str, out: str, noise: float = 0.01, seed: int = 1, loads=None, pressures=None,
               points: int = 41, max_samples: int | None = None) -> str:
    """``tirecli data synth TIRE --out FILE``: a SYNTHETIC rig data set generated from a Magic Formula
    tyre (:mod:`tirecli.studies.rig_data`), written as the format of ``out``'s suffix. The file name must
    say it is synthetic."""
    from tirecli import limits
    from tirecli.app.mf import load_tire
    from tirecli.io.staging import staged_file
    from tirecli.io.files import check_output_file, show_path
    from tirecli.io.readers import WRITE_FORMATS, format_of, write_measured
    from tirecli.studies.rig_data import RigPlan, synthetic_rig_data

    if not (math.isfinite(noise) and 0 <= noise <= 1):
        raise UsageError(f"--noise {noise!r}: expected a fraction from 0 to 1 (0.01: 1 % of each force's peak)")
    if points < 3:
        raise UsageError(f"--points {points}: expected at least 3 samples per sweep")
    if "synthetic" not in Path(str(out)).name.lower():
        raise UsageError(f"--out {show_path(out)}: the file name must say the data are synthetic "
                         f"(e.g. synthetic-{Path(str(out)).name})")
    fmt = format_of(out)
    if fmt not in WRITE_FORMATS:
        raise UsageError(f"--out {show_path(out)}: tirecli writes {', '.join(WRITE_FORMATS)} files")
    check_output_file(out)
    plan = RigPlan(loads=parse_list(loads, "--loads"), pressures=parse_list(pressures, "--pressures"), points=points)
    with limits.budget(max_samples, config_key=False):
        limits.refuse_over_budget(plan.sweeps() * points, f"{plan.sweeps()} sweeps of {points} samples", 1000)
        ps, tire = load_tire(tire_ref)
        if tire.family != "mf":
            raise UsageError(f"{tire_ref}: a {tire.version} tyre; data synth needs a Magic Formula 5.2 or 6.x tyre")
        data = synthetic_rig_data(tire, ps.name, plan, noise, seed, source=str(out))
        extra = [f"generated with: {synth_command(tire_ref, out, noise, seed, loads, pressures, points)}"]
        with staged_file(out) as tmp:
            write_measured(tmp, data, fmt, comments=extra,
                           header={"SEED": str(seed)} if fmt == "tdx" else None)
    return (f"wrote {out}: SYNTHETIC data from {ps.name}, {len(data):,} rows in {int(data.frame['run'].max())} "
            f"sweeps, noise {noise:g}, seed {seed}")


def synth_command(tire_ref, out, noise, seed, loads, pressures, points) -> str:
    """The ``tirecli data synth`` command line that makes this file (written into it: reproducible)."""
    import shlex

    words = ["tirecli", "data", "synth", str(tire_ref), "--out", Path(str(out)).name, "--noise", f"{noise:g}",
             "--seed", str(seed)]
    if loads:
        words += ["--loads", str(loads)]
    if pressures:
        words += ["--pressures", str(pressures)]
    if points != 41:
        words += ["--points", str(points)]
    return " ".join(shlex.quote(w) for w in words)


__all__ = ["data_show", "data_convert", "data_synth", "describe", "read_options", "parse_list"]


def observer_log_synth(config_path: str, out: str, rate: float, noise: float = 0.0, seed: int = 0) -> str:
    """Write a SYNTHETIC observer log (CSV: ``t, omega, torque, vx``) of the simulated plant of an observe config
    (:func:`tirecli.studies.observe.log.synthetic_log`); returns the path written."""
    from tirecli.config.loader import load_config
    from tirecli.io.readers import write_measured

    data = synthetic_log(load_config(config_path), rate, noise, seed)
    cmd = (f"made by: python -c \"from tirecli.app.data import observer_log_synth; observer_log_synth("
           f"'{Path(config_path).name}', '{Path(out).name}', rate={rate:g}, noise={noise:g}, seed={seed})\"")
    write_measured(out, data, "csv", comments=[cmd])
    return out


def synthetic_log(config, rate: float, noise: float = 0.0, seed: int = 0):
    """A SYNTHETIC log of the first case of an observe ``config`` (a simulated plant): ``t, omega, torque, vx``
    at ``rate`` [Hz] over the scenario, ``omega`` as the observe study's sampled measurement (``noise`` [rad/s]
    Gaussian, ``seed``). Returns a :class:`tirecli.io.measured.MeasuredData`."""
    from tirecli.io.measured import RawColumn, assemble
    from tirecli.numerics.observer import adaptive as oi
    from tirecli.observers.measurement import Sensor
    from tirecli.studies.registry import plan

    p = plan(config)
    det, case = p.detail, p.detail.cases[0]
    sensor = Sensor(rate=rate, noise_std=noise, seed=seed)
    tr = oi.simulate_adaptive(det.plant, case.gains, case.scenario, sensor, method="lsoda", rtol=1e-9)
    ts = sensor.sample_times(case.scenario.duration)
    i = np.searchsorted(tr.t, ts + 1e-12, side="right") - 1   # the segment start where sample k is held
    cols = [RawColumn(ts, "t", "t", "s"), RawColumn(tr.y[i], "omega", "omega", "rad/s"),
            RawColumn(np.asarray(case.scenario.torque(ts), float), "torque", "torque", "N m",
                      "wheel torque (> 0 drives)"),
            RawColumn(tr.v[i], "vx", "vx", "m/s")]
    return assemble("<synthetic>", "csv", cols, "iso",
                    comments=[f"SYNTHETIC observer log: the simulated plant of {Path(str(config.label)).name} (tirecli observe), "
                              f"sampled at {rate:g} Hz, wheel-speed noise {noise:g} rad/s, seed {seed}"])
