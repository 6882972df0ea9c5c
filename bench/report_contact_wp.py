"""The work-precision section of docs/bench_contact.md (bench/contact_wp.py): a table per scene, the
sentences that read the table (each from the numbers: how far each peer's overlap and energy gain fall
and at what cost), and the figure. The section sits between two markers so that either writer of the
page keeps it: bench/run --sections contact_wp replaces it in place, and report_contact.write_contact
(bench/run --sections contact) regenerates it from bench/results/bench_contact_wp.json, and so does
`python bench/report_contact_wp.py` (with the figure; no engine runs)."""
from __future__ import annotations

import math
import os
import sys
from typing import Any

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from page_block import replace_block  # noqa: E402
from report import f, load_average_text  # noqa: E402
from report_contact import CONTACT_NAMES, md_table  # noqa: E402

BEGIN = "<!-- contact_wp: begin (bench/run --sections contact_wp writes this section) -->"
END = "<!-- contact_wp: end -->"
FIGURE = "bench_contact_wp.png"
# libcollide's stated accuracy: a peer "reaches libcollide" when it is within these or within
# libcollide's own figure in the same run, whichever is larger
OVERLAP_TARGET = 1e-6     # m
GAIN_TARGET = 1e-9        # worst relative energy gain per 1/60 s
# log axes: values at or below these (no overlap, no energy gain) are drawn on the floor
OVERLAP_FLOOR = 1e-13
GAIN_FLOOR = 1e-17
PEERS = ("box2d3", "pymunk")


def _ok(points: list[dict[str, Any]], engine: str, measure: str) -> list[dict[str, Any]]:
    """The points of one engine that finished and have the measure."""
    return [p for p in points if p["engine"] == engine and p.get("kind") == "ok"
            and measure in p and p[measure] is not None and not math.isnan(p[measure])]


def _where(p: dict[str, Any], lc_us: float) -> str:
    ratio = p["us_per_frame"] / lc_us if lc_us and math.isfinite(lc_us) else math.nan
    return f"{p['series']}, {p['knob']}: {f(p['us_per_frame'], '.4g')} µs ({f(ratio, '.3g')}× libcollide)"


def _mm(x: float) -> str:
    return "0" if x == 0 else f"{x * 1e3:.3g} mm"


def _reach(pts: list[dict[str, Any]], measure: str, target: float) -> dict[str, Any] | None:
    """The cheapest point whose measure is at most target (None if no point is)."""
    good = [p for p in pts if p[measure] <= target]
    return min(good, key=lambda p: p["us_per_frame"]) if good else None


def findings(sec: dict[str, Any], key: str) -> list[str]:
    """One bullet per peer and measure: the smallest value any of its settings reached, where and at
    what cost, the value at the costliest setting of each of its series, and whether (and for how much) it reaches
    libcollide's level in this run."""
    points = sec["scenes"][key]["points"]
    lc = next((p for p in points if p["engine"] == "libcollide" and p.get("kind") == "ok"), None)
    lc_us = lc["us_per_frame"] if lc else math.nan
    L = []
    if lc is not None:
        L.append(f"- libcollide (defaults): {f(lc_us, '.4g')} µs per 1/60 s, max overlap {_mm(lc['max_overlap'])}, "
                 f"worst ΔE/E {lc['max_step_gain']:+.2g}.")
    for eng in PEERS:
        name = CONTACT_NAMES[eng]
        for measure, unit, target_of in (("max_overlap", _mm, OVERLAP_TARGET), ("max_step_gain", None, GAIN_TARGET)):
            pts = _ok(points, eng, measure)
            if not pts:
                continue
            show = unit or (lambda x: f"{x:+.2g}")
            what = "max overlap" if measure == "max_overlap" else "worst ΔE/E per 1/60 s"
            best = min(pts, key=lambda p: p[measure])
            target = max(target_of, lc[measure]) if lc is not None and lc[measure] > 0 else target_of
            hit = _reach(pts, measure, target)
            ends = [max((p for p in pts if p["series"] == s), key=lambda p: p["us_per_frame"])
                    for s in dict.fromkeys(p["series"] for p in pts)]
            text = (f"- {name}, {what}: smallest {show(best[measure])} ({_where(best, lc_us)}); at the costliest "
                    "setting of each series " + "; ".join(f"{show(p[measure])} ({_where(p, lc_us)})" for p in ends)
                    + "; ")
            at_frame = [p for p in pts if math.isclose(p["dt"], sec["frame_dt"])]
            if measure == "max_overlap" and at_frame:
                knobs = "substep count or contact_hertz" if eng == "box2d3" else "iteration count or slop"
                low = min(at_frame, key=lambda p: p[measure])
                text += (f"at dt 1/60 it does not fall below {show(low[measure])} at any {knobs} measured "
                         f"(range {show(low[measure])}-{show(max(p[measure] for p in at_frame))}); ")
            if hit is None:
                text += f"no setting measured reaches {show(target)} (libcollide's level here)."
            else:
                text += f"≤ {show(target)} (libcollide's level here) first at {_where(hit, lc_us)}."
            L.append(text)
    return L


def _best_cell(points: list[dict[str, Any]], engine: str, measure: str, lc_us: float) -> str:
    """The smallest value of a measure over an engine's points, with its setting, cost and cost ratio."""
    pts = _ok(points, engine, measure)
    if not pts:
        return "—"
    p = min(pts, key=lambda q: q[measure])
    value = f"{p[measure] * 1e3:.3g}" if measure == "max_overlap" else f"{p[measure]:+.2g}"
    ratio = p["us_per_frame"] / lc_us if lc_us and math.isfinite(lc_us) else math.nan
    return f"{value} ({_short(p)}; {f(p['us_per_frame'], '.4g')} µs, {f(ratio, '.3g')}×)"


def _short(p: dict[str, Any]) -> str:
    """A point's setting in a few words: its knob with the settings its series holds fixed."""
    st = p.get("settings") or {}
    if p["engine"] == "pymunk":
        return f"{p['knob']}" + (", 10 iterations" if "iterations" not in p["knob"] else "") + \
            f", slop {st.get('collision_slop', math.nan) * 1e3:g} mm"
    if p["engine"] == "box2d3" and "substeps" not in p["knob"]:
        return f"{st.get('substeps', '?')} substeps, {p['knob']}"
    return p["knob"]


def summary_table(sec: dict[str, Any]) -> list[str]:
    """One row per scene: libcollide's cost and quality, and each peer's smallest max overlap and
    smallest worst energy gain over all its settings, each with where and at what cost."""
    head = ["scene", "libcollide µs per 1/60 s", "libcollide overlap mm / ΔE/E"]
    for eng in PEERS:
        head += [f"{CONTACT_NAMES[eng]} smallest overlap mm (setting; µs, × libcollide)",
                 f"{CONTACT_NAMES[eng]} smallest worst ΔE/E (setting; µs, × libcollide)"]
    rows = []
    for key, s in sec["scenes"].items():
        lc = next((p for p in s["points"] if p["engine"] == "libcollide" and p.get("kind") == "ok"), None)
        lc_us = lc["us_per_frame"] if lc else math.nan
        row = [key, f(lc_us, ".4g"), "—" if lc is None else f"{lc['max_overlap'] * 1e3:.3g} / {lc['max_step_gain']:+.2g}"]
        for eng in PEERS:
            row += [_best_cell(s["points"], eng, "max_overlap", lc_us), _best_cell(s["points"], eng, "max_step_gain", lc_us)]
        rows.append(row)
    return md_table(head, rows)


def _sink_cell(p: dict[str, Any]) -> str:
    if "sink_end" not in p:
        return "—"
    return f"{p['sink_end'] * 1e3:.3g} / {p['creep'] * 1e3:.3g}"


def scene_table(sec: dict[str, Any], key: str) -> list[str]:
    """One row per point: engine series, setting, dt, cost per 1/60 s and its ratio to libcollide's,
    max overlap, worst energy gain per 1/60 s (and sink / creep for the scenes at rest)."""
    s = sec["scenes"][key]
    points = s["points"]
    lc = next((p for p in points if p["engine"] == "libcollide"), None)
    lc_us = lc["us_per_frame"] if lc else math.nan
    head = ["engine, series", "setting", "dt s", "µs per 1/60 s", "× libcollide", "max overlap mm",
            "worst ΔE/E per 1/60 s"] + (["sink end / creep mm"] if s["at_rest"] else [])
    rows = []
    for p in points:
        status = "" if p.get("kind") == "ok" else f" ({p.get('kind')}: {p.get('status')})"
        ov = p.get("max_overlap")
        gain = p.get("max_step_gain")
        row = [p["series"], p["knob"] + status, f"1/{round(1 / p['dt'])}", f(p["us_per_frame"], ".4g"),
               f(p["us_per_frame"] / lc_us if lc_us else math.nan, ".3g"),
               "—" if ov is None else ("0" if ov == 0 else f"{ov * 1e3:.3g}"),
               "—" if gain is None or math.isnan(gain) else f"{gain:+.2g}"]
        rows.append(row + ([_sink_cell(p)] if s["at_rest"] else []))
    return md_table(head, rows)


def _scene_title(key: str, s: dict[str, Any]) -> str:
    seeds = s.get("seeds") or []
    which = f"; seeds {','.join(map(str, seeds))}: median cost, worst seed's quality" if len(seeds) > 1 else (
        f"; seed {seeds[0]}" if seeds else "")
    return f"### {key} ({s['bodies']} bodies{which})"


def _small_dts(sec: dict[str, Any], engine: str) -> str:
    """The dt values below 1/60 s that an engine's variants use, as '1/240, 1/960'."""
    dts = sorted({v["dt"] for v in sec["variants"] if v["engine"] == engine and v["dt"] < sec["frame_dt"]}, reverse=True)
    return ", ".join(f"1/{round(1 / d)}" for d in dts) or "none"


def section(wp: dict[str, Any]) -> list[str]:
    """The whole section (markers included) from bench/results/bench_contact_wp.json's dict."""
    sec, meta = wp["contact_wp"], wp.get("meta", {})
    L = [BEGIN, "## Work-precision: the peers' accuracy knobs turned up", "",
         "Regenerate with `bench/run --sections contact_wp` (bench/contact_wp.py; `--quick`: 1 repeat, first seed "
         "only). It rewrites this section, `docs/img/" + FIGURE + "` and `bench/results/bench_contact_wp.json`; "
         "`bench/run --sections contact` keeps the section (it redraws it from that JSON).", "",
         f"Run of {meta.get('date', '?')}, {sec['repeats']} repeat(s) per point, on {meta.get('cpus', '?')} × "
         f"{meta.get('cpu_model', '?')}; load average before/after {load_average_text(meta.get('load_before'))} / "
         f"{load_average_text(meta.get('load_after'))} (shared VM). libcollide: {meta.get('libcollide', '?')}. Peers: "
         + ", ".join(f"{k} {v}" for k, v in meta.get("versions", {}).items() if k in ("pymunk", "pyb2d3")) + ".", "",
         "Each point is one engine at one setting on the scene of the table above (same scene, same quality "
         "measures, `bench/metrics.py`). Cost = CPU of the step loop per 1/60 s of simulated time, median over the "
         "repeats, so a run at dt 1/240 counts four steps. States are read every 1/60 s in every run: max overlap "
         "is taken at the same instants for every point and the worst energy gain is per 1/60 s. Box2D v3 series: "
         "substeps 4-64 at its default contact stiffness (contact_hertz 30, damping ratio 10, push speed 3 m/s) "
         "and with contact_hertz at an eighth of the substep rate (the stiffest it applies: its step clamps "
         f"larger values to that), and 4 substeps at dt {_small_dts(sec, 'box2d3')}; its linear slop (5 mm) is compiled in. "
         f"Chipmunk: iterations 10-160 with collision_slop 5 mm and 0, and 10 iterations at dt {_small_dts(sec, 'pymunk')}. "
         f"\"libcollide's level here\" = libcollide's figure in the same run, or {OVERLAP_TARGET:g} m overlap / "
         f"{GAIN_TARGET:g} energy gain if that is larger.", "",
         "Smallest value each peer reaches over all its settings (the figure and the tables below have every point):",
         ""] + summary_table(sec) + ["",
         f"![CPU per 1/60 s against max overlap and worst energy gain, per scene](img/{FIGURE})", ""]
    for key, s in sec["scenes"].items():
        L += [_scene_title(key, s) + f": {s['what']}", ""] + findings(sec, key) + [""] + scene_table(sec, key) + [""]
    return L + [END]


def splice(page: str, block: list[str]) -> str:
    """The page with its contact_wp section replaced by block (appended when the page has none)."""
    return replace_block(page, BEGIN, END, "\n".join(block), append_missing=True)


def update_page(wp: dict[str, Any], path: str) -> None:
    """Replaces (or appends) the section in docs/bench_contact.md, the rest of the page as it is."""
    page = open(path).read() if os.path.exists(path) else "# Benchmarks: contact scenes\n"
    with open(path, "w") as fh:
        fh.write(splice(page, section(wp)))


def _series_style(series: list[str]) -> dict[str, tuple[str, str]]:
    """(colour, marker) per series: Box2D blues, Chipmunk oranges/reds, libcollide black."""
    b2 = iter([("#1f77b4", "o"), ("#6baed6", "s"), ("#08306b", "^")])
    cm = iter([("#ff7f0e", "o"), ("#d62728", "s"), ("#fdae6b", "^"), ("#a50f15", "v")])
    out = {}
    for s in series:
        out[s] = ("black", "*") if s == "libcollide" else next(b2 if s.startswith("Box2D") else cm, ("grey", "x"))
    return out


def plot(sec: dict[str, Any], path: str) -> None:
    """One row of two log-log panels per scene: CPU per 1/60 s against max overlap, and against the
    worst energy gain per 1/60 s; one line of markers per series, in the order of its settings."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    keys = list(sec["scenes"])
    series = list(dict.fromkeys(p["series"] for k in keys for p in sec["scenes"][k]["points"]))
    style = _series_style(series)
    fig, axes = plt.subplots(len(keys), 2, figsize=(11, 3.1 * len(keys) + 1.2), squeeze=False)
    for row, key in zip(axes, keys):
        pts = [p for p in sec["scenes"][key]["points"] if p.get("kind") == "ok"]
        for ax, measure, floor, label in ((row[0], "max_overlap", OVERLAP_FLOOR, "max overlap (m)"),
                                          (row[1], "max_step_gain", GAIN_FLOOR, "worst ΔE/E per 1/60 s")):
            for s in series:
                sp = [p for p in pts if p["series"] == s and measure in p and not math.isnan(p[measure])]
                if not sp:
                    continue
                c, m = style[s]
                ax.plot([p["us_per_frame"] for p in sp], [max(p[measure], floor) for p in sp], color=c, marker=m,
                        ms=9 if s == "libcollide" else 5, lw=1, label=s)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("CPU µs per 1/60 s simulated")
            ax.set_ylabel(label)
            ax.set_title(f"{key}: {label.split(' (')[0]}", fontsize=10)
            ax.grid(True, which="major", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=3, fontsize=8, frameon=False)
    fig.text(0.5, 0.005, f"values ≤ {OVERLAP_FLOOR:g} m overlap or ≤ {GAIN_FLOOR:g} gain (incl. 0 and losses) "
             "are drawn on that floor", ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.015, 1, 1 - 0.9 / (3.1 * len(keys) + 1.2)))
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main() -> int:
    """Redraws the section of docs/bench_contact.md and the figure from the last run's JSON, no engine run."""
    import json
    root = os.path.dirname(HERE)
    with open(os.path.join(HERE, "results", "bench_contact_wp.json")) as fh:
        wp = json.load(fh)
    plot(wp["contact_wp"], os.path.join(root, "docs", "img", FIGURE))
    update_page(wp, os.path.join(root, "docs", "bench_contact.md"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
