"""The Yeoh material (shellbvp/materials/yeoh.py): its energy, its checks, files, labels, the
command line, the 3D reference's model, and curves against the neo-Hookean's (c2 = c3 = 0)."""

import doctest
import json

import numpy as np
import pytest
import sympy as sp

import shellbvp as sb
from shellbvp.cli import main
from shellbvp.materials import MATERIALS
from shellbvp.plotting import scene_label
from symbolic import materials as sm

C2, C3 = sp.symbols("c2 c3", nonnegative=True)


def test_the_energy_vanishes_is_stress_free_and_has_shear_modulus_one_for_every_c2_c3():
    W = sb.Yeoh.energy(C2, C3)
    at_rest = {sm.LS: 1, sm.LT: 1}
    assert sp.simplify(W.subs(at_rest)) == 0
    assert sp.simplify(sp.diff(W, sm.LS).subs(at_rest)) == 0
    assert sm.small_strain_shear_modulus(W) == 1  # independent of c2 and c3: mu = 2 C10
    assert sm.check_energy(W.subs({C2: sp.Rational(3, 10), C3: sp.Rational(1, 20)})) == 1
    assert sp.simplify(sb.Yeoh.energy(0, 0) - sm.neo_hookean()) == 0


def test_the_docstring_examples_run():
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for test in doctest.DocTestFinder().find(sb.Yeoh, "Yeoh", globs={}):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.attempted >= 3 and result.failed == 0


def test_the_derivation_gets_the_registered_energy_with_its_parameters_in_order():
    W, params = MATERIALS["yeoh"].strain_energy({"family": "yeoh"})
    assert [p.name for p in params] == ["c2", "c3"] == list(sb.Yeoh().values())
    assert sp.simplify(W - sb.Yeoh.energy(*params)) == 0


@pytest.mark.parametrize("kwargs, message", [
    ({"c2": -0.1}, "c2 (Yeoh) must be a finite number >= 0; got -0.1"),
    ({"c3": float("nan")}, "c3 (Yeoh) must be a finite number >= 0; got nan"),
    ({"c2": True}, "c2 (Yeoh) must be a finite number >= 0; got True"),
    ({"c3": "0.1"}, "c3 (Yeoh) must be a finite number >= 0; got '0.1'"),
])
def test_parameters_out_of_range_are_refused_naming_them(kwargs, message):
    with pytest.raises(ValueError) as err:
        sb.Scene.preset("base", material=sb.Yeoh(**kwargs))
    assert str(err.value) == message


def test_files_labels_and_words():
    scene = sb.Scene.preset("base", material=sb.Yeoh(c2=0.1, c3=0.01))
    data = scene.to_dict()
    assert data["material"] == {"family": "yeoh", "c2": 0.1, "c3": 0.01}
    assert sb.Scene.from_dict(json.loads(json.dumps(data))) == scene
    with pytest.raises(ValueError, match="scene data material has no 'c3'"):
        sb.Scene.from_dict({**data, "material": {"family": "yeoh", "c2": 0.1}})
    assert scene.structure()["material"] == {"family": "yeoh"}  # c2, c3 are run-time values
    assert "Yeoh c2 0.1 c3 0.01" in scene.describe()
    assert "Yeoh c2=0.1 c3=0.01" in scene_label(scene)


def test_the_command_line_chooses_it_by_name(capsys):
    from shellbvp.cli import build_parser, scene_from_args

    parser = build_parser()
    args = parser.parse_args(["curve", "--material", "yeoh:c2=0.1,c3=0.01"])
    assert scene_from_args(args).material == sb.Yeoh(0.1, 0.01)
    assert scene_from_args(parser.parse_args(["curve", "--material", "yeoh:c3=0.2"])).material == sb.Yeoh(0.0, 0.2)
    for bad, says in (("yeoh:c2=-1", "c2 (Yeoh) must be a finite number >= 0"), ("yeoh:c4=1", "NAME one of c2, c3"),
                      ("yeoh:c2=1,c2=2", "once each"), ("yeoh:c2=exp(1)", "c2 must be a plain finite number")):
        with pytest.raises(SystemExit):
            parser.parse_args(["curve", "--material", bad])
        assert says in capsys.readouterr().err
    with pytest.raises(SystemExit):
        parser.parse_args(["curve", "--help"])
    assert "yeoh, c2 a finite number >= 0, c3 a finite number >= 0" in " ".join(capsys.readouterr().out.split())


def test_the_3d_reference_has_the_same_energy():
    """FElupe's Yeoh (C10 = 1/2, C20 = c2/2, C30 = c3/2) in uniaxial isochoric stretch:
    P11 = 2 W'(I1) (lambda - I1/(3 lambda)), W' from the shell model's formula."""
    pytest.importorskip("felupe")
    import felupe

    lam = 1.4
    F = np.diag([lam, lam**-0.5, lam**-0.5]).reshape(3, 3, 1, 1)
    I1 = lam**2 + 2 / lam
    for c2, c3 in ((0.0, 0.0), (0.3, 0.05)):
        umat = sb.Yeoh(c2, c3).felupe_model(felupe)
        dW = (1 + 2 * c2 * (I1 - 3) + 3 * c3 * (I1 - 3) ** 2) / 2
        assert umat.gradient([F])[0][0, 0].item() == pytest.approx(2 * dW * (lam - I1 / (3 * lam)), rel=1e-12)
    neo = felupe.NeoHooke(mu=1.0).gradient([F])[0]
    assert np.allclose(sb.Yeoh().felupe_model(felupe).gradient([F])[0], neo, rtol=1e-12, atol=1e-14)


DELTAS = [0.05, 0.1]


@pytest.fixture(scope="module")
def neo_hookean_curve():
    return sb.curve(sb.Scene.preset("base", material=sb.NeoHookean()), deltas=DELTAS, estimate_error=False)


# The Yeoh structure's code is derived once for this file (4.7 s here; the curves ~5 s more).
def test_with_c2_c3_zero_the_curve_is_the_neo_hookean_one_and_c2_stiffens(neo_hookean_curve, tmp_path):
    """Same physics, other generated code: F equal to 1e-10; c2 > 0 stiffens (larger F); the
    curve's file gives its scene back."""
    yeoh0 = sb.curve(sb.Scene.preset("base", material=sb.Yeoh()), deltas=DELTAS, estimate_error=False)
    assert np.array_equal(yeoh0.delta, neo_hookean_curve.delta)
    assert np.allclose(yeoh0.force, neo_hookean_curve.force, rtol=1e-10, atol=0)
    stiff = sb.curve(sb.Scene.preset("base", material=sb.Yeoh(c2=0.5)), deltas=DELTAS, estimate_error=False)
    assert np.all(stiff.force > neo_hookean_curve.force * (1 + 1e-4))
    stiff.to_hdf5(tmp_path / "yeoh.h5")
    assert sb.read_curve(tmp_path / "yeoh.h5").scene == stiff.scene


def test_the_command_line_solves_a_yeoh_scene(capsys):
    assert main(["solve", "--material", "yeoh:c2=0.5", "--delta", "0.1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    expected = sb.solve(sb.Scene.preset("base", material=sb.Yeoh(c2=0.5)), delta=0.1)
    assert out["success"] and out["force"] == pytest.approx(expected.force, rel=1e-9)


@pytest.mark.slow  # three 3D solves: 2.4 s after FElupe has warmed up, 13 s in a fresh process
def test_the_3d_reference_solves_a_yeoh_shell():
    """fe_curve takes the material from its module: c2 = c3 = 0 gives the neo-Hookean force
    (FElupe's own NeoHooke, another code path) to 1e-9; c2 > 0 a larger one."""
    pytest.importorskip("felupe")
    settings = dict(thickness=0.1, deltas=[0.05], through_thickness=2, element_length=1.0)
    neo = sb.fe_curve(sb.Scene.preset("base", material=sb.NeoHookean()), **settings).force
    assert np.allclose(sb.fe_curve(sb.Scene.preset("base", material=sb.Yeoh()), **settings).force, neo,
                       rtol=1e-9, atol=0)
    assert np.all(sb.fe_curve(sb.Scene.preset("base", material=sb.Yeoh(c2=0.5)), **settings).force > neo * 1.001)
