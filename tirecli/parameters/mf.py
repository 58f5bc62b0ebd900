"""Magic Formula tyre data: from ``.tir`` files (or their YAML form) to checked, SI tyres.

:func:`tire_data` turns a :class:`~tirecli.io.tir.TirDocument` into the evaluator's flat view
(docs/models/magic_formula_tyre.md §12.5 item 3) and checks it:

- ``[UNITS]`` other than SI are converted to SI for every dimensional key of the catalogue
  (lengths, loads, stiffnesses, speeds, pressures, masses, times; §12.5 item 8). A non-radian
  ``ANGLE`` is refused for MF files, because the coefficients that multiply angles would need
  converting too (docs/models/magic_formula_tyre.md §12.5 item 8); PAC89 files are in degrees by definition.
- The version comes from ``FITTYP``, else ``PROPERTY_FILE_FORMAT``, else the keys present
  (§12.3).
- Required coefficients (§12.5 item 9: ``FNOMIN, UNLOADED_RADIUS, PCX1, PDX1, PKX1, PCY1,
  PDY1, PKY1, PKY2``) missing are errors naming them; other model coefficients take tirecli's
  defaults (``L*`` 1, ``PKY4`` 2, else 0) with one warning; ``FNOMIN``, ``UNLOADED_RADIUS`` <= 0
  and ``PKY2 = 0`` are rejected (division by zero).
- Unknown keys are kept in the document and warned about; text values where a number is
  expected, ranges with min > max, and pressure coefficients without ``NOMPRES`` are errors.

Every problem names the file and line. Built-in tyres are ``.tir`` package data listed in
:data:`BUILTIN_TIRES` with their origin and licence.

Their parameter sets, and a config's tyre group (:func:`~tirecli.parameters.sets.resolve_tire`), are made
by :mod:`tirecli.parameters.sets`.
"""
from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from tirecli.errors import ConfigError, Problem, token
from tirecli.io import tir as tirio
from tirecli.models.magic_formula.axes import normalise_side
from tirecli.models.magic_formula.tire import RANGE_KEYS, MFTire, complete_coefficients, family
from tirecli.parameters.mf_catalogue import CATALOGUE, NON_MF_SECTIONS

#: Built-in tyres (package data ``tirecli/parameters/data/NAME.tir``): origin and licence of each.
BUILTIN_TIRES = {
    "pacejka2006-205-60r15": {
        "title": "Pacejka (2006) Table A3.1 205/60R15 91V, 2.2 bar, MF 6.1 (the golden-data tyre of docs/models/magic_formula_tyre.md §15.3)",
        "citation": "H. B. Pacejka, Tyre and Vehicle Dynamics, 2nd ed., Butterworth-Heinemann, 2006, Table A3.1, "
                    "as transcribed by KMoula30/outlap (data/tires/pacejka_2006_205_60r15/car.tyr.yaml); "
                    "data CC-BY-SA-4.0",
        "licence": "CC-BY-SA-4.0 (transcription); the coefficient values are facts from the book",
    },
    "externdata-205-60r15": {
        "title": "ExternData sample.tir: MF 6.1 205/60R15 passenger tyre, 4000 N (book 3rd-ed. reference set "
                 "except PCY1, PVX1, PPY4)",
        "citation": "modelica-3rdparty/ExternData, ExternData/Resources/Examples/sample.tir, commit "
                    "0c2533d86b5cace345ff9e7c48e449366060b13a (copied byte for byte as ExternData_sample.tir)",
        "licence": "BSD-2-Clause (Copyright Thomas Beutlich)",
    },
    "mfeval-255-55r20": {
        "title": "mfeval sample MagicFormula61_Parameters.tir: MF 6.1 255/55R20, 6752 N, right tyre, with "
                 "pressure and turn-slip coefficients",
        "citation": "matheusft/MFeval_julia, test/fixtures/MagicFormula61_Parameters.tir, commit "
                    "a3b3ba49c121928e5dfbf0a351843de5a5d153d0 (the sample file of M. Furlan's mfeval)",
        "licence": "MIT (MFeval.jl contributors); mfeval itself BSD-3-Clause",
    },
    "chrono-185-80r14": {
        "title": "Project Chrono VW microbus mf_185_80R14.tir: PAC2002 (MF 5.2) 185/80 R14 van tyre, 3800 N",
        "citation": "projectchrono/chrono, data/vehicle/VW_microbus/json/mf_185_80R14.tir, commit "
                    "7689fbc02d12c5419fa6acad8791100fd89979dd",
        "licence": "BSD-3-Clause (Project Chrono)",
    },
}

_LENGTH = {"meter": 1.0, "metre": 1.0, "meters": 1.0, "m": 1.0, "mm": 1e-3, "millimeter": 1e-3,
           "millimetre": 1e-3, "cm": 1e-2, "centimeter": 1e-2, "km": 1e3, "kilometer": 1e3, "in": 0.0254,
           "inch": 0.0254, "ft": 0.3048, "foot": 0.3048, "feet": 0.3048, "mile": 1609.344}
_FORCE = {"newton": 1.0, "n": 1.0, "kn": 1e3, "kilonewton": 1e3, "kilo_newton": 1e3, "millinewton": 1e-3,
          "pound_force": 4.4482216152605, "lbf": 4.4482216152605, "kg_force": 9.80665, "kgf": 9.80665,
          "kpf": 9.80665, "ounce_force": 0.27801385095378125, "dyne": 1e-5}
_MASS = {"kg": 1.0, "kilogram": 1.0, "gram": 1e-3, "g": 1e-3, "tonne": 1e3, "metric_ton": 1e3,
         "pound_mass": 0.45359237, "lbm": 0.45359237, "kpound_mass": 453.59237, "slug": 14.593902937206364,
         "ounce_mass": 0.028349523125}
_TIME = {"second": 1.0, "sec": 1.0, "s": 1.0, "millisecond": 1e-3, "milli": 1e-3, "ms": 1e-3,
         "minute": 60.0, "min": 60.0, "hour": 3600.0, "hr": 3600.0}
_ANGLE = {"radians": 1.0, "radian": 1.0, "rad": 1.0, "deg": math.pi / 180.0, "degree": math.pi / 180.0,
          "degrees": math.pi / 180.0}
_PRESSURE = {"pascal": 1.0, "pa": 1.0, "kpa": 1e3, "kilopascal": 1e3, "mpa": 1e6, "megapascal": 1e6,
             "bar": 1e5, "psi": 6894.757293168361, "atm": 101325.0}
UNIT_TABLES = {"LENGTH": _LENGTH, "FORCE": _FORCE, "MASS": _MASS, "TIME": _TIME, "ANGLE": _ANGLE,
               "PRESSURE": _PRESSURE}
_BASE = {"L": "LENGTH", "F": "FORCE", "M": "MASS", "T": "TIME", "P": "PRESSURE", "A": "ANGLE"}

_PRESSURE_KEYS = re.compile(r"^(PP[XYZ]\d|PPMX1|PFZ1|QSY8)$")

#: ``FITTYP`` -> equation version (§12.3); any other value is an error naming these.
FITTYP_VERSIONS = {61: "6.1", 62: "6.2", 6: "5.2", 21: "5.2", 5: "5.2", 60: "6.1"}
FITTYP_ALLOWED = "61, 62 (MF 6.1/6.2), 6, 21 (MF 5.2), 5 (MF-Tyre 5.x, read as 5.2) or 60 (read as 6.1)"
#: Accepted ``TYRESIDE`` texts (any case): the side the tyre was measured on.
TYRESIDES = ("LEFT", "RIGHT", "L", "R")


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, (int, float)) and not isinstance(v, bool) else repr(v)[:40]


def unknown_fittyp(value) -> str:
    """The problem text for a ``FITTYP`` value that names no version (:data:`FITTYP_VERSIONS`)."""
    return f"unknown Magic Formula version {_fmt(value)} (expected {FITTYP_ALLOWED})"


def fittyp_version(value) -> str | None:
    """The version of a ``FITTYP`` value (None if it is not one of :data:`FITTYP_VERSIONS`)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not float(value).is_integer():
        return None
    return FITTYP_VERSIONS.get(int(value))


def used_keys(version: str) -> set:
    """The ``.tir`` keys tirecli's evaluator reads for ``version`` (its model coefficients, ranges,
    radius, turn slip, operating conditions): overriding any other key would change nothing."""
    from tirecli.models.magic_formula.tire import MODEL_KEYS, RADIUS_KEYS, TURNSLIP_DEFAULTS

    keys = set(MODEL_KEYS[version]) | {k for pair in RANGE_KEYS.values() for k in pair} | set(RADIUS_KEYS)
    keys |= {"FITTYP", "FNOMIN", "UNLOADED_RADIUS", "LONGVL", "VXLOW", "NOMPRES", "INFLPRES"}
    if version in ("6.1", "6.2"):
        keys |= set(TURNSLIP_DEFAULTS)
    return keys


@dataclass
class TireData:
    """A checked Magic Formula tyre read from a document.

    Attributes
    ----------
    values : dict
        Complete flat coefficient map in SI (what :class:`MFTire` needs).
    version : str
        ``6.1``, ``6.2``, ``5.2`` or ``pac89`` (§12.3), and ``version_source`` how it was found.
    side : str
        ``left``, ``right`` or ``unknown`` (``TYRESIDE``).
    source : dict
        Key -> ``file:line`` (or the default's reason).
    defaulted : list
        Model keys that took tirecli's default.
    units : dict
        ``[UNITS]`` as written, and ``factors``: the SI factor applied per base dimension.
    warnings : list of Problem
    """

    doc: tirio.TirDocument
    values: dict
    version: str
    version_source: str
    side: str
    source: dict = field(default_factory=dict)
    defaulted: list = field(default_factory=list)
    units: dict = field(default_factory=dict)
    factors: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    text: dict = field(default_factory=dict)

    def tire(self, name: str = "") -> MFTire:
        return MFTire(dict(self.values), self.version, self.side, name or Path(self.doc.file).stem)


def _norm_unit(text: str) -> str:
    return str(text).strip().lower().replace(" ", "_").replace("-", "_")


def _unit_factors(doc: tirio.TirDocument, problems: list) -> tuple[dict, dict]:
    units, factors = {}, {}
    sec = doc.sections.get("UNITS")
    for name, table in UNIT_TABLES.items():
        e = sec.entries.get(name) if sec is not None else None
        if e is None:
            factors[name] = 1.0
            continue
        units[name] = e.value
        u = _norm_unit(e.value)
        if u not in table:
            hint = difflib.get_close_matches(u, list(table), n=1)
            dym = f"; did you mean {hint[0]!r}?" if hint else ""
            problems.append(doc.problem(e.line, name, f"unknown unit {token(e.value)}{dym} (known: {', '.join(table)})"))
            factors[name] = 1.0
        else:
            factors[name] = table[u]
    if "PRESSURE" not in units:  # pressure in FORCE/LENGTH^2 when not given (§12.2)
        factors["PRESSURE"] = factors["FORCE"] / factors["LENGTH"] ** 2
    return units, factors


def dim_factor(dim: str, factors: dict) -> float:
    """SI factor of a catalogue dimension such as ``F/L`` or ``M*L^2`` for the file's units."""
    if dim in ("-", "str", "pac89"):
        return 1.0
    num, _, den = dim.partition("/")
    f = 1.0
    for part, sign in ((num, 1), (den, -1)):
        if not part or part == "1":
            continue
        for tok in part.split("*"):
            base, _, exp = tok.partition("^")
            f *= factors[_BASE[base]] ** (sign * (int(exp) if exp else 1))
    return f


def detect_version(doc: tirio.TirDocument, flat: dict) -> tuple[str | None, str, list]:
    """The equation family of a document (§12.3): ``(version, how, problems)``."""
    problems = []
    found = doc.find("FITTYP")
    if found:
        _, e = found[0]
        v = e.value
        version = fittyp_version(v)
        if version is not None:
            how = f"FITTYP = {int(v)}"
            if int(v) in (5, 60):
                doc.warnings.append(doc.problem(e.line, "FITTYP", f"FITTYP = {int(v)} is evaluated with the "
                                                                  f"{version} equations"))
            return version, how, problems
        problems.append(doc.problem(e.line, "FITTYP", f"unknown Magic Formula version {token(v)} (expected {FITTYP_ALLOWED})"))
        return None, "", problems
    pff = doc.find("PROPERTY_FILE_FORMAT")
    if pff:
        text = str(pff[0][1].value).strip().upper()
        if text in ("PAC2002", "MF_05", "MF05", "PAC2002_MF"):
            return "5.2", f"PROPERTY_FILE_FORMAT = '{pff[0][1].value}'", problems
        if text in ("PAC89", "PAC_89"):
            return "pac89", f"PROPERTY_FILE_FORMAT = '{pff[0][1].value}'", problems
    return version_from_keys(flat, problems, doc.file)


def version_from_keys(flat: dict, problems: list, file: str) -> tuple[str | None, str, list]:
    """Version from the keys present (§12.3): 6.x keys, 5.2 keys, or PAC89 ``A0/B0/C0``."""
    if "FITTYP" in flat:
        version = fittyp_version(flat["FITTYP"])
        if version is not None:
            return version, f"FITTYP = {int(flat['FITTYP'])}", problems
        problems.append(Problem(file, None, "FITTYP", unknown_fittyp(flat["FITTYP"])))
        return None, "", problems
    has = set(flat)
    if {"A0", "B0", "C0"} <= has and "PCX1" not in has:
        return "pac89", "PAC89 coefficients A0, B0, C0", problems
    six = sorted(has & {"PKY6", "PKY7", "PPX1", "PPY1", "QDZ10", "PEY5", "NOMPRES"})
    five = sorted(has & {"PHY3", "LGAY", "LGAX", "LGAZ", "PTX1"})
    if six:
        return "6.1", f"MF 6.x keys present ({', '.join(six[:3])})", problems
    if five:
        return "5.2", f"MF 5.2 keys present ({', '.join(five[:3])})", problems
    if "PCX1" in has or "PCY1" in has:
        return "6.1", "no FITTYP: MF 6.1 assumed", problems
    problems.append(Problem(file, None, "FITTYP", "cannot tell the Magic Formula version: add FITTYP = 61 (MF 6.1) "
                                                  "or 6 (MF 5.2) to [MODEL], or PROPERTY_FILE_FORMAT = 'PAC89'"))
    return None, "", problems


def _cut_off(doc: tirio.TirDocument, defaulted: list) -> bool:
    """Whether the coefficients a file lacks are those a cut at its end would remove: all in its
    last section or in sections that come after it in the usual order (SECTION_ORDER)."""
    from tirecli.parameters.mf_catalogue import SECTION_ORDER

    if not defaulted or not doc.sections:
        return False
    last = list(doc.sections)[-1]
    rank = {name: i for i, name in enumerate(SECTION_ORDER)}
    if last not in rank:
        return False
    return all(rank.get(CATALOGUE[k].section, -1) >= rank[last] for k in defaulted)


def tire_data(doc: tirio.TirDocument) -> TireData:
    """Check a parsed document and build the SI flat view of its Magic Formula coefficients.

    Raises
    ------
    ConfigError
        Every problem of the file at once (see the module docstring).
    """
    problems: list[Problem] = []
    units, factors = _unit_factors(doc, problems)
    flat, source, lines, text = {}, {}, {}, {}
    warnings = list(doc.warnings)
    unknown = []
    for sname, sec in doc.sections.items():
        if sname in NON_MF_SECTIONS:
            continue
        for key, e in sec.entries.items():
            info = CATALOGUE.get(key)
            if info is None:
                unknown.append((key, e.line, sname))
                continue
            if info.is_text:
                text.setdefault(key, e.value)
                continue
            if not e.is_number:
                problems.append(doc.problem(e.line, key, f"expected a number [{info.unit}], got the text {token(e.value)}"))
                continue
            if key in flat:
                warnings.append(doc.problem(e.line, key, f"also given in [{lines[key][1]}] (line {lines[key][0]}); "
                                                         f"that first value is used"))
                continue
            flat[key] = float(e.value) * dim_factor(info.dim, factors) if info.dim not in ("-", "pac89") else e.value
            lines[key] = (e.line, sname)
            source[key] = f"{doc.file}:{e.line}"
    for key, line, sname in unknown:
        warnings.append(doc.problem(line, key, f"unknown key in [{sname}], kept but not used"))
    for key in ("TYRESIDE", "PROPERTY_FILE_FORMAT"):
        for _, e in doc.find(key)[:1]:
            text.setdefault(key, e.value)
    version, how, vprob = detect_version(doc, flat)
    problems += vprob
    if version is None:
        raise ConfigError(problems)
    fam = family(version)
    ang = units.get("ANGLE")
    if ang is not None and factors["ANGLE"] != 1.0 and fam == "mf":
        e = doc.entry("UNITS", "ANGLE")
        problems.append(doc.problem(e.line, "ANGLE", f"ANGLE = {token(ang)}: MF coefficients are read in radians only; "
                                                     "the coefficients that multiply angles (PKY*, PHY*, QHZ*, RBY3, ...) "
                                                     "would need converting too (docs/models/magic_formula_tyre.md §12.5 item 8)"))
    coef, missing, defaulted = complete_coefficients(flat, version, turn_slip=False)
    if doc.ends_mid_line and missing:
        # a file cut short: one line saying so (the coefficients after the cut are all missing)
        shown = ", ".join(missing[:6]) + (f" and {len(missing) - 6} more" if len(missing) > 6 else "")
        cut = " = ".join(x for x in doc.cut_number if x) if doc.cut_number else ""
        after = f", right after {cut[:60]!r}" if cut else ""
        problems.append(doc.problem(doc.last_line, "", f"the file may be truncated: it ends in the middle of line "
                                                       f"{doc.last_line}{after} with no line break, and "
                                                       f"{len(missing)} required coefficient(s) are not in it ({shown})"))
        raise ConfigError(problems)
    named = {q.key for q in problems}
    for key in missing:
        if key in named:  # there with a value that cannot be read: that problem says so
            continue
        sect = CATALOGUE[key].section
        present = f"[{sect}] is missing" if sect not in doc.sections else f"not in [{sect}]"
        problems.append(Problem(doc.file, None, key, f"missing required coefficient ({CATALOGUE[key].meaning}; "
                                                     f"{present})"))
    if doc.ends_mid_line and not missing and _cut_off(doc, defaulted):
        # a file cut in the middle of a line (no final line break) that also lacks the coefficients
        # of its last section or of the sections after it is a truncated file, not a tyre to
        # evaluate with zeros (issue 6: truncated -> error)
        shown = ", ".join(defaulted[:6]) + (f" and {len(defaulted) - 6} more" if len(defaulted) > 6 else "")
        problems.append(doc.problem(doc.last_line, "", f"the file may be truncated: it ends in the middle of line "
                                                       f"{doc.last_line} and {len(defaulted)} model coefficient(s) "
                                                       f"are not in it ({shown}); if the file is complete, end "
                                                       f"it with a line break"))
    elif doc.cut_number is not None and not missing:
        # every coefficient is there, but the last line ends in a number with no line break or
        # comment after it: a file cut in the middle of that number ("QSY8 = -0." of "-0.4")
        # would silently evaluate with the shortened value
        key, number = doc.cut_number
        what = (f"{key} = {number}" if key and number else key) if key else f"the table row ending in {number}"
        problems.append(doc.problem(doc.last_line, "", f"the file may be truncated: it ends in the middle of line "
                                                       f"{doc.last_line}, right after {what[:60]!r} with no line break "
                                                       "(a file cut inside a line ends so); if the file is "
                                                       "complete, end it with a line break"))
    _value_checks(doc, coef, fam, version, lines, problems, warnings)
    if problems:
        raise ConfigError(problems)
    for k in defaulted:
        source[k] = f"default {coef[k]:g} (not in the file; docs/models/magic_formula_tyre.md §12.5 item 9)"
    if defaulted:
        shown = ", ".join(defaulted[:12]) + (f" and {len(defaulted) - 12} more" if len(defaulted) > 12 else "")
        warnings.append(Problem(doc.file, None, "", f"{len(defaulted)} model coefficient(s) not in the file take "
                                                    f"tirecli's default (L* = 1, PKY4 = 2, else 0; "
                                                    f"docs/models/magic_formula_tyre.md §12.5 item 9): {shown}"))
    side = normalise_side(text.get("TYRESIDE"))
    return TireData(doc=doc, values=coef, version=version, version_source=how, side=side, source=source,
                    defaulted=defaulted, units=units, factors=factors, warnings=warnings, text=text)


def _value_checks(doc, coef, fam, version, lines, problems, warnings):
    def where(key):
        return lines.get(key, (None, ""))[0]

    problems += [doc.problem(where(keys[0]), keys[0], msg) for keys, msg in coefficient_problems(coef, fam)]
    if fam == "mf":
        if "LONGVL" not in coef:
            speed_terms = [k for k in ("QSY3", "QSY4") if coef.get(k)]
            if speed_terms:  # My needs V0 (rolling resistance grows with vx / LONGVL)
                gone = "; [MODEL] is missing" if "MODEL" not in doc.sections else ""
                problems.append(Problem(doc.file, None, "LONGVL", f"missing, but {'/'.join(speed_terms)} (rolling "
                                                                  f"resistance with speed) need the reference speed{gone}"))
            else:
                warnings.append(Problem(doc.file, None, "LONGVL", "no reference speed LONGVL: give vx with every evaluation"))
        if version != "5.2" and "NOMPRES" not in coef:
            used = sorted(k for k, v in coef.items() if _PRESSURE_KEYS.match(k) and v)
            if used:
                problems.append(Problem(doc.file, None, "NOMPRES", f"missing, but pressure coefficients are given "
                                                                   f"({', '.join(used[:4])}): dp_i needs it (§3)"))
            else:
                warnings.append(Problem(doc.file, None, "NOMPRES", "no NOMPRES: inflation pressure has no effect"))
        if "VXLOW" not in coef:
            warnings.append(Problem(doc.file, None, "VXLOW", "no VXLOW: no low-speed handling (§11)"))
    side = doc.find("TYRESIDE")
    if side:
        _, e = side[0]
        if str(e.value).strip().upper() not in TYRESIDES:
            problems.append(doc.problem(e.line, "TYRESIDE", f"unknown side {str(e.value)[:40]!r} (expected 'LEFT' or "
                                                            "'RIGHT', the side the tyre was measured on; leave the key "
                                                            "out when it is not known)"))
    if fam == "mf":
        for key in ("WIDTH", "ASPECT_RATIO", "RIM_RADIUS", "RIM_WIDTH"):
            found = doc.find(key)
            if found and found[0][1].is_number and not found[0][1].value > 0:
                warnings.append(doc.problem(found[0][1].line, key, f"must be > 0, got {found[0][1].value:g} "
                                                                   "(a tyre dimension; not used by the evaluator)"))


def coefficient_problems(coef: dict, fam: str) -> list[tuple[tuple, str]]:
    """``(keys, what is wrong)`` for every coefficient value the evaluator cannot use: loads, radius,
    speeds and pressures that must be positive, divisors that must not be 0, ranges whose minimum is
    above their maximum (``keys``: the key at fault first, then the other one involved). The same
    rules hold for a ``.tir`` file, inline coefficients and overrides."""
    out = []
    if fam == "mf":
        for key in ("FNOMIN", "UNLOADED_RADIUS", "LONGVL", "NOMPRES", "INFLPRES", "FZMAX", "PRESMIN", "PRESMAX",
                    "VERTICAL_STIFFNESS"):
            if key in coef and not coef[key] > 0:
                out.append(((key,), f"must be > 0, got {coef[key]:g}"))
        for key in ("FZMIN", "VXLOW"):
            if key in coef and not coef[key] >= 0:
                out.append(((key,), f"must be >= 0, got {coef[key]:g}"))
        if coef.get("PKY2") == 0:
            out.append((("PKY2",), "must not be 0 (K_ya divides by it; §12.5 item 9)"))
        if coef.get("LFZO") == 0:
            out.append((("LFZO",), "must not be 0 (F'z0 = LFZO FNOMIN divides)"))
    elif coef.get("A4") == 0:
        out.append((("A4",), "must not be 0 (BCD of Fy divides by it; §13.2)"))
    bad = {k for keys, _ in out for k in keys}
    for lo, hi in RANGE_KEYS.values():
        if lo in coef and hi in coef and coef[lo] > coef[hi] and not {lo, hi} & bad:
            out.append(((lo, hi), f"range minimum {lo} = {coef[lo]:g} is above its maximum {hi} = {coef[hi]:g}"))
    return out


def read_tire_data(path: str | Path) -> TireData:
    """A ``.tir`` file (or its YAML form) read and checked (see :func:`tire_data`)."""
    return tire_data(tirio.read_any(path))


# --------------------------------------------------------------------------- built-in tyres


def builtin_tire_names() -> list[str]:
    """Names of the built-in tyres (``tirecli/parameters/data/*.tir``)."""
    root = resources.files("tirecli.parameters").joinpath("data")
    return sorted(p.name[:-4] for p in root.iterdir() if p.name.endswith(".tir"))


def builtin_tire_resource(name: str):
    """Package resource ``tirecli/parameters/data/NAME.tir`` of a built-in tyre."""
    return resources.files("tirecli.parameters").joinpath("data").joinpath(name + ".tir")


def load_builtin_tire_data(name: str) -> TireData:
    """A built-in tyre by name (package data)."""
    res = builtin_tire_resource(name)
    return tire_data(tirio.parse_tir(res.read_bytes(), f"<built-in {name}>"))


def read_document(ref: str, base_dir: Path | None = None) -> tuple[tirio.TirDocument, str]:
    """A ``.tir`` file, its YAML form, or a built-in tyre by name: ``(document, label)``; a relative
    path is read against ``base_dir`` when given (a config's folder). UsageError (one line, with a
    did-you-mean) for a name that is neither."""
    from tirecli.errors import UsageError
    from tirecli.io.files import exists

    path = ref if base_dir is None or Path(ref).is_absolute() else str(Path(base_dir) / ref)
    if ref in builtin_tire_names() and not exists(path):
        res = builtin_tire_resource(ref)
        return tirio.parse_tir(res.read_bytes(), f"<built-in {ref}>"), ref
    if not exists(path) and "/" not in ref and not ref.lower().endswith((".tir", ".yaml", ".yml")):
        root = resources.files("tirecli.parameters").joinpath("data")
        if root.joinpath(ref + ".yaml").is_file():  # a built-in LuGre or vehicle set
            raise UsageError(f"{ref}: a LuGre or vehicle parameter set, not a Magic Formula tyre "
                             f"(see 'tirecli params show {ref}')")

        names = builtin_tire_names()
        hint = difflib.get_close_matches(ref, names, n=1)
        dym = f"; did you mean {hint[0]!r}?" if hint else ""
        raise UsageError(f"{token(ref)}: no such file and no built-in tyre of that name{dym} (built-in: {', '.join(names)})")
    return tirio.read_any(path), ref


# --------------------------------------------------------------------------- tyres from coefficients


def tire_from_values(**values) -> MFTire:
    """An :class:`MFTire` from flat coefficients (version from ``FITTYP`` or the keys; side unknown)."""
    version, _, problems = version_from_keys(values, [], "<values>")
    if version is None:
        raise ConfigError(problems)
    coef, missing, _ = complete_coefficients(values, version)
    if missing:
        raise ConfigError([Problem("<values>", None, k, "missing required coefficient") for k in missing])
    return MFTire(coef, version)


def tire_from_set(ps) -> MFTire:
    """The :class:`MFTire` of a resolved ``magic_formula`` parameter set."""
    ex = ps.extra or {}
    version = ex.get("version")
    if version is None:
        return tire_from_values(**ps.values)
    coef, _, _ = complete_coefficients(ps.values, version, turn_slip=False)
    return MFTire(coef, version, ex.get("side", "unknown"), ps.name)
