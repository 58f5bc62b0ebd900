"""The MCPS studies (Sorine & Szymanski 2000): the multi-DOF dynamic tire model against the Magic Formula.

``tirecli compare CONFIG`` runs ``study: mcps-stationary`` (MCPS Figs. 7-11); ``tirecli simulate
CONFIG`` runs the time-domain studies ``mcps-slider`` (Fig. 3), ``mcps-standstill`` (Figs. 4-5) and
``mcps-relaxation`` (force build-up after a slip-angle step). Models: :mod:`tirecli.models.mcps`;
solvers: :mod:`tirecli.numerics.mcps_stationary`, :mod:`tirecli.numerics.mcps_transient`,
:mod:`tirecli.numerics.mcps_calibrate`. Axes ISO-W, road on tire, SI (rad, not degrees, in configs
and CSVs; figures draw degrees). Users' guide: ``docs/models/mcps_tire.md``.

``mcps-stationary``::

    study: mcps-stationary
    tire: sorine2000-mcps             # MCPS set (default), a set file, or {set: ..., r_x: 6e7}
    mf: externdata-205-60r15          # built-in MF tyre (default), a .tir path, simple, none,
                                      # or {tire: ..., convention: mfeval}
    carcass: complete                 # complete (default), rigid, or a list of both
    fz: 4000                          # [N] a number or a list
    kappa: {start: 0, stop: 0.12, num: 49}        # [-] pure longitudinal slip (alpha = 0)
    alpha: {start: 0, stop: 0.2094, num: 49}      # [rad] pure side slip (kappa = 0)
    combined: {alpha: [0.0175, 0.0349], kappa: {start: -0.1, stop: 0.1, num: 81}}   # every pair
    curvature: {start: 0, stop: 0.1, num: 21}     # [1/m] path curvature at kappa = alpha = 0
    calibrate: false                  # true: fit the rubber parameters to the MF curves first

Output ``data/stationary.csv``: ``model`` (mcps, mf), ``carcass``, ``calibrated``, ``family``
(kappa, alpha, combined, curvature), ``fz, kappa, alpha, phi, fx, fy, mz`` and the belt
deflections ``x, y, delta`` of the MCPS rows (empty for the Magic Formula).

Modules: :mod:`~tirecli.studies.mcps.common` (the MCPS parameter set, the Magic Formula side),
:mod:`~tirecli.studies.mcps.stationary`, :mod:`~tirecli.studies.mcps.slider`,
:mod:`~tirecli.studies.mcps.standstill`, :mod:`~tirecli.studies.mcps.relaxation` (one study each).
"""
