"""The aggregation of bench/run --scaling-runs (bench/scaling_runs.py) on hand-made rows.

The page's claims (CPU per body within 1.5x over the range, the ratio to Box2D v3) are read off this
aggregation, so it must take the median of the runs' own ratios (not the ratio of the medians), leave
out runs that did not finish, and splice its block into the page without touching the rest; and a timed
repeat must give both engines the same laps of the same scene (harness.Task.laps), summed."""
from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from bench_module import load_bench

ROOT = Path(__file__).resolve().parents[2]


def _mod() -> ModuleType:
    return load_bench("scaling_runs")


def _row(engine: str, n: int, us: float, status: str = "ok") -> dict[str, Any]:
    return {"engine": engine, "n": n, "us_per_step": us, "status": status}


# three runs at 100 and 1000 bodies; the n = 0 floor rows must not show up as a count
RUNS = [
    [_row("libcollide", 0, 1.0), _row("box2d3", 0, 1.0),
     _row("libcollide", 100, 60.0), _row("box2d3", 100, 50.0),      # ratio 1.2
     _row("libcollide", 1000, 800.0), _row("box2d3", 1000, 400.0)],  # ratio 2.0
    [_row("libcollide", 100, 90.0), _row("box2d3", 100, 100.0),     # ratio 0.9
     _row("libcollide", 1000, 700.0), _row("box2d3", 1000, 1000.0)],  # ratio 0.7
    [_row("libcollide", 100, 40.0), _row("box2d3", 100, 25.0),      # ratio 1.6
     _row("libcollide", 1000, 1e9, "over_budget"), _row("box2d3", 1000, 500.0)],
]


def test_ratio_is_the_median_of_each_runs_own_ratio() -> None:
    sr = _mod()
    agg = {r["n"]: r for r in sr.aggregate(RUNS, "box2d3")}
    assert sorted(agg) == [100, 1000]
    a = agg[100]
    # medians of the columns: 60 and 50, whose quotient (1.2) is also the median ratio here by chance;
    # the ratios are 1.2, 0.9, 1.6
    assert a["ratio"]["median"] == pytest.approx(1.2)
    assert (a["ratio"]["lo"], a["ratio"]["hi"]) == pytest.approx((0.9, 1.6))
    assert a["libcollide"]["median"] == 60.0 and a["box2d3"]["median"] == 50.0
    assert a["libcollide_per_body"]["median"] == pytest.approx(0.6)
    assert (a["libcollide_per_body"]["lo"], a["libcollide_per_body"]["hi"]) == pytest.approx((0.4, 0.9))
    assert a["ratio_runs"] == 3


def test_a_run_that_did_not_finish_is_left_out() -> None:
    sr = _mod()
    b = {r["n"]: r for r in sr.aggregate(RUNS, "box2d3")}[1000]
    # libcollide finished in two runs (800, 700): median 750, not pulled up by the 1e9 of the third
    assert b["libcollide"]["median"] == pytest.approx(750.0) and b["libcollide"]["count"] == 2
    assert b["box2d3"]["median"] == pytest.approx(500.0) and b["box2d3"]["count"] == 3
    # ratios of the two complete runs: 2.0 and 0.7 -> median 1.35; the ratio of the medians would be 1.5
    assert b["ratio_runs"] == 2
    assert b["ratio"]["median"] == pytest.approx(1.35)
    assert (b["ratio"]["lo"], b["ratio"]["hi"]) == pytest.approx((0.7, 2.0))


def test_spread_is_highest_over_lowest_median_per_body() -> None:
    sr = _mod()
    agg = sr.aggregate(RUNS, "box2d3")
    sp, at_lo, at_hi = sr.spread(agg)
    # medians per body: 0.6 µs at 100 bodies, 0.75 at 1000 (the unfinished run left out)
    assert (at_lo, at_hi) == (100, 1000)
    assert sp == pytest.approx(1.25)


def test_no_finished_run_gives_nan_not_an_error() -> None:
    sr = _mod()
    agg = sr.aggregate([[_row("libcollide", 50, math.nan), _row("box2d3", 50, 10.0)]], "box2d3")
    assert math.isnan(agg[0]["libcollide"]["median"]) and agg[0]["ratio_runs"] == 0


def test_splice_replaces_only_the_block() -> None:
    sr = _mod()
    page = f"# Page\n\nbefore\n{sr.BEGIN}\nold table\n{sr.END}\nafter\n"
    out = sr.splice(page, [sr.BEGIN, "new table", sr.END])
    assert out == f"# Page\n\nbefore\n{sr.BEGIN}\nnew table\n{sr.END}\nafter\n"
    with pytest.raises(ValueError):
        sr.splice("# Page without the block\n", [sr.BEGIN, sr.END])


def test_laps_for_gives_each_repeat_the_body_steps_floor() -> None:
    sr = _mod()
    # the fewest laps of 60 steps with n x 60 x laps >= BODY_STEPS, at least one
    for n in (1, 3, 100, 999, 1000, 2000, 5000, 16_667, 20_000, 100_000):
        laps = sr.laps_for(n)
        assert laps >= 1
        assert n * sr.LAP_STEPS * laps >= sr.BODY_STEPS or laps == 1
        if laps > 1:
            assert n * sr.LAP_STEPS * (laps - 1) < sr.BODY_STEPS
    assert [sr.laps_for(n, 1_000_000) for n in (100, 1000, 2000, 5000, 20_000)] == [167, 17, 9, 4, 1]


def _bench_main() -> ModuleType:
    sys.path.insert(0, str(ROOT / "bench"))
    spec = importlib.util.spec_from_file_location("bench_main", ROOT / "bench" / "main.py")
    assert spec is not None and spec.loader is not None
    main = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(main)
    return main


def test_the_scaling_runs_give_both_engines_the_same_laps() -> None:
    main = _bench_main()
    seen: list[Any] = []

    class Probe(main.Bench):   # type: ignore[name-defined,misc]
        def run(self, tasks: list[Any], repeats: int | None = None) -> dict[str, dict[str, Any]]:
            seen.extend(tasks)
            return {}

    b = Probe(main.argparse.Namespace(quick=False, full=False, budget=None, engines="box2d3"))
    sr = _mod()
    b.scaling_rows([100, 20_000], b.scaling_engines(), sr.laps_for)
    laps = {(t.engine, t.scene.name): (t.laps, round(t.scene.duration / t.dt)) for t in seen}
    assert laps[("libcollide", "many100")] == laps[("box2d3", "many100")] == (167, 60)
    assert laps[("libcollide", "many20000")] == laps[("box2d3", "many20000")] == (1, 60)
    seen.clear()
    b.scaling_rows([100], b.scaling_engines())   # the page's scaling section: one lap
    assert {t.laps for t in seen} == {1}


class _FakeEngine:
    """Counts the engines built; each steps 1 ms of CPU per step and moves one body 1 m per step."""
    built = 0

    def __init__(self) -> None:
        _FakeEngine.built += 1
        self.x = 0.0
        self.status = 0
        self.precision = "float64"

    def advance(self, dt: float, n: int) -> float:
        self.x += n
        return 1e-3 * n

    def states(self) -> Any:
        import numpy as np
        return np.array([[self.x, 0.0, 0.0, 0.0, 0.0, 0.0]])

    def stages(self) -> dict[str, Any]:
        return {"steps": int(self.x)}


def test_laps_sum_cpu_and_steps_from_fresh_builds(monkeypatch: pytest.MonkeyPatch) -> None:
    sys.path.insert(0, str(ROOT / "bench"))
    import harness
    fake = ModuleType("engines")
    fake.make = lambda engine, scene, settings: _FakeEngine()  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "engines", fake)
    scenes = _scenes()
    _FakeEngine.built = 0
    r = harness.run_task(harness.Task("fake", scenes.many(10), 1 / 60, laps=3))
    assert _FakeEngine.built == 3
    assert r["status"] == "ok" and r["laps"] == 3
    assert r["steps"] == 180 and r["cpu"] == pytest.approx(0.18)
    # states and stages of the last lap: a fresh build that stepped 60 times, not 180
    assert r["states"][-1][0][0] == 60.0 and r["stages"] == {"steps": 60}
    with pytest.raises(ValueError):
        harness.Task("fake", scenes.many(10), 1 / 60, laps=2, stream=True)


def _scenes() -> ModuleType:
    sys.path.insert(0, str(ROOT / "bench"))
    import scenes
    return scenes


def test_block_names_the_laps_and_the_peers_own_spread() -> None:
    sr = _mod()
    laps = (10, 10, 167, 167, 17, 17)
    rows = [dict(r, laps=k, steps=60 * k) for r, k in zip(RUNS[0], laps)]
    block = sr.section({"peer": "box2d3", "runs": [{"rows": rows, "start": "?", "end": "?"}],
                        "body_steps": 1_000_000}, "img",
                       {"libcollide": "libcollide", "box2d3": "Box2D v3 (pyb2d3)"})
    text = "\n".join(block)
    assert "| 100 | 167 × 60 |" in text and "| 1000 | 17 × 60 |" in text
    assert "n × steps ≥ 1 000 000 body-steps" in text
    # Box2D v3 per body: 0.5 at 100, 0.4 at 1000 -> 1.25x; libcollide: 0.6 and 0.8 -> 1.33x
    assert "1.33x apart" in text and "1.25x apart" in text
