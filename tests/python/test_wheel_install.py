"""The Python package as a user installs it, without the project's environment or ROS.

`pip wheel . --no-build-isolation` builds a wheel with pyproject.toml's backend (scikit-build-core
driving the top-level CMake, pinned in requirements.txt so scripts/setup installs it into .venv); a
fresh `python -m venv` (no system site-packages) gets it, with numpy, cffi and PyYAML from the
pinned wheels scripts/setup keeps in .venv/wheelhouse (--no-index: nothing comes from the network).
Every command in that venv runs with a minimal environment: no PYTHONPATH, LD_LIBRARY_PATH,
LIBCOLLIDE_BUILD_DIR or ROS variables, so only what the wheel installed can be found. There,
`import collide` loads the package's own extension and libcollide.so, a body in free flight follows
the closed form, the runner writes its output, and the binding's suites pass.

About 40 s on a loaded 2-core machine, most of it compiling the library for the wheel."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WHEELHOUSE = Path(sys.prefix) / "wheelhouse"
# the binding's suites, run against the installed package; the two tests of test_binding.py that
# check the source checkout's extension build (python -m collide.build_ffi) do not apply to a wheel
BINDING_SUITES = ["test_binding.py", "test_binding_physics.py", "test_body_props.py", "test_query.py",
                  "test_events.py", "test_snapshot.py", "test_force_callback.py"]
SOURCE_BUILD_TESTS = ["test_cdef_is_generated_from_the_public_header",
                      "test_build_is_idempotent_and_reports_up_to_date"]

# Free flight under gravity: RK4 is exact (to rounding) for constant forces, so after 100 steps
# of 0.01 s the state and the energy terms equal the closed form to far below 1e-9.
SMOKE = r"""
import json, sys
import collide
from collide import build_ffi

w = collide.World(gravity=(0.0, -9.81))
box = w.add_box(1.0, 0.5, mass=2.0, position=(1.0, 2.0), velocity=(2.0, 5.0), angular_velocity=0.7,
                name="box")
e0 = w.energy
w.step(0.01, steps=100)
e = w.energy
with open("/proc/self/maps") as fh:
    mapped = sorted({ln.split()[-1] for ln in fh if "collide" in ln.split()[-1]})
print(json.dumps({
    "file": collide.__file__, "version": collide.version(), "time": w.time,
    "state": w.state[box.index].tolist(), "inertia": box.inertia,
    "energy0": e0.total, "energy": [e.translational, e.rotational, e.gravitational, e.total],
    "source_checkout": build_ffi.in_source_checkout(), "mapped": mapped,
    "ros_modules": sorted(m for m in sys.modules if m.split(".")[0] in ("rclpy", "collide_ros")),
}))
"""


def _cmake_version() -> str:
    m = re.search(r"project\(libcollide VERSION ([0-9]+\.[0-9]+\.[0-9]+)", (ROOT / "CMakeLists.txt").read_text())
    assert m, "no project(libcollide VERSION x.y.z) in CMakeLists.txt"
    return m.group(1)


def _run(cmd: list[str], env: dict[str, str] | None = None, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    res = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    assert res.returncode == 0, (f"{' '.join(cmd)} exited {res.returncode}\n"
                                 f"stdout:\n{res.stdout[-4000:]}\nstderr:\n{res.stderr[-4000:]}")
    return res


def _clean_env(venv: Path, home: Path) -> dict[str, str]:
    """What a user's shell with this venv activated has: no project or ROS variables."""
    return {"PATH": f"{venv / 'bin'}:/usr/bin:/bin", "HOME": str(home), "LANG": "C.UTF-8",
            "VIRTUAL_ENV": str(venv), "PIP_DISABLE_PIP_VERSION_CHECK": "1", "PIP_NO_INPUT": "1"}


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict[str, str]]:
    """(venv, wheel, env): the package's wheel built from this checkout and installed into a fresh venv."""
    assert WHEELHOUSE.is_dir() and any(WHEELHOUSE.glob("numpy-*.whl")), \
        f"{WHEELHOUSE} (pinned wheels for the clean venv) is missing: run scripts/setup"
    tmp = tmp_path_factory.mktemp("wheel")
    dist = tmp / "dist"
    # the pinned backend in .venv; --no-index: a build that wanted anything from an index fails here
    _run(["nice", sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "--no-build-isolation",
          "--no-index", "-q", "-w", str(dist)], cwd=tmp)
    wheels = sorted(dist.glob("libcollide-*.whl"))
    assert len(wheels) == 1, wheels
    venv = tmp / "venv"
    home = tmp / "home"
    home.mkdir()
    env = _clean_env(venv, home)
    # the base interpreter, not .venv's: the new venv must not see the project's site-packages.
    # Without pip of its own (ensurepip would take half a minute on a loaded machine): .venv's pip
    # installs into it with --python, resolving for the new venv's interpreter and site-packages.
    base = getattr(sys, "_base_executable", sys.executable)
    _run([base, "-m", "venv", "--without-pip", str(venv)], env=env, cwd=tmp)
    # the clean environment here too (so the new venv's interpreter, which pip runs, has none of the
    # project's paths), plus the flag that spares .venv's python the ROS wheels' re-exec hook
    _run([sys.executable, "-m", "pip", "--python", str(venv / "bin" / "python"), "install", "-q", "--no-index",
          "--find-links", str(WHEELHOUSE), str(wheels[0]), "pytest"],
         env={**env, "_ROS_WHEELS_BOOTSTRAP_COMPLETE": "1"}, cwd=tmp)
    return venv, wheels[0], env


def test_build_requirements_are_pinned_where_setup_installs_them() -> None:
    """--no-build-isolation builds offline only with pyproject's backend in .venv: each build
    requirement is pinned, with the same pin in requirements.txt and constraints.txt."""
    build_reqs = tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"]
    assert build_reqs and all("==" in r for r in build_reqs), build_reqs
    for name in ("requirements.txt", "constraints.txt"):
        pins = {ln.split("#")[0].strip().lower() for ln in (ROOT / name).read_text().splitlines()}
        missing = [r for r in build_reqs if r.lower() not in pins]
        assert not missing, f"{name} does not pin {missing}"


def test_wheel_is_named_for_cmake_version_and_python(installed: tuple[Path, Path, dict[str, str]]) -> None:
    _, wheel, _ = installed
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    assert wheel.name.startswith(f"libcollide-{_cmake_version()}-{tag}-{tag}-linux_"), wheel.name


def test_installed_package_runs_from_the_venv_alone(installed: tuple[Path, Path, dict[str, str]]) -> None:
    venv, _, env = installed
    out = _run([str(venv / "bin" / "python"), "-c", SMOKE], env=env, cwd=venv.parent)
    r = json.loads(out.stdout.strip().splitlines()[-1])
    site = (venv / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages").resolve()
    pkg = site / "collide"
    # the package, its extension and its library all come from the venv
    assert Path(r["file"]).resolve() == pkg / "__init__.py", r["file"]
    assert not r["source_checkout"]
    mapped = {Path(p).resolve() for p in r["mapped"]}
    assert pkg / "libcollide.so.0" in mapped, r["mapped"]
    assert any(p.parent == pkg and p.name.startswith("_collide_cffi.") for p in mapped), r["mapped"]
    assert all(p.parent == pkg for p in mapped), r["mapped"]
    assert r["ros_modules"] == []
    assert r["version"] == _cmake_version()

    g, m, t = 9.81, 2.0, 1.0
    inertia = m * (1.0 ** 2 + 0.5 ** 2) / 12.0  # solid 1 m x 0.5 m box about its centre
    assert r["time"] == pytest.approx(t, abs=1e-12)
    assert r["inertia"] == pytest.approx(inertia, rel=1e-12)
    x, y, a, vx, vy, om = r["state"]
    y_t, vy_t = 2.0 + 5.0 * t - 0.5 * g * t * t, 5.0 - g * t
    assert (x, y, a) == pytest.approx((1.0 + 2.0 * t, y_t, 0.7 * t), abs=1e-9)
    assert (vx, vy, om) == pytest.approx((2.0, vy_t, 0.7), abs=1e-9)
    translational, rotational, gravitational, total = r["energy"]
    assert translational == pytest.approx(0.5 * m * (2.0 ** 2 + vy_t ** 2), abs=1e-9)
    assert rotational == pytest.approx(0.5 * inertia * 0.7 ** 2, abs=1e-9)
    assert gravitational == pytest.approx(m * g * y_t, abs=1e-9)
    assert total == pytest.approx(r["energy0"], abs=1e-9)  # free flight conserves energy


def test_installed_runner_writes_its_output(installed: tuple[Path, Path, dict[str, str]]) -> None:
    venv, _, env = installed
    out_dir = venv.parent / "run"
    _run([str(venv / "bin" / "python"), "-m", "collide.run", "--default", "--until", "0.5", "--out", str(out_dir),
          "--no-progress"], env=env, cwd=venv.parent)
    summary = json.loads((out_dir / "summary.json").read_text())
    assert summary["steps"] == 50 and summary["bodies"][-2:] == ["block1", "block2"]
    assert (out_dir / "trajectories.csv").stat().st_size > 0


def test_binding_suites_pass_against_the_installed_package(installed: tuple[Path, Path, dict[str, str]]) -> None:
    venv, _, env = installed
    # --noconftest: tests/python/conftest.py would put ros_pkg/ on the path (and lock a ROS domain)
    suites = [str(ROOT / "tests" / "python" / s) for s in BINDING_SUITES]
    res = subprocess.run([str(venv / "bin" / "python"), "-m", "pytest", "-q", "-p", "no:cacheprovider", "--noconftest",
                          "--rootdir", str(venv.parent), "-k", " and ".join(f"not {t}" for t in SOURCE_BUILD_TESTS),
                          *suites], env={**env, "PYTHONDONTWRITEBYTECODE": "1"},  # no .pyc into tests/python
                         cwd=venv.parent, capture_output=True, text=True)
    tail = res.stdout.strip().splitlines()[-1] if res.stdout.strip() else ""
    assert res.returncode == 0, f"binding suites failed against the wheel:\n{res.stdout[-6000:]}\n{res.stderr[-2000:]}"
    m = re.search(r"(\d+) passed, (\d+) deselected", tail)
    assert m and int(m.group(1)) >= 50 and int(m.group(2)) == len(SOURCE_BUILD_TESTS), tail
