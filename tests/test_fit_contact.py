"""The contact point of records without an approach (issue 55): a sealed capsule between plates
whose force grows like delta^2 from contact rises by a few per cent over its first rows, which
the baseline test read as a baseline (the contact put 1.6 um inside the loaded rows, mu*H 0.70
for 0.5, rated fair).  Its first rows now are no baseline; a contact guess inside loaded rows
is left behind (the fit runs again on a curve reaching past it); residuals that trace a curve
rate a fit poor."""

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.fit_checks import fit_quality
from shellbvp.segments import BASELINE_FLAT, BASELINE_RISE, estimate_contact

R_L, MU_H, CONTACT = 30e-6, 0.5, 3e-6  # the shipped capsule record's truths (its header)


def _loading_only(tmp_path):
    """The shipped capsule record without its approach (the rows before contact, force noise
    only, as many as its header says), written as a file of its own: (path, d, f) in m and N."""
    src = Path(sb.__file__).parent / "data" / "capsule_plates_synthetic.csv"
    lines = src.read_text().splitlines()
    assert f"mu*H = {MU_H:g} N/m, contact at {CONTACT * 1e6:g} um" in lines[0]
    approach = int(re.search(r"an approach of (\d+) rows", lines[0]).group(1))
    rows = lines[2 + approach:]
    path = tmp_path / "capsule_loading_only.csv"
    path.write_text("\n".join(lines[:2] + rows) + "\n")
    d, f = np.array([[float(v) for v in r.split(",")] for r in rows]).T * 1e-6
    assert d[0] > CONTACT and np.all(f > 0)  # every row loaded
    return path, d, f


def test_a_loading_only_capsule_record_fits_from_its_first_row(tmp_path):
    path, d, f = _loading_only(tmp_path)
    rec = sb.read_instrument(path)
    assert rec.contact_estimate is None and rec.counts() == {"loading": d.size}
    res, used = sb.fit_record(sb.Scene.preset("capsule-plates"), rec, R_L=R_L)
    assert res.success, res.message
    assert res.baseline_model == "none" and used.all()
    assert res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1]
    assert res.offset_ci95[0] < CONTACT < res.offset_ci95[1]  # the contact within its noise
    assert abs(res.offset - CONTACT) < 0.05e-6
    assert res.quality == "good", res.warning_codes


def test_a_contact_guess_inside_the_loaded_rows_is_left_behind(tmp_path):
    """A guess 3.35 um inside the loaded rows (where the old baseline test put it) and a constant
    baseline: the contact ran into the model curve's end 1.6 um inside; the fit runs again on a
    curve reaching past it.  With the curve's depth given (delta_max), it stays there: its
    residuals trace a curve, and it is rated poor."""
    _, d, f = _loading_only(tmp_path)
    scene = sb.Scene.preset("capsule-plates")
    guess = 6.35e-6
    res = sb.fit(scene, d, f, R_L=R_L, baseline="constant", contact_guess=guess)
    assert res.success, res.message
    assert res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1]
    assert res.offset_ci95[0] < CONTACT < res.offset_ci95[1]
    pinned = sb.fit(scene, d, f, R_L=R_L, baseline="constant", contact_guess=guess,
                    delta_max=1.2 * (d.max() - guess) / R_L)
    assert pinned.offset > 4.5e-6 and pinned.mu_H > 0.6  # the old fit: 0.70 N/m, contact at 4.62 um
    assert {"residual_runs", "residual_autocorrelation"} <= set(pinned.warning_codes)
    assert pinned.quality == "poor"


def test_a_baseline_is_flat_or_straight_and_loaded_rows_are_not_one():
    rng = np.random.default_rng(5)
    x = np.linspace(0, 1, 300)
    noise = 1e-4 * rng.standard_normal(x.size)
    # convex from the first row (force ~ delta^2): its first tenth rises by 2 % of the whole, which
    # the 5 % rule alone took for a baseline
    loaded = (x + 0.02) ** 2 + noise
    k = x.size // 10
    assert (loaded[k] - loaded[0]) / np.ptp(loaded) < 0.05
    assert estimate_contact(x, loaded) is None
    assert estimate_contact(x[::10], loaded[::10]) is None  # 30 rows
    # an approach to the contact at 0.3: flat, tilted (drift: 30 times the noise over the first
    # tenth, 0.6 % of the rise; the threshold, from the flat baseline's band, is met early), noise-free
    shape = np.clip(x - 0.3, 0, None) ** 2
    tilt = 0.03 * x
    assert tilt[k] - tilt[0] > BASELINE_FLAT * 1e-4
    for f, lo in ((shape + noise, 0.29), (shape + tilt + noise, 0.2), (shape, 0.29)):
        e = estimate_contact(x, f)
        assert e is not None and lo < e < 0.45, e


def test_residuals_that_run_and_follow_each_other_rate_a_fit_poor():
    narrow = (0.99, 1.01)
    assert fit_quality(True, ["residual_runs"], 1.0, narrow) == "fair"
    assert fit_quality(True, ["residual_autocorrelation"], 1.0, narrow) == "fair"
    assert fit_quality(True, ["residual_runs", "residual_autocorrelation"], 1.0, narrow) == "poor"


@pytest.mark.parametrize("name", ["capsule_plates_synthetic.csv", "cell_glass_synthetic.csv",
                                  "lepidium_synthetic.csv"])
def test_the_shipped_records_keep_their_contact_estimate(name):
    path = Path(sb.__file__).parent / "data" / name
    approach = re.search(r"an approach of (\d+) rows", path.read_text().splitlines()[0])
    d, f = sb.read_force_csv(path)
    est = estimate_contact(d, f)
    if approach is None:  # the example of the README starts 0.01 R_L beyond its contact: no baseline
        assert est is None
    else:  # the last row of the approach or one of the first two loaded
        n = int(approach.group(1))
        assert est is not None and d[n - 1] <= est <= d[n + 1], (est, d[n - 1:n + 2])


def test_a_record_whose_first_rows_rise_like_the_rest_has_no_baseline(tmp_path):
    """A shell's record without its approach (the first row 3 um past the contact at 10 um) from a
    curve of another shape than the fitting model's (a hemisphere's, fitted as the preset's
    spheroid): its first tenth rises steadily but by only 3 % of the whole and hardly curves,
    which the baseline test read as an approach (the contact guessed at 25 um, a constant baseline
    fitted: the contact put at 16.4 um, past the first row, and the baseline taking up the
    shapes' difference, mu*H 13 % above the fit with the contact known; 4.7 % without it).  Its first rows rise at
    0.4 of the slope beyond them; an approach (flat or tilted by drift) rises far less steeply."""
    fit_scene = sb.Scene.preset("fit")
    r_l, mu_h, contact = 0.3e-3, 52.0, 10e-6
    c = sb.curve(dataclasses.replace(fit_scene, gamma=1.0), deltas=np.linspace(0.01, 0.25, 49),
                 estimate_error=False)
    rng = np.random.default_rng(3)
    d = contact + r_l * c.delta
    f = mu_h * r_l * c.force * (1 + 0.02 * rng.standard_normal(d.size))
    k = d.size // 10
    assert (f[k - 1] - f[0]) / np.ptp(f) < BASELINE_RISE  # the 5 % rule alone reads a baseline
    assert estimate_contact(d, f) is None
    path = tmp_path / "hemisphere_loading_only.tsv"
    path.write_text("Displacement (um)\tForce (uN)\n" + "\n".join(f"{a * 1e6:.5f}\t{b * 1e6:.6g}" for a, b in zip(d, f))
                    + "\n")
    rec = sb.read_instrument(path)
    assert rec.contact_estimate is None
    # the shapes differ on purpose: the weightings' check would (rightly) refuse every fit of it
    res, used = sb.fit_record(fit_scene, rec, R_L=r_l, weights_check=False)
    assert res.success, res.message
    assert res.baseline_model == "none" and used.all()
    assert contact - 1e-6 < res.offset < d[0]  # before the first row, near the truth
    known = sb.fit(fit_scene, d - contact, f, R_L=r_l, fit_offset=False, weights_check=False)
    assert abs(res.mu_H / known.mu_H - 1) < 0.08  # the shapes' difference, not a baseline's (+13 %)
