"""The version of tirecli (a leaf: imports nothing; setuptools reads it, see pyproject.toml)."""

__version__ = "0.1.0"
