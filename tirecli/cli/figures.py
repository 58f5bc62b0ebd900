"""``tirecli figures``: the figure registry."""
from __future__ import annotations

import typer

from tirecli.cli.common import result_line

app = typer.Typer(help="The registered figures (paper figures and generic plots).", no_args_is_help=True)


@app.command("list")
def list_() -> None:
    """List every registered figure: id, paper, numbering, title and the study it needs."""
    from tirecli.figures.registry import load_all

    for f in sorted(load_all().values(), key=lambda f: (f.paper, f.order, f.id)):
        result_line(f"{f.id:24s} {f.paper:8s} {f.label:24s} {f.title}  [study: {f.study or 'any'}]")
