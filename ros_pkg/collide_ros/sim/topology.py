"""The node's world: built from the scene (the default scene from the parameters, or a scene file with
the parameters that differ from its own settings), the sim time across resets, and everything keyed by
the body set (rows, names, masses), recomputed after a build, a spawn, a kill or a frame change."""
from __future__ import annotations

import numpy as np

import collide

from collide_ros.sim.scanners import ScannerSpec


#: parameters that change the world in place (applied at once)
WORLD_SETTINGS = ("gravity", "damping", "elasticity", "green_mass")


def scene_values(scene: collide.Scene, world: collide.World) -> dict[str, float]:
    """The values of WORLD_SETTINGS a scene brings: the defaults of those parameters with a scene file."""
    s = world.settings
    vals = {"gravity": -float(s["gravity"][1]), "damping": float(s["damping"])}
    dyn = [b for b in scene.bodies if not b.get("static")]
    vals["elasticity"] = float(dyn[0]["elasticity"]) if dyn else 1.0
    green = [b for b in scene.bodies if b["name"] == "block1"]
    vals["green_mass"] = float(green[0]["mass"]) if green else 1.0
    return vals


class Topology:
    """Owns ``world``, ``_time_offset`` (sim time before the last reset), ``_colors`` (scene colours by
    body), ``_scanner_specs`` (the scene's laser scanners) and the body-set tables: ``_names``, ``_ids``, ``_static``, ``_dyn_rows``, ``_dyn_names``,
    ``_row_of``, ``_name_of_id``, ``_bodies``, ``_masses``, ``_inertias``."""

    world: collide.World

    @property
    def sim_time(self) -> float:
        return self._time_offset + self.world.time

    def _scene(self) -> collide.Scene:
        if self._p["scene_file"]:
            return self._scene_file.load(self._p["scene_file"])  # re-read, parsed again if it changed
        return collide.default_scene(blocks=int(self._p["blocks"]), green_mass=float(self._p["green_mass"]),
                                     gravity=float(self._p["gravity"]), elasticity=float(self._p["elasticity"]),
                                     damping=float(self._p["damping"]))

    def _build_world(self) -> None:
        scene = self._scene()
        start, self._start_world = self._start_world, None
        world = start[1] if start is not None and start[0] is scene else scene.build()
        self._colors = {b["name"]: b.get("color") for b in scene.bodies}
        self._scanner_specs = [ScannerSpec.from_scene(sc) for sc in scene.scanners]
        if self._p["scene_file"]:
            # A scene file brings its own settings; a parameter applies only where it differs from the file.
            for key in WORLD_SETTINGS:
                if self._p[key] != self._scene_defaults[key]:
                    self._apply_setting(world, key, self._p[key])
        self.world = world

    def _apply_setting(self, world: collide.World, name: str, value: float) -> None:
        """One of WORLD_SETTINGS applied to ``world``."""
        if name == "gravity":
            world.set_gravity((0.0, -value))
        elif name == "damping":
            world.set_damping(value)
        elif name == "elasticity":
            world.set_elasticity(value)
        elif "block1" in world:  # green_mass
            world.body("block1").mass = value
        else:
            self._warn("green_mass", "green_mass: this world has no body 'block1'; nothing to apply")

    def _on_topology(self, deleteall: bool = False) -> None:
        """Recompute everything that depends on the body set (after build, spawn, kill, frame change)."""
        w = self.world
        self._names = w.names
        self._ids = np.array(w.ids, dtype=np.int64)
        self._static = np.array(w.static_mask, dtype=bool)
        self._dyn_rows = np.flatnonzero(~self._static)
        self._dyn_names = [self._names[i] for i in self._dyn_rows]
        self._row_of = {n: i for i, n in enumerate(self._names)}
        self._name_of_id = {int(i): n for i, n in zip(self._ids, self._names)}
        self._bodies = {n: w.body(n) for n in self._names}
        self._masses = np.array(w.masses)
        self._inertias = np.array(w.inertias)
        self._make_writers()
        self._make_scanners()
        self._make_thrust_topics()
        self._forget_gone_bodies()
        self._publish_markers(reset=deleteall)
