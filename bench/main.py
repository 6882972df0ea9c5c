"""libcollide against Box2D v3 (pyb2d3), Chipmunk2D (pymunk) and Box2D 2.3 (pybox2d): speed against
error on the seed and hard-case scenes (docs/benchmarks.md). Use bench/run (it installs bench/requirements.txt first).

    bench/run [--quick | --full] [--sections wp,ref,impacts,cradle,tunnel,stacks,hard,pyramid,scaling]
    bench/run [--quick] --sections contact [--seeds 1,2,3]   # piles, pushing, friction (bench/contact.py)
    bench/run [--quick] --sections contact_wp   # the peers' accuracy knobs on those scenes (bench/contact_wp.py)
    bench/run --scaling-runs 5 --scaling-n 100,1000,2000,5000,20000 --engines box2d3   # bench/scaling_runs.py

Writes docs/benchmarks.md, docs/img/bench_*.png and bench/results/latest.json (and the results behind each
page it writes: bench/results/benchmarks.json, bench_contact.json, bench_contact_wp.json). The contact section is
not in the default list; it writes docs/bench_contact.md, and docs/benchmarks.md only when other
sections ran too (a run of it alone leaves that page as it is). contact_wp writes its own section of
docs/bench_contact.md and docs/img/bench_contact_wp.png. --scaling-runs K runs the scaling section
alone K times and rewrites only its own block of docs/benchmarks.md (bench/results/scaling_runs.json
keeps its data; a full report writes the block from there)."""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from typing import Any, Callable

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import contact  # noqa: E402
import contact_wp  # noqa: E402
import harness  # noqa: E402
import metrics  # noqa: E402
import report  # noqa: E402
import report_contact  # noqa: E402
import report_contact_wp  # noqa: E402
import scaling_runs  # noqa: E402
import scenes  # noqa: E402
from harness import Task  # noqa: E402

ROOT = os.path.dirname(HERE)
PEERS = ("pymunk", "box2d3", "box2d2")
ALL = ("libcollide",) + PEERS
DTS = (1 / 60, 1 / 120, 1 / 240, 1 / 960)

# Work-precision settings per engine: (label, settings, dts). Peers at their defaults plus the fair
# settings of bench/engines/*.py; the variants move each engine's own accuracy knob.
WP_VARIANTS: dict[str, list[tuple[str, dict, tuple[float, ...]]]] = {
    "libcollide": [("libcollide", {}, DTS),
                   ("libcollide tol 1e-6", {"toi_time_tolerance": 1e-6, "toi_distance_tolerance": 1e-8}, DTS[:1]),
                   ("libcollide tol 1e-3", {"toi_time_tolerance": 1e-3, "toi_distance_tolerance": 1e-4,
                                            "contact_gap": 1e-3, "contact_distance": 1e-2}, DTS[:1])],
    "pymunk": [("pymunk", {}, DTS), ("pymunk 30 it", {"iterations": 30}, DTS[:1] + DTS[2:3])],
    "box2d3": [("box2d3", {}, DTS), ("box2d3 1 sub", {"substeps": 1}, DTS[:1]),
               ("box2d3 8 sub", {"substeps": 8}, DTS[:1])],
    "box2d2": [("box2d2", {}, DTS), ("box2d2 20/10 it", {"velocity_iterations": 20, "position_iterations": 10},
                                     DTS[:1])],
}
# Trajectory reference (section "ref"): libcollide at its tightest TOI tolerances. Computed at dt 1/60
# and at 1/960, seeds 1-3 (docs/benchmarks.md, trajectory error, the check line), it agrees with itself to
# 2.6e-12 m over 0.5 s, but at 1 s one g = 9.8 seed is 1.7 m apart and by 2 s all are metres apart
# (chaos), so REF_T = 0.5 s; the check runs to 2 s so that every run shows where the horizon stands.
REF_T = 0.5
REF_CHECK_T = 2.0
REF_CHECK_AT = (0.25, 0.5, 1.0, 2.0)
REF_SETTINGS = {"toi_time_tolerance": 1e-14, "toi_distance_tolerance": 1e-14}
HALF_DIAGONAL = math.hypot(scenes.BLOCK_W, scenes.BLOCK_H) / 2


def log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {msg}", flush=True)


def strip(res: dict[str, Any]) -> dict[str, Any]:
    """JSON-able copy without the bulky state arrays."""
    return {k: v for k, v in res.items() if k not in ("states", "times", "trace")}


class Bench:
    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        self.quick = args.quick
        self.full = args.full
        self.repeats = 1 if args.quick else (5 if args.full else 3)
        self.budget = args.budget or (4.0 if args.quick else (60.0 if args.full else 15.0))
        self.pool = harness.Pool()
        self.out: dict[str, Any] = {}

    def run(self, tasks: list[Task], repeats: int | None = None) -> dict[str, dict[str, Any]]:
        res = harness.run_interleaved(self.pool, tasks, self.repeats if repeats is None else repeats, log)
        self.time_stages(tasks, res)
        return res

    def time_stages(self, tasks: list[Task], res: dict[str, dict[str, Any]]) -> None:
        """One more run of every finished libcollide task with stage timing on, for the per-stage
        shares of its time (`stage_times`: s per step). Separate from the timed repeats: the clock
        reads cost ~5-15 % of a small scene's step."""
        for t in tasks:
            r = res.get(t.key)
            if t.engine != "libcollide" or r is None or r.get("status") != "ok" or "stage_times" in r:
                continue
            timed = self.pool.run(Task(t.engine, t.scene, t.dt, {**t.settings, "stage_timing": True}, t.sample_dt,
                                       t.budget, t.label, t.key))
            st = timed.get("stages") or {}
            steps = max(int(st.get("steps", 0)), 1)
            if timed.get("status") == "ok" and st.get("time_step"):
                r["stage_times"] = {k: st[k] / steps for k in st if k.startswith("time_")}

    # ---- seed scene: work-precision ------------------------------------------------------------
    def wp(self) -> None:
        seeds = (1,) if self.quick else (1, 2, 3)
        gs = (0.0, 9.8)
        out: dict[str, Any] = {}
        for g in gs:
            tasks = []
            for sd in seeds:
                sc = scenes.seed(20, g, sd)
                # interleave engines: case by case, every engine's variant in turn
                for dt in DTS[:2] if self.quick else DTS:
                    for eng in ALL:
                        for label, settings, dts in WP_VARIANTS[eng]:
                            if dt in dts and (not self.quick or label == eng):
                                tasks.append(Task(eng, sc, dt, settings, None, self.budget, label))
            log(f"seed scene g={g}: {len(tasks)} runs x {self.repeats}")
            res = self.run(tasks)
            pts: dict[str, list[dict[str, Any]]] = {}
            for r in res.values():
                sc = scenes.seed(20, g, int(r["scene"].rsplit("_s", 1)[1]))
                m = metrics.seed_metrics(sc, r) if r.get("status") == "ok" and metrics.finite(r) else {}
                pts.setdefault(f"{r['label']}|{r['dt']!r}", []).append({**strip(r), **m})
            rows = []
            for key, runs in pts.items():
                label, dt = key.split("|")
                ok = [x for x in runs if "drift" in x]
                rows.append({"label": label, "engine": runs[0]["engine"], "dt": float(dt), "runs": len(runs),
                             "failed": [x["status"] for x in runs if "drift" not in x],
                             "drift": float(np.median([x["drift"] for x in ok])) if ok else math.nan,
                             "drifts": [x["drift"] for x in ok],
                             "abs_drift": float(np.median([abs(x["drift"]) for x in ok])) if ok else math.nan,
                             "max_abs_drift": float(np.median([x["max_abs_drift"] for x in ok])) if ok else math.nan,
                             "escaped": int(sum(x["escaped"] for x in ok)),
                             "cost": float(np.median([x["cpu_per_sim_s"] for x in runs if "cpu_per_sim_s" in x])),
                             "us_per_step": float(np.median([x["us_per_step"] for x in runs if "us_per_step" in x])),
                             "stages": runs[0].get("stages", {}),
                             "stage_times": runs[0].get("stage_times", {})})
            out[f"g{g:g}"] = rows
        # N = 6 at dt 1/60, g = 0 and 9.8 (the seed page's block count)
        tasks = [Task(eng, scenes.seed(6, g, sd), 1 / 60, {}, None, self.budget) for g in gs for sd in seeds
                 for eng in ALL]
        res = self.run(tasks)
        six = []
        for r in res.values():
            g = float(r["scene"].split("_g")[1].split("_")[0])
            sc = scenes.seed(6, g, int(r["scene"].rsplit("_s", 1)[1]))
            m = metrics.seed_metrics(sc, r) if r.get("status") == "ok" and metrics.finite(r) else {}
            six.append({**strip(r), **m, "g": g})
        out["n6"] = six
        self.out["wp"] = out

    # ---- seed scene: trajectory error against a converged reference ----------------------------
    def ref(self) -> None:
        """Each engine's trajectory against libcollide at its tightest TOI tolerances, over REF_T s of
        the seed scene. The scene is chaotic (every block-block impact amplifies a difference), so
        the horizon is short, and the reference is checked by computing it a second way (dt 1/960:
        other step boundaries, so other round-off and other TOI brackets) over REF_CHECK_T s."""
        seeds = (1,) if self.quick else (1, 2, 3)
        out: dict[str, Any] = {"horizon": REF_T, "check_horizon": REF_CHECK_T, "settings": REF_SETTINGS}
        for g in (0.0, 9.8):
            tasks = []
            for sd in seeds:
                sc = scenes.seed(20, g, sd, duration=REF_T)
                long = scenes.seed(20, g, sd, duration=REF_CHECK_T)
                tasks += [Task("libcollide", long, 1 / 60, REF_SETTINGS, 1 / 60, self.budget, "reference"),
                          Task("libcollide", long, 1 / 960, REF_SETTINGS, 1 / 60, self.budget, "reference check")]
                for dt in DTS[:2] if self.quick else DTS:
                    for eng in ALL:
                        for label, settings, dts in WP_VARIANTS[eng]:
                            if dt in dts and (not self.quick or label == eng):
                                tasks.append(Task(eng, sc, dt, settings, 1 / 60, self.budget, label))
            log(f"trajectory reference g={g}: {len(tasks)} runs")
            res = harness.run_interleaved(self.pool, tasks, 1, log)
            refs = {r["scene"]: r for r in res.values() if r["label"] == "reference" and r.get("status") == "ok"}
            checks = {r["scene"]: r for r in res.values() if r["label"] == "reference check"
                      and r.get("status") == "ok"}
            # 10 s costs of the same settings from the work-precision section, where it ran (its repeats
            # are the timed ones)
            wp_cost = {(r["label"], r["dt"]): r["cost"] for r in self.out.get("wp", {}).get(f"g{g:g}", [])}
            check = []
            for name, r in refs.items():
                c = checks.get(name)
                if c is not None and metrics.finite(c) and metrics.finite(r):
                    t = r["times"]
                    check.append({"scene": name, "err": {f"{h:g}": metrics.trajectory_error(
                        c["states"][t <= h + 1e-9], r["states"][t <= h + 1e-9], HALF_DIAGONAL)
                        for h in REF_CHECK_AT}})
            pts: dict[tuple[str, float], list[dict[str, Any]]] = {}
            for r in res.values():
                if r["label"].startswith("reference"):
                    continue
                ref_run = refs.get(r["scene"])
                e, why = math.nan, r.get("status", "?")
                if ref_run is None:
                    why = "no reference: it did not finish"
                elif r.get("status") == "ok" and metrics.finite(r):
                    e = metrics.trajectory_error(r["states"], ref_run["states"], HALF_DIAGONAL)
                pts.setdefault((r["label"], r["dt"]), []).append({**strip(r), "traj_err": e, "why": why})
            rows = []
            for (label, dt), runs in pts.items():
                ok = [x["traj_err"] for x in runs if not math.isnan(x["traj_err"])]
                own = float(np.median([x["cpu_per_sim_s"] for x in runs if "cpu_per_sim_s" in x]))
                rows.append({"label": label, "engine": runs[0]["engine"], "dt": dt, "runs": len(runs),
                             "failed": [x["why"] for x in runs if math.isnan(x["traj_err"])],
                             "traj_err": float(np.median(ok)) if ok else math.nan, "traj_errs": ok,
                             "cost": wp_cost.get((label, dt), own),
                             "cost_from": "wp" if (label, dt) in wp_cost else "own"})
            out[f"g{g:g}"] = {"rows": rows, "check": check}
        self.out["ref"] = out

    # ---- single impacts and the flat drop ------------------------------------------------------
    def impacts(self) -> None:
        cases = [(scenes.wall_hit(3.0, 0.0), (1 / 60, 1 / 240)), (scenes.wall_hit(3.0, math.radians(30)), (1 / 60,)),
                 (scenes.flat_drop(), (1 / 60, 1 / 240))]
        fly = scenes.free_flight()
        tasks = [Task(eng, sc, dt, {}, None, self.budget) for sc, dts in cases for dt in dts for eng in ALL]
        tasks += [Task(eng, fly, dt, {}, 1 / 60, self.budget) for dt in (1 / 60, 1 / 240) for eng in ALL]
        log(f"impacts: {len(tasks)} runs")
        res = self.run(tasks)
        rows = []
        for r in res.values():
            ok = r.get("status") == "ok" and metrics.finite(r)
            if r["scene"] == fly.name:
                rows.append({**strip(r), **(metrics.free_flight_metrics(fly, r) if ok else {})})
                continue
            sc = next(sc for sc, _ in cases if sc.name == r["scene"])
            m = metrics.impact_metrics(sc, r) if ok else {}
            rows.append({**strip(r), **m})
        self.out["impacts"] = rows

    # ---- Newton's cradle -----------------------------------------------------------------------
    def cradle(self) -> None:
        cases = [scenes.cradle(0.0), scenes.cradle(0.05)]
        tasks = [Task(eng, sc, 1 / 60, {}, None, self.budget) for sc in cases for eng in ALL]
        tasks += [Task("pymunk", sc, 1 / 60, {"iterations": 30}, None, self.budget, "pymunk 30 it") for sc in cases]
        log(f"cradle: {len(tasks)} runs")
        res = self.run(tasks)
        rows = []
        for r in res.values():
            sc = next(sc for sc in cases if sc.name == r["scene"])
            m = metrics.cradle_metrics(sc, r) if r.get("status") == "ok" and metrics.finite(r) else {}
            rows.append({**strip(r), **m})
        self.out["cradle"] = rows

    # ---- stacks --------------------------------------------------------------------------------
    def stacks(self) -> None:
        cases = [(scenes.stack(10), (1 / 60, 1 / 240)), (scenes.stack(10, e=1.0), (1 / 60,)),
                 (scenes.stack(20), (1 / 60, 1 / 240))]
        if self.quick:
            cases = [(scenes.stack(10), (1 / 60,)), (scenes.stack(10, e=1.0), (1 / 60,))]
        tasks = []
        for sc, dts in cases:
            for dt in dts:
                for eng in ALL:
                    if eng == "libcollide" and dt != 1 / 60:
                        continue   # event-driven: dt is only the output interval
                    tasks.append(Task(eng, sc, dt, {}, 1 / 60, self.budget))
                if sc.e == 1.0:
                    tasks.append(Task("box2d3", sc, dt, {"restitution_threshold": 1.0}, 1 / 60, self.budget,
                                      "box2d3 thr 1 m/s"))
        log(f"stacks: {len(tasks)} runs")
        res = self.run(tasks, repeats=1 if not self.full else 3)
        rows = []
        for r in res.values():
            sc = next(sc for sc, _ in cases if sc.name == r["scene"])
            ok = r.get("status") in ("ok", "over_budget") and metrics.finite(r) and r.get("sim_time", 0) > 0
            m = metrics.stack_metrics(sc, r) if ok else {}
            rows.append({**strip(r), **m})
        self.out["stacks"] = rows

    # ---- pyramid --------------------------------------------------------------------------------
    def pyramid(self) -> None:
        bases = (5, 20) if self.quick else ((5, 20, 50, 100) if self.full else (5, 20, 50))
        rows = []
        failed: set[str] = set()
        for base in bases:
            sc = scenes.pyramid(base, duration=(100 if self.quick else 500) / 60)
            tasks = [Task(eng, sc, 1 / 60, {}, None, self.budget * (2 if base > 20 else 1)) for eng in ALL
                     if eng not in failed]
            for eng in failed:
                rows.append({"engine": eng, "label": eng, "scene": sc.name, "dt": 1 / 60, "base": base,
                             "bodies": len(sc.dynamic), "status": "not run: a smaller base did not finish"})
            log(f"pyramid base {base}: {len(tasks)} runs")
            res = self.run(tasks)
            for r in res.values():
                ok = r.get("status") in ("ok", "over_budget") and metrics.finite(r) and r.get("sim_time", 0) > 0
                m = metrics.pyramid_metrics(sc, r) if ok else {}
                rows.append({**strip(r), **m, "base": base, "bodies": len(sc.dynamic)})
                if r.get("status") != "ok":
                    failed.add(r["engine"])
        self.out["pyramid"] = rows

    # ---- tunnelling ---------------------------------------------------------------------------
    def tunnel(self) -> None:
        cases = [scenes.tunnel(v) for v in (10.0, 50.0, 200.0)]
        tasks = [Task(eng, sc, 1 / 60, {}, 1 / 60, self.budget) for sc in cases for eng in ALL]
        log(f"tunnel: {len(tasks)} runs")
        res = self.run(tasks, repeats=1)
        rows = []
        for r in res.values():
            sc = next(sc for sc in cases if sc.name == r["scene"])
            m = metrics.tunnel_metrics(sc, r) if r.get("status") == "ok" and metrics.finite(r) else {}
            rows.append({**strip(r), **m})
        self.out["tunnel"] = rows

    # ---- hard cases: settling, mass ratio, wedged block, smash ----------------------------------
    def hard(self) -> None:
        cases = [scenes.settling(), scenes.mass_ratio_stack(), scenes.wedged(), scenes.smash()]
        if self.quick:
            cases = [scenes.settling(duration=3.0), scenes.mass_ratio_stack(duration=3.0), scenes.wedged(duration=3.0),
                     scenes.smash(duration=1.0)]
        tasks = [Task(eng, sc, 1 / 60, {}, 1 / 60, self.budget) for sc in cases for eng in ALL]
        log(f"hard cases: {len(tasks)} runs")
        res = self.run(tasks, repeats=1 if not self.full else 3)
        rows = []
        for r in res.values():
            sc = next(sc for sc in cases if sc.name == r["scene"])
            ok = r.get("status") in ("ok", "over_budget") and metrics.finite(r) and r.get("sim_time", 0) > 0
            m = metrics.hard_metrics(sc, r) if ok else {}
            rows.append({**strip(r), **m})
        self.out["hard"] = rows

    # ---- scaling ---------------------------------------------------------------------------------
    def scaling(self) -> None:
        ns = [6, 20, 50, 100, 200, 500, 1000]
        if self.quick:
            ns = [6, 20, 100, 300]
        else:
            ns += [2000]
        if self.full:
            ns += [5000]
        if self.args.scaling_n:
            ns = [int(x) for x in self.args.scaling_n.split(",")]
        self.out["scaling"] = self.scaling_rows(ns, self.scaling_engines())

    def scaling_engines(self) -> tuple[str, ...]:
        return ALL if not self.args.engines else \
            ("libcollide",) + tuple(e for e in PEERS if e in self.args.engines.split(","))

    def scaling_rows(self, ns: list[int], engs: tuple[str, ...],
                     laps_for: Callable[[int], int] | None = None) -> list[dict[str, Any]]:
        """One run of the scaling section: a row per engine and body count (n = 0 included); laps_for(n),
        when given, is how many times a timed repeat runs the n-body scene (Task.laps, the same for
        every engine)."""
        # n = 0: one static box only, i.e. the per-step floor of each engine and its Python binding
        empty = scenes.Scene("many0", (scenes.Box(1.0, 1.0, 0.0, 0.0, static=True),), duration=10.0)
        tasks = [Task(eng, empty, 1 / 60, {}, None, self.budget) for eng in engs]
        tasks += [Task(eng, scenes.many(n), 1 / 60, {}, None, self.budget, laps=laps_for(n) if laps_for else 1)
                  for n in ns for eng in engs]
        log(f"scaling: {len(tasks)} runs")
        res = self.run(tasks)
        rows = []
        for r in res.values():
            n = int(r["scene"][4:])
            m = {}
            if n and r.get("status") == "ok" and metrics.finite(r):
                m = metrics.seed_metrics(scenes.many(n), r)
            rows.append({**strip(r), **m, "n": n})
        return rows

    def scaling_runs(self, k: int, command: str) -> None:
        """The scaling section k times, libcollide against the one peer of --engines, each run with
        fresh workers; its own results (out["scaling_runs"]), not the page's scaling section."""
        engs = self.scaling_engines()
        if len(engs) != 2:
            raise SystemExit("bench/main.py: --scaling-runs compares libcollide with one peer: "
                             "give it --engines with one of " + ",".join(PEERS))
        ns = [int(x) for x in (self.args.scaling_n or "100,1000,2000,5000,20000").split(",")]
        runs = []
        for i in range(k):
            if i:
                self.pool.close()
                self.pool = harness.Pool()
            run: dict[str, Any] = {"start": _utc(), "load_before": os.getloadavg()}
            log(f"scaling run {i + 1}/{k}")
            run["rows"] = self.scaling_rows(ns, engs, scaling_runs.laps_for)
            run.update(end=_utc(), load_after=os.getloadavg())
            runs.append(run)
        self.out["scaling_runs"] = {"peer": engs[1], "n": ns, "command": command, "runs": runs,
                                    "body_steps": scaling_runs.BODY_STEPS}

    # ---- contact: piles, pushing, friction (bench/contact.py) ----------------------------------
    def contact(self) -> None:
        """Every contact scene for libcollide, Box2D v3 and Chipmunk, sampled every step. Its own
        CPU budget per libcollide run (--budget, else 20 s quick / 60 s), so that the section ends in
        minutes even when libcollide is over budget on every scene; the peers always finish. The
        random piles run on --seeds (default 1,2,3; --quick: mixed1000 on the first only) and report
        medians over the seeds (bench/contact.py)."""
        budget = self.args.budget or (contact.BUDGET_QUICK if self.quick else contact.BUDGET_DEFAULT)
        seeds = self.args.seeds or contact.SEEDS
        self.out["contact"] = contact.run_section(self.pool, list(contact.SCENE_KEYS), contact.ENGINES,
                                                  self.repeats, budget, log, seeds, self.quick)

    def contact_wp(self) -> None:
        """Work-precision of the contact scenes: the peers' substeps, iterations, slop and dt turned up,
        libcollide at its defaults (bench/contact_wp.py). --quick: 1 repeat, each random pile's first seed."""
        given = self.args.seeds or contact_wp.SEEDS["mixed30"]   # mixed100 (one seed by default) takes the first
        seeds = {k: given[:1] if self.quick or len(v) == 1 else given for k, v in contact_wp.SEEDS.items()}
        self.out["contact_wp"] = contact_wp.run_section(self.pool, list(contact_wp.SCENES), self.repeats, log, seeds)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="smoke run of a few seconds (1 seed, 1 repeat, short scenes)")
    g.add_argument("--full", action="store_true", help="more repeats, larger scenes, longer budgets")
    ap.add_argument("--sections", default="wp,ref,impacts,cradle,tunnel,stacks,hard,pyramid,scaling",
                    help="comma list; also 'contact' and 'contact_wp' (not run by default: docs/bench_contact.md)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "benchmarks.md"),
                    help="markdown file to write; the plots go to img/ next to it")
    ap.add_argument("--budget", type=float, help="CPU seconds per run before it is stopped (default 15, quick 4, "
                    "full 60; contact: libcollide runs only, default 60, quick 20)")
    ap.add_argument("--seeds", help="comma list of seeds for the contact section's random piles (mixed30, "
                    "mixed100, mixed1000; default 1,2,3; with --quick mixed1000 runs the first only)")
    ap.add_argument("--no-report", action="store_true", help="only write bench/results/latest.json")
    ap.add_argument("--scaling-n", help="comma list of body counts for the scaling section (e.g. 100,500,2000,5000,20000) "
                    "instead of its default list")
    ap.add_argument("--engines", help="comma list of engines for the scaling section (default: all; libcollide always)")
    ap.add_argument("--scaling-runs", type=int, metavar="K", help="only the scaling section, K times, libcollide "
                    "against the one peer of --engines (default counts 100,1000,2000,5000,20000): medians over "
                    "the runs in its own block of the page (bench/scaling_runs.py); the rest of the page stays")
    args = ap.parse_args()
    if args.scaling_runs is not None:
        if args.scaling_runs < 1:
            ap.error("--scaling-runs needs K >= 1")
        if args.sections != ap.get_default("sections"):
            ap.error("--scaling-runs runs the scaling section only: drop --sections")
    if args.seeds:
        args.seeds = contact.parse_seeds(args.seeds)   # a bad list stops here, not after the sections before contact
    t0 = time.time()
    b = Bench(args)
    import importlib.metadata as md
    b.out["meta"] = {"date": _utc(), "mode":
                     "quick" if args.quick else ("full" if args.full else "default"),
                     "repeats": b.repeats, "budget_cpu_s": b.budget, "machine": platform.machine(),
                     "cpus": os.cpu_count(), "python": platform.python_version(),
                     "cpu_model": _cpu_model(), "load_before": os.getloadavg(), "libcollide": _lc_build(),
                     "versions": {p: _ver(md, p) for p in ("pymunk", "pyb2d3", "Box2D", "numpy", "matplotlib")}}
    try:
        if args.scaling_runs is not None:
            b.scaling_runs(args.scaling_runs, " ".join(["bench/run"] + sys.argv[1:]))
        else:
            for sec in args.sections.split(","):
                getattr(b, sec.strip())()
    finally:
        b.pool.close()
    b.out["meta"]["wall_s"] = time.time() - t0
    b.out["meta"]["load_after"] = os.getloadavg()
    save_results(b.out, "latest.json")
    if "scaling_runs" in b.out:
        b.out["scaling_runs"]["meta"] = b.out["meta"]
        if not args.no_report:
            docs = os.path.dirname(os.path.abspath(args.out))
            scaling_runs.write_block(b.out["scaling_runs"], args.out, os.path.join(docs, "img"), report.NAMES,
                                     report.COLORS)
            log(f"wrote the scaling-runs block of {args.out} and img/{scaling_runs.PLOT}")
            save_results(b.out, scaling_runs.results_name(args.out))
    elif not args.no_report:
        docs = os.path.dirname(os.path.abspath(args.out))
        if any(sec.strip() not in ("contact", "contact_wp") for sec in args.sections.split(",")):
            # the page keeps the block of the last --scaling-runs run (its own date, commit and load)
            stored = stored_scaling_runs(args.out)
            if stored:
                b.out["scaling_runs"] = stored
            report.write(b.out, args.out, os.path.join(docs, "img"))
            log(f"wrote {args.out}")
            # the data behind this page's figures, kept until the page is written again
            # (python bench/report.py --replot redraws them from it)
            save_results(b.out, os.path.splitext(os.path.basename(args.out))[0] + ".json")
        if "contact_wp" in b.out:   # its section of docs/bench_contact.md, kept when the contact section rewrites the page
            wp = {"meta": b.out["meta"], "contact_wp": b.out["contact_wp"]}
            save_results(wp, "bench_contact_wp.json")
            report_contact_wp.plot(b.out["contact_wp"], os.path.join(docs, "img", report_contact_wp.FIGURE))
            if "contact" not in b.out:
                report_contact_wp.update_page(wp, os.path.join(docs, "bench_contact.md"))
                log(f"wrote its section of {os.path.join(docs, 'bench_contact.md')}")
        if "contact" in b.out:   # a page of its own: report.write rewrites the whole of args.out
            report_contact.write_contact(b.out, os.path.join(docs, "bench_contact.md"))
            log(f"wrote {os.path.join(docs, 'bench_contact.md')}")
            save_results(b.out, "bench_contact.json")
    log(f"done in {time.time() - t0:.0f} s")
    return 0


def save_results(out: dict[str, Any], name: str) -> None:
    """bench/results/<name>: the results dict of this run as JSON."""
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    path = os.path.join(HERE, "results", name)
    with open(path, "w") as f:
        json.dump(out, f, indent=1, default=_json)
    log(f"wrote {path}")


def stored_scaling_runs(page: str) -> dict[str, Any] | None:
    """The comparison of the last bench/run --scaling-runs that wrote the page, if it is stored."""
    path = os.path.join(HERE, "results", scaling_runs.results_name(page))
    if not os.path.exists(path):
        return None
    with open(path) as fh:
        return json.load(fh).get("scaling_runs")


def _utc() -> str:
    return time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())


def _lc_build() -> str:
    """Which libcollide was measured: git HEAD, whether libcollide/ has uncommitted edits, .so time."""
    import subprocess
    def git(*a: str) -> str:
        try:
            return subprocess.run(["git", "-C", ROOT, *a], capture_output=True, text=True, timeout=20).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return "?"
    other = os.environ.get("LIBCOLLIDE_BENCH_LIB")
    if other:   # bench/run --lib DIR
        so = os.path.join(other, "libcollide.so")
        src = "?"
        cache = os.path.join(other, "CMakeCache.txt")
        if os.path.exists(cache):   # the build's source tree; a COMMIT file there names an exported commit
            for line in open(cache):
                if line.startswith("CMAKE_HOME_DIRECTORY:"):
                    src = line.split("=", 1)[1].strip()
            commit = os.path.join(src, "COMMIT")
            if os.path.exists(commit):
                src += f" = commit {open(commit).read().strip()}"
            elif src == ROOT:
                src += f" (commit {git('rev-parse', '--short', 'HEAD')}, working tree)"
        when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(so)))
        return f"{so}, sources {src}, built {when}"
    head = git("rev-parse", "--short", "HEAD")
    dirty = " + uncommitted edits in libcollide/" if git("status", "--porcelain", "--", "libcollide") else ""
    so = os.path.join(os.environ.get("LIBCOLLIDE_BUILD_DIR", os.path.join(ROOT, "build")), "libcollide.so")
    when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(os.path.getmtime(so))) if os.path.exists(so) else "?"
    return f"commit {head}{dirty}, library built {when}"


def _ver(md: Any, p: str) -> str:
    try:
        return md.version(p)
    except md.PackageNotFoundError:
        return "missing"


def _cpu_model() -> str:
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def _json(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.bool_):
        return bool(o)
    return str(o)


if __name__ == "__main__":
    sys.exit(main())
