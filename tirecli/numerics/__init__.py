"""Solvers of the transient models (no I/O, no plotting).

- :mod:`tirecli.numerics.ros2` — adaptive second-order Rosenbrock driver (breakpoints, wheel lock,
  stop condition);
- :mod:`tirecli.numerics.lumped` — quarter car / tire alone with the lumped LuGre model;
- :mod:`tirecli.numerics.characteristics` — the same with the distributed LuGre model, solved
  exactly along characteristics;
- :mod:`tirecli.numerics.runs` — one entry point per run kind (coupled, open loop);
- :mod:`tirecli.numerics.observer` — quarter car + adhesion observer (OBS): a structured fixed-step scheme, adaptive
  scipy methods and a Radau reference;
- :mod:`tirecli.numerics.mf_fit` — Magic Formula 6.1 coefficients fitted to measured points, stage by
  stage, with intervals and identifiability.
"""
