"""``tirecli figures``: the figure registry."""
from __future__ import annotations

import typer

from tirecli.cli.common import result_line, table

app = typer.Typer(help="The registered figures (paper figures and generic plots).", no_args_is_help=True)


@app.command("list")
def list_() -> None:
    """List every registered figure: id, paper, numbering, title and the study it needs."""
    from tirecli.figures.registry import load_all

    figs = sorted(load_all().values(), key=lambda f: (f.paper, f.order, f.id))
    for line in table([(f.id, f.paper, f.label, f"{f.title}  [study: {f.study or 'any'}]") for f in figs]):
        result_line(line)
