"""``tirecli mf``: Magic Formula evaluation."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli.common import echo, max_samples, pairs, result_line, warn

app = typer.Typer(help="Magic Formula tyre model (MF 6.1 / 6.2 / 5.2 / PAC89).", no_args_is_help=True)


@app.command("eval")
def eval_(
    tire: str = typer.Argument(..., metavar="TIRE", help="A .tir file, its YAML form, or a built-in tyre name.",
                               show_default=False),
    points: Path = typer.Option(..., "--points", metavar="CSV", help="CSV with columns kappa, alpha, gamma, fz [, p, vx] "
                                                      "(SI: -, rad, rad, N, Pa, m/s).", show_default=False),
    out: str = typer.Option(..., "--out", "-o", metavar="FILE", help="Result CSV: the input columns, then fx, fy, mz, mx, my [N, N m], then "
                             "those of sigmax, sigmay [m], Kxk [N], Kya [N/rad], Cx, Cy, Cz [N/m], re, a, b [m] "
                             "the tyre gives (relaxation lengths, slip and carcass stiffnesses, vertical stiffness, "
                             "effective rolling radius, contact-patch half-length and half-width).",
                             show_default=False),
    convention: str = typer.Option("mfeval", "--convention", metavar="mfeval|teasit", help="Where public implementations differ "
                                   "(docs/models/magic_formula_tyre.md §10): mfeval (default) or teasit (reproduces the "
                                   "public golden data)."),
    side: Optional[str] = typer.Option(None, "--side", metavar="left|right", help="Mount the tyre on this side (left or right); "
                                                            "mirrored when the file was measured on the other."),
    no_limits: bool = typer.Option(False, "--no-limits", help="No input clipping to the file's ranges and no "
                                                              "low-speed handling (docs/models/magic_formula_tyre.md §11)."),
    map_: Optional[List[str]] = typer.Option(None, "--map", metavar="FILE_COLUMN=NAME",
                                             help="Use a differently named column, e.g. --map slip=kappa (repeatable)."),
    max_samples_: Optional[str] = typer.Option(None, "--max-samples", metavar="N",
                                               help="Most points (CSV rows) one run may evaluate [default: 1000000]."),
) -> None:
    """Evaluate a Magic Formula tyre at the points of a CSV (ISO-W axes, SI units).

    p and vx default to the tyre's INFLPRES (else NOMPRES) and LONGVL. Bad input (missing column,
    non-numeric or NaN cell) is an error naming the column and row (exit 2), and nothing is written.
    After the forces come mfeval's further outputs where the tyre's coefficients give them
    (docs/models/magic_formula_tyre.md §17); the command names the ones left out and what they need.
    """
    from tirecli.app.mf import mf_eval
    from tirecli.models.magic_formula.inputs import describe_counts, describe_outside
    from tirecli.errors import UsageError

    if convention not in ("mfeval", "teasit"):
        raise UsageError(f"--convention {convention!r}: expected mfeval or teasit")
    if side is not None and side.lower() not in ("left", "right"):
        raise UsageError(f"--side {side!r}: expected left or right")
    s = mf_eval(tire, points, out, convention=convention, side=side.lower() if side else None,
                limits=not no_limits, mapping=pairs(map_), max_samples=max_samples(max_samples_))
    extra = []
    if s["pressure_default"] is not None:
        extra.append(f"p = {s['pressure_default']:g} Pa (tyre default)")
    if s["speed_default"] is not None:
        extra.append(f"vx = {s['speed_default']:g} m/s (LONGVL)")
    echo(f"mf eval: {s['points']} point(s), tyre {s['tire']} (MF {s['version']}, measured {s['side']}"
         f"{', mirrored' if s['mirrored'] else ''}), convention {s['convention']}"
         + (f"; {', '.join(extra)}" if extra else ""))
    if s["omitted"]:
        by_reason: dict = {}
        for k, why in s["omitted"].items():
            by_reason.setdefault(why, []).append(k)
        echo("not written (the tyre lacks the coefficients): "
             + "; ".join(f"{', '.join(ks)} ({why})" for why, ks in by_reason.items()))
    if s["warnings"]:
        echo(f"{len(s['warnings'])} reader warning(s) for {tire} (tirecli tir show {tire} lists them)")
    touched = describe_counts(s["counts"])
    if s["limits"]:
        echo("limits and low-speed rules: " + ("; ".join(touched) if touched else "no point touched"))
    else:
        echo("limits and low-speed rules off (--no-limits)")
    for line in describe_outside(s["outside"]):  # flagged even with --quiet: these rows are extrapolated
        warn(line)
    result_line(f"wrote {s['out']}")
