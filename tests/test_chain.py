"""Contact configurations as chains of regions and junctions, assembled by one class (issue 12).

Every chain and control mode: analytic fun_jac and bc_jac against central
differences (the point-load chain included); layout tables from the
declaration; the states of the hand-written classes the assembler replaced
(commit 1109cdf), solved again to 1e-10.  (Before those classes were deleted,
the assembled fun/fun_jac/bc/bc_jac equalled theirs to 4e-15 at random points.)
"""

import math

import numpy as np
import pytest

import shellbvp as sb
from shellbvp import chain as ch
from shellbvp.configurations.annulus import annulus_chain
from shellbvp.configurations.cap import cap_chain
from shellbvp.configurations.cap_band_cylinder import cap_band_cylinder_chain
from shellbvp.configurations.cap_band_tip import cap_band_tip_chain
from shellbvp.configurations.cap_cylinder import cylinder_chain
from shellbvp.configurations.cap_line_cylinder import cap_line_cylinder_chain
from shellbvp.configurations.cap_line_tip import cap_line_tip_chain
from shellbvp.configurations.line import line_chain
from shellbvp.configurations.line_corner import line_kink_chain
from shellbvp.configurations.point import point_chain
from shellbvp.inflation import system_parameters

EPS = 1e-3
CHAINS = {"cap": lambda L, contact: cap_chain(EPS, L, contact),
          "annulus": lambda L, contact: annulus_chain(EPS, L),
          "line": lambda L, contact: line_chain(EPS, L),
          "point": lambda L, contact: point_chain(1e-12, L),
          "cylinder": lambda L, contact: cylinder_chain(EPS, L, contact),
          "wall_line": lambda L, contact: cap_line_cylinder_chain(EPS, L, contact),
          "wall_band": lambda L, contact: cap_band_cylinder_chain(EPS, L, contact),
          "tip_line": lambda L, contact: cap_line_tip_chain(EPS, L),
          "tip_band": lambda L, contact: cap_band_tip_chain(EPS, L),
          "line_corner": lambda L, contact: line_kink_chain(EPS, L)}
CASES = [("cap", c, m) for c in ("smooth", "paper", "corner", "pinned")
         for m in ("delta", "lambda0", "force", "arclength")] + \
        [(k, "smooth", m) for k in ("annulus", "line", "line_corner") for m in ("delta", "lambda0", "force")] + \
        [("point", "smooth", "delta")] + \
        [(k, c, m) for k in ("cylinder", "wall_line", "wall_band") for c in ("smooth", "paper")
         for m in ("delta", "lambda0", "force", "arclength")] + \
        [(k, "smooth", m) for k in ("tip_line", "tip_band") for m in ("delta", "lambda0", "force", "arclength")]
ARC = (np.array([0.2, 1.0, 0.4]), np.array([0.6, 0.0, 0.8]), np.array([1.0, 0.5, 2.0]))


def central_difference(f, x, h=1e-7):
    cols = []
    for j in range(x.size):
        e = np.zeros(x.size)
        e[j] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=-1)


#: Volume control (a sealed shell: the pressure an unknown, one volume state per region)
SEALED_CASES = [(k, "smooth", "delta") for k in CHAINS] + \
               [("cap", "smooth", m) for m in ("lambda0", "force", "arclength")] + \
               [("cap", "paper", "force"), ("cap", "corner", "delta"), ("line", "smooth", "lambda0"),
                ("cylinder", "paper", "force"), ("wall_line", "smooth", "arclength"), ("tip_band", "smooth", "force")]


def system(kind, contact, control, sealed=False):
    # "corner": the smooth model's cap with a Weierstrass-Erdmann corner at its edge
    # "pinned": the paper's cap with its edge held at the tip's end
    contact_model = {"corner": "smooth", "pinned": "paper"}.get(contact, contact)
    scene = (sb.Scene.preset("balloon", sealed=True, contact=contact_model) if sealed
             else sb.Scene.preset("base", contact=contact_model))
    value = ARC if control == "arclength" else 0.3
    mod = scene.model()
    return ch.ChainBVP(scene, CHAINS[kind](scene.shell_length, contact), control, value, model=mod,
                       par=system_parameters(scene, mod), enclosed_volume=sb.enclosed_volume(scene) if sealed else None)


def state(sysm, rng):
    t = np.linspace(0.0, 1.0, 4)
    y = 0.5 + 0.3 * rng.random((sysm.n, t.size))
    values = dict(ln_Sc=np.log(0.1), ln_S1=np.log(0.05), ln_Sk=np.log(0.02), ln_S2=np.log(0.15), ln_Send=np.log(0.07), chi1=0.9,
                  lambda0=1.02, delta=0.3, pressure=0.13)
    return t, y, sysm.pack(**values)


@pytest.mark.parametrize("kind, contact, control, sealed",
                         [(*c, False) for c in CASES] + [(*c, True) for c in SEALED_CASES])
def test_analytic_jacobians_equal_central_differences(kind, contact, control, sealed):
    sysm = system(kind, contact, control, sealed)
    assert sysm.volume_control == sealed and ("pressure" in sysm.unknowns) == sealed
    t, y, p = state(sysm, np.random.default_rng(2))
    rel = lambda a, b: np.max(np.abs(a - b)) / (1 + np.max(np.abs(b)))  # noqa: E731
    jac = sysm.fun_jac(t, y, p)
    dfdy, dfdp = jac if sysm.k else (jac, None)
    for k in range(t.size):
        assert rel(dfdy[:, :, k], central_difference(lambda v: sysm.fun(t[k:k + 1], v[:, None], p)[:, 0],
                                                     y[:, k])) < 1e-6
        if sysm.k:
            assert rel(dfdp[:, :, k], central_difference(lambda v: sysm.fun(t[k:k + 1], y[:, k:k + 1], v)[:, 0],
                                                         p)) < 1e-6
    ya, yb = y[:, 0], y[:, -1]
    A, B, *P = sysm.bc_jac(ya, yb, p)
    assert sysm.bc(ya, yb, p).size == sysm.n + sysm.k == sysm.n_conditions == A.shape[0]
    assert rel(A, central_difference(lambda v: sysm.bc(v, yb, p), ya)) < 1e-6
    assert rel(B, central_difference(lambda v: sysm.bc(ya, v, p), yb)) < 1e-6
    if sysm.k:
        assert rel(P[0], central_difference(lambda v: sysm.bc(ya, yb, v), p)) < 1e-6


@pytest.mark.parametrize("kind, sealed", [("tip_line", False), ("cap", True)])
def test_fun_kept_results_are_those_of_its_arguments(kind, sealed):
    """fun's last results are reused for equal arguments only (values, not identity: an array
    changed in place is evaluated again), and fun_jac with them equals fun_jac without, bit for bit."""
    sysm = system(kind, "smooth", "delta", sealed)
    t, y, p = state(sysm, np.random.default_rng(3))
    fresh = ch.ChainBVP(sysm.scene, sysm.chain, "delta", 0.3, par=sysm.par, enclosed_volume=sysm.enclosed_volume)
    f0 = sysm.fun(t, y, p)
    assert np.array_equal(sysm.fun(t, y.copy(), p.copy()), f0)  # equal values: kept
    f0[:] = 0.0  # a caller changing its result does not change what is kept
    assert np.array_equal(sysm.fun(t, y, p), fresh.fun(t, y, p))
    y2 = y.copy()
    y2[0, 1] += 1e-3  # changed in place: evaluated again
    assert np.array_equal(sysm.fun(t, y2, p), fresh._fun(t, y2, p)[0])
    p2 = p.copy()
    p2[0] += 1e-3
    assert np.array_equal(sysm.fun(t, y2, p2), fresh._fun(t, y2, p2)[0])
    sysm.fun(t, y, p)  # kept at y: fun_jac takes the right-hand sides from it
    with_kept = sysm.fun_jac(t, y, p)
    fresh.__dict__.pop("_fun_cache", None)  # nothing kept: fun_jac evaluates them
    without = fresh.fun_jac(t, y, p)
    for a, b in zip(with_kept, without):
        assert np.array_equal(a, b)


def test_layout_table_is_generated_from_the_declaration():
    text = annulus_chain(EPS, 1.5).layout()
    assert "y[0:6]  region 0 free" in text and "y[6:8]  region 1 contact" in text and "y[8:14]" in text
    assert "[3:8]  Edge(kc=1, kf=0" in text and "[13:16]  Rim(k=2)" in text


def test_control_the_chain_cannot_take_is_refused():
    scene = sb.Scene.preset("base")
    with pytest.raises(ValueError, match="only delta"):
        ch.ChainBVP(scene, point_chain(1e-12, scene.shell_length), "force", 0.3)
    with pytest.raises(ValueError, match="arclength"):
        ch.ChainBVP(scene, line_chain(EPS, scene.shell_length), "arclength", ARC)


# -- regression: the states of the hand-written classes (commit 1109cdf), to 1e-10 ---------------------
def _reference():
    import json
    from pathlib import Path

    data = json.loads((Path(__file__).parent / "data" / "regression_states.json").read_text())
    return data["states"]


@pytest.mark.parametrize("ref", _reference(), ids=lambda r: f"{r['preset']}-{r['contact']}-{r['control']}"
                         f"{r['value']}-{r['topology']}")
def test_states_equal_those_before_the_assembler(ref):
    """benchmarks/regression_reference.py wrote these at 1109cdf, before the chain assembler."""
    scene = sb.Scene.preset(ref["preset"], contact=ref["contact"])
    s = sb.solve(scene, **{ref["control"]: ref["value"]}, topology=ref["topology"], tol=1e-8, estimate_error=False)
    assert s.success == ref["success"] and s.topology == ref["result_topology"], s.message
    if not ref["success"]:
        return  # e.g. an annulus closing onto the pole: a degenerate state, its numbers are not reproducible
    for key in ("force", "delta", "lambda0", "Sc", "energy"):
        assert getattr(s, key) == pytest.approx(ref[key], rel=1e-10, abs=1e-14, nan_ok=True), key
    if ref["result_topology"] in ("line", "annulus"):  # (the file holds Sc for a cap: it had no S1)
        assert s.S1 == pytest.approx(ref["S1"], rel=1e-10, abs=1e-14)


def test_results_round_trip_through_pickle():
    """A Solution holds its system but not the generated module (code): it is loaded again from
    the code cache on unpickling, so results can be returned by worker processes."""
    import pickle

    for scene, delta in ((sb.Scene.preset("base"), 0.3), (sb.Scene.preset("base"), 0.05),
                         (sb.Scene.preset("flat"), 0.01)):
        s = sb.solve(scene, delta=delta)
        back = pickle.loads(pickle.dumps(s))
        assert back.topology == s.topology and back.force == s.force and back.scene == s.scene
        np.testing.assert_array_equal(back.profile()["z"], s.profile()["z"])
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2])
    back = pickle.loads(pickle.dumps(c))
    np.testing.assert_array_equal(back.force, c.force)
    assert back.solutions[1].profile()["r"].size == c.solutions[1].profile()["r"].size


def test_repr_shows_the_layout():
    scene = sb.Scene.preset("base")
    text = repr(ch.ChainBVP(scene, cap_chain(EPS, scene.shell_length), "delta", 0.2))
    assert "ChainBVP(delta=0.2)" in text and "ContactPole(k=0)" in text and "y[2:8]  region 1 free" in text


def test_a_run_that_does_not_converge_reports_nan_numbers_not_its_last_iterate():
    from shellbvp.state import make_system, solve_from, warm_guess

    scene = sb.Scene.preset("base")
    good = sb.solve(scene, delta=0.2, estimate_error=False)
    sysm = make_system(scene, "delta", 0.6, good.system.eps)  # far from the guess, few nodes allowed
    bad = solve_from(sysm, warm_guess(sysm, good), tol=1e-10, max_nodes=20)
    assert not bad.success and bad.status not in (0, 4) and bad.message
    assert bad.delta == 0.6  # prescribed: known
    for key in ("force", "lambda0", "Sc", "energy", "ring_force", "pressure_min"):
        assert np.isnan(getattr(bad, key)), key
    assert not bad.valid and bad.y.shape[0] == sysm.n  # the last iterate stays for inspection


def test_the_diagnosis_points_are_the_mesh_and_its_midpoints_sorted_without_repeats():
    from shellbvp.diagnosis import _nodes_and_midpoints

    x = np.array([0.0, 0.1, 0.25, 0.7, 1.0])
    np.testing.assert_array_equal(_nodes_and_midpoints(x), np.unique(np.r_[x, 0.5 * (x[1:] + x[:-1])]))
    tiny = np.array([0.0, 0.5, np.nextafter(0.5, 1.0), 1.0])  # an interval of one ulp: its midpoint is a node
    np.testing.assert_array_equal(_nodes_and_midpoints(tiny), np.unique(np.r_[tiny, 0.5 * (tiny[1:] + tiny[:-1])]))


def test_the_pole_height_is_kept_but_not_across_parameters():
    s = sb.solve(sb.Scene.preset("balloon", sealed=True), delta=0.1, estimate_error=False)
    sysm = s.system
    h = sysm.pole_height
    assert sysm.__dict__["_pole_height"] == h
    other = sysm.at(s.p * 1.0)
    assert "_pole_height" not in other.__dict__ or other.par is sysm.par
    assert other.pole_height == float(other.model.reference_shell(0.0, other.par)["Z"]) + other._param("pole_rise")



def test_diagnosis_median_is_numpys():
    from shellbvp.diagnosis import _median

    rng = np.random.default_rng(7)
    for n in (1, 2, 3, 4, 407, 408):
        a = np.abs(rng.standard_normal(n)) * 10.0 ** rng.uniform(-8, 8, n)
        assert _median(a) == float(np.median(a))
    assert math.isnan(_median(np.array([1.0, np.nan, 2.0]))) and math.isnan(_median(np.empty(0)))


def test_a_solution_has_fixed_fields_and_one_way_to_fail():
    """Every field is declared: a misspelt name is refused, not stored beside the real one;
    a search without any state is built by ``failure`` with every state number NaN but the
    prescribed one."""
    from shellbvp.solution import STATE_NUMBERS, failure

    sol = sb.solve(sb.Scene.preset("base"), delta=0.2, estimate_error=False)
    with pytest.raises(AttributeError):
        sol.forse = 1.0
    assert math.isnan(sol.force_error) and sol.error_method == ""  # declared, not estimated
    scene = sb.Scene.preset("base", sealed=True)
    fail = failure(5, "no guess converged", scene=scene, control="force", value=0.3)
    assert fail.force == 0.3 and not fail.success and not fail.valid and fail.message
    assert all(math.isnan(getattr(fail, k)) for k in STATE_NUMBERS if k != "force")
    assert math.isnan(fail.pressure)  # an unknown under volume control
    with pytest.raises(ValueError, match="status must be that of a failure"):
        failure(0, "", scene=scene, control="delta", value=0.1)


def test_a_solution_is_built_once_and_holds_no_other_state():
    """A state is never written after it is built: what a later step adds makes a new state
    (``with_``), and no state holds another (a lifted state keeps the numbers of the cap it
    replaced, not the cap)."""
    import dataclasses

    from shellbvp.solution import Solution

    sol = sb.solve(sb.Scene.preset("base"), delta=0.1)  # a line replacing the cap that pulls
    assert sol.topology == "line" and sol.cap_state["force"] > 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        sol.force = 1.0
    flagged = sol.with_(flags=["checked"])
    assert flagged.flags == ["checked"] and sol.flags == [] and flagged.force == sol.force
    with pytest.raises(TypeError):
        sol.with_(forse=1.0)
    values = [getattr(sol, f.name) for f in dataclasses.fields(sol)]
    values += list(sol.cap_state.values())
    assert not any(isinstance(v, Solution) for v in values)


def test_every_configuration_is_registered_once_with_its_system():
    """The registry names every configuration a state can have; each builds its own system
    (the chain it declares, the tip tabulated) and refuses what it does not allow in one line."""
    from shellbvp import configurations as cf

    assert cf.CONFIGURATION_NAMES == tuple(cf.CONFIGURATIONS) and len(set(cf.CONFIGURATION_NAMES)) == 10 + 16
    assert set(cf.names("wall")) == {"cap+line(cylinder)", "cap+band(cylinder)", "cap+cylinder"}
    assert cf.ASKED[0] == "auto" and "cap+line(tip)" not in cf.ASKED
    scene = sb.Scene.preset("base")
    closed = sb.Scene(closed=True, tip=sb.SphereTip(), rho=0.5, beta=1e-2)  # on a substrate: two contacts
    for name, conf in cf.CONFIGURATIONS.items():
        sysm = conf.system(closed if conf.family == "closed" else scene, "delta", 0.2, EPS)
        assert sysm.topology == name and sysm.tip_A.size > 0
    with pytest.raises(ValueError, match="a closed shell's on a substrate"):
        cf.configuration("closed-cap-cap").system(scene, "delta", 0.2, EPS)
    with pytest.raises(ValueError, match="a rimmed shell's"):
        cf.configuration("cap").system(closed, "delta", 0.2, EPS)
    with pytest.raises(ValueError, match="topology must be one of"):
        cf.configuration("cap+line(tipp)")
    with pytest.raises(ValueError, match="registered already"):
        cf.register(cf.Configuration("cap", "cap", cap_chain))
    with pytest.raises(ValueError, match="needs contact='smooth'"):
        cf.configuration("line").system(sb.Scene.preset("base", contact="paper"), "delta", 0.2, EPS)
    with pytest.raises(ValueError, match="control must be one of"):
        cf.configuration("point").system(scene, "force", 0.2, EPS)
    with pytest.raises(ValueError, match="needs contact='smooth'"):  # before any solve
        sb.solve(sb.Scene.preset("base", contact="paper"), delta=0.9, topology="cap+band(cylinder)")


def test_every_switch_joins_registered_configurations_on_a_field_of_their_states():
    import dataclasses

    from shellbvp import configurations as cf
    from shellbvp.solution import Solution
    from shellbvp.switches import MEASURED

    fields = {f.name for f in dataclasses.fields(Solution)}
    for sw in cf.SWITCHES:
        a, b = sorted(sw.between)
        assert {a, b} <= set(cf.CONFIGURATION_NAMES) and sw.measured_on in sw.between
        assert set(sw.criteria) <= fields and sw.sign in (1.0, -1.0)
        assert cf.switch_between(a, b) is sw is cf.switch_between(b, a)
        # the family measured on says how its state is found at and near a point
        state_at, solved_at = MEASURED[cf.configuration(sw.measured_on).family]
        assert callable(state_at) and callable(solved_at)
    assert cf.switch_between("cap", "cap") is None and cf.switch_between("point", "line") is None
