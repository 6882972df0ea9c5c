"""Contact section of the benchmark: piles, pushing and friction. libcollide, Box2D v3 and Chipmunk
run the same scenes in one run (interleaved per scene, CPU per step = median over repeats), and the
harness measures the quality of each run from the states sampled at every step (bench/metrics.py:
max_overlap, escaped_bodies, energy_steps, sink_creep).

Developer entry (prints the table, touches nothing in docs/):

    source scripts/env.sh
    python bench/contact.py --scenes mixed30,push --engines libcollide,box2d3 --repeats 1 --budget 30

The full section runs from the benchmark driver (`bench/run --sections contact`), which writes
bench/results/latest.json and docs/bench_contact.md. A libcollide run that exceeds its CPU budget
stops after the step in which it passed it and reports the steps it did, their CPU per step and the
quality of the part it ran; one that sits inside a single step for 2 x budget + 10 s of wall time
is killed and reported with the samples it reached."""
from __future__ import annotations

import argparse
import math
import os
import sys
import time
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import harness  # noqa: E402
import metrics  # noqa: E402
import scenes  # noqa: E402
from harness import Task  # noqa: E402

ENGINES = ("libcollide", "box2d3", "pymunk")
# Per-engine settings of this section, passed to the adapters (bench/engines/*.py). The peers' values
# are the fair settings their adapters default to (sleep is off in both adapters whatever is set
# here); libcollide's dict goes to collide.World as keyword arguments, so a new lc_world_def field
# (e.g. "allow_sleep": 0) is added here and nowhere else.
CONTACT_SETTINGS: dict[str, dict[str, Any]] = {
    "libcollide": {},
    "box2d3": {"substeps": 4, "restitution_threshold": 0.0, "continuous": True},
    "pymunk": {"iterations": 10, "collision_slop": 0.005},
}
DT = 1 / 60
PEER_BUDGET = 600.0       # s of CPU: a safety net only; the largest peer run (pyramid100) takes ~25 s
BUDGET_QUICK = 20.0       # s of CPU per libcollide task with --quick
BUDGET_DEFAULT = 60.0
GROUND_ONLY = (-math.inf, 0.0, math.inf, math.inf)   # no walls: a centre below the ground top escaped


@dataclass(frozen=True)
class ContactScene:
    key: str
    scene: scenes.Scene
    inner: tuple[float, float, float, float]   # escape box for the centres (xmin, ymin, xmax, ymax)
    at_rest: bool                              # starts at rest with the top box last: sink and creep apply
    what: str                                  # one line for the report


def _pyramid(base: int) -> ContactScene:
    return ContactScene(f"pyramid{base}", replace(scenes.pyramid(base), duration=10.0), GROUND_ONLY, True,
                        f"pyramid base {base} (unit boxes, μ 0.6, e 0, g 10), 10 s")


def _mixed(n: int) -> ContactScene:
    sc = scenes.mixed_boxes(n)
    return ContactScene(f"mixed{n}", sc, sc.meta["inner"], False,
                        f"{n} boxes 0.3-0.8 m falling into a walled box (μ 0.5, e 0.3), 5 s")


def contact_scenes() -> dict[str, Callable[[], ContactScene]]:
    """Scene key -> builder (built on demand: pyramid100 has 5050 boxes)."""
    push = scenes.push_row()
    settle = scenes.settling()
    return {
        "mixed30": lambda: _mixed(30),
        "mixed100": lambda: _mixed(100),
        "mixed1000": lambda: _mixed(1000),
        "push": lambda: ContactScene("push", push, push.meta["inner"], False,
                                     "20 kg block at 6 m/s into a row of 40 boxes (μ 0.5, e 0.3), 5 s"),
        "pyramid20": lambda: _pyramid(20),
        "pyramid50": lambda: _pyramid(50),
        "pyramid100": lambda: _pyramid(100),
        "drop12": lambda: ContactScene("drop12", scenes.drop_on_pyramid(12), GROUND_ONLY, False,
                                       "5 kg box at 8 m/s onto a base-12 pyramid (μ 0.6, e 0, g 10), 5 s"),
        "settling": lambda: ContactScene("settling", settle, (0.0, 0.0, settle.meta["size"], settle.meta["size"]),
                                         False, "20 seed blocks settling in the 10 m box (e 0.8, μ 0.5), 10 s"),
        "stack10": lambda: ContactScene("stack10", scenes.stack(10, e=0.0, mu=0.6), GROUND_ONLY, True,
                                        "10 seed blocks stacked at rest (μ 0.6, e 0, g 9.8), 10 s"),
    }


SCENE_KEYS = tuple(contact_scenes())


def budget_for(engine: str, budget: float) -> float:
    """libcollide gets the section's budget; the peers always finish."""
    return budget if engine == "libcollide" else max(budget, PEER_BUDGET)


def tasks_for(cs: ContactScene, engines: tuple[str, ...], budget: float) -> list[Task]:
    """One task per engine, sampled every step. libcollide streams its samples so that a run killed
    inside one step keeps what it did."""
    return [Task(eng, cs.scene, DT, dict(CONTACT_SETTINGS.get(eng, {})), DT, budget_for(eng, budget),
                 key=f"{cs.key}|{eng}", stream=eng == "libcollide") for eng in engines]


def classify(r: dict[str, Any]) -> str:
    """ok, over budget (stopped at its CPU budget, or killed inside a step that outlasted the wall
    limit), or failed (lc_world_step returned an error, NaN states, an exception, a crash)."""
    s = str(r.get("status", "?"))
    if s == "ok":
        return "ok"
    if s == "over_budget" or s.startswith("hang"):
        return "over budget"
    return "failed"


def finite_prefix(states: np.ndarray) -> np.ndarray:
    """The samples before the first non-finite one (a run stopped by a NaN keeps its good part)."""
    ok = np.all(np.isfinite(states.reshape(len(states), -1)), axis=1)
    return states if ok.all() else states[:int(np.argmin(ok))]


def summarize(cs: ContactScene, r: dict[str, Any]) -> dict[str, Any]:
    """One engine's run of one scene as a JSON-able row: timing, status, quality, libcollide counters."""
    total = int(round(cs.scene.duration / DT))
    killed = str(r.get("status", "")).startswith("hang")
    steps = int(r.get("steps", r.get("steps_done", 0)) or 0)
    us = r.get("us_per_step", math.nan)
    if killed and steps:   # CPU of the completed steps only: the step it was killed in is not counted
        us = 1e6 * r.get("cpu_done", math.nan) / steps
    row: dict[str, Any] = {
        "key": cs.key, "scene": cs.scene.name, "engine": r["engine"], "label": r.get("label", r["engine"]),
        "bodies": len(cs.scene.dynamic), "total_steps": total, "steps": steps, "status": r.get("status"),
        "kind": classify(r), "killed_in_step": killed, "us_per_step": us, "cpu_all": r.get("cpu_all"),
        "cpu_median": r.get("cpu_median"), "build_cpu": r.get("build_cpu"), "settings": r.get("settings"),
        "stages": r.get("stages", {}), "precision": r.get("precision"),
        "nondeterministic": bool(r.get("nondeterministic", False))}
    if "trace" in r:
        row["trace"] = r["trace"]
    states = r.get("states")
    if states is not None and len(states) >= 2:
        good = finite_prefix(np.asarray(states))
        if len(good) >= 2:
            row.update(metrics.contact_metrics(cs.scene, {"states": good}, cs.inner, cs.at_rest))
            row["samples"] = len(good)
    return row


def add_ratios(rows: list[dict[str, Any]]) -> None:
    """libcollide's µs per step over each peer's, same scene, same run."""
    for lc in (r for r in rows if r["engine"] == "libcollide"):
        for peer in ("box2d3", "pymunk"):
            p = next((r for r in rows if r["key"] == lc["key"] and r["engine"] == peer), None)
            if p is not None and p.get("us_per_step") and not math.isnan(p["us_per_step"]):
                lc[f"ratio_{peer}"] = lc["us_per_step"] / p["us_per_step"]


def run_section(pool: harness.Pool, keys: list[str], engines: tuple[str, ...], repeats: int, budget: float,
                log: Callable[[str], None]) -> dict[str, Any]:
    """Runs the scenes one after another, the engines of a scene interleaved (harness.run_interleaved:
    round-robin, start rotated each repeat; runs that did not finish are not repeated). States are
    reduced to the quality measures as each scene ends, so memory holds one scene's runs at most."""
    builders = contact_scenes()
    rows: list[dict[str, Any]] = []
    info: dict[str, Any] = {}
    for key in keys:
        cs = builders[key]()
        tasks = tasks_for(cs, engines, budget)
        log(f"contact {key}: {len(cs.scene.dynamic)} bodies, {len(tasks)} engines x {repeats} repeat(s)")
        res = harness.run_interleaved(pool, tasks, repeats, log)
        t0 = time.time()
        scene_rows = [summarize(cs, res[t.key]) for t in tasks]
        add_ratios(scene_rows)
        rows += scene_rows
        info[key] = {"name": cs.scene.name, "what": cs.what, "bodies": len(cs.scene.dynamic),
                     "steps": int(round(cs.scene.duration / DT)), "inner": list(cs.inner), "at_rest": cs.at_rest}
        log(f"  {key}: " + ", ".join(f"{r['engine']} {r['us_per_step']:.4g} µs/step ({r['kind']}, "
                                     f"{r['steps']}/{r['total_steps']} steps)" for r in scene_rows)
            + f"; quality measures {time.time() - t0:.1f} s")
    return {"dt": DT, "engines": list(engines), "settings": {e: CONTACT_SETTINGS.get(e, {}) for e in engines},
            "budget_cpu_s": budget, "peer_budget_cpu_s": max(budget, PEER_BUDGET), "repeats": repeats,
            "scenes": info, "rows": rows}


def _parse_list(text: str, known: tuple[str, ...], what: str) -> list[str]:
    items = [x.strip() for x in text.split(",") if x.strip()]
    bad = [x for x in items if x not in known]
    if bad:
        raise SystemExit(f"unknown {what}: {', '.join(bad)}; known: {', '.join(known)}")
    return items


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(SCENE_KEYS), help=f"comma list of {', '.join(SCENE_KEYS)}")
    ap.add_argument("--engines", default=",".join(ENGINES), help=f"comma list of {', '.join(ENGINES)}")
    ap.add_argument("--repeats", type=int, default=1, help="timed repeats per run (median); default 1")
    ap.add_argument("--budget", type=float, default=BUDGET_QUICK,
                    help=f"CPU seconds per libcollide run before it is stopped (default {BUDGET_QUICK:g})")
    ap.add_argument("--json", help="also write the rows (without states) to this JSON file")
    args = ap.parse_args()
    keys = _parse_list(args.scenes, SCENE_KEYS, "scene")
    engines = tuple(_parse_list(args.engines, ENGINES, "engine"))

    def log(msg: str) -> None:
        print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)

    pool = harness.Pool()
    try:
        sec = run_section(pool, keys, engines, args.repeats, args.budget, log)
    finally:
        pool.close()
    import report
    print("\n".join(report.contact_table(sec) + [""] + report.contact_notes(sec)))
    if args.json:
        import json
        with open(args.json, "w") as fh:
            json.dump(sec, fh, indent=1, default=_json)
    return 0


def _json(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    return str(o)


if __name__ == "__main__":
    sys.exit(main())
