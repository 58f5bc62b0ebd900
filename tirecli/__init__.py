"""tirecli: tire/road friction analysis (LuGre, observer, Magic Formula) from the command line."""

__version__ = "0.1.0"
