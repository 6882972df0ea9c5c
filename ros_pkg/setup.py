"""The ament_python package collide_ros (package.xml beside this file), built by `colcon build`.

It installs the Python package collide_ros/ with the live view's page, the ament index marker and
package.xml, and one console script per tool into lib/collide_ros/ (setup.cfg), where `ros2 run
collide_ros <tool>` finds it. The binding `collide` in the same directory is not part of it: it
needs the C library, and comes from `pip install` of the repository root (pyproject.toml)."""
import re
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE = "collide_ros"
# the version is written once for this package, in package.xml (which repeats CMake's project(VERSION);
# tests/python/test_versions.py checks that they agree)
VERSION = re.search(r"<version>([^<]+)</version>", (Path(__file__).parent / "package.xml").read_text()).group(1)

setup(
    name=PACKAGE,
    version=VERSION,
    packages=find_packages(include=[PACKAGE, f"{PACKAGE}.*"]),
    package_data={f"{PACKAGE}.view": ["page.html"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
    ],
    install_requires=["setuptools"],
    zip_safe=False,
    description="ROS 2 node and tools of the libcollide 2D rigid-body simulator",
    license="MIT",
    entry_points={
        "console_scripts": [
            f"sim = {PACKAGE}.node:main",
            f"teleop = {PACKAGE}.teleop:main",
            f"recorder = {PACKAGE}.recorder:main",
            f"replay = {PACKAGE}.replay:main",
            f"view = {PACKAGE}.view.server:main",
        ],
    },
)
