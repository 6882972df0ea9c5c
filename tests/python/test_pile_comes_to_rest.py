"""A dropped pile comes to rest: the contact bench's 100-box mixed pile of seed 5 (bench/scenes.py
mixed_boxes: boxes 0.3-0.8 m, mu 0.5, e 0.3, dropped into a walled box, dt 1/60).

This pile is the case for the pile rule (docs/contact_regime.md, stopping rule; tunables.h
LC_CONTACT_PILE_FLOW_FRACTION): moving at centimetres a second, slower than gravity changes a velocity in
a step, its flow solves stopped at contact_iterations sweeps keep an error the size of its motion, its
friction holds too little and it flows on as a slow avalanche (3-37 cm/s rms up to 11 s). Box2D v3's pile
of the same scene rests by 6 s (bench/repro/pile_rest.py).

Asserted over 12 s: every step returns LC_OK, no step gains more than 1e-9 of the total energy (nothing
drives the scene), and the pile rests: over the last 2 s every body's velocity is exactly 0 and no
coordinate changes by a single bit (docs/contact_regime.md, "Settling and rest")."""
from __future__ import annotations

import sys

import numpy as np

from bench_module import ROOT, load_bench

sys.path.append(str(ROOT / "bench"))   # appended: bench/'s modules never shadow another import
from engines import make  # noqa: E402  (bench/engines: the bench's libcollide adapter builds the scene)

sc = load_bench("scenes")

DT = 1.0 / 60.0
SECONDS = 12
LAST = 2 * 60          # steps: the last 2 s
GAIN_TOL = 1e-9        # the bound on one step's gain in a dissipative scene


def test_mixed_pile_of_seed_5_comes_to_rest() -> None:
    engine = make("libcollide", sc.mixed_boxes(100, seed=5))
    e_prev = engine.world.energy.total
    worst = -np.inf
    last_states = []
    steps = SECONDS * 60
    for k in range(steps):
        engine.advance(DT, 1)   # records a failed step in engine.status
        e = engine.world.energy.total
        worst = max(worst, (e - e_prev) / abs(e_prev))
        e_prev = e
        if k >= steps - LAST - 1:
            last_states.append(engine.states())
    assert engine.status == 0, f"a step failed with status {engine.status}"
    assert worst <= GAIN_TOL, f"a step gained {worst:.3g} of the energy"
    moving = int(np.count_nonzero(np.stack(last_states)[:, :, 3:]))
    changed = int(sum(np.count_nonzero(s[:, :3] != last_states[0][:, :3]) for s in last_states))
    assert moving == 0, f"{moving} velocity components were not 0 over the last 2 s"
    assert changed == 0, f"{changed} coordinates changed over the last 2 s"
