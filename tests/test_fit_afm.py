"""Fits that cannot be silently wrong on AFM data (issue 56, items 1, 2 and 8): the mixed noise
model read from the residuals' local scatter (a misfit is not taken for noise), a fit that misses
the contact region rated poor, a force map's summary that counts its curves' ratings and
warnings, shallow curves that start in the point-load limit, and a fitting range (max_depth)."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.afm import ForceMap
from shellbvp.cli import main
from shellbvp.fit_checks import CONTACT_MISFIT, RUNS_P, check_result, contact_misfit, fit_quality
from shellbvp.fitrecord import read_fit
from shellbvp.fitting import example_data_path, fit_record
from shellbvp.fitting.least_squares import local_scatter

DATA = Path(__file__).parent / "data" / "afm"
#: the sample of the README's AFM example: a 10 um rim, 2.5 um tip, 5 um rise, 0.5 um wall
AFM_SCENE = dict(gamma=0.5, rho=0.25, thickness=0.05)


def test_local_scatter_reads_the_noise_not_a_smooth_misfit():
    """A smooth misfit ten times the noise cancels in the second differences: their mean is the
    noise variance; the squared residuals would be ~100 x it."""
    rng = np.random.default_rng(3)
    d = np.sort(rng.uniform(0, 1, 4000))
    sigma = 0.01
    resid = 0.1 * np.sin(3 * d) + rng.normal(0, sigma, d.size)
    shuffled = rng.permutation(d.size)  # rows in any order: the differences are taken in depth order
    s2 = local_scatter(resid[shuffled], d[shuffled])
    assert np.mean(s2) == pytest.approx(sigma ** 2, rel=0.1)
    assert np.mean(resid ** 2) > 30 * sigma ** 2


def test_contact_misfit_flags_a_missed_contact_region_not_noise():
    rng = np.random.default_rng(4)
    d = np.linspace(0, 1, 200)
    model = np.clip(d - 0.5, 0, None) ** 1.5
    noise = rng.normal(0, 1e-3, d.size)
    assert contact_misfit(noise, d, model)[1] > RUNS_P        # a fit that follows the data
    # a least-squares misfit: the model's force too low, then too high (10 % of the force there)
    missed = np.where(model > 0, 0.1 * model.max() * np.sin(4 * np.pi * (d - 0.5)), 0.0) + noise
    runs, p, n, largest = contact_misfit(missed, d, model)
    assert n == np.count_nonzero(model > 0) and p < RUNS_P and largest > CONTACT_MISFIT
    status, warnings = check_result(True, 1.0, (0.9, 1.1), (0.0, 0.0), True, d.size, None,
                                    (runs, p, n, largest))
    codes = [c for c, _ in warnings]
    assert status == 0 and codes == ["contact_misfit"] and "--max-depth" in warnings[0][1]
    assert fit_quality(True, codes, 1.0, (0.99, 1.01)) == "poor"
    assert fit_quality(True, [], 1.0, (0.99, 1.01)) == "good"


def test_map_summary_counts_ratings_and_warnings():
    def row(quality_codes, grid):
        codes = list(quality_codes)
        result = SimpleNamespace(mu_H=0.05, quality="poor" if "contact_misfit" in codes else "good",
                                 warning_codes=codes, warnings=[f"text of {c}" for c in codes])
        return SimpleNamespace(status="ok", result=result), SimpleNamespace(grid=grid, index=grid[0])

    rows, curves = zip(row(["residual_runs", "contact_misfit"], (0, 0)), row([], (1, 0)),
                       row(["residual_runs"], (0, 1)))
    fm = ForceMap(path="m.jpk-force-map", curves=list(curves), rows=list(rows), shape=(2, 2), scene=None,
                  R_L=1e-5, segment="loading", settings={})
    text = fm.summary()
    assert "quality good 2, fair 0, poor 1" in text
    assert "warnings: residual_runs in 2, contact_misfit in 1" in text
    assert fm.warning_counts()["residual_runs"] == ([(0, 0), (0, 1)], "text of residual_runs")


@pytest.fixture(scope="module")
def flipsign():
    from shellbvp.afm import read_afm

    pytest.importorskip("afmformats")
    (curve,) = read_afm(DATA / "flipsign_2015.05.22-15.31.49.352.jpk-force")
    return curve.record


def test_a_long_approach_does_not_swamp_the_contact_region(flipsign):
    """~9,400 approach rows, ~100 in contact: the default (mixed) weights found a contact point
    2 um early and mu*H 1.7e-4 N/m, missing the contact region by up to 3.7 nN (424 x below the
    uniform weights' 7.4e-2 N/m).  Now the two weightings agree within 10 %; the model still
    misses part of the contact region (a systematic residual), and says so."""
    scene = sb.Scene.preset("base", **AFM_SCENE)
    fits = {w: fit_record(scene, flipsign, R_L=10e-6, weights=w, model="shell")[0] for w in ("mixed", "uniform")}
    mixed, uniform = fits["mixed"], fits["uniform"]
    assert mixed.success and uniform.success
    assert mixed.mu_H == pytest.approx(uniform.mu_H, rel=0.1)
    assert mixed.offset == pytest.approx(uniform.offset, abs=0.05e-6)
    for res in fits.values():
        if "contact_misfit" in res.warning_codes:
            assert res.quality == "poor"


def test_a_shallow_afm_curve_fits_from_the_point_load_limit():
    """161 nm deep on a 10 um rim (delta ~ 0.016): the model curve's first depths are in the
    point-load limit, where it cannot start; it starts deeper and the point-load solution gives
    the shallower forces.  It was refused as 'check the displacement units'."""
    from shellbvp.afm import read_afm

    pytest.importorskip("afmformats")
    (curve,) = read_afm(DATA / "spot3-0192.jpk-force")
    # its weightings disagree (the next test): the shallow fit itself is what is tested here
    res, used = fit_record(sb.Scene.preset("base", **AFM_SCENE), curve.record, R_L=10e-6, model="shell",
                           weights_check=False)
    assert res.success and 0.05 < res.mu_H < 0.5
    depth = curve.record.displacement[used].max() - res.offset
    assert 100e-9 < depth < 250e-9


def test_max_depth_leaves_out_the_deeper_rows():
    d, F = sb.read_force_csv(example_data_path())   # contact at ~0.01 mm, 40 rows
    scene = sb.Scene.preset("fit")
    cut = 0.6 * (d.max() - 1e-5)
    res = sb.fit(scene, d, F, R_L=0.3e-3, max_depth=cut, contact_guess=1e-5)
    assert res.n == np.count_nonzero(d - 1e-5 <= cut) < d.size and res.max_depth == cut
    lo, hi = res.mu_H_ci95
    assert lo < 52 < hi   # the synthetic record's truth, from its shallower rows
    assert np.isnan(res.point_weights[d - 1e-5 > cut]).all()
    with pytest.raises(ValueError, match="max_depth"):
        sb.fit(scene, d, F, R_L=0.3e-3, max_depth=-1e-6)
    with pytest.raises(ValueError, match="--max-depth"):
        sb.fit(scene, d, F, R_L=0.3e-3, max_depth=1e-9, contact_guess=1e-5)


def test_cli_max_depth_in_lab_units_or_a_fraction_of_R_L(tmp_path, capsys):
    out = tmp_path / "fit.h5"
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--max-depth", "0.1", "-q",
                 "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "range  = depths up to 0.03 mm" in text and "--max-depth" in text
    rec = read_fit(out)
    assert rec.parameters["max_depth"] == pytest.approx(0.03e-3)
    assert rec.parameters["n_points"] < 40
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--max-depth", "30um", "-q",
                 "--json"]) == 0
    doc = capsys.readouterr().out
    import json

    assert json.loads(doc)["max_depth"] == pytest.approx(30e-6)
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--max-depth", "0", "-q"]) == 2
    assert "--max-depth" in capsys.readouterr().err


def test_a_real_afm_curve_whose_weightings_disagree_is_not_a_success():
    """spot3 (161 nm deep): mixed weights 0.125 N/m, uniform 0.161 N/m, intervals +-2 %:
    the model misses the data's shape, and the fit says so; its numbers are kept."""
    from shellbvp.afm import read_afm

    pytest.importorskip("afmformats")
    (curve,) = read_afm(DATA / "spot3-0192.jpk-force")
    res, _ = fit_record(sb.Scene.preset("base", **AFM_SCENE), curve.record, R_L=10e-6, model="shell")
    assert res.status == 6 and not res.success and res.quality == "poor"
    check = res.weights_check
    assert not check["agree"] and check["weights"] == "uniform"
    lo, hi = res.mu_H_ci95
    assert np.isfinite([res.mu_H, lo, hi]).all() and lo < res.mu_H < hi
    assert check["mu_H_ci95"][0] > hi                       # no overlap
    assert f"{res.mu_H:.4g}" in res.message and f"{check['mu_H']:.4g}" in res.message
