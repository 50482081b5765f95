"""Issue #11, sections 3 and 4: output paths, checkpoints, LAPACK noise, malformed files,
extreme values -- each gets an answer (a status or a one-line ValueError), never a traceback."""

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.state import delta_bounds, solve_point_load


def run(*args, cwd=None, timeout=300):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ), timeout=timeout)


def one_line_error(r, *words):
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("shellbvp: error: "), r.stderr
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


# -- LAPACK/BLAS messages ---------------------------------------------------------------------

def test_overflowing_jacobian_never_reaches_lapack_and_json_is_one_document():
    """The extreme scene's Newton iterates overflow; SuperLU used to get a NaN matrix and its
    BLAS printed '** On entry to DGEMV parameter number 2 had an illegal value' on stdout."""
    r = run("solve", "--gamma", "99.9999999", "--rho", "0.01", "--beta", "1e-4", "--xi", "0", "--neo-hookean",
            "--delta", "0.0184286", "--tol", "1e-3", "--json")
    assert "illegal value" not in r.stdout + r.stderr
    out = json.loads(r.stdout)  # exactly one document: nothing before or after it
    assert r.returncode == 1 and not out["success"] and out["status"] != 0
    assert "overflowed" in out["message"]


def test_guard_returns_status_2_for_a_nan_guess():
    sol = sb.solve(sb.Scene.preset("base"), delta=0.1, estimate_error=False)
    sysm = sol.system
    from shellbvp.state import solve_bvp

    y = sol.y.copy()
    y[3, 5] = np.nan
    bvp = solve_bvp(sysm.fun, sysm.bc, sol.x, y, sol.p, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=1e-6)
    assert bvp.status == 2 and not bvp.success and "NaN" in bvp.message
    assert np.all(np.isnan(bvp.sol(np.array([0.2, 0.7]))))
    x = sol.x.copy()
    x[3] = x[2]  # degenerate mesh: scipy would raise ValueError (read as bad user input)
    bvp = solve_bvp(sysm.fun, sysm.bc, x, sol.y, sol.p, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=1e-6)
    assert bvp.status == 2 and "mesh" in bvp.message


# -- extreme values -----------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs,name", [
    (dict(deltas=[1e-300, 2e-300]), "deltas"),
    (dict(delta_max=1e-300), "delta_max"),
    (dict(delta_max=0.5, delta_min=1e-9), "delta_min"),
    (dict(delta_max=5.0), "delta_max"),
])
def test_curve_refuses_depths_outside_the_range_at_once(kwargs, name):
    scene = sb.Scene.preset("base")
    low, high = delta_bounds(scene, 1e-6)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=name) as err:
        sb.curve(scene, **kwargs)
    assert time.perf_counter() - t0 < 2.0
    assert f"[{low:g}, {high:.4g}]" in str(err.value)


def test_delta_bound_is_the_doubled_meridian():
    """high = Z(0) - Z(L) + 2 l: the dome's pole starts 1 above the rim, the bowl's 1 below,
    a hemisphere's meridian is pi/2 long; a flat plate's (R = sin S) 1."""
    assert delta_bounds(sb.Scene.preset("dome"), 1e-6)[1] == pytest.approx(1 + np.pi, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("base"), 1e-6)[1] == pytest.approx(np.pi - 1, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("flat"), 1e-6)[1] == pytest.approx(2.0, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("base"), 1e-8)[0] == 1e-8


def test_solve_dome_paper_at_delta_5_is_refused_at_once():
    scene = sb.Scene.preset("dome", contact="paper")
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"delta = 5 is outside \[1e-06, 4.142\]"):
        sb.solve(scene, delta=5.0)
    assert time.perf_counter() - t0 < 2.0
    with pytest.raises(ValueError, match="delta = 1e-300"):
        sb.solve(scene, delta=1e-300)


def test_curve_from_point_load_states_goes_up_without_index_error():
    """delta_max = 1e-3 on the base scene: every state is the point-load limit (the cap is
    below 1e-30), so the upward leg cannot follow a cap branch; it used to fail with an
    IndexError in state._state_params (a point state has no ln Sc)."""
    c = sb.curve(sb.Scene.preset("base"), delta_max=1e-3, estimate_error=False)
    assert c.complete and c.delta[-1] == pytest.approx(1e-3) and "delta_max" in c.stop_reason
    assert np.all(np.diff(c.delta) > 0) and np.all(c.status == 0)
    assert set(c.topology) == {"point"}
    # the point-load limit F/delta -> 1.2625 (README), the same whichever way it is reached
    direct = solve_point_load(sb.Scene.preset("base"), 1e-3)
    assert c.force[-1] == pytest.approx(direct.force, rel=1e-5)


def test_natural_curve_from_a_point_state_reaches_the_cap_again():
    c = sb.curve(sb.Scene.preset("base"), deltas=[1e-4, 0.05, 0.1], topology="cap", estimate_error=False)
    assert c.complete and list(c.topology) == ["point", "cap", "cap"]
    ref = sb.solve(sb.Scene.preset("base"), delta=0.1, topology="cap", estimate_error=False)
    assert c.force[-1] == pytest.approx(ref.force, abs=1e-7)


def test_solve_with_a_point_load_guess_starts_cold():
    scene = sb.Scene.preset("base")
    point = solve_point_load(scene, 1e-3)
    sol = sb.solve(scene, delta=0.1, guess=point, topology="cap", estimate_error=False)
    assert sol.success and sol.topology == "cap"
