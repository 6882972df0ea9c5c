"""How long a large scene file takes to load: collide.load_scene alone, and a sim node's start and
one ~/reset with that scene file.

    source scripts/env.sh && nice python bench/scene_load.py [--bodies 10000] [--repeat 3] [--json]
                                                             [--node-repeat 1] [--no-node] [--profile]

The scene is bench/node_bench.py's generated one (big_scene: N 0.5 m boxes on a 2 m grid inside
walls, random speeds), written as YAML and, with --json, also as JSON, into a temp dir. Prints, per
file, its size and the median (and range) over --repeat runs of
- load_scene(path): parse, validate and the trial build (what every load does),
- load_scene(path, validate=False): parse and validate the structure only,
and then, unless --no-node, for the YAML file: the wall time from starting a node process
(`python -m collide_ros.node -p scene_file:=...`) to its first bodies/states message, and of one
~/reset service call (request to response: the reset rebuilds the world from the file), median over
--node-repeat node starts. --profile
prints cProfile's top entries of one load_scene. Uses ROS_DOMAIN_ID from the environment, or picks a
free one in the bench range 75-79. Not run by the tests (timings).
"""
from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Callable

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "ros_pkg"))
sys.path.insert(0, str(ROOT / "bench"))

import collide  # noqa: E402

from node_bench import big_scene, pick_domain  # noqa: E402


def timed(fn: Callable[[], object], repeat: int) -> list[float]:
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def show(label: str, times: list[float]) -> None:
    print(f"  {label:<34} median {statistics.median(times):8.3f} s  (min {min(times):.3f}, max {max(times):.3f}, "
          f"{len(times)} runs)", flush=True)


def node_start_and_reset(path: Path, repeat: int) -> tuple[list[float], list[float]]:
    """Wall seconds from a node's start to its first bodies/states, and of one ~/reset call, per run."""
    import rclpy
    from std_srvs.srv import Empty

    from collide_ros.testing import NodeProcess, SimClient

    starts, resets = [], []
    for _ in range(repeat):
        ctx = rclpy.Context()
        rclpy.init(context=ctx)
        client = SimClient(context=ctx, watch=("bodies/states",))
        t0 = time.perf_counter()
        proc = NodeProcess("-p", f"scene_file:={path}", "-p", "real_time_factor:=1.0")
        try:
            if not client.wait_for(lambda: client.count["bodies/states"] > 0, timeout=600.0):
                raise RuntimeError(f"the node published no bodies/states; log:\n{proc.output()}")
            starts.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            if client.call(Empty, "reset", timeout=600.0) is None:
                raise RuntimeError(f"~/reset did not answer; log:\n{proc.output()}")
            resets.append(time.perf_counter() - t0)
        finally:
            client.close()
            proc.stop()
            rclpy.shutdown(context=ctx)
    return starts, resets


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=10000, help="boxes in the generated scene (default 10000)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per measurement (median)")
    ap.add_argument("--json", action="store_true", help="also time the same scene as a JSON file")
    ap.add_argument("--node-repeat", type=int, default=1, help="node starts (each with one ~/reset) (median)")
    ap.add_argument("--no-node", action="store_true", help="only load_scene, no node start / ~/reset")
    ap.add_argument("--profile", action="store_true", help="cProfile one load_scene of the YAML file")
    a = ap.parse_args()
    print(f"PyYAML {yaml.__version__}, libyaml {'yes' if yaml.__with_libyaml__ else 'no'}")
    with tempfile.TemporaryDirectory(prefix="scene_load_") as tmp:
        ypath = Path(tmp) / f"bench_{a.bodies}.yaml"
        big_scene(a.bodies, ypath)
        paths = [ypath]
        if a.json:
            jpath = ypath.with_suffix(".json")
            collide.load_scene(ypath, validate=False).dump(jpath)
            paths.append(jpath)
        for path in paths:
            print(f"{path.name}: {a.bodies} bodies, {path.stat().st_size / 1e6:.2f} MB")
            show("load_scene", timed(lambda: collide.load_scene(path), a.repeat))
            show("load_scene(validate=False)", timed(lambda: collide.load_scene(path, validate=False), a.repeat))
        if a.profile:
            prof = cProfile.Profile()
            prof.runcall(collide.load_scene, ypath)
            pstats.Stats(prof).sort_stats("cumulative").print_stats(25)
        if not a.no_node:
            lock = pick_domain()
            os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
            try:
                starts, resets = node_start_and_reset(ypath, a.node_repeat)
            finally:
                if lock is not None:
                    lock.release()  # type: ignore[attr-defined]
            print(f"node with {ypath.name}:")
            show("start to first bodies/states", starts)
            show("~/reset call", resets)
    return 0


if __name__ == "__main__":
    sys.exit(main())
