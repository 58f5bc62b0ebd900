"""Parameter sets: built-in (YAML package data, each with its citation), from files, inline.

A parameter-set file::

    name: canudas2003-table1
    kind: lugre
    title: FM Table 1 = OBS Fig. 1 tire
    citation: C. Canudas-de-Wit et al. ... Table 1.
    values:
      sigma0: 181.54
      sigma1: {value: 1.0, assumed: "missing in FM Table 1; OBS Fig. 1 gives 1.0 s/m"}

A value is a number, or a mapping with ``value`` and either ``assumed`` (why the value is a
documented default rather than the paper's) or ``note``. In a config, a parameter group names
a set and may override values::

    tire: {set: canudas2003-table1, sigma0: 170}

``set`` is a built-in name or a path to a set file (relative to the config). An override
replaces the value and clears its *assumed* flag.

Magic Formula tyres (built-in ``.tir`` files, ``.tir`` paths, their YAML form) are sets of kind
``magic_formula`` made from the tyre data of :mod:`tirecli.parameters.mf` (:func:`tire_set`); a
config's tyre group is resolved by :func:`resolve_tire`.
"""
from __future__ import annotations

import copy
import dataclasses
import difflib
import functools
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from tirecli.config.schema import MISSING, Context, Map, Num, Str, check_document
from tirecli.errors import ConfigError, Problem, token
from tirecli.io.yamlio import Origins, load_yaml, parse_yaml, require_kind
from tirecli.limits import MAX_TITLE_CHARS
from tirecli.parameters.kinds import KINDS, Kind

_DATA = "data"


@dataclass
class ParameterSet:
    """A resolved, checked parameter set.

    Attributes
    ----------
    name : str
        Set name (built-in name, file stem, or ``inline``).
    kind : str
        Kind of set (see :mod:`tirecli.parameters.kinds`).
    values : dict
        Parameter -> value (SI units).
    source : dict
        Parameter -> where the value came from (set name, config file, ``--set``).
    assumed : dict
        Parameter -> why it is an assumed default (only values still assumed).
    notes : dict
        Parameter -> remark from the set file.
    title, citation : str
        What the set is and where its values were published.
    overridden : tuple
        Parameters whose value a config or ``--set`` changed from the named set's.
    """

    name: str
    kind: str
    values: dict
    source: dict = field(default_factory=dict)
    assumed: dict = field(default_factory=dict)
    notes: dict = field(default_factory=dict)
    title: str = ""
    citation: str = ""
    extra: dict = field(default_factory=dict)
    overridden: tuple = ()

    @property
    def label(self) -> str:
        """The set's name, with the overridden parameters: ``canudas2003-table1 (sigma0 changed)``."""
        return f"{self.name} ({', '.join(self.overridden)} changed)" if self.overridden else self.name

    @property
    def kind_def(self) -> Kind:
        return KINDS[self.kind]

    def model(self):
        """The model's parameter object (e.g. ``LuGreParams``)."""
        return self.kind_def.build(dict(self.values))

    def rows(self) -> list[dict]:
        """One row per parameter: name, value, unit, meaning, equation, source, assumed."""
        out = []
        for key, spec in self.kind_def.fields.items():
            if key not in self.values:
                continue
            out.append({
                "name": key,
                "value": self.values[key],
                "unit": spec.unit,
                "meaning": spec.doc,
                "equation": spec.eq,
                "source": self.source.get(key, ""),
                "assumed": self.assumed.get(key, ""),
                "note": self.notes.get(key, ""),
            })
        return out

    def record(self) -> dict:
        """JSON-ready description for ``run.json``: values with units, assumed ones flagged."""
        return {
            "name": self.name,
            "kind": self.kind,
            "title": self.title,
            "citation": self.citation,
            "parameters": {
                r["name"]: {k: r[k] for k in ("value", "unit", "source")}
                | ({"assumed": r["assumed"]} if r["assumed"] else {})
                for r in self.rows()
            },
        } | ({"details": self.extra} if self.extra else {})


_VALUE_META = Map(fields={
    "value": Num(unit="", doc="the value"),
    "assumed": Str(default=None, doc="why this is an assumed default"),
    "note": Str(default=None, doc="remark"),
})

_SET_FILE = Map(fields={
    "name": Str(doc="set name", max_len=MAX_TITLE_CHARS),
    "kind": Str(doc="kind of set"),
    "title": Str(default="", doc="what the set describes", max_len=MAX_TITLE_CHARS),
    "citation": Str(doc="where the values were published"),
    "values": Map(open_keys=None, doc="parameter values"),  # checked per kind below
    "notes": Str(default="", doc="free remarks"),
})


def builtin_names() -> list[str]:
    """Names of the built-in parameter sets (package data: YAML sets and ``.tir`` tyres)."""
    return list(_builtin_names())


@functools.lru_cache(maxsize=1)
def _builtin_names() -> tuple:
    root = resources.files(__package__).joinpath(_DATA)
    return tuple(sorted(p.name.rsplit(".", 1)[0] for p in root.iterdir() if p.name.endswith((".yaml", ".tir"))))


def builtin_path(name: str):
    """Package resource of a built-in set; ``ConfigError`` with a did-you-mean if unknown."""
    names = builtin_names()
    if name not in names:
        hint = difflib.get_close_matches(name, names, n=1)
        dym = f"; did you mean {hint[0]!r}?" if hint else ""
        raise ConfigError(Problem("<built-in sets>", None, "", f"no built-in parameter set {token(name)}{dym} "
                                  f"(available: {', '.join(names)})"))
    root = resources.files(__package__).joinpath(_DATA)
    yaml_res = root.joinpath(name + ".yaml")
    return yaml_res if yaml_res.is_file() else root.joinpath(name + ".tir")


def _unwrap_values(raw: dict, origins: Origins, path: tuple) -> tuple[dict, dict, dict]:
    """Split ``{value, assumed, note}`` entries into values, assumed reasons and notes."""
    values, assumed, notes = {}, {}, {}
    ctx = Context(origins)
    for key, v in raw.items():
        if isinstance(v, dict):
            meta = _VALUE_META.check(v, path + (key,), ctx)
            if meta is MISSING or meta["value"] is MISSING:
                continue
            values[key] = meta["value"]
            if meta["assumed"]:
                assumed[key] = meta["assumed"]
            if meta["note"]:
                notes[key] = meta["note"]
        else:
            values[key] = v
    ctx.raise_if_any()
    return values, assumed, notes


def _check_values(kind: Kind, values: dict, origins: Origins, path: tuple, partial: bool = False) -> dict:
    checked = check_document(values, kind.spec(partial=partial), origins, path)
    return {k: v for k, v in checked.items() if v is not None}


def parse_set(data: Any, origins: Origins, label: str) -> ParameterSet:
    """Check a parameter-set document (already parsed) and build the :class:`ParameterSet`."""
    if not isinstance(data, dict):
        raise ConfigError(origins.problem((), "expected a parameter set (a mapping with name, kind, citation, values)"))
    require_kind(data, origins, "a parameter set", _SET_FILE.fields, "name, kind, citation or values")
    head = {k: v for k, v in data.items() if k != "values"}
    head["values"] = {}
    meta = check_document(head, _SET_FILE, origins)
    kind = KINDS.get(meta["kind"])
    if kind is None:
        hint = difflib.get_close_matches(meta["kind"], list(KINDS), n=1)
        dym = f"; did you mean {hint[0]!r}?" if hint else ""
        raise ConfigError(origins.problem(("kind",), f"unknown kind {token(meta['kind'])}{dym} (expected one of: {', '.join(KINDS)})"))
    raw = data.get("values")
    if not isinstance(raw, dict):
        raise ConfigError(origins.problem(("values",), "expected a mapping of parameter values"))
    values, assumed, notes = _unwrap_values(raw, origins, ("values",))
    values = _check_values(kind, values, origins, ("values",))
    for key, spec in kind.fields.items():
        if key not in raw and not spec.required and spec.default is not None:
            assumed.setdefault(key, f"not in the set; tirecli default {spec.default:g} {spec.unit}")
    return ParameterSet(
        name=meta["name"], kind=kind.name, values=values,
        source={k: label for k in values}, assumed=assumed, notes=notes,
        title=meta["title"], citation=meta["citation"],
    )


#: Names of the built-in sets this process loaded (:func:`load_builtin`): ``tirecli report`` clears it
#: before a study and keys the study's cached outputs on the files of the sets it read.
BUILTINS_READ: set[str] = set()


def load_builtin(name: str) -> ParameterSet:
    """A built-in parameter set by name (a fresh copy: the caller may change it)."""
    ps = _parsed_builtin(name)
    BUILTINS_READ.add(name)
    return dataclasses.replace(ps, values=dict(ps.values), source=dict(ps.source), assumed=dict(ps.assumed),
                               notes=dict(ps.notes), extra=copy.deepcopy(ps.extra))


@functools.lru_cache(maxsize=None)
def _parsed_builtin(name: str) -> ParameterSet:
    """A built-in set, read and checked once per process (the files are package data: they do not
    change while it runs; a campaign resolves them for every point)."""
    res = builtin_path(name)
    if res.name.endswith(".tir"):
        return builtin_tire_set(name)
    data, origins = parse_yaml(res.read_text(encoding="utf-8"), file=f"<built-in {name}>")
    return parse_set(data, origins, label=name)


def load_set_file(path: str | Path) -> ParameterSet:
    """A parameter set from a YAML file, or a Magic Formula tyre (``.tir`` or its YAML form)."""
    from tirecli.io.tir import from_yaml_data, is_yaml_form

    if str(path).lower().endswith(".tir"):
        return tire_set_from_file(path)
    data, origins = load_yaml(path)
    if is_yaml_form(data):
        from tirecli.parameters.mf import tire_data

        return tire_set(tire_data(from_yaml_data(data, origins, str(path))), name=Path(path).stem)
    return parse_set(data, origins, label=str(path))


def load_set(ref: str, base_dir: Path | None = None) -> ParameterSet:
    """A set by built-in name or by file path (relative to ``base_dir``)."""
    if ref in builtin_names():
        return load_builtin(ref)
    from tirecli.io.files import exists

    p = Path(ref)
    if not p.is_absolute() and base_dir is not None:
        p = base_dir / p
    looks_like_path = ref.lower().endswith((".yaml", ".yml", ".tir")) or "/" in ref or "\\" in ref
    if looks_like_path or (ref.strip() and exists(p)):
        return load_set_file(p)
    builtin_path(ref)  # raises with a did-you-mean
    raise AssertionError("unreachable")


def resolve_group(raw: Any, origins: Origins, path: tuple, kind: str, base_dir: Path | None,
                  default_set: str | None = None) -> ParameterSet:
    """Resolve a parameter group of a config (``tire:``, ``vehicle:`` ...) into a checked set.

    ``raw`` is a set name/path, or a mapping with an optional ``set`` key and parameter values
    (overrides on top of the set, or a complete inline set). Problems name the config's file,
    key path and line.
    """
    kdef = KINDS[kind]
    if raw is None and default_set is not None:
        raw = {"set": default_set}
    if isinstance(raw, str):
        raw = {"set": raw}
    if not isinstance(raw, dict):
        raise ConfigError(origins.problem(path, f"expected a parameter-set name or a mapping of {kind} parameters"))
    # Gather every problem of the group (unknown keys, bad values, mu_c <= mu_s across set and
    # overrides) before raising, so one run reports them all.
    problems: list = []
    over = {}
    for key, v in raw.items():
        if key == "set":
            continue
        if key in kdef.fields:
            over[key] = v
            continue
        hint = difflib.get_close_matches(key, list(kdef.fields), n=1, cutoff=0.6)
        dym = f"; did you mean {hint[0]!r}?" if hint else ""
        names = list(kdef.fields)
        listing = ", ".join(names) if len(names) <= 24 else f"a {kind} parameter name ({len(names)} known)"
        problems.append(origins.problem(path + (key,), f"unknown key{dym} (expected 'set' or {'one of: ' if len(names) <= 24 else ''}{listing})"))
    if "set" in raw:
        if not isinstance(raw["set"], str):
            raise ConfigError(problems + [origins.problem(path + ("set",), "expected a built-in set name or a file path")])
        try:
            base = load_set(raw["set"], base_dir)
        except ConfigError as err:
            raise ConfigError(problems + [Problem(*origins.of(path + ("set",)), _key(path + ("set",)), p.message)
                                          if p.file == "<built-in sets>" else p for p in err.problems]) from None
        if base.kind != kind:
            raise ConfigError(problems + [origins.problem(path + ("set",), f"set {token(raw['set'])} is of kind {base.kind!r}, expected {kind!r}")])
        try:
            over_vals, _, _ = _unwrap_values(over, origins, path)
        except ConfigError as err:
            raise ConfigError(problems + err.problems) from None
        ctx = Context(origins)
        checked = kdef.spec(partial=True).check(over_vals, path, ctx)
        problems += ctx.problems
        failed = {k for k, v in checked.items() if v is MISSING}
        over_vals = {k: v for k, v in checked.items() if v is not None and v is not MISSING}
        values = {**base.values, **over_vals}
        # cross-field rules on the merged set (e.g. mu_c <= mu_s across set and override); a
        # faulty override stays MISSING rather than falling back to the set's value
        merged = Origins(default_file=origins.default_file)
        merged.where.update({(k,): origins.of(path + (k,)) for k in over_vals})
        for k in base.values:
            if k not in over_vals:
                merged.set((k,), f"<set {base.name}>", None)
        if kdef.post is not None and (kdef.post_partial or not problems):
            mctx = Context(_prefixed(merged, origins, path))
            kdef.post({**values, **{k: MISSING for k in failed}}, path, mctx)
            problems += mctx.problems
        if problems:
            raise ConfigError(problems)
        source = {**base.source, **{k: _where(origins, path + (k,)) for k in over_vals}}
        assumed = {k: v for k, v in base.assumed.items() if k not in over_vals}
        return ParameterSet(name=base.name, kind=kind, values=values, source=source, assumed=assumed,
                            notes=base.notes, title=base.title, citation=base.citation, extra=dict(base.extra),
                            overridden=tuple(k for k in over_vals if over_vals[k] != base.values.get(k)))
    try:
        vals, assumed, notes = _unwrap_values(over, origins, path)
        vals = _check_values(kdef, vals, origins, path)
    except ConfigError as err:
        raise ConfigError(problems + err.problems) from None
    if problems:
        raise ConfigError(problems)
    for key, spec in kdef.fields.items():
        if key not in over and not spec.required and spec.default is not None:
            assumed.setdefault(key, f"not given; tirecli default {spec.default:g} {spec.unit}")
    return ParameterSet(name="inline", kind=kind, values=vals,
                        source={k: _where(origins, path + (k,)) for k in vals},
                        assumed=assumed, notes=notes, title="inline parameters", citation="given in the config")


def _key(path: tuple) -> str:
    from tirecli.io.yamlio import format_key

    return format_key(path)


def _where(origins: Origins, path: tuple) -> str:
    file, line = origins.of(path)
    return file if line is None else f"{file}:{line}"


def _prefixed(merged: Origins, origins: Origins, path: tuple) -> Origins:
    out = Origins(default_file=origins.default_file)
    out.where[tuple(path)] = origins.of(path)
    for p, v in merged.where.items():
        out.where[tuple(path) + tuple(p)] = v
    return out


# --------------------------------------------------------------------------- Magic Formula tyres


def tire_set(td, name: str, title: str = "", citation: str = "") -> ParameterSet:
    """The :class:`ParameterSet` of kind ``magic_formula`` of checked tyre data
    (:class:`~tirecli.parameters.mf.TireData`).

    Values are the complete SI coefficients; defaulted model coefficients are flagged as
    *assumed*; ``extra`` records the version, side, units, file and the reader's warnings.
    """
    assumed = {k: f"not in the file; tirecli's default {td.values[k]:g} (docs/models/magic_formula_tyre.md §12.5 item 9)"
               for k in td.defaulted}
    extra = {
        "version": td.version, "version_source": td.version_source, "side": td.side,
        "file": td.doc.file, "units": dict(td.units),
        "property_file_format": td.text.get("PROPERTY_FILE_FORMAT", ""),
        "warnings": [str(w) for w in td.warnings],
    }
    return ParameterSet(name=name, kind="magic_formula", values=dict(td.values), source=dict(td.source),
                        assumed=assumed, title=title or f"Magic Formula tyre {name} ({td.version})",
                        citation=citation or f"read from {td.doc.file}", extra=extra)


def builtin_tire_set(name: str) -> ParameterSet:
    """The parameter set of a built-in tyre, with its title and citation
    (:data:`~tirecli.parameters.mf.BUILTIN_TIRES`)."""
    from tirecli.parameters.mf import BUILTIN_TIRES, load_builtin_tire_data

    meta = BUILTIN_TIRES.get(name, {})
    return tire_set(load_builtin_tire_data(name), name, meta.get("title", ""), meta.get("citation", ""))


def tire_set_from_file(path: str | Path) -> ParameterSet:
    """The parameter set of a ``.tir`` file (or its YAML form)."""
    from tirecli.parameters.mf import read_tire_data

    return tire_set(read_tire_data(path), Path(path).stem)


def resolve_tire(raw, origins, path: tuple, base_dir: Path | None):
    """Resolve a config's tyre group: a built-in tyre, a ``.tir`` path (relative to the config),
    its YAML form, or inline coefficients, with overrides -- exactly like the LuGre parameter
    groups (:func:`resolve_group`).

    Returns ``(ParameterSet, MFTire)``; ConfigError names the config's file, key and line.
    """
    from tirecli.models.magic_formula.tire import complete_coefficients, family
    from tirecli.parameters.mf import (coefficient_problems, fittyp_version, tire_from_set, unknown_fittyp, used_keys,
                                       version_from_keys)
    from tirecli.parameters.mf_catalogue import CATALOGUE

    ps = resolve_group(raw, origins, path, "magic_formula", base_dir)
    version = (ps.extra or {}).get("version")
    problems = []
    if version is None:  # inline coefficients
        version, how, vp = version_from_keys(ps.values, [], origins.of(path)[0])
        if version is None:
            raise ConfigError([origins.problem(path, p.message) for p in vp])
        coef, missing, defaulted = complete_coefficients(ps.values, version, turn_slip=False)
        problems += [origins.problem(path, f"missing required coefficient {k!r} ({CATALOGUE[k].meaning})")
                     for k in missing]
        ps.assumed = {k: f"not given; tirecli's default {coef[k]:g} (docs/models/magic_formula_tyre.md §12.5 item 9)"
                      for k in defaulted}
        ps.values = coef
        ps.extra = {"version": version, "version_source": how, "side": "unknown", "file": "inline"}
    over = [k for k in raw if k != "set"] if isinstance(raw, dict) and "set" in raw else []
    if "FITTYP" in over:  # a changed FITTYP changes the equations (or is refused), never ignored
        new = fittyp_version(ps.values.get("FITTYP"))
        if new is None:
            raise ConfigError(origins.problem(path + ("FITTYP",), unknown_fittyp(ps.values.get("FITTYP"))))
        if new != version:
            if family(version) != family(new):
                raise ConfigError(origins.problem(path + ("FITTYP",), f"the tyre {ps.name} is a {version} tyre: "
                                                                      "its coefficients cannot be read as MF "
                                                                      f"{new} (FITTYP {int(ps.values['FITTYP'])})"))
            coef, missing, defaulted = complete_coefficients(ps.values, new, turn_slip=False)
            if missing:
                raise ConfigError(origins.problem(path + ("FITTYP",), f"MF {new} needs {', '.join(missing)}, "
                                                                      f"which the tyre {ps.name} does not give"))
            ps.values = coef
            ps.extra = {**(ps.extra or {}), "version": new,
                        "version_source": f"FITTYP = {int(ps.values['FITTYP'])} (override; the file says {version})"}
            version = new
    inert = [k for k in over if k in CATALOGUE and k not in used_keys(version)]
    for k in inert:
        problems.append(origins.problem(path + (k,), f"not read by tirecli's {version} Magic Formula evaluator "
                                                     "(a tyre file key tirecli keeps but does not use): overriding "
                                                     "it would change nothing"))
    # the rules of a .tir file hold for inline coefficients and overrides too (never accepted silently)
    given = {str(k).upper(): k for k in raw} if isinstance(raw, dict) else {}
    for keys, msg in coefficient_problems(ps.values, family(version)):
        key = next((k for k in keys if k in given), None)
        problems.append(origins.problem(path + (given[key],), msg) if key is not None else
                        origins.problem(path, f"{keys[0]}: {msg}"))
    if problems:
        raise ConfigError(problems)
    return ps, tire_from_set(ps)
