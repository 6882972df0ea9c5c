"""The main job end to end, as scripts/demo runs it: node + recorder + scripted driver over ROS,
bag, GIF, summary, and the replay check of the recorded bag."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from collide_ros.demo import COAST_FROM, cue
from collide_ros.render import GREEN, COLLISION

GIVE_UP = 600.0  # s: guards against a hang only


def test_cue_script() -> None:
    # pure script: F on block1 first, the spring grabbed from 3 s to 6 s, nothing in the coast
    assert cue(0.1).firing["block1"][1] and cue(0.1).spring is None
    assert cue(4.0, (1.0, 2.0)).spring is not None and cue(4.5).torque != 0.0
    c = cue(COAST_FROM + 0.01)
    assert not any(any(f) for f in c.firing.values()) and c.spring is None and c.torque == 0.0


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    out = tmp_path_factory.mktemp("demo")
    r = subprocess.run([sys.executable, "-m", "collide_ros.demo", "--out", str(out), "--replay"],
                       capture_output=True, text=True, timeout=GIVE_UP, env=dict(os.environ))
    assert r.returncode == 0, r.stdout + r.stderr
    return out, r.stdout


def test_summary(demo: tuple[Path, str]) -> None:
    out, stdout = demo
    for key in ("energy drift:", "real-time factor:", "bag:", "GIF:", "replay:"):
        assert key in stdout
    assert "demo: live view: open http://127.0.0.1:" in stdout  # the live view ran next to the node
    s = json.loads((out / "demo_summary.json").read_text())
    # e = 1, no damping, no gravity and no command in the coast: the engine's event-accurate
    # impacts keep energy to round-off (~1e-15); 1e-9 is the project's target
    assert s["energy_drift_rel"] < 1e-9 and s["coast_seconds"] > 2.0 and s["coast_energy_J"] > 0.1
    assert s["real_time_factor"] > 0.0 and s["sim_seconds"] > 9.9
    # the push sends block1 across the 12 m box at > 1 m/s: at least one impact in 10 s, reported
    # on `contacts` and visible as a velocity jump in the recorded states
    assert s["impacts_in_states"] >= 1 and s["impact_contacts"] >= 1
    # every state from the snapshot the recorder asked for at its start (the ones before it are skipped)
    r = s["replay"]
    assert r["ok"] and r["identical"] == r["compared"] == r["recorded"] - r["skipped"] > 900


def test_bag(demo: tuple[Path, str]) -> None:
    out, _ = demo
    meta = yaml.safe_load((out / "demo_bag" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["version"] == 9 and meta["storage_identifier"] == "mcap"
    counts = {t["topic_metadata"]["name"]: t["message_count"] for t in meta["topics_with_message_count"]}
    # 10 s of 100 Hz states at least, and the commands with their echoes (same count: all accepted)
    assert counts["/bodies/states"] > 1000
    for t in ("/thrusters", "/spring", "/block1/thrust", "/block2/thrust", "/cmd_vel"):
        assert counts[t] > 0 and counts[t] == counts["/applied" + t]


def test_gif(demo: tuple[Path, str]) -> None:
    out, _ = demo
    im = Image.open(out / "demo.gif")
    assert im.n_frames > 200 and im.size == (480, 592)  # >= 10 s at 20 frames/s
    green = red = 0
    for k in range(im.n_frames):
        im.seek(k)
        # the arena below the energy bar graph (112 px); GIF palette quantisation moves colours
        # by up to ~30 per channel, far less than the distance between the drawing colours
        a = np.asarray(im.convert("RGB"))[112:].reshape(-1, 3).astype(int)
        green += int(np.any(np.all(np.abs(a - GREEN) <= 30, axis=1)))   # block1 is drawn green
        red += int(np.any(np.all(np.abs(a - COLLISION) <= 30, axis=1)))  # an impact dot
    assert green == im.n_frames
    assert red >= 4  # at least one impact, shown for 0.2 s = 4 frames
