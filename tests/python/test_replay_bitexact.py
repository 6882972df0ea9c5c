"""Replay determinism: a bag recorded while the demo driver ran the node live (thrusters, a
dragged spring, a torque, cmd_vel) is replayed from the snapshot at its start; every recorded state
comes back bit for bit. A control run that applies one command a single step late must not match."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from collide_ros.recorder import make_typestore
from collide_ros.replay import Command, iter_commands, iter_states, replay

GIVE_UP = 300.0  # s: guards against a hang only


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("replay")
    # 6.5 s of the demo script: thrusters, a push, the spring drag from 3 s, torque from 4 s, cmd_vel 5-6 s
    r = subprocess.run([sys.executable, "-m", "collide_ros.demo", "--out", str(out), "--duration", "6.5",
                        "--no-gif"], capture_output=True, text=True, timeout=GIVE_UP, env=dict(os.environ))
    assert r.returncode == 0, r.stdout + r.stderr
    return out / "demo_bag"


def _commands(bag: Path) -> list[Command]:
    return list(iter_commands(bag, make_typestore()))


def test_recording_has_every_command_kind(bag: Path) -> None:
    kinds = {c.topic for c in _commands(bag)}
    assert {"thrusters", "spring", "block1/thrust", "block2/thrust", "cmd_vel"} <= kinds
    assert sum(1 for _ in iter_states(bag, make_typestore())) > 300


def test_replay_is_bit_identical(bag: Path, ros: None) -> None:
    res = replay(bag)
    # byte for byte: the CDR of every recorded state from the snapshot on
    assert res["ok"], json.dumps(res)
    assert res["identical"] == res["compared"] == res["recorded"] - res["skipped"] > 300
    assert res["missing"] == 0 and res["max_abs_diff"] == 0.0 and res["commands"] > 50


def test_one_step_late_command_is_detected(bag: Path, ros: None) -> None:
    # the snapshot is taken before the driver's first command: every command is replayed, index i too
    cmds = _commands(bag)
    # a spring command followed by a command at a later step, so delaying it keeps the order
    i = next(k for k, c in enumerate(cmds[:-1])
             if c.topic == "spring" and cmds[k + 1].stamp > c.stamp + 1_000_000)
    res = replay(bag, delay_command=i)
    assert not res["ok"] and res["identical"] < res["compared"]
    # everything before the delayed command still matches: the first mismatch is after it
    assert res["first_mismatch_s"] is not None and res["first_mismatch_s"] > cmds[i].stamp * 1e-9
    assert res["max_abs_diff"] > 0.0
