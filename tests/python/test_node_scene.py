"""The node on a scene file (parameter scene_file): the file's bodies and settings, parameters
defaulting to the file's values, and a malformed file stopping the start with the reason."""
from __future__ import annotations

from pathlib import Path
from typing import Iterator

import pytest
import rclpy
from geometry_msgs.msg import WrenchStamped
from std_srvs.srv import Empty

from collide_ros.testing import NodeProcess, SimClient, running_sim

SCENE = """\
version: 1
world: {gravity: [0.0, -2.0], damping: 0.0}
walls: {xmin: -5, ymin: -5, xmax: 5, ymax: 5, thickness: 1, elasticity: 1}
bodies:
  - {name: tri, shape: polygon, vertices: [[0, 0], [1, 0], [0, 1]], position: [-2, 2], mass: 1.5}
  - {name: crate, shape: box, width: 1, height: 1, position: [2, 2], mass: 2.0, thrusters: {default: 1.5}}
"""


@pytest.fixture(scope="module")
def scene_sim(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[SimClient, NodeProcess]]:
    path = tmp_path_factory.mktemp("scene") / "two.yaml"
    path.write_text(SCENE)
    with running_sim("-p", f"scene_file:={path}", "-p", "cmd_vel_body:=crate") as (client, proc):
        yield client, proc


def test_scene_file_bodies_and_settings(scene_sim: tuple[SimClient, NodeProcess]) -> None:
    sim, _ = scene_sim
    assert list(sim.fresh("bodies/states").names) == ["tri", "crate"]
    # the file's gravity became the parameter's value (g = 2 m/s^2, applied as (0, -g))
    assert sim.get_params(["gravity", "cmd_vel_body"]) == {"gravity": 2.0, "cmd_vel_body": "crate"}
    assert sim.call(Empty, "reset") is not None
    assert sim.wait_for(lambda: (sim.body_state("tri", 1.0) or (0, 0, 0, 0, 0.0))[4] < -0.2, 20.0)
    # bodies of the file have their thrust topics
    assert sim.wait_subscribed("crate/thrust", WrenchStamped)


def test_bad_scene_file_is_reported(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\nbodies:\n  - {name: x, shape: box, width: 1, height: 1, mass: heavy}\n")
    proc = NodeProcess("-p", f"scene_file:={bad}")
    try:
        code = proc.proc.wait(60.0)
    finally:
        proc.stop()
    assert code == 2
    assert "bad.yaml" in proc.output() and "mass" in proc.output()
