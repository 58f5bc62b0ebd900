"""Steady-state sweeps of a Magic Formula tyre, through ``tirecli sweep`` (beside the LuGre sweeps).

A sweep config whose ``tire:`` is a Magic Formula tyre (a built-in tyre, a ``.tir`` path relative
to the config, its YAML form, or inline ``.tir`` coefficients, with overrides) runs this study;
a LuGre ``tire:`` runs :mod:`tirecli.studies.sweep`. The command, the output contract
(``run.json``, ``data/*.csv``, PNG + SVG) and ``--set`` overrides are the same::

    study: sweep
    tire: chrono-185-80r14              # or tires/my.tir, or {set: my.tir, LMUY: 0.9}
    convention: mfeval                  # mfeval (default, docs/models/magic_formula_tyre.md §10) or teasit (§15.2)
    side: left                          # optional: mount side (mirrors a tyre measured on the other)
    limits: true                        # clip inputs to the file's ranges, low-speed rules (§11)
    sweep:
      kappa: {start: -0.5, stop: 0.5, num: 201}     # slip [-] of the Fx-kappa curves (ISO-W)
      alpha: {start: -0.3, stop: 0.3, num: 121}     # slip angle [rad] of the Fy-alpha, Mz-alpha curves
      loads: [2000, 4000, 6000]                     # [N] (default: 0.5, 1, 1.5 x FNOMIN)
      load: 4000                                    # [N] of the camber and combined families (default FNOMIN)
      camber: [-0.05, 0, 0.05]                      # [rad] camber family
      combined_alpha: [0.02, 0.05, 0.1]             # [rad] fixed alpha of the Fx-Fy curves (kappa sweeps)
      combined_kappa: [0.02, 0.05, 0.1]             # [-] fixed kappa of the Fx-Fy curves (alpha sweeps)
      speed: 16.7                                   # [m/s] (default LONGVL)
      pressure: 220000                              # [Pa] (default INFLPRES, else NOMPRES)
    compare:                                        # optional: a LuGre tire on the same |mu|-|s| plot
      lugre: canudas2003-table1
      speed: 20                                     # [m/s] held speed of the LuGre curve
    figures: [mf-fx-kappa, mf-fy-alpha, mf-mz-alpha, mf-camber, mf-combined]

Output frame ``sweep`` (long format, ISO-W, SI): ``family`` (``fx-kappa``, ``fy-alpha``,
``camber``, ``combined-alpha``, ``combined-kappa``), ``kappa, alpha, gamma, fz, vx, p, fx, fy,
mz, mx, my``, and ``mu_x = fx/fz``, ``mu_y = fy/fz``, ``slip`` (the LuGre slip of
:func:`tirecli.conventions.slip_from_kappa`). With ``compare``, family ``compare`` holds the pure
longitudinal Magic Formula force on the LuGre slip grid (``kappa = kappa_from_slip(slip)``,
``|slip| <= 0.999``) and frame ``lugre`` the LuGre steady state (``slip, mu, direction``) at the
held speed. Set ``limits: false`` for the comparison when the file's ``KPUMAX`` is below the
slips of interest (clipping flattens the curve, docs/models/magic_formula_tyre.md §11).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from tirecli.config.loader import Config
from tirecli.config.schema import Bool, Grid, Map, Num, Raw, Str, check_document, collect
from tirecli.conventions import kappa_from_slip, slip_from_kappa
from tirecli.errors import ConfigError, RunError, token
from tirecli.studies.base import StudyResult, common_fields
from tirecli.studies.study import Plan

if TYPE_CHECKING:  # pandas is imported when a study runs, not when its config is checked
    import pandas as pd

FAMILIES = ("fx-kappa", "fy-alpha", "camber", "combined-alpha", "combined-kappa", "compare")

def _lin(start, stop, num):
    return [float(x) for x in np.linspace(start, stop, num)]


MF_SWEEP = Map(fields={
    "kappa": Grid(unit="-", ge=-1.0, le=10.0, default=_lin(-0.5, 0.5, 201),
                  doc="longitudinal slip of the Fx-kappa and combined curves (ISO-W, > 0 driving)"),
    "alpha": Grid(unit="rad", ge=-1.5, le=1.5, default=_lin(-0.3, 0.3, 121),
                  doc="slip angle of the Fy-alpha, Mz-alpha and combined curves"),
    "loads": Grid(unit="N", gt=0, default=None, doc="loads of the pure-slip families (default 0.5, 1, 1.5 x FNOMIN)"),
    "load": Num(unit="N", gt=0, default=None, doc="load of the camber and combined families (default FNOMIN)"),
    "camber": Grid(unit="rad", ge=-0.5, le=0.5, default=[-0.05, 0.0, 0.05], doc="camber family"),
    "combined_alpha": Grid(unit="rad", ge=-1.5, le=1.5, default=[0.02, 0.05, 0.1, 0.2],
                           doc="fixed slip angles of the Fx-Fy curves (kappa sweeps)"),
    "combined_kappa": Grid(unit="-", ge=-1.0, le=10.0, default=[0.02, 0.05, 0.1, 0.2],
                           doc="fixed slips of the Fx-Fy curves (alpha sweeps)"),
    "speed": Num(unit="m/s", default=None, doc="forward speed (default LONGVL)"),
    "pressure": Num(unit="Pa", gt=0, default=None, doc="inflation pressure (default INFLPRES, else NOMPRES)"),
})

COMPARE = Map(fields={
    "lugre": Raw(kind="lugre", doc="LuGre parameter set drawn beside the Magic Formula curve"),
    "speed": Num(unit="m/s", gt=0, default=20.0, doc="held speed of the LuGre curve"),
    "slip": Grid(unit="-", ge=-1, le=1, default=_lin(-1.0, 1.0, 401), doc="slip grid of both curves"),
    "load": Num(unit="N", gt=0, default=None, doc="load of the Magic Formula curve (default FNOMIN)"),
}, default=None)

SPEC = Map(fields=common_fields() | {
    "tire": Raw(kind="magic_formula", doc="Magic Formula tyre: a built-in name, a .tir path, or {set: ..., overrides}"),
    "convention": Str(choices=("mfeval", "teasit"), default="mfeval", doc="variant of docs/models/magic_formula_tyre.md §10"),
    "side": Str(choices=("left", "right"), default=None, doc="mount side (mirroring, §2.4)"),
    "limits": Bool(default=True, doc="input clipping and low-speed rules (§11)"),
    "sweep": Map(fields=MF_SWEEP.fields, default=None),
    "compare": COMPARE,
})

DEFAULT_FIGURES = ["mf-fx-kappa", "mf-fy-alpha", "mf-mz-alpha", "mf-camber", "mf-combined"]


def uses_mf_tire(config: Config) -> bool:
    """Whether the config's ``tire:`` is a Magic Formula tyre (so ``tirecli sweep`` runs this study)."""
    from tirecli.parameters.mf_catalogue import CATALOGUE
    from tirecli.parameters.sets import load_set

    raw = config.data.get("tire")
    ref = raw if isinstance(raw, str) else (raw.get("set") if isinstance(raw, dict) else None)
    if isinstance(ref, str):
        if ref.lower().endswith(".tir"):
            return True
        try:
            return load_set(ref, config.base_dir).kind == "magic_formula"
        except ConfigError:
            return False
    if isinstance(raw, dict) and raw:
        return all(isinstance(k, str) and k in CATALOGUE for k in raw)
    return False


@dataclass
class MFSweep:
    """The detail of a Magic Formula sweep's plan: the tyre model."""

    tire: Any


def plan(config: Config) -> Plan:
    """Check an MF sweep config completely (sets ``tire`` and, with ``compare``, ``lugre``; detail
    :class:`MFSweep`)."""
    from tirecli.parameters.sets import resolve_group, resolve_tire

    checked, tire = collect(lambda: config.checked(SPEC),
                            lambda: resolve_tire(config.data.get("tire"), config.origins, ("tire",), config.base_dir))
    ps, t = tire
    if checked["sweep"] is None:  # every sweep key has a default
        checked["sweep"] = check_document({}, MF_SWEEP, config.origins, ("sweep",))
    lugre = None
    cmp = checked["compare"]
    if cmp is not None:
        lugre = resolve_group(cmp["lugre"], config.origins, ("compare", "lugre"), "lugre", config.base_dir)
    if checked["side"] is not None and t.side == "unknown" and t.family == "mf":
        raise ConfigError(config.origins.problem(("side",), f"the tyre {ps.name} has no TYRESIDE, so it cannot be mirrored"))
    foreign = [f for f in (checked["figures"] or []) if not f.startswith("mf-")]
    if foreign:
        raise ConfigError(config.origins.problem(("figures",), f"figure {token(foreign[0])} draws a LuGre sweep; a Magic "
                                                               "Formula sweep draws the mf-* figures (tirecli figures list)"))
    if checked["sweep"]["speed"] is None and t.family == "mf" and t.reference_speed is None:
        raise ConfigError(config.origins.problem(("sweep",), "missing 'speed': the tyre has no LONGVL to default to"))
    est = _estimate(checked["sweep"], checked["compare"])
    est.check(config.origins)
    sets = {"tire": ps} if lugre is None else {"tire": ps, "lugre": lugre}
    return Plan("sweep", config, checked, sets, est, MFSweep(t))


#: Memory per row of a Magic Formula sweep (frame of 16 columns, CSV text, figures) [bytes].
BYTES_PER_ROW = 1400


def _estimate(sw: dict, cmp: dict | None):
    """The rows of every family (see :func:`mf_sweep_frame`), each blamed on its grids."""
    from tirecli.limits import Estimate

    n = {k: len(sw[k]) for k in ("kappa", "alpha", "camber", "combined_alpha", "combined_kappa")}
    n["loads"] = len(sw["loads"] or (0, 0, 0))
    est = Estimate()
    for family, a, b in (("fx-kappa", "loads", "kappa"), ("fy-alpha", "loads", "alpha"), ("camber", "camber", "alpha"),
                         ("combined-alpha", "combined_alpha", "kappa"), ("combined-kappa", "combined_kappa", "alpha")):
        est.add_product({("sweep", a): n[a], ("sweep", b): n[b]}, f"the {family} family", BYTES_PER_ROW)
    if cmp is not None:
        est.add(2 * len(cmp["slip"]), ("compare", "slip"), "the comparison", BYTES_PER_ROW)
    return est


class NonFinite(Exception):
    """The Magic Formula gave no finite output in a family: ``(key, text, input_at_fault)``."""


def _block(t, family, kappa, alpha, gamma, fz, vx, p, kw, key=("sweep",)) -> pd.DataFrame:
    import pandas as pd

    from tirecli.models.magic_formula import evaluate
    from tirecli.models.magic_formula.engine import nonfinite_point

    k, a, g, f = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (kappa, alpha, gamma, fz)))
    r = evaluate(t, k, a, g, f, vx, p, **{n: v for n, v in kw.items() if n != "outside"})
    found = nonfinite_point(t, r, {"kappa": k, "alpha": a, "gamma": g, "fz": f, "vx": vx, "p": p}, kw["limits"])
    if found is not None:  # never an empty cell in the frame
        raise NonFinite(key, f"family {family}: {found[1]}", found[2])
    for name, n in r.outside.items():
        kw["outside"][name] = kw["outside"].get(name, 0) + n
    with np.errstate(divide="ignore", invalid="ignore"):
        mux = np.where(f > 0, r.fx / f, 0.0)
        muy = np.where(f > 0, r.fy / f, 0.0)
    df = pd.DataFrame({
        "family": family, "kappa": k.ravel(), "alpha": a.ravel(), "gamma": g.ravel(), "fz": f.ravel(),
        "vx": np.full(k.size, np.nan if vx is None else float(vx)),
        "p": np.full(k.size, np.nan if p is None else float(p)),
        "fx": r.fx.ravel(), "fy": r.fy.ravel(), "mz": r.mz.ravel(), "mx": r.mx.ravel(), "my": r.my.ravel(),
        "mu_x": mux.ravel(), "mu_y": muy.ravel(), "slip": slip_from_kappa(k.ravel()),
    })
    return df, r.counts


def mf_sweep_frame(t, sw: dict, convention="mfeval", side=None, limits=True, compare=None, outside=None):
    """Evaluate every family of an MF sweep (see module doc); returns ``(frame, counts)``.

    ``outside`` (a dict) receives the counts of points evaluated outside the tyre's ranges
    (:func:`tirecli.models.magic_formula.inputs.outside_ranges`). :class:`NonFinite` when an output
    is not finite (the frame never holds an empty cell)."""
    import pandas as pd

    fz0 = t.coef.get("FNOMIN", 4000.0)
    loads = sw["loads"] or [0.5 * fz0, fz0, 1.5 * fz0]
    load = sw["load"] or fz0
    vx = sw["speed"] if sw["speed"] is not None else t.reference_speed
    p = sw["pressure"] if sw["pressure"] is not None else (t.default_pressure if t.nominal_pressure else None)
    kw = {"convention": convention, "side": side, "limits": limits}
    ev = {**kw, "outside": {}}
    K = np.asarray(sw["kappa"], dtype=float)
    A = np.asarray(sw["alpha"], dtype=float)
    L = np.asarray(loads, dtype=float)[:, None]
    lkey = ("sweep", "loads") if sw["loads"] else ("sweep",)
    okey = ("sweep", "load") if sw["load"] else ("sweep",)
    parts = [
        _block(t, "fx-kappa", K[None, :], 0.0, 0.0, L, vx, p, ev, lkey),
        _block(t, "fy-alpha", 0.0, A[None, :], 0.0, L, vx, p, ev, lkey),
        _block(t, "camber", 0.0, A[None, :], np.asarray(sw["camber"], dtype=float)[:, None], load, vx, p, ev, okey),
        _block(t, "combined-alpha", K[None, :], np.asarray(sw["combined_alpha"], dtype=float)[:, None], 0.0, load, vx, p,
               ev, okey),
        _block(t, "combined-kappa", np.asarray(sw["combined_kappa"], dtype=float)[:, None], A[None, :], 0.0, load, vx, p,
               ev, okey),
    ]
    if compare is not None:
        s = np.clip(np.asarray(compare["slip"], dtype=float), -0.999, 0.999)
        parts.append(_block(t, "compare", kappa_from_slip(s), 0.0, 0.0, compare["load"] or fz0, vx, p, ev,
                            ("compare", "load") if compare["load"] else ("compare",)))
    counts: dict = {}
    for _, c in parts:
        for key, n in c.items():
            counts[key] = counts.get(key, 0) + n
    if outside is not None:
        outside.update(ev["outside"])
    return pd.concat([df for df, _ in parts], ignore_index=True), counts


def lugre_frame(lugre_set, cmp: dict) -> pd.DataFrame:
    """The LuGre steady state (distributed, uniform load) at the held speed, for the comparison."""
    from tirecli.models.variants import FrictionVariant
    from tirecli.studies.sweep_frames import sweep_frame

    p = lugre_set.model()
    df = sweep_frame([FrictionVariant(model="distributed")], p, cmp["slip"], [cmp["speed"]], [1.0])
    return df[["model", "direction", "speed", "slip", "mu"]]


def compare_gaps(df, lu) -> dict:
    """The gap of the LuGre curve to the Magic Formula curve on the ``mf-lugre-compare`` plot, per direction
    (``braking``, ``driving``): :func:`tirecli.numerics.gaps.curve_gap` of LuGre ``|mu|`` (interpolated onto
    the Magic Formula's ``|s|``) against the Magic Formula ``|Fx/Fz|`` over the drawn points ("at" is
    ``|s|`` [-]; the gaps are in units of ``|mu|`` [-])."""
    from tirecli.numerics.gaps import curve_gap

    d = df[df["family"] == "compare"]
    out = {}
    for direction, sel in (("braking", d["kappa"] <= 0), ("driving", d["kappa"] >= 0)):
        g = d[sel].assign(s=d["slip"].abs(), m=d["mu_x"].abs()).sort_values("s").drop_duplicates("s")
        lg = lu[lu["direction"] == direction]
        lg = lg.assign(s=lg["slip"].abs(), m=lg["mu"].abs()).sort_values("s").drop_duplicates("s")
        if len(g) >= 2 and len(lg) >= 2:
            out[direction] = curve_gap(g["s"].to_numpy(), lg["m"].to_numpy(), g["m"].to_numpy(),
                                       model_x=lg["s"].to_numpy()).as_dict()
    return out


def run(plan_: Plan, progress=None) -> StudyResult:
    """Run a planned Magic Formula sweep (see module doc)."""
    from tirecli.models.magic_formula.inputs import describe_counts
    from tirecli.models.magic_formula.tire import VERSION_NAMES

    config, checked, t = plan_.config, plan_.checked, plan_.detail.tire
    ps, lugre = plan_.sets["tire"], plan_.sets.get("lugre")
    sw = checked["sweep"]
    if progress is not None:
        progress.start(1, "mf sweep")
    outside: dict = {}
    try:
        df, counts = mf_sweep_frame(t, sw, checked["convention"], checked["side"], checked["limits"], checked["compare"],
                                    outside)
    except NonFinite as exc:
        key, text, at_fault = exc.args
        if at_fault:
            raise ConfigError(config.origins.problem(key, f"{text}; nothing was written")) from None
        raise RunError(f"{config.label}: {text}; nothing was written") from None
    from tirecli.models.magic_formula.inputs import describe_outside

    flags = describe_outside(outside)
    data = {"sweep": df}
    sets = {"tire": ps}
    if lugre is not None:
        data["lugre"] = lugre_frame(lugre, checked["compare"])
        sets["lugre"] = lugre
    facts = {"gap": compare_gaps(df, data["lugre"])} if lugre is not None else {}
    if progress is not None:
        progress.advance(1)
        progress.close()
    default_figs = DEFAULT_FIGURES + (["mf-lugre-compare"] if lugre is not None else [])
    return StudyResult(
        study="sweep",
        config=config,
        parameter_sets=sets,
        data=data,
        meta={
            "model": f"Magic Formula {VERSION_NAMES[t.version]}",
            "convention": checked["convention"],
            "axes": "ISO-W (docs/models/magic_formula_tyre.md §2.2): alpha > 0 gives Fy < 0; kappa > 0 driving",
            "tyre_side": t.side, "mount_side": checked["side"] or t.side,
            "limits": checked["limits"],
            "input_rules": {k: n for k, n in counts.items() if n},
            "input_rules_text": describe_counts(counts),
            "outside_ranges": outside,
            "flags": flags,
            "points": int(len(df)),
            **({"facts": facts} if facts else {}),
            "title": checked["title"] or f"Magic Formula sweep: {ps.name}",
        },
        figures=checked["figures"] or default_figs,
        payload={"tire": t, "convention": checked["convention"], "sweep": sw},
    )


__all__ = ["uses_mf_tire", "plan", "run", "mf_sweep_frame", "FAMILIES", "SPEC", "MFSweep"]
