"""What the node publishes from its shared pose frame (sim/pose_frame.py: the poses computed once per
publish round into preallocated arrays, the dynamic rows a view or one gather) is byte for byte what
the per-topic path gives: poses and twists from ``world.state[dyn_rows]`` (``cdr.poses_from_state``
and ``cdr.twists_from_state`` on fresh arrays), each message written by a fresh CDR writer, and the
energy as an rclpy ``Energy`` object serialized by rclpy.

One in-process node per scene (no executor, no subscribers) publishes every topic after every step
(state, tf and marker rates = 1 / time_step); each publish is compared at once, while the world still
holds the state it was made from. Two scenes of 60 moving, spinning boxes and polygons with names of
several lengths: static bodies in the middle of the row order (the dynamic rows are gathered) and
static bodies last (the dynamic rows are a view). Exact equality: the same float64 bits or a layout
bug (padding excepted: rclpy leaves it uninitialised, the node's is zero)."""
from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rclpy
import yaml
from builtin_interfaces.msg import Time
from geometry_msgs.msg import Vector3
from libcollide_msgs.msg import Energy
from rclpy.serialization import serialize_message

from collide_ros import cdr, markers
from collide_ros.node import SimNode
from collide_ros.sim.publishing import hex_color

STEPS = 30
DT = 0.01


def scene(static_in_middle: bool) -> dict[str, Any]:
    """60 boxes and triangles on a 1.5 m grid with random speeds and spins inside four static walls."""
    rng = np.random.default_rng(11)
    bodies: list[dict[str, Any]] = []
    for k in range(60):
        x, y = -6.0 + 1.5 * (k % 9), -6.0 + 1.5 * (k // 9)
        name = ["b", "box", "block_number_"][k % 3] + str(k)
        body: dict[str, Any] = {"name": name, "position": [x, y], "angle": float(rng.uniform(-3, 3)),
                                "velocity": [float(v) for v in rng.uniform(-2, 2, 2)],
                                "angular_velocity": float(rng.uniform(-4, 4)), "mass": 1.0, "elasticity": 1.0}
        if k % 4 == 3:
            body.update(shape="polygon", vertices=[[-0.3, -0.2], [0.3, -0.2], [0.0, 0.35]])
        else:
            body.update(shape="box", width=0.5, height=0.4)
        bodies.append(body)
    walls = [{"name": n, "shape": "box", "width": w, "height": h, "position": p, "static": True, "elasticity": 1.0}
             for n, w, h, p in (("floor", 16.0, 1.0, [0.0, -8.0]), ("roof", 16.0, 1.0, [0.0, 8.0]),
                                ("left", 1.0, 15.0, [-8.0, 0.0]), ("right", 1.0, 15.0, [8.0, 0.0]))]
    at = 25 if static_in_middle else len(bodies)
    return {"version": 1, "world": {"gravity": [0.0, 0.0]}, "bodies": bodies[:at] + walls + bodies[at:]}


def energy_object(node: SimNode, sec: int, ns: int) -> Energy:
    """The energy message as an rclpy object, field by field from world.energy."""
    e = node.world.energy
    em = Energy()
    em.header.stamp = Time(sec=sec, nanosec=ns)
    em.header.frame_id = node._p["world_frame"]
    em.translational, em.rotational = float(e.translational), float(e.rotational)
    em.gravitational, em.spring, em.total = float(e.gravitational), float(e.spring), float(e.total)
    em.linear_momentum = Vector3(x=float(e.linear_momentum[0]), y=float(e.linear_momentum[1]), z=0.0)
    em.angular_momentum = float(e.angular_momentum)
    return em


def per_topic(node: SimNode) -> dict[str, Callable[[], bytes]]:
    """Each topic's bytes on the per-topic path, from the world's current state."""
    frame = node._p["world_frame"]
    sec, ns = cdr.split_time(node.sim_time)
    st = node.world.state[node._dyn_rows]
    names = node._dyn_names
    ids = [int(i) for i in node._ids]
    outlines = [node._bodies[n].local_vertices() for n in node._names]
    colors = [hex_color(node._colors.get(n), markers.body_color(n, i, bool(node._static[i])))
              for i, n in enumerate(node._names)]
    c = node.world.contacts
    extras = markers.contact_markers(np.array(c["point"]).reshape(-1, 2), np.array(c["normal"]).reshape(-1, 2))
    return {
        "poses": lambda: cdr.PoseArrayCdr(len(names), frame).encode(sec, ns, cdr.poses_from_state(st)),
        "states": lambda: cdr.BodyStatesCdr(names, frame).encode(sec, ns, cdr.poses_from_state(st),
                                                                 cdr.twists_from_state(st)),
        "tf": lambda: cdr.TFMessageCdr(frame, [node._p["frame_prefix"] + n for n in names]).encode(
            sec, ns, cdr.poses_from_state(st)),
        "markers": lambda: markers.MarkerArrayCdr(frame, ids, outlines, colors).encode(
            sec, ns, cdr.poses_from_state(node.world.state), extras),
        "energy": lambda: serialize_message(energy_object(node, sec, ns)),
    }


def same_bytes(raw: bytes, ref: bytes) -> bool:
    """Equal, apart from padding bytes that are zero in ``raw`` (the reference's may be anything)."""
    a, b = np.frombuffer(raw, np.uint8), np.frombuffer(ref, np.uint8)
    return len(a) == len(b) and not np.any(a[a != b])


@pytest.mark.parametrize("static_in_middle", [True, False], ids=["gathered", "view"])
def test_published_bytes_equal_the_per_topic_path(tmp_path: Path, static_in_middle: bool) -> None:
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene(static_in_middle)))
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    rate = f"{1.0 / DT!r}"
    node = SimNode(context=ctx, cli_args=[
        "--ros-args", "-r", "__ns:=/pose_frame", "-p", f"scene_file:={path}", "-p", f"time_step:={DT!r}",
        "-p", f"state_rate:={rate}", "-p", f"tf_rate:={rate}", "-p", f"marker_rate:={rate}"])
    compared: dict[str, int] = {}
    try:
        assert (node._frame._range is None) == static_in_middle
        pubs = {"poses": node._pub_poses, "states": node._pub_states, "tf": node._pub_tf,
                "markers": node._pub_markers, "energy": node._pub_energy}
        for topic, pub in pubs.items():
            def check(msg: Any, topic: str = topic, publish: Callable[[Any], None] = pub.pub.publish) -> None:
                assert isinstance(msg, bytes), f"{topic} should be published as CDR bytes"
                ref = per_topic(node)[topic]()
                assert same_bytes(msg, ref), f"{topic} at t={node.sim_time}"
                compared[topic] = compared.get(topic, 0) + 1
                publish(msg)
            pub.pub.publish = check
        for _ in range(STEPS):
            assert node.step_once(), node.last_rejection
        node._publish_state()  # outside a step's round: the frame is refreshed by the publisher itself
        node._publish_tf()
        moved = node.world.state[node._dyn_rows]
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)
    assert compared == {"poses": STEPS + 1, "states": STEPS + 1, "tf": STEPS + 1, "markers": STEPS, "energy": STEPS + 1}
    # the comparison covered spinning bodies at angles of every quadrant
    assert np.ptp(np.mod(moved[:, 2], 2 * np.pi)) > 5.0 and np.all(moved[:, 5] != 0.0)
