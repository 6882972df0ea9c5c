"""The Python binding and node tests against an AddressSanitizer + UndefinedBehaviorSanitizer build of
libcollide.

A sanitizer build of the library (gcc, -O1 -fsanitize=address,undefined -fno-sanitize-recover=all)
is made once per source state in build/sanitizer-python/ (a hash of the sources is its stamp). The
binding's extension finds libcollide.so.0 through a RUNPATH, so LD_LIBRARY_PATH substitutes the
sanitizer build without rebuilding the extension (docs/contracts.md); the ASan runtime must be the
first library loaded (LD_PRELOAD), and libstdc++ with it, or ASan cannot intercept C++ exceptions
thrown inside the ROS middleware of the node tests. Sanitizer reports of every process (the pytest
child and the nodes it starts) go to files in a fresh directory, which must stay empty.
Leak detection is off: CPython and the ROS libraries keep allocations to exit by design; the C
tests under build-asan/ check libcollide for leaks.
"""
from __future__ import annotations

import fcntl
import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SAN_DIR = ROOT / "build" / "sanitizer-python"
# the generated collide/version.h (world.c includes it) of the CMake build the binding uses
GENERATED_INCLUDE = Path(os.environ.get("LIBCOLLIDE_BUILD_DIR") or ROOT / "build") / "include"
SAN_FLAGS = ["-std=c99", "-O1", "-g", "-fPIC", "-ffp-contract=off", "-fno-omit-frame-pointer",
             "-fsanitize=address,undefined", "-fno-sanitize-recover=all"]
# the tests run under the sanitizers: the binding's own suites (the force callback's too: Python
# called from inside a step) and two node tests (spawn errors go through the C library's validation
# and messages in a separate node process)
SUITES = ["tests/python/test_binding.py", "tests/python/test_binding_physics.py",
          "tests/python/test_force_callback.py",
          "tests/python/test_node.py::test_spawn_bad_numbers_get_the_c_message",
          "tests/python/test_node.py::test_spawn_rejects_bad_shapes_and_overlap"]


def _gcc_file(name: str) -> str:
    out = subprocess.run(["gcc", f"-print-file-name={name}"], capture_output=True, text=True, check=True)
    path = out.stdout.strip()
    assert os.path.isabs(path) and os.path.exists(path), f"gcc has no {name} (apt-get install gcc)"
    return path


def _sources() -> list[Path]:
    version_h = GENERATED_INCLUDE / "collide" / "version.h"
    assert version_h.exists(), f"{version_h} not found: configure the C build first (scripts/setup)"
    return (sorted((ROOT / "libcollide" / "src").glob("*.[ch]")) + sorted((ROOT / "libcollide" / "include").rglob("*.h"))
            + [version_h])


@pytest.fixture(scope="module")
def sanitized_lib() -> Path:
    """Directory holding the sanitizer build libcollide.so.0 (rebuilt when the sources change)."""
    h = hashlib.sha256(" ".join(SAN_FLAGS).encode())
    for src in _sources():
        h.update(src.name.encode())
        h.update(src.read_bytes())
    stamp = h.hexdigest()
    SAN_DIR.mkdir(parents=True, exist_ok=True)
    lib = SAN_DIR / "libcollide.so.0"
    with open(SAN_DIR / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # concurrent test runs share the one build
        stamp_file = SAN_DIR / ".stamp"
        if not lib.exists() or not stamp_file.exists() or stamp_file.read_text() != stamp:
            tmp = SAN_DIR / "libcollide.so.0.tmp"
            cmd = (["nice", "gcc", *SAN_FLAGS, "-shared", "-Wl,-soname,libcollide.so.0",
                    f"-I{ROOT / 'libcollide' / 'include'}", f"-I{GENERATED_INCLUDE}", f"-I{ROOT / 'libcollide' / 'src'}"]
                   + [str(p) for p in sorted((ROOT / "libcollide" / "src").glob("*.c"))] + ["-lm", "-o", str(tmp)])
            res = subprocess.run(cmd, capture_output=True, text=True)
            assert res.returncode == 0, f"sanitizer build failed:\n{res.stderr[-4000:]}"
            os.replace(tmp, lib)
            stamp_file.write_text(stamp)
    return SAN_DIR


def _env(lib_dir: Path, report_dir: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["LD_PRELOAD"] = " ".join([_gcc_file("libasan.so"), _gcc_file("libstdc++.so")])
    env["LD_LIBRARY_PATH"] = os.pathsep.join(p for p in (str(lib_dir), env.get("LD_LIBRARY_PATH", "")) if p)
    env["ASAN_OPTIONS"] = f"detect_leaks=0:halt_on_error=1:abort_on_error=0:log_path={report_dir}/asan"
    env["UBSAN_OPTIONS"] = f"halt_on_error=1:print_stacktrace=1:log_path={report_dir}/ubsan"
    env["LIBCOLLIDE_SANITIZED_CHILD"] = "1"
    return env


def _reports(report_dir: Path) -> str:
    return "\n".join(f"--- {p.name}\n{p.read_text(errors='replace')[:3000]}" for p in sorted(report_dir.iterdir()))


def test_child_loads_the_sanitizer_build(sanitized_lib: Path, tmp_path: Path) -> None:
    probe = ("import collide\n"
             "w = collide.World(); w.add_box(1, 1); w.step(0.01); print('stepped', w.time)\n"
             "maps = open('/proc/self/maps').read()\n"
             "print('\\n'.join(sorted({l.split()[-1] for l in maps.splitlines() if 'libcollide' in l or 'libasan' in l})))\n")
    res = subprocess.run([sys.executable, "-c", probe], env=_env(sanitized_lib, tmp_path),
                         capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    loaded = res.stdout.splitlines()
    assert str(sanitized_lib / "libcollide.so.0") in loaded, f"the sanitizer build was not loaded: {loaded}"
    assert any("libasan" in line for line in loaded), loaded
    assert not any(line.startswith(str(ROOT / "build") + "/libcollide") for line in loaded), loaded
    assert "stepped 0.01" in res.stdout


def test_sanitizer_catches_an_overflow_through_the_binding(sanitized_lib: Path, tmp_path: Path) -> None:
    """Positive control: a C call told a buffer is bigger than it is must be reported by ASan."""
    probe = ("import cffi, collide\n"
             "from collide._ffi import ffi, lib\n"
             "c = cffi.FFI(); c.cdef('void *malloc(size_t);'); libc = c.dlopen(None)\n"
             "w = collide.World(); b = w.add_box(1, 1)\n"
             "buf = libc.malloc(2 * 16)  # room for 2 vertices\n"
             "out = ffi.cast('lc_vec2 *', int(c.cast('uintptr_t', buf)))\n"
             "lib.lc_body_get_world_vertices(w._w, b.id, out, 4)  # claims room for 4\n"
             "print('not caught')\n")
    res = subprocess.run([sys.executable, "-c", probe], env=_env(sanitized_lib, tmp_path),
                         capture_output=True, text=True, cwd=ROOT)
    report = _reports(tmp_path)
    assert res.returncode != 0 and "not caught" not in res.stdout, res.stdout + res.stderr
    assert "heap-buffer-overflow" in report and "lc_body_get_world_vertices" in report, report


def test_binding_and_node_tests_pass_under_asan_ubsan(sanitized_lib: Path, tmp_path: Path) -> None:
    if os.environ.get("LIBCOLLIDE_SANITIZED_CHILD"):
        pytest.fail("test_sanitized_python must not be collected by its own child run")
    report_dir = tmp_path / "reports"
    report_dir.mkdir()
    res = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *SUITES],
                         env=_env(sanitized_lib, report_dir), capture_output=True, text=True, cwd=ROOT,
                         timeout=1800)  # a hang guard only; the run takes well under a minute
    tail = (res.stdout + res.stderr)[-4000:]
    assert res.returncode == 0, f"the tests failed under ASan+UBSan:\n{tail}\n{_reports(report_dir)}"
    assert " passed" in res.stdout and "failed" not in res.stdout, tail
    assert not list(report_dir.iterdir()), f"sanitizer reports:\n{_reports(report_dir)}"
