"""Figure functions, registered in :mod:`tirecli.figures.registry` when their module is imported.

:data:`tirecli.figures.registry.FIGURE_MODULES` lists the modules; ``registry.get`` imports them
in order until the figure is found, ``registry.load_all`` imports them all.
"""
