"""Geometric queries on a World's current poses (the C API of collide/query.h): the bodies at a point or
sharing a point with a box, ray casts (first hit, or every hit sorted along the ray), and the overlap and
distance of two bodies; also the first hits of many rays in one call (a laser scan). Bodies are closed
polygons: a point on an edge is in the body, touching counts as overlapping. The World methods of the
same names call these; see docs/queries.md."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Iterable

import numpy as np
from numpy.typing import ArrayLike

from . import _convert as cv
from ._ffi import check, ffi, lib
from ._views import _struct_dtype
from .body import Body, BodyRef, _vec

if TYPE_CHECKING:
    from .world import World

__all__ = ["RayHit", "RayHits", "BodyDistance", "query_point", "query_box", "ray_cast", "ray_cast_all",
           "ray_cast_batch", "body_distance", "bodies_overlap"]

_RAY_HIT_DTYPE = _struct_dtype("lc_ray_hit", {"body": np.uint32, "point": (np.float64, (2,)),
                                              "normal": (np.float64, (2,)), "fraction": np.float64})


@dataclass(frozen=True)
class RayHit:
    """Where a ray from start to end enters a body."""

    body: Body
    point: tuple[float, float]   # m, world: start + fraction * (end - start)
    normal: tuple[float, float]  # unit outward normal of the edge entered; -direction for a ray starting in the body
    fraction: float              # [0, 1] along the ray; 0 when it starts inside or on the body


@dataclass(frozen=True)
class RayHits:
    """The first hit of each ray of a batch (ray_cast_batch), as arrays indexed by ray."""

    found: np.ndarray     # (n,) bool
    body: np.ndarray      # (n,) uint32 body id, 0 where nothing was hit
    point: np.ndarray     # (n, 2) m, world; nan where nothing was hit
    normal: np.ndarray    # (n, 2) unit; nan where nothing was hit
    fraction: np.ndarray  # (n,) along each ray, [0, 1]; nan where nothing was hit


@dataclass(frozen=True)
class BodyDistance:
    """How far apart two bodies a and b are."""

    distance: float               # m: > 0 apart, 0 touching, < 0 overlapping (minus the penetration depth)
    normal: tuple[float, float]   # unit, from a towards b
    point_a: tuple[float, float]  # m, world; point_b - point_a = distance * normal
    point_b: tuple[float, float]


def _filter(world: World, skip_static: bool, skip: BodyRef | None) -> Any:
    f = ffi.new("lc_query_filter *")
    f.skip_static = 1 if cv.flag(skip_static, "skip_static") else 0
    f.skip_body = 0 if skip is None else world._id(skip)
    return f


def _listing(world: World, ctype: str, fn: Any, args: tuple[Any, ...], skip_static: bool,
             skip: BodyRef | None) -> tuple[Any, int]:
    """Calls fn(world, *args, filter, out, capacity, out_count) with room for every body: (out, count)."""
    f = _filter(world, skip_static, skip)
    n = len(world)
    out, count = ffi.new(f"{ctype}[]", max(n, 1)), ffi.new("int *")
    check(world._w, fn(world._w, *args, f, out, n, count))
    return out, count[0]


def query_point(world: World, point: Iterable[float], skip_static: bool = False,
                skip: BodyRef | None = None) -> list[Body]:
    """The bodies containing point (boundary included), in row order."""
    args = (cv.vec2(point, "point"),)
    out, n = _listing(world, "lc_body_id", lib.lc_world_query_point, args, skip_static, skip)
    return [Body(world, int(out[i])) for i in range(n)]


def query_box(world: World, lower: Iterable[float], upper: Iterable[float], skip_static: bool = False,
              skip: BodyRef | None = None) -> list[Body]:
    """The bodies sharing a point with the axis-aligned box [lower, upper], in row order."""
    args = (cv.vec2(lower, "lower"), cv.vec2(upper, "upper"))
    out, n = _listing(world, "lc_body_id", lib.lc_world_query_box, args, skip_static, skip)
    return [Body(world, int(out[i])) for i in range(n)]


def _hit(world: World, h: Any) -> RayHit:
    return RayHit(Body(world, int(h.body)), _vec(h.point), _vec(h.normal), h.fraction)


def ray_cast(world: World, start: Iterable[float], end: Iterable[float], skip_static: bool = False,
             skip: BodyRef | None = None) -> RayHit | None:
    """The first body the segment from start to end meets, or None."""
    a, b = cv.vec2(start, "start"), cv.vec2(end, "end")
    f = _filter(world, skip_static, skip)
    hit, found = ffi.new("lc_ray_hit *"), ffi.new("int *")
    check(world._w, lib.lc_world_ray_cast(world._w, a, b, f, hit, found))
    return _hit(world, hit) if found[0] else None


def ray_cast_all(world: World, start: Iterable[float], end: Iterable[float], skip_static: bool = False,
                 skip: BodyRef | None = None) -> list[RayHit]:
    """Every body the segment meets, one hit each, sorted by fraction (ties: the body added first)."""
    args = (cv.vec2(start, "start"), cv.vec2(end, "end"))
    out, n = _listing(world, "lc_ray_hit", lib.lc_world_ray_cast_all, args, skip_static, skip)
    return [_hit(world, out[i]) for i in range(n)]


def ray_cast_batch(world: World, starts: ArrayLike, ends: ArrayLike, skip_static: bool = False,
                   skip: BodyRef | None = None) -> RayHits:
    """The first hit of each segment from starts[i] to ends[i] ((n, 2) arrays, or one (2,) start for
    all), in one C call (lc_world_ray_cast_batch): each answer is ray_cast's, bit for bit."""
    b = np.ascontiguousarray(ends, dtype=np.float64)
    if b.ndim != 2 or b.shape[1] != 2:
        raise ValueError(f"ends must be an (n, 2) array, got shape {b.shape}")
    a0 = np.asarray(starts, dtype=np.float64)
    if a0.shape not in ((2,), b.shape):
        raise ValueError(f"starts must be a (2,) point or an array of the shape of ends {b.shape}, got {a0.shape}")
    a = np.ascontiguousarray(np.broadcast_to(a0, b.shape))
    n = len(b)
    if n >= 2**31:
        raise ValueError(f"at most 2**31 - 1 rays per call, got {n}")
    f = _filter(world, skip_static, skip)
    hits = np.zeros(n, dtype=_RAY_HIT_DTYPE)
    found = np.zeros(n, dtype=np.intc)
    check(world._w, lib.lc_world_ray_cast_batch(
        world._w, ffi.cast("lc_vec2 *", ffi.from_buffer(a)), ffi.cast("lc_vec2 *", ffi.from_buffer(b)), n, f,
        ffi.cast("lc_ray_hit *", ffi.from_buffer(hits)), ffi.cast("int *", ffi.from_buffer(found))))
    hit = found.astype(bool)
    point, normal, fraction = hits["point"].copy(), hits["normal"].copy(), hits["fraction"].copy()
    point[~hit] = normal[~hit] = np.nan
    fraction[~hit] = np.nan
    return RayHits(hit, hits["body"].copy(), point, normal, fraction)


def body_distance(world: World, a: BodyRef, b: BodyRef) -> BodyDistance:
    """Distance (negative: penetration depth), normal from a to b and closest points of two bodies."""
    r = ffi.new("lc_distance_result *")
    check(world._w, lib.lc_body_distance(world._w, world._id(a), world._id(b), r))
    return BodyDistance(r.distance, _vec(r.normal), _vec(r.point_a), _vec(r.point_b))


def bodies_overlap(world: World, a: BodyRef, b: BodyRef) -> bool:
    """True when the two bodies share at least one point (touching counts)."""
    out = ffi.new("int *")
    check(world._w, lib.lc_body_overlap(world._w, world._id(a), world._id(b), out))
    return bool(out[0])
