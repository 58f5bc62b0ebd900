"""The samples a fit reads: a CSV file or the frame of a simulate run, renamed, selected and checked
(see :mod:`tirecli.studies.fit`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tirecli.config.loader import load_config
from tirecli.errors import DataError, token
from tirecli.studies.configs import builtin_config, builtin_config_names

def _simulate_frame(d: dict, base_dir: Path):
    """Run a simulate config (only ``cases``) and return the frame ``d['frame']``, whether it is synthetic, its
    name and the config's brake pressure gain [N m/bar]."""
    from tirecli.studies import simulate

    ref = d["simulate"]
    if ref in builtin_config_names() and not ref.endswith((".yaml", ".yml")):
        sim = builtin_config(ref)
    else:
        p = Path(ref)
        sim = load_config(p if p.is_absolute() else base_dir / p)
    if d["cases"]:
        keep = set(d["cases"])
        raw_cases = sim.data.get("cases") or []
        labels = [c.get("label") if isinstance(c, dict) and isinstance(c.get("label"), str) else None
                  for c in (raw_cases if isinstance(raw_cases, list) else [])]
        missing = keep - set(lab for lab in labels if lab)
        if missing:
            raise DataError(f"{sim.label}: no case(s) labelled {', '.join(map(token, sorted(map(str, missing))))}")
        sim.data["cases"] = [c for c, lab in zip(raw_cases, labels) if lab in keep]
        sim.data.pop("open_loop", None)
        meas = sim.data.get("measurement")
        if isinstance(meas, dict) and isinstance(meas.get("cases"), list):  # (checked by the simulate study)
            idx = [i for i, lab in enumerate(meas["cases"]) if isinstance(lab, str) and lab in keep]
            meas["cases"] = [meas["cases"][i] for i in idx]
            starts = meas.get("record_starts")
            if isinstance(starts, list) and starts:
                meas["record_starts"] = [starts[i] for i in idx if i < len(starts)]
    res = simulate.run(simulate.plan(sim))
    if d["frame"] not in res.data:
        raise DataError(f"{sim.label}: no frame {token(d['frame'])} (frames: {', '.join(res.data)})")
    gain = res.meta.get("pressure_gain_N_m_per_bar")
    return res.data[d["frame"]].copy(), res.synthetic, f"{d['frame']} of simulate config {sim.label}", gain


def _file_frame(d: dict, base_dir: Path, r: float):
    """The channel table of a measured-data file (:func:`tirecli.io.readers.read_measured`) with the fit's
    columns derived from its channels (docs/data.md, "LuGre identification from measured data"): ``v`` from
    ``vx``; ``s`` from ``kappa`` or ``romega`` from ``omega`` times ``re`` (else ``r``) when the file gives no ``s``
    or ``romega``; ``mu = fx / fz`` when it gives no ``mu``; ``pressure`` [bar] from ``brake_pressure`` [Pa].
    Also whether it is synthetic, and its name."""
    from tirecli.conventions import slip_from_kappa
    from tirecli.io.readers import read_measured

    path = Path(d["file"])
    if not path.is_absolute():
        path = base_dir / path
    data = read_measured(path, mapping=d["map"], units=d["units"], convention=d["convention"], rate=d["rate"])
    frame, name = data.frame.copy(), data.source
    have = set(frame.columns)

    def need(what: str, *options: tuple) -> None:
        if not any(set(o) <= have for o in options):
            alts = " or ".join(" and ".join(o) for o in options)
            raise DataError(f"{name}: missing channel {what}: {alts} (the file gives: {', '.join(frame.columns[:16])}; "
                            "name the file's channels with data.map / --map FILE_COLUMN=NAME)")

    need("time", ("t",))
    need("vehicle speed", ("vx",), ("v",))
    need("wheel slip", ("s",), ("kappa",), ("romega",), ("omega",))
    need("friction", ("mu",), ("fx", "fz"))
    if "v" not in have:
        frame["v"] = frame["vx"]
    if "s" not in have and "romega" not in have:
        if "kappa" in have:
            frame["s"] = slip_from_kappa(frame["kappa"].to_numpy())
        else:
            frame["romega"] = frame["omega"] * (frame["re"] if "re" in have else r)
    if "mu" not in have:
        frame["mu"] = frame["fx"] / frame["fz"]
    if "brake_pressure" in have and "pressure" not in have:
        frame["pressure"] = frame["brake_pressure"] / 1e5  # Pa (the table's SI) -> bar, the unit of pressure_gain
    return frame, data.synthetic, name


def load_samples(d: dict, base_dir: Path, r: float = 1.0, inputs: bool = False) -> dict:
    """The selected samples: ``t, v, s, mu`` arrays (with ``inputs``, also the columns of :data:`INPUTS` the data
    give), source description, synthetic flag and the pressure gain of a simulate config. ``r``: the rolling
    radius [m] for a file's ``omega`` without ``re``."""
    from tirecli.io.data import data_rows, frame_columns, leading_comments, names, read_table, rename_columns, select_rows
    from tirecli.io.output import SYNTHETIC_NOTE

    gain = None
    if d["file"] is not None:
        frame, synthetic, source = _file_frame(d, base_dir, r)
        where_name = source
    elif d["csv"] is not None:
        path = Path(d["csv"])
        if not path.is_absolute():
            path = base_dir / path
        frame = read_table(path)
        synthetic = any("SYNTHETIC" in c.upper() for c in leading_comments(path))
        source, where_name = str(path), str(path)
    else:
        frame, synthetic, source, gain = _simulate_frame(d, base_dir)
        where_name = source
    if d["file"] is None:
        frame = rename_columns(frame, d["map"], where_name)
    frame = select_rows(frame, d["where"], where_name, "data.where")
    has_s = "s" in frame.columns
    rows = data_rows(frame)  # rows of the file, also after 'where' kept some
    cols = frame_columns(frame, ["t", "v", "mu"] + (["s"] if has_s else []), where_name, increasing="t",
                         optional=(() if has_s else ("romega",)) + (INPUTS if inputs else ()))
    if not has_s:
        if "romega" not in cols:
            raise DataError(f"{where_name}: missing column 's' (slip) and no 'romega' to compute it "
                            f"(file has: {names(frame.columns)}; map names with --map FILE_COLUMN=NAME)")
        from tirecli.conventions import slip_from_speeds

        cols["s"] = slip_from_speeds(cols["v"], cols["romega"], 1.0)
    if np.any(cols["v"] < 0):
        i = int(np.argmax(cols["v"] < 0))
        raise DataError(f"{where_name}: column 'v' row {rows[i]}: negative speed {cols['v'][i]:g} (forward motion, >= 0)")
    if np.any(np.abs(cols["s"]) > 1):
        i = int(np.argmax(np.abs(cols["s"]) > 1))
        what = "column 's'" if has_s else "slip from columns 'v', 'romega'"
        raise DataError(f"{where_name}: {what} row {rows[i]}: |slip| = {abs(cols['s'][i]):g} > 1")
    return {"t": cols["t"], "v": cols["v"], "s": cols["s"], "mu": cols["mu"], "source": source,
            "synthetic": synthetic, "note": SYNTHETIC_NOTE if synthetic else "", "pressure_gain": gain,
            **{k: cols[k] for k in INPUTS if k in cols}}


#: Brake-input columns of the output-error fit: pressure [bar], the brake's torque [N m] (>= 0), the signed
#: wheel torque [N m] (< 0 brakes).
INPUTS = ("pressure", "brake_torque", "torque")


def _window_mask(t, w):
    m = np.ones_like(t, dtype=bool)
    if w:
        if w["start"] is not None:
            m &= t >= w["start"] - 1e-12
        if w["end"] is not None:
            m &= t <= w["end"] + 1e-12
    return m
