"""The fast reader of scene files: libyaml's parser (or json) turns a plain file into the same Python
data as scene.py's line-numbered reader, without its pure-Python composer. It reads only what it can
read exactly like that reader (no anchors, aliases, tags or duplicate keys, nothing nested too deep)
and raises NotPlain for anything else; the caller then reads the file with scene.py's reader, which
also names the line of every problem."""
from __future__ import annotations

import json
import re
from typing import Any

import yaml

__all__ = ["NotPlain", "PLAIN_NUMBER", "json_nests_too_deep", "read_plain"]

# A plain YAML scalar that looks like a number is one, although YAML 1.1 reads 1e-7 (no dot) or NaN as text.
PLAIN_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|[-+]?\.?(inf|Inf|INF)|\.?(nan|NaN|NAN)")
# The common plain scalars, read here without PyYAML's resolver and constructor: exactly the values those
# give them (an integer in decimal without underscores or a sign other than '-'; a decimal with a dot).
_DECIMAL_INT = re.compile(r"-?(?:0|[1-9][0-9]*)")
_DECIMAL_FLOAT = re.compile(r"-?[0-9]+\.[0-9]*(?:[eE][-+]?[0-9]+)?")
_WORDS = {"true": True, "false": False, "null": None, "~": None, "": None}
# First characters of YAML 1.1's implicit types (bool, int, float, null, timestamp, merge, value, yaml): a
# plain scalar starting with any other character is a string (or a PLAIN_NUMBER such as inf).
_TYPED_FIRST = frozenset("-+.0123456789yYnNtTfFoO~<=!&*")
# a string (to its closing quote, or to the end if unterminated: never backtracks) or a bracket
_JSON_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"?|[\[\]{}]', re.DOTALL)
# json joins a \uD83D\uDE00 pair into one character, PyYAML keeps two
_JSON_SURROGATE = re.compile(r"\\u[dD][89abAB]")


class NotPlain(Exception):
    """The file uses something the fast reader leaves to the line-numbered one (or is malformed)."""


def json_nests_too_deep(text: str, max_depth: int) -> bool:
    """Whether brackets outside strings nest deeper than max_depth (json's decoder recurses per level)."""
    depth = 0
    for m in _JSON_TOKEN.finditer(text):
        tok = m.group()
        if tok in ("[", "{"):
            depth += 1
            if depth > max_depth:
                return True
        elif tok in ("]", "}"):
            depth -= 1
    return False


def read_plain(text: str, is_json: bool, max_depth: int, max_nodes: int) -> Any:
    """The file's data as the line-numbered reader gives it, or NotPlain. Values deeper than max_depth
    (the root is at depth 0) or more than max_nodes values in all are NotPlain: that reader refuses them."""
    return _read_json(text, max_depth, max_nodes) if is_json else _read_yaml(text, max_depth, max_nodes)


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out = dict(pairs)
    if len(out) != len(pairs):
        raise NotPlain("duplicate key")
    return out


def _read_json(text: str, max_depth: int, max_nodes: int) -> Any:
    # brackets bound the depth of the data, and keep json's recursive decoder far from the recursion limit;
    # the line-numbered reader reads JSON as YAML, whose reader refuses characters that json takes, and
    # whose scanner refuses a tab between tokens where json takes it as a space (as _read_yaml says)
    if (json_nests_too_deep(text, max_depth + 1) or _JSON_SURROGATE.search(text)
            or yaml.reader.Reader.NON_PRINTABLE.search(text) or "\t" in text):
        raise NotPlain("deep, surrogate escapes, a tab or a character PyYAML's reader refuses")
    try:
        data = json.loads(text, object_pairs_hook=_unique_keys)
    except (ValueError, RecursionError) as exc:  # JSONDecodeError is a ValueError
        raise NotPlain(str(exc)) from None
    # as in the line-numbered reader, every value counts, keys do not
    nodes = 0
    stack: list[tuple[Any, int]] = [(data, 0)]
    while stack:
        value, depth = stack.pop()
        nodes += 1
        if depth > max_depth or nodes > max_nodes:
            raise NotPlain("too deep or too many values")
        if isinstance(value, dict):
            stack.extend((v, depth + 1) for v in value.values())
        elif isinstance(value, list):
            stack.extend((v, depth + 1) for v in value)
    return data


def _read_yaml(text: str, max_depth: int, max_nodes: int) -> Any:
    if not getattr(yaml, "__with_libyaml__", False):
        raise NotPlain("PyYAML without libyaml")
    if yaml.reader.Reader.NON_PRINTABLE.search(text):
        raise NotPlain("a character PyYAML's reader refuses")
    # libyaml takes a tab as the space between tokens of a flow collection where PyYAML's own scanner
    # refuses it ("found character '\t' that cannot start any token"): a file with a tab is the
    # line-numbered reader's, which decides as it always does
    if "\t" in text:
        raise NotPlain("a tab")
    loader = yaml.CSafeLoader(text)
    try:
        return _compose(loader, max_depth, max_nodes)
    except yaml.YAMLError as exc:
        raise NotPlain(str(exc)) from None
    finally:
        loader.dispose()


def _scalar(loader: yaml.CSafeLoader, ev: yaml.ScalarEvent) -> Any:
    """A plain scalar's value: YAML 1.1's implicit type, then PLAIN_NUMBER."""
    value: str = ev.value
    if _DECIMAL_INT.fullmatch(value):
        return int(value)
    if _DECIMAL_FLOAT.fullmatch(value):
        return float(value)
    if value in _WORDS:
        return _WORDS[value]
    if value[0] in _TYPED_FIRST:
        node = yaml.ScalarNode(loader.resolve(yaml.ScalarNode, value, ev.implicit), value,
                               ev.start_mark, ev.end_mark, ev.style)
        try:
            out = loader.construct_object(node, deep=True)
        except Exception as exc:  # noqa: BLE001 - PyYAML's constructors fail with Value/Key/Attribute errors
            raise NotPlain(str(exc)) from None
        if not isinstance(out, str):
            return out
    if PLAIN_NUMBER.fullmatch(value):
        return float(value.replace(".", "")) if "n" in value.lower() else float(value)
    return value


_AWAIT_KEY = object()


def _compose(loader: yaml.CSafeLoader, max_depth: int, max_nodes: int) -> Any:
    """Events to plain data without recursion: a stack of the open containers and, for a mapping, the
    key whose value comes next (_AWAIT_KEY between entries)."""
    get = loader.get_event
    scalar_ev, map_ev, seq_ev = yaml.ScalarEvent, yaml.MappingStartEvent, yaml.SequenceStartEvent
    end_evs = (yaml.MappingEndEvent, yaml.SequenceEndEvent)
    if not isinstance(get(), yaml.StreamStartEvent) or not isinstance(get(), yaml.DocumentStartEvent):
        raise NotPlain("no document")
    containers: list[Any] = []
    keys: list[Any] = []
    root: Any = None
    nodes = 0
    while True:
        ev = get()
        cls = type(ev)
        if cls in end_evs:
            containers.pop()
            keys.pop()
            if not containers:
                break
            continue
        if ev.anchor is not None or cls not in (scalar_ev, map_ev, seq_ev) or ev.tag is not None:
            raise NotPlain(f"{cls.__name__} with anchor {ev.anchor!r}, tag {getattr(ev, 'tag', None)!r}")
        if containers and keys[-1] is _AWAIT_KEY:
            if cls is not scalar_ev or ev.value in containers[-1]:
                raise NotPlain("a key that is not a plain name, or a duplicate key")
            keys[-1] = ev.value
            continue
        nodes += 1
        if len(containers) > max_depth or nodes > max_nodes:
            raise NotPlain("too deep or too many values")
        if cls is scalar_ev:
            value = ev.value if ev.style else _scalar(loader, ev)
        else:
            value = {} if cls is map_ev else []
        if not containers:
            root = value
        elif keys[-1] is None:
            containers[-1].append(value)
        else:
            containers[-1][keys[-1]] = value
            keys[-1] = _AWAIT_KEY
        if cls is scalar_ev:
            if not containers:
                break
        else:
            containers.append(value)
            keys.append(_AWAIT_KEY if cls is map_ev else None)
    if not isinstance(get(), yaml.DocumentEndEvent) or not isinstance(get(), yaml.StreamEndEvent):
        raise NotPlain("more than one document")
    return root
