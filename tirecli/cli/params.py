"""``tirecli params``: built-in parameter sets and validation of YAML files."""
from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from tirecli.cli.common import MaxSamplesOpt, max_samples, result_line, table

app = typer.Typer(help="List, show and validate parameter sets.", no_args_is_help=True)


@app.command("list")
def list_() -> None:
    """List the built-in parameter sets with their kind and title."""
    from tirecli.parameters.sets import builtin_names, load_builtin

    sets = [load_builtin(name) for name in builtin_names()]
    for line in table([(name, ps.kind, ps.title) for name, ps in zip(builtin_names(), sets)]):
        result_line(line)


@app.command("show")
def show(name: str = typer.Argument(..., metavar="NAME", help="A built-in set name (tirecli params list) or a "
                                                             "parameter-set YAML file.", show_default=False)) -> None:
    """Show a parameter set: values, units, meaning, equation, source; assumed values flagged."""
    from tirecli.app.run import show_parameter_set

    result_line(show_parameter_set(name))


@app.command("validate")
def validate(file: Path = typer.Argument(..., metavar="FILE", help="A parameter-set file, a study config, a campaign "
                                         "file or a .tir file.", show_default=False),
             max_samples_: Optional[str] = MaxSamplesOpt) -> None:
    """Check a parameter-set file, a study config or a campaign (every point; its sample budget included); one
    line per problem, exit 2 if any."""
    from tirecli.app.run import validate_file

    result_line(validate_file(file, max_samples(max_samples_)))
