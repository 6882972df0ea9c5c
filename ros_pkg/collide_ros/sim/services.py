"""The node's services: ``~/reset`` (a new world, the clock running on), ``~/pause``, ``~/step`` (while
paused), ``~/kill`` and ``~/spawn`` (spawning.py). Each runs under the lock; an exception is a refusal
with its reason (guards.py)."""
from __future__ import annotations

from builtin_interfaces.msg import Time
from libcollide_msgs.srv import Kill, Spawn, Step
from std_srvs.srv import Empty, SetBool

from collide_ros import cdr

MAX_STEPS_PER_CALL = 1_000_000  # ~/step upper bound per request


class Services:
    """Owns ``_paused``; a pause and a reset restart the loop's schedule (``_schedule_dirty``)."""

    def _init_services(self) -> None:
        self.create_service(Empty, "~/reset", self._guard_srv("reset", self._srv_reset))
        self.create_service(SetBool, "~/pause", self._guard_srv("pause", self._srv_pause))
        self.create_service(Step, "~/step", self._guard_srv("step", self._srv_step))
        self.create_service(Spawn, "~/spawn", self._guard_srv("spawn", self._srv_spawn))
        self.create_service(Kill, "~/kill", self._guard_srv("kill", self._srv_kill))

    def _srv_reset(self, req: Empty.Request, resp: Empty.Response) -> Empty.Response:
        self.reset()
        return resp

    def reset(self) -> None:
        self._springs.clear()  # the springs go with the old world
        self.failing_since = None
        self._thrust.clear()
        self._thrusters.clear()
        self._cmd_vel = None
        self._ext_bodies.clear()
        offset = self.sim_time  # the clock keeps running forward across a reset
        self._build_world()
        self._time_offset = offset
        self.steps = 0
        self._schedule_dirty = True
        self._on_topology(deleteall=True)
        self._publish_state()
        self._publish_snapshot()
        self.get_logger().info(f"reset: {len(self._dyn_names)} dynamic bodies at sim time {self.sim_time:.3f} s")

    def _srv_pause(self, req: SetBool.Request, resp: SetBool.Response) -> SetBool.Response:
        self._paused = bool(req.data)
        self._schedule_dirty = True
        resp.success = True
        resp.message = "paused" if self._paused else "running"
        return resp

    def _srv_step(self, req: Step.Request, resp: Step.Response) -> Step.Response:
        if not self._paused:
            resp.success = False
            resp.message = "~/step works only while paused; call ~/pause with data: true first"
        elif req.steps > MAX_STEPS_PER_CALL:
            resp.success = False
            resp.message = f"steps {req.steps} exceeds {MAX_STEPS_PER_CALL} per call"
        else:
            done = 0
            for _ in range(req.steps):
                if not self.step_once():
                    break
                done += 1
            resp.success = done == req.steps
            resp.message = f"stepped {done} x {self._p['time_step']} s" + (
                "" if resp.success else f"; stopped: {self.last_rejection}")
        sec, ns = cdr.split_time(self.sim_time)
        resp.sim_time = Time(sec=sec, nanosec=ns)
        return resp

    def _srv_kill(self, req: Kill.Request, resp: Kill.Response) -> Kill.Response:
        if req.name not in self._row_of:
            resp.success = False
            resp.message = f"no body named '{req.name}'"
            return resp
        if self._bodies[req.name].static and not self._p["allow_kill_static"]:
            resp.success = False
            resp.message = (f"'{req.name}' is static (a wall of the box or a fixed body) and stays; "
                            "set parameter allow_kill_static to true to remove it")
            self._warn(f"kill:static:{req.name}", f"rejected: {resp.message}")
            return resp
        self.world.remove_body(req.name)
        self._springs = {s: e for s, e in self._springs.items() if e.body != req.name}
        if self._cmd_vel is not None and self._p["cmd_vel_body"] == req.name:
            self._cmd_vel = None
        self._on_topology(deleteall=True)  # its marker must go from RViz too
        resp.success = True
        resp.message = f"killed '{req.name}'"
        return resp
