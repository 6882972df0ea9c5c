"""One version: CMake's project(VERSION) is the library's, the wheel's and lc_version()'s; the two ROS
packages must repeat it in their package.xml (ament reads it there), and collide_ros's setup.py takes
it from its package.xml."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import collide

ROOT = Path(__file__).resolve().parents[2]


def cmake_version() -> str:
    m = re.search(r"project\(libcollide VERSION ([0-9]+\.[0-9]+\.[0-9]+)", (ROOT / "CMakeLists.txt").read_text())
    assert m, "no project(libcollide VERSION x.y.z) in CMakeLists.txt"
    return m.group(1)


def package_xml_version(path: Path) -> str:
    found = re.findall(r"<version>([^<]+)</version>", path.read_text())
    assert len(found) == 1, f"{path}: {found}"
    return found[0]


def test_library_reports_the_cmake_version() -> None:
    assert collide.version() == cmake_version()


def test_ros_packages_repeat_the_cmake_version() -> None:
    for xml in (ROOT / "ros_pkg" / "package.xml", ROOT / "msg" / "libcollide_msgs" / "package.xml"):
        assert package_xml_version(xml) == cmake_version(), f"{xml.relative_to(ROOT)} disagrees with CMakeLists.txt"


def test_setup_py_takes_its_version_from_package_xml() -> None:
    setup_py = ROOT / "ros_pkg" / "setup.py"
    assert not re.search(r"version\s*=\s*[\"']", setup_py.read_text()), "a literal version in ros_pkg/setup.py"
    r = subprocess.run([sys.executable, "setup.py", "--version"], cwd=setup_py.parent, capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == cmake_version()
