"""The smooth model past the loss of convexity at the contact edge (issue 13): the
Weierstrass-Erdmann corner, where lambda_s and kappa_s jump at the edge."""

import numpy as np
import pytest
from scipy.optimize import fsolve

import shellbvp as sb
from shellbvp.corner import edge_model
from shellbvp.edge_models import EDGE_MODELS
from shellbvp.state import make_system, solve_from, warm_guess

BASE = sb.Scene.preset("base")


@pytest.fixture(scope="module")
def base_curve():
    return sb.curve(BASE, delta_max=1.0, estimate_error=False)


def _edge(sol):
    sysm = sol.system
    return sol.Sc, sol.y[sysm.rows(0), -1], sol.y[sysm.rows(1), 0], sysm


def test_corner_conditions_are_sliding_and_eshelby_from_the_profiles():
    """The generated corner rows against the regions' own profiles: sliding
    [tau_s] + kappa_s^c [M_s] = 0 and the Eshelby [lambda_s dU/dlambda_s - U] = 0, U_lambda
    by central differences of the energy density at fixed kappa_s (independent of the junction's
    generated code)."""
    sol = sb.solve(BASE, delta=0.4, estimate_error=False, topology="cap")
    Sc, yc, yf, sysm = _edge(sol)
    mod, par = sysm.model, sysm.par
    yf = yf.copy()
    yf[2] *= 1.07  # a jump in lambda_s
    yf[3] -= 0.8   # and in kappa_s
    fc = lambda y: mod.contact_profile(np.array([Sc]), y[:, None], par)  # noqa: E731
    ff = lambda y: mod.free_profile(np.array([Sc]), y[:, None], par)  # noqa: E731

    def H(prof, y, i):  # R Psi (lambda_s dU/dlambda_s - U) from the energy density U R Psi
        h = 1e-6
        up, dn = y.copy(), y.copy()
        up[i] += h
        dn[i] -= h
        dU = (prof(up)["energy_density"][0] - prof(dn)["energy_density"][0]) / (2 * h)
        return y[i] * dU - prof(y)["energy_density"][0]

    pc, pf = fc(yc), ff(yf)
    slide = pf["tau_s"][0] - pc["tau_s"][0] + pc["kappa_s"][0] * (pf["M_s"][0] - pc["M_s"][0])
    eshelby = H(ff, yf, 2) - H(fc, yc, 1)
    res = mod.junction_corner_res(Sc, yc, yf, sol.delta, 0.0, par)
    R_Psi = float(mod.reference_shell(np.array([Sc]), par)["R"][0]) * np.hypot(np.cos(Sc), BASE.gamma * np.sin(Sc))
    assert abs(slide) > 1e-3 and abs(eshelby) > 1e-3  # a state that is not a corner: both rows nonzero
    assert res[3] == pytest.approx(slide, rel=1e-10, abs=1e-12)
    assert res[4] * R_Psi == pytest.approx(eshelby, rel=1e-6)
    # r, phi, z continuous exactly as at a smooth edge; a continuous state satisfies the corner rows
    np.testing.assert_array_equal(res[:3], mod.junction_smooth_res(Sc, yc, yf, sol.delta, 0.0, par)[:3])
    Sc, yc, yf, _ = _edge(sol)
    assert np.max(np.abs(mod.junction_corner_res(Sc, yc, yf, sol.delta, 0.0, par))) < 1e-8


def test_interior_corner_conditions_are_the_momenta_and_eshelby_from_the_profiles():
    """The generated interior-corner rows (``kink_res``) against the free region's own profile:
    [tau_s] = [M_s] = 0 and [lambda_s dU/dlambda_s - U] = 0, U_lambda by central differences of
    the energy density at fixed kappa_s; a continuous state satisfies them at any S."""
    sol = sb.solve(BASE, delta=0.4, estimate_error=False, topology="cap")
    sysm = sol.system
    mod, par = sysm.model, sysm.par
    t = np.array([0.4])
    S = float(sysm.S(1, t, sol.p)[0])
    yl = sol.sol(t)[sysm.rows(1), 0]
    yr = yl.copy()
    yr[2] *= 0.93  # a jump in lambda_s
    yr[3] += 0.6   # and in kappa_s
    prof = lambda y: mod.free_profile(np.array([S]), y[:, None], par)  # noqa: E731

    def H(y):  # R Psi (lambda_s dU/dlambda_s - U) from the energy density U R Psi
        h = 1e-6
        up, dn = y.copy(), y.copy()
        up[2] += h
        dn[2] -= h
        dU = (prof(up)["energy_density"][0] - prof(dn)["energy_density"][0]) / (2 * h)
        return y[2] * dU - prof(y)["energy_density"][0]

    pl, pr = prof(yl), prof(yr)
    res = mod.kink_res(S, yl, yr, par)
    R_Psi = float(mod.reference_shell(np.array([S]), par)["R"][0]) * np.hypot(np.cos(S), BASE.gamma * np.sin(S))
    assert min(abs(res)) > 1e-4  # not a corner: every row nonzero
    assert res[0] == pytest.approx(pr["tau_s"][0] - pl["tau_s"][0], rel=1e-10)
    assert res[1] == pytest.approx(pr["M_s"][0] - pl["M_s"][0], rel=1e-10)
    assert res[2] * R_Psi == pytest.approx(H(yr) - H(yl), rel=1e-6)
    assert np.max(np.abs(mod.kink_res(S, yl, yl, par))) < 1e-13


def test_before_the_limit_the_edges_other_root_is_not_convex():
    """Before the convexity limit the corner conditions at the edge of the smooth state have a
    second root (lambda_s smaller, kappa_s larger on the free side), but there the free side's
    Legendre determinant is negative: not a minimum, and the free equations are singular on the
    way out of it.  So no corner competes with the smooth cap there (no first-order switch)."""
    for delta in (0.5, 0.6):
        sol = sb.solve(BASE, delta=delta, estimate_error=False, topology="cap")
        Sc, yc, yf, sysm = _edge(sol)
        mod, par = sysm.model, sysm.par

        def at(v):
            y = yf.copy()
            y[2], y[3] = v
            return y

        def conditions(v):
            return mod.junction_corner_res(Sc, yc, at(v), delta, 0.0, par)[3:]

        roots = []
        for l0 in np.linspace(0.7, 1.6, 10):
            for k0 in np.linspace(2.0, 14.0, 7):
                v, _, ier, _ = fsolve(conditions, [l0, k0], full_output=True)
                if ier == 1 and np.max(np.abs(conditions(v))) < 1e-10 and abs(v[0] - yf[2]) > 1e-3:
                    roots.append(v)
        assert roots, "the second root of the corner conditions was not found"
        det = [mod.free_legendre(np.array([Sc]), at(v)[:, None], par)[0][0] for v in roots]
        assert max(det) < 0
        assert mod.free_legendre(np.array([Sc]), yf[:, None], par)[0][0] > 0  # the smooth state is convex


def test_base_curve_passes_the_convexity_limit_with_a_continuous_switch(base_curve):
    c = base_curve
    P = c.points
    assert c.complete and P["delta"][-1] == pytest.approx(1.0)
    assert np.all(P["valid"])
    corner = P["contact_edge"] == "corner"
    assert corner.any() and set(P["contact_edge"][~corner]) <= {"smooth", ""}  # "": a point load, no edge
    assert np.all(P["edge_jump_ls"][corner] > 0) and np.all(P["legendre_min"] > 0)
    assert np.all(P["delta"][corner] > 0.614) and np.all(P["delta"][~corner] < 0.6146)
    sw = [s for s in c.settings["topology_switches"] if s["to"] == "cap (corner edge)"]
    assert len(sw) == 1
    sw = sw[0]
    # located two ways: the smooth side's edge Legendre determinant and the corner's jump both reach 0
    assert sw["delta"] == pytest.approx(0.61455, abs=1e-4)
    assert abs(sw["delta_from_jump"] - sw["delta"]) < 1e-5
    # F from each side, extrapolated (quadratics through solves at tol 1e-6, 0.003 apart), meets
    # to 1e-4 of F; a first-order switch would jump by a finite amount
    assert abs(sw["force_jump"]) < 1e-4 * sw["force"] and sw["kind"].startswith("continuous")
    # the two candidates' energies at their overlap, the switch: equal (E is C1 across it)
    assert abs(sw["energy_jump"]) < 1e-6


def _corner_energy(delta, guess, tol=1e-8):
    sysm = make_system(BASE, "delta", delta, guess.system.eps, "corner")
    sol = solve_from(sysm, warm_guess(sysm, guess), tol=tol, max_nodes=50000)
    assert sol.success and edge_model(sol) is EDGE_MODELS["corner"]  # the object, named as files name it
    return sol


@pytest.mark.parametrize("delta", [0.7, 0.9])
def test_energy_identity_on_the_corner_branch(base_curve, delta):
    """F = dE/ddelta by Richardson-extrapolated central differences of E on the corner branch."""
    near = min(base_curve.solutions, key=lambda s: abs(s.delta - delta))
    mid = _corner_energy(delta, near)

    def D(h):
        return (_corner_energy(delta + h, mid).energy - _corner_energy(delta - h, mid).energy) / (2 * h)

    dE = (4 * D(0.005) - D(0.01)) / 3
    err = abs(D(0.005) - D(0.01))  # the differencing error estimate (before extrapolation)
    assert abs(dE - mid.force) < max(err, 1e-6), (dE, mid.force, err)


def test_a_cold_solve_past_the_limit_finds_the_corner(base_curve):
    sol = sb.solve(BASE, delta=0.8, estimate_error=False)
    assert sol.success and sol.valid and sol.contact_edge == "corner"
    near = _corner_energy(0.8, min(base_curve.solutions, key=lambda s: abs(s.delta - 0.8)))
    assert sol.force == pytest.approx(near.force, rel=1e-5)


def test_without_a_corner_the_curve_stops_at_the_limit_at_once(monkeypatch):
    """If no corner state is found past the limit, the curve stops there with the reason after
    one failed step, instead of halving its step many times (the old 40-50 s stall)."""
    import shellbvp.legs as legs
    import shellbvp.steps as steps

    failed = []
    solve = legs.solve_from

    def counted(*a, **k):
        sol = solve(*a, **k)
        if not sol.success:
            failed.append(sol.delta)
        return sol

    for module in (legs, steps):  # the curve's arclength steps and its delta steps
        monkeypatch.setattr(module, "cross_convexity_limit", lambda *a, **k: None)
        monkeypatch.setattr(module, "solve_from", counted)
    c = sb.curve(BASE, delta_max=1.0, delta_start=0.55, estimate_error=False, topology="cap")
    assert "no corner state was found" in c.stop_reason and not c.complete
    assert 0.6 < c.points["delta"][-1] < 0.6146
    assert len(failed) <= 4, failed


def test_the_corner_is_seeded_along_the_null_direction_where_no_other_root_is_found():
    """gamma = 0 (numpy functions): at the last smooth caps before the limit (0.7113) the edge
    conditions are flat to 1e-15 along their null direction near the smooth root, the other root
    is not found, and the corner was not reached (the grid's curve stopped at 0.7008).  A jump of
    CORNER_SEED_JUMP along the null direction reaches it."""
    from shellbvp.corner import edge_null_jump, is_corner
    from shellbvp.state import cross_convexity_limit

    scene = sb.Scene.preset("base", gamma=0.0)
    prev2 = sb.curve(scene, deltas=[0.4, 0.675], estimate_error=False).solutions[-1]  # a cold solve there: 9 s
    prev = sb.solve(scene, delta=0.7008, guess=prev2, estimate_error=False)
    assert prev2.success and prev.success and prev.contact_edge == "smooth"
    direction = edge_null_jump(prev)
    assert direction[0] == 1 and direction[1] < 0
    sol = cross_convexity_limit(prev, prev2, 0.72, eps=prev.system.eps, tol=1e-6, max_nodes=10000, bc_tol=1e-10)
    assert sol is not None and is_corner(sol, 1e-6) and sol.valid
    assert sol.delta == 0.72 and 0.01 < sol.edge_jump_ls < 0.03  # 0.0168
