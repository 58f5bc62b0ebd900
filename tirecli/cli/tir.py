"""``tirecli tir``: Magic Formula tyre property files (.tir): show, check, convert."""
from __future__ import annotations

from typing import Optional

import typer

from tirecli.cli.common import result_line

app = typer.Typer(help="Tyre property files (.tir): show a summary, check the coefficients, convert to YAML and back.",
                  no_args_is_help=True)

FileArg = typer.Argument(..., metavar="TIRE", help="A .tir file, its YAML form, or a built-in tyre name "
                                                     "(tirecli params list).", show_default=False)


@app.command("show")
def show(file: str = FileArg) -> None:
    """Summary: tyre size, model version, nominal load and pressure, ranges, sections, reader warnings."""
    from tirecli.app.mf import tir_show

    result_line(tir_show(file))


@app.command("check")
def check(file: str = FileArg) -> None:
    """Coefficient sanity (C > 0, D > 0, E <= 1, stiffness signs, ranges containing the nominal point).

    Exit code 1 when an error is found, 0 with warnings only.
    """
    from tirecli.app.mf import tir_check
    from tirecli.errors import RunError

    text, n_err = tir_check(file)
    result_line(text)
    if n_err:
        raise RunError(f"{file}: {n_err} coefficient error(s)")


@app.command("convert")
def convert(
    file: str = FileArg,
    to: str = typer.Option(..., "--to", metavar="yaml|tir", help="Target format: yaml or tir.", show_default=False),
    out: Optional[str] = typer.Option(None, "--out", "-o", metavar="FILE", help="Output file [default: print to stdout]."),
) -> None:
    """Convert a .tir file to YAML (--to yaml) or back (--to tir), keeping coefficients, units and tables."""
    from tirecli.app.mf import tir_convert

    result_line(tir_convert(file, to, out))
