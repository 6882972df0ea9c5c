"""The contact section's quality measures (bench/metrics.py) on states made by hand, and how
bench/contact.py and bench/report_contact.py turn a run that stopped early into a row and a table cell.

The overlap depth must be the true penetration depth of two rectangles (the shortest separating
translation), whatever their angles: the section ranks engines by it, so a measure that misses a
pair or under-reports a rotated one would flatter the engine that lets boxes sink into each other.
No peer engine is needed (none is imported)."""
from __future__ import annotations

import itertools
import math
from types import ModuleType

import numpy as np
import pytest

from bench_module import load_bench


m = load_bench("metrics")
sc = load_bench("scenes")


def _scene(*boxes: object, gravity: float = 0.0) -> object:
    return sc.Scene("hand", tuple(boxes), gravity=gravity)


def _state(scene: object) -> np.ndarray:
    return scene.initial_state()[None]          # one sample


def _depth_by_directions(ca: np.ndarray, aa: float, ha: np.ndarray, cb: np.ndarray, ab: float, hb: np.ndarray,
                         k: int = 20000) -> float:
    """Penetration depth as the smallest projection overlap over directions: an independent, slower
    definition (exact for convex shapes as the sampling gets finer). k directions over [0, pi),
    then k more within one step of the best: the minimum can sit on a kink (a face normal), where
    the sampling error is first order in the step."""
    def overlap(t: np.ndarray) -> np.ndarray:
        n = np.stack([np.cos(t), np.sin(t)], -1)

        def radius(a: float, h: np.ndarray) -> np.ndarray:
            u, v = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
            return h[0] * np.abs(n @ u) + h[1] * np.abs(n @ v)
        return radius(aa, ha) + radius(ab, hb) - np.abs(n @ (cb - ca))
    step = np.pi / k
    coarse = np.arange(k) * step
    best = coarse[int(np.argmin(overlap(coarse)))]
    return float(np.min(overlap(np.linspace(best - step, best + step, k))))


def test_axis_aligned_overlap_is_the_smaller_axis_overlap() -> None:
    scene = _scene(sc.Box(1.0, 1.0, 0.0, 0.0), sc.Box(1.0, 1.0, 0.9, 0.2))   # 0.1 m in x, 0.8 m in y
    r = m.max_overlap(scene, _state(scene))
    assert math.isclose(r["max_overlap"], 0.1, rel_tol=1e-12)
    assert r["overlap_sample"] == 0 and sorted(r["overlap_pair"]) == [0, 1]


def test_rotated_overlaps_have_their_exact_depth() -> None:
    a = 0.3
    u = np.array([math.cos(a), math.sin(a)])
    # two unit squares at the same angle, 0.95 m apart along their common local x axis: 0.05 m deep
    scene = _scene(sc.Box(1.0, 1.0, 0.0, 0.0, angle=a), sc.Box(1.0, 1.0, *(0.95 * u), angle=a))
    assert math.isclose(m.max_overlap(scene, _state(scene))["max_overlap"], 0.05, rel_tol=1e-9)
    # a unit square on its corner (45 deg) whose corner is 0.03 m into a static floor (top at y = 0)
    diamond = _scene(sc.Box(1.0, 1.0, 0.0, math.sqrt(0.5) - 0.03, angle=math.pi / 4),
                     sc.Box(20.0, 1.0, 0.0, -0.5, static=True))
    r = m.max_overlap(diamond, _state(diamond))
    assert math.isclose(r["max_overlap"], 0.03, rel_tol=1e-9)
    assert sorted(r["overlap_pair"]) == [0, 1]                         # dynamic 0 against the static box


def test_separating_axis_depth_matches_the_smallest_projection_overlap() -> None:
    rng = np.random.default_rng(3)
    overlapping = 0
    for _ in range(200):
        ha, hb = rng.uniform(0.1, 0.6, 2), rng.uniform(0.1, 0.6, 2)
        aa, ab = rng.uniform(0, 2 * np.pi, 2)
        ca, cb = np.zeros(2), rng.uniform(-0.8, 0.8, 2)
        sat = float(m.sat_depth(ca[None], np.array([aa]), ha[None], cb[None], np.array([ab]), hb[None])[0])
        brute = _depth_by_directions(ca, aa, ha, cb, ab, hb)
        if sat <= 0.0:
            # apart or touching: some face normal separates them, so no direction finds an overlap
            # (apart, the face normals under-report the gap when the closest points are two corners,
            # so only the sign is compared)
            assert brute <= 1e-12
            continue
        overlapping += 1
        # sampled directions can only miss the minimum: brute >= sat, by about the fine step (1.6e-8 rad)
        assert sat <= brute + 1e-12
        assert brute - sat < 1e-7
    assert overlapping > 50


def test_touching_and_apart_boxes_do_not_overlap() -> None:
    touching = _scene(sc.Box(1.0, 0.5, 0.0, 0.25), sc.Box(1.0, 0.5, 0.0, 0.75), sc.Box(20.0, 1.0, 0.0, -0.5, static=True))
    assert m.max_overlap(touching, _state(touching))["max_overlap"] == 0.0
    apart = _scene(sc.Box(1.0, 1.0, 0.0, 0.0, angle=0.7), sc.Box(1.0, 1.0, 1.5, 0.3, angle=0.2))
    r = m.max_overlap(apart, _state(apart))
    assert r["max_overlap"] == 0.0 and r["overlap_sample"] == -1


def test_walls_sharing_corners_are_not_an_overlap_but_a_box_in_a_wall_is() -> None:
    inside = _scene(sc.Box(1.0, 1.0, 5.0, 5.0), *sc.walls(0, 0, 10, 10))     # walls() boxes overlap at corners
    assert m.max_overlap(inside, _state(inside))["max_overlap"] == 0.0
    into = _scene(sc.Box(1.0, 1.0, 9.8, 5.0), *sc.walls(0, 0, 10, 10))       # 0.3 m into the right wall
    assert math.isclose(m.max_overlap(into, _state(into))["max_overlap"], 0.3, rel_tol=1e-12)


def test_the_largest_overlap_over_samples_and_its_step() -> None:
    scene = _scene(sc.Box(1.0, 1.0, 0.0, 0.0), sc.Box(1.0, 1.0, 2.0, 0.0))
    states = np.repeat(scene.initial_state()[None], 4, axis=0)
    states[1, 1, 0] = 0.98                       # 0.02 m
    states[2, 1, 0] = 0.9                        # 0.1 m: the largest
    states[3, 1, 0] = 0.95
    r = m.max_overlap(scene, states)
    assert math.isclose(r["max_overlap"], 0.1, rel_tol=1e-9) and r["overlap_sample"] == 2


def test_broadphase_finds_every_overlapping_pair_once() -> None:
    rng = np.random.default_rng(0)
    for _ in range(10):
        n = 150
        lo = rng.uniform(0, 10, (n, 2))
        hi = lo + rng.uniform(0.05, 1.0, (n, 2))
        static = rng.uniform(size=n) < 0.05
        hi[static] += rng.uniform(0, 8, (int(static.sum()), 2))      # large static boxes
        a, b = m.aabb_pairs(lo, hi, static)
        got = [tuple(sorted(p)) for p in zip(a.tolist(), b.tolist())]
        want = {(i, j) for i, j in itertools.combinations(range(n), 2) if not (static[i] and static[j])
                and lo[i, 0] <= hi[j, 0] and lo[j, 0] <= hi[i, 0] and lo[i, 1] <= hi[j, 1] and lo[j, 1] <= hi[i, 1]}
        assert len(got) == len(set(got)) and set(got) == want


def test_a_centre_outside_the_walls_is_an_escape() -> None:
    states = np.zeros((3, 2, 6))
    states[:, :, :2] = [[2.0, 2.0], [5.0, 1.0]]
    states[2, 1, 0] = 10.4                        # body 1 passes the right wall (inner x <= 10) at sample 2
    r = m.escaped_bodies(states, (0.0, 0.0, 10.0, 10.0))
    assert r == {"escaped": 1, "escape_sample": 2}
    assert m.escaped_bodies(states[:2], (0.0, 0.0, 10.0, 10.0)) == {"escaped": 0, "escape_sample": -1}
    states[1, 0, 1] = -0.1                        # body 0 below the ground top, body 1 as before
    assert m.escaped_bodies(states, (-math.inf, 0.0, math.inf, math.inf)) == {"escaped": 1, "escape_sample": 1}


def test_energy_steps_find_the_largest_single_step_gain() -> None:
    scene = _scene(sc.Box(1.0, 1.0, 0.0, 1.0, mass=2.0), gravity=10.0)      # E = v^2 + 20 y
    energy = np.array([40.0, 30.0, 33.0, 20.0, 21.0])                        # gains: 3/30 at step 2, 1/20 at 4
    states = np.zeros((5, 1, 6))
    states[:, 0, 1] = 1.0
    states[:, 0, 4] = np.sqrt(energy - 20.0)
    assert np.allclose(m.energy(scene, states), energy)
    r = m.energy_steps(scene, states)
    assert math.isclose(r["max_step_gain"], 0.1, rel_tol=1e-12) and r["gain_step"] == 2
    assert math.isclose(r["e_change"], -0.475, rel_tol=1e-12)
    falling = states[[0, 1, 3]]                                              # only losses: a negative worst gain
    assert m.energy_steps(scene, falling)["max_step_gain"] < 0


def test_sink_and_creep_of_a_stack() -> None:
    states = np.zeros((4, 3, 6))
    states[:, :, 1] = [0.25, 0.75, 1.25]          # the top box is the last one
    states[1, 2, 1] = 1.24                        # sinks 10 mm ...
    states[2, 2, 1] = 1.23                        # ... 20 mm at most ...
    states[3, 2, 1] = 1.245                       # ... and ends 5 mm low
    states[2, 0, 0] = -0.003                      # the bottom box creeps 3 mm left, then back
    states[3, 1, 0] = 0.001
    r = m.sink_creep(states)
    assert math.isclose(r["sink_end"], 0.005, abs_tol=1e-12)
    assert math.isclose(r["sink_max"], 0.02, abs_tol=1e-12)
    assert math.isclose(r["creep"], 0.003, abs_tol=1e-12)


def test_mixed_boxes_never_start_overlapping() -> None:
    for n in (30, 100, 1000):
        scene = sc.mixed_boxes(n)
        assert m.max_overlap(scene, _state(scene))["max_overlap"] == 0.0
        assert m.escaped_bodies(_state(scene), scene.meta["inner"])["escaped"] == 0
        w = np.array([b.w for b in scene.dynamic])
        assert np.all((w >= 0.3) & (w <= 0.8))
        assert np.allclose(scene.masses, 2.0 * w * np.array([b.h for b in scene.dynamic]))


def test_push_row_rests_on_the_floor_with_gaps() -> None:
    scene = sc.push_row()
    block, row = scene.dynamic[0], scene.dynamic[1:]
    assert len(row) == 40 and all(b.y == 0.25 for b in row)
    assert np.allclose(np.diff([b.x for b in row]), 0.55)
    assert math.isclose(row[0].x - 0.25 - (block.x + 0.5), 1.0)
    assert m.max_overlap(scene, _state(scene))["max_overlap"] == 0.0


@pytest.fixture(scope="module")
def contact() -> ModuleType:
    return load_bench("contact")          # it imports harness, metrics and scenes by name; no engine


def _run(engine: str, status: str, steps: int, cpu: float, states: np.ndarray) -> dict:
    """A harness result as run_interleaved returns it (cpu_median over the repeats)."""
    return {"engine": engine, "label": engine, "status": status, "steps": steps, "cpu_median": cpu,
            "us_per_step": 1e6 * cpu / steps, "states": states, "stages": {"steps": steps, "collisions": 2 * steps}}


def test_a_run_over_budget_keeps_its_steps_cpu_and_quality(contact: ModuleType) -> None:
    cs = contact.contact_scenes()["stack10"]()
    states = np.repeat(cs.scene.initial_state()[None], 42, axis=0)
    states[-1, -1, 1] -= 0.004                                   # the top box 4 mm low after 41 steps
    lc = contact.summarize(cs, _run("libcollide", "over_budget", 41, 20.5, states))
    assert lc["kind"] == "over budget" and lc["steps"] == 41 and lc["total_steps"] == 600
    assert math.isclose(lc["us_per_step"], 5e5) and math.isclose(lc["sink_end"], 0.004, rel_tol=1e-9)
    # the top box 4 mm low is 4 mm into the box below it
    assert math.isclose(lc["max_overlap"], 0.004, rel_tol=1e-9) and lc["overlap_sample"] == 41
    assert lc["escaped"] == 0 and "states" not in lc
    peer = contact.summarize(cs, _run("box2d3", "ok", 600, 0.01,
                                      np.repeat(cs.scene.initial_state()[None], 601, axis=0)))
    contact.add_ratios([lc, peer])
    assert math.isclose(lc["ratio_box2d3"], 5e5 / (1e6 * 0.01 / 600))
    failed = contact.summarize(cs, _run("libcollide", "step error status 3", 7, 1.0, states[:8]))
    assert failed["kind"] == "failed"
    killed = contact.summarize(cs, {"engine": "libcollide", "status": "hang: no progress for 50 s wall",
                                    "steps_done": 5, "cpu_done": 2.0, "states": states[:6]})
    assert killed["kind"] == "over budget" and killed["killed_in_step"] and math.isclose(killed["us_per_step"], 4e5)

    report = load_bench("report_contact")
    sec = {"engines": ["libcollide", "box2d3"], "rows": [lc, peer], "repeats": 1, "dt": 1 / 60,
           "settings": contact.CONTACT_SETTINGS, "budget_cpu_s": 20.0, "peer_budget_cpu_s": 600.0,
           "scenes": {"stack10": {"name": cs.scene.name, "what": cs.what, "bodies": 10, "steps": 600,
                                  "at_rest": True}}}
    table = report.contact_table(sec)
    assert len(table) == 3 and "over budget: 41/600 steps" in table[2] and "4 / 4 / 0" in table[2]
    assert "4 (s41)" in table[2]
    assert report.contact_notes(sec)


def _seed_row(seed: int, engine: str, us: float, kind: str = "ok", **quality: object) -> dict:
    """A per-seed row of one random pile as bench/contact.py's summarize makes it."""
    steps = 300 if kind == "ok" else 41
    return {"key": "mixed30", "scene": f"mixed30_s{seed}", "engine": engine, "label": engine, "bodies": 30,
            "total_steps": 300, "steps": steps, "status": "ok" if kind == "ok" else "over_budget", "kind": kind,
            "killed_in_step": False, "us_per_step": us, "seed": seed, "stages": {"steps": steps, "collisions": seed},
            "max_overlap": 0.0, "overlap_sample": -1, "overlap_pair": [-1, -1], "escaped": 0, "escape_sample": -1,
            "max_step_gain": -1e-3, "gain_step": 1, "e_change": -0.5, **quality}


def test_random_piles_take_the_median_cost_and_the_worst_quality_over_seeds(contact: ModuleType) -> None:
    # seed 3 is slow and over budget, seed 2 has the deepest overlap, seed 3 the most escapes, and
    # seed 2 the largest energy gain though seeds 1 and 3 have larger |gain|: a mean (250 µs), a
    # median of the quality (20 mm) or a largest |gain| would each give another row
    lc = [_seed_row(1, "libcollide", 100.0, max_overlap=0.01, overlap_sample=10, escaped=1, escape_sample=9,
                    max_step_gain=-1e-3, gain_step=4, e_change=-0.6),
          _seed_row(2, "libcollide", 150.0, max_overlap=0.05, overlap_sample=20, overlap_pair=[3, 4],
                    max_step_gain=2e-12, gain_step=77, e_change=-0.5),
          _seed_row(3, "libcollide", 500.0, "over budget", max_overlap=0.02, overlap_sample=5, escaped=3,
                    escape_sample=7, max_step_gain=-5e-4, gain_step=2, e_change=-0.1)]
    b2 = [_seed_row(1, "box2d3", 50.0), _seed_row(2, "box2d3", 40.0), _seed_row(3, "box2d3", 60.0)]
    for a, b in zip(lc, b2):
        contact.add_ratios([a, b])                                   # per-seed ratios 2, 3.75, 8.33
    rows = [contact.aggregate_seeds(lc), contact.aggregate_seeds(b2)]
    contact.add_seed_ratios(rows)
    agg = rows[0]
    assert agg["us_per_step"] == 150.0 and rows[1]["us_per_step"] == 50.0
    assert math.isclose(agg["ratio_box2d3"], 3.75)                   # the seeds' median ratio, not 150 / 50
    assert agg["seeds"] == [1, 2, 3] and agg["per_seed"] is lc and agg["per_seed"][0]["ratio_box2d3"] == 2.0
    assert agg["max_overlap"] == 0.05 and agg["overlap_sample"] == 20 and agg["overlap_pair"] == [3, 4]
    assert agg["max_overlap_seed"] == 2
    assert (agg["escaped"], agg["escape_sample"], agg["escaped_seed"]) == (3, 7, 3)
    assert (agg["max_step_gain"], agg["gain_step"], agg["max_step_gain_seed"]) == (2e-12, 77, 2)
    assert agg["kind"] == "over budget" and agg["steps"] == 41 and agg["status_seed"] == 3
    assert agg["e_change"] == -0.5 and agg["stages"] == {"steps": 641, "collisions": 6}
    assert rows[1]["kind"] == "ok" and rows[1]["max_overlap"] == 0.0

    report = load_bench("report_contact")
    sec = {"engines": ["libcollide", "box2d3"], "rows": rows, "repeats": 1, "dt": 1 / 60,
           "settings": contact.CONTACT_SETTINGS, "budget_cpu_s": 20.0, "peer_budget_cpu_s": 600.0,
           "scenes": {"mixed30": {"name": "mixed30_s1, mixed30_s2, mixed30_s3", "what": "pile", "bodies": 30,
                                  "steps": 300, "at_rest": False, "seeds": [1, 2, 3]}}}
    cells = [c.strip() for c in report.contact_table(sec)[2].split("|")[1:-1]]
    assert cells[:4] == ["mixed30 (30, 300; seeds 1,2,3)", "150 (over budget: 41/300 steps, seed 3)", "50", "3.75×"]
    assert cells[4:7] == ["50 (s20, seed 2)", "3 (s7, seed 3)", "+2e-12 (s77, seed 2)"]
    notes = "\n".join(report.contact_notes(sec))
    assert "- mixed30, seeds 1 / 2 / 3: libcollide 100 / 150 / 500 (over budget); Box2D v3 50 / 40 / 60; " \
           "libcollide / Box2D v3 2× / 3.75× / 8.33×" in notes


class _FakePool:
    """harness.Pool's run() for run_section: every run finishes two steps at rest, its CPU set by the
    seed (1 for a scene without one; the same for every engine), and the pool records which scene
    each engine ran, in order."""

    def __init__(self) -> None:
        self.ran: list[tuple[str, str]] = []

    def run(self, task: object) -> dict:
        self.ran.append((task.engine, task.scene.name))
        seed = task.scene.meta.get("seed", 1)
        return {"engine": task.engine, "label": task.label, "status": "ok", "steps": 2, "cpu": 1e-4 * seed,
                "states": np.repeat(task.scene.initial_state()[None], 3, axis=0), "stages": {"steps": 2}}


def test_each_engine_runs_the_same_seeds_interleaved(contact: ModuleType) -> None:
    pool = _FakePool()
    sec = contact.run_section(pool, ["mixed30", "stack10"], ("libcollide", "box2d3"), 1, 20.0, lambda _: None,
                              seeds=(4, 7), quick=True)
    assert pool.ran == [("libcollide", "mixed30_s4"), ("box2d3", "mixed30_s4"), ("libcollide", "mixed30_s7"),
                        ("box2d3", "mixed30_s7"), ("libcollide", "stack10_e0"), ("box2d3", "stack10_e0")]
    mixed = [r for r in sec["rows"] if r["key"] == "mixed30"]
    assert [r["seeds"] for r in mixed] == [[4, 7], [4, 7]]
    assert all(math.isclose(r["us_per_step"], 1e6 * 1e-4 * 5.5 / 2) for r in mixed)   # median of 4 and 7
    assert sec["scenes"]["mixed30"]["seeds"] == [4, 7] and "seeds" not in sec["scenes"]["stack10"]
    assert "seeds" not in next(r for r in sec["rows"] if r["key"] == "stack10")
    assert contact.seeds_for("mixed1000", (4, 7), quick=True) == (4,)
    assert contact.seeds_for("mixed1000", (4, 7), quick=False) == (4, 7)
    assert contact.parse_seeds(" 3, 1 ") == (3, 1)
    with pytest.raises(SystemExit):
        contact.parse_seeds("1,1")


def test_end_motion_is_each_bodys_displacement_over_the_last_window() -> None:
    scene = _scene(sc.Box(1.0, 1.0, 0.0, 0.0), sc.Box(1.0, 1.0, 2.0, 0.0), sc.Box(1.0, 1.0, 4.0, 0.0))
    states = np.repeat(scene.initial_state()[None], 5, axis=0)
    states[0, 0, 0] += 7.0                       # before the window: not counted
    states[4, 1, 1] -= 0.003                     # 3 mm down in the window's last sample
    states[4, 2, 0] += 0.004                     # 4 mm along x
    states[4, 2, 3] = 0.5                        # the end speed
    r = m.end_motion(states, 3)
    assert math.isclose(r["end_motion_median"], 0.003, rel_tol=1e-9)
    assert math.isclose(r["end_motion_max"], 0.004, rel_tol=1e-9)
    assert r["end_speed_max"] == 0.5
    assert m.end_motion(states, 5) == {}         # a run no longer than the window has no measure
