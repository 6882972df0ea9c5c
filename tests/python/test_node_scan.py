"""Laser scanners of the scene file on the node: sensor_msgs/LaserScan through ROS against the geometry.

The scene: walls whose inner faces bound [-4, 6] x [-2, 3], no gravity, a box ``bot`` at rest at
(1, 0.5) turned by 0.3 rad carrying ``lidar`` (mount (0.05, 0.02), 0.1 rad; 360 rays, 0.05 m to 5 m,
20 Hz), and a static post (0.4 m square at (-3, -1)) carrying ``fixed`` (5 rays over [-0.5, 0.5] rad,
3 m, 10 Hz). Nothing moves, so every scan sees the same geometry: each ray's first hit is on an
axis-aligned wall face or post face, at a distance computed here by the slab method in closed form.

The node's ranges in double precision (collide_ros.sim.scanners.scan_ranges, the function that fills the
message) match those distances to 1e-9 m. Through ROS the ranges are float32 (the LaserScan field), so
there each must be the analytic distance rounded to float32, within half a float32 ulp plus 1e-9 m.
Rays with nothing within range_max must be +inf. Also checked: the stamps (sim time, one scan per
1/rate), the frame ids with the node's frame prefix, the mount transforms on /tf, a bad scanner
refused with its reason (the node does not start), and a scanner whose body is killed stops with a
warning while the sim runs on.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from libcollide_msgs.srv import Kill
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan

import collide
from collide_ros.cdr import join_time
from collide_ros.sim.scanners import ScannerSpec, scan_ranges, scanner_pose
from collide_ros.testing import NodeProcess, running_sim

WALLS = (-4.0, -2.0, 6.0, 3.0)
POST = (-3.2, -1.2, -2.8, -0.8)       # x0, y0, x1, y1 of the static post
BOT = (1.0, 0.5, 0.3)
PREFIX = "r1/"
TOL = 1e-9  # m: the ray casts are exact to round-off (1e-15 m here); the margin is the brief's bound


def scene() -> dict[str, Any]:
    return {
        "world": {"gravity": [0, 0]},
        "walls": {"xmin": WALLS[0], "ymin": WALLS[1], "xmax": WALLS[2], "ymax": WALLS[3]},
        "bodies": [
            {"name": "bot", "shape": "box", "width": 0.2, "height": 0.2, "position": list(BOT[:2]), "angle": BOT[2]},
            {"name": "post", "shape": "box", "width": 0.4, "height": 0.4, "position": [-3.0, -1.0], "static": True},
        ],
        "scanners": [
            {"name": "lidar", "body": "bot", "position": [0.05, 0.02], "angle": 0.1, "range_min": 0.05,
             "range_max": 5.0, "rate": 20.0},
            {"name": "fixed", "body": "post", "angle_min": -0.5, "angle_max": 0.5, "angle_increment": 0.25,
             "range_max": 3.0, "rate": 10.0},
        ],
    }


def slab(ox: float, oy: float, a: float, box: tuple[float, float, float, float], inside: bool) -> float:
    """Distance along the ray from (ox, oy) at angle a to the boundary of the axis-aligned box: where it
    leaves (inside) or enters it (outside; inf if it misses)."""
    c, s = math.cos(a), math.sin(a)
    t_in, t_out = -math.inf, math.inf
    for o, d, lo, hi in ((ox, c, box[0], box[2]), (oy, s, box[1], box[3])):
        if d == 0.0:
            if not lo <= o <= hi:
                return math.inf
            continue
        t0, t1 = sorted(((lo - o) / d, (hi - o) / d))
        t_in, t_out = max(t_in, t0), min(t_out, t1)
    if inside:
        return t_out
    return t_in if t_in <= t_out and t_in >= 0 else math.inf


def expected(spec: ScannerSpec, pose: tuple[float, float, float], skip_post: bool) -> np.ndarray:
    ox, oy, heading = scanner_pose(spec, pose)
    out = []
    for a in heading + spec.ray_angles():
        r = slab(ox, oy, float(a), WALLS, inside=True)
        if not skip_post:
            r = min(r, slab(ox, oy, float(a), POST, inside=False))
        out.append(math.inf if r > spec.range_max else -math.inf if r < spec.range_min else r)
    return np.array(out)


def specs() -> dict[str, ScannerSpec]:
    return {sc["name"]: ScannerSpec.from_scene(sc) for sc in collide.load_scene(scene()).scanners}


POSES = {"lidar": BOT, "fixed": (-3.0, -1.0, 0.0)}


def test_scan_ranges_match_the_geometry_in_double() -> None:
    world = collide.load_scene(scene()).build()
    for name, spec in specs().items():
        body = world.body(spec.body)
        got = scan_ranges(world, spec, body.id, POSES[name])
        want = expected(spec, POSES[name], skip_post=name == "fixed")
        assert np.array_equal(np.isinf(got), np.isinf(want)) and np.array_equal(got[np.isinf(got)],
                                                                                want[np.isinf(want)])
        fin = np.isfinite(want)
        assert np.max(np.abs(got[fin] - want[fin])) <= TOL, name
    # the scene covers every case: wall hits on all four sides, post hits, nothing in range
    lidar = expected(specs()["lidar"], BOT, False)
    assert np.sum(np.isinf(lidar)) > 50 and np.sum(np.isfinite(lidar)) > 200
    ox, oy, h = scanner_pose(specs()["lidar"], BOT)
    post_rays = [slab(ox, oy, float(a), POST, False) < slab(ox, oy, float(a), WALLS, True)
                 for a in h + specs()["lidar"].ray_angles()]
    assert any(post_rays)


def _check_scan(msg: LaserScan, spec: ScannerSpec, want: np.ndarray, period: float) -> None:
    assert msg.header.frame_id == PREFIX + spec.name
    t = join_time(msg.header.stamp)
    assert abs(t / period - round(t / period)) < 1e-6, f"stamp {t} is not a multiple of {period}"
    f32 = np.float32
    assert (msg.angle_min, msg.angle_max, msg.angle_increment) == (f32(spec.angle_min), f32(spec.angle_max),
                                                                   f32(spec.angle_increment))
    assert (msg.range_min, msg.range_max) == (f32(spec.range_min), f32(spec.range_max))
    assert msg.time_increment == 0.0 and msg.scan_time == np.float32(period)
    got = np.array(msg.ranges, dtype=np.float64)
    assert len(got) == len(want) == spec.rays
    inf = np.isinf(want)
    assert np.array_equal(got[inf], want[inf])
    ulp = np.spacing(np.abs(want[~inf]).astype(np.float32)).astype(np.float64)
    assert np.all(np.abs(got[~inf] - want[~inf]) <= ulp / 2 + TOL)


def _yaw(q: Any) -> float:
    return 2.0 * math.atan2(q.z, q.w)


def test_laser_scans_through_ros(tmp_path: Path) -> None:
    path = tmp_path / "scan.yaml"
    path.write_text(yaml.safe_dump(scene()))
    with running_sim("-p", f"scene_file:={path}", "-p", f"frame_prefix:={PREFIX}") as (client, proc):
        deep = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        scans: dict[str, list[LaserScan]] = {"lidar": [], "fixed": []}
        for name, got in scans.items():
            client.node.create_subscription(LaserScan, f"/{name}/scan", got.append, deep)
        assert client.wait_for(lambda: len(scans["lidar"]) >= 6 and len(scans["fixed"]) >= 3, 60.0), proc.output()
        sp = specs()
        for name, got in scans.items():
            want = expected(sp[name], POSES[name], skip_post=name == "fixed")
            for msg in got:
                _check_scan(msg, sp[name], want, 1.0 / sp[name].rate)
            stamps = [join_time(m.header.stamp) for m in got]
            assert all(b - a == pytest.approx(1.0 / sp[name].rate, abs=1e-9) for a, b in zip(stamps, stamps[1:]))
        # the mounts on /tf: lidar in the bot's frame, fixed (on a static body) in the world frame
        tfs = {t.child_frame_id: t for _, m in client.history["tf"] for t in m.transforms}
        lidar, fixed = tfs[PREFIX + "lidar"], tfs[PREFIX + "fixed"]
        assert lidar.header.frame_id == PREFIX + "bot" and PREFIX + "bot" in tfs
        tr = lidar.transform
        assert (tr.translation.x, tr.translation.y, tr.translation.z) == (0.05, 0.02, 0.0)
        assert _yaw(tr.rotation) == pytest.approx(0.1, abs=1e-15)
        fx, fy, fyaw = scanner_pose(sp["fixed"], POSES["fixed"])
        assert fixed.header.frame_id == "world"
        assert (fixed.transform.translation.x, fixed.transform.translation.y) == (fx, fy)
        assert _yaw(fixed.transform.rotation) == pytest.approx(fyaw, abs=1e-15)
        # kill the lidar's body: its scans stop with a warning, the sim and the other scanner go on
        resp = client.call(Kill, "kill", Kill.Request(name="bot"))
        assert resp is not None and resp.success, resp
        assert client.wait_rosout("scanner 'lidar': body 'bot' is gone") is not None
        client.spin(0.2)  # a scan published before the kill may still be on its way
        n_lidar, n_fixed = len(scans["lidar"]), len(scans["fixed"])
        assert client.wait_for(lambda: len(scans["fixed"]) >= n_fixed + 3, 30.0)
        assert len(scans["lidar"]) == n_lidar


@pytest.mark.parametrize("change, key, words", [
    ({"range_min": 6.0}, "range_max", "range_min (6.0) < range_max"),
    ({"angle_max": 1.0}, "angle_max", "not a whole number of angle_increment"),
    ({"angle_increment": 1e-5}, "angle_increment", "at most 10000"),
    ({"rate": -1.0}, "rate", "(0, 1000] Hz"),
    ({"body": "ghost"}, "body", "no body named 'ghost'"),
    ({"name": "bot"}, "name", "is taken"),
    ({"name": "a b"}, "name", "a letter then letters"),
    ({"position": [2e3, 0]}, "position", "more than 1000 m"),
])
def test_bad_scanner_is_refused_with_its_reason(change: dict[str, Any], key: str, words: str) -> None:
    bad = scene()
    bad["scanners"][0].update(change)
    with pytest.raises(collide.SceneError) as err:
        collide.load_scene(bad)
    assert f"scanners[0].{key}: " in str(err.value) and words in str(err.value), str(err.value)


def test_node_refuses_a_bad_scanner(tmp_path: Path) -> None:
    bad = scene()
    bad["scanners"][1]["range_max"] = 0.0
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(bad, sort_keys=False))
    proc = NodeProcess("-r", "__ns:=/scan_bad", "-p", f"scene_file:={path}")
    code = proc.proc.wait(60.0)
    out = proc.output()
    assert code == 2, out
    assert "scanners[1].range_max" in out and "range_min (0.0) < range_max (0.0)" in out, out
