"""The physics models: pure, vectorized functions of their inputs and a parameter object (no file access,
no solvers). Static maps are ``f(inputs..., p)`` with every input's unit in its docstring; dynamic models
give ``rhs(t, x, u, p)`` and ``outputs(t, x, u, p)``.

The public names below are importable from here (``from tirecli.models import mu_ss_uniform``); each is
imported from its module on first use, so ``import tirecli.models`` stays cheap. The parameter objects
come from ``tirecli.load_params`` / ``tirecli.load_tire`` (``docs/api.md``).

- LuGre friction (:mod:`tirecli.models.lugre`, ``docs/models/lugre_friction.md``): ``LuGreParams``,
  ``mu_ss_uniform``, ``mu_ss_exponential``, ``mu_ss_density``, ``mu_ss_lumped``, ``stribeck``,
  ``patch_ratio``, ``kappa0_of_x``, ``lumped_zdot``, ``lumped_mu``; the model variants of the commands
  (:mod:`tirecli.models.variants`): ``FrictionVariant``; the peaks of a steady-state curve:
  ``curve_peaks``;
- the quarter car (:mod:`tirecli.models.vehicle`, :mod:`tirecli.models.quarter_car`): ``QuarterCarParams``;
- the Magic Formula (:mod:`tirecli.models.magic_formula`, ``docs/models/magic_formula_tyre.md``):
  ``MFTire``, ``evaluate``, ``evaluate_extras``;
- the MCPS tire (:mod:`tirecli.models.mcps`, ``docs/models/mcps_tire.md``): ``MCPSParams``.
"""

#: Public name -> its module (below ``tirecli.models``).
PUBLIC = {
    "LuGreParams": "lugre", "mu_ss_uniform": "lugre", "mu_ss_exponential": "lugre", "mu_ss_density": "lugre",
    "mu_ss_lumped": "lugre", "stribeck": "lugre", "patch_ratio": "lugre", "kappa0_of_x": "lugre",
    "lumped_zdot": "lugre", "lumped_mu": "lugre",
    "FrictionVariant": "variants", "curve_peaks": "steady_peaks",
    "QuarterCarParams": "vehicle",
    "MFTire": "magic_formula", "evaluate": "magic_formula", "evaluate_extras": "magic_formula.extras",
    "MCPSParams": "mcps.params",
}

__all__ = sorted(PUBLIC)


def __getattr__(name: str):
    if name in PUBLIC:
        import importlib

        value = getattr(importlib.import_module(f"{__name__}.{PUBLIC[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(PUBLIC))
