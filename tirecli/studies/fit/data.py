"""The samples a fit reads: a CSV file or the frame of a simulate run, renamed, selected and checked
(see :mod:`tirecli.studies.fit`)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tirecli.config.loader import load_config
from tirecli.errors import DataError, token
from tirecli.studies.configs import builtin_config, builtin_config_names

def _simulate_frame(d: dict, base_dir: Path):
    """Run a simulate config (only ``cases``) and return the frame ``d['frame']`` and whether it is synthetic."""
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
    return res.data[d["frame"]].copy(), res.synthetic, f"{d['frame']} of simulate config {sim.label}"


def load_samples(d: dict, base_dir: Path) -> dict:
    """The selected samples: ``t, v, s, mu`` arrays (plus source description and synthetic flag)."""
    from tirecli.io.data import data_rows, frame_columns, leading_comments, names, read_table, rename_columns, select_rows
    from tirecli.io.output import SYNTHETIC_NOTE

    if d["csv"] is not None:
        path = Path(d["csv"])
        if not path.is_absolute():
            path = base_dir / path
        frame = read_table(path)
        synthetic = any("SYNTHETIC" in c.upper() for c in leading_comments(path))
        source, where_name = str(path), str(path)
    else:
        frame, synthetic, source = _simulate_frame(d, base_dir)
        where_name = source
    frame = rename_columns(frame, d["map"], where_name)
    frame = select_rows(frame, d["where"], where_name, "data.where")
    has_s = "s" in frame.columns
    rows = data_rows(frame)  # rows of the file, also after 'where' kept some
    cols = frame_columns(frame, ["t", "v", "mu"] + (["s"] if has_s else []), where_name, increasing="t",
                         optional=() if has_s else ("romega",))
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
            "synthetic": synthetic, "note": SYNTHETIC_NOTE if synthetic else ""}


def _window_mask(t, w):
    m = np.ones_like(t, dtype=bool)
    if w:
        if w["start"] is not None:
            m &= t >= w["start"] - 1e-12
        if w["end"] is not None:
            m &= t <= w["end"] + 1e-12
    return m
