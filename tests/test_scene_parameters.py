"""The registry of scene parameters (shellbvp.scene_parameters, issue 57 item 3): every parameter
declared once, and the sweep's grid, the geometry's uncertainty, the pixel tables, the fit and
the command line read it; a material's flagged parameter reaches all of them (a toy material
here, registered for one test)."""

import argparse
import math
import re
from dataclasses import dataclass

import pytest

import shellbvp as sb
from shellbvp.cli import build_parser
from shellbvp.materials import MATERIALS, Material, Parameter
from shellbvp.scene_parameters import (
    ROLES, SCENE_PARAMETERS, parameters_that, scene_parameter, scene_parameters, scene_with,
)


def _parser(command):
    return build_parser()._subparsers._group_actions[0].choices[command]


def _options(command):
    return {o: a for a in _parser(command)._actions for o in a.option_strings}


def _scene_of(p):
    """A scene that has the parameter ``p`` (its material's, at its default)."""
    from shellbvp.materials import material_class

    scene = sb.Scene.preset("fit", thickness=0.05)
    return scene.replace(material=material_class(p.material)()) if p.material else scene


def test_the_tables_read_from_the_registry_hold_what_they_held():
    """The parameters each user takes, as before the registry (issue 57): the order of the
    sweep's axes and of the fit's table columns is the registry's."""
    from shellbvp.pixel_table import PIXEL_PARAMETERS
    from shellbvp.shape_parameters import SHAPE_PARAMETERS
    from shellbvp.sweeps import SWEEP_PARAMETERS
    from shellbvp.uncertainty import UNCERTAIN_PARAMETERS

    assert SWEEP_PARAMETERS == ("beta", "rho", "gamma", "alpha", "Jm", "pressure")
    assert repr(SWEEP_PARAMETERS) == repr(("beta", "rho", "gamma", "alpha", "Jm", "pressure"))
    assert list(SHAPE_PARAMETERS) == ["beta", "alpha", "pressure", "thickness"]
    assert set(UNCERTAIN_PARAMETERS) == {"gamma", "rho", "beta", "alpha"}
    assert dict(PIXEL_PARAMETERS) == {"beta": "", "alpha": "", "thickness": "length"}
    assert list(SCENE_PARAMETERS) == ["beta", "rho", "gamma", "alpha", "Jm", "c2", "c3", "pressure", "thickness"]


@pytest.mark.parametrize("name", list(SCENE_PARAMETERS))
def test_every_parameter_enters_the_scene_and_keeps_its_range(name):
    p = scene_parameter(name)
    scene = _scene_of(p)
    x = p.get(scene)
    assert x is not None and p.contains(x)
    # a value inside the range, set and read back through the one way into a scene
    inside = 0.9 * x if x else 0.1
    assert p.get(scene_with(scene, {name: inside})) == pytest.approx(inside)
    # outside: one line naming the parameter and its range, as the scene raises it
    outside = p.low if p.low_open else (p.low - 1 if math.isfinite(p.low) else None)
    if outside is not None:
        with pytest.raises(ValueError, match=rf"^{name} \(.*\) must be {re.escape(p.range_text())}; got") as info:
            scene_with(scene, {name: outside})
        assert "\n" not in str(info.value)
        with pytest.raises(ValueError) as direct:
            p.check(outside)
        assert str(direct.value) == str(info.value)


def test_the_scene_raises_the_registry_errors():
    for kw, name, value in ((dict(rho=0), "rho", 0), (dict(beta=-1), "beta", -1), (dict(thickness=0.7), "thickness", 0.7)):
        with pytest.raises(ValueError) as scene_error:
            sb.Scene(**kw)
        with pytest.raises(ValueError) as registry_error:
            scene_parameter(name).check(value)
        assert str(scene_error.value) == str(registry_error.value)
    assert str(pytest.raises(ValueError, sb.Scene, thickness=0.7).value) == \
        "thickness (H / R_L) must be in (0, 0.5]; got 0.7"


def test_every_parameter_reaches_the_command_line_the_sweep_the_uncertainty_and_the_pixel_tables(tmp_path):
    from shellbvp.batch import TABLE_COLUMNS
    from shellbvp.cli.scene_options import scene_from_args
    from shellbvp.fitrecord import PARAMETER_UNITS
    from shellbvp.pixel_table import PIXEL_PARAMETERS, read_pixel_table
    from shellbvp.sweeps.grid import check_grid
    from shellbvp.uncertainty import UNCERTAIN_PARAMETERS, _check_uncertainty

    fit, sweep, solve = _options("fit"), _options("sweep"), _options("solve")
    for p in scene_parameters().values():
        scene, x = _scene_of(p), p.get(_scene_of(p))
        if p.option:  # its scene option, which every solving command offers
            assert p.option in fit and p.option in solve and fit[p.option].dest == p.dest
        if p.material and p.option:
            args = _parser("solve").parse_args(["--preset", "fit", p.option, repr(x)])
            assert scene_from_args(args).material.family == p.material
        if p.sweep:
            assert p.option in sweep and sweep[p.option].dest == p.dest
            values = (x, 0.9 * x if x else 0.1)
            assert check_grid(scene, {p.name: list(values)}) == {p.name: values}
        if p.uncertainty:
            assert p.name in UNCERTAIN_PARAMETERS
            assert fit[p.option].type(f"{x}+-0.01") == (x, 0.01)  # VALUE+-U on the command line
            perturbed = _check_uncertainty(scene, {p.name: 0.01 * abs(x)}, {})
            assert p.get(perturbed[p.name, 1]) == pytest.approx(1.01 * x)
        if p.fit is not None:
            assert {f"--fit-{p.name}", f"--{p.name}-range"} <= set(fit)
            assert p.name in PARAMETER_UNITS and any(c.split(" (")[0] == p.name for c in TABLE_COLUMNS)
        if p.per_pixel:
            kind = PIXEL_PARAMETERS[p.name]
            assert kind == (p.lab.kind if p.lab is not None else "")
            path = tmp_path / f"{p.name}.csv"
            path.write_text(f"ix,iy,{p.name}_um\n0,0,{x * 0.3e3}\n" if kind == "length" else
                            f"ix,iy,{p.name}\n0,0,{x}\n")
            table = read_pixel_table(path)
            assert table.nondimensional(R_L=0.3e-3)[0, 0] == pytest.approx(x)
            assert p.name in _parser("fit")._option_string_actions["--pixel-table"].help
        else:
            assert p.name not in PIXEL_PARAMETERS
    assert set(ROLES) == {"fit", "sweep", "uncertainty", "per_pixel"}


def test_the_thickness_unit_is_explicit_where_it_converts():
    """``thickness`` is H/R_L in a Scene and H in m (its lab form) in FitResult and the pixel
    tables' thickness_um: one declaration says so, and the conversions go through it."""
    from shellbvp.fitting.result import FitResult
    from shellbvp.pixel_table import PixelTable
    from shellbvp.units import Dimensions

    t = scene_parameter("thickness")
    assert (t.unit, t.symbol, t.lab.unit, t.lab.kind) == ("1", "H/R_L", "m", "length")
    assert t.sets == ("thickness", "beta") and "eps" in t.aliases
    res = FitResult(mu_H=1.0, mu_H_ci95=(0.9, 1.1), offset=0.0, offset_ci95=(0, 0), residual_rms=0.0, n=3,
                    status=0, message="", R_L=0.3e-3, scene=sb.Scene.preset("fit", thickness=0.05))
    assert res.thickness == pytest.approx(15e-6) == t.to_lab(0.05, 0.3e-3)
    assert res.to_dict()["units"]["thickness"] == "m"
    assert PixelTable("thickness", {(0, 0): 15.0}, unit="um").nondimensional(R_L=0.3e-3)[0, 0] == pytest.approx(0.05)
    # the pressure's lab form needs mu*H too; the conversion is units.Dimensions'
    p = scene_parameter("pressure")
    assert p.from_lab(2e5, 0.3e-3, 52.0) == Dimensions(R_L=0.3e-3, mu_H=52.0).p(2e5)
    with pytest.raises(ValueError, match="needs mu\\*H"):
        p.from_lab(2e5, 0.3e-3)


@dataclass(frozen=True)
class _Toy(Material):
    """A material only this test registers: one parameter with every flag."""

    kappa: float = 1.0
    family = "toy"
    label, short_label = "Toy", "Toy"
    parameters = (Parameter("kappa", 0.0, 2.0, fit=True, sweep=True, uncertainty=True, per_pixel=True),)


def test_a_material_parameter_with_its_flags_reaches_every_user(monkeypatch, tmp_path):
    """A material's module is all a new material takes: its flagged parameter is swept, given an
    uncertainty, taken per pixel and fitted, and the command line offers it (no curve computed)."""
    from shellbvp.batch import TABLE_COLUMNS
    from shellbvp.cli.scene_options import scene_from_args
    from shellbvp.fitrecord import PARAMETER_UNITS
    from shellbvp.pixel_table import PIXEL_PARAMETERS, read_pixel_table
    from shellbvp.shape_parameters import SHAPE_PARAMETERS, shape_parameter
    from shellbvp.sweeps import SWEEP_PARAMETERS
    from shellbvp.sweeps.grid import check_grid
    from shellbvp.uncertainty import UNCERTAIN_PARAMETERS, _check_uncertainty

    assert "kappa" not in SCENE_PARAMETERS
    monkeypatch.setitem(MATERIALS, "toy", _Toy)
    kappa = scene_parameter("kappa")
    assert (kappa.material, kappa.option, kappa.range_text()) == ("toy", "--kappa", "in [0, 2]")
    assert "kappa" in SWEEP_PARAMETERS and "kappa" in UNCERTAIN_PARAMETERS and PIXEL_PARAMETERS["kappa"] == ""
    toy, mr = sb.Scene.preset("fit", material=_Toy(0.5)), sb.Scene.preset("fit")
    # the sweep
    assert check_grid(toy, {"kappa": [0.5, 1.5], "rho": [0.3]}) == {"kappa": (0.5, 1.5), "rho": (0.3,)}
    with pytest.raises(ValueError, match=r"grid: kappa needs a Toy base scene; its material is MooneyRivlin"):
        check_grid(mr, {"kappa": [0.5]})
    with pytest.raises(ValueError, match=r"kappa \(Toy\) must be in \[0, 2\]; got 3"):
        scene_with(toy, {"kappa": 3.0})
    # the uncertainty
    scenes = _check_uncertainty(toy, {"kappa": 0.1}, {})
    assert [scenes["kappa", s].material.kappa for s in (-1, 1)] == pytest.approx([0.4, 0.6])
    with pytest.raises(ValueError, match="uncertainty: kappa is fitted"):
        _check_uncertainty(toy, {"kappa": 0.1}, {"fit_kappa": True})
    # the fit
    param = shape_parameter("kappa")
    assert param.default_bounds(toy) == (0.0, 2.0) and param.step(toy) == pytest.approx(0.4)
    assert param.set(toy, 2.5).material == _Toy(2.0)  # a trial value held in the range
    assert param.unavailable(mr) == "fit_kappa needs a Toy material (kappa); the scene's material is mooney-rivlin"
    assert "kappa" in SHAPE_PARAMETERS and PARAMETER_UNITS["kappa"] == "1" and "kappa" in TABLE_COLUMNS
    # the pixel table
    (tmp_path / "t.csv").write_text("ix,iy,kappa\n0,0,0.7\n1,0,1.1\n")
    assert read_pixel_table(tmp_path / "t.csv").values == {(0, 0): 0.7, (1, 0): 1.1}
    (tmp_path / "u.csv").write_text("ix,iy,kappa (um)\n0,0,0.7\n")
    with pytest.raises(ValueError, match="kappa is nondimensional"):
        read_pixel_table(tmp_path / "u.csv")
    # the command line: its option (VALUE+-U in fit), --fit-kappa, --kappa-range, the sweep's --kappa
    fit = _options("fit")
    assert fit["--kappa"].type("0.5+-0.1") == (0.5, 0.1) and {"--fit-kappa", "--kappa-range"} <= set(fit)
    assert "--kappa" in _options("sweep")
    args = _parser("solve").parse_args(["--preset", "fit", "--kappa", "0.25"])
    assert scene_from_args(args).material == _Toy(0.25)
    with pytest.raises(SystemExit):  # a material option excludes the others
        _parser("solve").parse_args(["--preset", "fit", "--kappa", "0.25", "--alpha", "0.1"])
    monkeypatch.delitem(MATERIALS, "toy")
    assert "kappa" not in SCENE_PARAMETERS and "kappa" not in SWEEP_PARAMETERS


def test_one_name_per_quantity(monkeypatch):
    @dataclass(frozen=True)
    class Clash(Material):
        beta: float = 1.0
        family = "clash"
        label = short_label = "Clash"
        parameters = (Parameter("beta", 0.0),)

    monkeypatch.setitem(MATERIALS, "clash", Clash)
    with pytest.raises(ValueError, match="scene parameter 'beta' is declared twice"):
        scene_parameters()


def test_a_flag_without_what_it_needs_is_refused(monkeypatch):
    @dataclass(frozen=True)
    class Unbounded(Material):
        k: float = 1.0
        family = "unbounded"
        label = short_label = "Unbounded"
        parameters = (Parameter("k", 0.0, fit=True),)

    monkeypatch.setitem(MATERIALS, "unbounded", Unbounded)
    with pytest.raises(ValueError, match="needs a finite range"):
        scene_parameters()


def test_roles_and_names_are_checked():
    with pytest.raises(ValueError, match="unknown role 'swept'"):
        parameters_that("swept")
    with pytest.raises(ValueError, match="unknown scene parameter 'mu'; known: beta, rho"):
        scene_parameter("mu")
    assert isinstance(build_parser(), argparse.ArgumentParser)


def test_the_registrys_examples_run():
    import doctest

    import shellbvp.scene_parameters

    result = doctest.testmod(shellbvp.scene_parameters, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
