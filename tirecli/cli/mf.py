"""``tirecli mf``: Magic Formula evaluation (``mf eval``) and fitting to measured data (``mf fit``)."""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer

from tirecli.cli import data as data_cli
from tirecli.cli.common import MaxSamplesOpt, SetOpt, StrictOpt, echo, max_samples, pairs, result_line, run_command, warn

app = typer.Typer(help="Magic Formula tyre model (MF 6.1 / 6.2 / 5.2 / PAC89): evaluate, fit to measured data.",
                  no_args_is_help=True)


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


@app.command("fit")
def fit(
    data: List[str] = typer.Argument(..., metavar="DATA", hidden=True, show_default=False),  # in the docstring
    start: Optional[str] = typer.Option(None, "--start", metavar="TIRE",
                                        help="Start tyre: a .tir file (or its YAML form) or a built-in name, MF 6.1 or "
                                             "6.2; gives the start values, the dimensions and every coefficient not fitted."),
    out: Optional[str] = typer.Option(None, "--out", "-o", metavar="DIR",
                                      help="Output directory [default: tirecli-out/mf-fit-DATA]."),
    map_: Optional[List[str]] = data_cli.MapOpt,
    units: Optional[List[str]] = data_cli.UnitsOpt,
    convention: Optional[str] = data_cli.ConventionOpt,
    rate: Optional[float] = data_cli.RateOpt,
    parts: Optional[str] = typer.Option(None, "--parts", metavar="PARTS",
                                        help="Parts to fit, comma-separated: longitudinal, lateral, aligning, combined "
                                             "[default: all the data have sweeps for]."),
    loss: Optional[str] = typer.Option(None, "--loss", metavar="LOSS",
                                       help="linear (least squares, the default) or a robust loss: soft_l1, huber, "
                                            "cauchy, arctan."),
    f_scale: Optional[float] = typer.Option(None, "--f-scale", metavar="FRACTION",
                                            help="Residual where a robust loss starts to discount a point, as a "
                                                 "fraction of the channel's peak [default: 0.02]."),
    weight: Optional[List[str]] = typer.Option(None, "--weight", metavar="CHANNEL=WEIGHT",
                                               help="Weight of fx, fy or mz in the sums of squares, e.g. --weight mz=0.5 "
                                                    "(0 leaves the channel out; repeatable)."),
    bound: Optional[List[str]] = typer.Option(None, "--bound", metavar="BOUND",
                                              help="Bounds of a coefficient: NAME=LOW,HIGH, e.g. --bound PDX1=0.8,1.6 (repeatable)."),
    fix: Optional[str] = typer.Option(None, "--fix", metavar="NAMES",
                                      help="Coefficients kept at their start values, comma-separated."),
    mf_convention: Optional[str] = typer.Option(None, "--mf-convention", metavar="mfeval|teasit",
                                                help="Magic Formula variant of the evaluation [default: mfeval]."),
    reference: Optional[str] = typer.Option(None, "--reference", metavar="TIRE",
                                            help="A tyre the fitted curves are checked against (e.g. the tyre SYNTHETIC "
                                                 "data were generated from): reference checks in run.json."),
    set_: Optional[List[str]] = SetOpt,
    strict: bool = StrictOpt,
    max_samples_: Optional[str] = MaxSamplesOpt,
) -> None:
    """Fit Magic Formula 6.1 coefficients to measured tyre data (DATA: .tdx, .csv, .parquet or .mf4 files,
    or one mf-fit config .yaml) and write DIR/fitted.tir.

    The fit is staged (pure longitudinal, pure lateral, aligning torque, combined slip; nominal load
    before the load dependence); coefficients the data cannot identify keep the start tyre's values and
    are named with why. Writes fitted.tir (passes 'tirecli tir check', reads in 'tirecli mf eval'),
    run.json, data/fit.csv (data, fit and residual per point, the fit being fitted.tir read back),
    data/coefficients.csv (95 % intervals), data/correlations.csv, data/stages.csv, data/goodness.csv and
    the figures. Bad input is one error line (exit 2) and nothing is written. docs/data.md.
    """
    from tirecli.app.mf_fit import as_overrides, config_of, default_out, is_config, settings

    values = settings(start, data_cli.reader_options(map_, units, convention, rate), parts, loss, f_scale, weight,
                      bound, fix, mf_convention, None, reference)
    if is_config(data):
        run_command("mf fit", Path(data[0]), list(set_ or []) + as_overrides(values), out, None, strict, max_samples_)
        return
    config = config_of(data, values, overrides=list(set_ or []))
    run_command("mf fit", config, None, out or str(default_out(data)), None, strict, max_samples_)
