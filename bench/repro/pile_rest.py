"""Whether a dropped pile comes to rest: libcollide against Box2D v3 on the contact bench's mixed piles.

    source scripts/env.sh && python bench/repro/pile_rest.py                  # 100 boxes, seeds 1-3, ~2 min
    source scripts/env.sh && python bench/repro/pile_rest.py --boxes 1000 --seeds 1 --seconds 10

Each engine runs bench/scenes.py's mixed_boxes(n, seed) (boxes 0.3-0.8 m, mu 0.5, e 0.3, dropped into a
walled box; libcollide at its defaults, Box2D v3 at bench/contact.py's settings, sleep off in both) at
dt 1/60. Printed per engine and second: the kinetic energy of the bodies' centres (J), the median and
largest centre displacement over that second (mm), the largest centre speed at its end (m/s) and the CPU
per step over that second (µs, this thread's time; one run on a shared machine: a trend, not a bench);
then a summary: the second from which no body's centre moved 1 µm in any later second (at rest), and the
median CPU per step over the last 3 s. A pile that creeps keeps moving by micrometres to millimetres a
second.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import contact  # noqa: E402
import scenes  # noqa: E402
from engines.box2d3 import Box2D3  # noqa: E402
from engines.libcollide import LibCollide  # noqa: E402

DT = 1 / 60
PER_SECOND = 60


ENGINES = {"libcollide": LibCollide, "box2d3": Box2D3}


def engines(scene: Any, names: list[str]) -> list[tuple[str, Any]]:
    return [(name, ENGINES[name](scene, dict(contact.CONTACT_SETTINGS[name]))) for name in names]


STILL_MM = 1e-3  # a second in which no body's centre moved this far (1 µm) is a second of rest


def summary(largest_mm: list[float], cpu: list[float]) -> str:
    """When the pile came to rest for good (every later second still), and the last 3 s's median CPU."""
    after = len(largest_mm)
    while after > 0 and largest_mm[after - 1] < STILL_MM:
        after -= 1
    still = f"{1e3 * STILL_MM:g} µm"
    rest = (f"at rest from {after} s (no body moved {still} in a second after that)" if after < len(largest_mm)
            else f"not at rest (a body moved {still} or more in the last second)")
    return f"{rest}; last 3 s: median {np.median(cpu[-3:]):.0f} µs/step"


def seconds_of(eng: Any, masses: np.ndarray, seconds: int) -> list[str]:
    """One line per simulated second: kinetic energy, median / largest displacement, largest speed and
    CPU per step, then the summary line."""
    lines = []
    largest: list[float] = []
    cpus: list[float] = []
    prev = eng.states()
    for sec in range(1, seconds + 1):
        t0 = time.thread_time()
        for _ in range(PER_SECOND):
            eng.step(DT)
        cpu = 1e6 * (time.thread_time() - t0) / PER_SECOND
        s = eng.states()
        d = np.hypot(s[:, 0] - prev[:, 0], s[:, 1] - prev[:, 1])
        speed = np.hypot(s[:, 3], s[:, 4])
        ke = 0.5 * float(np.sum(masses * speed ** 2))
        lines.append(f"{sec:3d} s  KE {ke:9.2e} J  moved median {1e3 * np.median(d):9.2e} / largest "
                     f"{1e3 * d.max():9.2e} mm  speed max {speed.max():8.2e} m/s  cpu {cpu:8.0f} µs/step")
        prev = s
        largest.append(1e3 * float(d.max()))
        cpus.append(cpu)
    lines.append(summary(largest, cpus))
    return lines


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--boxes", type=int, default=100)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--seconds", type=int, default=10)
    ap.add_argument("--engines", default="libcollide,box2d3", help="of " + ",".join(ENGINES))
    args = ap.parse_args()
    names = args.engines.split(",")
    unknown = [n for n in names if n not in ENGINES]
    if unknown:
        ap.error(f"unknown engine(s) {','.join(unknown)}: choose from {','.join(ENGINES)}")
    for seed in (int(x) for x in args.seeds.split(",")):
        scene = scenes.mixed_boxes(args.boxes, seed=seed)
        masses = np.array([b.mass for b in scene.boxes if not b.static])
        for name, eng in engines(scene, names):
            print(f"mixed{args.boxes} seed {seed}, {name}:", flush=True)
            for line in seconds_of(eng, masses, args.seconds):
                print("  " + line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
