"""The tests' ROS_DOMAIN_ID locking: collide_ros.ros_domain, importable as ``ros_domain`` from the tests
(conftest.py imports it before it puts ros_pkg on sys.path, so this module does)."""
from __future__ import annotations

import sys
from pathlib import Path

_ROS_PKG = str(Path(__file__).resolve().parents[2] / "ros_pkg")
if _ROS_PKG not in sys.path:
    sys.path.insert(0, _ROS_PKG)

from collide_ros.ros_domain import (  # noqa: E402
    HAND_RUN_IDS, MAX_ID, MIN_ID, PORT_BASE, DomainLock, acquire, candidate_ids, is_locked, lock_unless_set,
    main, try_lock)

__all__ = ["HAND_RUN_IDS", "MAX_ID", "MIN_ID", "PORT_BASE", "DomainLock", "acquire", "candidate_ids", "is_locked",
           "lock_unless_set", "main", "try_lock"]

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
