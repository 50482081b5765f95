"""The benchmark's peer (benchmarks/shooting.py, the paper's shooting method) agrees with sb.solve.

Shooting shares only the generated equations with the collocation solver, so agreement
checks both.  Shooting's basin of attraction is tiny (see the module), so it starts from
the collocation state perturbed by 0.1 % -- these tests check agreement, not robustness.
"""

import importlib.util
import math
import sys
from pathlib import Path

import pytest

import shellbvp as sb

_PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "shooting.py"


@pytest.fixture(scope="module")
def shooting():
    spec = importlib.util.spec_from_file_location("shellbvp_benchmarks_shooting", _PATH)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("contact", ["smooth", "paper"])
def test_shooting_agrees_with_collocation(shooting, contact):
    scene = sb.Scene.preset("base", contact=contact)
    lambda0 = 1.05
    ref = sb.solve(scene, lambda0=lambda0, tol=1e-9, estimate_error=False)
    assert ref.success, ref.message
    # free unknown at Sc+: rQ (smooth, Q jumps) or kappa_s (paper); free states start at row 2
    u = ref.y[2 + shooting._UNKNOWN[contact], 0]
    st = shooting.shoot_state(scene, lambda0, rtol=1e-9, guess=(ref.Sc * 1.001, u * 1.001))
    assert st.success, st.message
    assert st.delta > 0
    assert math.isclose(st.Sc, ref.Sc, rel_tol=1e-6)
    assert abs(st.F - ref.force) < 1e-6
    assert abs(st.delta - ref.delta) < 1e-6
    assert st.force_defect < 1e-7        # F is a first integral of the free region
