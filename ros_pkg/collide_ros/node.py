"""The simulator node ``sim``: libcollide driven and observed over ROS 2 (docs/ros_interface.md).

    python -m collide_ros.node --ros-args [-r __ns:=/arena2] [-p blocks:=4] [-p scene_file:=f.yaml]

Physics runs in C. The node is a thin shell: a sleep-until loop steps the world at
``time_step`` / ``real_time_factor`` of wall time and publishes at rates counted in sim-time steps;
an executor thread handles commands, services and parameters as they arrive, under one lock. Bulk messages
(poses, states, contacts, /tf, markers, /clock) are written as CDR bytes with numpy (cdr.py, markers.py).
Bad input is rejected with a throttled warning naming the reason; nothing a peer sends stops the loop.
SimNode below wires the parts, one concern per module of collide_ros.sim (its __init__ lists them).
"""
from __future__ import annotations

import sys
from typing import Any

import rclpy
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

import collide

from collide_ros.sim.commands import APPLIED, MAX_CMD_SPEED, Commands
from collide_ros.sim.diagnostics import Diagnostics
from collide_ros.sim.forces import Forces
from collide_ros.sim.guards import WARN_PERIOD, Guards
from collide_ros.sim.loop import CATCH_UP_LIMIT, Loop
from collide_ros.sim.parameters import Parameters
from collide_ros.sim.publishing import MAX_CONTACTS_PER_MESSAGE, Publishing
from collide_ros.sim.publishing import concat_rows as _concat_rows
from collide_ros.sim.scanners import Scanners
from collide_ros.sim.services import MAX_STEPS_PER_CALL, Services
from collide_ros.sim.snapshots import Snapshots
from collide_ros.sim.spawning import Spawning
from collide_ros.sim.stepping import SPLIT_DEPTH, SPLIT_MAX_SOLVER_WORK_PER_BODY, SPLIT_MAX_WORK, Stepping
from collide_ros.sim.topology import Topology

__all__ = ["SimNode", "main", "APPLIED", "CATCH_UP_LIMIT", "MAX_CMD_SPEED", "MAX_CONTACTS_PER_MESSAGE",
           "MAX_STEPS_PER_CALL", "SPLIT_DEPTH", "SPLIT_MAX_SOLVER_WORK_PER_BODY", "SPLIT_MAX_WORK", "WARN_PERIOD",
           "_concat_rows"]


class SimNode(Loop, Stepping, Forces, Commands, Publishing, Scanners, Diagnostics, Services, Snapshots, Spawning,
              Parameters, Topology, Guards, Node):
    """The ``sim`` node. Construct after rclpy.init(); call run() to simulate until shutdown."""

    #: every accepted command is republished on applied/<topic> (docs/contracts.md, bit-exact replay)
    ECHOES_COMMANDS = True

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("sim", **kwargs)
        self._init_guards()
        self._declare_parameters()
        self._time_offset = 0.0
        self._paused = bool(self._p["start_paused"])
        self._build_world()  # raises on a bad scene file: the node cannot start without a world
        self._init_publishing()
        self._init_scanners()
        self._init_diagnostics()
        self._init_forces()
        self._init_commands()
        self._init_services()
        self._init_snapshots()
        self._watch_parameters()
        self._init_stepping()
        self._init_loop()
        self._start_diagnostics_window()
        self._periods()
        self._on_topology(deleteall=True)
        self._publish_snapshot()
        self.get_logger().info(
            f"sim ready: {len(self.world.names)} bodies ({', '.join(self._dyn_names[:8])}"
            f"{' ...' if len(self._dyn_names) > 8 else ''}), dt {self._p['time_step']} s, "
            f"RTF {self._p['real_time_factor']}, {'paused' if self._paused else 'running'}, "
            f"frame prefix '{self._p['frame_prefix']}', "
            + ("publishing /clock" if self._pub_clock is not None else "not publishing /clock (publish_clock false)"))


def main(argv: list[str] | None = None) -> int:
    rclpy.init(args=argv if argv is not None else sys.argv)
    node = None
    try:
        node = SimNode()
        node.run()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except collide.SceneError as exc:
        print(f"sim: cannot load scene: {exc}", file=sys.stderr)
        return 2
    except (InvalidParameterTypeException, InvalidParameterValueException) as exc:
        print(f"sim: bad parameter on the command line: {exc}", file=sys.stderr)
        return 2
    finally:
        if node is not None:
            node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
