"""Studies: combine models, numerics and parameter sets into runs (no file I/O, no plotting).

Importing this package registers every study in :data:`tirecli.studies.base.STUDIES`.
"""
from tirecli.studies import sweep  # noqa: F401
from tirecli.studies import simulate  # noqa: F401
from tirecli.studies import fit  # noqa: F401
from tirecli.studies import observe  # noqa: F401
from tirecli.studies import mf_golden  # noqa: F401
