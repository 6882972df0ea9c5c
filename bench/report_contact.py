"""docs/bench_contact.md from the contact section (bench/contact.py) of a bench/main.py results dict:
the scene table with each engine's cost and quality, its legend, the random piles' figures per seed and
libcollide's counters."""
from __future__ import annotations

import math
import os
import sys
from typing import Any

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from report import f, load_average_text, pct  # noqa: E402

CONTACT_NAMES = {"libcollide": "libcollide", "box2d3": "Box2D v3", "pymunk": "Chipmunk"}
# libcollide counters shown per step under the contact table (all of them stay in the JSON)
CONTACT_COUNTERS = ("collisions", "toi_searches", "force_evaluations", "contact_solves", "contact_solve_iterations",
                    "serial_iterations", "inelastic_fallbacks", "resting_contacts")


def md_table(head: list[str], rows: list[list[str]]) -> list[str]:
    """A markdown table with its columns padded to equal width (readable as plain text too)."""
    width = [max(len(c) for c in col) for col in zip(head, *rows)]
    def line(cells: list[str]) -> str:
        return "| " + " | ".join(c.ljust(w) for c, w in zip(cells, width)) + " |"
    return [line(head), "|" + "|".join("-" * (w + 2) for w in width) + "|"] + [line(r) for r in rows]


def _seed_of(r: dict[str, Any], field: str) -> str:
    """', seed N': the seed a row of several seeds took a figure from (r[field]); '' otherwise."""
    return f", seed {r[field]}" if len(r.get("seeds", [])) > 1 and field in r else ""


def _speed_cell(r: dict[str, Any] | None) -> str:
    """µs per step (median over repeats; over seeds for a random pile), and how far the run got when
    it (its worst seed) did not finish."""
    if r is None:
        return "—"
    us = f(r.get("us_per_step"), ".4g")
    if r["kind"] == "ok":
        return us
    seed = _seed_of(r, "status_seed")
    if r["kind"] == "over budget":
        killed = f", killed inside step {r['steps'] + 1}" if r.get("killed_in_step") else ""
        return f"{us} (over budget: {r['steps']}/{r['total_steps']} steps{killed}{seed})"
    return f"{us} (failed at step {r['steps']}{seed}: {r['status']})"


def _ratio_cell(lc: dict[str, Any] | None, peer: str) -> str:
    x = (lc or {}).get(f"ratio_{peer}")
    return "—" if x is None or math.isnan(x) else f"{x:.3g}×"


def _overlap_cell(r: dict[str, Any] | None) -> str:
    if r is None or "max_overlap" not in r:
        return "—"
    d = r["max_overlap"] * 1e3
    return "0" if d == 0 else f"{d:.3g} (s{r['overlap_sample']}{_seed_of(r, 'max_overlap_seed')})"


def _escaped_cell(r: dict[str, Any] | None) -> str:
    if r is None or "escaped" not in r:
        return "—"
    return f"{r['escaped']} (s{r['escape_sample']}{_seed_of(r, 'escaped_seed')})" if r["escaped"] else "0"


def _gain_cell(r: dict[str, Any] | None) -> str:
    if r is None or "max_step_gain" not in r or math.isnan(r["max_step_gain"]):
        return "—"
    return f"{r['max_step_gain']:+.2g} (s{r['gain_step']}{_seed_of(r, 'max_step_gain_seed')})"


def _sink_cell(r: dict[str, Any] | None) -> str:
    if r is None or "sink_end" not in r:
        return "—"
    return f"{r['sink_end'] * 1e3:.3g} / {r['sink_max'] * 1e3:.3g} / {r['creep'] * 1e3:.3g}"


def _motion_cell(r: dict[str, Any] | None) -> str:
    if r is None or "end_motion_median" not in r:
        return "—"
    seed = _seed_of(r, "end_motion_median_seed")
    return (f"{r['end_motion_median'] * 1e3:.2g} / {r['end_motion_max'] * 1e3:.2g} / "
            f"{r['end_speed_max']:.2g}{' (' + seed[2:] + ')' if seed else ''}")


def _scene_cell(key: str, s: dict[str, Any]) -> str:
    seeds = s.get("seeds")
    which = f"; seed{'s' if len(seeds) > 1 else ''} {','.join(map(str, seeds))}" if seeds else ""
    return f"{key} ({s['bodies']}, {s['steps']}{which})"


def contact_table(sec: dict[str, Any]) -> list[str]:
    """One row per scene: each engine's µs per step (with its status), libcollide's ratio to each
    peer, then per engine the quality columns (sink/creep only when a scene of the table has them).
    A random pile's row is bench/contact.py's aggregate over its seeds (listed in the scene cell)."""
    engines = sec["engines"]
    rows = sec["rows"]
    peers = [p for p in ("box2d3", "pymunk") if p in engines and "libcollide" in engines]
    sinks = any(s["at_rest"] for s in sec["scenes"].values())
    head = ["scene (bodies, steps)"] + [f"{CONTACT_NAMES[e]} µs/step" for e in engines]
    head += [f"libcollide / {CONTACT_NAMES[p]}" for p in peers]
    for e in engines:
        n = CONTACT_NAMES[e]
        head += [f"{n}: max overlap mm (step)", f"{n}: escaped", f"{n}: worst step ΔE/E (step)",
                 f"{n}: last 1 s median / max motion mm, end speed m/s"]
        head += [f"{n}: sink end / max, creep mm"] if sinks else []
    body = []
    for key, s in sec["scenes"].items():
        by_eng = {e: next((r for r in rows if r["key"] == key and r["engine"] == e), None) for e in engines}
        cells = [_scene_cell(key, s)] + [_speed_cell(by_eng[e]) for e in engines]
        cells += [_ratio_cell(by_eng.get("libcollide"), p) for p in peers]
        for e in engines:
            r = by_eng[e]
            cells += [_overlap_cell(r), _escaped_cell(r), _gain_cell(r), _motion_cell(r)]
            cells += [_sink_cell(r) if s["at_rest"] else ""] if sinks else []
        body.append(cells)
    return md_table(head, body)


def _per_seed_value(r: dict[str, Any], text: str) -> str:
    """A seed's figure, marked when that seed's run did not finish."""
    return text if r["kind"] == "ok" else f"{text} ({r['kind']})"


def per_seed_lines(sec: dict[str, Any]) -> list[str]:
    """For each random pile run on several seeds: every engine's µs per step and libcollide's ratio
    to each peer, seed by seed (the figures the table's medians are taken of)."""
    engines = sec["engines"]
    peers = [p for p in ("box2d3", "pymunk") if p in engines and "libcollide" in engines]
    L = []
    for key, s in sec["scenes"].items():
        if len(s.get("seeds", [])) < 2:
            continue
        by_eng = {r["engine"]: r for r in sec["rows"] if r["key"] == key and r.get("per_seed")}
        parts = [f"{CONTACT_NAMES[e]} " + " / ".join(_per_seed_value(x, f(x.get("us_per_step"), ".4g"))
                                                     for x in by_eng[e]["per_seed"]) for e in engines if e in by_eng]
        lc = by_eng.get("libcollide")
        parts += [f"libcollide / {CONTACT_NAMES[p]} " + " / ".join(_ratio_cell(x, p) for x in lc["per_seed"])
                  for p in peers if lc is not None]
        L.append(f"- {key}, seeds {' / '.join(map(str, s['seeds']))}: " + "; ".join(parts))
    return L


def contact_notes(sec: dict[str, Any]) -> list[str]:
    """Legend, settings, the random piles' figures per seed, each run's total energy change,
    libcollide's counters per step."""
    seeded = [k for k, s in sec["scenes"].items() if s.get("seeds")]
    seeds_text = ""
    if seeded:
        seeds_text = (f"Random piles ({', '.join(seeded)}; seeds in the scene cell): each engine runs every seed in "
                      "the same run, the engines interleaved within a seed; µs/step is the median over the seeds "
                      "of each seed's median, libcollide / peer the median of the seeds' own ratios (listed below: "
                      "each compares the engines on the same pile), not the quotient of the row's two medians, and "
                      "every quality column the worst seed's "
                      "(largest overlap, most escapes, largest gain; ', seed N' names it), a run that did not "
                      "finish the worst seed's status. ")
    L = ["Legend: µs/step = CPU time of the step loop per 1/60 s step, median over "
         f"{sec['repeats']} repeat(s) (a run that did not finish: its steps so far, run once). " + seeds_text +
         "(sN) = at step N (state after N steps; s0 = the initial state). max overlap = largest "
         "penetration depth between any two boxes (static ones included) at any step end, exact "
         "separating-axis depth. escaped = bodies whose centre left the walls' inner box (the ground's "
         "top for pyramids and the stack) at some step. worst step ΔE/E = largest (E[k+1] − E[k]) / |E[k]|, "
         "E = KE + m g y (no scene here is driven, so > 0 is energy made by the solver; float32 Box2D "
         "states round at ~1e-7). sink = y₀ − y of the top box at the end / its largest; creep = "
         "largest |x − x₀| of any box. last 1 s motion = each body's centre displacement over the run's last "
         "second, its median over the bodies / its largest, and the largest centre speed at the end: a pile "
         "at rest moves by round-off, one that creeps by its creep. The quality of a run that stopped early covers the steps it did. "
         "Reading the states after every step puts each step in its own timed call: about 1 µs of clock "
         "reading per step is in every engine's figure.", "",
         f"Settings: dt {sec['dt']:.6g} s; " + "; ".join(f"{CONTACT_NAMES[e]} {v or 'adapter defaults'}"
                                                          for e, v in sec["settings"].items())
         + f"; CPU budget per libcollide run {sec['budget_cpu_s']:g} s (peers {sec['peer_budget_cpu_s']:g} s).", ""]
    seed_lines = per_seed_lines(sec)
    if seed_lines:
        L += ["µs/step per seed (the table's medians are taken of these; every seed's figures are in the "
              "JSON under per_seed):"] + seed_lines + [""]
    rows = sec["rows"]
    L.append("Total energy change (E_end − E₀)/|E₀| per scene (random piles: median over the seeds): "
             + "; ".join(
        f"{key}: " + ", ".join(f"{CONTACT_NAMES[r['engine']]} {pct(r['e_change'])}" for r in rows
                               if r["key"] == key and "e_change" in r) for key in sec["scenes"]) + ".")
    lc = [r for r in rows if r["engine"] == "libcollide" and r.get("stages")]
    if lc:
        L += ["", "libcollide counters per step (world.counters(last=False) at the end of the first run; "
              "random piles: summed over the seeds' first runs):"]
        for r in lc:
            st = r["stages"]
            steps = max(int(st.get("steps", 0)), 1)
            L.append(f"- {r['key']}: " + ", ".join(f"{k} {st[k] / steps:.3g}" for k in CONTACT_COUNTERS
                                                   if st.get(k)) + f" ({steps} steps)")
    bad = [x for r in rows for x in r.get("per_seed", [r]) if x["kind"] == "failed"]
    if bad:
        L += [""] + [f"- {r['key']}{' seed ' + str(r['seed']) if 'seed' in r else ''} {CONTACT_NAMES[r['engine']]}: "
                     f"{r['status']}" for r in bad]
    return L


WP_RESULTS = os.path.join(HERE, "results", "bench_contact_wp.json")


def write_contact(out: dict[str, Any], path: str, wp_results: str = WP_RESULTS) -> None:
    """docs/bench_contact.md: the contact section of a bench/run run, on a page of its own so that a
    run of this section alone leaves docs/benchmarks.md as it is. The work-precision section
    (bench/contact_wp.py) is redrawn at the end from wp_results, the JSON of its last run, if there is one."""
    sec = out["contact"]
    meta = out.get("meta", {})
    L = ["# Benchmarks: contact scenes (piles, pushing, friction)", "",
         "Regenerate with `bench/run --sections contact` (`--quick`: 1 repeat, 20 s CPU budget per libcollide "
         "run, mixed1000 on its first seed only; default 3 repeats, 60 s; `--budget S` sets the budget, "
         "`--seeds 1,2,3` the random piles' seeds, default 1,2,3). It writes this page and "
         "`bench/results/latest.json`; `docs/benchmarks.md` is left as it is. For a quick look without "
         "touching docs/: `python bench/contact.py --scenes mixed30,push --engines libcollide,box2d3 "
         "--repeats 1 --budget 30` (inside `source scripts/env.sh`).", "",
         f"Run of {meta.get('date', '?')}, mode **{meta.get('mode', '?')}**, on {meta.get('cpus', '?')} × "
         f"{meta.get('cpu_model', '?')}; load average before/after {load_average_text(meta.get('load_before'))} / "
         f"{load_average_text(meta.get('load_after'))} (the VM is shared: compare ratios from the same run). libcollide: "
         f"{meta.get('libcollide', '?')}. Peers: " + ", ".join(f"{k} {v}" for k, v in meta.get("versions", {}).items())
         + ".", "",
         "Every engine runs the same neutral scene (`bench/scenes.py`) through its adapter "
         "(`bench/engines/`), sleep off in the peers (and in libcollide, whose default is off; it does not "
         "solve a still island, one that rested through its last step at the state it starts from, "
         "docs/contact_regime.md: no setting, no delay, the same states), the engines of a scene (of each "
         "seed of a random pile) interleaved round-robin; "
         "states are read after every step (outside the timed loop) and every quality figure is "
         "computed from them by `bench/metrics.py`, never taken from an engine.", "", "Scenes:", ""]
    L += [f"- **{key}** (" + ", ".join(f"`{n}`" for n in s.get("names", [s["name"]])) + f"): {s['what']}"
          for key, s in sec["scenes"].items()]
    L += [""] + contact_table(sec) + [""] + contact_notes(sec) + [""]
    if os.path.exists(wp_results):
        import json
        import report_contact_wp
        with open(wp_results) as fh:
            L += report_contact_wp.section(json.load(fh)) + [""]
    with open(path, "w") as fh:
        fh.write("\n".join(L))
