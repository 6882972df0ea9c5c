"""soak/step_search.py, engine mode: it drives the soak's command mix and notices a step C undoes."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO))

import collide  # noqa: E402
from soak import step_search  # noqa: E402

STEPS = 30_000  # 24 commands, no parameter set or reset: ~0.5 s


def test_the_mix_moves_the_blocks_and_counts_every_step() -> None:
    res = step_search.run_engine(seed=7, steps=STEPS, chunk=10)
    assert res.steps == STEPS and res.undone == 0 and res.failed == 0 and res.events == []
    # commands acted: some step needed force evaluations (thrust and springs on touching blocks)
    assert set(res.max_work) == set(step_search.WORK_KEYS)
    assert res.max_work["force_evaluations"] > 0


def test_an_undone_step_is_counted_and_its_halves_tried(monkeypatch: pytest.MonkeyPatch) -> None:
    real = collide.World.step
    calls = {"n": 0}

    def step(self: Any, dt: float, steps: int = 1) -> None:
        calls["n"] += 1
        if calls["n"] == 1000:  # the 1000th step of dt is refused as C refuses one
            raise collide.CollideError(10, "injected; the step was undone")
        real(self, dt, steps)

    monkeypatch.setattr(collide.World, "step", step)
    res = step_search.run_engine(seed=7, steps=2000, chunk=10)
    assert res.steps == 2000 and res.undone == 1 and res.failed == 0
    assert len(res.events) == 1 and "injected" in res.events[0] and "halves went through" in res.events[0]
    calls["n"] = 0
    assert step_search.main(["--mode", "engine", "--seeds", "7", "--steps", "2000"]) == 1  # exit 1: a step undone
