"""Contact section of the benchmark: piles, pushing and friction. libcollide, Box2D v3 and Chipmunk
run the same scenes in one run (interleaved per scene, CPU per step = median over repeats), and the
harness measures the quality of each run from the states sampled at every step (bench/metrics.py:
max_overlap, escaped_bodies, energy_steps, sink_creep).

The random piles (mixed30, mixed100, mixed1000: scenes.mixed_boxes) run on several seeds, every
engine on the same ones, the engines interleaved within each seed: one pile's chance arrangement
moves libcollide's cost by 20-30 %. Their row (aggregate_seeds) gives each engine's CPU per step as
the median over the seeds, libcollide / peer as the median over the seeds of each seed's ratio (both
engines on the same pile: the ratio of the two medians can pair one engine's seed with the other's),
and every quality measure as the worst seed's; each seed's row stays in the JSON under per_seed.
Default seeds 1, 2, 3 (--seeds); with --quick mixed1000 runs the first seed only (~10 s of libcollide
CPU per seed).

Developer entry (prints the table, touches nothing in docs/):

    source scripts/env.sh
    python bench/contact.py --scenes mixed30,push --engines libcollide,box2d3 --repeats 1 --budget 30
    python bench/contact.py --scenes mixed30 --engines libcollide,box2d3 --seeds 1,2 --json /tmp/c.json

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
SEEDS = (1, 2, 3)         # the random piles' seeds (scenes.mixed_boxes) unless --seeds says otherwise
SEEDED = ("mixed30", "mixed100", "mixed1000")
QUICK_FIRST_SEED_ONLY = ("mixed1000",)   # ~10 s of libcollide CPU per seed: --quick runs one
# worst seed first: a row's status is its worst seed's
KIND_RANK = {"ok": 0, "over budget": 1, "failed": 2}
# quality measures taken from the worst seed (the largest value; sink_end the largest |value|), each
# with the fields that locate it in that seed's run
WORST_OF: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("max_overlap", ("overlap_sample", "overlap_pair")), ("escaped", ("escape_sample",)),
    ("max_step_gain", ("gain_step",)), ("sink_end", ()), ("sink_max", ()), ("creep", ()),
    ("end_motion_median", ("end_motion_max", "end_speed_max")))


@dataclass(frozen=True)
class ContactScene:
    key: str
    scene: scenes.Scene
    inner: tuple[float, float, float, float]   # escape box for the centres (xmin, ymin, xmax, ymax)
    at_rest: bool                              # starts at rest with the top box last: sink and creep apply
    what: str                                  # one line for the report
    seed: int | None = None                    # the random pile's seed; None for the other scenes


def _pyramid(base: int) -> ContactScene:
    return ContactScene(f"pyramid{base}", replace(scenes.pyramid(base), duration=10.0), GROUND_ONLY, True,
                        f"pyramid base {base} (unit boxes, μ 0.6, e 0, g 10), 10 s")


def _mixed(n: int, seed: int) -> ContactScene:
    sc = scenes.mixed_boxes(n, seed=seed)
    return ContactScene(f"mixed{n}", sc, sc.meta["inner"], False,
                        f"{n} boxes 0.3-0.8 m falling into a walled box (μ 0.5, e 0.3), 5 s", seed)


def contact_scenes() -> dict[str, Callable[..., ContactScene]]:
    """Scene key -> builder (built on demand: pyramid100 has 5050 boxes). The SEEDED scenes' builders
    take the seed (default 1); the others take no argument."""
    push = scenes.push_row()
    settle = scenes.settling()
    return {
        "mixed30": lambda seed=1: _mixed(30, seed),
        "mixed100": lambda seed=1: _mixed(100, seed),
        "mixed1000": lambda seed=1: _mixed(1000, seed),
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


def seeds_for(key: str, seeds: tuple[int, ...], quick: bool) -> tuple[int, ...]:
    """The seeds scene `key` runs on: all of `seeds` for a random pile (with quick, only the first
    for QUICK_FIRST_SEED_ONLY), none for the scenes that are not random."""
    if key not in SEEDED:
        return ()
    return seeds[:1] if quick and key in QUICK_FIRST_SEED_ONLY else seeds


def budget_for(engine: str, budget: float) -> float:
    """libcollide gets the section's budget; the peers always finish."""
    return budget if engine == "libcollide" else max(budget, PEER_BUDGET)


def tasks_for(cs: ContactScene, engines: tuple[str, ...], budget: float) -> list[Task]:
    """One task per engine, sampled every step. libcollide streams its samples so that a run killed
    inside one step keeps what it did."""
    case = cs.key if cs.seed is None else f"{cs.key}|s{cs.seed}"
    return [Task(eng, cs.scene, DT, dict(CONTACT_SETTINGS.get(eng, {})), DT, budget_for(eng, budget),
                 key=f"{case}|{eng}", stream=eng == "libcollide") for eng in engines]


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
    if cs.seed is not None:
        row["seed"] = cs.seed
    if "trace" in r:
        row["trace"] = r["trace"]
    states = r.get("states")
    if states is not None and len(states) >= 2:
        good = finite_prefix(np.asarray(states))
        if len(good) >= 2:
            row.update(metrics.contact_metrics(cs.scene, {"states": good}, cs.inner, cs.at_rest,
                                                window=round(1.0 / DT)))
            row["samples"] = len(good)
    return row


def add_ratios(rows: list[dict[str, Any]]) -> None:
    """libcollide's µs per step over each peer's, same scene, same run."""
    for lc in (r for r in rows if r["engine"] == "libcollide"):
        for peer in ("box2d3", "pymunk"):
            p = next((r for r in rows if r["key"] == lc["key"] and r["engine"] == peer), None)
            if p is not None and p.get("us_per_step") and not math.isnan(p["us_per_step"]):
                lc[f"ratio_{peer}"] = lc["us_per_step"] / p["us_per_step"]


def add_seed_ratios(rows: list[dict[str, Any]]) -> None:
    """libcollide's ratio to each peer over a random pile's seeds: the median of the seeds' own ratios
    (each from the same pile in the same run), not the ratio of the row's medians."""
    for lc in (r for r in rows if r["engine"] == "libcollide"):
        for peer in ("box2d3", "pymunk"):
            ratios = [s.get(f"ratio_{peer}") for s in lc.get("per_seed", [])]
            if any(x is not None and math.isfinite(x) for x in ratios):
                lc[f"ratio_{peer}"] = _median(ratios)


def _worst_seed(rows: list[dict[str, Any]], measure: str) -> dict[str, Any] | None:
    """The seed row with the worst value of a quality measure (first of equals), None if no row has it."""
    have = [r for r in rows if measure in r and not math.isnan(r[measure])]
    if not have:
        return None
    return max(have, key=lambda r: abs(r[measure]) if measure == "sink_end" else r[measure])


def _median(values: list[float]) -> float:
    """Median of the finite values (NaN if none: every seed failed before its first step)."""
    finite = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.median(finite)) if finite else math.nan


def _sum_stages(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """libcollide's counters summed over the seeds (steps too, so a per-step figure covers them all)."""
    total: dict[str, Any] = {}
    for r in rows:
        for k, v in (r.get("stages") or {}).items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                total[k] = total.get(k, 0) + v
    return total


def aggregate_seeds(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """One engine's runs of one random pile on several seeds as one row. us_per_step is the median
    over the seeds of each seed's figure (itself a median over repeats); status, kind and steps are
    the worst seed's (failed > over budget > ok; `status_seed` names it); each quality measure of
    WORST_OF is the worst seed's with its locating fields (`<measure>_seed` names the seed); e_change
    is the median; the counters are summed. The seed rows are kept as they are under per_seed."""
    worst = max(rows, key=lambda r: KIND_RANK.get(r["kind"], 2))
    base = ("key", "engine", "label", "bodies", "total_steps", "steps", "status", "kind", "killed_in_step",
            "settings", "precision")
    out: dict[str, Any] = {k: worst.get(k) for k in base}
    out.update({"scene": ", ".join(r["scene"] for r in rows), "seeds": [r["seed"] for r in rows],
                "status_seed": worst["seed"], "us_per_step": _median([r.get("us_per_step") for r in rows]),
                "stages": _sum_stages(rows),
                "nondeterministic": any(r.get("nondeterministic", False) for r in rows)})
    for measure, fields in WORST_OF:
        w = _worst_seed(rows, measure)
        if w is not None:
            out.update({k: w[k] for k in (measure,) + fields if k in w})
            out[f"{measure}_seed"] = w["seed"]
    if any("e_change" in r for r in rows):
        out["e_change"] = _median([r.get("e_change") for r in rows])
    out["per_seed"] = rows
    return out


def _run_case(pool: harness.Pool, cs: ContactScene, engines: tuple[str, ...], repeats: int, budget: float,
              log: Callable[[str], None]) -> list[dict[str, Any]]:
    """One scene (one seed of a random pile), the engines interleaved (harness.run_interleaved:
    round-robin, start rotated each repeat; runs that did not finish are not repeated), reduced to
    rows with libcollide's ratios to the peers."""
    tasks = tasks_for(cs, engines, budget)
    seed = "" if cs.seed is None else f" seed {cs.seed}"
    log(f"contact {cs.key}{seed}: {len(cs.scene.dynamic)} bodies, {len(tasks)} engines x {repeats} repeat(s)")
    res = harness.run_interleaved(pool, tasks, repeats, log)
    t0 = time.time()
    rows = [summarize(cs, res[t.key]) for t in tasks]
    add_ratios(rows)
    log(f"  {cs.key}{seed}: " + ", ".join(f"{r['engine']} {r['us_per_step']:.4g} µs/step ({r['kind']}, "
                                          f"{r['steps']}/{r['total_steps']} steps)" for r in rows)
        + f"; quality measures {time.time() - t0:.1f} s")
    return rows


def run_section(pool: harness.Pool, keys: list[str], engines: tuple[str, ...], repeats: int, budget: float,
                log: Callable[[str], None], seeds: tuple[int, ...] = SEEDS, quick: bool = False) -> dict[str, Any]:
    """Runs the scenes one after another and a random pile's seeds one after another (seeds_for), the
    engines of each interleaved. States are reduced to the quality measures as each run of the
    engines ends, so memory holds one scene's (one seed's) runs at most. A random pile's rows are
    aggregate_seeds of its seed rows, with libcollide's ratios the median of the seeds' ratios."""
    builders = contact_scenes()
    rows: list[dict[str, Any]] = []
    info: dict[str, Any] = {}
    for key in keys:
        case_seeds = seeds_for(key, seeds, quick)
        cases = [builders[key](sd) for sd in case_seeds] or [builders[key]()]
        per_case = [_run_case(pool, cs, engines, repeats, budget, log) for cs in cases]
        if case_seeds:
            scene_rows = [aggregate_seeds([case_rows[i] for case_rows in per_case]) for i in range(len(engines))]
            add_seed_ratios(scene_rows)
        else:
            scene_rows = per_case[0]
        rows += scene_rows
        cs = cases[0]
        names = [c.scene.name for c in cases]
        info[key] = {"name": ", ".join(names), "names": names, "what": cs.what, "bodies": len(cs.scene.dynamic),
                     "steps": int(round(cs.scene.duration / DT)), "inner": list(cs.inner), "at_rest": cs.at_rest}
        if case_seeds:
            info[key]["seeds"] = list(case_seeds)
    return {"dt": DT, "engines": list(engines), "settings": {e: CONTACT_SETTINGS.get(e, {}) for e in engines},
            "budget_cpu_s": budget, "peer_budget_cpu_s": max(budget, PEER_BUDGET), "repeats": repeats,
            "seeds": list(seeds), "quick_first_seed_only": list(QUICK_FIRST_SEED_ONLY) if quick else [],
            "ratio": "median over seeds of each seed's ratio", "scenes": info, "rows": rows}


def parse_seeds(text: str) -> tuple[int, ...]:
    """--seeds: a comma list of distinct non-negative integers, in the order given."""
    try:
        seeds = tuple(int(x) for x in text.split(",") if x.strip())
    except ValueError:
        raise SystemExit(f"--seeds: not a comma list of integers: {text!r}") from None
    if not seeds or len(set(seeds)) != len(seeds) or min(seeds) < 0:
        raise SystemExit(f"--seeds: give distinct non-negative integers, e.g. 1,2,3 (got {text!r})")
    return seeds


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
    ap.add_argument("--seeds", default=",".join(map(str, SEEDS)),
                    help=f"comma list of seeds for the random piles ({', '.join(SEEDED)}); default "
                    f"{','.join(map(str, SEEDS))}")
    ap.add_argument("--quick", action="store_true",
                    help=f"as bench/run --quick: {', '.join(QUICK_FIRST_SEED_ONLY)} on the first seed only")
    ap.add_argument("--json", help="also write the rows (without states) to this JSON file")
    args = ap.parse_args()
    keys = _parse_list(args.scenes, SCENE_KEYS, "scene")
    engines = tuple(_parse_list(args.engines, ENGINES, "engine"))
    seeds = parse_seeds(args.seeds)

    def log(msg: str) -> None:
        print(f"[{time.strftime('%H:%M:%S')}] {msg}", file=sys.stderr, flush=True)

    pool = harness.Pool()
    try:
        sec = run_section(pool, keys, engines, args.repeats, args.budget, log, seeds, args.quick)
    finally:
        pool.close()
    import report_contact
    print("\n".join(report_contact.contact_table(sec) + [""] + report_contact.contact_notes(sec)))
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
