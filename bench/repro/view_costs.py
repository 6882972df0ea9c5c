"""Where the live view's time goes at 1 000 bodies: its ROS callbacks and its frames, in process.

A sim node runs (its own process) with bench/node_bench.py's parameters and 1 000-body scene; this
process builds the view's ROS node (``ViewBridge``, with timing wrappers around its subscription
callbacks) and, at the view's display rate, does what the server does per frame for one page:
``snapshot()`` and ``frames.encode_state()``. Over --seconds it prints, per callback, calls per
second, mean milliseconds and the share of a core, the same for the frame, and this process's
whole CPU share. Then, on the last messages received, rclpy's ``deserialize_message`` (what a
subscription without ``raw=True`` does) against the view's readers (collide_ros/view/cdr_in.py).

    source scripts/env.sh && nice python bench/repro/view_costs.py [--bodies 1000] [--seconds 10] [--rate 30]
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "ros_pkg"))
import node_bench  # noqa: E402  (pick_domain, parse_case, node_args)

GIVE_UP = 90.0  # s


def timed(fn: Callable[[float], Any], n: int = 5) -> float:
    """Median seconds of fn over n calls."""
    out = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn(0.0)
        out.append(time.perf_counter() - t0)
    return statistics.median(out)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bodies", default="1000", help="node_bench case (6, 1000, ...)")
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--rate", type=float, default=30.0, help="frames per second, as the view's --rate")
    a = p.parse_args()
    lock = node_bench.pick_domain()
    import rclpy
    from libcollide_msgs.msg import BodyStates
    from rclpy.serialization import deserialize_message
    from visualization_msgs.msg import MarkerArray

    from collide_ros.testing import NodeProcess
    from collide_ros.view import cdr_in, frames
    from collide_ros.view.bridge import ViewBridge, spin_in_thread

    spent: dict[str, list[float]] = defaultdict(list)
    last: dict[str, bytes] = {}

    class TimedBridge(ViewBridge):
        def _time(self, key: str, fn: Callable[[bytes], None], raw: bytes) -> None:
            t0 = time.perf_counter()
            fn(raw)
            spent[key].append(time.perf_counter() - t0)
            last[key] = raw

        def _on_states(self, raw: bytes) -> None:
            self._time("bodies/states", super()._on_states, raw)

        def _on_markers(self, raw: bytes) -> None:
            self._time("markers", super()._on_markers, raw)

        def _on_contacts(self, raw: bytes) -> None:
            self._time("contacts", super()._on_contacts, raw)

    case = node_bench.parse_case(a.bodies)
    print(f"ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']}, {os.cpu_count()} cores, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average "
          f"{' '.join(f'{x:.1f}' for x in os.getloadavg())}", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        node = NodeProcess(*node_bench.node_args(case, Path(tmp)))
        rclpy.init()
        bridge = TimedBridge()
        thread, ex = spin_in_thread(bridge)
        try:
            end = time.monotonic() + GIVE_UP
            while time.monotonic() < end:
                with bridge.lock:
                    if bridge.scene.matched and len(bridge.scene.names) >= min(case.bodies, 1):
                        break
                time.sleep(0.1)
            with bridge.lock:
                named = len(bridge.scene.name_of)
            print(f"{len(bridge.shapes()['bodies'])} shapes, {named} named as dynamic bodies", flush=True)
            spent.clear()
            frame_times: list[float] = []
            sizes: list[int] = []
            period = 1.0 / a.rate
            c0, t0 = time.process_time(), time.monotonic()
            while time.monotonic() - t0 < a.seconds:
                f0 = time.perf_counter()
                _seq, state = bridge.snapshot()
                sizes.append(len(frames.encode_state(state)))
                frame_times.append(time.perf_counter() - f0)
                time.sleep(max(0.0, period - (time.perf_counter() - f0)))
            wall = time.monotonic() - t0
            cpu = time.process_time() - c0
            sim_rate = None
            with bridge.lock:
                sim_rate = bridge.scene.rtf
        finally:
            rclpy.try_shutdown()
            thread.join(timeout=2.0)
            ex.shutdown(timeout_sec=1.0)
            bridge.destroy_node()
            node.stop()
    if lock is not None:
        lock.release()

    print(f"\nover {wall:.1f} s wall (node's real-time factor {sim_rate}); this process: "
          f"{100 * cpu / wall:.0f} % of a core\n")
    print("| what | per second | mean (ms) | share of a core |")
    print("|---|---|---|---|")
    for key, xs in [*spent.items(), (f"frame: snapshot + encode_state ({statistics.median(sizes) / 1e3:.0f} kB)",
                                     frame_times)]:
        if xs:
            print(f"| {key} | {len(xs) / wall:.1f} | {1e3 * statistics.mean(xs):.3f} | {100 * sum(xs) / wall:.1f} % |")
    print("\nthe last messages read both ways (median of 5, ms):\n")
    print("| message | bytes | rclpy deserialize_message | cdr_in |")
    print("|---|---|---|---|")
    if "bodies/states" in last:
        raw = last["bodies/states"]
        sr = cdr_in.StatesReader()
        print(f"| bodies/states | {len(raw)} | {1e3 * timed(lambda _: deserialize_message(raw, BodyStates)):.2f} "
              f"| {1e3 * timed(lambda _: sr.read(raw)):.2f} |")
    if "markers" in last:
        raw = last["markers"]
        mr = cdr_in.MarkersReader()
        first = timed(lambda _: cdr_in.MarkersReader().read(raw))
        mr.read(raw)
        print(f"| markers | {len(raw)} | {1e3 * timed(lambda _: deserialize_message(raw, MarkerArray), 3):.2f} "
              f"| {1e3 * timed(lambda _: mr.read(raw)):.2f} (shortcut), {1e3 * first:.2f} (read in full) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
