"""What the view knows of the sim, built from the node's topics (no ROS calls; the messages come
read by cdr_in.py, the bulk of them as numpy arrays).

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

import numpy as np

from collide_ros.view.cdr_in import Markers

Pose = tuple[float, float, float]  # x, y, yaw

CONTACT_HOLD = 0.15   # s (wall): an impact stays visible this long (it lasts one state message)
MAX_CONTACTS = 500    # drawn per frame


def yaw_of(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


@dataclass
class Shape:
    id: int
    verts: list[list[float]]      # body frame, about the centre of mass
    color: str


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


def _rows(poses: Any) -> np.ndarray:
    return np.asarray(poses, dtype=np.float64).reshape(-1, 3)


@dataclass
class SceneState:
    """Latest view of the sim; every method runs under the bridge's lock."""

    shapes: "OrderedDict[int, Shape]" = field(default_factory=OrderedDict)
    marker_poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # shapes order, from markers
    shapes_version: int = 0
    names: tuple[str, ...] = ()                               # dynamic bodies, row order (bodies/states)
    poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))   # rows of names: x, y, yaw
    twists: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # vx, vy, omega
    name_of: dict[int, str] = field(default_factory=dict)   # marker id -> dynamic body name
    matched: bool = False
    sim_time: float | None = None
    springs: list[list[float]] = field(default_factory=list)  # [x0, y0, x1, y1]
    energy: dict[str, float] | None = None
    energy_start: float | None = None
    contacts: list[tuple[float, np.ndarray]] = field(default_factory=list)  # (wall time, (m, 2) points)
    marker_stamp: float | None = None
    # stamp -> (names, poses) of the states messages received lately
    _states_by_stamp: "OrderedDict[float, tuple[tuple[str, ...], np.ndarray]]" = field(default_factory=OrderedDict)
    _rtf_ref: tuple[float, float] | None = None
    rtf: float | None = None
    seq: int = 0  # bumps on every change worth sending
    resets: int = 0  # DELETEALL markers seen (a reset, a kill, a new node)
    _layout: object = None  # cdr_in's layout of the markers the shapes came from
    _index: tuple[np.ndarray, np.ndarray] | None = None  # (shape rows, state rows) of the named bodies

    # ---------------------------------------------------------------- input
    def on_states(self, stamp: float, names: Any, poses: Any, twists: Any, wall: float | None = None) -> None:
        """names: sequence of str; poses, twists: (n, 3) array-likes in the order of names."""
        wall = time.monotonic() if wall is None else wall
        if self.sim_time is not None and stamp < self.sim_time:
            self.restarted()  # a new node: sim time went back (a reset keeps the clock running)
        names = tuple(names)
        if names != self.names:
            self.names = names
            self.matched = False
            self._index = None
        self.poses, self.twists = _rows(poses), _rows(twists)
        self.sim_time = stamp
        self._states_by_stamp[stamp] = (names, self.poses)
        while len(self._states_by_stamp) > 100:
            self._states_by_stamp.popitem(last=False)
        if not self.matched and self.marker_stamp == stamp:
            self._match(self.poses)
        if self._rtf_ref is None or wall < self._rtf_ref[0]:
            self._rtf_ref = (wall, stamp)
        elif wall - self._rtf_ref[0] >= 0.5:
            self.rtf = (stamp - self._rtf_ref[1]) / (wall - self._rtf_ref[0])
            self._rtf_ref = (wall, stamp)
        self.seq += 1

    def on_markers(self, m: Markers) -> None:
        """One markers message, as cdr_in.MarkersReader reads it."""
        changed = False
        if m.delete_alls:  # the node was (re)built: a reset or a new node
            self.restarted()
            self.resets += m.delete_alls
            self.shapes.clear()
            self.marker_poses = np.zeros((0, 3))
            self.name_of.clear()
            self.matched = False
            self.springs = []
            changed = True
        gone = [i for i in m.deleted if i in self.shapes]
        if m.ids:
            if not changed and not gone and m.layout is not None and m.layout is self._layout:
                self.marker_poses = m.poses  # the same bodies as the shapes, in the same order: poses moved
            else:
                # a markers message carries every body: the shapes become its bodies, in its order
                shapes: OrderedDict[int, Shape] = OrderedDict()
                for bid, verts, color in zip(m.ids, m.verts, m.colors):
                    old = self.shapes.get(bid)
                    if old is None or old.verts != verts or old.color != color:
                        old = Shape(bid, verts, color)
                        changed = True
                    shapes[bid] = old
                changed = changed or list(shapes) != list(self.shapes)
                self.shapes = shapes
                self.marker_poses = _rows(m.poses)
                self._layout = m.layout
        elif gone:  # bodies deleted one by one, no full set
            keep = [k for k, bid in enumerate(self.shapes) if bid not in gone]
            for bid in gone:
                del self.shapes[bid]
            self.marker_poses = self.marker_poses[keep]
            self._layout = None
            changed = True
        self.springs = m.springs
        if changed:
            self.shapes_version += 1
            self.matched = False
            self._index = None
        self.marker_stamp = m.stamp
        if not self.matched and self.names:
            got = self._states_by_stamp.get(m.stamp) if m.stamp is not None else None
            # the states of this step, unless the bodies changed in it (a spawn between two steps
            # keeps the stamp): then the latest states, which match if nothing moved (e.g. paused)
            self._match(got[1] if got is not None and got[0] == self.names else self.poses)
        self.seq += 1

    def _match(self, state_poses: np.ndarray) -> None:
        """Name the shapes of the dynamic bodies; ``state_poses`` in the order of self.names."""
        ids = list(self.shapes)
        rows = match_rows(self.marker_poses.tolist(), state_poses.tolist())
        if rows is None or len(rows) != len(self.names):
            return
        self.name_of = {ids[i]: name for i, name in zip(rows, self.names)}
        self.matched = True
        self._index = None
        self.shapes_version += 1

    def on_energy(self, values: dict[str, float]) -> None:
        self.energy = values
        if self.energy_start is None:
            self.energy_start = values["total"]
        self.seq += 1

    def on_contacts(self, points: Any, wall: float | None = None) -> None:
        """points: (m, 2) array-like."""
        wall = time.monotonic() if wall is None else wall
        self.contacts.append((wall, np.asarray(points, dtype=np.float64).reshape(-1, 2)[:MAX_CONTACTS]))
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
        self.names = ()
        self.poses = np.zeros((0, 3))
        self.twists = np.zeros((0, 3))
        self.matched = False
        self._index = None
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

    def _named_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """(rows among the shapes, rows in bodies/states) of the named dynamic bodies."""
        if self._index is None:
            row_of = {n: j for j, n in enumerate(self.names)}
            pairs = [(i, row_of[self.name_of[bid]]) for i, bid in enumerate(self.shapes)
                     if self.name_of.get(bid) in row_of]
            a = np.array([p[0] for p in pairs], dtype=np.int64)
            b = np.array([p[1] for p in pairs], dtype=np.int64)
            self._index = (a, b)
        return self._index

    def state_message(self, wall: float | None = None) -> dict[str, Any]:
        """The frame for the page and the Foxglove stream: ``poses`` and ``velocities`` (k, 3) in the
        order of the shapes (velocities NaN for the bodies without a state: walls, unnamed),
        ``contacts`` (m, 2); the rest plain values."""
        wall = time.monotonic() if wall is None else wall
        k = len(self.shapes)
        poses = self.marker_poses.copy() if len(self.marker_poses) == k else np.zeros((k, 3))
        vel = np.full((k, 3), np.nan)
        si, ri = self._named_rows()
        if len(si) and len(self.poses) == len(self.names):
            poses[si] = self.poses[ri]
            vel[si] = self.twists[ri]
        held = [ps for t, ps in self.contacts if wall - t <= CONTACT_HOLD]
        pts = np.concatenate(held)[:MAX_CONTACTS] if held else np.zeros((0, 2))
        e = self.energy
        energy = None if e is None else {**e, "start": self.energy_start}
        return {"type": "state", "version": self.shapes_version, "t": self.sim_time, "rtf": self.rtf,
                "resets": self.resets, "poses": poses, "velocities": vel, "contacts": pts,
                "springs": self.springs, "energy": energy, "dynamic": len(self.names)}
