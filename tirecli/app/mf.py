"""Application layer of the Magic Formula commands (``tirecli tir ...``, ``tirecli mf eval``).

What each command does, independent of the CLI framework: the Typer commands in
:mod:`tirecli.cli.tir` and :mod:`tirecli.cli.mf` only parse arguments and call these functions.
Errors are :class:`~tirecli.errors.TirecliError` subclasses (exit codes in ``cli/main.py``).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tirecli.errors import DataError, RunError, UsageError, token
from tirecli.io import tir as tirio
from tirecli.io.files import check_output_file, exists
from tirecli.models.magic_formula.tire import VERSION_NAMES
from tirecli.parameters import mf as mfp
from tirecli.parameters.mf import read_document
from tirecli.studies.mf_points import INPUT_COLUMNS, OUTPUT_COLUMNS


def tyre_size(v: dict) -> str:
    """``205/60 R15`` from WIDTH [m], ASPECT_RATIO [-] and RIM_RADIUS [m], when all are given."""
    try:
        w, ar, rr = v["WIDTH"], v["ASPECT_RATIO"], v["RIM_RADIUS"]
    except KeyError:
        return ""
    rim = 2 * rr / 0.0254
    rim_txt = f"{rim:.0f}" if abs(rim - round(rim)) < 0.05 else f"{rim:.1f}"
    return f"{w * 1000:.0f}/{ar * 100:.0f} R{rim_txt}"


def _fmt_range(t, var: str, unit: str) -> str:
    lo, hi = t.range(var)
    if var == "fz" and hi == float("inf") and lo == 0.0:
        return "none"
    if lo == -float("inf") and hi == float("inf"):
        return "none"
    return f"{lo:g} .. {hi:g}{(' ' + unit) if unit else ''}"


def tir_show(ref: str) -> str:
    """Summary of a tyre file: sizes, model version, nominal load and pressure, ranges, sections."""
    doc, label = read_document(ref)
    td = mfp.tire_data(doc)
    t = td.tire()
    v = td.values
    lines = []
    if label in mfp.BUILTIN_TIRES:
        meta = mfp.BUILTIN_TIRES[label]
        lines += [f"built-in tyre {label}: {meta['title']}", f"citation: {meta['citation']}", f"licence: {meta['licence']}"]
    if doc.n_bytes:
        enc = "" if doc.encoding == "ascii" else f", {doc.encoding} text"
        lines.append(f"file: {doc.file} ({doc.n_bytes} bytes, {doc.last_line} lines, {doc.line_ends} line ends{enc})")
    else:
        lines.append(f"file: {doc.file} (the YAML form of a .tir file)")
    size = tyre_size(v)
    dims = ", ".join(f"{k} {v[k]:g} m" for k in ("UNLOADED_RADIUS", "WIDTH", "RIM_RADIUS", "RIM_WIDTH") if k in v)
    if "ASPECT_RATIO" in v:
        dims += f", ASPECT_RATIO {v['ASPECT_RATIO']:g}"
    lines.append(f"tyre size: {size or 'not given'} ({dims})")
    lines.append(f"model: {VERSION_NAMES[td.version]} (from {td.version_source}); "
                 f"TYRESIDE {td.text.get('TYRESIDE', 'not given')!r} -> {td.side}")
    if t.family == "mf":
        nom = [f"FNOMIN {v['FNOMIN']:g} N"]
        nom.append(f"LONGVL {v['LONGVL']:g} m/s" if "LONGVL" in v else "LONGVL not given")
        if td.version == "5.2":
            nom.append("pressure: no effect (MF 5.2)")
        else:
            nom.append(f"NOMPRES {v['NOMPRES']:g} Pa" if "NOMPRES" in v else "NOMPRES not given (no pressure effect)")
            if "INFLPRES" in v:
                nom.append(f"INFLPRES {v['INFLPRES']:g} Pa")
        nom.append(f"VXLOW {v['VXLOW']:g} m/s" if "VXLOW" in v else "VXLOW not given")
        lines.append("nominal: " + ", ".join(nom))
    lines.append("ranges: " + "; ".join(f"{name} {_fmt_range(t, var, unit)}" for name, var, unit in (
        ("Fz", "fz", "N"), ("kappa", "kappa", ""), ("alpha", "alpha", "rad"), ("gamma", "gamma", "rad"),
        ("p", "p", "Pa"))))
    if td.units:
        lines.append("units: " + ", ".join(f"{k} {u!r}" for k, u in td.units.items()))
    secs = []
    for name, sec in doc.sections.items():
        part = f"[{name}] {len(sec.entries)} key(s)"
        if sec.table is not None:
            part += f" + table {{{sec.table.header}}} {len(sec.table.rows)} row(s)"
        secs.append(part)
    lines.append(f"sections ({len(secs)}):")
    lines += [f"  {x}" for x in secs]
    missing = [s for s in ("TURNSLIP_COEFFICIENTS", "OPERATING_CONDITIONS", "VERTICAL_FORCE_RANGE")
               if s not in doc.sections and t.family == "mf" and not (td.version == "5.2" and s != "VERTICAL_FORCE_RANGE")]
    if missing:
        lines.append("not present: " + ", ".join(f"[{s}]" for s in missing))
    if td.warnings:
        lines.append(f"warnings ({len(td.warnings)}):")
        lines += [f"  {w}" for w in td.warnings]
    return "\n".join(lines)


def _finding_place(doc: tirio.TirDocument, keys: str) -> str:
    """``file:line: `` of the first coefficient named in a finding's key (``PEX1..PEX4``,
    ``KPUMIN/KPUMAX``), so every problem reads ``file:line: KEY: what is wrong`` (issue 6); the
    file alone when none of the keys is written in it (a default)."""
    import re

    for key in re.split(r"\.\.|/|,\s*", keys):
        found = doc.find(key.strip()) if key.strip() else []
        if found:
            return f"{doc.file}:{found[0][1].line}: "
    return f"{doc.file}: "


def tir_check(ref: str) -> tuple[str, int]:
    """Coefficient sanity of a tyre file: ``(report, number of errors)``; RunError if any error."""
    from tirecli.models.magic_formula.check import check_coefficients

    doc, label = read_document(ref)
    td = mfp.tire_data(doc)
    findings = check_coefficients(td.tire(label))
    lines = [f"{label}: {VERSION_NAMES[td.version]}"]
    lines += [f"warning: {w}" for w in td.warnings]
    lines += [f"{f.level}: {_finding_place(doc, f.key)}{f.key}: {f.message}" for f in findings]
    n_err = sum(f.level == "error" for f in findings)
    n_warn = len(td.warnings) + sum(f.level == "warning" for f in findings)
    lines.append(f"{n_err} error(s), {n_warn} warning(s)")
    return "\n".join(lines), n_err


def tir_convert(ref: str, to: str, out: str | None) -> str:
    """Convert a tyre file to its YAML form (``to='yaml'``) or to ``.tir`` (``to='tir'``).

    Returns the converted text when ``out`` is None, else writes ``out`` and returns a message.
    The document is checked first (a file the reader refuses is not converted).
    """
    from tirecli.io.yamlio import dump_yaml

    if to not in ("yaml", "tir"):
        raise UsageError(f"--to {to!r}: expected 'yaml' or 'tir'")
    if out is not None:
        check_output_file(out)
    doc, label = read_document(ref)
    mfp.tire_data(doc)  # refuse what cannot be evaluated
    encoding = "utf-8"
    if to == "yaml":
        head = (f"# {label} as YAML (tirecli tir convert --to yaml): sections, keys, values, units and tables "
                f"as in the .tir file;\n# convert back with: tirecli tir convert FILE.yaml --to tir\n")
        text = head + dump_yaml(tirio.to_yaml_data(doc))
    else:
        text = tirio.format_tir(doc)
        tirio.encode_tir(doc, text)  # a character the file's encoding cannot hold: an error naming it
        encoding = "latin-1" if doc.encoding == "latin-1" else "utf-8"
    if out is None:
        return text.rstrip("\n")
    from tirecli.io.staging import staged_file
    from tirecli.io.output import write_text

    with staged_file(out) as tmp:
        write_text(tmp, text, encoding=encoding)
    return f"wrote {out}"


# --------------------------------------------------------------------------- mf eval


def load_tire(ref: str, base_dir: Path | None = None):
    """``(ParameterSet, MFTire)`` of a built-in tyre name or a ``.tir``/YAML path."""
    from tirecli.parameters.sets import builtin_names, load_set

    if ref not in builtin_names() and not exists(ref):
        read_document(ref)  # raises with a did-you-mean
    ps = load_set(ref, base_dir)  # a relative path stays as the user wrote it (messages name it so)
    if ps.kind != "magic_formula":
        raise UsageError(f"{ref}: a {ps.kind} parameter set, not a Magic Formula tyre")
    return ps, mfp.tire_from_set(ps)


def _echo_ok(facts: dict, header: list[str], n: int, mapped: bool) -> bool:
    """Whether the input rows can be copied verbatim (plain CSV in the canonical column order)."""
    if mapped or facts["lines"] != n + 1 or facts["comment"] or facts["quote"] or facts["blank"] or facts["trailing"]:
        return False
    # a missing p or vx is appended after the copied cells, so only a missing tail can be copied
    # (a file with vx but no p would put vx under the p header)
    return header[:4] == list(INPUT_COLUMNS[:4]) and header[4:] in ([], ["p"], ["p", "vx"])


def mf_eval(tire_ref: str, points: str | Path, out: str | Path, convention: str = "mfeval", side: str | None = None,
            limits: bool = True, mapping: dict | None = None, threads: int | None = None,
            max_samples: int | None = None) -> dict:
    """Evaluate a tyre at the points of a CSV and write the result CSV (``tirecli mf eval``).

    ``points`` has the columns ``kappa, alpha, gamma, fz`` (rad, N) and optionally ``p`` [Pa] and
    ``vx`` [m/s] (defaults: the tyre's INFLPRES/NOMPRES and LONGVL). The result has the six input
    columns (inputs copied verbatim when the file is a plain CSV in that column order, else written
    exactly) followed by ``fx, fy, mz, mx, my`` (ISO-W, N and N m, 17 significant digits) and the
    :data:`~tirecli.studies.mf_points.EXTRA_COLUMNS` the tyre's coefficients give (the others are left out and listed under
    ``"omitted"`` with what they need). Bad
    input (missing column, non-numeric or NaN cell, p <= 0) is a DataError naming the column and
    row, and nothing is written. A points file of more rows than the sample budget (``max_samples``,
    default :data:`tirecli.limits.DEFAULT_MAX_SAMPLES`) is refused before it is parsed.
    """
    from tirecli import limits as budgets
    from tirecli.io.staging import staged_file

    check_output_file(out)  # before the run: a bad location fails at once, naming it
    with budgets.budget(max_samples, config_key=False):
        with staged_file(out) as tmp:  # the lock of ``out``; ``out`` replaced only by a complete result
            s = _evaluate_points(tire_ref, points, tmp, convention, side, limits, mapping, threads)
    return {**s, "out": str(out)}


def _evaluate_points(tire_ref, points, out: Path, convention, side, limits, mapping, threads) -> dict:
    """:func:`mf_eval` writing to ``out`` (its staging file)."""
    from tirecli.io.data import check_size, plain_columns, read_columns
    from tirecli.io.fastcsv import text_facts, write_table
    from tirecli.io.files import read_input_bytes
    from tirecli.limits import csv_max_bytes
    from tirecli.studies.mf_points import PointError, evaluate_points, needs_speed

    check_size(points)  # a points file over the budget is refused before anything is loaded
    ps, tire = load_tire(tire_ref)
    if side is not None and tire.side == "unknown" and tire.family == "mf":
        raise UsageError(f"--side {side}: the tyre {tire_ref} does not say which side it was measured on "
                         "(no TYRESIDE), so it cannot be mirrored")
    points = Path(points)
    data = read_input_bytes(points, "a CSV file", csv_max_bytes())
    want = list(INPUT_COLUMNS[:4])
    cols = plain_columns(data, want, min_rows=1, optional=("p", "vx"), rename=mapping)
    if cols is None:  # not a plain numeric CSV: the general reader, with every check
        cols = read_columns(points, want, min_rows=1, optional=("p", "vx"), rename=mapping)
    n = len(cols["kappa"])
    p = cols.get("p")
    if p is not None:
        bad = np.flatnonzero(p <= 0)
        if bad.size:
            raise DataError(f"{points}: column 'p' row {bad[0] + 1}: pressure must be > 0 Pa, got {p[bad[0]]:g}")
    if needs_speed(tire, cols.get("vx")):
        raise DataError(f"{points}: no column 'vx' and the tyre has no LONGVL to default to")
    try:
        ev = evaluate_points(tire, cols, convention=convention, side=side, limits=limits, threads=threads)
    except PointError as err:  # never an empty cell: the row, its inputs and why
        cls = DataError if err.at_fault else RunError
        raise cls(f"{points}: row {err.index + 1}: {err.text}; nothing was written") from None
    res, outputs = ev.result, list(ev.outputs().values())
    text, facts = text_facts(data)
    del data
    head = text.split(b"\n", 1)[0]
    header = [h.strip() for h in head.decode("utf-8", "replace").split(",")]
    const = {k: (b"" if d is None else repr(float(d)).encode()) for k, d in (("p", ev.p_default), ("vx", ev.vx_default))}
    names = ",".join(INPUT_COLUMNS + OUTPUT_COLUMNS + tuple(ev.extras))
    if _echo_ok(facts, header, n, bool(mapping)) and b"\x01" not in text:  # (the filler byte of the formatter)
        nl = facts["newlines"]  # the newline before each data row
        lead = b"".join(b"," + const[k] for k in ("p", "vx") if k not in header)
        write_table(out, names, outputs, lines=(text, nl, np.append(nl[1:], len(text))), lead=lead, threads=threads)
        how = "copied"
    else:
        ins = [cols["kappa"], cols["alpha"], cols["gamma"], cols["fz"]]
        ins += [np.full(n, np.nan) if cols.get(k) is None and const[k] == b"" else
                (cols[k] if cols.get(k) is not None else np.full(n, float(const[k]))) for k in ("p", "vx")]
        write_table(out, names, ins + outputs, threads=threads)
        how = "rewritten exactly"
    return {"points": n, "tire": ps.name, "warnings": list((ps.extra or {}).get("warnings", [])), "version": tire.version, "side": tire.side, "mirrored": res.mirrored,
            "convention": res.convention, "limits": limits, "counts": res.counts, "inputs": how, "out": str(out),
            "pressure_default": ev.p_default, "speed_default": ev.vx_default,
            "outside": res.outside, "extras": list(ev.extras), "omitted": ev.omitted}


__all__ = ["tir_show", "tir_check", "tir_convert", "mf_eval", "load_tire", "read_document"]
