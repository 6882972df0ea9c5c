"""Rewrite the build-machine paths baked into the pip ROS wheels' CMake files.

The ros-jazzy-* wheels were built under manylinux's /opt/python/cp311-cp311, so their exported
`*__rosidl_generator_pyExport.cmake` targets point INTERFACE_INCLUDE_DIRECTORIES at
/opt/python/cp311-cp311/include/python3.11 and .../site-packages/numpy/_core/include, which do not
exist here; CMake then refuses to build any interface package that depends on them. Rewrites
them to this interpreter's include dir and site-packages. Idempotent; prints how many files changed.
"""
from __future__ import annotations

import sys
import sysconfig
from pathlib import Path

OLD_ROOT = "/opt/python/cp311-cp311"
OLD_SITE = f"{OLD_ROOT}/lib/python3.11/site-packages"
OLD_INCLUDE = f"{OLD_ROOT}/include/python3.11"


def main() -> int:
    prefix = Path(sys.prefix)
    site = sysconfig.get_paths()["purelib"]
    include = sysconfig.get_paths()["include"]
    if not Path(include, "Python.h").is_file():
        print(f"error: {include}/Python.h missing (install the Python headers, e.g. python3-dev)",
              file=sys.stderr)
        return 1
    changed = 0
    for path in (prefix / "share").rglob("*.cmake"):
        text = path.read_text(encoding="utf-8", errors="surrogateescape")
        if OLD_ROOT not in text:
            continue
        new = text.replace(OLD_SITE, site).replace(OLD_INCLUDE, include)
        if OLD_ROOT in new:
            print(f"error: unknown {OLD_ROOT} path left in {path}", file=sys.stderr)
            return 1
        path.write_text(new, encoding="utf-8", errors="surrogateescape")
        changed += 1
    import numpy  # noqa: E402  (numpy must be installed; its include dir must exist)
    if not Path(numpy.get_include()).is_dir() or not numpy.get_include().startswith(site):
        print(f"error: numpy include {numpy.get_include()} is not under {site}", file=sys.stderr)
        return 1
    print(f"fix_ros_cmake_paths: rewrote {changed} file(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
