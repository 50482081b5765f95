"""Contact on the indenter's cylinder (issue 12): the region's generated equations, the
tip | cylinder junction, and the cap+cylinder configuration.

The scene: the Lepidium fit preset (gamma 2.5, rho 1/3) with beta = 1e-3, whose single
cap passes through the indenter's side from delta ~1.14 and reaches the tip's end at
delta ~1.32 (issue 12).
"""

import dataclasses
import math

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import shellbvp as sb
from shellbvp.cylinder import wall_contact_suspected, wall_state

SCENE = sb.Scene.preset("fit", beta=1e-3)


@pytest.fixture(scope="module")
def state():
    return sb.solve(SCENE, delta=1.25, topology="cap+cylinder", tol=1e-8)


def test_cylinder_profile_is_the_indenter_side():
    """r = rho A(omega_max), phi = pi/2, kappa_s = 0, kappa_theta = 1/r, and z climbs the wall
    with omega at unit speed (in units of rho)."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    rho, w0 = SCENE.rho, mod.OMEGA_MAX
    assert w0 == pytest.approx(math.pi / 2, abs=1e-15)
    S = np.array([0.25, 0.3, 0.4])
    omega = w0 + np.array([0.0, 0.2, 0.5])
    y = np.vstack([rho * omega / S, np.array([1.1, 1.3, 0.9])])
    f = mod.cylinder_profile(S, y, par)
    np.testing.assert_allclose(f["r"], rho, rtol=1e-15)
    np.testing.assert_allclose(f["phi"], math.pi / 2, rtol=1e-15)
    np.testing.assert_allclose(f["kappa_s"], 0.0, atol=1e-15)
    np.testing.assert_allclose(f["kappa_theta"], 1 / rho, rtol=1e-14)
    np.testing.assert_allclose(f["z"], rho * (1 + omega - w0), rtol=1e-14)  # from the apex; sphere B(w0) = 1


def test_tension_is_constant_along_the_cylinder():
    """On a straight wall (r constant, kappa_s = 0) the tangential balance is tau_s' = 0: an
    independent check of the generic contact derivation specialised to the cylinder."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    S0, S1 = 0.2, 0.35
    y0 = [SCENE.rho * (mod.OMEGA_MAX + 0.01) / S0, 1.4]
    sol = solve_ivp(lambda S, y: mod.cylinder_rhs(np.array([S]), y[:, None], par)[:, 0] / S, (S0, S1), y0,
                    rtol=1e-11, atol=1e-13, dense_output=True)
    assert sol.success
    S = np.linspace(S0, S1, 9)
    tau = mod.cylinder_profile(S, sol.sol(S), par)["tau_s"]
    ls = sol.sol(S)[1]
    assert np.ptp(ls) > 0.05  # the stretch does change along the wall
    np.testing.assert_allclose(tau, tau[0], rtol=1e-8)


def test_tip_end_condition_is_the_jump_of_lambda_s_dU_dlambda_s_minus_U():
    """tip_end_res against [ls U_ls - U] written out here from the Mooney-Rivlin energy and
    the bending energy (beta/2) m^2, m = ls^2 ks + lt^2 kt - ksR - ktR (not from the DAG)."""
    mod = SCENE.model()
    par = SCENE.parameters(mod)
    rho, alpha, beta, gamma = SCENE.rho, SCENE.material.alpha, SCENE.beta, SCENE.gamma
    ls, lt, ks, kt, ksR, ktR = sp.symbols("ls lt ks kt ksR ktR")
    I1 = ls**2 + lt**2 + 1 / (ls * lt) ** 2
    I2 = 1 / ls**2 + 1 / lt**2 + ls**2 * lt**2
    U = ((1 - alpha) * (I1 - 3) + alpha * (I2 - 3)) / 2 + beta / 2 * (ls**2 * ks + lt**2 * kt - ksR - ktR) ** 2
    H = sp.lambdify((ls, lt, ks, kt, ksR, ktR), ls * sp.diff(U, ls) - U)
    rng = np.random.default_rng(3)
    for _ in range(5):
        S = rng.uniform(0.15, 0.5)
        ls_t, ls_w = rng.uniform(0.8, 2.5, 2)
        off = rho * mod.OMEGA_MAX / S + rng.uniform(-0.1, 0.1)  # omega off the end: the first two rows
        res = mod.tip_end_res(S, np.array([off, ls_t]), np.array([off, ls_w]), par)
        np.testing.assert_allclose(res[:2], off - rho * mod.OMEGA_MAX / S, rtol=1e-13)
        chi = rho * mod.OMEGA_MAX / S  # at the end: the third row
        res = mod.tip_end_res(S, np.array([chi, ls_t]), np.array([chi, ls_w]), par)
        ref = mod.reference_shell(np.array([S]), par)
        R, ksR_, ktR_ = ref["R"][0], ref["kappa_s"][0], ref["kappa_theta"][0]
        lt_ = rho / R  # at omega_max on the sphere and on the cylinder r = rho
        expect = H(ls_t, lt_, 1 / rho, 1 / rho, ksR_, ktR_) - H(ls_w, lt_, 0.0, 1 / rho, ksR_, ktR_)
        assert res[2] == pytest.approx(expect, rel=1e-12, abs=1e-13), gamma


def test_cap_passing_through_the_side_is_replaced_by_contact_with_the_wall(state):
    cap = sb.solve(SCENE, delta=1.25, topology="cap", tol=1e-8, estimate_error=False)
    assert cap.success and not cap.valid and wall_contact_suspected(cap)
    assert any("passes through the indenter" in f for f in cap.flags)
    auto = sb.solve(SCENE, delta=1.25, tol=1e-8, estimate_error=False)
    assert auto.topology != "cap" and auto.valid  # a wall configuration (the line here: lower energy)
    assert state.success and state.valid, state.flags
    assert 0 < state.S_end < state.Sc < SCENE.shell_length
    assert state.pressure_min > 0 and state.edge_forces[0] > 0
    assert state.penetration < 1e-6
    assert state.force_error < 1e-7


def test_profile_regions_and_the_refraction_at_the_tip_end(state):
    """Profile: tip (0), cylinder (2), free (1) in order; at S*, omega = omega_max from both
    sides, lambda_s jumps and R Psi (ls lt (T_s + 2 kappa_s M_s) - U) does not."""
    prof = state.profile()
    codes = prof["region"]
    assert list(dict.fromkeys(codes.tolist())) == [0, 2, 1]
    i_t = np.nonzero(codes == 0)[0][-1]
    i_w = np.nonzero(codes == 2)[0][0]
    assert prof["S"][i_t] == pytest.approx(state.S_end, rel=1e-12) == prof["S"][i_w]
    assert abs(prof["lambda_s"][i_w] - prof["lambda_s"][i_t]) > 1e-3  # a real jump

    def hamiltonian(i):  # energy_density is U R Psi: multiply the rest by R Psi
        RPsi = prof["energy_density"][i] / _U(prof, i)
        return RPsi * prof["lambda_s"][i] * prof["lambda_theta"][i] * (
            prof["T_s"][i] + 2 * prof["kappa_s"][i] * prof["M_s"][i]) - prof["energy_density"][i]

    assert hamiltonian(i_t) == pytest.approx(hamiltonian(i_w), rel=1e-8)
    np.testing.assert_allclose(prof["r"][codes == 2], SCENE.rho, rtol=1e-12)


def _U(prof, i):
    """U from the profile's stretches and curvatures (Mooney-Rivlin + bending), independently."""
    a, beta = SCENE.material.alpha, SCENE.beta
    ls, lt, ks, kt = (prof[k][i] for k in ("lambda_s", "lambda_theta", "kappa_s", "kappa_theta"))
    S = prof["S"][i]
    mod = SCENE.model()
    ref = mod.reference_shell(np.array([S]), SCENE.parameters(mod))
    I1 = ls**2 + lt**2 + 1 / (ls * lt) ** 2
    I2 = 1 / ls**2 + 1 / lt**2 + ls**2 * lt**2
    m = ls**2 * ks + lt**2 * kt - ref["kappa_s"][0] - ref["kappa_theta"][0]
    return ((1 - a) * (I1 - 3) + a * (I2 - 3)) / 2 + beta / 2 * m**2


def test_force_is_the_derivative_of_the_energy_on_the_cylinder_branch(state):
    """F = dE/ddelta (Richardson-extrapolated central differences, error O(h^4)): the refraction
    condition at S* and the edge conditions on the wall are the natural ones of E."""
    h = 2e-3
    E = {}
    for k in (-2, -1, 1, 2):
        s = sb.solve(SCENE, delta=state.delta + k * h, guess=state, tol=1e-8, estimate_error=False)
        assert s.success and s.topology == "cap+cylinder", s.message
        E[k] = s.energy
    d1, d2 = (E[1] - E[-1]) / (2 * h), (E[2] - E[-2]) / (4 * h)
    assert (4 * d1 - d2) / 3 == pytest.approx(state.force, abs=1e-7)


@pytest.mark.parametrize("control", ["force", "lambda0"])
def test_other_controls_reach_the_same_cylinder_state(state, control):
    value = getattr(state, control)
    s = wall_state(state, "cap+cylinder", control=control, value=value, tol=1e-8)
    assert s.success and s.topology == "cap+cylinder"
    assert s.delta == pytest.approx(state.delta, abs=1e-7)
    assert s.force == pytest.approx(state.force, rel=1e-7)


# -- the shell that meets the indenter's side: line, band, and the sequence along a curve ---------------
@pytest.mark.parametrize("delta, expected", [(1.2, "cap+line(cylinder)"), (1.35, "cap+band(cylinder)")])
def test_the_valid_wall_configuration_of_lowest_energy_is_the_state(delta, expected):
    s = sb.solve(SCENE, delta=delta, tol=1e-8, estimate_error=False)
    assert s.topology == expected and s.valid, (s.topology, s.flags)
    others = {k: v for k, v in s.candidates.items() if k != expected}
    assert others and all(e > s.energy for e in others.values()), s.candidates
    assert s.pressure_min > 0 and all(f > 0 for f in s.edge_forces)
    if expected == "cap+line(cylinder)":
        assert s.curvature_excess < 0  # the shell bends away from the wall at the line


@pytest.mark.parametrize("delta, topology", [(1.2, "cap+line(cylinder)"), (1.35, "cap+band(cylinder)")])
def test_force_is_the_derivative_of_the_energy_touching_the_wall(delta, topology):
    base = sb.solve(SCENE, delta=delta, topology=topology, tol=1e-8, estimate_error=False)
    assert base.success and base.topology == topology
    h = 2e-3
    E = {}
    for k in (-2, -1, 1, 2):
        s = sb.solve(SCENE, delta=delta + k * h, topology=topology, guess=base, tol=1e-8, estimate_error=False)
        assert s.success and s.topology == topology, s.message
        E[k] = s.energy
    d1, d2 = (E[1] - E[-1]) / (2 * h), (E[2] - E[-2]) / (4 * h)
    assert (4 * d1 - d2) / 3 == pytest.approx(base.force, abs=1e-7)


@pytest.fixture(scope="module")
def wall_curve():
    return sb.curve(SCENE, delta_max=2.0)


def test_curve_goes_on_past_the_tip_end_with_every_point_valid(wall_curve):
    """Issue 12: this curve was invalid from delta 1.14 (the shell through the indenter's side)
    and stopped at 1.32 (the contact at the tip's end)."""
    c = wall_curve
    assert c.complete and c.delta[-1] == pytest.approx(2.0) and np.all(c.valid), c.flags
    assert list(dict.fromkeys(c.topology.tolist())) == ["cap", "cap+line(cylinder)", "cap+band(cylinder)"]
    assert np.all(c.force_error < 1e-6)


def test_switches_are_located_where_their_criteria_change_sign(wall_curve):
    """cap -> line: the cap's free shell reaches the wall (wall_gap crosses 0); line -> band:
    the shell at the line bends as tightly as the wall (curvature excess crosses 0).  Each is
    checked on both sides of the located delta, 1e-4 away."""
    sw = {(s["from"], s["to"]): s for s in wall_curve.settings["topology_switches"]}
    touch = sw[("cap", "cap+line(cylinder)")]["delta"]
    assert 1.1 < touch < 1.15
    gaps = [sb.solve(SCENE, delta=touch + h, topology="cap", estimate_error=False).wall_gap for h in (-1e-4, 1e-4)]
    assert gaps[0] > 0 > gaps[1], gaps
    band = sw[("cap+line(cylinder)", "cap+band(cylinder)")]["delta"]
    line = sb.solve(SCENE, delta=band, topology="cap+line(cylinder)", estimate_error=False)
    excess = [sb.solve(SCENE, delta=band + h, topology="cap+line(cylinder)", guess=line,
                       estimate_error=False).curvature_excess for h in (-1e-4, 1e-4)]
    assert excess[0] < 0 < excess[1], excess


def test_force_is_continuous_where_the_shell_meets_the_wall(wall_curve):
    """At the located switch the cap and the line state coincide: the same F (no snap)."""
    sw = next(s for s in wall_curve.settings["topology_switches"] if s["to"] == "cap+line(cylinder)")
    cap = sb.solve(SCENE, delta=sw["delta"], topology="cap", tol=1e-8, estimate_error=False)
    line = sb.solve(SCENE, delta=sw["delta"] + 1e-3, topology="cap+line(cylinder)", tol=1e-8,
                    estimate_error=False)
    assert line.success
    slope = (line.force - cap.force) / 1e-3  # a finite slope: F continuous across the switch
    assert 0 < slope < 5 * (cap.force / cap.delta)


@pytest.mark.slow
def test_wide_indenter_on_a_hemisphere_to_delta_2_5():
    """Issue 12's first scene: gamma 1, rho 0.6, to delta 2.5 (10 of 45 points invalid before)."""
    c = sb.curve(sb.Scene.preset("base", rho=0.6), delta_max=2.5)
    assert c.complete and np.all(c.valid), c.flags
    assert "cap+band(cylinder)" in set(c.topology)


@pytest.mark.slow
def test_fit_scene_with_thin_wall_to_the_geometric_limit():
    """Issue 12's second scene: gamma 2.5, rho 1/3, beta 1e-3 to the upper end of delta_bounds."""
    hi = sb.delta_bounds(SCENE, 1e-6)[1]
    c = sb.curve(SCENE, delta_max=0.999 * hi, estimate_error=False)
    assert c.complete and np.all(c.valid), c.flags
    assert c.delta[-1] == pytest.approx(0.999 * hi)


def test_paper_model_runs_onto_the_cylinder_when_the_first_wall_guess_has_no_room():
    """beta = 1e-3, the paper's model: the cap reaches the tip's end near delta 0.915; from the
    cap just past it cap+cylinder lands on a contact that runs back onto the tip, from a slightly
    deeper cap it does not.  The curve goes on to delta = 1, every point valid."""
    c = sb.curve(sb.Scene.preset("base", contact="paper", beta=1e-3), delta_max=1.0, estimate_error=False)
    assert c.complete and c.delta[-1] == pytest.approx(1.0) and np.all(c.valid)
    sw = [s for s in c.settings["topology_switches"] if s["to"] == "cap+cylinder"]
    assert len(sw) == 1 and 0.905 < sw[0]["delta"] < 0.925
    assert set(c.topology[c.delta > sw[0]["delta"] + 1e-6]) == {"cap+cylinder"}


def _wall_solves(record):
    """shellbvp.cylinder.solve_chain_from (the solve of every wall state) with each solve_bvp run
    of its system passed to ``record(run, kwargs)`` (the raw run: status 0 = converged)."""
    import shellbvp.cylinder

    orig = shellbvp.cylinder.solve_chain_from

    def counted(sysm, guess, **kw):
        raw = sysm.solve

        def solve(*a, **k):
            r = raw(*a, **k)
            record(r, k)
            return r

        sysm.solve = solve  # this system only
        try:
            return orig(sysm, guess, **kw)
        finally:
            del sysm.solve

    return counted


@pytest.mark.slow  # ~25 s, most of it generating the code of the xi = 0 structure
def test_a_wall_guess_whose_mesh_runs_away_fails_at_the_node_budget(monkeypatch):
    """xi = 0 with the paper's contact has no valid state on the cylinder past the tip's end
    (benchmarks/results/stability.md); a guess there refined its mesh to max_nodes (8101
    nodes, ~10 s a try, 34 s after the curve's last point).  The budget is a few times the
    cap's mesh, as for every guessed configuration."""
    import shellbvp.cylinder

    meshes = []
    counted = _wall_solves(lambda r, kw: meshes.append((int(r.x.size), kw["max_nodes"])))

    scene = sb.Scene.preset("base", xi=0, contact="paper")
    near = sb.curve(scene, deltas=np.linspace(0.2, 0.9, 8), estimate_error=False, topology="cap").solutions[-1]
    cap = sb.solve(scene, delta=0.97, guess=near, topology="cap", estimate_error=False)
    assert cap.status in (0, 4) and wall_contact_suspected(cap)
    monkeypatch.setattr(shellbvp.cylinder, "solve_chain_from", counted)
    res = wall_state(cap, "cap+cylinder")
    assert not (res.success and res.valid)
    budget = max(shellbvp.cylinder.WALL_MIN_NODES, 4 * cap.nodes)
    assert meshes and all(limit == budget and n <= budget for n, limit in meshes), (meshes, budget)


@pytest.mark.slow  # ~25 s with the code generation of the xi = 0 structure
def test_no_deeper_wall_starts_where_no_guess_finds_a_state(monkeypatch):
    """Going deeper past the tip's end gives the contact room on the cylinder: it cures wall
    states that converge with their contact back on the tip, not guesses that find no state
    at all (xi 0, paper's contact: every guess's mesh runs away).  After the one set of wall
    attempts from the cap past the end the curve goes on with the cap held at the tip's end."""
    import shellbvp.cylinder

    statuses = []
    record = _wall_solves(lambda r, kw: statuses.append(int(r.status)))
    monkeypatch.setattr(shellbvp.cylinder, "solve_chain_from", record)
    c = sb.curve(sb.Scene.preset("base", xi=0, contact="paper"), deltas=np.linspace(0.85, 1.0, 7),
                 estimate_error=False)
    assert c.complete and c.delta.max() == pytest.approx(1.0) and np.all(c.valid)
    assert c.points["contact_edge"][-1] == "pinned"
    assert 1 <= len(statuses) <= len(shellbvp.cylinder._CAP_SPLITS) and 0 not in statuses, statuses


def test_the_paper_cap_held_at_the_tip_end_takes_over_where_the_free_edge_reaches_it():
    """The paper's cap with its edge held at the tip's end (contact_edge "pinned"): shallower than
    where the free cap's edge reaches the end its ring force would pull, deeper it pushes; it
    vanishes where the free cap's edge is at the end, and there the two caps agree in F."""
    from shellbvp.solution import passed_tip_end
    from shellbvp.state import make_system, solve_from, warm_guess

    scene = sb.Scene.preset("base", contact="paper", beta=1e-3)
    free = {0.91: sb.solve(scene, delta=0.91, topology="cap", estimate_error=False)}
    sysm = make_system(scene, "delta", 0.92, free[0.91].system.eps)
    free[0.92] = solve_from(sysm, warm_guess(sysm, free[0.91]))  # past the end: inadmissible, status 4
    assert free[0.91].success and free[0.92].status == 4
    assert free[0.91].tip_end_margin > 0 > free[0.92].tip_end_margin
    assert passed_tip_end(free[0.92]) and not passed_tip_end(free[0.91])  # the diagnosis' flag
    told = dataclasses.replace(free[0.92], past_tip_end=False)
    assert not passed_tip_end(told)  # the flag decides, not the message's words
    held = {}
    for d in (0.91, 0.92):
        sysm = make_system(scene, "delta", d, free[0.91].system.eps, edge="pinned")
        held[d] = solve_from(sysm, warm_guess(sysm, free[0.91]))
        assert held[d].success and held[d].contact_edge == "pinned"
        assert abs(held[d].tip_end_margin) < 1e-10  # the edge is at the tip's end (a boundary condition: to bc_tol)
    n1, n2 = held[0.91].edge_forces[0], held[0.92].edge_forces[0]
    assert n1 < 0 < n2 and held[0.92].valid and not held[0.91].valid
    m1, m2 = free[0.91].tip_end_margin, free[0.92].tip_end_margin
    d_held = 0.91 + 0.01 * n1 / (n1 - n2)
    d_free = 0.91 + 0.01 * m1 / (m1 - m2)
    assert d_held == pytest.approx(d_free, abs=2e-4)  # linear interpolation over 0.01
    f_held = held[0.91].force + (held[0.92].force - held[0.91].force) * (d_held - 0.91) / 0.01
    f_free = free[0.91].force + (free[0.92].force - free[0.91].force) * (d_free - 0.91) / 0.01
    assert f_held == pytest.approx(f_free, rel=1e-4)


@pytest.mark.slow  # ~25 s with the code generation of the xi = 0 structure
def test_the_paper_cap_is_held_at_the_tip_end_where_no_cylinder_state_exists():
    """xi = 0, the paper's contact: past delta 0.934 no cap+cylinder state exists (followed in beta
    from 1e-4, where it does, its band on the cylinder shrinks to nothing near beta 2e-3 at
    delta 1), and the free cap's edge would pass the tip's end.  The edge stays at the tip's end,
    where the indenter's curvature jumps and can push on the edge's circle: the curve reaches
    delta 1, every point valid.  At the located switch the held cap is the free cap: computed
    as the held cap whose ring force vanishes and as the free cap whose edge reaches the end,
    the two agree in delta and F."""
    from shellbvp.state import make_system, solve_from, warm_guess

    scene = sb.Scene.preset("base", xi=0, contact="paper")
    c = sb.curve(scene, delta_max=1.0, delta_start=0.85, delta_min=0.84, estimate_error=False)
    assert c.complete and c.delta[-1] == pytest.approx(1.0) and np.all(c.valid), c.stop_reason
    sw, = [s for s in c.settings["topology_switches"] if s["to"] == "cap (pinned at the tip's end)"]
    assert 0.93 < sw["delta"] < 0.94
    held = [s for s in c.solutions if s.contact_edge == "pinned"]
    assert held and all(s.delta > sw["delta"] and s.edge_forces[0] > 0 for s in held)
    assert np.all(np.diff([s.edge_forces[0] for s in held]) > 0)  # pushed harder as it goes deeper
    # the held cap's ring force vanishes at the switch: from held caps either side of it
    near = held[0]
    ring = {}
    for d in (sw["delta"] - 2e-3, sw["delta"] + 2e-3):
        sysm = make_system(scene, "delta", d, near.system.eps, edge="pinned")
        s = solve_from(sysm, warm_guess(sysm, near))
        assert s.success
        ring[d] = (s.edge_forces[0], s.force)
    (d1, (n1, f1)), (d2, (n2, f2)) = sorted(ring.items())
    assert n1 < 0 < n2  # before the switch the held cap would pull the edge
    d0 = d1 - n1 * (d2 - d1) / (n2 - n1)
    assert d0 == pytest.approx(sw["delta"], abs=2e-4)
    assert f1 + (f2 - f1) * (d0 - d1) / (d2 - d1) == pytest.approx(sw["force"], rel=1e-4)
