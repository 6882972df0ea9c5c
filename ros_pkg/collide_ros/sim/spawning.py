"""``~/spawn``: a box (width x height) or a convex polygon added at a pose with a twist, mass and
elasticity, refused with its reason when the name is taken or not a topic token, a number is not
finite, the body would reach outside the box the static bodies enclose, or would overlap another
body (touching is allowed: a box set down on the floor); C refuses bad shapes and values itself."""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from libcollide_msgs.srv import Spawn

import collide
from collide import CollideError

from collide_ros import params
from collide_ros.sim.guards import finite

# Depth (m) below which two polygons count as touching, not overlapping: the spawned polygon's vertices
# are rotated and moved here and again in C, each to round-off (~1e-15 m on a scene of 10 m), so a body
# set exactly onto another may come out a few ulp into it.
TOUCH_DEPTH = 1e-12


def yaw(q: Any) -> float:
    """The rotation about z of the quaternion ``q`` (rad)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def overlapped_body(world: collide.World, placed: np.ndarray) -> str | None:
    """The name of the first body (row order) that the convex polygon ``placed`` ((k, 2), world frame)
    would overlap by more than TOUCH_DEPTH, or None.

    The world's box query finds the bodies that meet the polygon's bounding box; the distance query
    decides for each, in a scratch world of static bodies (the polygon and a copy of the body), so the
    sim's world is not touched. A polygon C does not take is left to add_body, which says why."""
    try:
        near = world.query_box(placed.min(axis=0), placed.max(axis=0))
        if not near:
            return None
        probe = collide.World()
        cand = probe.add_body(placed, static=True)
        for body in near:
            other = probe.add_body(body.world_vertices(), static=True)
            if probe.body_distance(cand, other).distance < -TOUCH_DEPTH:
                return body.name
    except CollideError:
        return None
    return None


class Spawning:
    """~/spawn; it owns no state (the world's body set is topology.py's)."""

    def _srv_spawn(self, req: Spawn.Request, resp: Spawn.Response) -> Spawn.Response:
        resp.success = False
        name = req.name
        if not name:
            k = 1
            while f"body{k}" in self._row_of:
                k += 1
            name = f"body{k}"
        why = params.valid_body_name(name)
        if why:
            resp.message = why
            return resp
        if name in self._row_of:
            resp.message = f"a body named '{name}' already exists"
            return resp
        if len(req.vertices) > 0:
            if len(req.vertices) % 2:
                resp.message = f"vertices must hold x,y pairs; got {len(req.vertices)} numbers"
                return resp
            verts = np.asarray(req.vertices, dtype=np.float64).reshape(-1, 2)
        else:
            w, h = float(req.width), float(req.height)
            if w == 0.0 and h == 0.0:
                w = h = 1.0
            if not (finite(w, h) and w > 0 and h > 0):
                resp.message = f"box width {w} and height {h} must be finite and > 0"
                return resp
            verts = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
        p, q, tw = req.pose.position, req.pose.orientation, req.twist
        nums = (p.x, p.y, q.x, q.y, q.z, q.w, tw.linear.x, tw.linear.y, tw.angular.z, req.mass, req.elasticity)
        if not finite(*nums):
            resp.message = "pose, twist, mass and elasticity must be finite"
            return resp
        angle = yaw(q)
        mass = float(req.mass) if req.mass != 0.0 else 1.0
        if np.all(np.isfinite(verts)) and len(verts) >= 3:
            c, s = math.cos(angle), math.sin(angle)
            placed = verts @ np.array([[c, s], [-s, c]]) + np.array([p.x, p.y])
            outside = self._outside_static_extent(placed.min(axis=0), placed.max(axis=0))
            if outside:
                resp.message = f"spawn '{name}' at ({p.x:g}, {p.y:g}) {outside}"
                self._warn(f"spawn:outside:{name}", f"rejected: {resp.message}")
                return resp
            other = overlapped_body(self.world, placed)
            if other is not None:
                resp.message = f"spawn '{name}' at ({p.x:g}, {p.y:g}) overlaps body '{other}'"
                self._warn(f"spawn:overlap:{name}", f"rejected: {resp.message}")
                return resp
        try:
            self.world.add_body(verts, position=(p.x, p.y), angle=angle, velocity=(tw.linear.x, tw.linear.y),
                                angular_velocity=tw.angular.z, mass=mass, elasticity=float(req.elasticity),
                                name=name)
        except (CollideError, ValueError, TypeError) as exc:
            resp.message = f"spawn '{name}': {exc}"
            self._warn(f"spawn:c:{name}", f"rejected: {resp.message}")
            return resp
        self._on_topology()
        resp.success = True
        resp.name = name
        resp.message = f"spawned '{name}'"
        return resp

    def _outside_static_extent(self, lo: np.ndarray, hi: np.ndarray) -> str | None:
        """Why a body with bounds [lo, hi] lies (partly) outside the box the static bodies enclose, or None.

        The static bodies (walls, floor, fixed obstacles) bound the world; a body placed beyond them would
        fall or fly away for ever. A world without static bodies has no such bound."""
        extent = [self._bodies[n].world_vertices() for n in self._names if self._bodies[n].static]
        if not extent:
            return None
        pts = np.vstack(extent)
        smin, smax = pts.min(axis=0), pts.max(axis=0)
        if np.all(lo >= smin) and np.all(hi <= smax):
            return None
        return (f"lies outside the box the static bodies enclose (x in [{smin[0]:g}, {smax[0]:g}], "
                f"y in [{smin[1]:g}, {smax[1]:g}])")
