"""Campaigns: grid, Monte Carlo and sensitivity studies over any config key (``tirecli campaign``).

A campaign runs a base study (any study config) at many points, each the base with overrides of
keys that ``--set`` accepts, and tabulates chosen facts of every run.

* :mod:`tirecli.campaign.spec`: the campaign file, the design (grid and samples) and the points,
  each identified by a hash of its resolved config.
* :mod:`tirecli.campaign.check`: every point checked before anything runs.
* :mod:`tirecli.campaign.facts`: one point: run the study through its registry entry (no figures, no files)
  and pick its facts by name.
* :mod:`tirecli.campaign.execute`: batches of points on a local process pool or a Dask cluster.
* :mod:`tirecli.campaign.analysis`: statistics, one-at-a-time effects, tornado and Sobol indices,
  campaign-level checks.

Files are written by :mod:`tirecli.io.campaign`; figures are :mod:`tirecli.figures.campaign`; the
command is orchestrated by :mod:`tirecli.app.campaign`.
"""
