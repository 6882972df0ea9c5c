"""~/spawn's overlap check (collide_ros/sim/spawning.py, overlapped_body) on the default scene, without
ROS: the world's box and distance queries decide, touching is allowed, and the sim's world is left as
it was. The refusals over ROS are in test_node.py and test_badinput.py."""
from __future__ import annotations

import math

import numpy as np
import pytest

import collide
from collide_ros.sim.spawning import TOUCH_DEPTH, overlapped_body


def _box(cx: float, cy: float, w: float = 1.0, h: float = 1.0, angle: float = 0.0) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    local = np.array([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]])
    return local @ np.array([[c, s], [-s, c]]) + np.array([cx, cy])


@pytest.fixture()
def world() -> collide.World:
    # walls: floor top at y = -6, right wall's inner face at x = 6; block1 spans x [-3, -2], y [-1.5, 1.5]
    return collide.default_scene(blocks=2).build()


def test_a_box_set_on_the_floor_touches_and_is_allowed(world: collide.World) -> None:
    assert overlapped_body(world, _box(0.0, -5.5)) is None


def test_a_box_sunk_into_the_floor_overlaps_it(world: collide.World) -> None:
    # 1e-9 m deep: a thousand times TOUCH_DEPTH, far above the round-off of vertices of a 14 m scene
    assert 1e-9 > 100 * TOUCH_DEPTH
    assert overlapped_body(world, _box(0.0, -5.5 - 1e-9)) == "wall_bottom"


def test_overlap_with_a_block_and_a_wall(world: collide.World) -> None:
    assert overlapped_body(world, _box(-2.5, 0.0)) == "block1"
    assert overlapped_body(world, _box(6.2, 4.0)) == "wall_right"


def test_bounding_boxes_that_meet_are_not_an_overlap(world: collide.World) -> None:
    # a diamond above block1's top-right corner (-2, 1.5): its bounding box x [-2.21, -0.79],
    # y [1.29, 2.71] meets block1's, but its lower-left edge x + y = -0.207 passes the corner
    # (x + y = -0.5) at 0.29 / sqrt(2) = 0.21 m
    diamond = _box(-1.5, 2.0, angle=math.pi / 4)
    assert np.all(diamond.min(axis=0) < np.array([-2.0, 1.5]))
    assert [b.name for b in world.query_box(diamond.min(axis=0), diamond.max(axis=0))] == ["block1"]
    assert overlapped_body(world, diamond) is None
    assert overlapped_body(world, _box(-1.9, 1.6, angle=math.pi / 4)) == "block1"  # moved onto the corner


def test_the_world_is_left_as_it_was(world: collide.World) -> None:
    world.step(0.01)
    before = (world.names, world.state.copy(), world.time, len(world.contacts))
    for cx, cy in ((-2.5, 0.0), (0.0, -5.5), (0.0, 0.0)):
        overlapped_body(world, _box(cx, cy))
    after = (world.names, world.state.copy(), world.time, len(world.contacts))
    assert before[0] == after[0] and np.array_equal(before[1], after[1]) and before[2:] == after[2:]


def test_a_polygon_c_refuses_is_left_to_add_body(world: collide.World) -> None:
    # not convex: the scratch world's add_body refuses it, and so will the sim's, with C's reason
    nonconvex = np.array([[0.0, 0.0], [2.0, 0.0], [1.0, 0.3], [2.0, 2.0], [0.0, 2.0]]) + np.array([-3.0, -1.0])
    assert overlapped_body(world, nonconvex) is None
    with pytest.raises(collide.CollideError, match="not convex"):
        world.add_body(nonconvex)
