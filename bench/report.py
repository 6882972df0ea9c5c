"""docs/benchmarks.md and docs/img/bench_*.png from the results dict of bench/main.py (the contact
section's page, docs/bench_contact.md: report_contact.py).

    python bench/report.py --replot [bench/results/benchmarks.json]   # redraw the page's figures only
    python bench/report.py --replot bench/results/scaling_runs.json   # the plot of bench/run --scaling-runs
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
from typing import Any

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scaling_runs  # noqa: E402

COLORS = {"libcollide": "#d62728", "pymunk": "#1f77b4", "box2d3": "#2ca02c", "box2d2": "#9467bd"}
NAMES = {"libcollide": "libcollide", "pymunk": "Chipmunk (pymunk)", "box2d3": "Box2D v3 (pyb2d3)",
         "box2d2": "Box2D 2.3 (pybox2d)"}
ENGINES = ("libcollide", "pymunk", "box2d3", "box2d2")
FLOOR = 1e-16          # errors below double rounding are plotted at this floor
LEVELS = (1e-1, 1e-2, 1e-3, 1e-6, 1e-9)
STAGES = [("force_evaluations", "ODE integrator (force evaluations)"),
          ("analytic_advances", "closed-form free flight"),
          ("brute_force_steps", "broadphase: brute force"),
          ("sort_and_sweep_steps", "broadphase: sort-and-sweep"),
          ("grid_steps", "broadphase: grid"),
          ("toi_searches", "time-of-impact search"),
          ("impulse_solves", "impulse solve (eq. 11)"),
          ("serial_iterations", "serial impact passes"),
          ("inelastic_fallbacks", "inelastic fallback"),
          ("contact_solves", "resting-contact LCP")]
# libcollide's disjoint timed stages (lc_counters time_*), in the order of a pass
TIME_STAGES = [("time_detection", "detection"), ("time_integration", "integration"),
               ("time_toi_search", "time-of-impact search"), ("time_impulses", "impulses"),
               ("time_projection", "projection")]


def f(x: Any, fmt: str = ".3g") -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    return format(x, fmt)


def pct(x: Any) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "—"
    if abs(x) < 1e-6:
        return f"{x:.1e}"
    return f"{100 * x:+.3g} %"


def status_cell(r: dict[str, Any]) -> str:
    s = r.get("status", "?")
    if s == "ok":
        return ""
    if s == "over_budget":
        return f" (stopped at {r.get('sim_time', 0):.3g} s: CPU budget)"
    return f" (**{s}**)"


# ---- plots ------------------------------------------------------------------------------------
def _plt() -> Any:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_wp(rows: list[dict[str, Any]], title: str, path: str, key: str = "abs_drift",
            ylabel: str = "|relative energy drift| after 10 s (median of seeds)",
            target: tuple[float, str] | None = (1e-9, "target 1e-9")) -> None:
    """Error (rows[key]) against cost, one line per engine over dt, variants as triangles."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5.2), dpi=110)
    for eng in ENGINES:
        base = sorted([r for r in rows if r["label"] == eng and not math.isnan(r[key])],
                      key=lambda r: -r["dt"])
        if base:
            x = [r["cost"] * 1e3 for r in base]
            y = [max(r[key], FLOOR) for r in base]
            ax.plot(x, y, "-o", color=COLORS[eng], label=NAMES[eng] + " (dt 1/60 → 1/960)")
            for r, xi, yi in zip(base, x, y):
                ax.annotate(f"1/{round(1 / r['dt'])}", (xi, yi), fontsize=6, color=COLORS[eng],
                            textcoords="offset points", xytext=(3, 3))
        var = [r for r in rows if r["engine"] == eng and r["label"] != eng and not math.isnan(r[key])]
        for r in var:
            ax.plot(r["cost"] * 1e3, max(r[key], FLOOR), "^", color=COLORS[eng], mfc="none")
            ax.annotate(r["label"].replace(eng, "").strip() + f" 1/{round(1 / r['dt'])}",
                        (r["cost"] * 1e3, max(r[key], FLOOR)), fontsize=6, color=COLORS[eng],
                        textcoords="offset points", xytext=(3, -8))
    ax.set_xscale("log")
    ax.set_yscale("log")
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 3.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("CPU time per simulated second (ms), median of repeats")
    ax.set_ylabel(ylabel)
    if target is not None:
        ax.axhline(target[0], color="grey", lw=0.7, ls=":")
        ax.text(ax.get_xlim()[0], 1.3 * target[0], " " + target[1], fontsize=7, color="grey")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7, loc="center right")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def broadphase_used(stages: dict) -> str:
    """The broadphase that did most of a run's whole-world pair searches (its counters)."""
    counts = {"brute force": stages.get("brute_force_steps", 0), "sort-and-sweep": stages.get("sort_and_sweep_steps", 0),
              "grid": stages.get("grid_steps", 0)}
    return max(counts, key=lambda k: counts[k])


def plot_scaling(rows: list[dict[str, Any]], path: str) -> None:
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7.5, 5.2), dpi=110)
    for eng in ENGINES:
        rs = sorted([r for r in rows if r["engine"] == eng and r["n"] > 0
                     and not math.isnan(r.get("us_per_step", math.nan))], key=lambda r: r["n"])
        if not rs:
            continue
        ax.plot([r["n"] for r in rs], [r["us_per_step"] for r in rs], "-", color=COLORS[eng], label=NAMES[eng])
        if eng == "libcollide":
            for r in rs:
                bp = broadphase_used(r.get("stages", {}))
                ax.plot(r["n"], r["us_per_step"], {"grid": "D", "sort-and-sweep": "s"}.get(bp, "o"),
                        color=COLORS[eng], mfc=COLORS[eng] if bp == "brute force" else "white")
        else:
            ax.plot([r["n"] for r in rs], [r["us_per_step"] for r in rs], ".", color=COLORS[eng])
    ax.plot([], [], "o", color=COLORS["libcollide"], label="libcollide: brute-force broadphase")
    ax.plot([], [], "s", color=COLORS["libcollide"], mfc="white", label="libcollide: sort-and-sweep broadphase")
    ax.plot([], [], "D", color=COLORS["libcollide"], mfc="white", label="libcollide: grid broadphase")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("dynamic bodies (seed blocks, e = 1, g = 0, constant crowding)")
    ax.set_ylabel("CPU µs per 1/60 s step (median)")
    ax.set_title("Step cost against body count", fontsize=10)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


# ---- tables ------------------------------------------------------------------------------------
def dt_table(rows: list[dict[str, Any]], key: str, seeds_key: str, fmt: Any, head: str, name: str,
             unit: str = "") -> list[str]:
    """Work-precision table: a row per dt, per engine the median error rows[key] (with its range over
    the seeds, rows[seeds_key]) and the cost; the variants' settings in one line below."""
    dts = sorted({r["dt"] for r in rows if r["label"] in ENGINES}, reverse=True)
    out = ["| dt | " + " | ".join(f"{NAMES[e]}: {head} / ms per sim. s" for e in ENGINES) + " |",
           "|---|" + "---|" * len(ENGINES)]

    def cell(r: dict[str, Any]) -> str:
        seeds = r.get(seeds_key, [])
        rng = f" ({fmt(min(seeds))} … {fmt(max(seeds))})" if len(seeds) > 1 else ""
        return (f"{fmt(r[key]).lstrip('+')}{rng} / {f(r['cost'] * 1e3)}"
                + (f" ({', '.join(r['failed'])})" if r["failed"] else ""))
    for dt in dts:
        cells = [next((cell(r) for r in rows if r["label"] == e and r["dt"] == dt), "—") for e in ENGINES]
        out.append(f"| 1/{round(1 / dt)} | " + " | ".join(cells) + " |")
    var = [r for r in rows if r["label"] not in ENGINES]
    if var:
        out += ["", f"Variants (median {name} / cost): " + "; ".join(
            f"{r['label']} at 1/{round(1 / r['dt'])}: {fmt(r[key]).lstrip('+')}{unit} / {f(r['cost'] * 1e3)} ms"
            for r in var) + "."]
    return out


def wp_table(rows: list[dict[str, Any]]) -> list[str]:
    return dt_table(rows, "abs_drift", "drifts", pct, "abs drift (range over seeds)", "abs drift")


def traj_table(rows: list[dict[str, Any]]) -> list[str]:
    return dt_table(rows, "traj_err", "traj_errs", lambda x: f(x, ".2g"), "error (m, range over seeds)", "error",
                    " m")


def front(rows: list[dict[str, Any]], eng: str, level: float, key: str = "abs_drift") -> dict[str, Any] | None:
    ok = [r for r in rows if r["engine"] == eng and not math.isnan(r[key]) and r[key] <= level and not r["failed"]]
    return min(ok, key=lambda r: r["cost"]) if ok else None


def ratio_table(rows: list[dict[str, Any]], key: str = "abs_drift", levels: tuple[float, ...] = LEVELS,
                unit: str = "") -> list[str]:
    out = ["| error level | libcollide cheapest (ms / sim. s) | " + " | ".join(
        f"{NAMES[e]}: cheapest, ratio to libcollide" for e in ENGINES[1:]) + " |", "|---|---|" + "---|" * 3]
    for lv in levels:
        lc = front(rows, "libcollide", lv, key)
        cells = [f"{f(lc['cost'] * 1e3)} ({lc['label']}, 1/{round(1 / lc['dt'])})" if lc else "not reached"]
        for e in ENGINES[1:]:
            p = front(rows, e, lv, key)
            if p is None:
                cells.append("not reached")
            elif lc is None:
                cells.append(f"{f(p['cost'] * 1e3)} ms")
            else:
                cells.append(f"{f(p['cost'] * 1e3)} ms ({p['label']}, 1/{round(1 / p['dt'])}): "
                             f"**{p['cost'] / lc['cost']:.2g}x**")
        out.append(f"| ≤ {lv:g}{unit} | " + " | ".join(cells) + " |")
    return out


def by(rows: list[dict[str, Any]], scene: str, label: str, dt: float | None = None) -> dict[str, Any] | None:
    for r in rows:
        if r.get("scene") == scene and r.get("label") == label and (dt is None or abs(r["dt"] - dt) < 1e-12):
            return r
    return None


def stages_line(st: dict[str, Any]) -> str:
    if not st:
        return "—"
    steps = max(st.get("steps", 1), 1)
    ran = [f"{name} ({st[k] / steps:.3g}/step)" for k, name in STAGES if st.get(k, 0)]
    off = [name for k, name in STAGES if not st.get(k, 0)]
    return "ran: " + ", ".join(ran) + ("; skipped: " + ", ".join(off) if off else "")


# ---- document ----------------------------------------------------------------------------------
def write(out: dict[str, Any], path: str, img_dir: str) -> None:
    os.makedirs(img_dir, exist_ok=True)
    rel = os.path.relpath(img_dir, os.path.dirname(path))
    meta = out.get("meta", {})
    L: list[str] = []
    L += ["# Benchmarks: speed against error, beside Box2D and Chipmunk", "",
          "Regenerate everything on this page (tables, plots, `bench/results/latest.json`) with one command "
          "from the repository root:", "", "```bash",
          "bench/run            # default run, about 1 min on a 2-core VM (3 repeats)",
          "bench/run --quick    # smoke run of a few seconds (1 seed, 1 repeat, short scenes)",
          "bench/run --full     # about 5 min: 5 repeats, pyramid base 100, up to 5000 bodies, 60 s CPU budgets",
          "bench/run --sections wp,impacts   # only these (of wp,ref,impacts,cradle,tunnel,stacks,hard,pyramid,scaling);",
          "                                   # the page then holds only them: use --out /tmp/x.md to keep this one",
          "bench/run --sections contact       # piles, pushing, friction: bench_contact.md (this page is left as it is)",
          "bench/run --sections contact --seeds 1,2,3,4,5   # the random piles' seeds (default 1,2,3): medians over them",
          "bench/run --lib /path/to/build     # measure the libcollide.so of another build (first argument)",
          "bench/run --budget 60              # CPU seconds per run before it is stopped",
          "python bench/report.py --replot    # redraw this page's figures from bench/results/benchmarks.json, no new run",
          "bench/run --scaling-runs 5 --scaling-n 100,1000,2000,5000,20000 --engines box2d3",
          "                                   # libcollide against Box2D v3 over 5 runs: only its block of this page",
          "```", "",
          "`bench/run` installs the pinned peers of `bench/requirements.txt` into the project venv "
          "(`.venv`, made by `scripts/setup`) on first use, then runs `nice python bench/main.py`.", ""]
    L += ["## How it measures", "",
          f"- Run of {meta.get('date', '?')}, mode **{meta.get('mode', '?')}**, {meta.get('repeats', '?')} "
          f"repeat(s), on {meta.get('cpus', '?')} × {meta.get('cpu_model', '?')} (Python {meta.get('python', '?')}); "
          f"load average before/after {load_average_text(meta.get('load_before'))} / {load_average_text(meta.get('load_after'))} "
          f"(the VM is shared: **compare ratios from the same run, not absolute times**); "
          f"whole run {meta.get('wall_s', 0):.0f} s. libcollide: {meta.get('libcollide', '?')}. Peers: " + ", ".join(
              f"{k} {v}" for k, v in meta.get("versions", {}).items()) + ".",
          "- Every engine runs the same neutral scene description (`bench/scenes.py`: boxes in SI units, "
          "static boxes as walls) through one small adapter each (`bench/engines/`). All engines run in the "
          "same process tree, **interleaved round-robin** (one persistent worker per engine, one task at a "
          "time, the start of the round rotated each repeat); times are the **median of the repeats**.",
          "- Time = CPU time of the worker thread inside the step loop only (`time.thread_time`), per "
          "simulated second or per step; building the scene and reading states are not timed. Every engine "
          "is called once per step from Python (libcollide through cffi straight to `lc_world_step`).",
          "- Energy (KE + I ω²/2 + m g y, y = 0 at the floor), momentum and every error are computed by "
          "the harness (`bench/metrics.py`) from the states each engine returns, never taken from the "
          "engine. I = m (w² + h²)/12.",
          "- Sleep is disabled in every peer. Peers run at their defaults plus the fair settings of "
          "`../shared/notes/peer_bench.md`: Box2D v3 `restitution_threshold = 0` (variant `thr 1 m/s` "
          "keeps its default), 4 sub-steps, continuous on; Chipmunk `collision_slop = 0.005` m (its 0.1 "
          "assumes pixels), 10 iterations, per-shape e and μ set to √e, √μ because Chipmunk multiplies "
          "them; Box2D 2.3 8 velocity / 3 position iterations, its compiled-in 1 m/s restitution "
          "threshold. libcollide at its defaults (RK4, serial impacts, TOI tolerances 1e-10, damping 0).",
          "- Each run has a CPU budget (" + f"{meta.get('budget_cpu_s', '?')} s" + "); a run over budget "
          "stops early and reports its cost from the part it did. A run that makes no progress (workers "
          "report after every chunk of at most 0.25 s simulated) for 2 × budget + 10 s of wall time, or "
          "that crashes, is killed and reported as such with how far it got.",
          "- Precision: libcollide and Chipmunk float64, both Box2D wheels float32 (their 1e-7 rounding "
          "floor is far below the errors shown).", ""]

    summary: list[str] = []
    wp = out.get("wp")
    if wp:
        L += ["## Seed scene: energy drift against cost (work-precision)", "",
              "20 seed blocks (1 m × 0.5 m, 1 kg) at random cells of a 2 m grid in a walled 10 m box, random "
              "angle, v ∈ [-3, 3] m/s, ω ∈ [-2, 2] rad/s (seeds 1-3), e = 1, no friction, no damping, 10 s. "
              "drift = (E(10 s) − E₀)/E₀, median over seeds; cost = CPU ms per simulated second. Each engine "
              "at dt 1/60 … 1/960 plus its own accuracy knob (▲: iterations, sub-steps, libcollide's TOI "
              "tolerances: 'tol 1e-6' = toi_time_tolerance 1e-6 s and toi_distance_tolerance 1e-8 m; 'tol 1e-3' = "
              "1e-3 s and 1e-4 m with contact_gap 1 mm and contact_distance 1 cm). Errors below 1e-16 are "
              "plotted at 1e-16.", ""]
        for g in ("g0", "g9.8"):
            rows = wp.get(g)
            if not rows:
                continue
            gv = g[1:]
            fn = f"bench_wp_{g.replace('.', '_')}.png"
            plot_wp(rows, f"Seed scene, 20 blocks, e = 1, g = {gv} m/s², 10 s", os.path.join(img_dir, fn))
            L += [f"### g = {gv} m/s²", "", f"![work-precision g={gv}]({rel}/{fn})", ""]
            L += wp_table(rows) + [""]
            esc = [f"{r['label']} at 1/{round(1 / r['dt'])}: {r['escaped']}" for r in rows if r.get("escaped")]
            L += ["Bodies outside the box at the end (all seeds): " + ("; ".join(esc) if esc else "none, in every run")
                  + ".", ""]
            L += ["Speed ratio at each error level (cheapest setting of each engine whose drift is within the "
                  "level; ratio = peer cost / libcollide cost, > 1 means libcollide is faster):", ""]
            L += ratio_table(rows) + [""]
            lc = next((r for r in rows if r["label"] == "libcollide" and abs(r["dt"] - 1 / 60) < 1e-12), None)
            pm = next((r for r in rows if r["label"] == "pymunk" and abs(r["dt"] - 1 / 60) < 1e-12), None)
            if lc:
                ok_e = lc["abs_drift"] <= 1e-9 and not lc["failed"]
                ok_c = pm is not None and lc["cost"] <= pm["cost"]
                summary.append(f"| seed scene 20 blocks, g = {gv}: drift ≤ 1e-9 at a cost ≤ Chipmunk's at 1/60 | "
                               f"median abs drift {pct(lc['abs_drift'])}, {f(lc['us_per_step'])} µs/step vs Chipmunk "
                               f"{f(pm['us_per_step']) if pm else '—'} µs/step (ratio "
                               f"{(lc['cost'] / pm['cost']) if pm else math.nan:.2g}) | "
                               f"{'yes' if ok_e else 'NO'} / {'yes' if ok_c else 'NO'} |")
            stl = lc.get("stages") if lc else None
            if stl:
                L += [f"libcollide pipeline in this scene (seed 1, dt 1/60): {stages_line(stl)}.", ""]
        six = wp.get("n6")
        if six:
            L += ["### 6 blocks, dt 1/60", "", "| g | " + " | ".join(NAMES[e] for e in ENGINES) + " |",
                  "|---|" + "---|" * len(ENGINES)]
            for g in (0.0, 9.8):
                cells = []
                for e in ENGINES:
                    rs = [r for r in six if r["engine"] == e and r["g"] == g and "drift" in r]
                    cells.append(f"{pct(float(np.median([abs(r['drift']) for r in rs]))).lstrip('+')} / "
                                 f"{f(float(np.median([r['us_per_step'] for r in rs])))} µs/step" if rs else "—")
                L.append(f"| {g:g} | " + " | ".join(cells) + " |")
            L += ["", "(median abs drift over seeds / median µs per 1/60 s step)", ""]

    ref = out.get("ref")
    if ref:
        L += ["## Seed scene: trajectory error against a converged reference", "",
              "The same scenes (seeds as in the energy-drift section) for the first "
              f"{ref['horizon']:g} s, states sampled every 1/60 s, "
              "compared with a reference: libcollide at its tightest time-of-impact tolerances "
              f"(toi_time_tolerance {ref['settings']['toi_time_tolerance']:g} s, toi_distance_tolerance "
              f"{ref['settings']['toi_distance_tolerance']:g} m) at dt 1/60. error = the farthest any point of "
              "any block strays from the reference over the samples: max over samples and blocks of "
              "|Δcentre| + r |Δangle| (r = the block's half-diagonal, 0.559 m; a bound on every point's "
              "displacement), median over seeds. The scene is chaotic: each block-block impact amplifies a "
              "difference, so the horizon is short. The reference is checked by computing it a second way, "
              "at dt 1/960 (other step boundaries, so other round-off and other time-of-impact brackets); "
              "the check line gives how far the two computations are apart, which bounds what this table can "
              "resolve. Cost = the same setting's CPU ms per simulated second from the 10 s runs of the energy-drift "
              "section (from these short runs where it did not run).", ""]
        for g in ("g0", "g9.8"):
            sec_g = ref.get(g)
            if not sec_g:
                continue
            rows, check = sec_g["rows"], sec_g["check"]
            gv = g[1:]
            fn = f"bench_ref_{g.replace('.', '_')}.png"
            hz = f"{ref['horizon']:g}"
            floor = max((c["err"][hz] for c in check if hz in c["err"]), default=None)
            plot_wp(rows, f"Seed scene, 20 blocks, g = {gv} m/s²: error against the reference over "
                    f"{ref['horizon']:g} s", os.path.join(img_dir, fn), key="traj_err",
                    ylabel=f"farthest point displacement from the reference over {ref['horizon']:g} s (m)",
                    target=None if floor is None else (max(floor, FLOOR), f"reference computed twice: {floor:.1g} m apart"))
            L += [f"### g = {gv} m/s²", "", f"![trajectory error g={gv}]({rel}/{fn})", ""]
            L += traj_table(rows) + [""]
            if check:
                at = list(check[0]["err"].keys())
                L += ["Reference check (dt 1/960 against dt 1/60, largest over seeds): " + ", ".join(
                    f"{f(max(c['err'][h] for c in check), '.2g')} m by {h} s" for h in at) + ".", ""]
            else:
                L += ["Reference check: did not run to the end (see `bench/results/latest.json`).", ""]
            L += ["Speed ratio at each error level (cheapest setting whose error is within the level; ratio = "
                  "peer cost / libcollide cost, > 1 means libcollide is faster):", ""]
            L += ratio_table(rows, "traj_err", (1e-1, 1e-2, 1e-3, 1e-6, 1e-9), " m") + [""]

    imp = out.get("impacts")
    if imp:
        L += ["## Single impacts, the flat drop and free flight: energy and spin against the exact answer", "",
              "Face-on wall hit at 3 m/s (2-point manifold; exact: v' = −3, ω' = 0), corner hit with the block "
              "turned 30°, and a block dropped flat from 2 m onto the floor (g 9.8, exact: E ratio 1, ω 0), "
              "e = 1, μ = 0; states read 1 s after the start (after the single bounce).", "",
              "| case | dt | " + " | ".join(NAMES[e] + ": E'/E, ω'" for e in ENGINES) + " |",
              "|---|---|" + "---|" * len(ENGINES)]
        for scene in ("wall_hit_0deg", "wall_hit_30deg", "flat_drop"):
            for dt in sorted({r["dt"] for r in imp if r["scene"] == scene}, reverse=True):
                cells = []
                for e in ENGINES:
                    r = by(imp, scene, e, dt)
                    cells.append("—" if r is None or "e_ratio" not in r else
                                 f"{r['e_ratio']:.6g}, {r['omega']:+.3g}" + status_cell(r))
                L.append(f"| {scene} | 1/{round(1 / dt)} | " + " | ".join(cells) + " |")
        errs = [abs(r["e_ratio"] - 1) for r in imp if r["engine"] == "libcollide" and "e_ratio" in r]
        spin = [abs(r["omega"]) for r in imp if r["engine"] == "libcollide" and "e_ratio" in r
                and r["scene"] != "wall_hit_30deg"]
        if errs:
            summary.append(f"| single impacts and flat drop exact to 1e-9 (energy, spin) | max abs(E'/E − 1) "
                           f"{max(errs):.2g}, max abs(ω') {max(spin) if spin else math.nan:.2g} rad/s | "
                           f"{'yes' if max(errs) <= 1e-9 and (not spin or max(spin) <= 1e-9) else 'NO'} |")
        L += [""]
        fly = [r for r in imp if r["scene"] == "free_flight"]
        if fly:
            L += ["Free flight: the block thrown at (3, 6) m/s with ω = 5 rad/s under g = 9.8, nothing to hit, "
                  "1 s, states every 1/60 s against the closed form (parabola, angle linear in time). pos = the "
                  "farthest any point of the block strays from it (|Δcentre| + r |Δangle|, r = 0.559 m), vel = "
                  "largest velocity error, ΔE = relative energy change.", "",
                  "| dt | " + " | ".join(NAMES[e] + ": pos (m), vel (m/s), ΔE" for e in ENGINES) + " |",
                  "|---|" + "---|" * len(ENGINES)]
            for dt in sorted({r["dt"] for r in fly}, reverse=True):
                cells = []
                for e in ENGINES:
                    r = by(fly, "free_flight", e, dt)
                    cells.append("—" if r is None or "pos_err" not in r else
                                 f"{r['pos_err']:.2g}, {r['vel_err']:.2g}, {pct(r['e_change'])}" + status_cell(r))
                L.append(f"| 1/{round(1 / dt)} | " + " | ".join(cells) + " |")
            L += [""]

    cr = out.get("cradle")
    if cr:
        L += ["## Newton's cradle: final velocities against sequential impacts", "",
              "Striker (1 m × 0.5 m) at 5 m/s into 5 blocks, touching or with 5 cm gaps, e = 1, μ = 0, no "
              "gravity, 3 s, dt 1/60. Exact (sequential impacts): final vx = [0, 0, 0, 0, 0, 5]. "
              "err = max |vx − exact| / v0.", "",
              "| engine | touching: final vx | err, KE/KE₀, max abs(ω) | 5 cm gaps: final vx | err, KE/KE₀ |",
              "|---|---|---|---|---|"]
        labels = sorted({r["label"] for r in cr}, key=lambda x: (ENGINES.index(x.split()[0]), x))
        for lab in labels:
            a, b = by(cr, "cradle_gap0cm", lab), by(cr, "cradle_gap5cm", lab)
            ca = ("—" + status_cell(a) if a else "—") if not a or "vx" not in a else " ".join(f"{v:+.3g}" for v in a["vx"])
            cb = ("—" + status_cell(b) if b else "—") if not b or "vx" not in b else " ".join(f"{v:+.3g}" for v in b["vx"])
            ea = f"{a['err']:.2g}, {a['ke_ratio']:.6g}, {a['max_spin']:.3g}" if a and "err" in a else "—"
            eb = f"{b['err']:.2g}, {b['ke_ratio']:.6g}" if b and "err" in b else "—"
            L.append(f"| {lab} | {ca} | {ea} | {cb} | {eb} |")
        a, b = by(cr, "cradle_gap0cm", "libcollide"), by(cr, "cradle_gap5cm", "libcollide")
        if a and "err" in a:
            verdict = "yes" if a["err"] <= 1e-6 else ("borderline (at the limit)" if a["err"] <= 1.01e-6 else "NO")
            summary.append(f"| cradle, touching: sequential answer within 1e-6 | err {a['err']:.10g}, KE/KE₀ "
                           f"{a['ke_ratio']:.12g}, spin up to {a['max_spin']:.3g} rad/s | {verdict} |")
        if b and "err" in b:
            summary.append(f"| cradle, 5 cm gaps: exact | err {b['err']:.2g} | {'yes' if b['err'] <= 1e-9 else 'NO'} |")
        L += [""]

    tu = out.get("tunnel")
    if tu:
        L += ["## Tunnelling: a fast block against a thin wall", "",
              "A 0.2 m × 0.2 m block (0.1 kg) at v towards a static wall 0.1 m thick, 1 m away, e = 1, dt 1/60, "
              "0.5 s, state checked after every step. Exact: it comes back at −v.", "",
              "| v (m/s) | " + " | ".join(NAMES[e] + ": tunnelled?, v'/(−v)" for e in ENGINES) + " |",
              "|---|" + "---|" * len(ENGINES)]
        for v in sorted({float(r["scene"].split("_v")[1]) for r in tu}):
            cells = []
            for e in ENGINES:
                r = by(tu, f"tunnel_v{v:g}", e)
                cells.append("—" + (status_cell(r) if r else "") if not r or "tunnelled" not in r else
                             f"{'**yes**' if r['tunnelled'] else 'no'}, {r['vx_ratio']:.3g}")
            L.append(f"| {v:g} | " + " | ".join(cells) + " |")
        lt = [r for r in tu if r["engine"] == "libcollide"]
        bad = [r for r in lt if r.get("tunnelled") or "tunnelled" not in r]
        summary.append(f"| never a tunnel, never a NaN (tunnel scenes) | {len(lt) - len(bad)}/{len(lt)} runs clean |"
                       f" {'yes' if not bad else 'NO'} |")
        L += [""]

    stx = out.get("stacks")
    if stx:
        L += ["## Stacks: sink, creep and jitter of the top block", "",
              "N seed blocks (1 m wide, 0.5 m tall) stacked exactly touching on a floor, μ = 0.6, g = 9.8, 10 s, "
              "sleep off. sink = initial − final top-block height (positive = the stack sinks into itself), "
              "dx = sideways drift of the top block, jitter = std of the top height over the last 5 s, "
              "fell = |dx| or |sink| > 25 cm. libcollide runs at dt 1/60 only (it is event-driven; dt is the "
              "output interval).", "",
              "| stack | dt | engine | sink (mm) | dx (mm) | jitter (mm) | fell | µs/step |", "|---|---|---|---|---|---|---|---|"]
        for r in sorted(stx, key=lambda r: (r["scene"], -r["dt"], ENGINES.index(r["engine"]), r["label"])):
            if "sink" in r:
                L.append(f"| {r['scene']} | 1/{round(1 / r['dt'])} | {r['label']}{status_cell(r)} | "
                         f"{r['sink'] * 1e3:.3g} | {r['dx'] * 1e3:+.3g} | {r['jitter'] * 1e3:.2g} | "
                         f"{'**yes**' if r['fell'] else 'no'} | {f(r['us_per_step'])} |")
            else:
                L.append(f"| {r['scene']} | 1/{round(1 / r['dt'])} | {r['label']}{status_cell(r)} | — | — | — | — | — |")
        for r in stx:
            if r["engine"] != "libcollide":
                continue
            if "sink" in r and r.get("status") == "ok":
                good = abs(r["sink"]) < 1e-5 and abs(r["dx"]) < 1e-5 and not r["fell"]
                summary.append(f"| {r['scene']}: sink and creep < 0.01 mm, no jitter | sink {r['sink'] * 1e3:.3g} mm, "
                               f"dx {r['dx'] * 1e3:+.3g} mm, jitter {r['jitter'] * 1e3:.2g} mm | {'yes' if good else 'NO'} |")
            else:
                summary.append(f"| {r['scene']}: sink and creep < 0.01 mm, no jitter | did not finish: "
                               f"{r.get('status')}{' after ' + format(r.get('sim_time', 0), '.3g') + ' s simulated' if r.get('sim_time') else ''}"
                               f"{', ' + format(r['us_per_step'] / 1e3, '.3g') + ' ms per 1/60 s step' if not math.isnan(r.get('us_per_step', math.nan)) else ''} | NO |")
        st = next((r.get("stages") for r in stx if r["engine"] == "libcollide" and r.get("stages")), None)
        if st:
            L += ["", f"libcollide pipeline in the stacks: {stages_line(st)}."]
        L += [""]

    hd = out.get("hard")
    if hd:
        L += ["## Hard cases: energy and escapes when settling, at a 1:1000 mass ratio, wedged, and in a smash", "",
              "dt 1/60, states sampled every 1/60 s. settling20: the 20-block seed scene with e = 0.8, μ = 0.5, "
              "g = 9.8, 10 s (blocks come to rest); mass_ratio_1000: a 1000 kg seed block resting on a 1 kg one "
              "on the floor, μ = 0.6, e = 0, 10 s; wedged_30deg: a seed block turned 30° with its corners exactly "
              "touching two vertical walls, "
              "3 m above the floor, μ = 0.6, e = 0, 10 s (friction may hold it or let it slide; it must not pass a "
              "wall or blow up); smash_10x10: a 2 m × 2 m 40 kg block at 20 m/s into a 10 × 10 grid of 0.4 m blocks "
              "(0.16 kg), no gravity, no walls, e = 1, 2 s. ΔE = (E_end − E₀)/E₀; rise = (max E − E₀)/E₀ over the "
              "samples (must stay ≤ 0 up to rounding when nothing drives the scene); p err = linear momentum "
              "error / initial momentum.", "",
              "| scene | engine | ΔE | rise | KE end (J) | p err | escaped | sink / dx of top (mm) | µs/step |",
              "|---|---|---|---|---|---|---|---|---|"]
        for r in sorted(hd, key=lambda r: (r["scene"], ENGINES.index(r["engine"]))):
            if "e_change" not in r:
                L.append(f"| {r['scene']} | {r['label']}{status_cell(r)} | — | — | — | — | — | — | — |")
                continue
            sk = f"{r['sink'] * 1e3:.3g} / {r['dx'] * 1e3:+.3g}" if "sink" in r else ""
            L.append(f"| {r['scene']} | {r['label']}{status_cell(r)} | {pct(r['e_change'])} | {pct(r['e_max_rise'])} | "
                     f"{r['ke_end']:.3g} | {f(r.get('momentum_err'), '.2g') if 'momentum_err' in r else ''} | "
                     f"{r.get('escaped', '')} | {sk} | {f(r.get('us_per_step'))} |")
        for r in hd:
            if r["engine"] == "libcollide":
                fine = r.get("status") == "ok" and "e_change" in r and r["e_max_rise"] <= 1e-9 and not r.get("escaped")
                summary.append(f"| {r['scene']}: no NaN, no escape, no energy gain | "
                               + (f"rise {pct(r['e_max_rise'])}, escaped {r.get('escaped', 0)}, "
                                  f"{f(r.get('us_per_step'))} µs/step{status_cell(r)}" if "e_change" in r
                                  else f"{r.get('status')}") + f" | {'yes' if fine else 'NO'} |")
        L += [""]

    py = out.get("pyramid")
    if py:
        L += ["## Pyramid (Box2D `large_pyramid` layout): step cost and top-box drift", "",
              "Unit boxes (1 kg) in rows, μ = 0.6, e = 0, g = 10, dt 1/60, sleep off; "
              "ms per step = median CPU time per 1/60 s step; top moved = displacement of the top box at the end.", "",
              "| base (bodies) | " + " | ".join(NAMES[e] + ": ms/step, top moved (m)" for e in ENGINES) + " |",
              "|---|" + "---|" * len(ENGINES)]
        for base in sorted({r["base"] for r in py}):
            cells = []
            for e in ENGINES:
                r = next((r for r in py if r["base"] == base and r["label"] == e), None)
                if r is None:
                    cells.append("—")
                elif "ms_per_step" in r:
                    cells.append(f"{r['ms_per_step']:.3g}, {r['top_moved']:.3g}{status_cell(r)}")
                else:
                    cells.append("—" + status_cell(r))
            bodies = next(r["bodies"] for r in py if r["base"] == base)
            L.append(f"| {base} ({bodies}) | " + " | ".join(cells) + " |")
            lc = next((r for r in py if r["base"] == base and r["label"] == "libcollide"), None)
            target = {20: 0.2, 100: 5.0}.get(base)
            if lc and target:
                ms = lc.get("ms_per_step", math.nan)
                summary.append(f"| pyramid base {base}: < {target} ms per step | "
                               f"{'%.3g ms' % ms if not math.isnan(ms) else 'no figure'}{status_cell(lc)} | "
                               f"{'yes' if ms < target and lc.get('status') == 'ok' else 'NO'} |")
        L += [""]

    sc = out.get("scaling")
    if sc:
        plot_scaling(sc, os.path.join(img_dir, "bench_scaling.png"))
        L += ["## Scaling: step cost against body count", "",
              "Seed blocks (e = 1, g = 0, random velocities) in a walled box sized to keep the seed scene's "
              "crowding, 1 s at dt 1/60. libcollide's markers show the broadphase it chose "
              "(`world.counters()`: brute_force_steps, sort_and_sweep_steps, grid_steps; AUTO uses sort-and-sweep "
              "from 32 bodies and the grid from 4 096).", "",
              f"![scaling]({rel}/bench_scaling.png)", "",
              "| bodies | " + " | ".join(NAMES[e] + " µs/step" for e in ENGINES) + " | libcollide broadphase | "
              "libcollide body advances per step |", "|---|" + "---|" * (len(ENGINES) + 2)]
        for n in sorted({r["n"] for r in sc}):
            cells = []
            for e in ENGINES:
                r = next((r for r in sc if r["n"] == n and r["engine"] == e), None)
                cells.append("—" if r is None else f"{f(r.get('us_per_step'))}{status_cell(r)}")
            lc = next((r for r in sc if r["n"] == n and r["engine"] == "libcollide"), None)
            st = (lc or {}).get("stages") or {}
            bp = broadphase_used(st) if st else "—"
            adv = f"{st.get('analytic_advances', 0) / max(st.get('steps', 1), 1):.3g}" if st else "—"
            name = "0 (one static box: the per-step floor of engine + binding)" if n == 0 else str(n)
            L.append(f"| {name} | " + " | ".join(cells) + f" | {bp} | {adv} |")
        L += [""]
    sr = out.get("scaling_runs")
    if sr:
        if not sc:
            L += ["## Scaling: step cost against body count", "", "This run did not run the scaling section.", ""]
        scaling_runs.plot(sr, os.path.join(img_dir, scaling_runs.PLOT), NAMES, COLORS)
        L += scaling_runs.section(sr, rel, NAMES, scaling_runs.results_name(path)) + [""]

    if out.get("contact"):
        L += ["## Contact scenes: piles, pushing, friction", "",
              "This run's contact section (CPU per step and quality next to it, libcollide against Box2D v3 "
              "and Chipmunk) is in [bench_contact.md](bench_contact.md).", ""]

    # model only what a scene needs
    rows: list[tuple[str, dict[str, Any], dict[str, float]]] = []
    for sec in ("impacts", "cradle", "tunnel", "stacks", "pyramid", "scaling"):
        for r in out.get(sec) or []:
            if r["engine"] == "libcollide" and r["label"] == "libcollide" and r.get("stages"):
                rows.append((f"{r['scene']} (1/{round(1 / r['dt'])})", r["stages"], r.get("stage_times") or {}))
    if wp:
        for g in ("g0", "g9.8"):
            r = next((r for r in wp.get(g, []) if r["label"] == "libcollide"), None)
            if r and r.get("stages"):
                rows.append((f"seed 20, {g}", r["stages"], r.get("stage_times") or {}))
    if rows:
        L += ["## Pipeline stages libcollide ran per scene", "",
              "Which stages ran (counts per step, from `world.counters(last=False)` of the first repeat); an "
              "empty cell means the stage never ran in that scene.", "",
              "| scene | " + " | ".join(name for _, name in STAGES) + " |", "|---|" + "---|" * len(STAGES)]
        seen = set()
        for name, st, _ in rows:
            if name in seen:
                continue
            seen.add(name)
            steps = max(st.get("steps", 1), 1)
            L.append(f"| {name} | " + " | ".join(f"{st[k] / steps:.3g}" if st.get(k) else "" for k, _ in STAGES) + " |")
        L += [""]
        timed = [(name, tm) for name, _, tm in rows if tm.get("time_step")]
        if timed:
            L += ["### Share of the step time per stage", "",
                  "From one more run of each scene with `world.set_stage_timing(True)` (wall time per stage, "
                  "`time_*` counters; not the timed repeats above, since the clock reads cost ~5-15 % of a "
                  "small scene's step). The first five stages do not overlap; *other* is the rest of the step "
                  "(bookkeeping between stages). Contact forces are solved inside the integrations (trial "
                  "intervals, time-of-impact searches, swept checks), so their share is part of those columns.", "",
                  "| scene | µs per step (timed run) | " + " | ".join(n for _, n in TIME_STAGES) +
                  " | other | contact forces (inside) |", "|---|---|" + "---|" * (len(TIME_STAGES) + 2)]
            seen = set()
            for name, tm in timed:
                if name in seen:
                    continue
                seen.add(name)
                total = tm["time_step"]
                parts = [tm.get(k, 0.0) / total for k, _ in TIME_STAGES]
                cells = [f"{100 * p:.0f} %" if p > 0 else "" for p in parts]
                other = max(0.0, 1.0 - sum(parts))
                L.append(f"| {name} | {1e6 * total:.3g} | " + " | ".join(cells) +
                         f" | {100 * other:.0f} % | {100 * tm.get('time_contact_forces', 0.0) / total:.0f} % |")
            L += [""]

    # costliest scenes: where libcollide's time goes (counters per step)
    costly = []
    for sec in ("impacts", "cradle", "tunnel", "stacks", "hard", "pyramid", "scaling"):
        for r in out.get(sec) or []:
            if r["engine"] == "libcollide" and r.get("stages") and not math.isnan(r.get("us_per_step", math.nan)):
                costly.append(r)
    costly.sort(key=lambda r: -r["us_per_step"])
    if costly:
        L += ["### Where the time goes (costliest libcollide scenes of this run)", ""]
        for r in costly[:3]:
            st = r["stages"]
            steps = max(st.get("steps", 1), 1)
            per = ", ".join(f"{k} {st[k] / steps:.3g}" for k in ("force_evaluations", "analytic_advances",
                            "toi_searches", "toi_iterations", "collisions", "serial_iterations", "inelastic_fallbacks",
                            "contact_solves", "contact_solve_iterations", "resting_contacts") if st.get(k))
            tm = r.get("stage_times") or {}
            share = ""
            if tm.get("time_step"):
                share = "; time: " + ", ".join(f"{n} {100 * tm.get(k, 0.0) / tm['time_step']:.0f} %"
                                               for k, n in TIME_STAGES + [("time_contact_forces", "contact forces")]
                                               if tm.get(k))
            L.append(f"- **{r['scene']}**: {r['us_per_step']:.4g} µs per 1/60 s step{status_cell(r)}; per step: {per}{share}.")
        sc_rows = sorted([r for r in out.get("scaling") or [] if r["engine"] == "libcollide" and r.get("stages")],
                         key=lambda r: r["n"])
        if len(sc_rows) >= 2:
            sc_rows = [r for r in sc_rows if r["n"] > 0]
            a, b = sc_rows[0], sc_rows[-1]
            def adv(r: dict[str, Any]) -> float:
                return r["stages"]["analytic_advances"] / max(r["stages"]["steps"], 1) / r["n"]
            L.append(f"- Scaling: closed-form body advances per body per step go from {adv(a):.3g} ({a['n']} bodies) "
                     f"to {adv(b):.3g} ({b['n']} bodies); an impact advances only the bodies it involves and those "
                     f"near it (lazy clocks, docs/physics.md), where moving every body to every impact's time would "
                     f"cost impacts per step + 1.")
        L += [""]
    nd = [r["key"] for sec in out.values() if isinstance(sec, list) for r in sec if r.get("nondeterministic")]
    if nd:
        L += ["Runs whose repeats did not end in bit-identical states: " + ", ".join(nd) + ".", ""]

    head = ["## Targets: libcollide's accuracy and cost against its bars (this run)", "",
            "| target | measured | met |", "|---|---|---|"] + summary + [""]
    # insert the summary right after the "How it measures" section
    idx = L.index("## How it measures")
    end = next(i for i in range(idx + 1, len(L)) if L[i].startswith("## ")) if any(
        x.startswith("## ") for x in L[idx + 1:]) else len(L)
    L = L[:end] + head + L[end:]
    L += ["## Not covered yet", "",
          "- Pyramid base 100 and scaling beyond 2000 bodies run only in `--full` (up to 5000 bodies; "
          "`--scaling-runs` goes to 20 000 against one peer); "
          "an engine that did not finish a smaller pyramid is not run on the larger ones.",
          "- Rapier2D (needs a Rust driver) and native Box2D v3 with SIMD: not run here; "
          "their figures are in `../shared/notes/peer_bench.md`.",
          "- The 60 s hard-case stability suite belongs to the test suite, not to this benchmark.",
          "- libcollide crashes and hangs found by this benchmark have minimal reproductions in `bench/repro/`.", ""]
    with open(path, "w") as fh:
        fh.write("\n".join(L))


def load_average_text(x: Any) -> str:
    """A load-average triple as '1.0/2.0/3.0' ('?' when the run did not record it)."""
    try:
        return "/".join(f"{v:.1f}" for v in x)
    except TypeError:
        return "?"


def replot(out: dict[str, Any], img_dir: str) -> None:
    """Redraw the figures of the sections in `out` into img_dir; the page itself is left as it is."""
    with tempfile.TemporaryDirectory() as tmp:
        write(out, os.path.join(tmp, "benchmarks.md"), img_dir)


def main() -> int:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description="Redraw docs/img/bench_*.png from a stored bench/run result, "
                                 "without running the benchmarks again.")
    ap.add_argument("--replot", nargs="?", const=os.path.join(root, "bench", "results", "benchmarks.json"),
                    metavar="JSON", required=True,
                    help="results file written by bench/run (default bench/results/benchmarks.json)")
    ap.add_argument("--img-dir", default=os.path.join(root, "docs", "img"), help="where the figures go")
    args = ap.parse_args()
    if not os.path.exists(args.replot):
        print(f"report.py: no {args.replot}: run bench/run first (it keeps the results of the run that wrote "
              "docs/benchmarks.md there)", file=sys.stderr)
        return 1
    with open(args.replot) as fh:
        out = json.load(fh)
    secs = ("wp", "ref", "scaling", "scaling_runs")
    if not any(k in out for k in secs):
        print(f"report.py: {args.replot} holds no section with figures ({', '.join(secs)})", file=sys.stderr)
        return 1
    replot(out, args.img_dir)
    print(f"report.py: figures of {', '.join(k for k in secs if k in out)} "
          f"from {out.get('meta', {}).get('date', '?')} redrawn into {args.img_dir}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
