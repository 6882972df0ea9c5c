"""bench/<name>.py loaded as a module, for the tests of the benchmarks' own code (scenes, metrics,
reports) without running an engine."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[2]


def load_bench(name: str) -> ModuleType:
    """bench/<name>.py as a fresh module bench_<name>, registered in sys.modules (dataclasses need it)."""
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "bench" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


def load_node_bench() -> ModuleType:
    """bench/node_bench.py, loaded once for every test that checks the scenes its benches generate."""
    return sys.modules.get("bench_node_bench") or load_bench("node_bench")
