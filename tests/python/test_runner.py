"""The headless runner, end to end into a temporary directory."""
from __future__ import annotations

import csv
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import collide
from collide import run as runner

ROOT = Path(__file__).resolve().parents[2]


def read_csv(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_default_scene_to_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    rc = runner.main(["--default", "--blocks", "3", "--gravity", "9.81", "--until", "0.5", "--dt", "0.01",
                      "--out", str(out)])
    assert rc == 0
    assert "50 steps" in capsys.readouterr().out
    traj = read_csv(out / "trajectories.csv")
    assert list(traj[0]) == list(runner.TRAJ_COLUMNS)
    assert len(traj) == 51 * 3  # t = 0 plus 50 samples, 3 blocks (walls are static: not written)
    assert {r["name"] for r in traj} == {"block1", "block2", "block3"}
    last = [r for r in traj if r["name"] == "block1"][-1]
    t = float(last["time"])
    assert t == pytest.approx(0.5, abs=1e-12)
    # block1 falls freely from rest for 0.5 s (it reaches the floor only after ~0.9 s):
    # y = -g t^2 / 2 exactly under RK4, vy = -g t (rounding only)
    assert float(last["y"]) == pytest.approx(-0.5 * 9.81 * t * t, abs=1e-9)
    assert float(last["vy"]) == pytest.approx(-9.81 * t, abs=1e-9)
    energy = read_csv(out / "energy.csv")
    assert len(energy) == 51 and list(energy[0]) == list(runner.ENERGY_COLUMNS)
    # free fall, no contact yet: total energy constant to rounding (RK4 exact for this motion)
    totals = np.array([float(r["total"]) for r in energy])
    np.testing.assert_allclose(totals, totals[0], rtol=1e-9)
    contacts = read_csv(out / "contacts.csv")
    assert contacts == []  # no collision in the first 0.5 s
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == 50 and summary["error"] is None and summary["samples"] == 51
    assert summary["bodies"][:4] == list(collide.WALL_NAMES)


def test_scene_file_to_json_with_collisions(tmp_path: Path) -> None:
    scene = tmp_path / "pair.yaml"
    scene.write_text("world: {gravity: [0, 0]}\n"
                     "walls: {xmin: -6, ymin: -6, xmax: 6, ymax: 6}\n"
                     "bodies:\n"
                     "  - {name: striker, shape: box, width: 1, height: 1, position: [-4, 0], velocity: [2, 0]}\n"
                     "  - {name: c1, shape: box, width: 1, height: 1, position: [0, 0.25]}\n")  # offset: off-centre hit
    out = tmp_path / "json"
    rc = runner.main([str(scene), "--until", "2.5", "--out", str(out), "--format", "json", "--every", "10",
                      "--no-progress"])
    assert rc == 0
    traj = json.loads((out / "trajectories.json").read_text())
    assert len(traj) == (1 + 25) * 2 and set(traj[0]) == set(runner.TRAJ_COLUMNS)
    contacts = json.loads((out / "contacts.json").read_text())
    collisions = [c for c in contacts if c["kind"] == "collision"]
    assert collisions, "the striker reaches the row at t = 1.5 s"
    assert {collisions[0]["body_a"], collisions[0]["body_b"]} == {"striker", "c1"}
    # faces 3 m apart closing at 2 m/s: impact at 1.5 s; the time of impact is found to 1e-10 s,
    # the impact handled at a gap of 1e-7 m (5e-8 s at 2 m/s): 1e-6 s covers both
    assert collisions[0]["time"] == pytest.approx(1.5, abs=1e-6)
    energy = json.loads((out / "energy.json").read_text())
    # e = 1, no damping: kinetic energy 1/2 * 1 * 2^2 = 2 J conserved through the impact (to the
    # engine's impact accuracy, 1e-6 relative as in test_binding_physics)
    assert energy[-1]["total"] == pytest.approx(2.0, rel=1e-6)
    # equal and opposite impulses: momentum 1 kg * 2 m/s conserved to rounding (no wall hit before 2.5 s)
    assert (energy[-1]["px"], energy[-1]["py"]) == pytest.approx((2.0, 0.0), abs=1e-9)
    last = {r["name"]: r for r in traj[-2:]}
    assert last["c1"]["vx"] > 0.5 and last["striker"]["vx"] < 1.5  # momentum went from striker to c1


def test_partial_last_step_reaches_until_exactly(tmp_path: Path) -> None:
    rc = runner.main(["--default", "--until", "0.105", "--dt", "0.01", "--out", str(tmp_path), "--every", "5"])
    assert rc == 0
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["steps"] == 11 and s["final_time"] == pytest.approx(0.105, abs=1e-12)
    times = sorted({float(r["time"]) for r in read_csv(tmp_path / "trajectories.csv")})
    assert times[0] == 0.0 and times[-1] == pytest.approx(0.105, abs=1e-12) and len(times) == 4  # 0, 5, 10, 11


def test_progress_bar_on_long_runs(tmp_path: Path) -> None:
    err = io.StringIO()
    collide_scene = collide.default_scene(blocks=1)
    runner.run(collide_scene, until=1.0, dt=0.001, out=tmp_path, every=100, stderr=err)
    lines = err.getvalue().splitlines()
    assert lines and "100%" in lines[-1] and "[" in lines[-1] and "t=1.000/1.000" in lines[-1]
    assert len(lines) == 11  # not a terminal: one line per 10 %
    quiet = io.StringIO()
    runner.run(collide_scene, until=1.0, dt=0.001, out=tmp_path, every=100, progress=False, stderr=quiet)
    assert quiet.getvalue() == ""


@pytest.mark.parametrize("args,words", [
    (["--until", "1"], "exactly one of SCENE or --default"),
    (["--default", "scene.yaml"], "exactly one of SCENE or --default"),
    (["--default", "--until", "-1"], "--until"),
    (["--default", "--dt", "nan"], "--dt"),
    (["--default", "--dt", "2"], "--dt must be <= 1"),
    (["--default", "--blocks", "9"], "blocks must be an integer from 1 to 6"),
    (["--default", "--format", "xml"], "invalid choice"),
    (["SCENE", "--blocks", "2"], "--blocks applies only with --default"),
    (["missing.yaml"], "missing.yaml: no such file"),
])
def test_bad_input_exits_nonzero_with_a_message(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                args: list[str], words: str) -> None:
    args = [str(tmp_path / "s.yaml") if a == "SCENE" else (str(tmp_path / a) if a.endswith(".yaml") else a)
            for a in args]
    (tmp_path / "s.yaml").write_text("bodies: []\n")
    with pytest.raises(SystemExit) as ex:
        sys.exit(runner.main(args + ["--out", str(tmp_path / "o")]))
    assert ex.value.code == 2
    assert words in capsys.readouterr().err


def test_malformed_scene_file_message(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("bodies:\n  - {name: a, shape: box, width: 1, height: 1, mass: .nan}\n")
    assert runner.main([str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:2: bodies[0].mass: must be a finite number" in err
    assert not (tmp_path / "o").exists()  # nothing written for a rejected scene


def test_module_entry_point_runs_as_a_process(tmp_path: Path) -> None:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT / "ros_pkg"), env.get("PYTHONPATH", "")) if p)
    res = subprocess.run([sys.executable, "-m", "collide.run", "--default", "--until", "0.2", "--out",
                          str(tmp_path)], env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "trajectories.csv").exists() and "20 steps" in res.stdout
    bad = subprocess.run([sys.executable, "-m", "collide.run", "--default", "--until", "x", "--out",
                          str(tmp_path)], env=env, capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and "--until" in bad.stderr


def test_failed_step_writes_what_was_recorded_and_exits_1(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    real_step = collide.World.step

    def failing_step(self: collide.World, dt: float, steps: int = 1) -> None:
        if self.time > 0.045:  # the 6th step fails as a C LC_ERR_NUMERIC would
            raise collide.CollideError(10, "step produced a non-finite state; the step was undone")
        real_step(self, dt, steps)

    monkeypatch.setattr(collide.World, "step", failing_step)
    rc = runner.main(["--default", "--until", "1", "--dt", "0.01", "--out", str(tmp_path), "--no-progress"])
    assert rc == 1
    assert "step 6 at t=0.05 s failed" in capsys.readouterr().err
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["steps"] == 5 and "non-finite" in summary["error"]
    assert len(read_csv(tmp_path / "trajectories.csv")) == 6 * 2  # t = 0 and 5 steps, 2 blocks
