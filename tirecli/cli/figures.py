"""``tirecli figures``: the figure registry."""
from __future__ import annotations

import typer

from tirecli.cli.common import result_line

app = typer.Typer(help="The registered figures (paper figures and generic plots).", no_args_is_help=True)


@app.command("list")
def list_() -> None:
    """List every registered figure: id, paper, numbering, title and the study it needs."""
    from tirecli.figures.registry import load_all

    figs = sorted(load_all().values(), key=lambda f: (f.paper, f.order, f.id))
    w_id = max(len(f.id) for f in figs)
    w_label = max(len(f.label) for f in figs)
    for f in figs:
        result_line(f"{f.id:{w_id}s}  {f.paper:7s}  {f.label:{w_label}s}  {f.title}  [study: {f.study or 'any'}]")
