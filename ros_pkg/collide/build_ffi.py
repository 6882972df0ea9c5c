"""Build the cffi extension `collide._collide_cffi` (API mode) against the public C header.

The cdef is not hand-written: it is the output of the C preprocessor run on
``libcollide/include/collide/collide.h`` (system headers replaced by empty shims, since cffi
already knows ``size_t``/``uint32_t``/...), plus one ``#define NAME ...`` line per integer
constant the headers define, whose value cffi then reads from the compiler. The one hand-written
part declares the ``extern "Python"`` functions the force callback calls (``EXTERN_PYTHON``).

``python -m collide.build_ffi`` is idempotent: it rebuilds only when the headers, this file, the
Python ABI or the library directory changed (a fingerprint of those is embedded in the extension),
so it is fast when up to date. Environment: ``LIBCOLLIDE_BUILD_DIR`` (as scripts/env.sh sets it;
default ``<repo>/build``) holds ``libcollide.so``; ``CC`` picks the preprocessor (default ``cc``).

This is the source checkout's way. A wheel (``pip install .``, pyproject.toml) compiles the same
extension with CMake from the C source that ``--emit-c`` writes, and ships it with ``libcollide.so``
inside the installed package, which then has nothing to build.
"""
from __future__ import annotations

import argparse
import contextlib
import fcntl
import hashlib
import importlib.machinery
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path
from typing import Iterator

PACKAGE_DIR = Path(__file__).resolve().parent
REPO_ROOT = PACKAGE_DIR.parents[1]
INCLUDE_DIR = REPO_ROOT / "libcollide" / "include"
HEADER = INCLUDE_DIR / "collide" / "collide.h"
MODULE_NAME = "collide._collide_cffi"
_SHIMMED = ("stddef.h", "stdint.h")
_GUARD = re.compile(r"^COLLIDE_\w+_H$")
_MARK = "collide-cffi-fingerprint:"


class BuildError(RuntimeError):
    """The extension could not be built (missing library, compiler failure, ...)."""


def in_source_checkout() -> bool:
    """True when this package is the one in a checkout's ros_pkg/ (next to the C headers); False for
    an installed wheel, whose extension and library were built with it."""
    return PACKAGE_DIR.parent.name == "ros_pkg" and HEADER.is_file()


def build_dir() -> Path:
    return Path(os.environ.get("LIBCOLLIDE_BUILD_DIR") or REPO_ROOT / "build").resolve()


def library_path() -> Path:
    return build_dir() / "libcollide.so"


def extension_path() -> Path:
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    return PACKAGE_DIR / ("_collide_cffi" + suffix)


def work_dir() -> Path:
    return build_dir() / "cffi"


def _headers() -> list[Path]:
    return sorted((INCLUDE_DIR / "collide").glob("*.h"))


def _fingerprint() -> str:
    h = hashlib.sha256()
    for path in _headers() + [Path(__file__).resolve()]:
        h.update(path.name.encode())
        h.update(path.read_bytes())
    h.update(sysconfig.get_config_var("SOABI").encode() if sysconfig.get_config_var("SOABI") else b"")
    h.update(str(build_dir()).encode())
    return h.hexdigest()


def _cc() -> list[str]:
    return os.environ.get("CC", "cc").split()


def _preprocess(args: list[str], shim: Path) -> str:
    cmd = _cc() + ["-E", "-P", "-nostdinc", "-I", str(shim), "-I", str(INCLUDE_DIR)] + args + [str(HEADER)]
    try:
        res = subprocess.run(cmd, check=True, capture_output=True, text=True)
    except FileNotFoundError as exc:
        raise BuildError(f"C compiler not found ({_cc()[0]}); set CC") from exc
    except subprocess.CalledProcessError as exc:
        raise BuildError(f"preprocessing {HEADER} failed:\n{exc.stderr}") from exc
    return res.stdout


def generate_cdef() -> str:
    """The cdef text: preprocessed public header + the integer #define constants."""
    with tempfile.TemporaryDirectory(prefix="collide_cdef_") as tmp:
        shim = Path(tmp)
        for name in _SHIMMED:
            (shim / name).write_text("/* empty: cffi knows the standard integer types */\n")
        body = _preprocess([], shim)
        macros = _preprocess(["-dM"], shim)
    consts = []
    for line in macros.splitlines():
        m = re.match(r"#define\s+(LC_\w+)\s+(.+)$", line)
        if m and not _GUARD.match(m.group(1)) and re.fullmatch(r"\(?-?(0[xX][0-9a-fA-F]+|\d+)[uUlL]*\)?", m.group(2).strip()):
            consts.append(f"#define {m.group(1)} ...")
    # Drop blank lines and the extern "C" remnants (none survive -E in C, but be safe).
    lines = [ln for ln in body.splitlines() if ln.strip()]
    return "\n".join(sorted(consts) + lines) + "\n"


# The C entry points of the binding's force callbacks (collide/force.py defines them with
# @ffi.def_extern): cffi compiles them into the extension, so no libffi closure is made at run time.
EXTERN_PYTHON = """
extern "Python" int collide_force_callback(void *, const lc_force_query *, double *);
extern "Python" int collide_potential_callback(void *, const lc_force_query *, double *);
"""


def make_ffibuilder():  # -> cffi.FFI (imported lazily so `import collide` needs no setuptools)
    import cffi

    lib_dir = build_dir()
    ffibuilder = cffi.FFI()
    ffibuilder.cdef(generate_cdef())
    ffibuilder.cdef(EXTERN_PYTHON)
    rel = os.path.relpath(lib_dir, PACKAGE_DIR)
    # The fingerprint of what the extension was built from lives in the binary itself, so a check
    # never trusts a stamp that could belong to another build directory.
    ffibuilder.set_source(
        MODULE_NAME,
        '#include "collide/collide.h"\n'
        f'__attribute__((used)) static const char collide_cffi_fingerprint[] = "{_MARK}{_fingerprint()}";\n',
        include_dirs=[str(INCLUDE_DIR)],
        library_dirs=[str(lib_dir)],
        libraries=["collide"],
        # Absolute rpath for in-tree use, $ORIGIN-relative so a moved checkout still works.
        # It is a RUNPATH, so LD_LIBRARY_PATH can swap in e.g. a sanitizer build.
        extra_link_args=[f"-Wl,-rpath,{lib_dir}", f"-Wl,-rpath,$ORIGIN/{rel}", "-Wl,--enable-new-dtags"],
        extra_compile_args=["-ffp-contract=off"],
    )
    return ffibuilder


def write_c_source(target: Path) -> Path:
    """Write the extension's C source to target, for a build that compiles and links it itself (the
    wheel's CMake, cmake/python_package.cmake); the file is rewritten only when its text changes."""
    import cffi

    ffibuilder = cffi.FFI()
    ffibuilder.cdef(generate_cdef())
    ffibuilder.cdef(EXTERN_PYTHON)
    ffibuilder.set_source(MODULE_NAME, '#include "collide/collide.h"\n')
    target.parent.mkdir(parents=True, exist_ok=True)
    ffibuilder.emit_c_code(str(target))
    return target


@contextlib.contextmanager
def _lock() -> Iterator[None]:
    work_dir().mkdir(parents=True, exist_ok=True)
    with open(work_dir() / "build.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def is_up_to_date() -> bool:
    """True when the extension exists and was built from these headers, this file, this Python ABI
    and this library directory."""
    try:
        binary = extension_path().read_bytes()
    except FileNotFoundError:
        return False
    return (_MARK + _fingerprint()).encode() in binary


def ensure_built(force: bool = False, verbose: bool = False) -> Path:
    """Build the extension if needed; return its path. Safe to call from concurrent processes."""
    if not force and is_up_to_date():
        return extension_path()
    if not library_path().exists():
        raise BuildError(
            f"{library_path()} not found: build the C library first "
            f"(cmake -S {REPO_ROOT} -B {build_dir()} && cmake --build {build_dir()})"
        )
    with _lock():
        if not force and is_up_to_date():
            return extension_path()
        work = work_dir() / "tmp"
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        try:
            built = Path(make_ffibuilder().compile(tmpdir=str(work), verbose=verbose))
        except Exception as exc:  # cffi raises distutils/setuptools errors of various kinds
            raise BuildError(f"compiling {MODULE_NAME} failed: {exc}") from exc
        tmp_target = extension_path().with_suffix(".tmp")
        shutil.copy2(built, tmp_target)
        os.replace(tmp_target, extension_path())  # atomic: a running import never sees half a file
        shutil.rmtree(work, ignore_errors=True)
    return extension_path()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m collide.build_ffi", description=__doc__.splitlines()[0])
    parser.add_argument("--force", action="store_true", help="rebuild even if up to date")
    parser.add_argument("--print-cdef", action="store_true", help="print the generated cdef and exit")
    parser.add_argument("--emit-c", metavar="FILE", type=Path,
                        help="write the extension's C source to FILE and exit (the wheel's CMake build)")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args(argv)
    if not in_source_checkout():
        print(f"collide.build_ffi: {PACKAGE_DIR} is an installed package: its extension was built with it "
              "and there is nothing to build (this command works in a source checkout's ros_pkg/)", file=sys.stderr)
        return 0 if extension_path().exists() and not (args.print_cdef or args.emit_c) else 1
    try:
        if args.print_cdef:
            sys.stdout.write(generate_cdef())
            return 0
        if args.emit_c:
            print(f"collide.build_ffi: wrote {write_c_source(args.emit_c)}")
            return 0
        fresh = not args.force and is_up_to_date()
        path = ensure_built(force=args.force, verbose=args.verbose)
    except BuildError as exc:
        print(f"collide.build_ffi: error: {exc}", file=sys.stderr)
        return 1
    print(f"collide.build_ffi: {'up to date' if fresh else 'built'} {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
