"""What the MCPS figure modules share (:mod:`tirecli.figures.mcps`, :mod:`tirecli.figures.mcps_stationary`):
the study guard, the tire's name and description, the legend below the panels."""
from __future__ import annotations

def require(result, study: str, fid: str, family: str | None = None) -> None:
    """A UsageError unless ``result`` is a ``study`` run (holding ``family`` for stationary figures)."""
    from tirecli.errors import UsageError

    if result.study != study:
        raise UsageError(f"figure {fid!r} draws an '{study}' run, not a '{result.study}' run (see 'tirecli figures list')")
    if family is not None and family not in set(result.data["stationary"]["family"]):
        raise UsageError(f"figure {fid!r} draws the '{family}' family: add '{family}:' to the config")


def default_tire(result) -> bool:
    from tirecli.studies.mcps.common import reference_tire

    return reference_tire(result.parameter_sets["tire"])


def tire_name(result) -> str:
    return result.parameter_sets["tire"].label


def legend_below(fig, ax, ncol=3):
    """One legend for the figure, below the panels (never over the curves)."""
    h, lab = ax.get_legend_handles_labels()
    if h:
        fig.legend(h, lab, loc="outside lower center", ncol=ncol, fontsize=8, frameon=False)


def loads_text(result, default="4000 N") -> str:
    if result is None:
        return default
    loads = result.meta.get("loads") or [result.meta.get("scenario", {}).get("fz_N", 4000.0)]
    return ", ".join(f"{f:g}" for f in loads) + " N"


def tire_text(result) -> str:
    if result is None or default_tire(result):
        return "the default tire sorine2000-mcps [every value assumed: the paper prints none]"
    return f"the tire {tire_name(result)}"


__all__ = ["require", "default_tire", "tire_name", "legend_below", "loads_text", "tire_text"]
