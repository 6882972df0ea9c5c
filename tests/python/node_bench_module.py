"""bench/node_bench.py loaded as a module, for the tests that check the scenes its benches generate."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[2]


def load_node_bench() -> ModuleType:
    """bench/node_bench.py as the module bench_node_bench (registered: its dataclasses need it)."""
    name = "bench_node_bench"
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(name, ROOT / "bench" / "node_bench.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod
