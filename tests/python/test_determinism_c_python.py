"""Determinism between the C API and the Python API: the scripted scene of
tests/c/test_determinism_levels.c (its SCRIPT, printed by the worker with --script) run through
`collide` gives, after every step, exactly the lc_world_state_hash the C program prints (--print),
and two Python runs agree with each other.

The C worker is compiled here from that one file and linked against the same libcollide.so the
binding loads, so the comparison is between the two ways of driving one library (C calls vs cffi +
the Python objects' argument conversion), not between two builds (test_determinism_levels covers
-O0/-O2/-O3). No tolerance: the hashes are of the raw state bits and must be equal.
"""
from __future__ import annotations

import os
import shlex
import subprocess
from pathlib import Path

import pytest

from collide import World, build_ffi

ROOT = Path(__file__).resolve().parents[2]
SOURCE = ROOT / "tests" / "c" / "test_determinism_levels.c"


@pytest.fixture(scope="module")
def c_worker(tmp_path_factory: pytest.TempPathFactory) -> Path:
    lib_dir = build_ffi.library_path().parent
    exe = tmp_path_factory.mktemp("determinism") / "determinism_worker"
    cc = shlex.split(os.environ.get("CC", "cc"))
    cmd = cc + ["-std=c99", "-O2", "-ffp-contract=off", f"-I{ROOT / 'libcollide' / 'include'}",
                f"-I{ROOT / 'tests' / 'c'}", str(SOURCE), f"-L{lib_dir}", "-lcollide", "-lm",
                f"-Wl,-rpath,{lib_dir}", "-o", str(exe)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    assert res.returncode == 0, f"building the C worker failed:\n{' '.join(cmd)}\n{res.stderr}"
    return exe


def _c_output(exe: Path, arg: str) -> str:
    res = subprocess.run([str(exe), arg], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, f"{exe} {arg} failed:\n{res.stdout}\n{res.stderr}"
    return res.stdout


def run_script_python(script: str) -> list[int]:
    """Execute the worker's script through the collide API; the hash after every step."""
    world: World | None = None
    bodies: list = []
    springs: list = []
    hashes: list[int] = []
    for line in script.splitlines():
        cmd, *rest = line.split()
        a = [float(x) for x in rest]
        if cmd == "world":
            world = World(gravity=(a[0], a[1]), damping=a[2], damping_rotation_ratio=a[3])
            continue
        assert world is not None, f"{cmd} before world"
        if cmd == "walls":
            world.add_walls(a[0], a[1], a[2], a[3], thickness=a[4], elasticity=a[5])
        elif cmd == "box":
            bodies.append(world.add_box(a[0], a[1], position=(a[2], a[3]), angle=a[4], velocity=(a[5], a[6]),
                                        angular_velocity=a[7], mass=a[8], elasticity=a[9], friction=a[10]))
        elif cmd == "thrusters":
            bodies[int(a[0])].add_default_thrusters(a[1])
        elif cmd == "spring":
            other = None if a[3] < 0 else bodies[int(a[3])]
            springs.append(world.add_spring(bodies[int(a[0])], (a[1], a[2]), other, (a[4], a[5]),
                                            stiffness=a[6], damping=a[7], rest_length=a[8]))
        elif cmd == "mask":
            bodies[int(a[0])].set_thruster_mask(int(a[1]))
        elif cmd == "target":
            springs[int(a[0])].target = (a[1], a[2])
        elif cmd == "gravity":
            world.set_gravity((a[0], a[1]))
        elif cmd == "velocity":
            bodies[int(a[0])].set_velocity((a[1], a[2]), a[3])
        elif cmd == "simultaneous":
            world.configure(impact_mode="simultaneous")
        elif cmd == "step":
            for _ in range(int(a[0])):
                world.step(a[1])
                hashes.append(world.state_hash())
        else:
            raise AssertionError(f"unknown script command {cmd!r} (update this test with the C file)")
    return hashes


def test_c_and_python_give_identical_state_hashes(c_worker: Path) -> None:
    script = _c_output(c_worker, "--script")
    c_hashes = [int(line.split()[1], 16) for line in _c_output(c_worker, "--print").splitlines()]
    py_hashes = run_script_python(script)
    assert len(c_hashes) == 250, "the C worker ran the whole script"
    assert len(py_hashes) == len(c_hashes), "Python made as many steps as C"
    first = next((k for k, (c, p) in enumerate(zip(c_hashes, py_hashes)) if c != p), None)
    assert first is None, f"C and Python state hashes differ first after step {first}"
    # the hash really tracks the state: it changes every step (time advances)
    assert len(set(py_hashes)) == len(py_hashes)


def test_python_twice_gives_identical_state_hashes(c_worker: Path) -> None:
    script = _c_output(c_worker, "--script")
    assert run_script_python(script) == run_script_python(script)
