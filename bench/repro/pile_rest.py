"""Whether a dropped pile comes to rest: libcollide against Box2D v3 on the contact bench's mixed piles.

    source scripts/env.sh && python bench/repro/pile_rest.py                  # 100 boxes, seeds 1-3, ~2 min
    source scripts/env.sh && python bench/repro/pile_rest.py --boxes 1000 --seeds 1 --seconds 10

Each engine runs bench/scenes.py's mixed_boxes(n, seed) (boxes 0.3-0.8 m, mu 0.5, e 0.3, dropped into a
walled box; libcollide at its defaults, Box2D v3 at bench/contact.py's settings, sleep off in both) at
dt 1/60. Printed per engine and second: the kinetic energy of the bodies' centres (J), the median and
largest centre displacement over that second (mm) and the largest centre speed at its end (m/s). A pile
at rest shows kinetic energy at round-off and displacements that stop growing; a pile that creeps keeps
moving by millimetres a second.
"""
from __future__ import annotations

import argparse
import sys
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


def engines(scene: Any) -> list[tuple[str, Any]]:
    return [("libcollide", LibCollide(scene, dict(contact.CONTACT_SETTINGS["libcollide"]))),
            ("box2d3", Box2D3(scene, dict(contact.CONTACT_SETTINGS["box2d3"])))]


def seconds_of(eng: Any, masses: np.ndarray, seconds: int) -> list[str]:
    """One line per simulated second: kinetic energy, median / largest displacement, largest speed."""
    lines = []
    prev = eng.states()
    for sec in range(1, seconds + 1):
        for _ in range(PER_SECOND):
            eng.step(DT)
        s = eng.states()
        d = np.hypot(s[:, 0] - prev[:, 0], s[:, 1] - prev[:, 1])
        speed = np.hypot(s[:, 3], s[:, 4])
        ke = 0.5 * float(np.sum(masses * speed ** 2))
        lines.append(f"{sec:3d} s  KE {ke:9.2e} J  moved median {1e3 * np.median(d):9.2e} / largest "
                     f"{1e3 * d.max():9.2e} mm  speed max {speed.max():8.2e} m/s")
        prev = s
    return lines


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--boxes", type=int, default=100)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--seconds", type=int, default=10)
    args = ap.parse_args()
    for seed in (int(x) for x in args.seeds.split(",")):
        scene = scenes.mixed_boxes(args.boxes, seed=seed)
        masses = np.array([b.mass for b in scene.boxes if not b.static])
        for name, eng in engines(scene):
            print(f"mixed{args.boxes} seed {seed}, {name}:", flush=True)
            for line in seconds_of(eng, masses, args.seconds):
                print("  " + line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
