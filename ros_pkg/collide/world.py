"""The World: a libcollide world with names, settings, bulk views, energy and counters.

Bulk state is exposed as read-only numpy views of the C arrays (no per-body copies). A view of the
state stays valid until the next body is added or removed (the C library may move its arrays then);
a view of the contacts stays valid until the next step. Each view keeps its World alive.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Sequence

import numpy as np

from . import _convert as cv
from ._ffi import CollideError, check, ffi, lib
from ._views import COLLISION, CONTACT_DTYPE, EVENT_DTYPE, IMPACT_CONTACT, IMPACT_EVENT, RESTING, _view
from .body import Body, BodyRef, Spring, Thruster, _Record, _vec
from . import force as _force
from . import query as _query
from .force import ForceFn, PotentialFn
from .query import BodyDistance, RayHit, RayHits

__all__ = ["World", "Body", "Thruster", "Spring", "Energy", "CollideError", "CONTACT_DTYPE",
           "COLLISION", "RESTING", "EVENT_DTYPE", "IMPACT_EVENT", "IMPACT_CONTACT", "WALL_NAMES"]

WALL_NAMES = ("wall_bottom", "wall_right", "wall_top", "wall_left")  # lc_world_add_walls order


def _enum_names(ctype: str) -> dict[str, int]:
    rel = ffi.typeof(ctype).relements
    keys = list(rel)
    prefix = keys[0]
    for k in keys[1:]:
        while not k.startswith(prefix):
            prefix = prefix[:-1]
    prefix = prefix[: prefix.rfind("_") + 1]
    return {k[len(prefix):].lower(): int(v) for k, v in sorted(rel.items(), key=lambda kv: kv[1])}


_DEF_FIELDS = {name: f.type for name, f in ffi.typeof("lc_world_def").fields}
_ENUMS = {name: _enum_names(t.cname) for name, t in _DEF_FIELDS.items() if t.kind == "enum"}


def _set_def_field(d: Any, field: str, value: Any) -> None:
    t = _DEF_FIELDS.get(field)
    if t is None:
        raise TypeError(f"unknown world setting {field!r}; valid: {', '.join(_DEF_FIELDS)}")
    if t.kind == "enum":
        names = _ENUMS[field]
        if isinstance(value, str):
            if value.lower() not in names:
                raise ValueError(f"{field} must be one of {', '.join(names)}, got {value!r}")
            value = names[value.lower()]
        setattr(d, field, cv.integer(value, field))  # unknown ints: C answers LC_ERR_BAD_ENUM
    elif t.cname == "struct lc_vec2":
        x, y = cv.vec2(value, field)
        getattr(d, field).x, getattr(d, field).y = x, y
    elif t.cname == "double":
        setattr(d, field, cv.real(value, field))
    else:
        v = cv.integer(value, field)
        if not -2**31 <= v < 2**31:
            raise ValueError(f"{field} = {v} does not fit a C int")
        setattr(d, field, v)


def _def_to_dict(d: Any) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for field, t in _DEF_FIELDS.items():
        v = getattr(d, field)
        if t.kind == "enum":
            inv = {num: n for n, num in _ENUMS[field].items()}
            out[field] = inv.get(int(v), int(v))
        elif t.cname == "struct lc_vec2":
            out[field] = (v.x, v.y)
        else:
            out[field] = v
    return out


@dataclass(frozen=True)
class Energy:
    translational: float
    rotational: float
    gravitational: float
    spring: float
    total: float
    linear_momentum: tuple[float, float]
    angular_momentum: float
    callback: float = 0.0  # the force callback's potential (set_force_callback), included in total


class World:
    """A libcollide world. Keyword arguments are lc_world_def fields (enums by name or value)."""

    def __init__(self, **settings: Any) -> None:
        errbuf = ffi.new("char[]", 256)
        d = ffi.new("lc_world_def *", lib.lc_default_world_def())
        ptr = lib.lc_world_create(d, errbuf, 256)
        if ptr == ffi.NULL:
            raise CollideError(lib.LC_ERR_NO_MEMORY, ffi.string(errbuf).decode())
        self._w = ffi.gc(ptr, lib.lc_world_destroy)
        self._rec: dict[int, _Record] = {}
        self._by_name: dict[str, int] = {}
        self._names: list[str] = []
        self._springs: dict[str, int] = {}
        self._view = ffi.new("lc_state_view *")
        self._poly_cache: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None = None
        self._force_law: _force._Law | None = None   # kept alive while C holds its handle
        if settings:
            self.configure(**settings)

    # ---- settings ------------------------------------------------------------------------------
    @property
    def settings(self) -> dict[str, Any]:
        d = ffi.new("lc_world_def *")
        check(self._w, lib.lc_world_get_def(self._w, d))
        return _def_to_dict(d)

    def configure(self, **fields: Any) -> None:
        """Change any lc_world_def fields at once (validated by C as a whole)."""
        d = ffi.new("lc_world_def *")
        check(self._w, lib.lc_world_get_def(self._w, d))
        for k, v in fields.items():
            _set_def_field(d, k, v)
        check(self._w, lib.lc_world_set_def(self._w, d))

    def set_gravity(self, gravity: Iterable[float]) -> None:
        gx, gy = cv.vec2(gravity, "gravity")
        check(self._w, lib.lc_world_set_gravity(self._w, (gx, gy)))

    def set_damping(self, damping: float, rotation_ratio: float | None = None) -> None:
        k = cv.real(damping, "damping")
        r = self.settings["damping_rotation_ratio"] if rotation_ratio is None else cv.real(rotation_ratio, "rotation_ratio")
        check(self._w, lib.lc_world_set_damping(self._w, k, r))

    def set_elasticity(self, elasticity: float) -> None:
        check(self._w, lib.lc_world_set_elasticity(self._w, cv.real(elasticity, "elasticity")))

    # ---- time ----------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return lib.lc_world_get_time(self._w)

    def step(self, dt: float, steps: int = 1) -> None:
        """Advance by `steps` steps of dt seconds each."""
        h = cv.real(dt, "dt")
        for _ in range(cv.integer(steps, "steps")):
            _force.check_call(self, lib.lc_world_step(self._w, h))

    def set_force_callback(self, force: ForceFn | None, potential: PotentialFn | None = None) -> None:
        """A custom force law (collide/force.py): force(query) -> (n, 3) array of fx, fy, torque per
        body row, called at every force evaluation of a step; potential(query) -> its potential energy
        (J), added to energy.total. force=None removes the law. An exception in either fails the step
        (or the energy reading) with CollideError raised from it; a failed step is undone."""
        _force.set_force_callback(self, force, potential)

    # ---- bodies --------------------------------------------------------------------------------
    def _check_new_names(self, names: Sequence[str | None]) -> None:
        seen = set()
        for n in names:
            if n is None:
                continue
            cv.name(n)
            if n in self._by_name or n in seen:
                raise ValueError(f"a body named {n!r} already exists")
            seen.add(n)

    def _register(self, body_id: int, name: str | None, sync: bool = True) -> "Body":
        """Records a body's name. sync: the body was just added, so it holds the last state row (C
        appends rows in insertion order) and its name goes at the end of the row-order list; a full
        rebuild per body would make adding n bodies cost n^2."""
        if name is None:
            name = f"body{body_id}"
            while name in self._by_name:
                name += "_"
        self._rec[body_id] = _Record(name)
        self._by_name[name] = body_id
        if sync:
            self._names.append(name)
        return Body(self, body_id)

    def _sync_names(self) -> None:
        self._names = [self._rec[int(i)].name for i in self.ids]

    def add_body(self, vertices: Any, position: Any = (0.0, 0.0), angle: float = 0.0, velocity: Any = (0.0, 0.0),
                 angular_velocity: float = 0.0, mass: float = 1.0, elasticity: float = 1.0, friction: float = 0.0,
                 static: bool = False, name: str | None = None, inertia: float = 0.0,
                 center_of_mass: Any = None) -> "Body":
        """Add a convex polygon; vertices (k, 2) in the body frame, position = that frame's origin.

        inertia: kg*m^2 about the centre of mass, in (0, mass * r^2] (r: the farthest vertex from the
        centre of mass); 0 = the polygon's (uniform density). center_of_mass: (x, y) in the body frame,
        inside the polygon; None = the polygon's centroid."""
        pts = cv.points(vertices, "vertices")
        d = ffi.new("lc_body_def *", lib.lc_default_body_def())
        d.type = lib.LC_BODY_STATIC if cv.flag(static, "static") else lib.LC_BODY_DYNAMIC
        d.position.x, d.position.y = cv.vec2(position, "position")
        d.angle = cv.real(angle, "angle")
        d.velocity.x, d.velocity.y = cv.vec2(velocity, "velocity")
        d.angular_velocity = cv.real(angular_velocity, "angular_velocity")
        d.mass = cv.real(mass, "mass")
        d.elasticity = cv.real(elasticity, "elasticity")
        d.friction = cv.real(friction, "friction")
        d.inertia = cv.real(inertia, "inertia")
        if center_of_mass is not None:
            d.custom_center_of_mass = 1
            d.center_of_mass.x, d.center_of_mass.y = cv.vec2(center_of_mass, "center_of_mass")
        self._check_new_names([name])
        verts = ffi.new("lc_vec2[]", max(len(pts), 1))
        if len(pts):
            ffi.memmove(verts, ffi.from_buffer(pts), pts.nbytes)
        d.vertices = verts
        d.vertex_count = len(pts)
        out = ffi.new("lc_body_id *")
        check(self._w, lib.lc_world_add_body(self._w, d, out))
        return self._register(int(out[0]), name)

    def add_box(self, width: float, height: float, **kwargs: Any) -> "Body":
        """Add a width x height rectangle centred on its position; other arguments as add_body."""
        w, h = cv.real(width, "width"), cv.real(height, "height")
        out = ffi.new("lc_vec2[4]")
        status = lib.lc_make_rectangle(w, h, out)
        if status != lib.LC_OK:
            raise CollideError(status, f"cannot make a {w!r} x {h!r} rectangle: width and height must be finite and > 0")
        pts = np.frombuffer(ffi.buffer(out), dtype=np.float64).reshape(4, 2).copy()
        return self.add_body(pts, **kwargs)

    def add_walls(self, xmin: float, ymin: float, xmax: float, ymax: float, thickness: float = 1.0,
                  elasticity: float = 1.0, names: Iterable[str] = WALL_NAMES) -> list["Body"]:
        """Four static walls whose inner faces bound the rectangle; order bottom, right, top, left."""
        args = [cv.real(v, n) for v, n in ((xmin, "xmin"), (ymin, "ymin"), (xmax, "xmax"), (ymax, "ymax"),
                                           (thickness, "thickness"), (elasticity, "elasticity"))]
        names = list(names)
        if len(names) != 4:
            raise ValueError(f"names must hold 4 wall names (bottom, right, top, left), got {len(names)}")
        self._check_new_names(names)
        ids = ffi.new("lc_body_id[4]")
        check(self._w, lib.lc_world_add_walls(self._w, *args, ids))
        return [self._register(int(ids[i]), names[i]) for i in range(4)]

    def _id(self, body: BodyRef) -> int:
        if isinstance(body, Body):
            if body._world is not self:
                raise ValueError(f"body {body.id} belongs to another world")
            return body.id
        if isinstance(body, str):
            if body not in self._by_name:
                known = ", ".join(self._names[:12]) + (" ..." if len(self._names) > 12 else "")
                raise KeyError(f"no body named {body!r} (bodies: {known})")
            return self._by_name[body]
        return cv.integer(body, "body id")

    def body(self, ref: BodyRef) -> "Body":
        """The body with that name (or id)."""
        body_id = self._id(ref)
        if lib.lc_world_body_index(self._w, body_id) < 0:
            raise KeyError(f"no body with id {body_id}")
        return Body(self, body_id)

    def remove_body(self, ref: BodyRef) -> None:
        body_id = self._id(ref)
        check(self._w, lib.lc_world_remove_body(self._w, body_id))
        rec = self._rec.pop(body_id)
        del self._by_name[rec.name]
        self._springs = {n: s for n, s in self._springs.items() if self._spring_alive(s)}
        self._sync_names()

    @property
    def names(self) -> list[str]:
        """Body names in state-row order."""
        return list(self._names)

    @property
    def bodies(self) -> list["Body"]:
        return [Body(self, int(i)) for i in self.ids]

    def __len__(self) -> int:
        return lib.lc_world_body_count(self._w)

    def __contains__(self, name: str) -> bool:
        return name in self._by_name

    # ---- bulk state (zero-copy) -----------------------------------------------------------------
    def _state_view(self) -> Any:
        check(self._w, lib.lc_world_get_state(self._w, self._view))
        return self._view

    @property
    def state(self) -> np.ndarray:
        """(n, 6) read-only view: x, y, angle, vx, vy, omega of each centre of mass."""
        v = self._state_view()
        return _view(self, v.state, (v.count, 6), np.float64)

    @property
    def ids(self) -> np.ndarray:
        v = self._state_view()
        return _view(self, v.ids, (v.count,), np.uint32)

    @property
    def masses(self) -> np.ndarray:
        v = self._state_view()
        return _view(self, v.mass, (v.count,), np.float64)

    @property
    def inertias(self) -> np.ndarray:
        v = self._state_view()
        return _view(self, v.inertia, (v.count,), np.float64)

    @property
    def static_mask(self) -> np.ndarray:
        v = self._state_view()
        return _view(self, v.is_static, (v.count,), np.uint8).astype(bool)

    def set_state(self, state: Any) -> None:
        """Overwrite every dynamic body's state from an (n, 6) array (static rows ignored)."""
        arr = np.asarray(state)
        if arr.dtype.kind not in "iuf" or arr.dtype == np.bool_:
            raise TypeError(f"state must hold numbers, got dtype {arr.dtype}")
        n = len(self)
        if arr.shape != (n, 6):
            raise ValueError(f"state must have shape ({n}, 6), got {arr.shape}")
        arr = np.ascontiguousarray(arr, dtype=np.float64)
        check(self._w, lib.lc_world_set_state(self._w, ffi.cast("const double *", ffi.from_buffer(arr)), n))

    @property
    def contacts(self) -> np.ndarray:
        """Read-only structured view (CONTACT_DTYPE) of the last step's contacts; valid until the next step."""
        out = ffi.new("const lc_contact **")
        count = ffi.new("int *")
        check(self._w, lib.lc_world_get_contacts(self._w, out, count))
        return _view(self, out[0], (count[0],), CONTACT_DTYPE)

    def read_events(self, max_count: int | None = None) -> tuple[np.ndarray, int]:
        """The impacts of the steps since the last read, oldest first, removed from the stream
        (lc_world_get_events): (events, dropped). events is an EVENT_DTYPE array (a copy) of at most
        max_count rows (None: all unread); dropped counts the oldest events the stream let go since the
        last read because more than the world's event_capacity were unread."""
        pending = ffi.new("int *")
        dropped = ffi.new("uint64_t *")
        if max_count is None:
            check(self._w, lib.lc_world_get_events(self._w, ffi.NULL, 0, pending, ffi.NULL))
            cap = pending[0]
        else:
            cap = cv.integer(max_count, "max_count")
            if not 0 <= cap < 2**31:
                raise ValueError(f"max_count must be in [0, 2**31), got {cap}")
        out = np.zeros(cap, dtype=EVENT_DTYPE)
        if cap == 0:  # nothing to read: the C call with capacity 0 is a size query and clears nothing
            return out, 0
        check(self._w, lib.lc_world_get_events(self._w, ffi.cast("lc_impact_event *", ffi.from_buffer(out)), cap,
                                               pending, dropped))
        return out[: pending[0]], int(dropped[0])

    @property
    def pending_events(self) -> int:
        """Unread impact events (read_events returns them)."""
        pending = ffi.new("int *")
        check(self._w, lib.lc_world_get_events(self._w, ffi.NULL, 0, pending, ffi.NULL))
        return int(pending[0])

    @property
    def energy(self) -> Energy:
        e = ffi.new("lc_energy *")
        _force.check_call(self, lib.lc_world_get_energy(self._w, e))
        return Energy(e.translational, e.rotational, e.gravitational, e.spring, e.total,
                      _vec(e.linear_momentum), e.angular_momentum, e.callback)

    def set_stage_timing(self, on: bool) -> None:
        """Measure wall time per pipeline stage into the counters' time_* fields (s); off by default."""
        check(self._w, lib.lc_world_set_stage_timing(self._w, 1 if on else 0))

    @property
    def stage_timing(self) -> bool:
        """Whether set_stage_timing is on."""
        out = ffi.new("int *")
        check(self._w, lib.lc_world_get_stage_timing(self._w, out))
        return bool(out[0])

    def counters(self, last: bool = True) -> dict[str, Any]:
        """Work counters of the last step (last=True) or since creation (time_* in s: set_stage_timing)."""
        c = ffi.new("lc_counters *")
        if last:
            check(self._w, lib.lc_world_get_counters(self._w, c, ffi.NULL))
        else:
            check(self._w, lib.lc_world_get_counters(self._w, ffi.NULL, c))
        return {name: getattr(c, name) for name, _ in ffi.typeof("lc_counters").fields}

    def state_hash(self) -> int:
        return int(lib.lc_world_state_hash(self._w))

    # ---- snapshots (lc_world_save / lc_world_load, docs/events_and_snapshots.md) -------------------
    def save(self) -> bytes:
        """A snapshot of the world: loaded into any World (load, from_snapshot), it steps on bit for bit
        as this one does. Body and spring names are Python's and are not in it."""
        size = ffi.new("size_t *")
        check(self._w, lib.lc_world_save(self._w, ffi.NULL, 0, size))
        buf = ffi.new("unsigned char[]", max(int(size[0]), 1))
        check(self._w, lib.lc_world_save(self._w, buf, size[0], size))
        return bytes(ffi.buffer(buf, size[0]))

    def load(self, data: bytes | bytearray | memoryview) -> None:
        """Replace everything in this world by a snapshot (save). A body id this world names keeps its
        name, the others are named body<id>; unread impact events go. A truncated or corrupt snapshot
        raises CollideError (LC_ERR_BAD_SNAPSHOT) and leaves the world as it was."""
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise TypeError(f"a snapshot is bytes, got {type(data).__name__}")
        raw = bytes(data)
        check(self._w, lib.lc_world_load(self._w, raw, len(raw)))
        self._after_load()

    @classmethod
    def from_snapshot(cls, data: bytes | bytearray | memoryview) -> "World":
        """A new World loaded from a snapshot (save); bodies are named body<id>."""
        w = cls()
        w.load(data)
        return w

    def _after_load(self) -> None:
        old = {i: r.name for i, r in self._rec.items()}
        self._rec, self._by_name = {}, {}
        ids = [int(i) for i in self.ids]
        for i in ids:  # the kept names first, so a default name cannot take one
            if i in old:
                self._rec[i] = _Record(old[i])
                self._by_name[old[i]] = i
        for i in ids:
            if i not in self._rec:
                self._register(i, None, sync=False)
        self._sync_names()
        self._springs = {n: s for n, s in self._springs.items() if self._spring_alive(s)}
        self._poly_cache = None

    # ---- springs ---------------------------------------------------------------------------------
    def _spring_alive(self, spring_id: int) -> bool:
        d = ffi.new("lc_spring_def *")
        return lib.lc_spring_get_def(self._w, spring_id, d) == lib.LC_OK

    def add_spring(self, body_a: BodyRef, point_a: Any = (0.0, 0.0), body_b: BodyRef | None = None,
                   point_b: Any = (0.0, 0.0), stiffness: float = 3.0, damping: float = 0.0,
                   rest_length: float = 0.0, name: str | None = None) -> "Spring":
        """Spring from point_a (body_a frame) to point_b (body_b frame, or world when body_b is None)."""
        d = ffi.new("lc_spring_def *", lib.lc_default_spring_def())
        d.body_a = self._id(body_a)
        d.point_a.x, d.point_a.y = cv.vec2(point_a, "point_a")
        d.body_b = lib.LC_WORLD_ANCHOR if body_b is None else self._id(body_b)
        d.point_b.x, d.point_b.y = cv.vec2(point_b, "point_b")
        d.stiffness = cv.real(stiffness, "stiffness")
        d.damping = cv.real(damping, "damping")
        d.rest_length = cv.real(rest_length, "rest_length")
        if name is not None:
            cv.name(name, "spring name")
            if name in self._springs and self._spring_alive(self._springs[name]):
                raise ValueError(f"a spring named {name!r} already exists")
        out = ffi.new("lc_spring_id *")
        check(self._w, lib.lc_world_add_spring(self._w, d, out))
        if name is not None:
            self._springs[name] = int(out[0])
        return Spring(self, int(out[0]), name)

    def spring(self, name: str) -> "Spring":
        if name not in self._springs or not self._spring_alive(self._springs[name]):
            raise KeyError(f"no spring named {name!r}")
        return Spring(self, self._springs[name], name)

    def polygons(self) -> tuple[np.ndarray, np.ndarray]:
        """World vertices of every body at once: (vertices (K, 2), start (n + 1,)); body row i owns
        vertices[start[i]:start[i + 1]]. Computed with numpy from the state view and the local
        vertices (fetched from C only when bodies were added or removed)."""
        ids = self.ids
        cache = self._poly_cache
        if cache is None or not np.array_equal(cache[0], ids):
            local = [Body(self, int(i)).local_vertices() for i in ids]
            counts = np.array([len(v) for v in local], dtype=np.intp)
            start = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
            rows = np.repeat(np.arange(len(ids)), counts)
            table = np.concatenate(local) if local else np.zeros((0, 2))
            cache = self._poly_cache = (np.array(ids), table, rows, start)
        _, table, rows, start = cache
        st = self.state
        ang = st[rows, 2]
        c, s = np.cos(ang), np.sin(ang)
        out = np.empty_like(table)
        out[:, 0] = st[rows, 0] + c * table[:, 0] - s * table[:, 1]
        out[:, 1] = st[rows, 1] + s * table[:, 0] + c * table[:, 1]
        return out, start.copy()

    # ---- queries on the current poses (collide/query.h, collide/query.py) ------------------------
    def query_point(self, point: Iterable[float], skip_static: bool = False,
                    skip: BodyRef | None = None) -> list["Body"]:
        """Bodies containing point (boundary included), in row order; skip: a body left out."""
        return _query.query_point(self, point, skip_static, skip)

    def query_box(self, lower: Iterable[float], upper: Iterable[float], skip_static: bool = False,
                  skip: BodyRef | None = None) -> list["Body"]:
        """Bodies sharing a point with the axis-aligned box [lower, upper], in row order."""
        return _query.query_box(self, lower, upper, skip_static, skip)

    def ray_cast(self, start: Iterable[float], end: Iterable[float], skip_static: bool = False,
                 skip: BodyRef | None = None) -> RayHit | None:
        """First body the segment from start to end meets (RayHit), or None."""
        return _query.ray_cast(self, start, end, skip_static, skip)

    def ray_cast_all(self, start: Iterable[float], end: Iterable[float], skip_static: bool = False,
                     skip: BodyRef | None = None) -> list[RayHit]:
        """Every body the segment meets, one RayHit each, sorted by fraction."""
        return _query.ray_cast_all(self, start, end, skip_static, skip)

    def ray_cast_batch(self, starts: Any, ends: Any, skip_static: bool = False,
                       skip: BodyRef | None = None) -> RayHits:
        """The first hit of each segment starts[i] -> ends[i] ((n, 2) arrays; one (2,) start for all),
        one C call for all (RayHits of arrays by ray)."""
        return _query.ray_cast_batch(self, starts, ends, skip_static, skip)

    def body_distance(self, a: BodyRef, b: BodyRef) -> BodyDistance:
        """Distance of two bodies (< 0: minus the penetration depth), normal from a to b, closest points."""
        return _query.body_distance(self, a, b)

    def bodies_overlap(self, a: BodyRef, b: BodyRef) -> bool:
        """True when the two bodies share a point (touching counts)."""
        return _query.bodies_overlap(self, a, b)

    @property
    def spring_count(self) -> int:
        return lib.lc_world_spring_count(self._w)

    def __repr__(self) -> str:
        return f"<collide.World t={self.time:.6g} bodies={len(self)} springs={self.spring_count}>"
