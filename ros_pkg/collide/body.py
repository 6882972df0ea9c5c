"""Handles on the parts of a World: Body, Thruster, Spring."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Union

import numpy as np

from . import _convert as cv
from ._ffi import CollideError, check, ffi, lib

if TYPE_CHECKING:
    from .world import World

__all__ = ["Body", "Thruster", "Spring"]


def _vec(v: Any) -> tuple[float, float]:
    return (v.x, v.y)


class _Record:
    """What Python keeps about a body that C does not: its name. Everything else is read from C."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name


BodyRef = Union["Body", str, int]  # a Body, its name or its id


class Body:
    """A handle on one body of a World (cheap; two handles on the same id are equal)."""

    __slots__ = ("_world", "id")

    def __init__(self, world: World, body_id: int) -> None:
        self._world, self.id = world, body_id

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Body) and other._world is self._world and other.id == self.id

    def __hash__(self) -> int:
        return hash((id(self._world), self.id))

    def __repr__(self) -> str:
        rec = self._world._rec.get(self.id)
        return f"<collide.Body {rec.name if rec else '?'} id={self.id}>"

    @property
    def _w(self) -> Any:
        return self._world._w

    @property
    def world(self) -> World:
        return self._world

    @property
    def index(self) -> int:
        i = lib.lc_world_body_index(self._w, self.id)
        if i < 0:
            raise CollideError(lib.LC_ERR_UNKNOWN_BODY, f"body {self.id} is not in this world (removed?)")
        return i

    @property
    def name(self) -> str:
        self.index  # raises if removed
        return self._world._rec[self.id].name

    def _row(self) -> np.ndarray:
        return self._world.state[self.index]

    @property
    def position(self) -> tuple[float, float]:
        r = self._row()
        return (float(r[0]), float(r[1]))

    @property
    def angle(self) -> float:
        return float(self._row()[2])

    @property
    def velocity(self) -> tuple[float, float]:
        r = self._row()
        return (float(r[3]), float(r[4]))

    @property
    def angular_velocity(self) -> float:
        return float(self._row()[5])

    def _read(self, fn: Any) -> float:
        out = ffi.new("double *")
        check(self._w, fn(self._w, self.id, out))
        return float(out[0])

    @property
    def mass(self) -> float:
        """kg (0 for a static body); setting it keeps the inertia per unit mass."""
        return self._read(lib.lc_body_get_mass)

    @mass.setter
    def mass(self, value: float) -> None:
        check(self._w, lib.lc_body_set_mass(self._w, self.id, cv.real(value, "mass")))

    @property
    def inertia(self) -> float:
        """kg*m^2 about the centre of mass (0 for a static body); set it in (0, mass * r^2], r the farthest
        vertex from the centre of mass, or to 0 for the polygon's (uniform density)."""
        return self._read(lib.lc_body_get_inertia)

    @inertia.setter
    def inertia(self, value: float) -> None:
        check(self._w, lib.lc_body_set_inertia(self._w, self.id, cv.real(value, "inertia")))

    @property
    def static(self) -> bool:
        return bool(self._world.static_mask[self.index])

    @property
    def material(self) -> tuple[float, float]:
        """(elasticity, friction)."""
        e, f = ffi.new("double *"), ffi.new("double *")
        check(self._w, lib.lc_body_get_material(self._w, self.id, e, f))
        return float(e[0]), float(f[0])

    @property
    def elasticity(self) -> float:
        return self.material[0]

    @property
    def friction(self) -> float:
        return self.material[1]

    def set_material(self, elasticity: float | None = None, friction: float | None = None) -> None:
        """Set elasticity [0, 1] and/or friction [0, 10]; None keeps the current value."""
        e0, f0 = self.material
        e = e0 if elasticity is None else cv.real(elasticity, "elasticity")
        f = f0 if friction is None else cv.real(friction, "friction")
        check(self._w, lib.lc_body_set_material(self._w, self.id, e, f))

    def set_pose(self, position: Any, angle: float) -> None:
        """Set the centre-of-mass position (m) and angle (rad)."""
        x, y = cv.vec2(position, "position")
        check(self._w, lib.lc_body_set_pose(self._w, self.id, (x, y), cv.real(angle, "angle")))

    def set_velocity(self, velocity: Any, angular_velocity: float = 0.0) -> None:
        vx, vy = cv.vec2(velocity, "velocity")
        check(self._w, lib.lc_body_set_velocity(self._w, self.id, (vx, vy),
                                                cv.real(angular_velocity, "angular_velocity")))

    def set_external(self, force: Any = (0.0, 0.0), torque: float = 0.0) -> None:
        """Constant external force (N, world frame, at the centre of mass) and torque (N*m)."""
        fx, fy = cv.vec2(force, "force")
        check(self._w, lib.lc_body_set_external(self._w, self.id, (fx, fy), cv.real(torque, "torque")))

    @property
    def external(self) -> tuple[tuple[float, float], float]:
        """(force (N, world frame), torque (N*m)) set by set_external."""
        f, t = ffi.new("lc_vec2 *"), ffi.new("double *")
        check(self._w, lib.lc_body_get_external(self._w, self.id, f, t))
        return _vec(f), float(t[0])

    def _vertices(self, fn: Any) -> np.ndarray:
        n = lib.lc_body_vertex_count(self._w, self.id)
        if n < 0:
            raise CollideError(lib.LC_ERR_UNKNOWN_BODY, f"body {self.id} is not in this world (removed?)")
        out = ffi.new("lc_vec2[]", n)
        check(self._w, fn(self._w, self.id, out, n))
        return np.frombuffer(ffi.buffer(out), dtype=np.float64).reshape(n, 2).copy()

    def world_vertices(self) -> np.ndarray:
        """(k, 2) vertices in world coordinates (m)."""
        return self._vertices(lib.lc_body_get_world_vertices)

    def local_vertices(self) -> np.ndarray:
        """(k, 2) vertices relative to the centre of mass, body frame (m)."""
        return self._vertices(lib.lc_body_get_local_vertices)

    @property
    def center_offset(self) -> tuple[float, float]:
        """Offset (body frame, m) from the local-frame origin to the centre of mass."""
        out = ffi.new("lc_vec2 *")
        check(self._w, lib.lc_body_get_center_offset(self._w, self.id, out))
        return _vec(out)

    @property
    def center_of_mass(self) -> tuple[float, float]:
        """The centre of mass in the body's local frame (m): the given one, or the polygon's centroid.
        The same point as center_offset."""
        return self.center_offset

    # ---- thrusters ----
    def add_thruster(self, point: Any, direction: Any, magnitude: float) -> "Thruster":
        d = ffi.new("lc_thruster_def *")
        d.point.x, d.point.y = cv.vec2(point, "point")
        d.direction.x, d.direction.y = cv.vec2(direction, "direction")
        d.magnitude = cv.real(magnitude, "magnitude")
        idx = ffi.new("int *")
        check(self._w, lib.lc_body_add_thruster(self._w, self.id, d, idx))
        return Thruster(self, int(idx[0]))

    def add_default_thrusters(self, thrust: float = 1.5) -> list["Thruster"]:
        """myPhysicsLab's four: 0 left, 1 right, 2 up, 3 down (keys S,F,E,D / J,L,I,K)."""
        first = ffi.new("int *")
        check(self._w, lib.lc_body_add_default_thrusters(self._w, self.id, cv.real(thrust, "thrust"), first))
        return [Thruster(self, int(first[0]) + i) for i in range(4)]

    @property
    def thrusters(self) -> list["Thruster"]:
        n = lib.lc_body_thruster_count(self._w, self.id)
        if n < 0:
            raise CollideError(lib.LC_ERR_UNKNOWN_BODY, f"body {self.id} is not in this world (removed?)")
        return [Thruster(self, i) for i in range(n)]

    def set_thruster_mask(self, mask: int) -> None:
        m = cv.integer(mask, "mask")
        if not 0 <= m < 2**32:
            raise ValueError(f"mask must fit 32 bits, got {m}")
        check(self._w, lib.lc_body_set_thruster_mask(self._w, self.id, m))

    @property
    def thruster_mask(self) -> int:
        """Bit i on when thruster i fires (level > 0)."""
        out = ffi.new("uint32_t *")
        check(self._w, lib.lc_body_get_thruster_mask(self._w, self.id, out))
        return int(out[0])


class Thruster:
    __slots__ = ("body", "index")

    def __init__(self, body: Body, index: int) -> None:
        self.body, self.index = body, index

    def __repr__(self) -> str:
        try:
            level = f"level={self.level}"
        except CollideError:  # the body or the thruster is gone
            level = "gone"
        return f"<collide.Thruster {self.body!r}[{self.index}] {level}>"

    @property
    def level(self) -> float:
        """0 = off, 1 = full magnitude."""
        w = self.body.world
        out = ffi.new("double *")
        check(w._w, lib.lc_body_get_thruster_level(w._w, self.body.id, self.index, out))
        return float(out[0])

    @level.setter
    def level(self, value: float) -> None:
        lvl = cv.real(value, "level")
        w = self.body.world
        check(w._w, lib.lc_body_set_thruster_level(w._w, self.body.id, self.index, lvl))


class Spring:
    __slots__ = ("_world", "id", "name")

    def __init__(self, world: World, spring_id: int, name: str | None = None) -> None:
        self._world, self.id, self.name = world, spring_id, name

    def __repr__(self) -> str:
        return f"<collide.Spring {self.name or ''} id={self.id}>"

    def _def(self) -> Any:
        d = ffi.new("lc_spring_def *")
        check(self._world._w, lib.lc_spring_get_def(self._world._w, self.id, d))
        return d

    @property
    def definition(self) -> dict[str, Any]:
        d = self._def()
        anchored = d.body_b == lib.LC_WORLD_ANCHOR
        return {"body_a": int(d.body_a), "point_a": _vec(d.point_a), "body_b": None if anchored else int(d.body_b),
                "point_b": _vec(d.point_b), "stiffness": d.stiffness, "damping": d.damping,
                "rest_length": d.rest_length}

    @property
    def target(self) -> tuple[float, float] | None:
        """World anchor point of a world-anchored spring (None if attached to a second body)."""
        d = self._def()
        return _vec(d.point_b) if d.body_b == lib.LC_WORLD_ANCHOR else None

    @target.setter
    def target(self, point: Any) -> None:
        x, y = cv.vec2(point, "target")
        check(self._world._w, lib.lc_spring_set_target(self._world._w, self.id, (x, y)))

    def set_params(self, stiffness: float, damping: float, rest_length: float) -> None:
        check(self._world._w, lib.lc_spring_set_params(
            self._world._w, self.id, cv.real(stiffness, "stiffness"), cv.real(damping, "damping"),
            cv.real(rest_length, "rest_length")))

    def endpoints(self) -> tuple[tuple[float, float], tuple[float, float]]:
        a, b = ffi.new("lc_vec2 *"), ffi.new("lc_vec2 *")
        check(self._world._w, lib.lc_spring_get_endpoints(self._world._w, self.id, a, b))
        return _vec(a), _vec(b)

    def remove(self) -> None:
        check(self._world._w, lib.lc_world_remove_spring(self._world._w, self.id))
        if self.name is not None and self._world._springs.get(self.name) == self.id:
            del self._world._springs[self.name]
