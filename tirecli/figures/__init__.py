"""Figure functions, registered in :mod:`tirecli.figures.registry` on import."""
from tirecli.figures import steady  # noqa: F401
from tirecli.figures import transient  # noqa: F401
from tirecli.figures import identification  # noqa: F401
from tirecli.figures import observer  # noqa: F401
from tirecli.figures import magic_formula  # noqa: F401
