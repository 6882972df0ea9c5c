"""The sim node's step on the node bench's pile scene, in process: the step against each publisher.

`bench/node_bench.py --bodies pile200` finds the node far from real time on 200 boxes (0.3-0.8 m,
mu 0.5, e 0.3) dropped into a walled box, with its /diagnostics reporting more time publishing per
step than stepping. This script builds the same node in this process (`SimNode`, the scene file of
`node_bench.pile_scene`, the node's default parameters: 1 ms steps, 100 Hz state, 50 Hz tf, 20 Hz
markers, 1 kHz clock), calls its `step_once()` --steps times from the drop on (no executor, no
subscribers, so the publishers only serialize and hand over to DDS), and times with wrappers
- the physics step (`World.step` as the node calls it) and everything `step_once` does after it,
- each publisher's `publish()`: bodies/poses, bodies/states, energy (an rclpy message, converted and
  serialized inside publish), contacts, /tf, markers, /clock (CDR bytes, handed to DDS as they are),
- `_take_contacts` (the impacts kept since the last state publish and the resting contacts), and
  the rest of `_publish_state`: building the `Energy` Python message and writing the contacts
  message's CDR bytes (`cdr.ContactsCdr`; up to commit 04f7bee, one Python `Contact` per contact).
It prints the totals per step (ms per 1 ms step, the unit of /diagnostics' step_time_mean_ms and
publish_time_mean_ms) for each --bin of steps and for the whole run, and the contacts per contacts
message (the impacts since the last message, then the resting contacts; at most 1000) and how many
of them are impacts.

    source scripts/env.sh && python bench/repro/pile200_node_publish.py [--steps 3000] [--bin 500]
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any, Callable

import yaml

import collide

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from node_bench import pick_domain, pile_scene  # noqa: E402  (bench/node_bench.py)

PARTS = ("physics step", "after the step", "publish bodies/poses", "publish bodies/states", "publish energy",
         "publish contacts", "take contacts", "build msgs (Energy, contacts CDR)", "publish /tf", "publish markers",
         "publish /clock")


class Timers:
    """Accumulated wall time per part, and the contacts per contacts message."""

    def __init__(self) -> None:
        self.t: dict[str, float] = defaultdict(float)
        self.contacts: list[int] = []
        self.impacts: list[int] = []

    def wrap(self, key: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                self.t[key] += time.perf_counter() - t0
        return timed


def instrument(node: Any, tm: Timers) -> None:
    """Wrap the node's step, publishers and contact gathering with timers (instance attributes)."""
    pubs = {"publish bodies/poses": node._pub_poses, "publish bodies/states": node._pub_states,
            "publish energy": node._pub_energy, "publish contacts": node._pub_contacts, "publish /tf": node._pub_tf,
            "publish markers": node._pub_markers, "publish /clock": node._pub_clock}
    for key, pub in pubs.items():
        pub.pub.publish = tm.wrap(key, pub.pub.publish)
    take = node._take_contacts

    def take_counted() -> Any:
        c = take()
        tm.contacts.append(len(c))
        tm.impacts.append(int((c["kind"] == collide.COLLISION).sum()))
        return c
    node._take_contacts = tm.wrap("take contacts", take_counted)
    node._publish_state = tm.wrap("_publish_state", node._publish_state)
    world_step = node.world.step
    node.world.step = tm.wrap("physics step", world_step)


def row(tm: Timers, steps: int) -> dict[str, float]:
    """ms per step of each part; 'build ...' = _publish_state minus what it calls that is timed."""
    inside = ("publish bodies/poses", "publish bodies/states", "publish energy", "publish contacts", "take contacts")
    out = {k: 1e3 * tm.t[k] / steps for k in PARTS if k in tm.t}
    out["build msgs (Energy, contacts CDR)"] = 1e3 * (tm.t["_publish_state"] - sum(tm.t[k] for k in inside)) / steps
    out["after the step"] = 1e3 * (tm.t["step_once"] - tm.t["physics step"]) / steps
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=200, help="boxes in the pile")
    ap.add_argument("--steps", type=int, default=3000, help="node steps of 1 ms from the drop on")
    ap.add_argument("--bin", type=int, default=500, help="steps per printed line")
    a = ap.parse_args()
    lock = pick_domain()
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    import rclpy

    from collide_ros.node import SimNode
    tmp = Path(tempfile.mkdtemp()) / "pile.yaml"
    tmp.write_text(yaml.safe_dump(pile_scene(a.bodies)))
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    node = SimNode(context=ctx, cli_args=["--ros-args", "-r", "__ns:=/pile_publish", "-p", f"scene_file:={tmp}"])
    try:
        tm = Timers()
        instrument(node, tm)
        step_once = tm.wrap("step_once", node.step_once)
        print(f"{len(node._dyn_names)} dynamic bodies, time_step {node._p['time_step']} s; ms per step:\n")
        print("| steps | " + " | ".join(PARTS) + " | contacts per message (mean / max) | of which impacts (mean) |")
        print("|---" * (len(PARTS) + 3) + "|")
        total = Timers()
        for k in range(a.steps):
            if not step_once():
                print(f"step {k + 1} failed: {node.last_rejection}")
            if (k + 1) % a.bin == 0 or k + 1 == a.steps:
                n = (k % a.bin) + 1
                r = row(tm, n)
                cs, hits = tm.contacts or [0], tm.impacts or [0]
                print(f"| {k + 1 - n + 1}-{k + 1} | " + " | ".join(f"{r.get(p, 0.0):.3f}" for p in PARTS)
                      + f" | {sum(cs) / len(cs):.0f} / {max(cs)} | {sum(hits) / len(hits):.0f} |", flush=True)
                for key, v in tm.t.items():
                    total.t[key] += v
                total.contacts += tm.contacts
                total.impacts += tm.impacts
                tm.t.clear()
                tm.contacts, tm.impacts = [], []
        r = row(total, a.steps)
        pub = sum(v for p, v in r.items() if p not in ("physics step", "after the step"))
        print(f"\nall {a.steps} steps: physics step {r['physics step']:.3f} ms, after it {r['after the step']:.3f} ms "
              f"per step, of which publishing {pub:.3f} (contacts: take {r['take contacts']:.3f} + build "
              f"{r['build msgs (Energy, contacts CDR)']:.3f} + publish {r['publish contacts']:.3f}); "
              f"{sum(total.contacts) / max(len(total.contacts), 1):.0f} contacts per message, "
              f"{sum(total.impacts) / max(len(total.impacts), 1):.0f} of them impacts")
    finally:
        node.destroy_node()
        rclpy.shutdown(context=ctx)
        tmp.unlink(missing_ok=True)
        if lock is not None:
            lock.release()  # type: ignore[attr-defined]
    return 0


if __name__ == "__main__":
    sys.exit(main())
