"""The application layer: what each command does, independent of the CLI framework.

- :mod:`tirecli.app.run`: run a study config (``sweep``, ``simulate``, ``fit``, ``observe``, ``compare``),
  draw its figures, evaluate their checks, write the outputs; validate configs, show parameter sets;
- :mod:`tirecli.app.results`: the result writer (``run.json``, ``data/``, ``figures/``);
- :mod:`tirecli.app.mf`: the Magic Formula commands (``tirecli tir ...``, ``tirecli mf eval``);
- :mod:`tirecli.app.campaign`: ``tirecli campaign``;
- :mod:`tirecli.app.data`: measured data (``tirecli data show|convert|synth``).

The Typer commands in :mod:`tirecli.cli` only parse arguments and call these functions; the report
(:mod:`tirecli.report`) and the campaigns (:mod:`tirecli.campaign`) sit beside this layer.
"""
