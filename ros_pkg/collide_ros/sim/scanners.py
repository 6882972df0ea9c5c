"""Laser scanners mounted on bodies (the scene file's ``scanners``, docs/ros_interface.md "Laser scanners"):
each publishes sensor_msgs/LaserScan on ``<name>/scan`` at its rate in sim time, its ranges from one
batched ray cast of the C library (lc_world_ray_cast_batch) on the poses after the step, and its mount on
/tf (``<frame_prefix><body>`` -> ``<frame_prefix><name>``, or from ``world_frame`` on a static body)."""
from __future__ import annotations

import math
from array import array
from dataclasses import dataclass
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time
from geometry_msgs.msg import TransformStamped
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

import collide
from collide.scene import scanner_rays

from collide_ros import cdr

# Reliable so that RViz's default (reliable) subscription matches; a best-effort reader matches it too.
SCAN_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10, reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)


@dataclass(frozen=True)
class ScannerSpec:
    """A scanner as the scene gives it (collide.scene validated every value)."""

    name: str
    body: str
    mount: tuple[float, float]   # m, in the body's frame (its centre of mass and angle, as on /tf)
    mount_angle: float           # rad, the scanner's x axis from the body's
    angle_min: float             # rad, first ray from the scanner's x axis
    angle_max: float             # rad, last ray
    angle_increment: float       # rad
    range_min: float             # m: a closer hit is reported as -inf
    range_max: float             # m: the rays' length; nothing within it is +inf
    rate: float                  # Hz of sim time

    @classmethod
    def from_scene(cls, sc: dict[str, Any]) -> ScannerSpec:
        return cls(sc["name"], sc["body"], (float(sc["position"][0]), float(sc["position"][1])), float(sc["angle"]),
                   float(sc["angle_min"]), float(sc["angle_max"]), float(sc["angle_increment"]),
                   float(sc["range_min"]), float(sc["range_max"]), float(sc["rate"]))

    @property
    def rays(self) -> int:
        return scanner_rays({"angle_min": self.angle_min, "angle_max": self.angle_max,
                             "angle_increment": self.angle_increment})

    def ray_angles(self) -> np.ndarray:
        """Each ray's angle in the scanner frame."""
        return self.angle_min + self.angle_increment * np.arange(self.rays)


def scanner_pose(spec: ScannerSpec, pose: tuple[float, float, float]) -> tuple[float, float, float]:
    """World (x, y, yaw) of the scanner on a body at ``pose`` = (x, y, yaw) of its centre of mass."""
    x, y, a = pose
    c, s = math.cos(a), math.sin(a)
    mx, my = spec.mount
    return x + c * mx - s * my, y + s * mx + c * my, a + spec.mount_angle


def scan_ranges(world: collide.World, spec: ScannerSpec, body_id: int, pose: tuple[float, float, float],
                angles: np.ndarray | None = None) -> np.ndarray:
    """The ranges (m, float64) of one scan by a scanner on body ``body_id`` at ``pose``: the distance from
    the scanner to the first body (its own left out) along each ray, +inf when none is within range_max,
    -inf when the first is closer than range_min (REP 117). One C call for all rays."""
    ox, oy, heading = scanner_pose(spec, pose)
    a = heading + (spec.ray_angles() if angles is None else angles)
    ends = np.column_stack([ox + spec.range_max * np.cos(a), oy + spec.range_max * np.sin(a)])
    hits = world.ray_cast_batch((ox, oy), ends, skip=body_id)
    ranges = np.full(len(a), math.inf)
    d = np.hypot(hits.point[hits.found, 0] - ox, hits.point[hits.found, 1] - oy)
    ranges[hits.found] = np.where(d < spec.range_min, -math.inf, d)
    return ranges


class Scanners:
    """Owns the scanners of the current scene (``_scanner_specs`` from the scene, ``_scanners``: name ->
    (spec, publisher, steps per scan, ray angles) for those whose body exists) and ``_scanner_pubs``."""

    def _init_scanners(self) -> None:
        self._scanner_pubs: dict[str, Any] = {}
        self._scanners: dict[str, tuple[ScannerSpec, Any, int, np.ndarray]] = {}

    def _make_scanners(self) -> None:
        """Publishers and schedules for the scene's scanners on bodies that exist (after a build, spawn,
        kill or rate change); a scanner whose body was killed stops, with a warning."""
        dt = float(self._p["time_step"])
        live = {}
        for spec in self._scanner_specs:
            if spec.body not in self._row_of:
                self._warn(f"scanner:{spec.name}", f"scanner '{spec.name}': body '{spec.body}' is gone; "
                           "it publishes no more scans until a reset")
                continue
            topic = f"{spec.name}/scan"
            if topic not in self._scanner_pubs:
                self._scanner_pubs[topic] = self._publisher(LaserScan, topic, SCAN_QOS)
            every = max(1, int(round(1.0 / (spec.rate * dt))))
            live[spec.name] = (spec, self._scanner_pubs[topic], every, spec.ray_angles())
        for topic in [t for t in self._scanner_pubs if t.split("/")[0] not in live]:
            self._unpublish(topic, self._scanner_pubs.pop(topic))
        self._scanners = live

    def _publish_scans(self, s: int) -> None:
        """The scans due after step ``s``, each with its mount on /tf at the same stamp."""
        for spec, pub, every, angles in self._scanners.values():
            if s % every == 0:
                self._publish_scan(spec, pub, every, angles)

    def _publish_scan(self, spec: ScannerSpec, pub: Any, every: int, angles: np.ndarray) -> None:
        row = self._row_of[spec.body]
        st = self.world.state[row]
        ranges = scan_ranges(self.world, spec, int(self._ids[row]), (float(st[0]), float(st[1]), float(st[2])),
                             angles)
        sec, ns = cdr.split_time(self.sim_time)
        stamp = Time(sec=sec, nanosec=ns)
        prefix = self._p["frame_prefix"]
        msg = LaserScan()
        msg.header.stamp = stamp
        msg.header.frame_id = prefix + spec.name
        msg.angle_min, msg.angle_max, msg.angle_increment = spec.angle_min, spec.angle_max, spec.angle_increment
        msg.time_increment = 0.0  # every ray at the same sim time
        msg.scan_time = every * float(self._p["time_step"])
        msg.range_min, msg.range_max = spec.range_min, spec.range_max
        msg.ranges = array("f", ranges.astype(np.float32).tobytes())
        pub.publish(msg)
        self._pub_tf.publish(TFMessage(transforms=[self._mount_transform(spec, row, stamp)]))

    def _mount_transform(self, spec: ScannerSpec, row: int, stamp: Time) -> TransformStamped:
        """The scanner frame in its body's frame (a dynamic body's frame is on /tf), or in world_frame
        for a static body (which has no frame of its own)."""
        prefix = self._p["frame_prefix"]
        t = TransformStamped()
        t.header.stamp = stamp
        t.child_frame_id = prefix + spec.name
        if self._static[row]:
            st = self.world.state[row]
            x, y, yaw = scanner_pose(spec, (float(st[0]), float(st[1]), float(st[2])))
            t.header.frame_id = self._p["world_frame"]
        else:
            (x, y), yaw = spec.mount, spec.mount_angle
            t.header.frame_id = prefix + spec.body
        t.transform.translation.x, t.transform.translation.y = float(x), float(y)
        t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        return t
