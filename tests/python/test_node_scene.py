"""The node on a scene file (parameter scene_file): the file's bodies and settings, parameters
defaulting to the file's values, a malformed file stopping the start with the reason, and ~/reset
building the file as it is on disk (parsed again only when its text changed)."""
from __future__ import annotations

from pathlib import Path
from typing import Iterator

import pytest
import rclpy
from geometry_msgs.msg import WrenchStamped
from std_srvs.srv import Empty

from collide_ros.testing import NodeProcess, SimClient, running_sim, sims_side_by_side

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


def _start_fails(scene_file: Path) -> str:
    """Starts the node on scene_file, expects it to exit with status 2; returns its output."""
    proc = NodeProcess("-p", f"scene_file:={scene_file}")
    try:
        code = proc.proc.wait(60.0)
    finally:
        proc.stop()
    assert code == 2, proc.output()
    return proc.output()


def test_bad_scene_file_is_reported(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\nbodies:\n  - {name: x, shape: box, width: 1, height: 1, mass: heavy}\n")
    out = _start_fails(bad)
    assert "bad.yaml" in out and "mass" in out


def test_bad_range_in_scene_file_is_reported_with_its_line(tmp_path: Path) -> None:
    """A value only C refuses (mass -1) stops the start with C's message at the body's line."""
    bad = tmp_path / "range.yaml"
    bad.write_text(SCENE.replace("mass: 2.0", "mass: -1"))
    out = _start_fails(bad)
    assert f"{bad}:6: bodies[1]: mass = -1" in out, out


def test_reset_reads_the_scene_file_as_it_is_on_disk(tmp_path: Path) -> None:
    """~/reset builds the scene file as it is now: a changed file (here one of the same size, which
    its modification time may not tell apart) gives its new bodies; a file that became bad is refused
    with its reason and line, and the sim keeps the world it had."""
    path = tmp_path / "changing.yaml"
    path.write_text(SCENE)
    # a namespace of its own: the module's other sim may still be running in this domain
    with sims_side_by_side(("-r", "__ns:=/changing", "-p", f"scene_file:={path}")) as (sim,):
        def names_are(*names: str) -> bool:
            return sim.wait_for(lambda: tuple(sim.last["bodies/states"].names) == names, 20.0)

        assert names_are("tri", "crate")
        assert sim.call(Empty, "reset") is not None
        assert names_are("tri", "crate")
        changed = SCENE.replace("crate", "chest")
        assert len(changed) == len(SCENE)
        path.write_text(changed)
        assert sim.call(Empty, "reset") is not None
        assert names_are("tri", "chest")
        assert sim.wait_subscribed("chest/thrust", WrenchStamped)
        path.write_text(changed.replace("mass: 2.0", "mass: -1"))
        assert sim.call(Empty, "reset") is not None
        assert sim.wait_rosout(f"{path}:6: bodies[1]: mass = -1") is not None
        mark = sim.count["bodies/states"]
        assert sim.wait_for(lambda: sim.count["bodies/states"] >= mark + 3, 20.0)
        assert tuple(sim.last["bodies/states"].names) == ("tri", "chest")


def test_scene_file_is_parsed_once_per_text(tmp_path: Path) -> None:
    """The node's SceneFile: the same path and text give the Scene parsed before, new text a new one;
    a bad file raises each time and leaves nothing behind to be taken for it."""
    from collide import SceneError
    from collide_ros.sim.scene_file import SceneFile

    path = tmp_path / "s.yaml"
    path.write_text(SCENE)
    files = SceneFile()
    first = files.load(str(path))
    assert files.load(str(path)) is first and first.names[-2:] == ["tri", "crate"]
    path.write_text(SCENE.replace("crate", "chest"))
    second = files.load(str(path))
    assert second is not first and second.names[-1] == "chest"
    path.write_text("bodies: [1]\n")
    for _ in range(2):
        with pytest.raises(SceneError, match=r"s\.yaml:1: bodies\[0\]: expected a body"):
            files.load(str(path))
    path.write_text(SCENE.replace("crate", "chest"))
    third = files.load(str(path))
    assert third == second and third is not second
