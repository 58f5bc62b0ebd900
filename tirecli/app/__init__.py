"""The application layer: what each command does, independent of the CLI framework.

- :mod:`tirecli.app.plan`: a config checked completely before anything runs (its study's plan and the
  figure ids it lists);
- :mod:`tirecli.app.run`: run a study config (``sweep``, ``simulate``, ``fit``, ``observe``, ``compare``),
  draw its figures, evaluate their checks, write the outputs; validate configs, show parameter sets;
- :mod:`tirecli.app.draw`: the draw-and-check loop (commands and report);
- :mod:`tirecli.app.results`: the result writer (a run's ``run.json``, ``data/``, ``figures/``; the
  report's layout);
- :mod:`tirecli.app.mf`: the Magic Formula commands (``tirecli tir ...``, ``tirecli mf eval``);
- :mod:`tirecli.app.campaign`: ``tirecli campaign``;
- :mod:`tirecli.app.data`: measured data (``tirecli data show|convert|synth``);
- :mod:`tirecli.app.api`: the public Python API (``tirecli.run``, ``load_params``, ``load_tire``).

The Typer commands in :mod:`tirecli.cli` only parse arguments, call these functions and print what a
study's registry entry says (:mod:`tirecli.studies.registry`); the report (:mod:`tirecli.report`) and
the campaigns (:mod:`tirecli.campaign`) sit beside this layer and use the same entries.
"""
