"""Closed shells of a user meridian (issue 55): ``Scene(closed=True, shell=UserShell(R, Z, L))``
is the upper half from pole to equator, the lower half its mirror image (docs/closed.md)."""

import math

import numpy as np
import pytest

import shellbvp as sb

#: The spheroid gamma = 0.7's upper half (Z = 0.7 cos S): the built-in closed spheroid's
SPHEROID = ("sin(S)", "0.7*cos(S)", "pi/2")
#: A sphere with its top flattened: pole curvature 0.4 (the sphere's 1), the equator's as the sphere's
FLAT_TOP = ("sin(S)", "cos(S) - 0.2*cos(S)**3", "pi/2")


def closed(shell, support="plates", **kw):
    tip = dict(tip=sb.FlatTip()) if support == "plates" else dict(tip=sb.SphereTip(), rho=kw.pop("rho", 1.0))
    kw.setdefault("beta", None if "thickness" in kw else 1e-3)
    return sb.Scene(closed=True, support=support, shell=shell, **tip, **kw)


@pytest.mark.parametrize("meridian, message", [
    (("sin(S)", "cos(S)", "1.5"), "vertical tangent, R'(L) = 0"),            # the equator is at pi/2
    (("sin(S)", "-cos(S)", "pi/2"), "runs down to its equator, Z'(L) < 0"),  # a bowl, not a dome
    (("sin(S) - 0.8*sin(2*S)", "cos(S)", "pi/2"), "leaves its pole horizontally, R'(0) > 0"),
    (("sin(S)*(1 - 3*sin(2*S)**2)", "cos(S)", "pi/2"), "R(S) must be > 0"),  # crosses the axis
    (("sin(S)", "cos(S) + 0.8*sin(S)**2*cos(S)", "pi/2"), "the pole must be the highest point"),  # a dimple
    (("sin(S)", "cos(S) - 0.8*sin(2*S)**2", "pi/2"), "Z(S) must be > 0 before the equator"),
])
def test_a_meridian_that_is_no_closed_shells_upper_half_is_refused_in_one_line(meridian, message):
    shell = sb.UserShell(*meridian)  # a rimmed shell may have it
    with pytest.raises(ValueError, match=re_escape(message)) as err:
        closed(shell)
    assert str(err.value).startswith("shell: ") and "\n" not in str(err.value)
    assert shell.closed_problem() == str(err.value)  # the reason without a scene, and no code generated


def re_escape(text):
    import re

    return re.escape(text)


@pytest.mark.parametrize("delta", [0.02, 0.2])
def test_the_spheroids_meridian_between_plates_is_the_built_in_closed_spheroid(delta):
    built_in = sb.solve(sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=0.7, beta=1e-3), delta=delta)
    user = sb.solve(closed(sb.UserShell(*SPHEROID)), delta=delta)
    assert built_in.success and user.success and user.topology == built_in.topology
    assert user.force == pytest.approx(built_in.force, rel=1e-8)
    assert user.energy == pytest.approx(built_in.energy, rel=1e-8)
    assert np.allclose(user.p, built_in.p, rtol=1e-8, atol=1e-10)


@pytest.mark.parametrize("delta", [0.02, 0.2])
def test_the_spheroids_meridian_on_a_substrate_is_the_built_in_closed_spheroid(delta):
    # both halves, each its own contact (the tip above, the substrate below): the mirror image
    built_in = sb.solve(sb.Scene(closed=True, tip=sb.SphereTip(), rho=1.0, gamma=0.7, beta=1e-3), delta=delta)
    user = sb.solve(closed(sb.UserShell(*SPHEROID), support="substrate"), delta=delta)
    assert built_in.valid and user.valid and user.topology == built_in.topology
    assert user.force == pytest.approx(built_in.force, rel=1e-8)
    assert user.energy == pytest.approx(built_in.energy, rel=1e-8)
    assert np.allclose(user.p, built_in.p, rtol=1e-8, atol=1e-10)


def test_a_flattened_top_between_plates_runs_to_full_depth_with_a_plausible_force():
    scene = closed(sb.UserShell(*FLAT_TOP))
    c = sb.curve(scene, delta_max=0.5)
    assert c.complete and c.delta[-1] == pytest.approx(0.5)
    assert np.all(c.status == 0) and np.all(c.valid) and np.all(np.diff(c.force) > 0)
    # a small load: Reissner's point-load stiffness of the pole's curvature k, 4 k sqrt(3 beta) for two
    # poles in series, bounds it from below (the flatter top's curvature grows away from the pole:
    # 1.21 times that), the sphere's (k = 1) from above
    d = 0.002
    k = sb.solve(scene, delta=d).force / d
    sphere = sb.solve(sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=1e-3), delta=d)
    assert 4 * 0.4 * math.sqrt(3e-3) < k < 0.6 * sphere.force / d
    # F = dE/ddelta on the whole shell at depth
    h, s = 1e-4, sb.solve(scene, delta=0.3)
    E = [sb.solve(scene, delta=0.3 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)


def test_a_closed_user_meridian_is_written_read_back_and_described(tmp_path):
    scene = closed(sb.UserShell(*FLAT_TOP), thickness=0.05)
    assert sb.Scene.from_dict(scene.to_dict()) == scene and scene.to_dict()["shell"]["kind"] == "user"
    words = scene.describe(R_L=30e-6)
    assert "closed shell (user meridian) between plates on an equatorial radius of 30 um" in words
    c = sb.curve(scene, delta_max=0.05)
    assert np.all(c.status == 0)
    c.to_hdf5(tmp_path / "flat_top.h5")
    back = sb.read_curve(tmp_path / "flat_top.h5")
    assert back.scene == scene and back.scene.closed and back.scene.shell == scene.shell
    assert np.array_equal(back.force, c.force)


def test_a_flattened_top_between_plates_is_fitted():
    scene = closed(sb.UserShell(*FLAT_TOP))
    depths, R_L, mu_H = np.linspace(0.02, 0.2, 8), 30e-6, 0.5
    force = np.array([sb.solve(scene, delta=d, estimate_error=False).force for d in depths])
    noise = 1 + 0.005 * np.random.default_rng(3).standard_normal(depths.size)
    res = sb.fit(scene, depths * R_L, force * mu_H * R_L * noise, R_L=R_L)
    assert res.success, res.message
    assert res.mu_H_ci95[0] < mu_H < res.mu_H_ci95[1] and res.mu_H_ci95[1] - res.mu_H_ci95[0] < 0.05

def test_the_command_line_takes_a_closed_meridian(tmp_path, cli_main):
    cli = cli_main  # the command's main in this process
    r = cli("curve", "--closed", "--support", "plates", "--flat-tip", "--meridian", "; ".join(FLAT_TOP), "--beta", "1e-3",
            "--delta-max", "0.05", "-o", "flat.h5", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    back = sb.read_curve(tmp_path / "flat.h5")
    assert back.scene == closed(sb.UserShell(*FLAT_TOP)) and back.delta[-1] == pytest.approx(0.05)
    bad = cli("curve", "--closed", "--flat-tip", "--meridian", "sin(S); cos(S); 1.5", "-o", "bad.h5", cwd=tmp_path)
    assert bad.returncode == 2 and "R'(L) = 0" in bad.stderr and len(bad.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "bad.h5").exists()
    for args, message in ((("--gamma", "2", "--meridian", "; ".join(FLAT_TOP)), "not allowed with argument"),
                          (("--meridian", "sin(S); cos(S)"), "three formulas 'R(S); Z(S); L'")):
        r = cli("curve", "--closed", *args, cwd=tmp_path)
        assert r.returncode == 2 and message in r.stderr, r.stderr
    # a rimmed shell's meridian, pole to rim (tests/test_symbolic.py's user spheroid: one structure for both)
    rimmed = cli("curve", "--meridian", "2*sin(S); -2*cos(S); pi/2", "--delta-max", "0.02", "--points", "2", "-o",
                 "rim.h5", cwd=tmp_path)
    assert rimmed.returncode == 0, rimmed.stderr
    assert sb.read_curve(tmp_path / "rim.h5").scene.shell == sb.UserShell("2*sin(S)", "-2*cos(S)", "pi/2")


@pytest.mark.slow  # the user meridian's substrate structure derived and a two-contact curve (~160 s on a fresh cache)
def test_a_flattened_top_on_a_substrate_under_a_sphere_is_solved_along_a_curve():
    scene = closed(sb.UserShell(*FLAT_TOP), support="substrate", rho=0.5)
    c = sb.curve(scene, delta_max=0.1)
    assert c.complete and np.all(c.status == 0) and np.all(c.valid) and np.all(np.diff(c.force) > 0)
    h, s = 1e-4, sb.solve(scene, delta=0.1)
    E = [sb.solve(scene, delta=0.1 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)


@pytest.mark.slow  # a pressurised structure of its own derived (~55 s on a fresh cache)
def test_a_sealed_spheroids_meridian_between_plates_is_the_built_in_sealed_capsule():
    kw = dict(closed=True, support="plates", tip=sb.FlatTip(), beta=1e-3, pressure=0.05, sealed=True)
    built_in = sb.solve(sb.Scene(gamma=0.7, **kw), delta=0.2)
    user = sb.solve(sb.Scene(shell=sb.UserShell(*SPHEROID), **kw), delta=0.2)
    assert built_in.success and user.success
    assert user.force == pytest.approx(built_in.force, rel=1e-8)
    assert user.pressure == pytest.approx(built_in.pressure, rel=1e-8)
