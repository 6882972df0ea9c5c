"""The ament packages as a ROS user builds them: `colcon build` (colcon from pip, requirements.txt)
in a workspace whose src/ links to the repository's msg/ and ros_pkg/ builds libcollide_msgs
(ament_cmake + rosidl) and collide_ros (ament_python), and the sim node runs from the install space.

The workspace is build/colcon_ws/, with the toolchain in .venv (the pip ROS wheels; CMAKE_PREFIX_PATH
points there, as /opt/ros/jazzy does for a system install). Its build/ directory is colcon's own
incremental build: a fresh checkout (CI) configures and compiles everything, a rerun recompiles only
what changed, and a changed pip toolchain (.venv/.stamp-pip) starts it over. Its install/ and log/ are
made anew by every run, so every installed file checked here was installed by this run's colcon.
The node then runs with the environment of `. install/setup.sh` and without ros_pkg/ on PYTHONPATH, so
collide_ros and its executables can only come from the install space; the binding `collide` is the
checkout's (a system ROS user pip-installs it from the repository root, as test_wheel_install.py does).

About 70 s of CPU from nothing (6 min of wall time on a 2-core machine at load 15), nearly all of it
rosidl generating and compiling the message package's type support; a few seconds on a rerun."""
from __future__ import annotations

import fcntl
import json
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import rclpy
from rclpy.parameter_client import AsyncParameterClient

from collide_ros.testing import SimClient

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = {"libcollide_msgs", "collide_ros"}
TOOLS = ("sim", "teleop", "recorder", "replay", "view")
COLCON = Path(sys.executable).with_name("colcon")


def _run(cmd: list[str], cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, cwd=cwd, env=env, text=True, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, check=False)


def _build_env() -> dict[str, str]:
    env = dict(os.environ)
    # ament_cmake, rosidl and the message packages libcollide_msgs depends on are in the venv's prefix
    env["CMAKE_PREFIX_PATH"] = os.pathsep.join(p for p in (sys.prefix, env.get("CMAKE_PREFIX_PATH")) if p)
    env.setdefault("AMENT_PREFIX_PATH", sys.prefix)
    env["MAKEFLAGS"] = "-j2"
    return env


def _installed_env(install: Path, binding_dir: Path) -> dict[str, str]:
    """The environment of `. install/setup.sh`, started from this one without the source tree's
    ros_pkg/ on PYTHONPATH and with the binding alone (binding_dir holds only `collide`)."""
    env = dict(os.environ)
    source_tree = str(ROOT / "ros_pkg")
    env["PYTHONPATH"] = os.pathsep.join(
        [str(binding_dir)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                              if p and Path(p).resolve() != Path(source_tree).resolve()])
    out = subprocess.run(["sh", "-c", '. "$1/setup.sh" && env -0', "sh", str(install)], env=env,
                         check=True, stdout=subprocess.PIPE).stdout.decode()
    return dict(item.split("=", 1) for item in out.split("\0") if "=" in item)


class Workspace:
    def __init__(self, root: Path, build_log: str) -> None:
        self.root = root
        self.install = root / "install"
        self.build_log = build_log
        binding_dir = root / "binding"
        if not (binding_dir / "collide").is_symlink():
            binding_dir.mkdir(exist_ok=True)
            (binding_dir / "collide").symlink_to(ROOT / "ros_pkg" / "collide")
        self.env = _installed_env(self.install, binding_dir)


def _fresh_start(root: Path) -> None:
    """Keep colcon's build/ only while it was made with the current pip toolchain; always drop the
    previous run's install/ and log/."""
    stamp = (Path(sys.prefix) / ".stamp-pip").read_text() if (Path(sys.prefix) / ".stamp-pip").is_file() else ""
    mark = root / ".toolchain"
    if not mark.is_file() or mark.read_text() != stamp:
        shutil.rmtree(root, ignore_errors=True)
        root.mkdir(parents=True)
        mark.write_text(stamp)
    for d in ("install", "log"):
        shutil.rmtree(root / d, ignore_errors=True)
    src = root / "src"
    src.mkdir(exist_ok=True)
    # as a user links a checkout into a workspace: msg/ holds libcollide_msgs and tf2_msgs (which
    # carries COLCON_IGNORE), ros_pkg/ is the package collide_ros
    for name, target in (("msg", ROOT / "msg"), ("collide_ros", ROOT / "ros_pkg")):
        if not (src / name).is_symlink():
            (src / name).symlink_to(target)


@pytest.fixture(scope="module")
def ws() -> Iterator[Workspace]:
    root = ROOT / "build" / "colcon_ws"
    root.parent.mkdir(exist_ok=True)
    # one run at a time per checkout (another pytest process would rebuild the install space under us)
    with open(root.parent / ".colcon_ws.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        _fresh_start(root)
        built = _run(["nice", str(COLCON), "build", "--event-handlers", "console_direct+",
                      "--cmake-args", "-DBUILD_TESTING=OFF"], root, _build_env())
        assert built.returncode == 0, built.stdout[-6000:]
        yield Workspace(root, built.stdout)


def test_build_leaves_the_source_tree_alone(ws: Workspace) -> None:
    # colcon builds out of tree: no egg-info, build/, install/ or log/ appears next to the sources
    stray = [str(p) for d in (ROOT / "ros_pkg", ROOT / "msg" / "libcollide_msgs")
             for p in d.iterdir() if p.name.endswith(".egg-info") or p.name in ("build", "install", "log")]
    assert stray == []


def test_colcon_builds_the_two_packages(ws: Workspace) -> None:
    # exactly these two: msg/tf2_msgs is skipped (COLCON_IGNORE), ros_pkg/ is one package
    assert {p.name for p in ws.install.iterdir() if p.is_dir()} == PACKAGES
    for pkg in PACKAGES:
        assert f"Finished <<< {pkg}" in ws.build_log, ws.build_log[-3000:]


def test_install_space_has_both_packages(ws: Workspace) -> None:
    msgs = ws.install / "libcollide_msgs"
    share = msgs / "share" / "libcollide_msgs"
    assert (share / "package.xml").is_file()
    for name in ("BodyStates", "Contacts", "Energy", "SpringCommand", "ThrusterCommand"):
        assert (share / "msg" / f"{name}.json").is_file(), name  # the type description with its hash
    for name in ("Step", "Spawn", "Kill"):
        assert (share / "srv" / f"{name}.srv").is_file(), name
    assert (msgs / "share/ament_index/resource_index/rosidl_interfaces/libcollide_msgs").is_file()
    ros = ws.install / "collide_ros"
    assert (ros / "share/ament_index/resource_index/packages/collide_ros").is_file()
    assert (ros / "share/collide_ros/package.xml").is_file()
    for tool in TOOLS:
        exe = ros / "lib" / "collide_ros" / tool
        assert exe.is_file() and os.access(exe, os.X_OK), tool
        # the interpreter colcon ran with (the venv's), which has the binding's dependencies
        assert exe.read_text().startswith(f"#!{Path(sys.prefix) / 'bin' / 'python'}"), exe.read_text()[:200]
    pages = list(ros.glob("lib/python3*/site-packages/collide_ros/view/page.html"))
    assert len(pages) == 1, "the live view's page is installed with the package"
    assert not list(ros.glob("lib/python3*/site-packages/collide")), "the binding is not in collide_ros"


PROBE = r"""
import json, sys
from importlib.metadata import distribution
from ament_index_python.packages import get_package_prefix, get_package_share_directory
import collide, collide_ros, libcollide_msgs.msg, tf2_msgs.msg
scripts = {ep.name: callable(ep.load()) for ep in distribution("collide_ros").entry_points
           if ep.group == "console_scripts"}
print(json.dumps({
    "scripts": scripts,
    "collide_ros": collide_ros.__file__, "libcollide_msgs": libcollide_msgs.msg.__file__,
    "collide": collide.__file__, "tf2_msgs": tf2_msgs.msg.__file__,
    "prefix": get_package_prefix("collide_ros"),
    "msgs_share": get_package_share_directory("libcollide_msgs"),
}))
"""


def test_python_finds_the_packages_in_the_install_space(ws: Workspace) -> None:
    r = subprocess.run([sys.executable, "-c", PROBE], cwd=ws.root, env=ws.env, text=True,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, check=False)
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    install = str(ws.install)
    assert got["collide_ros"].startswith(f"{install}/collide_ros/lib/"), got
    assert got["libcollide_msgs"].startswith(f"{install}/libcollide_msgs/lib/"), got
    assert got["prefix"] == f"{install}/collide_ros", got
    # every executable's entry point imports and names a function
    assert got["scripts"] == {tool: True for tool in TOOLS}, got
    assert got["msgs_share"] == f"{install}/libcollide_msgs/share/libcollide_msgs", got
    # the binding comes from outside the workspace; tf2_msgs from the underlay (here the venv)
    assert not got["collide"].startswith(install) and not got["tf2_msgs"].startswith(install), got


def test_sim_runs_from_the_install_space(ws: Workspace) -> None:
    # what `ros2 run collide_ros sim` executes: <prefix of collide_ros>/lib/collide_ros/sim
    exe = ws.install / "collide_ros" / "lib" / "collide_ros" / "sim"
    log = ws.root / "sim.log"
    ctx = rclpy.Context()
    rclpy.init(context=ctx)
    client = SimClient(context=ctx, watch=("bodies/states",))
    with open(log, "wb") as out:
        proc = subprocess.Popen([str(exe), "--ros-args", "-p", "blocks:=3"], cwd=ws.root,
                                env={**ws.env, "PYTHONUNBUFFERED": "1", "RCUTILS_COLORIZED_OUTPUT": "0"},
                                stdout=out, stderr=subprocess.STDOUT)
    try:
        first = client.fresh("bodies/states", timeout=60.0)
        assert first is not None, log.read_text()
        later = client.fresh("bodies/states", n=5, timeout=30.0)
        assert later is not None, log.read_text()
        # what `ros2 param describe /sim blocks` asks (docs/ros_interface.md gives it for pip only)
        params = AsyncParameterClient(client.node, "/sim")
        assert params.wait_for_services(timeout_sec=20.0), log.read_text()
        future = params.describe_parameters(["blocks"])
        client.wait_for(future.done, timeout=20.0)
        assert future.done(), log.read_text()
        described = future.result().descriptors[0]
    finally:
        client.close()
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(20.0)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait(20.0)
        rclpy.shutdown(context=ctx)
    assert code == 0, log.read_text()
    # blocks:=3 reached the node: the default scene's walls and three blocks, stepping forward
    names = list(first.names)
    assert [n for n in names if n.startswith("block")] == ["block1", "block2", "block3"], names
    t0 = first.header.stamp.sec + 1e-9 * first.header.stamp.nanosec
    t1 = later.header.stamp.sec + 1e-9 * later.header.stamp.nanosec
    assert t1 > t0, (t0, t1)
    assert described.name == "blocks" and "default scene" in described.description, described
    assert (described.integer_range[0].from_value, described.integer_range[0].to_value) == (1, 6), described
