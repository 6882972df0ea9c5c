"""Scene files (YAML or JSON; format in docs/scene_format.md), strict validation, and the embedded
default scene that reproduces myPhysicsLab's demo."""
from __future__ import annotations

import copy
import difflib
import json
import math
import os
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Union

import yaml

from ._ffi import CollideError
from .scene_fast import PLAIN_NUMBER as _NUMBER, NotPlain, json_nests_too_deep, read_plain
from .world import _DEF_FIELDS, _ENUMS, World

__all__ = ["Scene", "SceneError", "load_scene", "load_scene_text", "read_scene_text", "default_scene",
           "DEFAULT_COLORS"]

Path_ = tuple[Union[str, int], ...]
_MISSING = object()
DEFAULT_COLORS = ("#2ca02c", "#1f77b4", "#d62728", "#ff7f0e", "#9467bd", "#8c564b")  # block1 green


class SceneError(ValueError):
    """A scene is malformed. ``errors`` lists (line or None, path, message); str() is readable."""

    def __init__(self, source: str, errors: list[tuple[int | None, str, str]]) -> None:
        self.source = source
        self.errors = errors
        lines = [f"{source}:{ln}: {p + ': ' if p else ''}{m}" if ln else f"{source}: {p + ': ' if p else ''}{m}"
                 for ln, p, m in errors]
        super().__init__("\n".join(lines))


def _fmt_path(path: Path_) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else p)
    return out


# ---- parsing with line numbers --------------------------------------------------------------

class _Parsed:
    """Plain Python data plus the 1-based line of every value, keyed by its path."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.lines: dict[Path_, int] = {}
        self.errors: list[tuple[int | None, str, str]] = []
        self.nodes = 0
        # one per parse: a constructor remembers every node it built (constructed_objects), so a
        # shared one kept every scalar of every scene ever loaded (found by the fuzzer's memory growth)
        self.constructor = yaml.constructor.SafeConstructor()

    def line(self, path: Path_) -> int | None:
        while path not in self.lines and path:
            path = path[:-1]
        return self.lines.get(path)

    def error(self, path: Path_, msg: str) -> None:
        self.errors.append((self.line(path), _fmt_path(path), msg))


_MAX_NODES = 1_000_000  # aliases can expand a small file exponentially ("billion laughs")
# A valid scene nests 6 levels (bodies[0].thrusters[0].point[0]); PyYAML's composer, json's decoder
# and _to_python recurse once per level, so a file nested thousands deep would hit RecursionError.
_MAX_DEPTH = 32
_TAG_MAP = "tag:yaml.org,2002:map"
_TAG_SEQ = "tag:yaml.org,2002:seq"


def _too_deep(source: str, line: int | None, path: Path_) -> SceneError:
    shown = _fmt_path(path[:4]) + ("..." if len(path) > 4 else "")
    return SceneError(source, [(line, shown, f"nested more than {_MAX_DEPTH} levels deep "
                                             f"(a valid scene nests at most 6)")])


class _DepthLimitedLoader(yaml.SafeLoader):
    """SafeLoader whose (recursive) composer refuses to go deeper than _MAX_DEPTH, before recursing."""

    def __init__(self, stream: str, source: str) -> None:
        super().__init__(stream)
        self._lc_source = source
        self._lc_path: list[Union[str, int]] = []

    def compose_node(self, parent: yaml.Node | None, index: Any) -> yaml.Node:
        # the composer calls (None, None) for the root, (node, None) for a key, (node, key node)
        # for a mapping value and (node, i) for a sequence item
        if parent is None:
            return super().compose_node(parent, index)
        if isinstance(index, int):
            step: Union[str, int] = index
        else:
            step = index.value if isinstance(index, yaml.ScalarNode) else "<key>"
        if len(self._lc_path) >= _MAX_DEPTH:
            mark = self.peek_event().start_mark
            raise _too_deep(self._lc_source, mark.line + 1, tuple(self._lc_path) + (step,))
        self._lc_path.append(step)
        try:
            return super().compose_node(parent, index)
        finally:
            self._lc_path.pop()


def _scalar(node: yaml.ScalarNode, path: Path_, parsed: _Parsed) -> Any:
    try:
        return parsed.constructor.construct_object(node, deep=True)
    except yaml.constructor.ConstructorError:
        msg = f"unsupported YAML tag {node.tag!r} (scene files use plain values)"
    except Exception as exc:  # noqa: BLE001 - PyYAML's constructors fail with Value/Key/Attribute errors
        msg = f"cannot read {node.value[:40]!r} as {node.tag.rsplit(':', 1)[-1]}: {type(exc).__name__}"
    raise SceneError(parsed.source, [(node.start_mark.line + 1, _fmt_path(path) or "(top level)", msg)])


def _to_python(node: yaml.Node, path: Path_, parsed: _Parsed, ancestors: tuple[int, ...] = ()) -> Any:
    parsed.lines[path] = node.start_mark.line + 1
    parsed.nodes += 1
    if parsed.nodes > _MAX_NODES:
        raise SceneError(parsed.source, [(node.start_mark.line + 1, _fmt_path(path),
                                          f"the scene expands to more than {_MAX_NODES} values (aliases?)")])
    if id(node) in ancestors:
        raise SceneError(parsed.source, [(node.start_mark.line + 1, _fmt_path(path), "recursive alias")])
    # the composer bounds each tree, but an alias can graft one deep tree onto another
    if len(path) > _MAX_DEPTH:
        raise _too_deep(parsed.source, node.start_mark.line + 1, path)
    if node.tag not in (_TAG_MAP, _TAG_SEQ) and not isinstance(node, yaml.ScalarNode):
        raise SceneError(parsed.source, [(node.start_mark.line + 1, _fmt_path(path) or "(top level)",
                                          f"unsupported YAML tag {node.tag!r} (scene files use plain values)")])
    ancestors = ancestors + (id(node),)
    if isinstance(node, yaml.MappingNode):
        out: dict[Any, Any] = {}
        for knode, vnode in node.value:
            if not isinstance(knode, yaml.ScalarNode):
                parsed.errors.append((knode.start_mark.line + 1, _fmt_path(path), "keys must be plain names"))
                continue
            key = knode.value
            if key in out:
                parsed.errors.append((knode.start_mark.line + 1, _fmt_path(path), f"duplicate key {key!r}"))
                continue
            out[key] = _to_python(vnode, path + (key,), parsed, ancestors)
            parsed.lines[path + (key,)] = knode.start_mark.line + 1
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_to_python(v, path + (i,), parsed, ancestors) for i, v in enumerate(node.value)]
    value = _scalar(node, path, parsed)
    if isinstance(value, str) and node.style is None and _NUMBER.fullmatch(value):
        # YAML 1.1 reads 1e-7 (no dot) or NaN as text; a plain scalar that looks like a number is one.
        return float(value.replace(".", "")) if "n" in value.lower() else float(value)
    return value


def _compose(text: str, source: str) -> yaml.Node | None:
    loader = _DepthLimitedLoader(text, source)
    try:
        return loader.get_single_node()
    finally:
        loader.dispose()


def _parse_text(text: str, source: str, is_json: bool) -> tuple[Any, _Parsed]:
    parsed = _Parsed(source)
    # JSON syntax first: clear messages for a truncated or malformed file. Too deep a file skips it:
    # the composer below reports the depth with the path where it was exceeded.
    if is_json and not json_nests_too_deep(text, _MAX_DEPTH):
        try:
            json.loads(text)
        except json.JSONDecodeError as exc:
            raise SceneError(source, [(exc.lineno, "", f"invalid JSON: {exc.msg} (column {exc.colno})")]) from None
    try:
        node = _compose(text, source)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        what = " ".join(x for x in (exc.context, exc.problem) if x)
        raise SceneError(source, [(mark.line + 1 if mark else None, "", f"invalid YAML: {what}")]) from None
    except yaml.YAMLError as exc:
        raise SceneError(source, [(None, "", f"invalid YAML: {exc}")]) from None
    if node is None:
        raise SceneError(source, [(None, "", "the scene file is empty")])
    return _to_python(node, (), parsed), parsed


# ---- validation ---------------------------------------------------------------------------------

Check = Callable[[Any, Path_, _Parsed], Any]


def _number(v: Any, path: Path_, p: _Parsed) -> Any:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        p.error(path, f"expected a number, got {_show(v)}")
        return _MISSING
    if isinstance(v, int) and abs(v) > sys.float_info.max:  # float() of it would raise OverflowError
        p.error(path, f"must be a finite number, got an integer of {len(str(abs(v)))} digits")
        return _MISSING
    if not math.isfinite(v):
        p.error(path, f"must be a finite number, got {v}")
        return _MISSING
    return float(v)


def _integer(v: Any, path: Path_, p: _Parsed) -> Any:
    if isinstance(v, bool) or not isinstance(v, int):
        p.error(path, f"expected an integer, got {_show(v)}")
        return _MISSING
    return v


def _boolean(v: Any, path: Path_, p: _Parsed) -> Any:
    if not isinstance(v, bool):
        p.error(path, f"expected true or false, got {_show(v)}")
        return _MISSING
    return v


def _string(v: Any, path: Path_, p: _Parsed) -> Any:
    if not isinstance(v, str) or not v.strip():
        p.error(path, f"expected a non-empty string, got {_show(v)}")
        return _MISSING
    return v


def _vec2(v: Any, path: Path_, p: _Parsed) -> Any:
    if not isinstance(v, list) or len(v) != 2:
        p.error(path, f"expected a pair [x, y], got {_show(v)}")
        return _MISSING
    xs = [_number(x, path + (i,), p) for i, x in enumerate(v)]
    return _MISSING if _MISSING in xs else xs


def _points(v: Any, path: Path_, p: _Parsed) -> Any:
    if not isinstance(v, list) or not v:
        p.error(path, f"expected a list of [x, y] vertices, got {_show(v)}")
        return _MISSING
    pts = [_vec2(x, path + (i,), p) for i, x in enumerate(v)]
    return _MISSING if _MISSING in pts else pts


def _show(v: Any) -> str:
    if isinstance(v, dict):
        return "a mapping"
    if isinstance(v, list):
        return f"a list of {len(v)}"
    if v is None:
        return "nothing (null)"
    return f"{type(v).__name__} {v!r}"


def _mapping(v: Any, path: Path_, p: _Parsed, spec: Mapping[str, tuple[Check, Any]]) -> Any:
    """Check a mapping against spec {key: (check, default or _MISSING if required)}."""
    if not isinstance(v, dict):
        p.error(path, f"expected a mapping of {', '.join(spec)}, got {_show(v)}")
        return _MISSING
    out: dict[str, Any] = {}
    ok = True
    for key in v:
        if key not in spec:
            close = difflib.get_close_matches(str(key), list(spec), n=1)
            hint = f"did you mean {close[0]!r}?" if close else f"allowed: {', '.join(spec)}"
            p.error(path + (key,), f"unknown key {key!r} ({hint})")
            ok = False
    for key, (check, default) in spec.items():
        if key in v:
            val = check(v[key], path + (key,), p)
            ok &= val is not _MISSING
            out[key] = val
        elif default is _MISSING:
            p.error(path, f"missing required key {key!r}")
            ok = False
        else:
            out[key] = copy.deepcopy(default)
    return out if ok else _MISSING


def _optional(check: Check) -> Check:
    return lambda v, path, p: None if v is None else check(v, path, p)


def _world_field(name: str) -> Check:
    t = _DEF_FIELDS[name]
    if t.kind == "enum":
        names = _ENUMS[name]

        def enum(v: Any, path: Path_, p: _Parsed) -> Any:
            if not isinstance(v, str) or v.lower() not in names:
                p.error(path, f"expected one of {', '.join(names)}, got {_show(v)}")
                return _MISSING
            return v.lower()
        return enum
    if t.cname == "struct lc_vec2":
        return _vec2
    return _number if t.cname == "double" else _integer


_WORLD_SPEC = {name: (_world_field(name), None) for name in _DEF_FIELDS}
_WALLS_SPEC = {"xmin": (_number, _MISSING), "ymin": (_number, _MISSING), "xmax": (_number, _MISSING),
               "ymax": (_number, _MISSING), "thickness": (_number, 1.0), "elasticity": (_number, 1.0)}
_THRUSTER_SPEC = {"point": (_vec2, _MISSING), "direction": (_vec2, _MISSING), "magnitude": (_number, _MISSING)}
_RUN_SPEC = {"dt": (_number, 0.01), "duration": (_number, 10.0)}
_SPRING_SPEC = {"name": (_optional(_string), None), "body_a": (_string, _MISSING), "point_a": (_vec2, [0.0, 0.0]),
                "body_b": (_optional(_string), None), "point_b": (_vec2, [0.0, 0.0]),
                "stiffness": (_number, 3.0), "damping": (_number, 0.0), "rest_length": (_number, 0.0)}


def _thrusters(v: Any, path: Path_, p: _Parsed) -> Any:
    if v == "default":
        return {"default": 1.5}
    if isinstance(v, dict):
        return _mapping(v, path, p, {"default": (_number, _MISSING)})
    if isinstance(v, list):
        items = [_mapping(t, path + (i,), p, _THRUSTER_SPEC) for i, t in enumerate(v)]
        return _MISSING if _MISSING in items else items
    p.error(path, f"expected 'default', {{default: THRUST}} or a list of {{point, direction, magnitude}}, got {_show(v)}")
    return _MISSING


def _inertia(v: Any, path: Path_, p: _Parsed) -> Any:
    val = _number(v, path, p)
    if val is not _MISSING and not val > 0:
        p.error(path, f"must be > 0 kg*m^2, got {val} (omit the key for the polygon's own inertia)")
        return _MISSING
    return val


# A laser scanner on a body (read by the ROS node, docs/ros_interface.md "Laser scanners"; the engine
# ignores it). Defaults: 360 rays, one a degree, from -pi; 10 m; 10 Hz of sim time.
_SCAN_STEP = 2 * math.pi / 360
_SCANNER_SPEC = {"name": (_string, _MISSING), "body": (_string, _MISSING), "position": (_vec2, [0.0, 0.0]),
                 "angle": (_number, 0.0), "angle_min": (_number, -math.pi),
                 "angle_max": (_number, math.pi - _SCAN_STEP), "angle_increment": (_number, _SCAN_STEP),
                 "range_min": (_number, 0.0), "range_max": (_number, 10.0), "rate": (_number, 10.0)}
SCANNER_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
MAX_SCAN_RAYS = 10_000
MAX_SCAN_RANGE = 1e4       # m
MAX_SCAN_MOUNT = 1e3       # m from the body's centre of mass
MAX_SCAN_RATE = 1000.0     # Hz of sim time


def scanner_problems(sc: Mapping[str, Any]) -> list[tuple[str, str]]:
    """The (key, reason) of each range rule a scanner's values break (its keys and types already
    checked); empty when it is usable. Its ray count is scanner_rays(sc)."""
    out = []
    if not SCANNER_NAME.fullmatch(sc["name"]):
        out.append(("name", f"{sc['name']!r} must be a letter then letters, digits or '_' "
                            "(it names the scanner's topic and frame)"))
    if max(abs(sc["position"][0]), abs(sc["position"][1])) > MAX_SCAN_MOUNT:
        out.append(("position", f"{sc['position']} is more than {MAX_SCAN_MOUNT:g} m from the body"))
    inc, lo, hi = sc["angle_increment"], sc["angle_min"], sc["angle_max"]
    if not 0 < inc <= 2 * math.pi:
        out.append(("angle_increment", f"must be in (0, 2*pi] rad, got {inc}"))
    if not -2 * math.pi <= lo <= hi <= 2 * math.pi:
        out.append(("angle_max", f"angle_min {lo} <= angle_max {hi} within [-2*pi, 2*pi] rad is required"))
    elif hi - lo > 2 * math.pi + 1e-12:
        out.append(("angle_max", f"the scan spans {hi - lo} rad, more than a turn (2*pi)"))
    elif 0 < inc <= 2 * math.pi:
        steps = (hi - lo) / inc
        if round(steps) + 1 > MAX_SCAN_RAYS:
            out.append(("angle_increment", f"{round(steps) + 1} rays over [angle_min, angle_max]; "
                                           f"at most {MAX_SCAN_RAYS}"))
        elif abs(steps - round(steps)) > 1e-6:
            out.append(("angle_max", f"angle_max - angle_min = {hi - lo} rad is not a whole number of "
                                     f"angle_increment {inc} ({steps:.6f})"))
    if not 0 <= sc["range_min"] < sc["range_max"] <= MAX_SCAN_RANGE:
        out.append(("range_max", f"0 <= range_min ({sc['range_min']}) < range_max ({sc['range_max']}) "
                                 f"<= {MAX_SCAN_RANGE:g} m is required"))
    if not 0 < sc["rate"] <= MAX_SCAN_RATE:
        out.append(("rate", f"must be in (0, {MAX_SCAN_RATE:g}] Hz, got {sc['rate']}"))
    return out


def scanner_rays(sc: Mapping[str, Any]) -> int:
    """The number of rays of a valid scanner: angle_min, angle_min + angle_increment, ... angle_max."""
    return int(round((sc["angle_max"] - sc["angle_min"]) / sc["angle_increment"])) + 1


_BODY_COMMON = {"name": (_string, _MISSING), "shape": (_string, _MISSING), "position": (_vec2, [0.0, 0.0]),
                "angle": (_number, 0.0), "velocity": (_vec2, [0.0, 0.0]), "angular_velocity": (_number, 0.0),
                "mass": (_number, 1.0), "inertia": (_optional(_inertia), None),
                "center_of_mass": (_optional(_vec2), None), "elasticity": (_number, 1.0), "friction": (_number, 0.0),
                "static": (_boolean, False), "color": (_optional(_string), None),
                "thrusters": (_optional(_thrusters), None),
                "external": (_optional(lambda v, path, p: _mapping(
                    v, path, p, {"force": (_vec2, [0.0, 0.0]), "torque": (_number, 0.0)})), None)}
_SHAPES = {"box": {"width": (_number, _MISSING), "height": (_number, _MISSING)},
           "polygon": {"vertices": (_points, _MISSING)}}


def _body(v: Any, path: Path_, p: _Parsed) -> Any:
    if not isinstance(v, dict):
        p.error(path, f"expected a body (a mapping with name, shape, ...), got {_show(v)}")
        return _MISSING
    shape = v.get("shape")
    if not isinstance(shape, str) or shape not in _SHAPES:  # a list or mapping is not even hashable
        if "shape" in v:
            p.error(path + ("shape",), f"expected 'box' or 'polygon', got {_show(shape)}")
        else:
            p.error(path, "missing required key 'shape' (box or polygon)")
        return _MISSING
    return _mapping(v, path, p, {"name": _BODY_COMMON["name"], "shape": _BODY_COMMON["shape"], **_SHAPES[shape],
                                 **_BODY_COMMON})


def _list_of(check: Check) -> Check:
    def lst(v: Any, path: Path_, p: _Parsed) -> Any:
        if not isinstance(v, list):
            p.error(path, f"expected a list, got {_show(v)}")
            return _MISSING
        items = [check(x, path + (i,), p) for i, x in enumerate(v)]
        return _MISSING if _MISSING in items else items
    return lst


_TOP_SPEC = {"version": (_integer, 1), "description": (_optional(_string), None),
             # absent = every field unset, the same dict a present world gets: to_dict() round-trips
             "world": (lambda v, path, p: _mapping(v, path, p, _WORLD_SPEC), dict.fromkeys(_WORLD_SPEC)),
             "walls": (_optional(lambda v, path, p: _mapping(v, path, p, _WALLS_SPEC)), None),
             "bodies": (_list_of(_body), _MISSING),
             "springs": (_list_of(lambda v, path, p: _mapping(v, path, p, _SPRING_SPEC)), []),
             "scanners": (_list_of(lambda v, path, p: _mapping(v, path, p, _SCANNER_SPEC)), []),
             "run": (lambda v, path, p: _mapping(v, path, p, _RUN_SPEC), dict(dt=0.01, duration=10.0))}


# ---- the Scene -----------------------------------------------------------------------------------

@dataclass
class Scene:
    """A validated scene. ``build()`` makes a fresh World from it (call it as often as needed)."""

    world: dict[str, Any]
    walls: dict[str, Any] | None
    bodies: list[dict[str, Any]]
    springs: list[dict[str, Any]]
    run: dict[str, float]
    description: str | None = None
    scanners: list[dict[str, Any]] = field(default_factory=list)  # for the ROS node; the engine ignores them
    source: str = field(default="<scene>", compare=False)
    _lines: dict[Path_, int] = field(default_factory=dict, repr=False, compare=False)
    # a scene read by the fast reader keeps no lines: this reads them when a message needs one
    _relines: Callable[[], dict[Path_, int]] | None = field(default=None, repr=False, compare=False)

    @property
    def names(self) -> list[str]:
        """Names of the scene's bodies (walls first when present), in World row order."""
        walls = list(_WALL_NAMES) if self.walls else []
        return walls + [b["name"] for b in self.bodies]

    def to_dict(self) -> dict[str, Any]:
        """Plain data (no None-valued optional keys) that load_scene reads back to an equal Scene."""
        def strip(d: dict[str, Any]) -> dict[str, Any]:
            return {k: v for k, v in d.items() if v is not None}
        out: dict[str, Any] = {"version": 1}
        if self.description:
            out["description"] = self.description
        out["world"] = strip(self.world)
        if self.walls:
            out["walls"] = dict(self.walls)
        out["bodies"] = [strip(b) for b in self.bodies]
        out["springs"] = [strip(s) for s in self.springs]
        if self.scanners:
            out["scanners"] = [dict(s) for s in self.scanners]
        out["run"] = dict(self.run)
        return copy.deepcopy(out)

    def dump(self, path: str | os.PathLike[str]) -> None:
        """Write the scene as YAML (or JSON for a .json path)."""
        data = self.to_dict()
        text = json.dumps(data, indent=2) if str(path).endswith(".json") else yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
        Path(path).write_text(text)

    def _fail(self, path: Path_, exc: Exception) -> SceneError:
        p = _Parsed(self.source)
        if not self._lines and self._relines is not None:
            self._lines = self._relines()
        p.lines = self._lines
        p.error(path, str(exc))
        return SceneError(self.source, p.errors)

    def build(self) -> World:
        """A new World holding this scene. Errors name the scene item (and line) that C rejected."""
        path: Path_ = ("world",)
        try:
            world = World(**{k: v for k, v in self.world.items() if v is not None})
            if self.walls:
                path = ("walls",)
                w = self.walls
                world.add_walls(w["xmin"], w["ymin"], w["xmax"], w["ymax"], w["thickness"], w["elasticity"])
            for i, b in enumerate(self.bodies):
                path = ("bodies", i)
                common = dict(position=b["position"], angle=b["angle"], velocity=b["velocity"],
                              angular_velocity=b["angular_velocity"], mass=b["mass"], elasticity=b["elasticity"],
                              friction=b["friction"], static=b["static"], name=b["name"],
                              inertia=b.get("inertia") or 0.0, center_of_mass=b.get("center_of_mass"))
                try:
                    if b["shape"] == "box":
                        body = world.add_box(b["width"], b["height"], **common)
                    else:
                        body = world.add_body(b["vertices"], **common)
                except CollideError as exc:
                    # C names the field it refused: point at that key's line when the scene gives it
                    for key in ("inertia", "center_of_mass"):
                        if b.get(key) is not None and exc.message.startswith(key):
                            path = ("bodies", i, key)
                    raise
                th = b.get("thrusters")
                path = ("bodies", i, "thrusters")
                if isinstance(th, dict):
                    body.add_default_thrusters(th["default"])
                elif th:
                    for t in th:
                        body.add_thruster(t["point"], t["direction"], t["magnitude"])
                if b.get("external"):
                    path = ("bodies", i, "external")
                    body.set_external(b["external"]["force"], b["external"]["torque"])
            for i, s in enumerate(self.springs):
                path = ("springs", i)
                world.add_spring(s["body_a"], s["point_a"], s["body_b"], s["point_b"], s["stiffness"],
                                 s["damping"], s["rest_length"], name=s["name"])
        except (CollideError, KeyError, ValueError, TypeError) as exc:
            msg = exc.args[0] if isinstance(exc, KeyError) and exc.args else str(exc)
            raise self._fail(path, Exception(msg)) from exc
        return world


_WALL_NAMES = ("wall_bottom", "wall_right", "wall_top", "wall_left")


def _from_data(data: Any, parsed: _Parsed, validate: bool) -> Scene:
    top = _mapping(data, (), parsed, _TOP_SPEC)
    if top is not _MISSING:
        if top["version"] != 1:
            parsed.error(("version",), f"unsupported version {top['version']} (this reader knows 1)")
        names = set(_WALL_NAMES) if top["walls"] else set()  # a set: a list is quadratic in the bodies
        for i, b in enumerate(top["bodies"]):
            if b["name"] in names:
                parsed.error(("bodies", i, "name"), f"duplicate body name {b['name']!r}")
            names.add(b["name"])
        for i, s in enumerate(top["springs"]):
            for key in ("body_a", "body_b"):
                if s[key] is not None and s[key] not in names:
                    parsed.error(("springs", i, key), f"no body named {s[key]!r}")
        scanner_names: set[str] = set()
        for i, sc in enumerate(top["scanners"]):
            if sc["body"] not in names:
                parsed.error(("scanners", i, "body"), f"no body named {sc['body']!r}")
            if sc["name"] in scanner_names or sc["name"] in names:
                parsed.error(("scanners", i, "name"), f"{sc['name']!r} is taken (by a scanner or a body: "
                                                      "the frames of both are named after them)")
            scanner_names.add(sc["name"])
            for key, why in scanner_problems(sc):
                parsed.error(("scanners", i, key), why)
        if top["run"]["dt"] <= 0 or top["run"]["dt"] > 1:
            parsed.error(("run", "dt"), f"must be in (0, 1] s, got {top['run']['dt']}")
        if top["run"]["duration"] < 0:
            parsed.error(("run", "duration"), f"must be >= 0 s, got {top['run']['duration']}")
    if parsed.errors:
        raise SceneError(parsed.source, parsed.errors[:20])
    scene = Scene(world=top["world"], walls=top["walls"], bodies=top["bodies"], springs=top["springs"],
                  run=top["run"], description=top["description"], scanners=top["scanners"], source=parsed.source,
                  _lines=parsed.lines)
    if validate:
        scene.build()  # range rules live in C: a trial build reports them against the scene's lines
    return scene


def _deeper_than_limit(data: Any) -> Path_ | None:
    """The first path longer than _MAX_DEPTH in plain data (walked without recursion), or None."""
    stack: list[tuple[Any, Path_]] = [(data, ())]
    while stack:
        value, path = stack.pop()
        items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
        for key, child in items:
            sub = path + (key if isinstance(key, (str, int)) else str(key),)
            if len(sub) > _MAX_DEPTH:
                return sub
            stack.append((child, sub))
    return None


def load_scene(source: Union[str, os.PathLike[str], dict[str, Any]], validate: bool = True) -> Scene:
    """Read a scene from a YAML/JSON file path or from a dict; raise SceneError if malformed."""
    if isinstance(source, dict):
        parsed = _Parsed("<dict>")
        deep = _deeper_than_limit(source)
        if deep is not None:  # before deepcopy, which recurses per level
            raise _too_deep(parsed.source, None, deep)
        return _from_data(copy.deepcopy(source), parsed, validate)
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"load_scene takes a path or a dict, got {type(source).__name__}")
    return load_scene_text(read_scene_text(source), str(Path(source)), validate)


def read_scene_text(path: Union[str, os.PathLike[str]]) -> str:
    """The text of a scene file; SceneError (no such file, cannot read) as load_scene raises it."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(str(Path(path)), [(None, "", "no such file")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(str(Path(path)), [(None, "", f"cannot read: {exc}")]) from None


def load_scene_text(text: str, source: str, validate: bool = True) -> Scene:
    """A scene from the text of the file named ``source`` (JSON if it ends in .json, else YAML), exactly
    as load_scene(source) reads it. A plain file is read by the fast reader (libyaml or json); anything
    else, and any file with a problem, by the line-numbered reader, whose messages name the lines."""
    is_json = Path(source).suffix.lower() == ".json"
    try:
        data = read_plain(text, is_json, _MAX_DEPTH, _MAX_NODES)
    except NotPlain:
        return _load_lined(text, source, is_json, validate)
    try:
        scene = _from_data(data, _Parsed(source), validate)
    except SceneError:
        return _load_lined(text, source, is_json, validate)
    scene._relines = _LinesOf(text, source, is_json)
    return scene


@dataclass(frozen=True)
class _LinesOf:
    """The lines of a file's values, read by the line-numbered reader when a message needs them (a
    class, not a closure: a Scene stays picklable)."""

    text: str
    source: str
    is_json: bool

    def __call__(self) -> dict[Path_, int]:
        return _parse_text(self.text, self.source, self.is_json)[1].lines


def _load_lined(text: str, source: str, is_json: bool, validate: bool) -> Scene:
    """The line-numbered reader: PyYAML's Python composer, the line of every value kept."""
    data, parsed = _parse_text(text, source, is_json)
    return _from_data(data, parsed, validate)


# Positions of blocks 1..6 in the default scene: inside [-6, 6]^2, none touching another or a wall.
_BLOCK_POSES = ((-2.5, 0.0, 0.0), (2.5, 0.0, 0.0), (0.0, 3.5, math.pi / 2), (0.0, -3.5, math.pi / 2),
                (-4.75, 0.5, 0.0), (4.75, 0.5, 0.0))


def default_scene(blocks: int = 2, green_mass: float = 1.0, gravity: float = 0.0, elasticity: float = 1.0,
                  damping: float = 0.0) -> Scene:
    """myPhysicsLab's demo: a walled box [-6, 6]^2 (1 m walls), 1-6 blocks 1 m x 3 m; block1 (green)
    has the adjustable mass, the others 1 kg; default thrusters (thrust 1.5) on block1 and block2;
    gravity (m/s^2, downward), elasticity for every body, damping k with rotation ratio 0.1."""
    if isinstance(blocks, bool) or not isinstance(blocks, int) or not 1 <= blocks <= 6:
        raise ValueError(f"blocks must be an integer from 1 to 6, got {blocks!r}")
    bodies = []
    for i in range(blocks):
        x, y, a = _BLOCK_POSES[i]
        body: dict[str, Any] = {"name": f"block{i + 1}", "shape": "box", "width": 1.0, "height": 3.0,
                                "position": [x, y], "angle": a, "mass": green_mass if i == 0 else 1.0,
                                "elasticity": elasticity, "color": DEFAULT_COLORS[i]}
        if i < 2:
            body["thrusters"] = {"default": 1.5}
        bodies.append(body)
    data = {"version": 1, "description": f"seed demo: {blocks} block(s) in a walled box",
            "world": {"gravity": [0.0, 0.0 - gravity], "zero_energy_level": -6.0, "damping": damping,
                      "damping_rotation_ratio": 0.1},
            "walls": {"xmin": -6.0, "ymin": -6.0, "xmax": 6.0, "ymax": 6.0, "thickness": 1.0,
                      "elasticity": elasticity},
            "bodies": bodies, "run": {"dt": 0.01, "duration": 10.0}}
    try:
        scene = load_scene(data)
    except SceneError as exc:  # e.g. a NaN mass: report it in the caller's terms
        raise ValueError(str(exc).replace("<dict>: ", "default_scene: ")) from None
    scene.source = "<default scene>"
    return scene
