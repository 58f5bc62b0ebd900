"""Studies: combine models, numerics and parameter sets into runs (no file I/O, no plotting).

Importing this package registers every study in :data:`tirecli.studies.base.STUDIES`.
"""
from tirecli.studies import mf_golden, sweep  # noqa: F401
