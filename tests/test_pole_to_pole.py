"""A closed shell's meridian given from pole to pole as one formula (issue 55):
``UserShell.pole_to_pole(R, Z, L)`` split at its widest point into the halves that
``UserShell(R, Z, L)`` and ``UserShell.closed_halves`` take (docs/closed.md)."""

import math
import subprocess
import sys

import pytest

import shellbvp as sb

#: An egg as one formula: polar semi-axes 1.3 above and 0.7 below the widest point S = pi/2
EGG = ("sin(S)", "cos(S)*(1 + 0.3*cos(S))", "pi")
#: ... and its two halves written by hand, each from its own pole (the lower in its mirror image)
EGG_HALVES = (("sin(S)", "cos(S) + 0.3*cos(S)**2", "pi/2"), ("sin(S)", "cos(S) - 0.3*cos(S)**2", "pi/2"))


def plates(shell, **kw):
    return sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), shell=shell, beta=1e-3, **kw)


def on_substrate(shell):
    return sb.Scene(closed=True, shell=shell, tip=sb.SphereTip(), rho=1.0, beta=1e-3)


@pytest.fixture(scope="module")
def egg():
    return sb.UserShell.pole_to_pole(*EGG)


@pytest.mark.parametrize("Z, gamma", [("cos(S)", 1.0), ("0.7*cos(S)", 0.7)])
def test_a_sphere_and_a_spheroid_pole_to_pole_are_the_built_in_closed_spheroid_between_plates(Z, gamma):
    shell = sb.UserShell.pole_to_pole("sin(S)", Z, "pi")
    half = sb.UserShell("sin(S)", Z, "pi/2")
    assert shell.lower is None and shell.upper_half() == half and shell.equator == pytest.approx(math.pi / 2, abs=1e-15)
    assert shell.meridian == ("sin(S)", Z, "pi") and shell != half  # what was given is kept
    scene = plates(shell)
    assert scene.structure() == plates(half).structure()  # the half's generated code
    s, h, ref = (sb.solve(x, delta=0.02) for x in (scene, plates(half), plates(sb.Spheroid(), gamma=gamma)))
    assert s.valid and s.status == 0
    for other in (h, ref):
        assert s.force == pytest.approx(other.force, rel=1e-10) and s.energy == pytest.approx(other.energy, rel=1e-10)


def test_an_eggs_halves_are_its_formula_substituted(egg):
    hand = sb.UserShell.closed_halves(*EGG_HALVES)
    assert egg.lower is not None and egg.upper_half() == hand.upper_half() and egg.lower == hand.lower
    assert {k: v for k, v in egg.description().items() if k != "pole_to_pole"} == hand.description()
    assert egg.description()["pole_to_pole"] == {"R": "sin(S)", "Z": "(0.3*cos(S) + 1)*cos(S)", "L": "pi"}
    assert egg.pole_curvature({}) == pytest.approx(-1.6) and egg.lower.pole_curvature({}) == pytest.approx(-0.4)
    assert repr(egg) == "UserShell.pole_to_pole(R='sin(S)', Z='(0.3*cos(S) + 1)*cos(S)', L='pi')"


def test_an_equator_found_numerically_is_exact_to_the_last_digit_and_splits_the_meridian():
    # R' = exp(0.2 cos S) (cos S - 0.2 sin^2 S) = 0 at cos S_e = (sqrt(1.16) - 1)/0.4
    shell = sb.UserShell.pole_to_pole("sin(S)*exp(0.2*cos(S))", "cos(S)", "pi")
    S_e = math.acos((math.sqrt(1.16) - 1) / 0.4)
    assert shell.equator == pytest.approx(S_e, abs=4e-16)
    assert float(shell.geometry.L) == shell.equator and float(shell.lower.geometry.L) == pytest.approx(
        math.pi - S_e, abs=1e-15)
    assert shell.lower is not None and shell.closed_problem() is None
    # each half rescaled to its equator R = 1, Z = 0; the lower's pole 1 + cos S_e below it
    from symbolic.geometry import S

    g, lg = shell.geometry, shell.lower.geometry
    for half in (g, lg):
        assert float(half.R.subs(S, half.L)) == pytest.approx(1.0, abs=1e-14)
        assert float(half.Z.subs(S, half.L)) == pytest.approx(0.0, abs=1e-14)
    scale = math.sin(S_e) * math.exp(0.2 * math.cos(S_e))
    assert float(g.Z.subs(S, 0)) == pytest.approx((1 - math.cos(S_e)) / scale, rel=1e-14)
    assert float(lg.Z.subs(S, 0)) == pytest.approx((1 + math.cos(S_e)) / scale, rel=1e-14)


@pytest.mark.parametrize("meridian, message", [
    (("sin(S)", "cos(S)", "3.14159"), "R(L) = 0 (the bottom pole on the axis); got 2.65e-06 at S = L = 3.14159 "
                                      "(give L exactly"),
    (("sin(S)", "cos(S)", "pi/2"), "R(L) = 0 (the bottom pole on the axis); got 1"),
    (("sin(S)", "cos(S) + S**2", "pi"), "Z'(L) = 0 (a smooth bottom pole)"),
    (("sin(S) + sin(2*S)/2", "cos(S)", "pi"), "leaves both poles horizontally, R'(0) > 0 and R'(L) < 0"),
    (("sin(S)*(1.5 + cos(2*S))", "cos(S)", "pi"), "one widest point (its equator), where R'(S) = 0 between the "
                                                  "poles; R'(S) = 0 at 3 points, S = 0.7"),
    # R' = cos S (cos^2 S - 1/4)^2: its sign changes at pi/2 only, it touches zero at pi/3 and 2 pi/3
    (("9*sin(S)/16 - sin(S)**3/2 + sin(S)**5/5", "cos(S)", "pi"), "R'(S) = 0 at 3 points, S = 1.047, 1.571, 2.094"),
    (("sin(S)", "cos(S)**3", "pi"), "the tangent at the widest point S = 1.5708 must be vertical"),
    (("sin(S)", "-cos(S)", "pi"), "Z(S) decreases through the widest point"),
    (("sin(S)", "cos(S) - 0.4*sin(S)**2*(1 - cos(S))", "pi"),  # a dimple at the bottom pole
     "the lower half (S >= S_e = 1.5708, in its mirror image from its pole): a closed shell's meridian: the pole "
     "must be the highest point"),
])
def test_a_meridian_that_is_no_closed_shells_is_refused_in_one_line(meridian, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")) as err:
        sb.UserShell.pole_to_pole(*meridian)
    assert str(err.value).startswith("shell: ") and "\n" not in str(err.value)


def test_a_whole_meridian_is_a_closed_shells_and_is_stored_as_given(egg):
    sphere = sb.UserShell.pole_to_pole("sin(S)", "cos(S)", "pi")
    with pytest.raises(ValueError, match=r"pole to pole \(UserShell.pole_to_pole\) is a closed shell's"):
        sb.Scene(shell=sphere, beta=1e-3)
    for scene in (plates(sphere), on_substrate(egg)):
        d = scene.to_dict()
        assert d["shell"]["pole_to_pole"] == dict(zip("RZL", scene.shell.meridian))
        back = sb.Scene.from_dict(d)
        assert back == scene and back.shell.meridian == scene.shell.meridian
        assert back.structure() == scene.structure()
    assert "closed shell (user meridian, pole to pole) between plates" in plates(sphere).describe()
    egg_text = "closed shell (user meridian, pole to pole, halves that differ) on a substrate"
    assert egg_text in on_substrate(egg).describe()
    assert sb.UserShell.returns_to_axis("sin(S)", "pi") and not sb.UserShell.returns_to_axis("sin(S)", "pi/2")


@pytest.mark.slow  # the egg's halves' structures derived (~2 min on a fresh cache)
def test_an_egg_pole_to_pole_is_the_closed_halves_of_its_two_halves_on_a_substrate(egg):
    s = sb.solve(on_substrate(egg), delta=0.02)
    h = sb.solve(on_substrate(sb.UserShell.closed_halves(*EGG_HALVES)), delta=0.02)
    assert s.valid and h.valid and s.topology == h.topology
    assert s.force == pytest.approx(h.force, rel=1e-8) and s.energy == pytest.approx(h.energy, rel=1e-8)


def cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=600)


def test_the_command_line_reads_a_meridian_that_returns_to_the_axis_pole_to_pole(tmp_path):
    import json

    spheroid = "sin(S); 0.7*cos(S); pi"
    scene = plates(sb.UserShell.pole_to_pole("sin(S)", "0.7*cos(S)", "pi"))
    common = ("--closed", "--support", "plates", "--flat-tip", "--meridian", spheroid, "--beta", "1e-3")
    r = cli("solve", *common, "--delta", "0.02", "--json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["force"] == pytest.approx(sb.solve(scene, delta=0.02).force, rel=1e-12)
    r = cli("curve", *common, "--delta-max", "0.02", "--points", "2", "-o", "pp.h5", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert sb.read_curve(tmp_path / "pp.h5").scene == scene
    info = cli("info", "pp.h5", cwd=tmp_path)
    assert info.returncode == 0, info.stderr
    assert "shell=UserShell.pole_to_pole(R='sin(S)', Z='0.7*cos(S)', L='pi')" in info.stdout
    assert "closed shell (user meridian, pole to pole) between plates" in info.stdout
    for args, message in ((("--closed", "--meridian", spheroid, "--meridian-lower", "sin(S); cos(S); pi/2"),
                           "--meridian, --meridian-lower: --meridian returns to the axis at S = L"),
                          (("--closed", "--meridian", "sin(S); cos(S); -1"), "--meridian: L must be a positive number"),
                          (("--meridian", spheroid), "it needs closed=True (--closed)"),
                          (("--closed", "--meridian", "sin(S); cos(S)**3; pi"), "must be vertical")):
        r = cli("solve", *args, "--delta", "0.02", cwd=tmp_path)
        assert r.returncode == 2 and message in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
