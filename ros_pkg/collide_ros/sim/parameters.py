"""The node's side of its parameters (the table itself: collide_ros/params.py): declaring them, with a
scene file's own settings as defaults, refusing use_sim_time, checking a set before rclpy takes it and
applying it after."""
from __future__ import annotations

from typing import Any

import numpy as np
from rcl_interfaces.msg import SetParametersResult
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.parameter import Parameter

import collide

from collide_ros import params
from collide_ros.sim.scene_file import SceneFile
from collide_ros.sim.topology import WORLD_SETTINGS, scene_values


class Parameters:
    """Owns ``_p`` (name -> current value of every parameter of params.SPECS), ``_scene_defaults``
    (the scene file's settings, empty without a scene file), ``_scene_file`` (the scene file read last
    and its Scene: the start and each reset parse it once, and again only when it changed) and
    ``_start_world`` (the scene file's Scene and the World built from it for the defaults, until the
    start's _build_world takes it)."""

    def _declare_parameters(self) -> None:
        """Declare every parameter. scene_file first: a scene file supplies the defaults of gravity,
        damping, elasticity and green_mass (its own settings), which -p on the command line still
        overrides. Raises on a bad scene file or a bad frame: the node cannot start with them."""
        sf = params.BY_NAME["scene_file"]
        scene_file = str(self.declare_parameter(sf.name, sf.default, params.descriptor(sf)).value)
        self._scene_defaults: dict[str, float] = {}
        self._scene_file = SceneFile()
        self._start_world: tuple[collide.Scene, collide.World] | None = None
        if scene_file:
            scene = self._scene_file.load(scene_file)
            world = scene.build()  # the start's world too (Topology._build_world), if the file stays the same
            self._scene_defaults = scene_values(scene, world)
            self._start_world = (scene, world)
        for spec in params.SPECS:
            if spec.name == sf.name:
                continue
            default = spec.default
            if spec.name == "frame_prefix":
                default = params.frame_prefix_for(self.get_namespace())
            if spec.name in self._scene_defaults:
                default = min(max(self._scene_defaults[spec.name], spec.lo), spec.hi)
            self._declare(spec, default)
        self._p: dict[str, Any] = {s.name: self.get_parameter(s.name).value for s in params.SPECS}
        for name in ("world_frame", "frame_prefix"):  # the on-set callback checks them from here on
            why = params.check({name: self._p[name]}, set())
            if why:
                raise InvalidParameterValueException(name, self._p[name], why)
        self._refuse_sim_time()

    def _declare(self, spec: params.Spec, default: Any) -> None:
        """Declare one parameter; an integer given on the command line for a double (-p gravity:=5)
        is taken as that double instead of aborting the start."""
        try:
            self.declare_parameter(spec.name, default, params.descriptor(spec))
        except InvalidParameterTypeException:
            over = getattr(self, "_parameter_overrides", {}).get(spec.name)
            if not (isinstance(default, float) and over is not None and over.type_ == Parameter.Type.INTEGER):
                raise
            self._parameter_overrides[spec.name] = Parameter(spec.name, Parameter.Type.DOUBLE, float(over.value))
            self.declare_parameter(spec.name, default, params.descriptor(spec))

    def _refuse_sim_time(self) -> None:
        """The sim is the clock: use_sim_time would make its node clock follow its own /clock (or, with
        publish_clock false, another sim's), standing still while it is paused. Launch files often set
        use_sim_time for every node, so it is not a start failure: the value is reset to false with an
        error in the log, and the on-set callback refuses true later (_on_set_parameters)."""
        if self.get_parameter("use_sim_time").value is True:
            self.set_parameters([Parameter("use_sim_time", Parameter.Type.BOOL, False)])
            self.get_logger().error(
                "use_sim_time:=true ignored: this node is the sim and publishes the sim time itself; it keeps "
                "wall time (set use_sim_time only on the nodes that consume /clock)")

    def _watch_parameters(self) -> None:
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._post_set_parameters)

    def _on_set_parameters(self, plist: list[Parameter]) -> SetParametersResult:
        if any(p.name == "use_sim_time" and p.value is True for p in plist):
            why = ("use_sim_time: the sim publishes the sim time itself and keeps wall time; set use_sim_time "
                   "on the nodes that consume /clock")
            self._warn("param:use_sim_time", f"parameter rejected: {why}")
            return SetParametersResult(successful=False, reason=why)
        cand = {p.name: p.value for p in plist if p.name in params.BY_NAME}
        why = params.check(cand, set(self._dyn_names))
        if why:
            self._warn(f"param:{why[:40]}", f"parameter rejected: {why}")
            return SetParametersResult(successful=False, reason=why)
        return SetParametersResult(successful=True)

    def _post_set_parameters(self, plist: list[Parameter]) -> None:
        with self._executor_lock():
            self._post_set_locked(plist)

    def _post_set_locked(self, plist: list[Parameter]) -> None:
        for prm in plist:
            if prm.name not in params.BY_NAME:
                continue
            self._p[prm.name] = prm.value
            try:
                self._apply_param(prm.name, prm.value)
            except Exception as exc:  # the value passed the checks; report what C said anyway
                self._warn(f"param-apply:{prm.name}", f"parameter {prm.name}={prm.value}: {exc}")

    def _apply_param(self, name: str, value: Any) -> None:
        if name in WORLD_SETTINGS:
            self._apply_setting(self.world, name, float(value))
            if name == "green_mass":
                self._masses = np.array(self.world.masses)
                self._inertias = np.array(self.world.inertias)
        elif name in ("time_step", "state_rate", "tf_rate", "marker_rate", "clock_rate"):
            self._periods()
            if name == "time_step":
                self._make_scanners()  # their periods in steps
            self._schedule_dirty = True
        elif name == "real_time_factor":
            self._schedule_dirty = True
        elif name in ("world_frame", "frame_prefix"):
            self._on_topology()
        elif name == "cmd_vel_stamped":
            self._make_cmd_vel_sub()
        elif name == "cmd_vel_body":
            self._cmd_vel = None
