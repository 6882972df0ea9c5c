"""Session-wide ROS isolation for the Python tests.

Before any test module is imported, this process locks its own ROS_DOMAIN_ID (ros_domain.py) and
exports it together with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, so rclpy in this process and
every subprocess a test starts talk only to each other, never to another test run, a hand run or
the network. Each pytest process (e.g. each xdist worker) gets a different id.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Iterator

import pytest

import ros_domain

ROOT = Path(__file__).resolve().parents[2]

_LOCK_KEY = pytest.StashKey[ros_domain.DomainLock]()


def pytest_configure(config: pytest.Config) -> None:
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.pop("ROS_LOCALHOST_ONLY", None)  # would override the range (deprecated)
    # Works without `source scripts/env.sh` too (e.g. .venv/bin/python -m pytest).
    os.environ.setdefault("AMENT_PREFIX_PATH", sys.prefix)
    ros_pkg = str(ROOT / "ros_pkg")
    if ros_pkg not in sys.path:
        sys.path.insert(0, ros_pkg)
    if ros_pkg not in os.environ.get("PYTHONPATH", "").split(os.pathsep):
        os.environ["PYTHONPATH"] = os.pathsep.join(
            p for p in (ros_pkg, os.environ.get("PYTHONPATH", "")) if p)
    # rosbags' parser dependency (lark) imports deprecated sre_* modules; not our code.
    config.addinivalue_line("filterwarnings", "ignore:module 'sre_:DeprecationWarning")
    lock = ros_domain.acquire()
    config.stash[_LOCK_KEY] = lock
    os.environ["ROS_DOMAIN_ID"] = str(lock.domain_id)


def pytest_unconfigure(config: pytest.Config) -> None:
    lock = config.stash.get(_LOCK_KEY, None)
    if lock is not None:
        lock.release()


def pytest_report_header(config: pytest.Config) -> str:
    return (f"ROS_DOMAIN_ID={os.environ.get('ROS_DOMAIN_ID')} (port-locked), "
            f"ROS_AUTOMATIC_DISCOVERY_RANGE={os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE')}")


@pytest.fixture(scope="session")
def ros_domain_id() -> int:
    """This test process's ROS_DOMAIN_ID (locked for the whole session)."""
    return int(os.environ["ROS_DOMAIN_ID"])


@pytest.fixture(scope="session")
def repo_root() -> Path:
    return ROOT


@pytest.fixture(scope="module")
def ros() -> Iterator[None]:
    """rclpy initialised for one test module (on this process's locked ROS_DOMAIN_ID), shut down after it."""
    import rclpy  # here, not at the top: pytest_configure sets the ROS environment first

    rclpy.init()
    try:
        yield
    finally:
        rclpy.try_shutdown()
