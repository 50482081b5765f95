"""Curves by continuation, their HDF5 files (issue: curves, HDF5, CLI)."""

import json
from unittest import mock

import h5py
import numpy as np
import pytest

import shellbvp as sb
from shellbvp.io import POINT_FIELDS


@pytest.fixture(scope="module")
def base_curve():
    return sb.curve(sb.Scene.preset("base"), delta_max=0.5)


def test_adaptive_base_curve_reaches_delta_max_with_increasing_force(base_curve):
    c = base_curve
    assert c.complete and not c.interrupted and "delta_max" in c.stop_reason
    assert c.delta[-1] == pytest.approx(0.5) and len(c) >= 20
    assert np.all(np.diff(c.delta) > 0)
    assert np.all(np.diff(c.force) > 0) and np.all(c.force > 0)
    assert np.all(c.status == 0)
    # the small-delta region is resolved: points below 0.01 with a shrinking cap
    assert c.delta[0] <= 0.01 and c.Sc[0] < 1e-10
    # error estimates and diagnostics are kept per point
    assert np.all(np.isfinite(c.force_error)) and np.max(c.force_error) < 1e-6
    assert np.max(c.force_defect) < 1e-6
    # energy identity along the curve (finite differences between points, O(h^2))
    assert np.nanmax(np.abs(c.energy_residual)) < 2e-3


def test_paper_model_curve_shows_the_energy_identity_gap():
    c = sb.curve(sb.Scene.preset("base", contact="paper"), delta_max=0.5, estimate_error=False)
    assert c.complete
    res = c.energy_residual
    assert np.all(res[len(res) // 2:] > 0.1)  # ~0.13-0.15: SPEC 2b's 0.11-0.15


def test_requested_deltas_are_computed_exactly():
    deltas = [0.05, 0.1, 0.2, 0.3]
    c = sb.curve(sb.Scene.preset("prolate2"), deltas=deltas)
    assert c.complete
    np.testing.assert_allclose(c.delta, deltas)
    single = sb.solve(sb.Scene.preset("prolate2"), delta=0.2)
    assert c.force[2] == pytest.approx(single.force, abs=1e-8)


def test_depths_a_hair_apart_do_not_blow_up_the_next_step():
    """Depths of two curves merged come in pairs 3e-10 apart: the secant through such a pair,
    extrapolated 6e7 times its length, made the guess at the next depth need twice the mesh
    (191 nodes among 91-98; at tol 1e-5 half of a 47-depth curve's steps failed)."""
    deltas = [0.16726326494928925, 0.16726326525383617, 0.18683651542859195, 0.18683651598855072,
              0.20546494944470345, 0.20546494979551597]
    c = sb.curve(sb.Scene.preset("base-xi0"), deltas=deltas, topology="cap", tol=1e-5, estimate_error=False)
    assert c.complete
    nodes = np.asarray(c.points["nodes"])
    assert nodes.max() <= 1.25 * np.median(nodes), f"meshes {nodes.tolist()}"


def test_secant_ratio_is_bounded():
    from types import SimpleNamespace as S

    from shellbvp.solution import SECANT_MAX_RATIO, secant_ratio

    assert secant_ratio(0.3, S(delta=0.2), S(delta=0.1)) == pytest.approx(1.0)
    assert secant_ratio(0.2 + 0.99 * SECANT_MAX_RATIO * 0.1, S(delta=0.2), S(delta=0.1)) == pytest.approx(
        0.99 * SECANT_MAX_RATIO)
    assert secant_ratio(0.2 + 1.01 * SECANT_MAX_RATIO * 0.1, S(delta=0.2), S(delta=0.1)) is None
    assert secant_ratio(0.3, S(delta=0.2), S(delta=0.2 - 1e-10)) is None  # 1e9 times a hair: no secant
    assert secant_ratio(0.3, S(delta=0.2), S(delta=0.2)) is None and secant_ratio(0.3, S(delta=0.2), None) is None


def test_the_quadratic_predictor_is_nearer_the_next_state_than_the_secant():
    """Natural continuation guesses from the quadratic through the last three states: on base
    (steps 0.02, and unequal ones) its guess is 3-5 times nearer the converged next state than
    the secant's, in the states and in the unknowns."""
    from shellbvp.steps import quadratic_guess as _quadratic, secant_guess as _secant
    from shellbvp.solution import secant_ratio
    from shellbvp.state import system_like

    for deltas in ([0.2, 0.22, 0.24, 0.26], [0.2, 0.21, 0.23, 0.26]):
        c = sb.curve(sb.Scene.preset("base"), deltas=deltas, topology="cap", estimate_error=False)
        s3, s2, s1, nxt = c.solutions
        sysm = system_like(s1, "delta", nxt.delta, s1.system.eps)
        want = sysm.pack(ln_Sc=nxt.p[0], lambda0=nxt.lambda0, delta=nxt.delta)
        errors = []
        for x, y, p in (_quadratic(sysm, (s1, s2, s3), nxt.delta),
                        _secant(sysm, s1, s2, secant_ratio(nxt.delta, s1, s2))):
            errors.append((np.max(np.abs(y - nxt.sol(x))), np.max(np.abs(p - want))))
        (qy, qp), (ly, lp) = errors
        assert qy < 0.4 * ly and qp < 0.4 * lp, errors


def test_the_quadratic_predictor_keeps_the_secants_guards():
    import dataclasses

    from shellbvp.solution import SECANT_MAX_RATIO
    from shellbvp.steps import quadratic_guess as _quadratic

    c = sb.curve(sb.Scene.preset("base"), deltas=[0.2, 0.22, 0.24], topology="cap", estimate_error=False)
    s3, s2, s1 = c.solutions
    states = (s1, s2, s3)
    assert _quadratic(s1.system, states, 0.26) is not None
    assert _quadratic(s1.system, states, 0.23) is None  # not beyond the newest state
    assert _quadratic(s1.system, (s1, s3, s2), 0.26) is None  # not monotone
    assert _quadratic(s1.system, states, 0.24 + 1.01 * SECANT_MAX_RATIO * 0.02) is None  # too far
    assert _quadratic(s1.system, (s1, s2, None), 0.26) is None
    other = dataclasses.replace(s3, contact_edge="corner")  # another configuration
    assert _quadratic(s1.system, (s1, s2, other), 0.26) is None
    with sb.options(quadratic_predictor=False):
        assert _quadratic(s1.system, states, 0.26) is None


def test_a_steps_system_is_the_previous_one_at_the_new_depth():
    """A continuation step takes the previous state's system with the new delta (no rebuild):
    the same residuals, bit for bit, as a system built anew; the previous one is unchanged."""
    from shellbvp.corner import edge_model
    from shellbvp.state import make_system, system_like

    s = sb.solve(sb.Scene.preset("base"), delta=0.2, topology="cap", estimate_error=False)
    s.system.fun(s.x, s.y, s.p)  # leaves a result in its cache
    step = system_like(s, "delta", 0.25, s.system.eps)
    fresh = make_system(s.scene, "delta", 0.25, s.system.eps, edge_model(s))
    assert step is not s.system and s.system.value == 0.2 and step.value == 0.25
    assert "_fun_cache" not in step.__dict__
    ya, yb = s.y[:, 0], s.y[:, -1]
    np.testing.assert_array_equal(step.bc(ya, yb, s.p), fresh.bc(ya, yb, s.p))
    np.testing.assert_array_equal(step.fun(s.x, s.y, s.p), fresh.fun(s.x, s.y, s.p))
    assert not np.array_equal(step.bc(ya, yb, s.p), s.system.bc(ya, yb, s.p))  # delta enters the edge
    arc = system_like(s, "arclength", (np.zeros(3), np.ones(3), np.ones(3)), s.system.eps)
    assert arc.control == "arclength" and arc is not s.system


def test_a_volume_controlled_system_is_not_copied_with_another_value():
    from shellbvp.state import make_system

    sysm = make_system(sb.Scene.preset("balloon", sealed=True), "delta", 0.2, 1e-8)
    assert sysm.volume_control
    with pytest.raises(ValueError, match="volume-controlled"):
        sysm.with_value(0.3)


def test_fold_in_lambda0_is_passed_by_pseudo_arclength():
    """On the dome, lambda0(delta) has a minimum near delta ~ 0.1: a fold for lambda0
    control, which the arclength continuation in (delta, lambda0, F) passes."""
    c = sb.curve(sb.Scene.preset("dome"), delta_max=0.3, estimate_error=False)
    assert c.complete and np.all(c.status == 0)
    lam = c.lambda0[np.isfinite(c.lambda0)]  # NaN at point-load states (smallest delta)
    i = int(np.argmin(lam))
    assert 0 < i < lam.size - 1  # an interior turning point of lambda0
    assert np.all(np.diff(c.delta) > 0) and np.all(np.diff(c.force) > 0)


def test_stopping_rules():
    c = sb.curve(sb.Scene.preset("base"), delta_max=0.5, force_max=0.3, estimate_error=False)
    assert c.complete and "force_max" in c.stop_reason
    assert c.force[-1] >= 0.3 and c.force[-2] < 0.3
    c = sb.curve(sb.Scene.preset("base"), delta_max=0.5, max_steps=3, estimate_error=False)
    assert not c.complete and "max_steps" in c.stop_reason and len(c) >= 1


def test_a_gent_curve_stops_where_the_material_locks():
    """Gent's energy diverges as (I1 - 3)/Jm -> 1: the curve stops with that reason once the
    ratio passes legs.GENT_LOCK (Jm 0.4 ran 400 steps into max_steps at delta 0.85)."""
    from shellbvp.legs import GENT_LOCK, gent_lock_ratio

    c = sb.curve(sb.Scene.preset("base", material=sb.Gent(0.03)), delta_max=1.0, estimate_error=False)
    assert not c.complete and c.stop_reason.startswith("the Gent material locks")
    ratios = [gent_lock_ratio(s) for s in c.solutions[-2:]]
    assert ratios[0] < GENT_LOCK <= ratios[1] < 1
    assert c.delta[-1] < 0.4 and c.force[-1] > 4 * np.interp(c.delta[-1] / 2, c.delta, c.force)
    assert np.all(c.valid) and np.all(np.diff(c.force) > 0)


def test_hdf5_round_trip(base_curve, tmp_path):
    path = tmp_path / "c.h5"
    base_curve.to_hdf5(path)
    back = sb.read_curve(path)
    assert back.scene == base_curve.scene
    for k in POINT_FIELDS:
        np.testing.assert_array_equal(back.points[k], base_curve.points[k])
    assert back.flags == base_curve.flags and back.stop_reason == base_curve.stop_reason
    assert back.complete and back.settings["tol"] == base_curve.settings["tol"]
    with h5py.File(path) as f:  # NXdata conventions for generic viewers
        g = f["entry/curve"]
        assert g.attrs["NX_class"] == "NXdata" and g.attrs["signal"] == "force"
        assert list(g.attrs["axes"]) == ["delta"]
        assert json.loads(g.attrs["scene"])["rho"] == 0.2
        assert "energy_residual" in g and "profiles" not in g
    with pytest.raises(FileExistsError):
        base_curve.to_hdf5(path)
    base_curve.to_hdf5(path, overwrite=True, profiles=True, units={"R_L": 1e-3, "mu_H": 50.0})
    with h5py.File(path) as f:
        g = f["entry/curve"]
        assert len(g["profiles"]) == len(base_curve)
        np.testing.assert_allclose(g["force_N"][()], 50.0 * 1e-3 * base_curve.force)
    assert not list(tmp_path.glob(".*.tmp"))  # no temporary files left behind


def test_curve_settings_are_a_frozen_record_and_the_file_keeps_them(base_curve, tmp_path):
    """The curve's settings are read from a frozen record; the curve (and its file) keeps them as
    one dict, with what the run learned beside them (issue 57)."""
    import dataclasses

    from shellbvp.curve_settings import CurveSettings

    st = CurveSettings.from_dict(base_curve.settings)
    with pytest.raises(dataclasses.FrozenInstanceError):
        st.tol = 1e-3
    assert st.mode == "adaptive" and st.solver == dict(tol=st.tol, max_nodes=st.max_nodes, bc_tol=1e-10)
    assert {k: base_curve.settings[k] for k in st.to_dict()} == st.to_dict()
    assert {"wall_time", "after_last_point_s", "topology_switches"} <= set(base_curve.settings) - set(st.to_dict())
    base_curve.to_hdf5(tmp_path / "c.h5")
    assert CurveSettings.from_dict(sb.read_curve(tmp_path / "c.h5").settings) == st
    with pytest.raises(ValueError, match="lack tol"):
        CurveSettings.from_dict({k: v for k, v in st.to_dict().items() if k != "tol"})


def test_user_scene_round_trips_through_hdf5(tmp_path):
    scene = sb.Scene.preset("base", material=sb.StrainEnergy(
        "(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2"))
    c = sb.curve(scene, deltas=[0.1, 0.15])
    c.to_hdf5(tmp_path / "u.h5")
    back = sb.read_curve(tmp_path / "u.h5")
    assert back.scene == scene and back.scene.structure() == scene.structure()


def test_interrupted_curve_keeps_finished_points(tmp_path):
    seen = []

    def stop_after_three(curve, sol):
        seen.append(sol.delta)
        if len(seen) == 3:
            raise KeyboardInterrupt

    c = sb.curve(sb.Scene.preset("base"), delta_max=0.5, callback=stop_after_three, estimate_error=False)
    assert c.interrupted and not c.complete and len(c) == 3
    c.to_hdf5(tmp_path / "partial.h5")
    back = sb.read_curve(tmp_path / "partial.h5")
    assert back.interrupted and len(back) == 3 and sorted(back.delta) == sorted(seen)


def test_iter_curve_yields_the_states_that_curve_records(base_curve):
    """The curve is a generator of states: iterating it gives what ``curve`` records (the
    located switch last), and its result is the same curve, number for number."""
    run = sb.iter_curve(sb.Scene.preset("base"), delta_max=0.5)
    states = list(run)
    c = run.result()
    assert len(states) == len(c) == len(base_curve)
    assert sorted(s.delta for s in states) == list(c.delta)
    np.testing.assert_array_equal(c.force, base_curve.force)
    np.testing.assert_array_equal(c.force_error, base_curve.force_error)
    assert c.stop_reason == base_curve.stop_reason and c.complete
    # the switch cap -> line is located after the legs, and yielded last
    (switch,) = c.settings["topology_switches"]
    assert states[-1].delta == pytest.approx(switch["delta"], abs=1e-12)


def test_iter_curve_checks_its_arguments_before_any_solve():
    with mock.patch("shellbvp.state.solve_from") as solve_from:
        with pytest.raises(ValueError, match="delta_max"):
            sb.iter_curve(sb.Scene.preset("base"), delta_max=-1)
    solve_from.assert_not_called()


def test_leaving_iter_curve_early_keeps_the_states_seen():
    run = sb.iter_curve(sb.Scene.preset("base"), delta_max=0.5, estimate_error=False)
    seen = []
    for sol in run:
        seen.append(sol.delta)
        if len(seen) == 4:
            break
    c = run.result()
    assert c.interrupted and not c.complete and c.stop_reason == "interrupted"
    assert sorted(c.delta) == sorted(seen)
    assert run.result() is c  # finished once


@pytest.mark.parametrize("bad", ["missing.h5", "foreign.h5", "corrupt.h5"])
def test_read_curve_rejects_bad_files(tmp_path, bad):
    path = tmp_path / bad
    if bad == "foreign.h5":
        with h5py.File(path, "w") as f:
            f["x"] = [1, 2, 3]
    elif bad == "corrupt.h5":
        path.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    with pytest.raises(ValueError, match=str(path.name)):
        sb.read_curve(path)


@pytest.mark.parametrize("kwargs,match", [
    (dict(delta_max=0.0), "delta_max"),
    (dict(delta_max=-1), "delta_max"),
    (dict(force_max=-1), "force_max"),
    (dict(deltas=[]), "deltas"),
    (dict(deltas=[0.1, -0.2]), "deltas"),
    (dict(max_steps=0), "max_steps"),
])
def test_curve_bad_input(kwargs, match):
    kw = dict(delta_max=0.5)
    kw.update(kwargs)
    with pytest.raises(ValueError, match=match):
        sb.curve(sb.Scene.preset("base"), **kw)


def test_switch_search_stops_where_the_secant_puts_the_root_within_its_tolerance():
    """_regula_falsi (Illinois) on a smooth criterion: it stops at a state with f >= 0 that the
    secant puts within 1e-8 (1 + delta) of the root -- before the bracket is 1e-7 wide, which
    the state it returns already satisfies (f = (d - r) e^(d - r): Illinois's iterates)."""
    import math

    from shellbvp.switches import regula_falsi as _regula_falsi

    root = 0.1117
    calls = []

    def f(d):
        return (root - d) * math.exp(d - root)  # decreasing: f >= 0 below the root

    def solve_at(d, near):
        calls.append(d)
        return {"d": d}, f(d)

    best = _regula_falsi(0.1, f(0.1), {"d": 0.1}, 0.1125, f(0.1125), {"d": 0.1125}, solve_at)
    assert best["d"] <= root and root - best["d"] < 1e-8 * (1 + root)
    assert calls[-1] == best["d"], calls  # it stopped at the state it returns
    stopped = len(calls)
    calls.clear()
    with mock.patch("shellbvp.switches._secant_distance", return_value=math.inf):  # the bracket alone
        assert _regula_falsi(0.1, f(0.1), {"d": 0.1}, 0.1125, f(0.1125), {"d": 0.1125}, solve_at) is not None
    assert len(calls) > stopped, (stopped, calls)


def test_the_plot_turn_is_the_angle_of_the_plotted_curve_whatever_the_force_scale():
    """The adaptive curve's refusal of a step that bends the plotted F(delta) too much
    (legs.plot_turn) measures the angle on axes scaled by delta_max and the largest
    |F|: a force peak of a thin dome (F ~ 1e-4) turns as much as one of F ~ 1."""
    from types import SimpleNamespace as St

    from shellbvp.legs import MAX_PLOT_TURN, plot_turn

    for f in (1.0, 1e-4):
        up, top, down = St(delta=0.15, force=0.5 * f), St(delta=0.2, force=1.0 * f), St(delta=0.25, force=0.5 * f)
        # chords (0.1, 0.5) and (0.1, -0.5) on the scaled axes
        assert plot_turn(up, top, down, 0.5, f) == pytest.approx(2 * np.arctan2(0.5, 0.1), rel=1e-12)
        assert plot_turn(up, top, down, 0.5, f) > MAX_PLOT_TURN
        straight = St(delta=0.25, force=1.5 * f)
        assert plot_turn(up, top, straight, 0.5, f) == pytest.approx(0.0, abs=1e-7)
    # with F's own unit (as in the arclength's (delta, lambda0, F)) the thin dome's peak is a turn
    # of 0.002 rad: its chords are nearly parallel
    up, top, down = St(delta=0.15, force=0.5e-4), St(delta=0.2, force=1e-4), St(delta=0.25, force=0.5e-4)
    assert plot_turn(up, top, down, 1.0, 1.0) == pytest.approx(2e-3, rel=1e-3)


def test_a_curve_file_with_si_columns_plots_in_mm_and_mn(tmp_path):
    """The lab scales a file was written with come back with it, survive a rewrite, and its plot
    is in mm and mN (issue 45, item 3): a nondimensional file stays nondimensional."""
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    from shellbvp.plotting import plot_curves

    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    c.to_hdf5(tmp_path / "si.h5", units={"R_L": 0.3e-3, "mu_H": 52.0})
    back = sb.read_curve(tmp_path / "si.h5")
    assert back.units == {"R_L": 0.3e-3, "mu_H": 52.0}
    back.to_hdf5(tmp_path / "again.h5")
    assert sb.read_curve(tmp_path / "again.h5").units == back.units
    ax = plot_curves([back])
    assert ax.get_xlabel() == "pole displacement (mm)" and ax.get_ylabel() == "force (mN)"
    x, y = ax.lines[0].get_data()
    np.testing.assert_allclose(x, back.delta * 0.3, rtol=1e-12)                  # mm
    np.testing.assert_allclose(y, back.force * 52.0 * 0.3e-3 * 1e3, rtol=1e-12)  # mN
    c.to_hdf5(tmp_path / "nondim.h5")
    assert sb.read_curve(tmp_path / "nondim.h5").units is None
    assert "R_L" in plot_curves([sb.read_curve(tmp_path / "nondim.h5")]).get_xlabel()
