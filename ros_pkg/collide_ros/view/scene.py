"""What the view knows of the sim, built from the node's topics (pure Python, no ROS calls).

Shapes come from ``markers`` (ns ``bodies``: one outline per body in the body frame, id = body id,
in the node's row order; transient local, so a late view still gets them). Names and fresh poses
come from ``bodies/states`` (the dynamic bodies only, also in row order, at ``state_rate``). A
markers message and a states message of the same step carry bit-identical poses, so the dynamic
bodies among the markers are found by matching poses in order; the rest are static (walls).
"""
from __future__ import annotations

import math
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

Pose = tuple[float, float, float]  # x, y, yaw

DELETEALL = 3
ADD = 0
CONTACT_HOLD = 0.15   # s (wall): an impact stays visible this long (it lasts one state message)
MAX_CONTACTS = 500    # drawn per frame


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def hex_color(c: Any) -> str:
    def ch(v: float) -> int:
        return max(0, min(255, int(round(255 * float(v)))))
    return f"#{ch(c.r):02x}{ch(c.g):02x}{ch(c.b):02x}"


@dataclass
class Shape:
    id: int
    verts: list[list[float]]      # body frame, about the centre of mass
    color: str
    pose: Pose                    # from the markers message


def match_rows(marker_poses: list[Pose], state_poses: list[Pose], tol: float = 1e-9) -> list[int] | None:
    """Indices into marker_poses of the state bodies, matched in order (both lists are in the node's
    row order, the states a subsequence); None if some state body has no marker at the same pose."""
    out: list[int] = []
    i = 0
    for sx, sy, _ in state_poses:
        while i < len(marker_poses) and not (abs(marker_poses[i][0] - sx) <= tol
                                             and abs(marker_poses[i][1] - sy) <= tol):
            i += 1
        if i == len(marker_poses):
            return None
        out.append(i)
        i += 1
    return out


@dataclass
class SceneState:
    """Latest view of the sim; every method runs under the bridge's lock."""

    shapes: "OrderedDict[int, Shape]" = field(default_factory=OrderedDict)
    shapes_version: int = 0
    names: list[str] = field(default_factory=list)          # dynamic bodies, row order (bodies/states)
    poses: dict[str, Pose] = field(default_factory=dict)
    twists: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    name_of: dict[int, str] = field(default_factory=dict)   # marker id -> dynamic body name
    matched: bool = False
    sim_time: float | None = None
    springs: list[list[float]] = field(default_factory=list)  # [x0, y0, x1, y1]
    energy: dict[str, float] | None = None
    energy_start: float | None = None
    contacts: list[tuple[float, list[list[float]]]] = field(default_factory=list)  # (wall time, points)
    marker_stamp: float | None = None
    # stamp -> (names, poses) of the states messages received lately
    _states_by_stamp: "OrderedDict[float, tuple[tuple[str, ...], list[Pose]]]" = field(default_factory=OrderedDict)
    _rtf_ref: tuple[float, float] | None = None
    rtf: float | None = None
    seq: int = 0  # bumps on every change worth sending
    resets: int = 0  # DELETEALL markers seen (a reset, a kill, a new node)

    # ---------------------------------------------------------------- input
    def on_states(self, stamp: float, names: list[str], poses: list[Pose],
                  twists: list[tuple[float, float, float]], wall: float | None = None) -> None:
        wall = time.monotonic() if wall is None else wall
        if self.sim_time is not None and stamp < self.sim_time:
            self.restarted()  # a new node: sim time went back (a reset keeps the clock running)
        if names != self.names:
            self.names = list(names)
            self.matched = False
            self.poses = {}
        self.poses = dict(zip(names, poses))
        self.twists = dict(zip(names, twists))
        self.sim_time = stamp
        self._states_by_stamp[stamp] = (tuple(names), list(poses))
        while len(self._states_by_stamp) > 100:
            self._states_by_stamp.popitem(last=False)
        if not self.matched and self.marker_stamp == stamp:
            self._match(list(poses))
        if self._rtf_ref is None or wall < self._rtf_ref[0]:
            self._rtf_ref = (wall, stamp)
        elif wall - self._rtf_ref[0] >= 0.5:
            self.rtf = (stamp - self._rtf_ref[1]) / (wall - self._rtf_ref[0])
            self._rtf_ref = (wall, stamp)
        self.seq += 1

    def on_markers(self, stamp: float | None, markers: list[Any]) -> None:
        """markers: visualization_msgs/Marker objects of one MarkerArray."""
        changed = False
        springs: list[list[float]] | None = None
        seen: set[int] = set()
        for m in markers:
            if m.action == DELETEALL:  # the node was (re)built: a reset or a new node
                self.restarted()
                self.resets += 1
                self.shapes.clear()
                self.name_of.clear()
                self.matched = False
                self.springs = []
                changed = True
                continue
            if m.ns == "bodies":
                p = m.pose
                pose = (p.position.x, p.position.y, yaw_of(p.orientation))
                old = self.shapes.get(m.id)
                if m.action != ADD:
                    if self.shapes.pop(m.id, None) is not None:
                        changed = True
                    continue
                seen.add(m.id)
                if old is None or len(old.verts) + 1 != len(m.points):
                    pts = [[q.x, q.y] for q in m.points]
                    if len(pts) > 1 and pts[0] == pts[-1]:
                        pts = pts[:-1]  # the closed loop's repeated first point
                    self.shapes[m.id] = Shape(m.id, pts, hex_color(m.color), pose)
                    changed = True
                else:
                    old.pose = pose
                    old.color = hex_color(m.color)
            elif m.ns == "springs":
                springs = springs if springs is not None else []
                if m.action == ADD and len(m.points) >= 2:
                    a, b = m.points[0], m.points[1]
                    springs.append([a.x, a.y, b.x, b.y])
        # a markers message carries every body (a body gone without DELETEALL: killed) and every spring
        if seen and not seen.issuperset(self.shapes):
            for gone in set(self.shapes) - seen:
                del self.shapes[gone]
            changed = True
        self.springs = springs or []
        if changed:
            self.shapes_version += 1
            self.matched = False
        self.marker_stamp = stamp
        if not self.matched and self.names:
            got = self._states_by_stamp.get(stamp) if stamp is not None else None
            # the states of this step, unless the bodies changed in it (a spawn between two steps
            # keeps the stamp): then the latest states, which match if nothing moved (e.g. paused)
            if got is not None and got[0] == tuple(self.names):
                self._match(got[1])
            else:
                self._match([self.poses[n] for n in self.names])
        self.seq += 1

    def _match(self, state_poses: list[Pose]) -> None:
        """Name the shapes of the dynamic bodies; ``state_poses`` in the order of self.names."""
        shapes = list(self.shapes.values())
        rows = match_rows([s.pose for s in shapes], state_poses)
        if rows is None or len(rows) != len(self.names):
            return
        self.name_of = {shapes[i].id: name for i, name in zip(rows, self.names)}
        self.matched = True
        self.shapes_version += 1

    def on_energy(self, values: dict[str, float]) -> None:
        self.energy = values
        if self.energy_start is None:
            self.energy_start = values["total"]
        self.seq += 1

    def on_contacts(self, points: list[list[float]], wall: float | None = None) -> None:
        wall = time.monotonic() if wall is None else wall
        self.contacts.append((wall, points[:MAX_CONTACTS]))
        self.contacts = [c for c in self.contacts if wall - c[0] <= CONTACT_HOLD][-20:]
        self.seq += 1

    def restarted(self) -> None:
        """Sim time went back (reset or a new node): forget what belongs to the old run."""
        self.energy_start = None
        self.energy = None
        self.contacts = []
        self._states_by_stamp.clear()
        self._rtf_ref = None
        self.rtf = None

    def gone(self) -> None:
        """The node left the graph."""
        self.restarted()
        self.sim_time = None
        self.names = []
        self.poses = {}
        self.matched = False
        self.seq += 1

    # ---------------------------------------------------------------- output
    def dynamic_bodies(self) -> frozenset[str]:
        return frozenset(self.names)

    def shapes_message(self) -> dict[str, Any]:
        bodies = []
        for s in self.shapes.values():
            name = self.name_of.get(s.id)
            bodies.append({"id": s.id, "name": name, "static": self.matched and name is None,
                           "color": s.color, "verts": s.verts})
        return {"type": "shapes", "version": self.shapes_version, "bodies": bodies}

    def state_message(self, wall: float | None = None) -> dict[str, Any]:
        wall = time.monotonic() if wall is None else wall
        poses = []
        for s in self.shapes.values():
            name = self.name_of.get(s.id)
            p = self.poses.get(name, s.pose) if name is not None else s.pose
            poses.append([p[0], p[1], p[2]])
        pts = [p for t, ps in self.contacts if wall - t <= CONTACT_HOLD for p in ps][:MAX_CONTACTS]
        e = self.energy
        energy = None if e is None else {**e, "start": self.energy_start}
        return {"type": "state", "version": self.shapes_version, "t": self.sim_time, "rtf": self.rtf,
                "resets": self.resets, "poses": poses, "contacts": pts, "springs": self.springs, "energy": energy,
                "velocities": {n: list(v) for n, v in self.twists.items()}}
