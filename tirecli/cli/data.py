"""``tirecli data``: measured tyre data (TYDEX, MDF4, CSV, Parquet): show, convert, synthesize."""
from __future__ import annotations

from typing import List, Optional

import typer

from tirecli.cli.common import max_samples, pairs, result_line, table

app = typer.Typer(help="Measured tyre data: TYDEX .tdx, MDF4 .mf4, CSV and Parquet files read into one channel "
                       "table (ISO-W axes, SI units); show, convert, and generate SYNTHETIC rig data.",
                  no_args_is_help=True)

MapOpt = typer.Option(None, "--map", metavar="FILE_COLUMN=NAME",
                      help="Read a column or channel of the file as NAME, e.g. --map Fz_N=fz (repeatable); for MDF "
                           "files the channels to read.")
UnitsOpt = typer.Option(None, "--units", metavar="NAME=UNIT",
                        help="The unit of a column, e.g. --units fz=kN or --units alpha=deg (repeatable; default: "
                             "the file's units, SI for CSV and Parquet).")
ConventionOpt = typer.Option(None, "--convention", metavar="CONVENTION",
                             help="Axis convention of the files: iso, sae or adapted-iso [default: what a file "
                                  "declares, else iso].")
RateOpt = typer.Option(None, "--rate", metavar="HZ", help="MDF files: resample onto this many samples per second "
                                                          "[default: the time stamps of the first channel].")
MaxSamplesOpt = typer.Option(None, "--max-samples", metavar="N",
                             help="Most samples (data rows) a file may hold [default: 1000000].")


def reader_options(map_, units, convention, rate) -> dict:
    """The reader options of a command (``--map``, ``--units``, ``--convention``, ``--rate``) as
    :func:`tirecli.io.readers.read_measured` takes them."""
    return {"mapping": pairs(map_), "units": pairs(units, "--units", "NAME=UNIT", "fz=kN"),
            "convention": convention, "rate": rate}


@app.command("show")
def show(
    files: List[str] = typer.Argument(..., metavar="FILE", hidden=True, show_default=False),  # in the docstring
    map_: Optional[List[str]] = MapOpt,
    units: Optional[List[str]] = UnitsOpt,
    convention: Optional[str] = ConventionOpt,
    rate: Optional[float] = RateOpt,
    max_samples_: Optional[str] = MaxSamplesOpt,
) -> None:
    """Channels, units and ranges of each FILE (.tdx, .mf4, .csv or .parquet), and the sweeps found in
    it (pure longitudinal, pure lateral, combined) with their loads, camber angles, pressures and speeds."""
    from tirecli import limits
    from tirecli.app.data import data_show

    with limits.budget(max_samples(max_samples_), config_key=False):
        blocks = data_show(files, **reader_options(map_, units, convention, rate))
    for k, block in enumerate(blocks):
        if k:
            result_line("")
        for item in block:
            if isinstance(item, str):
                result_line(item)
            else:
                for line in table(item):
                    result_line("  " + line)


@app.command("convert")
def convert(
    file: str = typer.Argument(..., metavar="FILE", help="A data file: .tdx, .mf4, .csv or .parquet.",
                               show_default=False),
    to: str = typer.Option(..., "--to", metavar="tdx|csv|parquet", help="Format to write.", show_default=False),
    out: Optional[str] = typer.Option(None, "--out", "-o", metavar="FILE",
                                      help="File to write [default: FILE with the new suffix]."),
    map_: Optional[List[str]] = MapOpt,
    units: Optional[List[str]] = UnitsOpt,
    convention: Optional[str] = ConventionOpt,
    rate: Optional[float] = RateOpt,
    max_samples_: Optional[str] = MaxSamplesOpt,
) -> None:
    """Write the channel table of a file (ISO-W axes, SI units, canonical names) as TYDEX, CSV or
    Parquet. The input is never overwritten; nothing is written when the file cannot be read."""
    from tirecli import limits
    from tirecli.app.data import data_convert

    with limits.budget(max_samples(max_samples_), config_key=False):
        result_line(data_convert(file, to, out, **reader_options(map_, units, convention, rate)))


@app.command("synth")
def synth(
    tire: str = typer.Argument(..., metavar="TIRE", help="A .tir file, its YAML form, or a built-in tyre name.",
                               show_default=False),
    out: str = typer.Option(..., "--out", "-o", metavar="FILE",
                            help="File to write (.tdx, .csv or .parquet); its name must say 'synthetic'.",
                            show_default=False),
    noise: float = typer.Option(0.01, "--noise", metavar="FRACTION",
                                help="Noise on the forces and moments: standard deviation as a fraction of each "
                                     "channel's peak."),
    seed: int = typer.Option(1, "--seed", metavar="N", help="Seed of the noise."),
    loads: Optional[str] = typer.Option(None, "--loads", metavar="LOADS",
                                        help="Loads of the pure sweeps [N], e.g. 2000,4000,6000 [default: 0.5, 1, 1.5 x FNOMIN]."),
    pressures: Optional[str] = typer.Option(None, "--pressures", metavar="PRESSURES",
                                            help="Further pressures [Pa] of pure sweeps at FNOMIN, e.g. 180000,220000 [default: none]."),
    samples: int = typer.Option(41, "--points", metavar="N", help="Samples per sweep."),
    max_samples_: Optional[str] = MaxSamplesOpt,
) -> None:
    """Generate a SYNTHETIC rig data set from a Magic Formula tyre: pure longitudinal and pure lateral
    sweeps at several loads, a camber sweep, combined sweeps, with seeded noise; labelled SYNTHETIC in
    the file and its name."""
    from tirecli.app.data import data_synth

    result_line(data_synth(tire, out, noise, seed, loads, pressures, samples, max_samples(max_samples_)))
