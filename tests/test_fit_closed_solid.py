"""The solid as the fitting model of closed shells (issue 55): ``fit(..., model="solid")`` of a
capsule between plates and a cell on a substrate, whose abscissa is the indenters' approach from
first touch (shellbvp.fitting.solid, shellbvp.fe_closed).

Checked on coarse meshes (the fitting model's mesh set to the records'): a record the closed
solid made itself, noise-free, is fitted back to 1e-3 with the contact point, and with 1 %
noise within the fit's interval; the kept curve is read back instead of a second FE run, a
tampered one is set aside; the kept curve's key holds the support, gamma and the interior; the
summary says what the solid and its abscissa are.  benchmarks/thick_fits.py --set closed fits
thick closed shells on the default mesh with both models."""

import json

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main

pytest.importorskip("felupe", reason="the 3D reference needs FElupe ('.[fe]')")

from shellbvp import fe  # noqa: E402
from shellbvp.fitting import solid  # noqa: E402

COARSE = dict(element_length=1.0, through_thickness=2)
R_L, MU_H, CONTACT = 30e-6, 0.5, 2e-6
MR = sb.MooneyRivlin(0.1)
SCENES = {"plates": sb.Scene(closed=True, gamma=1.0, support="plates", tip=sb.FlatTip(), thickness=0.1, material=MR),
          "substrate": sb.Scene(closed=True, gamma=1.0, support="substrate", tip=sb.SphereTip(), rho=0.5,
                                thickness=0.15, material=MR)}
DEPTHS = np.linspace(0.025, 0.2, 8)


@pytest.fixture(autouse=True)
def coarse_solid(monkeypatch, tmp_path):
    """The fitting model's solid on the records' coarse mesh, its kept curves in ``tmp_path``
    (the generated code in the run's cache)."""
    monkeypatch.setattr(solid, "FE_DEFAULTS", {**fe.FE_DEFAULTS, **COARSE})
    monkeypatch.setattr(solid, "kept_folder", lambda name, what: tmp_path / name)
    solid.clear_solid_curves()
    with sb.options(model_curve_cache=True):
        yield tmp_path
    solid.clear_solid_curves()


_RECORDS = {}


def record(where):
    """The closed solid's own record of ``SCENES[where]``: the indenters' approach (m) from a
    contact point at CONTACT, the force (N) at mu*H = MU_H, noise-free (computed once)."""
    if where not in _RECORDS:
        scene = SCENES[where]
        c = sb.fe_curve(scene, scene.thickness, DEPTHS, at="indenter", **COARSE)
        assert c.success, c.message
        assert np.allclose(c.indenter, DEPTHS)  # the approach reached, as asked
        _RECORDS[where] = (CONTACT + DEPTHS * R_L, MU_H * R_L * c.force)
    return _RECORDS[where]


@pytest.mark.parametrize("where", ["plates", "substrate"])
def test_a_closed_solids_own_record_is_fitted_back_and_its_kept_curve_reused(where, monkeypatch):
    scene = SCENES[where]
    d, F = record(where)
    res = sb.fit(scene, d, F, R_L=R_L, model="solid")
    assert res.success and res.model == "solid" and res.curves_computed == 1
    assert res.mu_H == pytest.approx(MU_H, rel=1e-3)           # measured: -4e-4 (plates), -5e-4 (substrate)
    assert res.offset == pytest.approx(CONTACT, abs=1e-3 * DEPTHS[-1] * R_L)
    assert res.curve.scene == scene and np.all(res.curve.delta > 0)
    # a second fit in another process: the kept curve read back, no FE run
    solid.clear_solid_curves()
    monkeypatch.setattr(solid, "fe_curve", lambda *a, **k: pytest.fail("the kept curve was not used"))
    again = sb.fit(scene, d, F, R_L=R_L, model="solid")
    assert again.curves_computed == 0 and again.curve.kept and again.mu_H == res.mu_H
    # 1 % noise: the truth within the interval (the kept curve again)
    noisy = F * (1 + 0.01 * np.random.default_rng(5).normal(size=F.size))
    res = sb.fit(scene, d, noisy, R_L=R_L, model="solid")
    lo, hi = res.mu_H_ci95
    assert lo < MU_H < hi and res.mu_H == pytest.approx(MU_H, rel=0.02)
    assert res.offset_ci95[0] < CONTACT < res.offset_ci95[1]


def test_a_tampered_kept_closed_curve_is_set_aside_and_the_key_holds_the_interior(coarse_solid, caplog):
    scene, grid = SCENES["plates"], np.array([0.02, 0.05, 0.08])
    counter = [0]
    first = solid.solid_curve(scene, grid, counter=counter)
    (kept,) = (coarse_solid / "solid_curves").glob("solid_*.json")
    solid.clear_solid_curves()
    assert solid.solid_curve(scene, grid, counter=counter).kept and counter == [1]
    doc = json.loads(kept.read_text())
    kept.write_text(json.dumps({**doc, "force": [1.01 * x for x in doc["force"]]}))  # edited, checksum kept
    solid.clear_solid_curves()
    again = solid.solid_curve(scene, grid, counter=counter)
    assert "its checksum does not match its contents" in caplog.text
    assert not again.kept and counter == [2] and np.array_equal(again.force, first.force)
    assert kept.with_name(kept.name + ".bad").exists()
    # what the closed solid depends on is in its key: support, gamma, interior, open or closed
    settings = solid.FE_DEFAULTS
    variants = [scene, scene.replace(support="substrate"), scene.replace(gamma=1.2), scene.replace(sealed=True),
                scene.replace(pressure=0.1), scene.replace(support="substrate", tip=sb.SphereTip(), rho=0.5),
                sb.Scene(gamma=1.0, rho=0.5, thickness=0.1, material=MR)]  # rimmed
    keys = {solid._place(s, grid, settings)[1] for s in variants}
    assert len(keys) == len(variants)


def test_auto_fits_thick_closed_shells_with_both_models_and_names_their_abscissas():
    plates, substrate = SCENES["plates"], SCENES["substrate"]
    assert solid.auto_model(plates) == ("both", "") and solid.auto_model(substrate) == ("both", "")
    choice, note = solid.auto_model(plates.replace(thickness=0.02))
    assert choice == "shell" and "mid-surface poles' approach" in note and "eps = 0.02 < 0.05" in note
    assert solid.solid_words(plates) == ("the half above the equator on its symmetry plane",
                                         "the indenters' approach from first touch")
    assert "substrate" in " ".join(solid.solid_words(substrate))
    solid.check_solid_fit(plates.replace(sealed=True))  # sealed and pressurised closed shells: no refusal
    solid.check_solid_fit(substrate.replace(pressure=0.15))


def test_cli_fits_a_capsule_between_plates_with_the_solid(tmp_path, capsys):
    d, F = record("plates")
    data = tmp_path / "capsule.tsv"
    data.write_text("Displacement (um)\tForce (uN)\n" + "".join(f"{a * 1e6:.9f}\t{b * 1e6:.9f}\n"
                                                                 for a, b in zip(d, F)))
    out = tmp_path / "fit.h5"
    assert main(["fit", str(data), "--closed", "--support", "plates", "--flat-tip", "--gamma", "1", "--radius", "30um",
                 "--thickness", "3um", "--alpha", "0.1", "--model", "solid", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "the half above the equator on its symmetry plane; the indenters' approach from first touch" in text
    assert "rim face" not in text
    rec = sb.read_fit(out)
    assert rec.settings["model"] == "solid" and rec.parameters["mu_H"] == pytest.approx(MU_H, rel=2e-3)
    from shellbvp.plotting import fit_summary_lines

    summary = "\n".join(fit_summary_lines(rec))
    assert "model: the 3D solid (its indenters' approach from first touch as the data's)" in summary


@pytest.mark.slow  # two solids on the default and a finer mesh, ~1 min
def test_a_sealed_capsule_is_fitted_by_the_solid_from_a_finer_solids_record(monkeypatch):
    # the fitting model on its default mesh, the record on one 1.5x finer each way (as
    # benchmarks/thick_fits.py): a sealed capsule between plates, eps 0.1, 1 % noise
    monkeypatch.setattr(solid, "FE_DEFAULTS", fe.FE_DEFAULTS)
    scene = SCENES["plates"].replace(sealed=True)
    c = sb.fe_curve(scene, 0.1, DEPTHS, at="indenter", element_length=0.33, through_thickness=4)
    assert c.success and np.all(c.pressure > 0)  # the held volume's pressure rises
    F = MU_H * R_L * c.force * (1 + 0.01 * np.random.default_rng(7).normal(size=DEPTHS.size))
    res = sb.fit(scene, CONTACT + DEPTHS * R_L, F, R_L=R_L, model="solid")
    lo, hi = res.mu_H_ci95
    assert res.success and lo < MU_H < hi and res.mu_H == pytest.approx(MU_H, rel=0.01)


@pytest.mark.slow  # the egg's solid twice, ~40 s
def test_an_eggs_solid_record_is_fitted_back_with_its_solid():
    # an egg between plates (its solid the whole wall, each half its own meridian): its own
    # record fitted back by the solid as the symmetric capsule's is, its kept curve keyed apart
    # from the symmetric shell of its upper half
    upper = ("sin(S)", "1.3*cos(S)", "pi/2")
    egg = sb.UserShell.closed_halves(upper, ("sin(S)", "0.7*cos(S)", "pi/2"))
    scene = sb.Scene(closed=True, shell=egg, support="plates", tip=sb.FlatTip(), thickness=0.1, material=MR)
    assert solid.auto_model(scene) == ("both", "")
    c = sb.fe_curve(scene, scene.thickness, DEPTHS, at="indenter", **COARSE)
    assert c.success and np.allclose(c.indenter, DEPTHS)
    res = sb.fit(scene, CONTACT + DEPTHS * R_L, MU_H * R_L * c.force, R_L=R_L, model="solid")
    assert res.success and res.model == "solid"
    assert res.mu_H == pytest.approx(MU_H, rel=1e-3)
    assert res.offset == pytest.approx(CONTACT, abs=1e-3 * DEPTHS[-1] * R_L)
    grid = np.array([0.02, 0.05])
    assert solid._place(scene, grid, solid.FE_DEFAULTS)[1] != \
        solid._place(scene.replace(shell=sb.UserShell(*upper)), grid, solid.FE_DEFAULTS)[1]
