"""The bending energy as the user's choice (issue 13, item 3): U = W + beta B for the
paper's B, a convex one built in, and a user formula."""

import numpy as np
import pytest
import sympy as sp

import shellbvp as sb
from shellbvp.state import make_system, solve_from, warm_guess
from symbolic import bending, materials

TRACE_TEXT = "(lambda_s**2*kappa_s + lambda_theta**2*kappa_theta - kappa_s0 - kappa_theta0)**2/2"


def test_a_user_formula_equal_to_the_papers_gives_the_same_force():
    base = sb.Scene.preset("base")
    user = base.replace(bending=sb.BendingEnergy(TRACE_TEXT))
    assert user.structure() != base.structure()  # its own generated code, through the general path
    for delta in (0.05, 0.3):
        a = sb.solve(base, delta=delta, estimate_error=False, topology="cap")
        b = sb.solve(user, delta=delta, estimate_error=False, topology="cap")
        assert b.force == pytest.approx(a.force, rel=1e-10)


def test_user_bending_energies_are_checked_and_never_run_as_code():
    with pytest.raises(ValueError, match="vanish in the reference state"):
        sb.BendingEnergy("kappa_s**2/2")
    with pytest.raises(ValueError, match="moment-free"):
        sb.BendingEnergy("(kappa_s - kappa_s0)")
    with pytest.raises(ValueError, match="positive bending stiffness"):
        sb.BendingEnergy("-(kappa_s - kappa_s0)**2")
    with pytest.raises(ValueError, match="not a permitted|attribute"):
        sb.BendingEnergy("__import__('os').system('true')")
    with pytest.raises(ValueError, match="unknown name"):
        sb.BendingEnergy("(kappa_s - kappa_s0)**2 * zeta")
    b = sb.BendingEnergy("(lambda_s*kappa_s - kappa_s0)**2/2 + (lambda_theta*kappa_theta - kappa_theta0)**2/2")
    assert b.stiffness == 1.0


def test_the_bending_choice_survives_the_scene_round_trip():
    for b in (sb.TraceBending(), sb.RotationBending(), sb.BendingEnergy(TRACE_TEXT)):
        scene = sb.Scene.preset("base", bending=b)
        assert sb.Scene.from_dict(scene.to_dict()) == scene
    old = sb.Scene.preset("base").to_dict()
    del old["bending"]  # files from before the choice read as the paper's energy
    assert sb.Scene.from_dict(old).bending == sb.TraceBending()


def test_convexity_of_the_builtin_bending_energies():
    """The Legendre determinant in the free region's velocities (psi, phi'): the paper's B makes
    it change sign at large bending; the rotation-gradient B leaves it to W (Mooney-Rivlin:
    positive)."""
    W = materials.mooney_rivlin(sp.Rational(1, 10))
    ref = {bending.KS0: 1, bending.KT0: 1}
    trace = bending.legendre_determinant(W, bending.trace_bending().xreplace(ref), beta=sp.Rational(1, 100))
    rot = bending.legendre_determinant(W, bending.rotation_bending().xreplace(ref), beta=sp.Rational(1, 100))
    assert not rot.has(bending.KS) and not rot.has(bending.KT)
    signs = set()
    for ls in (0.8, 1.2, 1.6):
        for ks in (0.0, 2.0, 5.0, 10.0):
            at = {materials.LS: ls, materials.LT: 1.1, bending.KS: ks, bending.KT: ks}
            signs.add(bool(trace.evalf(subs=at) > 0))
            assert rot.evalf(subs=at) > 0
    assert signs == {True, False}


def _energy_identity_error(scene, delta, h=0.01):
    """|dE/ddelta - F| with dE/ddelta by Richardson-extrapolated central differences, and the
    differencing error estimate."""
    mid = sb.solve(scene, delta=delta, estimate_error=False, topology="cap", tol=1e-8)

    def E(d):
        sysm = make_system(scene, "delta", d, mid.system.eps)
        s = solve_from(sysm, warm_guess(sysm, mid), tol=1e-8, max_nodes=50000)
        assert s.success
        return s.energy

    D = [(E(delta + k) - E(delta - k)) / (2 * k) for k in (h, h / 2)]
    return abs((4 * D[1] - D[0]) / 3 - mid.force), abs(D[1] - D[0])


def test_the_weierstrass_condition_against_the_convex_envelope():
    """``envelope_partner``: a base state lies on U's convex envelope in (lambda_s, lambda_s kappa_s);
    the same point stretched to lambda_s 1.2 with kappa_s rho 3 lies far above it with the paper's
    energy (a Weierstrass-Erdmann corner would lower it) and on it with the convex rotation energy."""
    from shellbvp.convexity import envelope_partner

    gaps = {}
    for bending in (sb.TraceBending(), sb.RotationBending()):
        sol = sb.solve(sb.Scene.preset("base", bending=bending), delta=0.3, estimate_error=False)
        sysm, t = sol.system, np.array([0.5])
        S, y = sysm.S(1, t, sol.p)[0], sol.sol(t)[sysm.rows(1)][:, 0]
        assert envelope_partner(sysm, S, y)["gap"] == 0.0
        y[2], y[3] = 1.2, 3.0 / sysm.scene.rho
        gaps[type(bending).__name__] = envelope_partner(sysm, S, y)
    assert gaps["TraceBending"]["gap"] > 0.1 and gaps["TraceBending"]["partner"][0] < 0.5
    assert gaps["RotationBending"]["gap"] == 0.0


def test_weierstrass_gap_of_states_with_each_bending_energy():
    """Base at delta 0.6 (a smooth edge, just before the corner): with the paper's energy the free
    side of the edge lies well above U's convex envelope (a crease phase would lower it: a weak
    minimum only); with the rotation energy every sampled point lies on it."""
    from shellbvp.convexity import weierstrass_gap

    paper = weierstrass_gap(sb.solve(sb.Scene.preset("base"), delta=0.6, estimate_error=False, topology="cap"),
                            points=3)
    assert paper["gap"] > 0.01 and paper["region"] == 1 and paper["partner"][0] < 0.5
    rotation = sb.solve(sb.Scene.preset("base", bending=sb.RotationBending()), delta=0.6, estimate_error=False)
    assert weierstrass_gap(rotation, points=3)["gap"] == 0.0


def test_energy_identity_holds_for_the_rotation_bending_energy():
    """With any B the generalised tensions come from the energy, so F = dE/ddelta still holds
    (with the paper's tau = T + M kappa it would fail by ~0.2 at delta = 1)."""
    scene = sb.Scene.preset("base", bending=sb.RotationBending())
    err, scale = _energy_identity_error(scene, 0.5)
    assert err < max(scale, 1e-6)


def test_rotation_bending_stays_convex_and_smooth_to_depth_one():
    scene = sb.Scene.preset("base", bending=sb.RotationBending())
    c = sb.curve(scene, delta_max=1.0, estimate_error=False)
    P = c.points
    assert c.complete and np.all(P["valid"]) and np.all(P["legendre_min"] > 0.1)
    assert set(P["contact_edge"]) <= {"smooth", ""}  # no corner needed


def test_cli_bending_choice_and_convexity_report(capsys):
    from shellbvp.cli import main

    assert main(["convexity", "--bending", "rotation"]) == 0
    assert "convex throughout" in capsys.readouterr().out
    assert main(["convexity"]) == 0
    assert "not convex from kappa rho" in capsys.readouterr().out
    assert main(["solve", "--preset", "base", "--delta", "0.3", "--bending", "rotation", "--json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    api = sb.solve(sb.Scene.preset("base", bending=sb.RotationBending()), delta=0.3, estimate_error=False)
    assert doc["force"] == pytest.approx(api.force, rel=1e-8)


def test_a_bending_energy_without_its_plate_limit_is_refused_at_registration():
    # beta from a thickness divides by the plate limit: no silent default of the trace's 1.0
    from shellbvp.materials.base import Bending, register_bending

    class Forgetful(Bending):
        family = "forgetful"

    with pytest.raises(ValueError, match="declares no small-strain plate limit"):
        register_bending(Forgetful)
