"""The campaign sections of ``tirecli report CAMPAIGN.yaml ...``.

Each campaign runs (or resumes: its finished points are reused) into its own output directory,
the default folder of ``tirecli campaign`` (``tirecli-out/campaign-STEM``); its section shows the design, the
statistics of each output, the campaign checks (also in the report's ``summary.json``, ids
``campaign/NAME/CHECK``) and the analysis figures, and the report folder gets a copy of its
``results.csv`` (``campaigns/NAME/results.csv``).
"""
from __future__ import annotations

import base64
from pathlib import Path


def _design_text(design: dict) -> str:
    parts = []
    if design.get("grid"):
        parts.append("grid " + " x ".join(f"{k} ({len(v)})" for k, v in design["grid"].items()))
    s = design.get("sample")
    if s:
        parts.append(f"{s['method']} sample of {', '.join(s['distributions'])} (n = {s['n']}, seed {s['seed']})")
    return "; ".join(parts)


def _output(path, folder) -> bytes:
    """A file the campaign just wrote in ``folder``, read through the input gate
    (:func:`tirecli.io.files.read_own_file`: a regular file of that folder, never a FIFO or a device)."""
    from tirecli import limits
    from tirecli.errors import RunError
    from tirecli.io.files import read_own_file

    data = read_own_file(path, limits.csv_max_bytes(), within=folder)
    if data is None:
        raise RunError(f"{path}: the campaign's output is no longer a regular file of {folder} (replaced meanwhile?)")
    return data


def campaign_sections(paths, root: Path, env, progress=None) -> tuple[str, list]:
    """Run the campaigns ``paths`` and render their sections: ``(html, check records)``; their
    results tables are copied under ``root/campaigns/``."""
    from tirecli.app.campaign import default_out, run_campaign
    from tirecli.io.output import write_text

    html, checks = [], []
    for path in paths:
        summary = run_campaign(path, default_out(path), progress=progress)
        rec = summary.record
        name = rec["campaign"]
        rel = f"campaigns/{name}/results.csv"
        (root / "campaigns" / name).mkdir(parents=True, exist_ok=True)
        write_text(root / rel, _output(summary.paths["csv"], summary.out).decode("utf-8"))
        figs = [{"name": Path(p).stem, "image": base64.b64encode(_output(p, summary.out)).decode("ascii")}
                for p in summary.paths["figures"] if str(p).endswith(".png")]
        records = []
        for c in summary.checks:
            r = c.record()
            r["id"] = f"campaign/{name}/{c.id}"
            records.append(r)
        checks += records
        html.append(env.get_template("campaign_section.html.j2").render(c={
            "name": name, "title": rec["title"], "description": rec["description"], "file": rec["file"],
            "study": rec["study"], "base": rec["base"]["file"], "points": rec["points"],
            "design_text": _design_text(rec["design"]), "stats": rec["analysis"]["statistics"],
            "checks": records, "failures": rec["failures"], "figures": figs, "results": rel,
        }))
    return "\n".join(html), checks


__all__ = ["campaign_sections"]
