"""Study configs: read a YAML config, apply ``--set`` overrides, resolve parameter groups.

A config is a YAML mapping; each study checks its own keys (see ``tirecli.studies``).
Overrides ``--set a.b=VALUE`` (``a.b[1].c=VALUE`` for list items) are applied to the raw
document before it is checked; ``VALUE`` is read as YAML (``170``, ``[5, 10]``, ``Z``).
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from tirecli import limits
from tirecli.config.schema import Spec, check_document
from tirecli.errors import ConfigError, Problem, UsageError, clip, token
from tirecli.io.yamlio import Origins, format_key, load_value, load_yaml_document, parse_yaml
from tirecli.parameters.sets import ParameterSet, resolve_group

OVERRIDE_FILE = "<command line --set>"
_PART = re.compile(r"([A-Za-z_][A-Za-z0-9_\-]*)|\[(\d+)\]")


@dataclass
class Config:
    """A loaded config.

    Attributes
    ----------
    data : dict
        The raw document with overrides applied.
    origins : Origins
        Key path -> (file, line) of every value.
    base_dir : Path
        Directory relative paths in the config are resolved against.
    label : str
        The file name, or the built-in config's name.
    """

    data: dict
    origins: Origins
    base_dir: Path
    label: str

    def checked(self, spec: Spec) -> dict:
        """The document checked against ``spec`` (every problem reported at once)."""
        return check_document(self.data, spec, self.origins)

    def group(self, key: str, kind: str, default_set: str | None = None) -> ParameterSet:
        """Resolve the parameter group ``key`` (e.g. ``tire``) of ``kind``."""
        raw = self.data.get(key)
        if raw is None and default_set is None:
            raise ConfigError(self.origins.problem((), f"missing required key {key!r} (a {kind} parameter set)"))
        return resolve_group(raw, self.origins, (key,), kind, self.base_dir, default_set)

    def digest(self) -> str:
        """SHA-256 of the document (overrides included), canonical JSON."""
        blob = json.dumps(self.data, sort_keys=True, default=str).encode()
        return hashlib.sha256(blob).hexdigest()


def parse_key_path(text: str) -> tuple:
    """``"sweep.models[1].lambda"`` -> ``("sweep", "models", 1, "lambda")``."""
    parts: list = []
    if len(text) > limits.MAX_KEY_PARTS * limits.MAX_KEY_CHARS or text.count(".") >= limits.MAX_KEY_PARTS:
        raise UsageError(f"--set: key too long ({len(text):,} characters, {text.count('.') + 1:,} parts; "
                         f"at most {limits.MAX_KEY_PARTS} parts of {limits.MAX_KEY_CHARS} characters)")
    for chunk in text.split("."):
        pos = 0
        if not chunk:
            raise UsageError(f"--set: empty key in {text!r}")
        while pos < len(chunk):
            m = _PART.match(chunk, pos)
            if not m:
                raise UsageError(f"--set: cannot read key {text!r} (expected a.b.c or a.b[1].c)")
            parts.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
            pos = m.end()
    return tuple(parts)


def apply_override(data: dict, origins: Origins, text: str) -> None:
    """Apply one ``KEY=VALUE`` override in place."""
    if "=" not in text:
        raise UsageError(f"--set {text!r}: expected KEY=VALUE, e.g. tire.sigma0=170")
    key, _, value_text = text.partition("=")
    path = parse_key_path(key.strip())
    try:
        value = load_value(value_text, OVERRIDE_FILE, path) if value_text.strip() else None
    except (yaml.YAMLError, ValueError, OverflowError, TypeError):  # malformed YAML, a date that does not exist
        digits = value_text.strip().lstrip("+-")
        if digits.isdigit() and len(digits) > 1000:  # an integer Python refuses to convert
            raise UsageError(f"--set {clip(key.strip())}=...: cannot read the value (a number of {len(digits)} "
                             "digits, beyond the range of a double)") from None
        raise UsageError(f"--set {token(text)}: cannot read the value {token(value_text)}") from None
    set_value(data, origins, path, value, f"--set {text!r}")


def set_value(data: dict, origins: Origins, path: tuple, value: Any, what: str,
              origin: tuple = (OVERRIDE_FILE, None)) -> None:
    """Set the value at the key path ``path`` (from :func:`parse_key_path`) in place, as ``--set``
    does: missing mappings are created, ``tire: NAME`` becomes ``tire: {set: NAME, ...}``, list items
    must exist. ``what`` starts the error messages (``--set 'KEY=VALUE'``); ``origin`` is the
    ``(file, line)`` recorded for the value."""
    key = format_key(path)
    node: Any = data
    for i, part in enumerate(path[:-1]):
        nxt = path[i + 1]
        if isinstance(part, int):
            if not isinstance(node, list) or part >= len(node):
                raise UsageError(f"{what}: no list item {part} at {key}")
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise UsageError(f"{what}: {part!r} is not inside a mapping")
        if isinstance(node.get(part), str) and not isinstance(nxt, int):
            node[part] = {"set": node[part]}  # tire: NAME -> tire: {set: NAME, ...}
        node = node.setdefault(part, [] if isinstance(nxt, int) else {})
    last = path[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or last >= len(node):
            raise UsageError(f"{what}: no list item {last} at {key}")
        node[last] = value
    else:
        if not isinstance(node, dict):
            raise UsageError(f"{what}: {key!r} is not inside a mapping")
        node[last] = value
    origins.drop(path)
    origins.set(path, *origin)


#: How a .tir file is used, for a command given one in place of a YAML file.
TIR_USE = "name it as tire: in a config, or use it with tirecli mf eval or tirecli tir show"


def load_config(path: str | Path, overrides: list[str] | tuple = ()) -> Config:
    """Read a config file and apply ``overrides``."""
    path = Path(path)
    data, origins = load_yaml_document(path, "a study config", TIR_USE)
    return _finish(data, origins, path.parent, str(path), overrides)


def config_from_text(text: str, label: str, base_dir: Path | None = None, overrides=()) -> Config:
    """A config from YAML text (built-in study configs)."""
    data, origins = parse_yaml(text, label)
    return _finish(data, origins, base_dir or Path.cwd(), label, overrides)


def config_from_mapping(data: dict, label: str = "<config>", base_dir: Path | None = None, overrides=()) -> Config:
    """A config from a mapping with the content of a YAML config (the public API's ``tirecli.run({...})``):
    a copy of it (tuples read as lists), relative paths against ``base_dir`` (default: the current
    directory); problems name ``label`` and the key (no line)."""
    def plain(obj):
        if isinstance(obj, dict):
            return {k: plain(v) for k, v in obj.items()}
        if isinstance(obj, (list, tuple)):
            return [plain(v) for v in obj]
        return obj

    return _finish(plain(data), Origins(default_file=label), base_dir or Path.cwd(), label, overrides)


def _finish(data, origins, base_dir, label, overrides) -> Config:
    if not isinstance(data, dict):
        raise ConfigError(Problem(label, 1, "", "expected a YAML mapping of keys at the top level"))
    for text in overrides:
        apply_override(data, origins, text)
    return Config(data=data, origins=origins, base_dir=Path(base_dir), label=label)
