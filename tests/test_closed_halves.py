"""Closed shells whose halves differ (issue 55, an egg): ``UserShell.closed_halves(upper, lower)``
on a substrate under a curved tip, each half its own meridian, module and L (docs/closed.md)."""

import numpy as np
import pytest

import shellbvp as sb

#: The spheroid gamma = 0.7's upper half (as tests/test_closed_meridian.py has it)
SPHEROID = ("sin(S)", "0.7*cos(S)", "pi/2")
#: The same half meridian at twice the pace: its own formulas, module and L = pi/4
SPHEROID_FAST = ("sin(2*S)", "0.7*cos(2*S)", "pi/4")
#: An egg: a prolate upper half on an oblate lower half
PROLATE, OBLATE = ("sin(S)", "1.3*cos(S)", "pi/2"), ("sin(S)", "0.7*cos(S)", "pi/2")


def on_substrate(shell, **kw):
    return sb.Scene(closed=True, shell=shell, tip=sb.SphereTip(), rho=kw.pop("rho", 1.0), beta=1e-3, **kw)


@pytest.mark.parametrize("halves, message", [
    ((SPHEROID, ("sin(S)", "cos(S)", "1.5")), "the lower half (in its mirror image): a closed shell's meridian ends"),
    ((("sin(S)", "-cos(S)", "pi/2"), SPHEROID), "runs down to its equator, Z'(L) < 0"),
    ((SPHEROID, ("sin(S)", "cos(S) - 0.8*sin(2*S)**2", "pi/2")), "the lower half (in its mirror image)"),
])
def test_a_half_that_is_no_closed_shells_half_is_refused_in_one_line(halves, message):
    shell = sb.UserShell.closed_halves(*halves)
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")) as err:
        on_substrate(shell)
    assert str(err.value).startswith("shell: ") and "\n" not in str(err.value)


@pytest.mark.parametrize("kw, message", [
    (dict(support="plates"), "the shell must be mirror-symmetric about its equator"),
    (dict(support="plates", rho=0.5), "the shell must be mirror-symmetric about its equator"),
])
def test_halves_that_differ_are_refused_where_the_mirror_symmetry_is_needed(kw, message):
    shell = sb.UserShell.closed_halves(PROLATE, OBLATE)
    base = dict(closed=True, shell=shell, tip=sb.SphereTip(), rho=1.0, beta=1e-3)
    with pytest.raises(ValueError, match=message) as err:
        sb.Scene(**{**base, **kw})
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="needs closed=True"):
        sb.Scene(shell=shell, beta=1e-3)
    with pytest.raises(ValueError, match="closed_halves' lower half must be"):
        sb.UserShell.closed_halves(PROLATE, "sin(S); cos(S); pi/2")


def test_halves_are_written_and_read_back():
    scene = on_substrate(sb.UserShell.closed_halves(PROLATE, OBLATE))
    d = scene.to_dict()
    assert d["shell"]["lower"] == {"R": "sin(S)", "Z": "0.7*cos(S)", "L": "pi/2"}
    back = sb.Scene.from_dict(d)
    assert back == scene and back.shell.lower == sb.UserShell(*OBLATE)
    assert "closed shell (user meridians, halves that differ) on a substrate" in scene.describe()
    assert repr(scene.shell) == f"UserShell.closed_halves(upper={PROLATE!r}, lower={OBLATE!r})"
    assert scene != on_substrate(sb.UserShell(*PROLATE))


@pytest.mark.slow  # two structures of the lower half's own derived (~2 min on a fresh cache)
@pytest.mark.parametrize("delta", [0.02, 0.2])
def test_equal_halves_given_apart_are_the_symmetric_closed_shell(delta):
    # the lower half's meridian at another pace (its own module, L = pi/4): the same shell
    symmetric = sb.solve(on_substrate(sb.UserShell(*SPHEROID)), delta=delta)
    halves = sb.solve(on_substrate(sb.UserShell.closed_halves(SPHEROID, SPHEROID_FAST)), delta=delta)
    assert symmetric.valid and halves.valid and halves.topology == symmetric.topology
    assert halves.force == pytest.approx(symmetric.force, rel=1e-8)
    assert halves.energy == pytest.approx(symmetric.energy, rel=1e-8)


@pytest.mark.slow  # four structures derived and a two-contact curve (~4 min on a fresh cache)
def test_an_egg_on_a_substrate_runs_a_curve_with_F_dE_ddelta():
    scene = on_substrate(sb.UserShell.closed_halves(PROLATE, OBLATE), rho=0.5)
    c = sb.curve(scene, delta_max=0.3)
    assert c.complete and c.delta[-1] == pytest.approx(0.3)
    assert np.all(c.status == 0) and np.all(c.valid) and np.all(np.diff(c.force) > 0)
    h, s = 1e-4, sb.solve(scene, delta=0.2)
    E = [sb.solve(scene, delta=0.2 + sign * h, guess=s).energy for sign in (-1, 1)]
    assert (E[1] - E[0]) / (2 * h) == pytest.approx(s.force, rel=1e-5)
    # its halves between the egg's (prolate above, oblate below): stiffer than the oblate's, softer
    # than the prolate's symmetric closed shell
    sym = [sb.solve(on_substrate(sb.UserShell(*half), rho=0.5), delta=0.2).force for half in (PROLATE, OBLATE)]
    assert min(sym) < s.force < max(sym)


def test_the_command_line_takes_a_lower_meridian_and_refuses_it_without_its_upper_half(tmp_path, cli_main):
    def cli(*args):  # the command's main in this process
        return cli_main("curve", "--closed", *args, "-o", "egg.h5", cwd=tmp_path)

    lower = "; ".join(OBLATE)
    for args, message in ((("--meridian-lower", lower), "--meridian-lower needs --meridian"),
                          (("--support", "plates", "--rho", "0.5", "--meridian", "; ".join(PROLATE), "--meridian-lower",
                            lower), "the shell must be mirror-symmetric about its equator"),
                          (("--meridian", "; ".join(PROLATE), "--meridian-lower", "sin(S); cos(S); 1.5"),
                           "the lower half (in its mirror image)")):
        r = cli(*args)
        assert r.returncode == 2 and message in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "egg.h5").exists()
