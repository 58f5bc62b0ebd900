"""Figure functions, registered in :mod:`tirecli.figures.registry` on import."""
from tirecli.figures import magic_formula, steady  # noqa: F401
