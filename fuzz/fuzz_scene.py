"""Fuzz harness for the scene-file parser (collide.load_scene), with atheris (libFuzzer for Python).

Each input is a scene file: the first byte picks YAML or JSON, the rest is the file's text. The
contract checked for every input:
  * load_scene(path) returns a Scene or raises SceneError (with a non-empty message) - any other
    exception (RecursionError, TypeError, KeyError, CollideError, ...) is a crash;
  * the line-numbered reader alone (collide.scene's, which load_scene leaves a plain file to the fast
    reader for) gives the same: an equal Scene of the same value types, or a SceneError with the same
    message;
  * a returned Scene round-trips: load_scene(scene.to_dict()) == scene;
  * it builds, and stepping it a few times either succeeds with a finite state or raises
    CollideError (never anything else).

    python fuzz/fuzz_scene.py CORPUS_DIR [libFuzzer flags, e.g. -max_total_time=60]   # fuzz
    python fuzz/fuzz_scene.py --replay FILE_OR_DIR ...                                # regressions

The replay mode needs no atheris (ctest fuzz_scene_regressions runs it).
"""
from __future__ import annotations

import atexit
import importlib
import math
import os
import shutil
import sys
import tempfile
import types
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "ros_pkg"))

_TMP = Path(tempfile.mkdtemp(prefix="fuzz_scene_", dir="/dev/shm" if os.path.isdir("/dev/shm") else None))
atexit.register(shutil.rmtree, _TMP, True)
_STEPS = 3  # a few steps show the built world is usable; more only costs time per input


class ContractViolation(AssertionError):
    """The parser broke its contract for this input."""


def check_one(data: bytes) -> None:
    """Run one input through load_scene and the checks in the module docstring."""
    from collide import CollideError, SceneError, load_scene

    suffix = ".json" if data[:1] in (b"{", b"J") else ".yaml"
    text = data[1:] if data[:1] == b"J" else data
    path = _TMP / f"input{suffix}"
    path.write_bytes(text)
    try:
        scene = load_scene(path)
    except SceneError as exc:
        if not str(exc).strip() or not exc.errors:
            raise ContractViolation(f"SceneError without a message: {exc!r}") from exc
        _same_as_lined(path, str(exc))
        return
    _same_as_lined(path, scene)
    again = load_scene(scene.to_dict())
    if again != scene:
        raise ContractViolation(f"to_dict round trip changed the scene:\n{scene}\n!=\n{again}")
    world = scene.build()
    dt = scene.run["dt"]
    try:
        for _ in range(_STEPS):
            world.step(dt)
    except CollideError:
        return  # e.g. LC_ERR_NUMERIC for an absurd scene: reported, and the step was undone
    if not all(math.isfinite(x) for x in world.state.ravel().tolist()):
        raise ContractViolation("a successful step left a non-finite state")


def _same_as_lined(path: Path, got: Any) -> None:
    """The line-numbered reader gives what load_scene gave (a Scene, or a SceneError's message)."""
    from collide import SceneError
    from collide.scene import _load_lined, read_scene_text

    try:
        text = read_scene_text(path)
    except SceneError:
        return  # not UTF-8: load_scene refused it before either reader
    try:
        lined: Any = _load_lined(text, str(path), path.suffix == ".json", True)
    except SceneError as exc:
        lined = str(exc)
    if isinstance(got, str) or isinstance(lined, str):
        same = got == lined
    else:
        same = got == lined and repr(got.to_dict()) == repr(lined.to_dict())  # 1 and 1.0 are ==
    if not same:
        raise ContractViolation(f"load_scene and the line-numbered reader differ:\n{got}\n!=\n{lined}")


def replay(paths: list[str]) -> int:
    files: list[Path] = []
    for p in map(Path, paths):
        files += sorted(f for f in p.iterdir() if f.is_file()) if p.is_dir() else [p]
    failed = 0
    for f in files:
        try:
            check_one(f.read_bytes())
        except Exception as exc:  # noqa: BLE001 - any exception is the finding being reported
            failed += 1
            print(f"fuzz_scene: FAIL {f}: {type(exc).__name__}: {str(exc)[:300]}")
    print(f"fuzz_scene: replayed {len(files)} inputs, {failed} failed")
    return 1 if failed or not files else 0


# Modules whose functions give coverage feedback: the parser/validator and what it calls.
_INSTRUMENTED = ("collide.scene", "collide.scene_fast", "collide.world", "collide.body", "collide._convert")


def _instrument(atheris: Any) -> int:
    """Replace the module-level functions of _INSTRUMENTED by atheris-instrumented ones.

    Measured on Python 3.11 / atheris 2.3.0: atheris.instrument_imports gave no coverage for
    collide; instrumenting every function of every collide module (incl. the cffi loader) gave
    none either; these four modules give it. PyYAML runs as shipped: instrumenting it raised a
    spurious AttributeError ('str' object has no attribute 'prefix') that the same input never
    raises uninstrumented."""
    count = 0
    for name in _INSTRUMENTED:
        module = importlib.import_module(name)
        for obj in list(vars(module).values()):
            if isinstance(obj, types.FunctionType) and obj.__module__ == name:
                atheris.instrument_func(obj)  # patches the function's code in place
                count += 1
    return count


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--replay":
        return replay(sys.argv[2:])
    import atheris

    _instrument(atheris)

    def test_one_input(data: bytes) -> None:
        check_one(data)

    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()
    return 0


if __name__ == "__main__":
    sys.exit(main())
