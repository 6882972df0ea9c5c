"""Check the project environment after scripts/setup (run inside the venv with scripts/env.sh).

- rclpy, the common message packages, libcollide_msgs (msgs + srvs) and tf2_msgs import;
- the RIHS01 type hash of our rebuilt tf2_msgs/msg/TFMessage (from the installed type description)
  equals the one in rosbags' ROS 2 Jazzy typestore (so real ROS tools accept our /tf).
Exit code 0 when all holds; prints one line per check.
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path


def installed_type_hash(prefix: Path, type_name: str) -> str:
    """RIHS01 hash of `pkg/msg/Name` from the type description JSON rosidl installed."""
    pkg, kind, name = type_name.split("/")
    data = json.loads((prefix / "share" / pkg / kind / f"{name}.json").read_text(encoding="utf-8"))
    for entry in data["type_hashes"]:
        if entry["type_name"] == type_name:
            return str(entry["hash_string"])
    raise KeyError(type_name)


def jazzy_type_hash(type_name: str) -> str:
    from rosbags.typesys import Stores, get_typestore

    return str(get_typestore(Stores.ROS2_JAZZY).hash_rihs01(type_name))


def main() -> int:
    import rclpy  # noqa: F401
    import geometry_msgs.msg  # noqa: F401
    import std_srvs.srv  # noqa: F401
    import libcollide_msgs.msg as lm
    import libcollide_msgs.srv as ls
    import tf2_msgs.msg as tm

    expected = ["BodyStates", "Contact", "Contacts", "Energy", "ThrusterCommand", "SpringCommand"]
    missing = [n for n in expected if not hasattr(lm, n)]
    missing += [n for n in ("Step", "Spawn", "Kill") if not hasattr(ls, n)]
    if missing or not hasattr(tm, "TFMessage"):
        print(f"check_env: FAIL missing interfaces {missing}", file=sys.stderr)
        return 1
    print("check_env: imports ok (rclpy, libcollide_msgs.msg/.srv, tf2_msgs.msg)")

    prefix = Path(sys.prefix)
    ours = installed_type_hash(prefix, "tf2_msgs/msg/TFMessage")
    ref = jazzy_type_hash("tf2_msgs/msg/TFMessage")
    if ours != ref:
        print(f"check_env: FAIL tf2_msgs/msg/TFMessage hash {ours} != Jazzy {ref}", file=sys.stderr)
        return 1
    print(f"check_env: tf2_msgs/msg/TFMessage {ours} == rosbags Jazzy typestore")

    if os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE") != "LOCALHOST":
        print("check_env: FAIL ROS_AUTOMATIC_DISCOVERY_RANGE is not LOCALHOST", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
