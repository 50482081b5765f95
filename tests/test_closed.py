"""Closed shells (issue 55): a complete spheroid compressed between two plates, or on a substrate
under a flat plate, solved on the half above the equator; on a substrate under a curved tip,
both halves with a contact each (docs/closed.md)."""

import math

import numpy as np
import pytest

import shellbvp as sb


def plates(beta, **kw):
    return sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=beta, **kw)


@pytest.mark.parametrize("kw, message", [
    (dict(closed=True, gamma=-1.0, tip=sb.FlatTip()), "gamma (polar / equatorial semi-axis"),
    (dict(closed=True, support="wall", tip=sb.FlatTip()), "support must be one of"),
    (dict(support="plates"), "needs closed=True"),
    (dict(closed=True, tip=sb.FlatTip(), rim="clamped"), "a closed shell has none"),
    (dict(closed="yes"), "closed must be True"),
    (dict(gamma=1.0, tip=sb.FlatTip()), "must be < 0"),  # a flat plate meets a bowl's rim first
])
def test_bad_closed_scenes_are_refused_in_one_line(kw, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(")) as err:
        sb.Scene(**kw)
    assert "\n" not in str(err.value)


def test_a_closed_scene_round_trips_and_says_what_it_is():
    scene = plates(1e-4, rho=0.3)
    assert scene.rho == 1.0 and scene.closed and scene.support == "plates"  # a plate has no radius
    assert sb.Scene.from_dict(scene.to_dict()) == scene
    assert sb.Scene(closed=True, tip=sb.FlatTip()).support == "substrate"
    assert sb.Scene().support == "rim" and "closed" not in sb.Scene().to_dict()  # rimmed files as before
    words = scene.describe(R_L=30e-6)
    assert "closed spheroid between plates" in words and "equatorial radius of 30 um" in words
    assert "flat plate" in words
    assert sb.Scene.preset("capsule-plates").sealed


def test_the_equator_holds_the_symmetry_and_moves_half_the_approach():
    s = sb.solve(plates(1e-3), delta=0.1)
    assert s.success
    prof = s.profile()
    assert prof["z"][-1] == pytest.approx(-0.05, abs=1e-9)                 # the equator moves by delta/2
    assert abs(prof["Q"][-1] * prof["r"][-1]) < 1e-9                       # no horizontal force
    assert abs(prof["phi"][-1]) == pytest.approx(math.pi / 2, abs=1e-9)   # the tangent stays vertical


@pytest.mark.parametrize("eps", [0.02, 0.01])
def test_a_thin_sphere_between_plates_has_reissners_stiffness_of_two_poles_in_series(eps):
    # Reissner: a point force on a thin sphere, F = 8 sqrt(3 beta) w per pole (nu = 1/2, E = 3 mu,
    # beta = eps^2/3); two poles in series: F/delta = 4 sqrt(3 beta).  The model's deficit is
    # O(eps^0.8): 2.8 % at eps 0.02, 1.6 % at 0.01 (and 0.9 % at 0.005).
    beta = eps**2 / 3
    k = [sb.solve(plates(beta), delta=d).force / d for d in (eps / 100, eps / 50)]
    k0 = 2 * k[0] - k[1]                                                   # F/delta at delta -> 0
    ratio = k0 / (4 * math.sqrt(3 * beta))
    assert 1 - 1.7 * eps < ratio < 1.0


def test_a_substrate_under_a_flat_plate_is_the_plates_problem():
    a = sb.solve(plates(1e-3), delta=0.05)
    b = sb.solve(plates(1e-3).replace(support="substrate"), delta=0.05)
    assert b.force == a.force


@pytest.mark.parametrize("sealed", [False, True])
def test_force_is_the_derivative_of_the_whole_shells_energy(sealed):
    # E of both halves, with the pressure's work under pressure control; delta the plates' approach
    scene = plates(1e-3, pressure=0.1, sealed=sealed)
    d, h = 0.2, 1e-4
    E = [sb.solve(scene, delta=x).energy for x in (d - h, d + h)]
    F = sb.solve(scene, delta=d).force
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(F, rel=1e-5)


def test_a_nearly_membrane_capsule_pushes_on_each_plate_with_pressure_times_contact_area():
    # a membrane's tension is tangent to the plate at the contact edge: F = p pi a^2; bending
    # adds the edge's shear, O(sqrt(beta)): 12 % at beta 1e-5, 47 % at 1e-4 (delta 0.1)
    def excess(beta):
        s = sb.solve(plates(beta, pressure=0.2), delta=0.1)
        prof = s.profile()
        a = prof["r"][prof["region"] == 0].max()
        return s.force / (0.2 * math.pi * a * a) - 1
    coarse, fine = excess(1e-4), excess(1e-5)
    assert 0 < fine < coarse / 2.5 and fine < 0.15


def test_a_closed_curve_is_written_and_read_back(tmp_path):
    c = sb.curve(sb.Scene.preset("capsule-plates"), delta_max=0.05)
    assert np.all(c.status == 0)
    path = tmp_path / "capsule.h5"
    c.to_hdf5(path)
    back = sb.read_curve(path)
    assert back.scene == c.scene and back.scene.closed
    assert np.array_equal(back.force, c.force)


def on_substrate(beta=1e-2, rho=0.5, **kw):
    return sb.Scene(closed=True, tip=sb.SphereTip(), rho=rho, gamma=1.0, beta=beta, **kw)


def test_the_two_halves_conditions_have_their_jacobians():
    from shellbvp.configurations import configuration, names

    scene = on_substrate()
    rng = np.random.default_rng(0)
    for name in [n for n in names() if n.startswith("closed-")]:
        sysm = configuration(name).system(scene, "delta", 0.05, 1e-3)
        assert sysm.n_conditions == sysm.n + sysm.k
        ya, yb = rng.uniform(0.5, 1.5, sysm.n), rng.uniform(0.5, 1.5, sysm.n)
        p = np.log(rng.uniform(0.05, 0.3, sysm.k)) if sysm.k else None
        A, B, *P = sysm.bc_jac(ya, yb, p)
        h, base = 1e-7, sysm.bc(ya, yb, p)
        fd = np.column_stack([(sysm.bc(ya + h * e, yb, p) - base) / h for e in np.eye(sysm.n)])
        assert np.allclose(fd, A, atol=1e-5, rtol=1e-5), name
        fd = np.column_stack([(sysm.bc(ya, yb + h * e, p) - base) / h for e in np.eye(sysm.n)])
        assert np.allclose(fd, B, atol=1e-5, rtol=1e-5), name
        if sysm.k:
            fd = np.column_stack([(sysm.bc(ya, yb, p + h * e) - base) / h for e in np.eye(sysm.k)])
            assert np.allclose(fd, P[0], atol=1e-5, rtol=1e-5), name


def test_a_closed_shell_on_a_substrate_under_a_sphere_has_its_force_from_its_energy():
    scene = on_substrate()
    s = sb.solve(scene, delta=0.1)
    assert s.success and s.valid, s.flags
    assert s.topology == "closed-line-cap"  # the pole lifted off the tip (a ring), a cap on the substrate
    h = 1e-4
    E = [sb.solve(scene, delta=0.1 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)


def test_a_closed_shell_on_a_substrate_is_solved_cold_at_a_force():
    # cold: the two symmetric problems at that force, joined; the state is the delta-controlled one
    scene = on_substrate()
    s = sb.solve(scene, delta=0.1, estimate_error=False)
    f = sb.solve(scene, force=s.force, estimate_error=False)
    assert f.success and f.valid and f.topology == s.topology
    assert f.delta == pytest.approx(0.1, abs=1e-6)
    with pytest.raises(ValueError, match="lambda0 control is not offered for a closed shell on a substrate"):
        sb.solve(scene, lambda0=1.01)


def test_a_closed_shells_profile_keeps_the_substrate_where_it_is():
    s = sb.solve(on_substrate(), delta=0.2, estimate_error=False)
    f = s.profile()
    on_plane = f["region"] == 3
    assert on_plane.any() and np.ptp(f["z"][on_plane]) < 1e-12
    edge = np.nonzero(np.diff(on_plane.astype(int)) == -1)[0][0]  # the plane's edge, then the lower free shell
    assert f["S"][edge] == pytest.approx(f["S"][edge + 1], abs=1e-12)
    assert f["z"][edge] == pytest.approx(f["z"][edge + 1], abs=1e-9)  # was off by delta


def test_a_closed_spheres_convexity_is_its_upper_halfs_the_dome():
    from shellbvp.convexity import convexity_limits

    closed = sb.Scene(closed=True, support="plates", tip=sb.SphereTip(), rho=0.5, gamma=1.0, beta=1e-2)
    dome, bowl = (sb.Scene(tip=sb.SphereTip(), rho=0.5, gamma=g, beta=1e-2) for g in (-1.0, 1.0))
    limits = convexity_limits(closed, stretches=(1.0, 1.5), kappa_max=10)
    assert limits == convexity_limits(dome, stretches=(1.0, 1.5), kappa_max=10)
    assert limits != convexity_limits(bowl, stretches=(1.0, 1.5), kappa_max=10)


def test_a_small_tip_on_a_thin_sphere_on_a_substrate_is_reissners_two_poles_in_series():
    # a small load: a point force at each pole, as between plates (to 1e-4)
    eps = 0.02
    beta = eps**2 / 3
    d = eps / 100
    s = sb.solve(on_substrate(beta=beta, rho=0.2), delta=d)
    assert s.valid and s.topology == "closed-point-point"
    plates_force = sb.solve(plates(beta), delta=d).force
    assert s.force == pytest.approx(plates_force, rel=1e-4)
    assert 0.96 < s.force / d / (4 * math.sqrt(3 * beta)) < 1.0


@pytest.mark.slow  # a two-contact curve (~25 s); its file round trip is the rimmed curves' code
def test_a_curve_of_a_closed_shell_on_a_substrate_is_written_and_read_back(tmp_path):
    c = sb.curve(on_substrate(beta=1e-3, rho=0.3), delta_max=0.04)
    assert np.all(c.status == 0) and np.all(c.valid)
    assert np.all(np.diff(c.force) > 0)
    assert {str(t) for t in c.topology} <= {"closed-point-line", "closed-line-cap"}
    c.to_hdf5(tmp_path / "cell.h5")
    back = sb.read_curve(tmp_path / "cell.h5")
    assert back.scene == c.scene and back.scene.two_contacts
    assert np.array_equal(back.force, c.force)


@pytest.mark.slow  # a pressurised structure with the substrate's code: its own derivation
@pytest.mark.parametrize("sealed", [False, True])
def test_a_pressurised_closed_shell_on_a_substrate_has_its_force_from_its_energy(sealed):
    scene = on_substrate(pressure=0.1, sealed=sealed)
    s = sb.solve(scene, delta=0.1)
    assert s.success and s.valid, s.flags
    h = 1e-4
    E = [sb.solve(scene, delta=0.1 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)
    assert (s.pressure > 0.1) == sealed  # a sealed shell's pressure rises as it is squeezed


def test_a_sphere_between_plates_is_checked_on_both_sides_of_its_equator():
    # the half's modes symmetric and antisymmetric about the equator; n = 1 (sliding on the
    # frictionless plates, zero) is left out by default
    s = sb.solve(plates(1e-3), delta=0.05)
    res = sb.stability(s, elements=40)
    assert 1 not in res.modes and 0 in res.modes and 2 in res.modes
    assert res.stable and res.minimum > 1e-3  # the spin about the axis (n = 0, zero) held: no rigid motion left
    from shellbvp.modal_stability import either_side
    from shellbvp.modal_stability.fem import Stability

    a = Stability(modes=np.array([2, 3]), eigenvalues=np.array([[1.0, 2.0], [5.0, 6.0]]), elements=1, S0=0.0)
    b = Stability(modes=np.array([2, 3]), eigenvalues=np.array([[0.5, 3.0], [7.0, 8.0]]), elements=1, S0=0.0)
    assert either_side([a, b]).eigenvalues.tolist() == [[0.5, 1.0], [5.0, 6.0]]


def test_a_closed_shell_on_a_substrate_under_a_curved_tip_has_the_smooth_contact_only():
    with pytest.raises(ValueError, match="smooth"):
        on_substrate(contact="paper")


def _record(scene, R_L, mu_H, depths, noise, seed):
    """A record made of the model's own states at the depths (lab units), with relative noise."""
    force = np.array([sb.solve(scene, delta=d, estimate_error=False).force for d in depths])
    rng = np.random.default_rng(seed)
    return depths * R_L, force * mu_H * R_L * (1 + noise * rng.standard_normal(depths.size))


def test_a_capsule_between_plates_is_fitted():
    scene = sb.Scene.preset("capsule-plates")
    disp, force = _record(scene, 30e-6, 0.5, np.linspace(0.02, 0.2, 12), 0.005, 3)
    res = sb.fit(scene, disp, force, R_L=30e-6)
    assert res.success, res.message
    assert res.mu_H_ci95[0] < 0.5 < res.mu_H_ci95[1]


@pytest.mark.slow  # a model curve of two contacts (~20 s of CPU)
def test_a_pollen_grain_on_a_substrate_is_fitted():
    scene = sb.Scene.preset("pollen")
    disp, force = _record(scene, 25e-6, 2.0, np.linspace(0.01, 0.1, 10), 0.005, 4)
    res = sb.fit(scene, disp, force, R_L=25e-6)
    assert res.success, res.message
    assert res.mu_H_ci95[0] < 2.0 < res.mu_H_ci95[1]


@pytest.mark.parametrize("name,preset,radius,truth", [
    ("capsule_plates_synthetic.csv", "capsule-plates", "30um", 0.5),
    pytest.param("cell_glass_synthetic.csv", "cell-glass", "2.5um", 3.3, marks=pytest.mark.slow),
])
def test_the_shipped_closed_shell_records_fit_as_docs_closed_md_shows(name, preset, radius, truth, cli_main):
    import json
    from pathlib import Path

    data = Path(sb.__file__).parent / "data" / name
    r = cli_main("fit", str(data), "--preset", preset, "--radius", radius, "--json")  # the command, in this process
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    lo, hi = out["mu_H_ci95"]
    assert lo < truth < hi and out["quality"] == "good"
