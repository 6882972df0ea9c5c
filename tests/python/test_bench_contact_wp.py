"""The contact work-precision study (bench/contact_wp.py, bench/report_contact_wp.py) on a fake pool
and on points made by hand: the cost of a run at a smaller dt must be counted per 1/60 s simulated (a
per-step figure would flatter the small-dt points 4-64x), the sentences must name the cheapest setting
that reaches libcollide's level or say that none does, and a rewrite of docs/bench_contact.md by either
writer must keep the section. No peer engine is needed (none is imported)."""
from __future__ import annotations

import json
import math
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

from bench_module import load_bench


@pytest.fixture(scope="module")
def wp() -> ModuleType:
    return load_bench("contact_wp")


@pytest.fixture(scope="module")
def rep() -> ModuleType:
    return load_bench("report_contact_wp")


class _FakePool:
    """harness.Pool's run(): every run ends at rest after the scene's steps at its dt, with 10 µs of CPU
    per step times the seed (1 for a scene without one), whatever the engine."""

    def __init__(self) -> None:
        self.ran: list[tuple[str, str, float]] = []

    def run(self, task: object) -> dict:
        self.ran.append((task.engine, task.scene.name, task.dt))
        n = int(round(task.scene.duration / task.dt))
        seed = task.scene.meta.get("seed", 1)
        return {"engine": task.engine, "label": task.label, "status": "ok", "steps": n, "sim_time": n * task.dt,
                "cpu": 1e-5 * n * seed, "states": np.repeat(task.scene.initial_state()[None], 3, axis=0),
                "stages": {"steps": n}}


def test_cost_is_per_frame_and_seeds_take_the_median(wp: ModuleType) -> None:
    pool = _FakePool()
    sec = wp.run_section(pool, ["mixed30", "stack10"], 1, lambda _: None, seeds={"mixed30": (2, 4)})
    vs = wp.variants()
    assert len({v.key for v in vs}) == len(vs)                     # one point per series and setting
    assert len(pool.ran) == 3 * len(vs) and {r[1] for r in pool.ran} == {"mixed30_s2", "mixed30_s4", "stack10_e0"}
    pts = {(p["series"], p["knob"]): p for p in sec["scenes"]["stack10"]["points"]}
    base = pts[("Chipmunk slop 5 mm", "10 iterations")]
    small = pts[("Chipmunk slop 5 mm, 10 it, smaller dt", "dt 1/960")]
    assert math.isclose(base["us_per_frame"], 10.0) and math.isclose(small["us_per_frame"], 160.0)
    assert small["total_steps"] == 600 * 16 and "sink_end" in small       # at rest: sink and creep
    mixed = sec["scenes"]["mixed30"]
    assert mixed["seeds"] == [2, 4]
    # the median of seeds 2 and 4 (20 and 40 µs per step), per 1/60 s
    assert all(math.isclose(p["us_per_frame"], 30.0 / (60 * p["dt"])) for p in mixed["points"])
    stiff = [v for v in vs if v.series == "Box2D v3 substeps, contact_hertz max"]
    assert stiff and all(v.settings["contact_hertz"] == 7.5 * v.settings["substeps"] for v in stiff)


def _pt(engine: str, series: str, knob: str, us: float, overlap: float, gain: float) -> dict:
    return {"engine": engine, "series": series, "knob": knob, "dt": 1 / 60, "us_per_frame": us, "kind": "ok",
            "status": "ok", "max_overlap": overlap, "max_step_gain": gain,
            "settings": {"collision_slop": 0.005} if engine == "pymunk" else {"substeps": 4}}


SEC = {"frame_dt": 1 / 60, "repeats": 1, "variants": [{"engine": "pymunk", "dt": 1 / 240}],
       "scenes": {"push": {"what": "row", "bodies": 41, "at_rest": False, "seeds": [], "points": [
           _pt("libcollide", "libcollide", "defaults", 100.0, 1e-7, 0.0),
           _pt("box2d3", "B sub", "4 substeps", 50.0, 0.03, 1e-5),
           _pt("box2d3", "B sub", "64 substeps", 400.0, 0.02, 1e-7),
           _pt("pymunk", "C it", "10 iterations", 80.0, 0.05, 1e-3),
           _pt("pymunk", "C dt", "dt 1/960", 900.0, 5e-7, 1e-10),
           _pt("pymunk", "C dt", "dt 1/3840", 3000.0, 2e-7, -1e-3)]}}}


def test_findings_name_the_cheapest_setting_that_reaches_libcollide(rep: ModuleType) -> None:
    text = "\n".join(rep.findings(SEC, "push"))
    # Box2D: never within 1e-6 m (libcollide's 1e-7 is below the stated level, so the level is 1e-6)
    assert "Box2D v3, max overlap: smallest 20 mm (B sub, 64 substeps: 400 µs (4× libcollide))" in text
    assert "no setting measured reaches 0.001 mm (libcollide's level here)" in text
    # Chipmunk: 1/960 is the cheapest point within 1e-6 m, though 1/3840 has the smaller overlap
    assert "≤ 0.001 mm (libcollide's level here) first at C dt, dt 1/960: 900 µs (9× libcollide)" in text
    assert "Chipmunk, max overlap: smallest 0.0002 mm (C dt, dt 1/3840: 3000 µs (30× libcollide))" in text
    # a loss (negative gain) counts as within the level; the cheapest such point is named
    assert "≤ +1e-09 (libcollide's level here) first at C dt, dt 1/960" in text
    cells = [c.strip() for c in rep.summary_table(SEC)[2].split("|")[1:-1]]
    assert cells == ["push", "100", "0.0001 / +0", "20 (64 substeps; 400 µs, 4×)", "+1e-07 (64 substeps; 400 µs, 4×)",
                     "0.0002 (dt 1/3840, 10 iterations, slop 5 mm; 3000 µs, 30×)",
                     "-0.001 (dt 1/3840, 10 iterations, slop 5 mm; 3000 µs, 30×)"]
    table = rep.scene_table(SEC, "push")
    assert len(table) == 2 + 6 and "| 9  " in table[6] and "| 0.0005 " in table[6]


def test_section_survives_both_writers(rep: ModuleType, tmp_path: Path) -> None:
    block = rep.section({"meta": {"date": "2026-01-01 00:00 UTC"}, "contact_wp": SEC})
    assert block[0] == rep.BEGIN and block[-1] == rep.END and "### push (41 bodies): row" in block
    page = rep.splice("# Page\n\ntable\n", block)
    again = rep.splice(page + "\ntail\n", block[:3] + [rep.END])
    assert page.count(rep.BEGIN) == again.count(rep.BEGIN) == 1
    assert again.startswith("# Page\n\ntable\n") and again.endswith("tail\n") and "### push" not in again
    # bench/run --sections contact rewrites the whole page: the section comes back from the JSON
    report_contact = load_bench("report_contact")
    results = tmp_path / "wp.json"
    results.write_text(json.dumps({"meta": {}, "contact_wp": SEC}))
    sec = {"engines": ["libcollide"], "rows": [], "repeats": 1, "dt": 1 / 60, "settings": {"libcollide": {}},
           "budget_cpu_s": 20.0, "peer_budget_cpu_s": 600.0, "scenes": {}}
    out = tmp_path / "bench_contact.md"
    report_contact.write_contact({"contact": sec}, str(out), wp_results=str(results))
    assert out.read_text().count(rep.BEGIN) == 1 and "first at C dt, dt 1/960" in out.read_text()
    report_contact.write_contact({"contact": sec}, str(out), wp_results=str(tmp_path / "none.json"))
    assert rep.BEGIN not in out.read_text()
