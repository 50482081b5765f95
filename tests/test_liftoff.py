"""Lift-off at the pole: line and annular contact (issue 7).

Where the single cap would need a negative contact pressure, the shell leaves
the indenter around the pole.  (The stacked systems' Jacobians are checked in
test_chain.py.)  These tests check that the states found are valid (pushing ring forces, no penetration), that they
satisfy the energy identity F = dE/ddelta, and that curves switch topology
without a jump in F(delta).
"""


import numpy as np
import pytest
from scipy.integrate import trapezoid

import shellbvp as sb
from shellbvp.config import OPTIONS
from shellbvp.lifted_ends import pole_corner_partner
from shellbvp.liftoff import liftoff_state
from shellbvp.pointload import solve_point_load


def _energy_slope(scene, delta, h=1e-3, tol=1e-8):
    """dE/ddelta by Richardson-extrapolated central differences (error O(h^4))."""
    E = {k: sb.solve(scene, delta=delta + k * h, tol=tol, estimate_error=False) for k in (-2, -1, 1, 2)}
    for s in E.values():
        assert s.success and s.valid, s.flags
    d1 = (E[1].energy - E[-1].energy) / (2 * h)
    d2 = (E[2].energy - E[-2].energy) / (4 * h)
    return (4 * d1 - d2) / 3, {s.topology for s in E.values()}


@pytest.mark.parametrize("preset, delta", [("base", 0.05), ("dome", 0.1)])
def test_lifted_pole_state_is_valid_and_energy_consistent(preset, delta):
    scene = sb.Scene.preset(preset)
    cap = sb.solve(scene, delta=delta, topology="cap")
    assert cap.success and not cap.valid and cap.pressure_min < 0  # the cap would pull the shell
    sol = sb.solve(scene, delta=delta, tol=1e-8)
    assert sol.success and sol.valid, sol.flags
    assert sol.topology == "line"
    assert sol.ring_force > 0
    # a line carries the whole force as the jump of Q there (from the profile, not the solver's sum)
    prof = sol.profile()
    i = np.nonzero(np.isclose(prof["S"], sol.S1, rtol=1e-12))[0][0]  # the inner cap's end; the outer region's start next
    jump = -2 * np.pi * prof["r"][i] * np.cos(prof["phi"][i]) * (prof["Q"][i + 1] - prof["Q"][i])
    assert jump == pytest.approx(sol.force, rel=1e-6)
    assert sol.penetration <= 0
    # the inner cap carries no force: its axial force vanishes along it
    assert sol.force_defect < 1e-6
    # the energy identity F = dE/ddelta, to the finite-difference and solver accuracy
    slope, kinds = _energy_slope(scene, delta)
    assert kinds == {"line"}
    assert abs(slope - sol.force) < 1e-8 + 10 * sol.force_error
    # the lifted state differs from the invalid cap by a small, measured amount
    assert sol.cap_state["force"] == pytest.approx(cap.force, rel=1e-6)
    assert sol.energy <= cap.energy + 1e-9


def test_lifted_pole_profile_is_ordered_and_off_the_indenter():
    scene = sb.Scene.preset("base")
    sol = sb.solve(scene, delta=0.1)
    prof = sol.profile()
    assert np.all(np.diff(prof["S"]) >= 0)
    assert np.all(prof["region"] == 1)  # line contact: free on both sides
    inner = prof["S"] <= sol.S1
    tip = sol.system.model.tip_shape(np.linspace(0, 1.5, 2001), sol.system.par)
    surface = sol.z_tip + scene.rho * np.interp(prof["r"][inner] / scene.rho, tip["A"], tip["B"])
    assert np.all(prof["z"][inner] <= surface + 1e-7)  # below the indenter: lifted off, not through it
    assert np.max(surface - prof["z"][inner]) > 1e-8   # and really off it somewhere


def test_valid_cap_is_kept_and_annulus_search_returns_the_cap():
    scene = sb.Scene.preset("base")
    sol = sb.solve(scene, delta=0.2)
    assert sol.topology == "cap" and sol.valid
    ann = liftoff_state(sol, "annulus")
    assert not ann.success and "reaches the pole" in ann.message
    line = liftoff_state(sol, "line")
    assert not line.valid and any("passes through the indenter" in f for f in line.flags)


def test_topology_argument_is_checked():
    scene = sb.Scene.preset("base")
    with pytest.raises(ValueError, match="topology"):
        sb.solve(scene, delta=0.1, topology="ring")
    with pytest.raises(ValueError, match="contact='smooth'"):
        sb.solve(sb.Scene.preset("base", contact="paper"), delta=0.1, topology="line")
    with pytest.raises(ValueError, match="topology"):
        sb.curve(scene, topology="line")


def test_force_and_lambda0_control_find_the_lifted_state():
    scene = sb.Scene.preset("base")
    ref = sb.solve(scene, delta=0.08)
    assert ref.topology == "line"
    sol = sb.solve(scene, force=ref.force)
    assert sol.topology == "line" and sol.valid
    assert sol.delta == pytest.approx(0.08, abs=1e-7)
    lifted = sb.solve(scene, lambda0=ref.lambda0, topology="line")  # the stretch at the lifted pole
    assert lifted.success and lifted.valid
    assert lifted.delta == pytest.approx(0.08, abs=1e-6) and lifted.force == pytest.approx(ref.force, rel=1e-6)


def test_base_curve_switches_from_line_to_cap_without_a_jump(tmp_path):
    scene = sb.Scene.preset("base")
    c = sb.curve(scene, delta_max=0.2)
    assert c.complete and np.all(c.valid), c.flags
    kinds = list(c.topology)
    assert kinds[0] == "point" and kinds[-1] == "cap" and "line" in kinds
    (switch,) = [s for s in c.settings["topology_switches"] if s["from"] == "line"]
    assert 0.09 < switch["delta"] < 0.13 and switch["criterion"] == "pressure_min" and abs(switch["value"]) < 1e-3
    # at the switch the line state and the cap coincide
    i = int(np.argmin(np.abs(c.delta - switch["delta"])))
    cap = c.solutions[i]
    line = liftoff_state(cap, "line")
    assert line.success
    assert line.force == pytest.approx(cap.force, abs=1e-7)
    # F(delta) is smooth across: the energy identity holds through the switch
    assert np.nanmax(np.abs(c.energy_residual)) < 2e-3
    path = tmp_path / "c.h5"
    c.to_hdf5(path)
    back = sb.read_curve(path)
    assert list(back.topology) == kinds
    np.testing.assert_array_equal(back.S1, c.S1)


def test_dome_curve_is_valid_at_every_point():
    c = sb.curve(sb.Scene.preset("dome"), delta_max=0.3)
    assert c.complete and np.all(c.valid), c.flags
    assert set(c.topology) <= {"point", "line"}
    assert np.all(c.force > 0) and np.all(np.diff(c.force) > 0)
    # point -> line: the point-load limit and the smallest line contact agree
    i = list(c.topology).index("line")
    point = solve_point_load(sb.Scene.preset("dome"), float(c.delta[i]))
    assert point.force == pytest.approx(c.force[i], rel=1e-5)


@pytest.mark.slow
def test_energy_identity_through_the_switch_on_a_fine_grid():
    c = sb.curve(sb.Scene.preset("base"), deltas=np.linspace(0.09, 0.14, 26), tol=1e-8)
    assert {"line", "cap"} <= set(c.topology)
    # At tol 1e-8 a window of width ~1e-3 at the switch has no valid state of the three
    # topologies (the cap pulls at its edge, the line bends through the tip by < 4e-4 in
    # curvature): flagged, not hidden (docs/limits.md).
    bad = ~c.valid
    assert np.all((c.delta[bad] > 0.111) & (c.delta[bad] < 0.1135)), c.delta[bad]
    assert all("no valid lift-off state found" in f for f, b in zip(c.flags, bad) if b)
    assert np.nanmax(np.abs(c.energy_residual)) < 5e-5


def test_cli_reports_the_topology(tmp_path, cli_main):
    _cli = cli_main  # the command's main in this process
    import json

    r = _cli("solve", "--preset", "dome", "--delta", "0.1", "--topology", "cap", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["topology"] == "cap" and not out["valid"]
    line = sb.solve(sb.Scene.preset("dome"), delta=0.1, estimate_error=False)  # what the CLI's default solves
    assert line.topology == "line" and line.valid and line.S1 == line.Sc > 0
    r = _cli("curve", "--preset", "dome", "--delta-max", "0.1", "-o", "d.h5", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "contact topologies along the curve: point x" in r.stdout and "line x" in r.stdout
    c = sb.read_curve(tmp_path / "d.h5")
    assert np.all(c.valid) and set(c.topology) == {"point", "line"}


# A large indenter in a prolate shell: the pole lifts while an outer band is pressed --
# line contact, then a finite annulus, then the cap.
ANNULAR = dict(rho=0.3, gamma=3.0)


def test_finite_annulus_is_valid_and_energy_consistent():
    scene = sb.Scene.preset("base", **ANNULAR)
    cap = sb.solve(scene, delta=0.1, topology="cap")
    assert cap.success and cap.pressure_min < 0
    line = sb.solve(scene, delta=0.1, topology="line")
    assert line.success and not line.valid and line.curvature_excess > 0  # bends through the tip
    sol = sb.solve(scene, delta=0.1, tol=1e-8)
    assert sol.topology == "annulus" and sol.valid, sol.flags
    assert 0 < sol.S1 < 0.8 * sol.Sc                     # a finite annulus, away from the pole
    assert sol.pressure_min > 0 and sol.ring_force > 0 and sol.ring_force_inner > 0
    assert sol.penetration <= 0
    prof = sol.profile(points_per_interval=3)
    on = prof["region"] == 0
    assert np.all(prof["P"][on] >= 0)
    # the force balance from the profile alone: the ring forces are the jumps of Q at the two
    # edges (-2 pi r cos(phi) [Q]), the annulus's share 2 pi Int P r dr; together they are the
    # force the outer free region carries
    i1, i2 = np.nonzero(on)[0][[0, -1]]
    ring_in = -2 * np.pi * prof["r"][i1] * np.cos(prof["phi"][i1]) * (prof["Q"][i1] - prof["Q"][i1 - 1])
    ring_out = -2 * np.pi * prof["r"][i2] * np.cos(prof["phi"][i2]) * (prof["Q"][i2 + 1] - prof["Q"][i2])
    band = 2 * np.pi * trapezoid(prof["P"][on] * prof["r"][on], prof["r"][on])
    assert ring_in == pytest.approx(sol.ring_force_inner, rel=1e-6)
    assert ring_out == pytest.approx(sol.ring_force, rel=1e-6)
    assert ring_in + band + ring_out == pytest.approx(sol.force, rel=1e-3)
    # the contact starts where the shell lies on the tip: below the surface inside S1, on it after
    tip = sol.system.model.tip_shape(np.linspace(0, 1.5, 4001), sol.system.par)
    height = prof["z"] - (sol.z_tip + scene.rho * np.interp(prof["r"] / scene.rho, tip["A"], tip["B"]))
    assert np.max(np.abs(height[on])) < 1e-6
    assert np.all(height[:i1 - 1] < 0) and height[i1 - 2] < 0
    slope, kinds = _energy_slope(scene, 0.1)
    assert kinds == {"annulus"}
    assert abs(slope - sol.force) < 1e-8 + 10 * sol.force_error
    assert sol.energy < cap.energy  # lifting off lowers the energy at fixed delta


def test_curve_passes_line_annulus_cap_without_a_jump():
    c = sb.curve(sb.Scene.preset("base", **ANNULAR), delta_max=0.15)
    assert c.complete and np.all(c.valid), c.flags
    runs = [k for i, k in enumerate(c.topology) if i == 0 or k != c.topology[i - 1]]
    assert runs == ["line", "annulus", "cap"]
    sw = {(s["from"], s["to"]): s for s in c.settings["topology_switches"]}
    assert sw[("line", "annulus")]["criterion"] == "curvature_excess"
    assert sw[("annulus", "cap")]["criterion"] == "pressure_min"
    assert sw[("line", "annulus")]["delta"] < sw[("annulus", "cap")]["delta"]
    ann = c.topology == "annulus"
    assert np.all(c.pressure_min[ann] >= 0) and np.all(c.ring_force_inner[ann] >= 0)
    # near the switch the annulus opens from the line: it is narrow there
    first = np.nonzero(ann)[0][0]
    assert c.Sc[first] - c.S1[first] < 0.5 * (c.Sc[first] - c.S1[np.nonzero(ann)[0][-1]])
    assert np.all(np.diff(c.force) > 0)
    assert np.nanmax(np.abs(c.energy_residual)) < 2e-3


def test_format_version_1_files_read_as_single_caps(tmp_path):
    import h5py

    c = sb.curve(sb.Scene.preset("base"), deltas=[0.2, 0.25], estimate_error=False)
    path = tmp_path / "v1.h5"
    c.to_hdf5(path)
    with h5py.File(path, "a") as f:  # what a file written before lift-off holds (at /curve, no NXentry)
        f.move("entry/curve", "curve")
        del f["entry"]
        for key in ("topology", "S1", "ring_force_inner"):
            del f["curve"][key]
        f.attrs["format_version"] = 1
    back = sb.read_curve(path)
    assert list(back.topology) == ["cap", "cap"] and np.all(back.S1 == 0)
    np.testing.assert_array_equal(back.force, c.force)


# 12-35 s each in CI (the default suite is at its budget): the split's growth from the line
# is checked by default in test_where_the_lifted_pole_comes_down_the_split_grows_from_the_line
@pytest.mark.slow
@pytest.mark.parametrize("delta", [0.33, 0.36])
def test_a_cap_pressed_at_the_pole_and_pulling_further_out_splits_into_a_cap_and_a_line(delta):
    """beta = 0.1: the cap presses at the pole but pulls near its edge, and neither a lifted
    pole's line nor an annulus is valid; the contact splits into a smaller cap and, beyond a
    lifted gap, a line on the tip where the cap's edge was (issue 12: two contact zones)."""
    scene = sb.Scene.preset("base", beta=0.1)
    cap = sb.solve(scene, delta=delta, topology="cap", estimate_error=False)
    assert cap.success and not cap.valid and cap.pressure_min < 0
    s = sb.solve(scene, delta=delta, tol=1e-8)
    assert s.topology == "cap+line(tip)" and s.valid, s.flags
    assert 0 < s.edge_S[0] < s.Sc < cap.Sc * 1.1 and s.curvature_excess < 0
    assert s.pressure_min >= 0 and all(f > 0 for f in s.edge_forces)
    slope, kinds = _energy_slope(scene, delta)
    assert kinds == {"cap+line(tip)"}
    assert abs(slope - s.force) < 1e-8 + 10 * s.force_error


def test_where_the_lifted_pole_comes_down_the_split_grows_from_the_line():
    """base at delta 0.1125 after the line at 0.1: the line is too curved there, the annulus
    closes onto the pole, the cap pulls at its edge and presses at the pole.  The line's pole is
    down on the tip (its clearance is -1e-8, solver precision), so the contact splits into a cap
    and the line: found from the line state (S_c = 0.7 S1; the guesses from the cap leave the
    model's domain), valid, where the curve recorded a flagged cap before."""
    from shellbvp.liftoff import liftoff_state, pole_clearance

    scene = sb.Scene.preset("base")
    c = sb.curve(scene, deltas=[0.1, 0.1125], estimate_error=False)
    assert list(c.topology) == ["line", "cap+line(tip)"] and np.all(c.valid), c.flags
    split = c.solutions[1]
    assert 0 < split.edge_S[0] < 0.8 * split.Sc and split.pressure_min >= 0 and min(split.edge_forces) > 0
    cap = sb.solve(scene, delta=0.1125, topology="cap", estimate_error=False)
    line = liftoff_state(cap, "line", previous=c.solutions[0])
    assert line.success and not line.valid and pole_clearance(line) <= 1e-6
    assert not cap.valid and c.force[1] == pytest.approx(cap.force, rel=1e-6)  # the gap is ~1e-8 wide


def test_where_the_lines_pole_is_down_the_split_is_tried_before_the_annulus(monkeypatch):
    """base at delta 0.1125 after the line at 0.1: the line there is too curved and its pole is
    down on the tip.  The split is probed first and found; the annulus (whose probes run onto
    the pole, the cap) is not tried.  In the old order (annulus first) the same state results."""
    import shellbvp.liftoff as lo

    scene = sb.Scene.preset("base")
    line = sb.curve(scene, deltas=[0.1], estimate_error=False).solutions[0]
    cap = sb.solve(scene, delta=0.1125, topology="cap", estimate_error=False)
    assert line.topology == "line" and line.valid and not cap.valid
    split, tried, line_here = lo.valid_liftoff_state(cap, previous=line, last=line)
    assert split.topology == "cap+line(tip)" and split.valid
    assert [t.split(":")[0] for t in tried] == ["line"], tried
    # the line converged there is kept beside it (no state holds another): the switch
    # line -> cap+line(tip) is located from it
    assert line_here.topology == "line" and line_here.delta == split.delta and not line_here.valid
    from shellbvp.recorder import Row
    from shellbvp.switches import line_state_at as _line_state_at

    row = Row(0.0, {}, "", split, cap=cap, line=line_here)
    assert _line_state_at(row, "line", {}) is line_here  # (no settings needed: nothing is solved)
    monkeypatch.setattr(OPTIONS, "split_first", False)
    again, tried_old, _ = lo.valid_liftoff_state(cap, previous=line, last=line)
    assert [t.split(":")[0] for t in tried_old] == ["line", "annulus"], tried_old
    assert again.topology == "cap+line(tip)" and abs(again.force - split.force) < 1e-9


# -- warm starts of lift-off states (issue 14 item 1) -------------------------------------------------
class _Count:
    """solve_bvp runs and Newton iterations of the lift-off solves (counts are deterministic)."""

    def __init__(self, monkeypatch):
        import shellbvp.liftoff

        self.calls = self.niter = 0
        orig = shellbvp.liftoff.solve_liftoff_from  # the one solve of a lift-off state

        def counted(*args, **kw):
            r = orig(*args, **kw)
            self.calls += 1
            self.niter += int(r.niter)
            return r

        monkeypatch.setattr(shellbvp.liftoff, "solve_liftoff_from", counted)


@pytest.mark.parametrize("scene_kw, deltas, fewer", [({}, np.linspace(0.04, 0.1, 5), True),
                                                     (ANNULAR, np.linspace(0.095, 0.105, 4), False)])
def test_warm_lift_off_gives_the_same_curve_with_fewer_newton_iterations(monkeypatch, scene_kw, deltas, fewer):
    """Lift-off states continued from the previous one: the same states, no more solves, and on
    the line fewer mesh passes (13 against 22).  On the annulus, since warm starts take meshes
    equidistributing the residual (solution.warm_mesh), a start from the cap converges in as
    many passes (40 each; 86 and 84 Jacobians)."""
    scene = sb.Scene.preset("base", **scene_kw)
    curves, counts = {}, {}
    for warm in (False, True):
        with monkeypatch.context() as m:
            m.setattr(OPTIONS, "warm_first", warm)
            counts[warm] = _Count(m)
            curves[warm] = sb.curve(scene, deltas=deltas, estimate_error="full")
    cold, warm = curves[False], curves[True]
    assert cold.complete and warm.complete
    assert list(warm.topology) == list(cold.topology) and set(warm.topology) <= {"line", "annulus"}
    assert np.all(warm.valid)
    # the same states, to the solver's accuracy (their Richardson estimates)
    bound = 10 * np.maximum(warm.points["force_error"], cold.points["force_error"]) + 1e-12
    assert np.all(np.abs(warm.force - cold.force) <= bound), (warm.force - cold.force, bound)
    # continued from the neighbour: no more solves, fewer Newton iterations
    assert counts[True].calls <= counts[False].calls
    if fewer:
        assert counts[True].niter < counts[False].niter, (counts[True].niter, counts[False].niter)


def test_no_failed_step_where_the_cap_grows_exponentially(monkeypatch):
    """Near the point-load limit Sc grows by orders of magnitude per step (base: 9e-12, 2e-6,
    1e-4 at delta 0.0125, 0.025, 0.0375): a secant linear in ln Sc overshoots and the step
    failed at the node budget; the plain warm start converges at once."""
    import shellbvp.state

    failed = []
    orig = shellbvp.state._run_bvp  # the one solve of a cap state

    def counted(*args, **kw):
        r = orig(*args, **kw)
        failed.append(not r.success)
        return r

    monkeypatch.setattr(shellbvp.state, "_run_bvp", counted)
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.0125, 0.025, 0.0375], estimate_error=False, topology="cap")
    assert c.complete and len(failed) >= 3
    assert not any(failed), failed


# -- the ends of the lifted and split branches on the stability grid (issues 12, 13) ---------------------
@pytest.mark.slow  # 10-20 s: eleven line states, five at tol 1e-8
def test_the_lifted_pole_branch_ends_where_the_pole_loses_convexity():
    """rho = 0.05: the lifted-pole line branch ends at delta* = 0.17543 because the energy stops
    being convex in (lambda_s, kappa_s) at the lifted cap's free pole, not at a regular fold:
    followed in the pole's stretch, delta grows to a maximum exactly where the pole's Legendre
    determinant reaches zero, with F(delta) smooth up to it (dE/ddelta = F there)."""
    from shellbvp.lifted_ends import lifted_pole_branch_end, pole_legendre
    from shellbvp.liftoff import replace_invalid_cap, solve_liftoff

    scene = sb.Scene.preset("base", rho=0.05)
    a, b = (replace_invalid_cap(sb.solve(scene, delta=d, topology="cap", estimate_error=False))
            for d in (0.11768, 0.14826))
    assert a.topology == b.topology == "line" and a.valid and b.valid
    assert 0 < pole_legendre(b) < pole_legendre(a)  # falling towards zero as delta grows
    end = lifted_pole_branch_end(b, a)
    assert end is not None and end.valid and end.topology == "line"
    assert 0 < pole_legendre(end) < 1e-3
    assert 0.1754 < end.delta < 0.17544  # delta* = 0.1754322 (followed to det 1e-6 at tol 1e-7)
    # delta is largest at the end along the branch: slope d delta/d lambda0 falls towards 0
    near, mid, far = (solve_liftoff(scene, "line", lambda0=end.lambda0 + dl, guess=end) for dl in (0.001, 0.02, 0.03))
    assert near.success and mid.success and far.success and far.delta < mid.delta < near.delta < end.delta
    slope_near = (end.delta - near.delta) / 0.001
    slope_far = (mid.delta - far.delta) / 0.01
    assert 0 < slope_near < 0.6 * slope_far
    # the energy identity on the line branch just before its end (Richardson differences)
    h, d0 = 1e-3, 0.172
    E = {}
    for k in (-2, -1, 0, 1, 2):
        s = solve_liftoff(scene, "line", delta=d0 + k * h, guess=end, tol=1e-8, estimate_error=k == 0)
        assert s.success and s.valid, s.flags
        E[k] = s
    slope = (4 * (E[1].energy - E[-1].energy) / (2 * h) - (E[2].energy - E[-2].energy) / (4 * h)) / 3
    assert abs(slope - E[0].force) < 1e-8 + 10 * E[0].force_error


def test_a_curve_stops_at_once_where_the_lifted_pole_branch_ends():
    """rho = 0.05: the curve ends at the lifted-pole line branch's end (recorded, valid) with the
    physical reason, instead of ten invalid caps that pull at the pole (delta 0.18-0.37)."""
    c = sb.curve(sb.Scene.preset("base", rho=0.05), delta_max=0.3, delta_min=0.045, estimate_error=False)
    assert c.complete and "loses convexity at the lifted cap's free pole" in c.stop_reason
    assert "interior Weierstrass-Erdmann corner" in c.stop_reason and "runs out with the box" in c.stop_reason
    assert np.all(c.valid) and c.topology[-1] == "line"
    assert 0.1754 < c.delta[-1] < 0.17544
    # the corner's other phase at the pole's (lambda_theta, kappa_theta): U lies above its convex
    # envelope there, and the envelope's far end moves out as the sampled box grows (a crease)
    corner = pole_corner_partner(c.solutions[-1])
    g = corner["gaps"]
    assert 1e-3 < g[0] < g[1] / 1.2 < g[2] / 1.2 ** 2 and not corner["finite"]
    (l1, k1), (l2, k2), _ = corner["partners"]
    assert l2 < 0.6 * l1 and k2 > 5 * k1


@pytest.mark.slow  # 6-10 s
def test_the_cap_and_line_on_the_tip_are_followed_until_the_gap_closes():
    """beta = 0.1: between the cap and the line on the tip the lifted gap closes near delta
    0.3941; at 0.39198 (the stability grid's one invalid point) the cap+line(tip) state is found
    by continuation in delta from the two before it, valid, with the gap nearly shut: its F and
    E are the (pulling) cap's to 1e-5 and 1e-7."""
    from shellbvp.liftoff import replace_invalid_cap, second_zone_state

    scene = sb.Scene.preset("base", beta=0.1)
    before = second_zone_state(sb.solve(scene, delta=0.34862, topology="cap", estimate_error=False))
    previous = second_zone_state(sb.solve(scene, delta=0.37039, topology="cap", estimate_error=False),
                                 previous=before)
    assert before.valid and previous.valid
    cap = sb.solve(scene, delta=0.39198, topology="cap", estimate_error=False)
    assert cap.success and not cap.valid and cap.pressure_min < 0
    s = replace_invalid_cap(cap, previous=previous, before=before)
    assert s.topology == "cap+line(tip)" and s.valid, s.flags
    assert s.delta == cap.delta
    q = dict(zip(s.system.unknowns, s.p))
    assert 0.98 < np.exp(q["ln_Sc"] - q["ln_S1"]) < 1  # the gap is nearly shut
    assert s.edge_forces[0] < 1e-4 < s.edge_forces[1]  # the inner edge's ring force vanishes with it
    assert s.force == pytest.approx(cap.force, rel=1e-5)
    assert s.energy == pytest.approx(cap.energy, rel=1e-7) and s.energy <= cap.energy + 1e-9


@pytest.mark.slow  # 15-60 s: the branch followed to its fold in ~40 solves
def test_the_lifted_pole_branch_of_a_thick_shell_folds():
    """beta = 0.2: the lifted-pole line branch turns back in delta at delta* = 0.356818 (a regular
    fold: the pole stays convex, its Legendre determinant 0.19 of the outer region's), with the
    lifted pole sagging away from the tip (not coming down onto it) and lambda0 falling fast.
    Located from two line states below it; F continuous through it along the branch; the
    energy identity holds on the branch close to it (Richardson differences)."""
    from shellbvp.lifted_ends import lifted_pole_fold, pole_legendre
    from shellbvp.liftoff import pole_clearance, replace_invalid_cap, solve_liftoff

    scene = sb.Scene.preset("base", beta=0.2)
    a = replace_invalid_cap(sb.solve(scene, delta=0.33, topology="cap", estimate_error=False))
    b = solve_liftoff(scene, "line", delta=0.34, guess=a)
    assert a.topology == b.topology == "line" and a.valid and b.valid
    fold, states = lifted_pole_fold(b, a)
    assert fold is not None and fold.valid and fold.topology == "line"
    assert 0.35681 < fold.delta < 0.35683  # 0.3568182 (three searches from different starts agree to 1e-9)
    assert fold.force == pytest.approx(1.88275, abs=1e-4)
    assert pole_legendre(fold) > 0.1 and pole_clearance(fold) > 0.01  # convex; the pole 0.011 below the apex
    assert all(s.valid and s.delta < fold.delta for s in states)
    assert np.all(np.diff([s.delta for s in states]) > 0)
    # a maximum of delta along the branch: lower on both sides, F passing continuously through it
    lo, hi = (solve_liftoff(scene, "line", lambda0=fold.lambda0 + dl, guess=fold) for dl in (-0.004, 0.004))
    assert lo.success and hi.success and lo.delta < fold.delta and hi.delta < fold.delta
    assert lo.force < fold.force < hi.force and hi.force - lo.force < 2e-3
    # F = dE/ddelta on the branch before the fold, to the error estimate (lambda0 moves ~7x as
    # fast as delta there: each state from its neighbour; tol 1e-7: these states need 3000-7000
    # nodes, at 1e-8 up to 19000; slope - F was 2.4e-9)
    h, d0 = 5e-4, 0.345
    E = {0: solve_liftoff(scene, "line", delta=d0, guess=min(states, key=lambda s: abs(s.delta - d0)), tol=1e-7,
                          estimate_error=True)}
    for k in (-1, 1, -2, 2):
        E[k] = solve_liftoff(scene, "line", delta=d0 + k * h, guess=E[k - int(np.sign(k))], tol=1e-7)
    for s in E.values():
        assert s.success and s.valid and s.lambda0 > fold.lambda0, s.flags
    slope = (4 * (E[1].energy - E[-1].energy) / (2 * h) - (E[2].energy - E[-2].energy) / (4 * h)) / 3
    assert abs(slope - E[0].force) < 1e-8 + 10 * E[0].force_error


@pytest.mark.slow  # 30-50 s
def test_a_curve_stops_at_the_fold_of_the_lifted_pole_branch():
    """beta = 0.2: the curve ends at the fold of its lifted-pole line branch (recorded, valid) with
    the physical reason, instead of 18 invalid caps that pull (delta 0.355-0.575) where the line
    state's warm starts missed the steepening branch."""
    c = sb.curve(sb.Scene.preset("base", beta=0.2), delta_max=1, delta_min=0.1, estimate_error=False)
    assert c.complete and "turns back in delta" in c.stop_reason and "snaps through" in c.stop_reason
    assert np.all(c.valid), c.flags
    assert c.topology[-1] == "line" and 0.35681 < c.delta[-1] < 0.35683


@pytest.mark.slow  # 5-7 s (the rotation bending's module loaded)
def test_the_touchdown_is_located_where_a_line_recorded_valid_already_touches():
    """beta = 0.2 with the rotation bending energy (no fold): the lifted pole comes down onto the tip
    near delta 0.9366 and the curve passes line -> cap+line(tip).  The last line points touch the
    tip within the validity tolerance (their poles down to 10 tol), so the two points either side of
    the recorded change do not bracket the touch-down; it is bracketed among the line points and
    located there, on the pole's clearance (before: no switch listed)."""
    scene = sb.Scene.preset("base", beta=0.2, bending=sb.RotationBending())
    c = sb.curve(scene, delta_max=1, delta_start=0.85, delta_min=0.85, estimate_error=False)
    assert c.complete and np.all(c.valid), c.flags
    assert list(c.topology)[0] == "line" and list(c.topology)[-1] == "cap+line(tip)"
    (sw,) = c.settings["topology_switches"]
    assert (sw["from"], sw["to"], sw["criterion"]) == ("line", "cap+line(tip)", "pole_clearance")
    assert 0.93 < sw["delta"] < 0.94 and 0 <= sw["value"] < 1e-8  # 0.936587 (on penetration)
    first_split = min(d for d, t in zip(c.delta, c.topology) if t == "cap+line(tip)")
    assert sw["delta"] < first_split
    # F(delta) smooth across (finite differences along the curve at this spacing: ~2e-3)
    assert np.nanmax(np.abs(c.energy_residual)) < 3e-3


@pytest.mark.slow  # 4 s with numba, ~15 s with numpy
def test_the_touchdown_is_located_where_the_split_state_has_no_line_at_its_depth(monkeypatch):
    """beta = 0.1 (the stability grid's scene), the adaptive curve's first step as long as the
    chord below (which places its points so): the last line point before the split has its pole
    down on the tip within 10 tol, and no line converges at the first split state's depth, so the
    two points either side of the change give no bracket.  The touch-down is bracketed among the
    line points and the switch point recorded between them in branch order (before: no switch
    listed; and a switch point from that bracket went after the line point deeper than it)."""
    monkeypatch.setattr(OPTIONS, "first_step", 1.0)
    c = sb.curve(sb.Scene.preset("base", beta=0.1), delta_max=1.0, delta_min=1e-4)
    sw = [s for s in c.settings["topology_switches"] if (s["from"], s["to"]) == ("line", "cap+line(tip)")]
    assert len(sw) == 1 and 0.3249 < sw[0]["delta"] < 0.3250 and sw[0]["criterion"] == "pole_clearance"
    assert np.all(np.diff(c.delta) > 0)


def test_solve_from_a_split_state_keeps_its_configuration():
    """``sb.solve(guess=<cap+line(tip) state>)`` re-solves that configuration (it built a single
    cap's system from it and failed in solve_bvp on the shapes): at a tighter tol at the same depth
    (1e-9: ten times the state's nodes, beyond the continuation's node budget of 1200 until that
    scaled with the tolerance), and under force control back to the same depth."""
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.1125], estimate_error=False)
    split = c.solutions[-1]
    assert split.topology == "cap+line(tip)" and split.valid
    tight = sb.solve(split.scene, delta=split.delta, tol=1e-9, guess=split)
    assert tight.topology == "cap+line(tip)" and tight.valid
    assert abs(tight.force - split.force) < 1e-8 and tight.force_error < 1e-10
    back = sb.solve(split.scene, force=split.force, guess=split, estimate_error=False)
    assert back.topology == "cap+line(tip)" and back.valid and abs(back.delta - split.delta) < 1e-7


def test_the_free_pole_conditions_are_well_scaled_and_the_line_is_continued_without_a_failed_run(monkeypatch):
    """The free pole's G = 0 row was G/zeta^2 (zeta = 1e-4 S1): its derivative in rQ reached
    3e12 on base's line at delta 0.075, Newton could not take its residual below bc_tol and
    the warm start from 0.0625 ran solve_bvp's ten Newton restarts to status 3 (0.3 s).
    Imposed as G = 0 (a force, like the other force conditions), every row is O(1) and no run fails."""
    import shellbvp.liftoff

    runs = []
    orig = shellbvp.liftoff.solve_liftoff_from

    def counted(*args, **kw):
        r = orig(*args, **kw)
        runs.append((r.status, r.delta))
        return r

    monkeypatch.setattr(shellbvp.liftoff, "solve_liftoff_from", counted)
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.05, 0.0625, 0.075], estimate_error=False)
    assert c.complete and list(c.topology) == ["line"] * 3
    assert all(status == 0 for status, _ in runs), runs
    line = c.solutions[-1]
    sysm = line.system
    A, B, P = sysm.bc_jac(line.y[:, 0], line.y[:, -1], line.p)
    row_size = np.max(np.abs(np.hstack([A, B, P])), axis=1)
    assert np.max(row_size) < 100, row_size


def test_the_annulus_probes_at_base_0_1125_see_the_cap_within_the_probe_budget(monkeypatch):
    """At base delta 0.1125 (the line too curved) the annulus probes walk their inner edge to
    the pole.  Before the free pole's G row was scaled, Newton could not settle there and each
    probe ran solve_bvp's ten restarts (66-70 fun_jac calls); now each ends within the probe's
    budget of 16 Jacobians and says that the state is the cap."""
    import shellbvp.liftoff
    import shellbvp.solution

    calls = []
    orig = shellbvp.solution._finite_jacobian

    def counting(jac, what, max_evaluations=None):
        wrapped = orig(jac, what, max_evaluations)
        if what != "fun_jac":
            return wrapped

        def counted(*args):
            calls[-1] += 1
            return wrapped(*args)
        return counted

    def probe(*args, **kw):
        calls.append(0)
        return orig_annulus(*args, **kw)

    orig_annulus = shellbvp.liftoff.solve_liftoff_from
    scene = sb.Scene.preset("base")
    cap = sb.solve(scene, delta=0.1125, topology="cap", estimate_error=False)
    line = liftoff_state(cap, "line")
    monkeypatch.setattr(shellbvp.solution, "_finite_jacobian", counting)
    monkeypatch.setattr(shellbvp.liftoff, "solve_liftoff_from", probe)
    res = liftoff_state(cap, "annulus", previous=line)
    assert not res.success and res.status == 4 and "reaches the pole" in res.message
    # two fun_jac calls per Jacobian
    assert len(calls) == 2 and max(calls) <= 2 * 16 + 1, calls
