"""Work-precision study of the contact scenes: what the peers' accuracy costs when their knobs are
turned up, next to libcollide at its defaults. Every point is one engine at one setting on one scene
of bench/contact.py (same scenes, same quality measures: contact.summarize -> metrics.contact_metrics).

    bench/run --sections contact_wp            # writes its section of docs/bench_contact.md and the figure
    source scripts/env.sh && python bench/contact_wp.py --scenes mixed30 --repeats 1   # table only

Knobs (variants()): Box2D v3 substeps 4-64 at its default contact stiffness (30 Hz) and with the
stiffest it applies (contact_hertz = an eighth of the substep rate: the Box2D in pyb2d3 0.11.1 clamps
larger values there), and 4 substeps at dt 1/240, 1/960, 1/3840; Chipmunk iterations 10-160 at
collision_slop 5 mm and 0, and 10 iterations at those dt; libcollide at its defaults. Cost is CPU per
1/60 s of simulated time (median over repeats), so a run at dt 1/240 counts four steps. States are
sampled every 1/60 s in every run, so the overlap is measured at the same instants and the worst
energy gain is per 1/60 s, whatever dt the engine steps with."""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Any, Callable

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import contact  # noqa: E402
import harness  # noqa: E402
from harness import Task  # noqa: E402

FRAME = contact.DT            # 1/60 s: the unit of cost and the sampling interval
SCENES = ("mixed30", "mixed100", "push", "drop12", "pyramid20")
SEEDS = {"mixed30": (1, 2, 3), "mixed100": (1,)}   # mixed100's other seeds add CPU, not a new regime
LIBCOLLIDE_BUDGET = 60.0      # s of CPU per libcollide run (contact.BUDGET_DEFAULT)
DT_DIVISORS = (4, 16, 64)     # the smaller-dt series: dt = 1/60 / divisor (up to 64x the steps per 1/60 s)
B2_BASE = {k: v for k, v in contact.CONTACT_SETTINGS["box2d3"].items() if k != "substeps"}


@dataclass(frozen=True)
class Variant:
    engine: str
    series: str                  # one marker series of the figure
    knob: str                    # the point's setting within its series, e.g. "16 substeps"
    settings: dict[str, Any] = field(default_factory=dict)
    dt: float = FRAME

    @property
    def key(self) -> str:
        return f"{self.series}|{self.knob}"


def variants() -> list[Variant]:
    """Every point of the study, cheapest setting of each series first."""
    v = [Variant("libcollide", "libcollide", "defaults")]
    for n in (4, 8, 16, 32, 64):
        v.append(Variant("box2d3", "Box2D v3 substeps", f"{n} substeps", {**B2_BASE, "substeps": n}))
    for n in (8, 16, 32, 64):   # at 4 substeps the stiffest Box2D applies (30 Hz) is its default
        hz = 0.125 * n / FRAME
        v.append(Variant("box2d3", "Box2D v3 substeps, contact_hertz max", f"{n} substeps, {hz:g} Hz",
                         {**B2_BASE, "substeps": n, "contact_hertz": hz}))
    for div in DT_DIVISORS:
        v.append(Variant("box2d3", "Box2D v3 4 substeps, smaller dt", f"dt 1/{60 * div}",
                         {**B2_BASE, "substeps": 4}, FRAME / div))
    for slop in (0.005, 0.0):
        for it in (10, 20, 40, 80, 160):
            v.append(Variant("pymunk", f"Chipmunk slop {slop * 1e3:g} mm", f"{it} iterations",
                             {"iterations": it, "collision_slop": slop}))
        for div in DT_DIVISORS:
            v.append(Variant("pymunk", f"Chipmunk slop {slop * 1e3:g} mm, 10 it, smaller dt", f"dt 1/{60 * div}",
                             {"iterations": 10, "collision_slop": slop}, FRAME / div))
    return v


def tasks_for(cs: contact.ContactScene, vs: list[Variant]) -> list[Task]:
    case = cs.key if cs.seed is None else f"{cs.key}|s{cs.seed}"
    return [Task(v.engine, cs.scene, v.dt, dict(v.settings), FRAME, contact.budget_for(v.engine, LIBCOLLIDE_BUDGET),
                 label=v.knob, key=f"{case}|{v.key}", stream=v.engine == "libcollide") for v in vs]


def point_row(cs: contact.ContactScene, v: Variant, res: dict[str, Any]) -> dict[str, Any]:
    """contact.summarize's row of one run, with the variant and the cost per 1/60 s simulated."""
    row = contact.summarize(cs, res)
    row.pop("stages", None)
    row.update(series=v.series, knob=v.knob, dt=v.dt, total_steps=int(round(cs.scene.duration / v.dt)),
               us_per_frame=1e6 * FRAME * res.get("cpu_per_sim_s", math.nan))
    return row


def run_section(pool: harness.Pool, keys: list[str], repeats: int, log: Callable[[str], None],
                seeds: dict[str, tuple[int, ...]] | None = None) -> dict[str, Any]:
    """Each scene (each seed) with every variant interleaved (harness.run_interleaved); a random
    pile's points are contact.aggregate_seeds of its seeds' (median cost, worst seed's quality)."""
    seeds = SEEDS if seeds is None else seeds
    builders, vs = contact.contact_scenes(), variants()
    out: dict[str, Any] = {"frame_dt": FRAME, "repeats": repeats, "variants": [v.__dict__ | {"key": v.key} for v in vs],
                           "scenes": {}}
    for key in keys:
        cases = [builders[key](sd) for sd in seeds.get(key, ())] or [builders[key]()]
        per_case = []
        for cs in cases:
            log(f"contact_wp {key}{'' if cs.seed is None else f' seed {cs.seed}'}: {len(vs)} points x {repeats}")
            tasks = tasks_for(cs, vs)
            res = harness.run_interleaved(pool, tasks, repeats, log)
            per_case.append([point_row(cs, v, res[t.key]) for v, t in zip(vs, tasks)])
        points = []
        for i, v in enumerate(vs):
            rows = [c[i] for c in per_case]
            if len(rows) > 1:
                p = contact.aggregate_seeds(rows)
                p.update(series=v.series, knob=v.knob, dt=v.dt,
                         us_per_frame=contact._median([r["us_per_frame"] for r in rows]))
                for r in p["per_seed"]:
                    r.pop("trace", None)
            else:
                p = rows[0]
            points.append(p)
        out["scenes"][key] = {"what": cases[0].what, "bodies": len(cases[0].scene.dynamic),
                              "at_rest": cases[0].at_rest, "seeds": [c.seed for c in cases if c.seed is not None],
                              "points": points}
        log(f"  {key}: " + "; ".join(f"{p['series']} {p['knob']}: {p['us_per_frame']:.4g} µs, "
                                    f"{p.get('max_overlap', math.nan) * 1e3:.3g} mm" for p in points))
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(SCENES), help=f"comma list of {', '.join(contact.SCENE_KEYS)}")
    ap.add_argument("--repeats", type=int, default=1, help="timed repeats per point (median); default 1")
    ap.add_argument("--json", help="also write the section (without states) to this JSON file")
    args = ap.parse_args()
    keys = contact._parse_list(args.scenes, contact.SCENE_KEYS, "scene")

    def log(msg: str) -> None:
        print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)

    pool = harness.Pool()
    try:
        sec = run_section(pool, keys, args.repeats, log)
    finally:
        pool.close()
    import report_contact_wp
    for key in sec["scenes"]:
        print("\n".join(report_contact_wp.scene_table(sec, key) + [""] + report_contact_wp.findings(sec, key) + [""]))
    if args.json:
        import json
        with open(args.json, "w") as fh:
            json.dump(sec, fh, indent=1, default=contact._json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
