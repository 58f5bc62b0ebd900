"""tirecli: tire/road friction analysis (LuGre, observer, Magic Formula, MCPS) from the command line and Python.

The public Python API (``docs/api.md``), loaded on first use so that ``import tirecli`` stays cheap:

- ``tirecli.run(config, *, set=None, out=None)``: run a study config (a path or a mapping), get its
  frames, facts and reference checks; ``out`` (or ``Result.write(dir)``) writes the command's outputs;
- ``tirecli.load_params(name_or_path)``, ``tirecli.load_tire(path)``: the parameter objects the models
  take (the model functions are in :mod:`tirecli.models`).
"""
from tirecli._version import __version__

#: The public names of :mod:`tirecli.app.api` (imported on first use).
_API = ("run", "load_params", "load_tire", "Result", "CheckRecord")

__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        from tirecli.app import api

        value = getattr(api, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'tirecli' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API))
