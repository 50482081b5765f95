"""A script of benchmarks/ loaded as a module, for tests that check it or reuse its solvers."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def load_benchmark(name):
    """benchmarks/NAME.py as a fresh module (benchmarks/ on sys.path while it loads: its scripts
    import their neighbours, e.g. ``checkout``)."""
    spec = importlib.util.spec_from_file_location(f"_bench_{name}", BENCH / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.path.insert(0, str(BENCH))
    try:
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(BENCH))
    return module
