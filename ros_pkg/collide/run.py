"""Headless runner: python -m collide.run SCENE|--default --until T --dt DT --out DIR [--format csv|json]

Writes trajectories (time, name, x, y, angle, vx, vy, omega of each centre of mass), contacts
(every impact, plus the resting contacts at each sample), energy, and summary.json into DIR.
Exit status: 0 success, 1 the simulation failed mid-run (what was recorded is written), 2 bad input.
"""
from __future__ import annotations

import argparse
import io
import json
import math
import sys
import time
from pathlib import Path
from typing import Any, Sequence, TextIO

import numpy as np

from ._ffi import CollideError
from .scene import Scene, SceneError, default_scene, load_scene
from .world import COLLISION, World

TRAJ_COLUMNS = ("time", "name", "x", "y", "angle", "vx", "vy", "omega")
CONTACT_COLUMNS = ("time", "step_time", "body_a", "body_b", "x", "y", "nx", "ny", "gap", "normal_velocity",
                   "impulse", "tangent_impulse", "force", "kind")
ENERGY_COLUMNS = ("time", "translational", "rotational", "gravitational", "spring", "total", "px", "py",
                  "angular_momentum")


class Progress:
    """A plain-text progress bar on a stream: redrawn in place on a terminal, a line per 10% otherwise."""

    def __init__(self, total: int, stream: TextIO, enabled: bool, width: int = 30) -> None:
        self.total, self.stream, self.enabled, self.width = max(total, 1), stream, enabled, width
        self.tty = enabled and hasattr(stream, "isatty") and stream.isatty()
        self.last = -1
        self.start = time.monotonic()

    def update(self, done: int, sim_time: float, until: float) -> None:
        if not self.enabled:
            return
        pct = int(100 * done / self.total)
        step = 1 if self.tty else 10
        if pct // step == self.last // step and done != self.total:
            return
        self.last = pct
        fill = self.width * done // self.total
        elapsed = time.monotonic() - self.start
        eta = elapsed * (self.total - done) / done if done else 0.0
        line = (f"[{'#' * fill}{'.' * (self.width - fill)}] {pct:3d}% t={sim_time:.3f}/{until:.3f} s "
                f"elapsed {elapsed:.1f} s eta {eta:.1f} s")
        self.stream.write(("\r" + line) if self.tty else line + "\n")
        if self.tty and done == self.total:
            self.stream.write("\n")
        self.stream.flush()


def _positive(text: str) -> float:
    v = float(text)
    if not math.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text}")
    return v


def _nonneg(text: str) -> float:
    v = float(text)
    if not math.isfinite(v) or v < 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return v


def _finite(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text}")
    return v


def _count(text: str) -> int:
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text}")
    return v


def make_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m collide.run", description=__doc__.splitlines()[0].split(": ", 1)[-1],
                                epilog="Scene format: docs/scene_format.md")
    p.add_argument("scene", nargs="?", help="scene file (.yaml, .yml or .json)")
    p.add_argument("--default", action="store_true", help="use the embedded default (seed demo) scene")
    p.add_argument("--until", type=_nonneg, help="simulated time to reach (s); default: the scene's run.duration")
    p.add_argument("--dt", type=_positive, help="time step (s); default: the scene's run.dt")
    p.add_argument("--out", required=True, help="output directory (created if needed)")
    p.add_argument("--format", choices=("csv", "json"), default="csv", help="output format (default csv)")
    p.add_argument("--every", type=_count, default=1, help="record a sample every N steps (default 1)")
    p.add_argument("--include-static", action="store_true", help="also write the (fixed) walls' trajectories")
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    g = p.add_argument_group("default scene options (with --default)")
    g.add_argument("--blocks", type=int, help="number of blocks, 1-6 (default 2)")
    g.add_argument("--green-mass", type=_positive, help="mass of block1 (kg, default 1)")
    g.add_argument("--gravity", type=_finite, help="gravity magnitude, downward (m/s^2, default 0)")
    g.add_argument("--elasticity", type=_finite, help="elasticity of every body, 0-1 (default 1)")
    g.add_argument("--damping", type=_finite, help="damping k (N*s/m, default 0)")
    return p


def _load(args: argparse.Namespace, parser: argparse.ArgumentParser) -> Scene:
    opts = {k: getattr(args, k) for k in ("blocks", "green_mass", "gravity", "elasticity", "damping")
            if getattr(args, k) is not None}
    if args.default == (args.scene is not None):
        parser.error("give exactly one of SCENE or --default")
    if args.default:
        try:
            return default_scene(**opts)
        except ValueError as exc:
            parser.error(str(exc))
    if opts:
        parser.error(f"--{next(iter(opts)).replace('_', '-')} applies only with --default")
    return load_scene(args.scene)


class Recorder:
    """Collects samples as numpy arrays (one copy of the state view per sample, no per-body loops)."""

    def __init__(self, world: World, include_static: bool) -> None:
        self.world = world
        rows = np.ones(len(world), dtype=bool) if include_static else ~world.static_mask
        self.rows = np.flatnonzero(rows)
        self.names = [world.names[i] for i in self.rows]
        self.times: list[float] = []
        self.states: list[np.ndarray] = []
        self.energy: list[list[float]] = []
        self.contacts: list[np.ndarray] = []
        self.contact_step_times: list[np.ndarray] = []

    def sample(self) -> None:
        w = self.world
        self.times.append(w.time)
        self.states.append(w.state[self.rows].copy())
        e = w.energy
        self.energy.append([w.time, e.translational, e.rotational, e.gravitational, e.spring, e.total,
                            e.linear_momentum[0], e.linear_momentum[1], e.angular_momentum])

    def contacts_of_step(self, all_kinds: bool) -> None:
        c = self.world.contacts
        if len(c) == 0:
            return
        keep = c if all_kinds else c[c["kind"] == COLLISION]
        if len(keep):
            self.contacts.append(np.array(keep))
            self.contact_step_times.append(np.full(len(keep), self.world.time))

    # ---- writing ----
    def trajectory_table(self) -> tuple[np.ndarray, list[str]]:
        n = len(self.rows)
        t = np.repeat(np.asarray(self.times), n)
        st = np.concatenate(self.states) if self.states else np.zeros((0, 6))
        return np.column_stack([t, st]), self.names * len(self.times)

    def contact_table(self) -> tuple[np.ndarray, list[str], list[str], list[str]]:
        if not self.contacts:
            return np.zeros((0, 11)), [], [], []
        c = np.concatenate(self.contacts)
        step_t = np.concatenate(self.contact_step_times)
        id_to_name = dict(zip((int(i) for i in self.world.ids), self.world.names))
        num = np.column_stack([c["time"], step_t, c["point"], c["normal"], c["gap"], c["normal_velocity"],
                               c["impulse"], c["tangent_impulse"], c["force"]])
        a = [id_to_name.get(int(i), str(int(i))) for i in c["body_a"]]
        b = [id_to_name.get(int(i), str(int(i))) for i in c["body_b"]]
        kind = ["collision" if k == COLLISION else "resting" for k in c["kind"]]
        return num, a, b, kind


def _csv_lines(num: np.ndarray) -> list[str]:
    if len(num) == 0:
        return []
    buf = io.StringIO()
    np.savetxt(buf, num, fmt="%.17g", delimiter=",")
    return buf.getvalue().splitlines()


def _json_numbers(a: np.ndarray) -> list[list[Any]]:
    """Rows as lists, non-finite numbers as null (JSON has no NaN or infinity)."""
    obj = a.astype(object)
    obj[~np.isfinite(a)] = None
    return obj.tolist()


def _finite_or_none(v: Any) -> Any:
    return v if not isinstance(v, float) or math.isfinite(v) else None


def write_outputs(rec: Recorder, out: Path, fmt: str) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    traj, names = rec.trajectory_table()
    cnum, ca, cb, ckind = rec.contact_table()
    energy = np.asarray(rec.energy).reshape(-1, len(ENERGY_COLUMNS))
    files = [out / f"trajectories.{fmt}", out / f"contacts.{fmt}", out / f"energy.{fmt}"]
    if fmt == "csv":
        with open(files[0], "w") as f:
            f.write(",".join(TRAJ_COLUMNS) + "\n")
            for line, name in zip(_csv_lines(traj), names):
                t, rest = line.split(",", 1)
                f.write(f"{t},{name},{rest}\n")
        with open(files[1], "w") as f:
            f.write(",".join(CONTACT_COLUMNS) + "\n")
            for line, a, b, k in zip(_csv_lines(cnum), ca, cb, ckind):
                t, st, rest = line.split(",", 2)
                f.write(f"{t},{st},{a},{b},{rest},{k}\n")
        with open(files[2], "w") as f:
            f.write(",".join(ENERGY_COLUMNS) + "\n")
            f.writelines(line + "\n" for line in _csv_lines(energy))
    else:
        traj_rows = [dict(zip(TRAJ_COLUMNS, [r[0], n, *r[1:]])) for r, n in zip(_json_numbers(traj), names)]
        cont_rows = [dict(zip(CONTACT_COLUMNS, [r[0], r[1], a, b, *r[2:], k]))
                     for r, a, b, k in zip(_json_numbers(cnum), ca, cb, ckind)]
        energy_rows = [dict(zip(ENERGY_COLUMNS, r)) for r in _json_numbers(energy)]
        for path, rows in zip(files, (traj_rows, cont_rows, energy_rows)):
            path.write_text(json.dumps(rows, indent=None, allow_nan=False) + "\n")
    return files


def run(scene: Scene, until: float, dt: float, out: Path, fmt: str = "csv", every: int = 1,
        include_static: bool = False, progress: bool = True, stderr: TextIO | None = None) -> dict[str, Any]:
    """Run a scene headless and write its outputs; returns the summary (also written as summary.json)."""
    world = scene.build()
    rec = Recorder(world, include_static)
    full = int(math.floor(until / dt + 1e-9))
    tail = until - full * dt
    steps = [dt] * full + ([tail] if tail > 1e-12 * max(1.0, until) else [])
    bar = Progress(len(steps), stderr or sys.stderr, progress and len(steps) >= 500)
    e0 = world.energy.total
    rec.sample()
    wall0 = time.perf_counter()
    error = None
    done = 0
    for i, h in enumerate(steps, 1):
        try:
            world.step(h)
        except CollideError as exc:
            error = f"step {i} at t={world.time:.6g} s failed: {exc}"
            if rec.times[-1] != world.time:
                rec.sample()  # keep the last good state
            break
        done = i
        at_sample = i % every == 0 or i == len(steps)
        rec.contacts_of_step(all_kinds=at_sample)
        if at_sample:
            rec.sample()
        bar.update(i, world.time, until)
    wall = time.perf_counter() - wall0
    files = write_outputs(rec, out, fmt)
    e1 = world.energy.total
    totals = world.counters(last=False)
    summary = {
        "scene": scene.source, "until": until, "dt": dt, "steps": done, "final_time": world.time,
        "samples": len(rec.times), "bodies": world.names,
        "collisions": totals["collisions"], "contacts_written": int(sum(len(c) for c in rec.contacts)),
        "energy_initial": e0, "energy_final": e1,
        "energy_drift_relative": (e1 - e0) / abs(e0) if e0 != 0 else e1 - e0,
        "wall_seconds": wall, "realtime_factor": world.time / wall if wall > 0 else None,
        "state_hash": f"{world.state_hash():016x}", "counters": totals,
        "files": [str(f) for f in files], "error": error,
    }
    summary = {k: _finite_or_none(v) for k, v in summary.items()}
    (out / "summary.json").write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    return summary


def main(argv: Sequence[str] | None = None) -> int:
    parser = make_parser()
    args = parser.parse_args(argv)
    try:
        scene = _load(args, parser)
    except SceneError as exc:
        print(f"collide.run: error: invalid scene\n{exc}", file=sys.stderr)
        return 2
    until = scene.run["duration"] if args.until is None else args.until
    dt = scene.run["dt"] if args.dt is None else args.dt
    if dt > 1:
        parser.error(f"--dt must be <= 1 s, got {dt}")
    try:
        summary = run(scene, until, dt, Path(args.out), args.format, args.every, args.include_static,
                      not args.no_progress)
    except SceneError as exc:
        print(f"collide.run: error: invalid scene\n{exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"collide.run: error: cannot write outputs: {exc}", file=sys.stderr)
        return 2
    drift = summary["energy_drift_relative"]
    print(f"{summary['scene']}: {summary['steps']} steps to t={summary['final_time']:.6g} s, "
          f"{summary['collisions']} collisions, energy drift {'n/a' if drift is None else f'{drift:.3g}'}, "
          f"{summary['wall_seconds']:.2f} s wall -> {args.out}")
    if summary["error"]:
        print(f"collide.run: error: {summary['error']}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
