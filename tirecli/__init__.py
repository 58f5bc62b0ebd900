"""tirecli: tire/road friction analysis (LuGre, observer, Magic Formula) from the command line."""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("tirecli")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+source"
