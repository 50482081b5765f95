"""A wall whose thickness varies along the meridian (``ThicknessProfile``, issue 58).

The derivation's equations with a profile are checked against the energy in
``tests/test_variational.py``; here the package: a uniform profile is the uniform scene, the
force is the energy's derivative, small loads see the pole's thickness, and the profile
travels through scenes and files.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.thickness_profile import ThicknessProfile, positions_to_S, read_profile_table

L = math.pi / 2


@pytest.fixture(scope="module")
def uniform():
    return sb.Scene.preset("base", beta=None, thickness=0.05)


@pytest.mark.parametrize("given", ["table", pytest.param("formula", marks=pytest.mark.slow)])
def test_a_uniform_profile_is_the_uniform_scene(uniform, given):
    """Given as a formula or as a table (the spline through constant rows), a uniform wall's
    states equal the uniform scene's to 1e-10 (its generated code holds t(S) = 1 as a term;
    the formula's, one more derivation, behind --runslow)."""
    if given == "formula":
        scene = uniform.replace(thickness=ThicknessProfile.formula("0.05 + 0*S"))
    else:
        scene = uniform.replace(thickness=ThicknessProfile.table(np.linspace(0, L, 7), np.full(7, 0.05)))
    assert scene.structure() != uniform.structure()  # the profiled code, not the uniform one
    for delta in (0.03, 0.4):  # a small cap and a deep one (a cold start at 0.02 costs 10-12 s each, at 0.03 0.5 s)
        ref = sb.solve(uniform, delta=delta, tol=1e-8, estimate_error=False)
        for scene in (scene,):
            s = sb.solve(scene, delta=delta, tol=1e-8, estimate_error=False)
            assert s.success and ref.success
            assert abs(s.force - ref.force) < 1e-10 * max(1.0, abs(ref.force)), (delta, s.force, ref.force)
            assert abs(s.Sc - ref.Sc) < 1e-10


def test_force_is_the_derivative_of_a_profiled_walls_energy(uniform):
    """F = dE/ddelta on a wall thinning linearly to half at the rim, central differences as
    for the uniform wall (tests/test_solve.py: the same 5e-6)."""
    scene = uniform.replace(thickness=ThicknessProfile.formula("0.05*(1 - 0.5*S/L)"))
    for delta in (0.3,):
        h = 1e-3
        s0 = sb.solve(scene, delta=delta, tol=1e-8, estimate_error=False)
        sp_, sm_ = (sb.solve(scene, delta=delta + k * h, tol=1e-8, guess=s0, estimate_error=False) for k in (1, -1))
        assert s0.success and sp_.success and sm_.success
        dE = (sp_.energy - sm_.energy) / (2 * h)
        assert abs(dE - s0.force) < 5e-6 * max(1.0, s0.force), (delta, s0.force, dE)


@pytest.mark.slow
def test_small_loads_follow_the_poles_thickness(uniform):
    """A wall equal to H0 near the pole for a few boundary-layer widths (sqrt(R H) ~ 0.22)
    and twice as thick at the rim: at delta = 0.1 H0 its force is the uniform H0 wall's within
    2 %; a wall thinner everywhere but at the pole is not the thin wall's."""
    scene = uniform.replace(thickness=ThicknessProfile.formula("0.05*(1 + exp(-((L - S)/0.25)**2))"))
    delta = 0.1 * 0.05
    f_ref = sb.solve(uniform, delta=delta, estimate_error=False).force
    f = sb.solve(scene, delta=delta, estimate_error=False).force
    assert abs(f / f_ref - 1) < 0.02, (f, f_ref)
    thick = 2 * sb.solve(uniform.replace(thickness=0.1), delta=delta, estimate_error=False).force  # units mu H0
    assert thick / f > 2  # the rim's thickness would be far off


def test_a_profile_is_checked_along_the_whole_meridian(uniform):
    with pytest.raises(ValueError, match=r"thickness profile must stay in \(0, 0.5\]"):
        uniform.replace(thickness=ThicknessProfile.formula("0.05 - 0.1*S"))
    with pytest.raises(ValueError, match="from the pole"):
        uniform.replace(thickness=ThicknessProfile.table([0.2, 1.0, L], [0.05, 0.05, 0.05]))
    with pytest.raises(ValueError, match="thickness H"):
        ThicknessProfile.formula("__import__('os')")
    with pytest.raises(ValueError, match="2 to 64 rows"):
        ThicknessProfile.table(np.linspace(0, L, 65), np.full(65, 0.05))


def test_the_pole_sets_beta_and_a_new_thickness_scales_the_profile(uniform):
    wall = ThicknessProfile.formula("0.04*(1 + S)")
    scene = uniform.replace(thickness=wall)
    assert scene.thickness == pytest.approx(0.04) and scene.beta == pytest.approx(0.04**2 / 3)
    thicker = scene.replace(thickness=0.08)
    assert thicker.thickness_profile.at([1.0], L=L)[0] == pytest.approx(0.16)
    assert thicker.structure() == scene.structure()  # the same generated code: only the scale changed
    assert scene.replace(beta=0.01).thickness_profile is None
    assert sb.Scene.from_dict(scene.to_dict()) == scene
    tab = uniform.replace(thickness=ThicknessProfile.table([0, 0.5, L], [0.05, 0.04, 0.03]))
    assert sb.Scene.from_dict(tab.to_dict()) == tab


def test_a_table_in_lab_units_along_the_arc_or_the_angle(tmp_path):
    """A thickness file in lab units: along the arc of a prolate spheroid (gamma 2, R_L 300 um)
    the positions become the package's S through the meridian's arc length."""
    scene = sb.Scene.preset("prolate2", beta=None, thickness=0.05)
    S = np.linspace(0.0, L, 2001)
    arc = np.concatenate([[0], np.cumsum(np.hypot(np.diff(np.sin(S)), np.diff(2 * np.cos(S))))])
    path = tmp_path / "wall.csv"
    rows = np.linspace(0.0, arc[-1], 5)
    path.write_text("arc_um,thickness_um\n" + "".join(f"{a * 300:.9f},{15 - 5 * a / arc[-1]:.9f}\n" for a in rows))
    pos, H, along = read_profile_table(path, R_L=300e-6)
    assert along == "arc" and H[0] == pytest.approx(0.05)
    S_rows = positions_to_S(scene, pos, along)
    assert S_rows[-1] == pytest.approx(L, rel=1e-6)
    assert np.interp(S_rows[2], S, arc) == pytest.approx(rows[2], rel=1e-5)
    bad = tmp_path / "bad.csv"
    bad.write_text("arc_furlong,thickness_um\n0,1\n1,1\n")
    with pytest.raises(ValueError, match="length unit"):
        read_profile_table(bad, R_L=300e-6)
    bad.write_text("angle_deg,thickness_um\n0,15\n95,15\n")
    pos, H, along = read_profile_table(bad, R_L=300e-6)
    with pytest.raises(ValueError, match="must lie in"):
        positions_to_S(scene, pos, along)


def test_the_command_line_reads_a_thickness_file(tmp_path):
    """``--thickness-profile FILE`` with ``--radius``: the table becomes the scene's profile (the
    pole's thickness sets beta); without ``--radius``, or with ``--thickness`` too, one line."""
    from shellbvp.cli import build_parser, scene_from_args

    path = tmp_path / "wall.csv"
    path.write_text("# sections\nangle_deg,thickness_um\n0,15\n45,12\n90,9\n")
    args = build_parser().parse_args(["solve", "--preset", "base", "--radius", "300um", "--thickness-profile",
                                      str(path)])
    scene = scene_from_args(args)
    assert scene.thickness == pytest.approx(0.05) and scene.beta == pytest.approx(0.05**2 / 3)
    assert scene.thickness_profile.at([L / 2], L=L)[0] == pytest.approx(0.04)  # the hemisphere: S is the angle
    for extra, message in ((["--thickness", "15um"], "drop --thickness"), ([], "needs --radius")):
        argv = ["solve", "--preset", "base", "--thickness-profile", str(path), *extra]
        if extra:
            argv += ["--radius", "300um"]
        with pytest.raises(ValueError, match=message):
            scene_from_args(build_parser().parse_args(argv))


def test_a_profiled_curve_file_reads_back_with_its_profile(uniform, tmp_path):
    """The curve file stores the profile: read back, the scene (and so its generated code) is the
    same, and the states' profiles carry the local thickness over the pole's."""
    scene = uniform.replace(thickness=ThicknessProfile.formula("0.05*(1 - 0.5*S/L)"))
    c = sb.curve(scene, delta_max=0.05)
    c.to_hdf5(tmp_path / "c.h5")
    back = sb.read_curve(tmp_path / "c.h5")
    assert back.scene == scene and back.scene.structure() == scene.structure()
    s = sb.solve(scene, delta=0.05)
    prof = s.profile()
    S, t = np.asarray(prof["S"]), np.asarray(prof["thickness"])
    assert np.allclose(t, 1 - 0.5 * S / L, atol=1e-12)


def test_transverse_shear_takes_the_local_thickness():
    """The shear strain is Q/(kappa mu H(S)): a profile twice the pole's thickness outside the
    edge halves the tilt that a uniform wall's Q gives (Q in units of mu H0)."""
    from shellbvp.thickness import shear_delta

    r = np.linspace(0.0, 1.0, 201)
    Q = -0.1 / (2 * np.pi * np.maximum(r, 1e-3))
    uniform = shear_delta([("free", {"r": r, "Q": Q})], 0, 0.1, 0.05)
    thick = shear_delta([("free", {"r": r, "Q": Q, "thickness": np.full_like(r, 2.0)})], 0, 0.1, 0.05)
    assert uniform > 0 and thick == pytest.approx(uniform / 2, rel=1e-12)


def test_the_hoop_indicator_takes_the_local_stiffnesses(uniform):
    """On a uniform profile the wrinkling indicator is the uniform wall's; on a wall thinning to
    half at the rim it fires no later (the thinner wall's threshold is lower)."""
    flat = uniform.replace(thickness=ThicknessProfile.table(np.linspace(0, L, 7), np.full(7, 0.05)))
    thin = uniform.replace(thickness=ThicknessProfile.formula("0.05*(1 - 0.5*S/L)"))
    for model in ("strip", "band"):
        ref = sb.hoop_indicator(sb.solve(uniform, delta=0.3), model=model)
        same = sb.hoop_indicator(sb.solve(flat, delta=0.3), model=model)
        assert same.ratio == pytest.approx(ref.ratio, rel=1e-8)
    assert sb.hoop_indicator(sb.solve(thin, delta=0.3)).ratio < ref.ratio
