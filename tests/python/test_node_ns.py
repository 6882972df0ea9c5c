"""Two sims in one ROS domain, separated only by their namespaces (``-r __ns:=/arenaN``): each has
its own bodies, commands, services and parameters (only /clock, /tf and /diagnostics are shared by
design, see docs/ros_interface.md)."""
from __future__ import annotations

from typing import Iterator

import pytest
from geometry_msgs.msg import WrenchStamped
from std_srvs.srv import SetBool

from collide_ros.testing import SimClient, sims_side_by_side


@pytest.fixture(scope="module")
def arenas() -> Iterator[tuple[SimClient, SimClient]]:
    with sims_side_by_side(("-r", "__ns:=/arena1", "-p", "blocks:=1", "-p", "command_timeout:=0.5"),
                           ("-r", "__ns:=/arena2", "-p", "blocks:=3", "-p", "command_timeout:=0.5")) as (c1, c2):
        yield c1, c2


def test_each_namespace_has_its_own_world(arenas: tuple[SimClient, SimClient]) -> None:
    a1, a2 = arenas
    assert list(a1.fresh("bodies/states").names) == ["block1"]
    assert list(a2.fresh("bodies/states").names) == ["block1", "block2", "block3"]
    assert a1.get_params(["blocks"]) == {"blocks": 1}
    assert a2.get_params(["blocks"]) == {"blocks": 3}


def test_commands_and_services_stay_in_their_namespace(arenas: tuple[SimClient, SimClient]) -> None:
    a1, a2 = arenas
    assert a1.wait_subscribed("block1/thrust", WrenchStamped)
    m = WrenchStamped()
    m.wrench.force.x = 1.0
    a1.publish("block1/thrust", m)  # /arena1/block1/thrust
    assert a1.wait_for(lambda: (a1.body_state("block1", 1.0) or (0, 0, 0, 0.0))[3] > 0.2, 20.0)
    # arena2's block1 never received it: still exactly at rest (no gravity, nothing touching)
    assert a2.body_state("block1")[3] == 0.0
    # pausing arena2 does not pause arena1
    assert a2.call(SetBool, "pause", SetBool.Request(data=True)).success
    a2.spin(0.5)  # take what was queued before the pause
    n2 = a2.count["bodies/states"]
    assert a1.fresh("bodies/states", 20) is not None  # arena1 goes on publishing ...
    a2.spin(0.3)
    assert a2.count["bodies/states"] == n2  # ... while arena2 publishes nothing
    assert a2.call(SetBool, "pause", SetBool.Request(data=False)).success
    assert a2.fresh("bodies/states", 5) is not None
