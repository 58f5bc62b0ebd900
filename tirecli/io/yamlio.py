"""Safe YAML reading and writing with the line of every value (the only YAML file access).

:func:`load_yaml` returns the plain Python data and an :class:`Origins` map from key paths
to ``(file, line)``, so validation errors can name the file, key and line.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from tirecli import limits
from tirecli.errors import ConfigError, Problem, clip, token

KeyPath = tuple  # tuple of str (mapping keys) and int (sequence indices)


def format_key(path: KeyPath) -> str:
    """Dotted form of a key path: ``("sweep", "models", 1, "lambda") -> sweep.models[1].lambda``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


@dataclass
class Origins:
    """Where each value came from: key path -> (file, 1-based line or None)."""

    default_file: str = "<input>"
    where: dict = field(default_factory=dict)

    def of(self, path: KeyPath) -> tuple[str, int | None]:
        """File and line of ``path``, falling back to its nearest known parent."""
        path = tuple(path)
        while True:
            if path in self.where:
                return self.where[path]
            if not path:
                return self.default_file, None
            path = path[:-1]

    def problem(self, path: KeyPath, message: str) -> Problem:
        file, line = self.of(path)
        return Problem(file, line, format_key(path), message)

    def set(self, path: KeyPath, file: str, line: int | None) -> None:
        self.where[tuple(path)] = (file, line)

    def rebase(self, prefix: KeyPath, other: "Origins") -> None:
        """Copy ``other``'s entries under ``prefix`` (for values merged from another file)."""
        for p, v in other.where.items():
            self.where[tuple(prefix) + tuple(p)] = v

    def drop(self, prefix: KeyPath) -> None:
        """Forget every entry at or below ``prefix``."""
        n = len(prefix)
        for p in [p for p in self.where if tuple(p[:n]) == tuple(prefix)]:
            del self.where[p]


class TooBig(Exception):
    """A YAML document over a limit of :mod:`tirecli.limits` (found while composing, at ``line``)."""

    def __init__(self, message: str, line: int | None):
        super().__init__(message)
        self.line = line


def _too_many(line):
    return TooBig(f"more than {limits.MAX_YAML_NODES:,} values (at most {limits.MAX_YAML_NODES:,} per document, "
                  "aliases counted where they are used)", line)


def _too_deep(line):
    return TooBig(f"nested more than {limits.MAX_YAML_DEPTH} levels deep", line)


class Loader(yaml.SafeLoader):
    """PyYAML's safe loader, with YAML 1.2 floats: ``1e5``, ``2E-3`` and ``5.`` are numbers.

    PyYAML follows YAML 1.1, where an exponent needs a dot (``1.0e5``) and ``1e5`` is the text
    "1e5": a config saying ``gamma: 2e5`` would then be refused as "expected a number".

    Composing counts the nodes and the nesting (:data:`tirecli.limits.MAX_YAML_NODES`,
    :data:`~tirecli.limits.MAX_YAML_DEPTH`), so no document can exhaust the memory or the stack.
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._nodes = 0
        self._depth = 0

    def compose_node(self, parent, index):
        self._nodes += 1
        self._depth += 1
        try:
            if self._nodes > limits.MAX_YAML_NODES:
                raise _too_many(self.peek_event().start_mark.line + 1)
            if self._depth > limits.MAX_YAML_DEPTH:
                raise _too_deep(self.peek_event().start_mark.line + 1)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


#: libyaml's loader (C) when PyYAML has it: a 1 MB document is composed in a fraction of a second, where the
#: pure-Python loader needs seconds. Node counts and nesting are checked on the parser's events first.
_CLoader = type("_CLoader", (yaml.CSafeLoader,), {}) if getattr(yaml, "CSafeLoader", None) else None


class Dumper(yaml.SafeDumper):
    """PyYAML's safe dumper that quotes text :class:`Loader` would read as a number (``'1e5'``)."""


_FLOAT_12 = re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?(?:[eE][-+]?[0-9]+)
                  |[-+]?(?:[0-9][0-9_]*)\.[0-9_]*
                  |[-+]?\.[0-9][0-9_]*(?:[eE][-+]?[0-9]+)?
                  |[-+]?\.(?:inf|Inf|INF)
                  |\.(?:nan|NaN|NAN))$""", re.X)
for _cls in (Loader, Dumper):
    _cls.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12, list("-+0123456789."))

# Numbers the reader takes: decimal integers without a leading zero, 0x/0o/0b integers, and the
# floats above. YAML 1.1's other forms silently gave other values than the one written: ``010``
# (octal 8) and ``1:30`` (sexagesimal 90) stay text here, so a number key refuses them by name.
_INT_12 = re.compile(r"^(?:[-+]?(?:0|[1-9][0-9_]*)|0x[0-9a-fA-F_]+|0o[0-7_]+|0b[01_]+)$")
Loader.yaml_implicit_resolvers = {
    ch: [(tag, rx) for tag, rx in resolvers if tag not in ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float")]
    for ch, resolvers in Loader.yaml_implicit_resolvers.items()}
Loader.add_implicit_resolver("tag:yaml.org,2002:int", _INT_12, list("-+0123456789"))
Loader.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12, list("-+0123456789."))
if _CLoader is not None:  # the same tags as Loader's (libyaml only scans and composes)
    _CLoader.yaml_implicit_resolvers = Loader.yaml_implicit_resolvers


def load_value(text: str, file: str = "<command line --set>", path: KeyPath = ()) -> Any:
    """One YAML value (e.g. the VALUE of ``--set KEY=VALUE`` at ``path``), read like values in files and
    within the same limits; malformed YAML raises ``yaml.YAMLError``, a value that cannot be read (a tag, a
    date that does not exist) ValueError, a value over a limit ConfigError."""
    try:
        nodes = _compose(text, file)
    except ConfigError as err:  # no line numbers on the command line
        raise ConfigError([Problem(file, None, format_key(path), p.message) for p in err.problems]) from None
    if not nodes:
        return None
    if len(nodes) > 1:
        raise yaml.YAMLError("several YAML documents in one value")
    problems: list[Problem] = []
    data = _build(nodes[0], tuple(path), Origins(default_file=file), file, problems)
    if problems and all(p.message.startswith("cannot read value") for p in problems):
        raise ValueError(problems[0].message)  # a tag, a date that does not exist: the caller names the value
    if problems:  # over a limit; no line numbers on the command line
        raise ConfigError([Problem(file, None, p.key, p.message) for p in problems])
    return data


class _Constructor(yaml.constructor.SafeConstructor):
    pass


#: The only tags a mapping or a list may carry (an explicit ``!!python/...`` or ``!custom`` tag is refused).
_PLAIN_TAGS = {yaml.MappingNode: "tag:yaml.org,2002:map", yaml.SequenceNode: "tag:yaml.org,2002:seq"}


def _tag_text(tag: str) -> str:
    return "!!" + tag[len("tag:yaml.org,2002:"):] if tag.startswith("tag:yaml.org,2002:") else tag


def _build(node, path: KeyPath, origins: Origins, file: str, problems: list[Problem]) -> Any:
    origins.set(path, file, node.start_mark.line + 1)
    plain = _PLAIN_TAGS.get(type(node))
    if plain is not None and node.tag != plain:
        problems.append(Problem(file, node.start_mark.line + 1, format_key(path),
                                f"cannot read value: the tag {token(_tag_text(node.tag))} is not allowed "
                                "(plain YAML only: mappings, lists, numbers, text)"))
        return None
    if isinstance(node, yaml.MappingNode):
        out: dict = {}
        for knode, vnode in node.value:
            if not isinstance(knode, yaml.ScalarNode):
                problems.append(Problem(file, knode.start_mark.line + 1, format_key(path),
                                        "keys must be plain names"))
                continue
            key = knode.value
            if len(key) > limits.MAX_KEY_CHARS:
                problems.append(Problem(file, knode.start_mark.line + 1, format_key(path),
                                        f"a key of {len(key):,} characters (at most {limits.MAX_KEY_CHARS:,})"))
                continue
            if key in out:
                problems.append(Problem(file, knode.start_mark.line + 1, format_key(path + (key,)),
                                        "duplicate key (given twice in one mapping)"))
                continue
            out[key] = _build(vnode, path + (key,), origins, file, problems)
            # a problem of a key names the key's line: a block mapping or list value starts on the
            # next line, and 'swep:' reported at the line of what follows it sent readers one line off
            origins.set(path + (key,), file, knode.start_mark.line + 1)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_build(n, path + (i,), origins, file, problems) for i, n in enumerate(node.value)]
    too_long = limits.text_problem(node.value, limits.MAX_SCALAR_CHARS) if isinstance(node, yaml.ScalarNode) else None
    if too_long is not None:
        problems.append(Problem(file, node.start_mark.line + 1, format_key(path), too_long))
        return None
    try:
        return _Constructor().construct_object(node, deep=True)
    except yaml.YAMLError as exc:  # e.g. an object tag (safe loading refuses it), bad base64
        what = getattr(exc, "problem", None) or (str(exc).splitlines() or [""])[0]
        problems.append(Problem(file, node.start_mark.line + 1, format_key(path), f"cannot read value: {yaml_message(what)}"))
        return None
    except (ValueError, OverflowError, TypeError, ArithmeticError) as exc:
        # a date that does not exist (2024-13-45), an integer beyond Python's digit limit, ...
        tag = str(getattr(node, "tag", ""))
        if tag.endswith(":int") and len(str(getattr(node, "value", ""))) > 1000:  # Python refuses to convert it
            problems.append(Problem(file, node.start_mark.line + 1, format_key(path),
                                    "cannot read value: a number of thousands of digits, beyond the range of a double"))
            return None
        what = "not a valid date or time" if "timestamp" in tag else "not a usable value"
        problems.append(Problem(file, node.start_mark.line + 1, format_key(path),
                                f"cannot read value {token(getattr(node, 'value', ''))}: {what} ({clip(exc, 80)})"))
        return None


_QUOTED = re.compile(r"'([^']*)'|\"([^\"]*)\"")


def yaml_message(text) -> str:
    """A PyYAML message with every quoted token cut to the token limit (no file content beyond it)."""
    def cut(m: re.Match) -> str:
        inner = m.group(1) if m.group(1) is not None else m.group(2)
        return token(inner)
    return clip(_QUOTED.sub(cut, str(text)), 240)


#: The parser that counts the events of a document before it is composed: libyaml's (C) when PyYAML has
#: it (a bomb is refused in a fraction of a second), else the pure-Python one.
_EVENT_LOADER = getattr(yaml, "CSafeLoader", None) or yaml.SafeLoader
_OPEN = (yaml.SequenceStartEvent, yaml.MappingStartEvent)
_CLOSE = (yaml.SequenceEndEvent, yaml.MappingEndEvent)


def _count_events(text: str) -> bool:
    """TooBig when the text holds more nodes or deeper nesting than the limits (malformed YAML is left to
    the composer, which names the error); whether the document may use aliases."""
    nodes = depth = 0
    aliases = False
    try:
        for event in yaml.parse(text, Loader=_EVENT_LOADER):
            if isinstance(event, _OPEN):
                depth += 1
                if depth > limits.MAX_YAML_DEPTH:
                    raise _too_deep(event.start_mark.line + 1)
            elif isinstance(event, _CLOSE):
                depth -= 1
                continue
            elif isinstance(event, yaml.AliasEvent):
                aliases = True
            elif not isinstance(event, yaml.ScalarEvent):
                continue
            nodes += 1
            if nodes > limits.MAX_YAML_NODES:
                raise _too_many(event.start_mark.line + 1)
    except yaml.YAMLError as exc:
        if "nesting depth" in str(exc):  # libyaml's own limit (1000 levels), hit before the events come
            mark = getattr(exc, "problem_mark", None)
            raise _too_deep(mark.line + 1 if mark is not None else None) from None
        return True
    return aliases


def _children(node) -> list:
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _check_expansion(root) -> None:
    """TooBig when the document, its aliases expanded, holds too many values or nests too deep (billion
    laughs), or when an alias refers to a node that contains it (a recursive alias)."""
    size: dict = {}
    depth: dict = {}
    open_: set = set()
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            kids = _children(node)
            size[key] = 1 + sum(size[id(k)] for k in kids)
            depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
            open_.discard(key)
            if size[key] > limits.MAX_YAML_NODES:
                raise _too_many(node.start_mark.line + 1)
            if depth[key] > limits.MAX_YAML_DEPTH:
                raise _too_deep(node.start_mark.line + 1)
            continue
        if key in size:
            continue
        open_.add(key)
        stack.append((node, True))
        for kid in _children(node):
            if id(kid) in open_:
                raise TooBig("recursive alias (a node that contains itself)", kid.start_mark.line + 1)
            if id(kid) not in size:
                stack.append((kid, False))


def _compose(text: str, file: str) -> list:
    """The node trees of the documents of ``text`` within the limits (ConfigError when over one)."""
    try:
        aliases = _count_events(text)
        nodes = [n for n in yaml.compose_all(text, Loader=_CLoader or Loader) if n is not None]
        for node in nodes if aliases else ():   # without aliases, the events counted are the nodes
            _check_expansion(node)
    except TooBig as exc:
        raise ConfigError(Problem(file, exc.line, "", str(exc))) from None
    return nodes


def parse_yaml(text: str, file: str = "<input>") -> tuple[Any, Origins]:
    """Parse YAML ``text`` safely; return ``(data, origins)``.

    Raises
    ------
    ConfigError
        Malformed YAML (with the line of the error), an empty document, duplicate keys,
        several documents in one file, or a document over a limit of :mod:`tirecli.limits`
        (too many values, aliases included, too deep, a recursive alias, a key or value too long).
    """
    origins = Origins(default_file=file)
    try:
        nodes = _compose(text, file)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        what = " ".join(str(x) for x in (exc.context, exc.problem) if x)
        raise ConfigError(Problem(file, line, "", f"malformed YAML: {yaml_message(what)}")) from None
    except yaml.YAMLError as exc:  # e.g. a ReaderError (a character YAML does not allow), without content
        line = None
        if isinstance(exc, yaml.reader.ReaderError):
            line = text.count("\n", 0, max(int(exc.position), 0)) + 1
            ch = exc.character
            what = (f"character U+{ch:04X} is not allowed in YAML" if isinstance(ch, int)
                    else "a character YAML does not allow")
        else:
            what = yaml_message((str(exc).splitlines() or [""])[0])
        raise ConfigError(Problem(file, line, "", f"malformed YAML: {what}")) from None
    if not nodes:
        raise ConfigError(Problem(file, None, "", "the file is empty (expected a YAML mapping)"))
    if len(nodes) > 1:
        raise ConfigError(Problem(file, nodes[1].start_mark.line + 1, "",
                                  "several YAML documents in one file (expected one)"))
    problems: list[Problem] = []
    data = _build(nodes[0], (), origins, file, problems)
    if problems:
        raise ConfigError(problems)
    return data, origins


def load_yaml(path: str | Path) -> tuple[Any, Origins]:
    """Read and parse a YAML file (see :func:`parse_yaml`); a missing file is a ConfigError."""
    from tirecli.io.files import read_input_text

    path = Path(path)
    text = read_input_text(path, "a YAML file", encoding="utf-8-sig", max_bytes=limits.MAX_YAML_BYTES)
    return parse_yaml(text, str(path))


def load_yaml_document(path: str | Path, what: str, use: str) -> tuple[Any, Origins]:
    """:func:`load_yaml` of a file the command reads as ``what`` (``a study config``): a ``.tir``
    tyre file there is refused by name with ``use`` (how a tyre is used instead), not as malformed YAML."""
    if Path(path).suffix.lower() == ".tir":
        from tirecli.io.files import exists

        if exists(path):
            raise ConfigError(Problem(str(path), None, "", f"a .tir tyre property file, not {what}: {use}"))
    return load_yaml(path)


def require_kind(data: Any, origins: Origins, what: str, keys, shown: str, also: str = "") -> None:
    """The gate of a parsed document's kind, before any message names a key or a value of it.

    A mapping none of whose top-level keys is one of ``keys`` is some other file (a password or
    shadow file read as YAML, a list of accounts, another tool's config): it is refused as not
    ``what`` (``"a campaign file"``), saying how many keys it has and which ones were expected
    (``shown``), never which ones it has: no message echoes the text of a file that is not of the
    kind expected. ``also`` is inserted before the count (``"no 'study' key, and "``). Anything but a
    mapping is left to the caller (its message names no content either).
    """
    if isinstance(data, dict) and not set(map(str, data)) & {str(k) for k in keys}:
        raise ConfigError(origins.problem((), f"not {what}: {also}none of its {len(data)} top-level key(s) "
                                              f"is {shown}"))


def dump_yaml(data: Any) -> str:
    """YAML text for plain data (keys kept in insertion order)."""
    return yaml.dump(data, Dumper=Dumper, sort_keys=False, allow_unicode=True, default_flow_style=False)
