"""Closed shells (issue 55, first step): a complete spheroid compressed between two plates, or on
a substrate under a flat plate, solved on the half above the equator (docs/closed.md)."""

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
    (dict(closed=True, support="plates"), "flat plate only"),
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


def test_what_a_closed_shell_does_not_have_yet_is_refused():
    s = sb.solve(plates(1e-3), delta=0.05)
    with pytest.raises(ValueError, match="closed shell is not supported yet"):
        sb.stability(s)
    from shellbvp.fe import check_solid_scene

    with pytest.raises(ValueError, match="closed shell"):
        check_solid_scene(plates(1e-3))
