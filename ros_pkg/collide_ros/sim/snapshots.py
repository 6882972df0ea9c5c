"""The node's state as one message, what a replay starts from: ``~/snapshot`` (libcollide_msgs/WorldSnapshot,
reliable, transient-local, depth 1) carries the world's snapshot (World.save), the sim time, the parameters,
the step count and the commands in force. It is published when the node starts, after each ``~/reset`` and
on each ``~/save_snapshot`` call (std_srvs/Trigger; the recorder calls it when it starts recording)."""
from __future__ import annotations

import json
from typing import Any

from builtin_interfaces.msg import Time
from libcollide_msgs.msg import WorldSnapshot
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger

from collide_ros import cdr
from collide_ros.sim.commands import APPLIED, CmdVel, Thrust

#: besides the command echoes (applied/...), what a replay reads from a bag
REPLAY_TOPICS = frozenset({"bodies/states"})
SNAPSHOT_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1, reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL)


class Snapshots:
    """Owns the ``~/snapshot`` publisher and the ``~/save_snapshot`` service."""

    def _init_snapshots(self) -> None:
        self._pub_snapshot = self.create_publisher(WorldSnapshot, "~/snapshot", SNAPSHOT_QOS)
        self.create_service(Trigger, "~/save_snapshot", self._guard_srv("save_snapshot", self._srv_save_snapshot))

    def node_state(self) -> dict[str, Any]:
        """What, besides the world, decides the coming steps: parameters, steps since the build (the
        publish phase), the clock offset and the commands in force. JSON floats round-trip exactly."""
        return {
            "params": {n: self.get_parameter(n).value for n in sorted(self._parameters)},
            "steps": self.steps,
            "time_offset": self._time_offset,
            "thrust": {n: [c.fx, c.fy, c.torque, c.world, c.stamp] for n, c in self._thrust.items()},
            "thrusters": dict(self._thrusters),
            "cmd_vel": None if self._cmd_vel is None else [self._cmd_vel.vx, self._cmd_vel.vy,
                                                           self._cmd_vel.wz, self._cmd_vel.stamp],
            "springs": sorted(self._springs),
            "names": list(self.world.names),
            "ext_bodies": sorted(self._ext_bodies),
            # the readers each writer a replay needs had matched when the snapshot was taken: a recorder
            # takes the snapshot as its start only once these include its own (collide_ros.recorder)
            "matched_readers": {p.pub.topic_name: p.pub.get_subscription_count()
                                for k, p in sorted(self._published.items())
                                if k in REPLAY_TOPICS or k.startswith(APPLIED)},
        }

    def snapshot_message(self) -> WorldSnapshot:
        sec, ns = cdr.split_time(self.sim_time)
        return WorldSnapshot(stamp=Time(sec=sec, nanosec=ns), node_state=json.dumps(self.node_state()),
                             world=self.world.save())

    def _publish_snapshot(self) -> None:
        self._pub_snapshot.publish(self.snapshot_message())

    def _srv_save_snapshot(self, req: Trigger.Request, resp: Trigger.Response) -> Trigger.Response:
        self._publish_snapshot()
        resp.success = True
        resp.message = f"snapshot at sim time {self.sim_time:.9f} s published on {self._pub_snapshot.topic_name}"
        return resp

    def restore_snapshot(self, world: bytes, state: dict[str, Any]) -> None:
        """Continue from a snapshot of a node with the same parameters (a replay's start). Raises
        ValueError for what cannot be restored: springs made over ROS (their handles are the node's) and
        bodies the scene does not name (spawned ones: a loaded world names only the bodies it knew)."""
        if state["springs"]:
            raise ValueError(f"the snapshot holds springs made over ROS ({', '.join(state['springs'])}); "
                             "a replay cannot start from it")
        old = self.world.save()
        self.world.load(bytes(world))
        if list(self.world.names) != list(state["names"]):
            self.world.load(old)
            raise ValueError("the snapshot holds bodies the scene does not name (spawned before it); "
                             "a replay cannot start from it")
        self._time_offset = float(state["time_offset"])
        self.steps = int(state["steps"])
        self._on_topology(deleteall=True)
        self._thrust = {n: Thrust(fx, fy, tq, bool(w), st) for n, (fx, fy, tq, w, st) in state["thrust"].items()}
        self._thrusters = {n: float(t) for n, t in state["thrusters"].items()}
        cv = state["cmd_vel"]
        self._cmd_vel = None if cv is None else CmdVel(*cv)
        self._ext_bodies = set(state["ext_bodies"])
