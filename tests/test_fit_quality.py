"""A fit report worth citing (issue 45, item 5): the correlation of the fitted parameters, the
noise scale, AIC/BIC, two residual diagnostics and a quality rating with written rules."""

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.fit_checks import AUTOCORRELATION_LEVEL
from shellbvp.fitting import QUALITY_RULES, example_data_path, fit_quality

R_L = 0.3e-3


@pytest.fixture(scope="module")
def data():
    return sb.read_force_csv(example_data_path())


def test_the_quality_rules_as_written():
    ci = lambda half: (1 - half, 1 + half)  # noqa: E731
    good, fair = QUALITY_RULES["good_halfwidth"], QUALITY_RULES["fair_halfwidth"]
    assert fit_quality(True, [], 1.0, ci(0.9 * good)) == "good"
    assert fit_quality(True, ["residual_runs"], 1.0, ci(0.9 * good)) == "fair"      # a warning
    assert fit_quality(True, [], 1.0, ci(1.1 * good)) == "fair"
    assert fit_quality(True, [], 1.0, ci(1.1 * fair)) == "poor"
    assert fit_quality(False, [], 1.0, ci(0.01)) == "poor"                           # failed its checks
    corr = np.array([[1.0, 0.99], [0.99, 1.0]])
    assert fit_quality(True, [], 1.0, ci(0.01), corr, ("mu_H", "beta")) == "fair"   # mu*H and beta entangled


def test_diagnostics_tell_the_right_model_from_a_wrong_one(data):
    """The example is made with preset fit (rho 1/3): fitted with it the residuals are noise; with
    rho 0.2 they form a pattern (few runs, correlated), the rating drops and AIC rises."""
    d, F = data
    right = sb.fit(sb.Scene.preset("fit"), d, F, R_L=R_L)
    wrong = sb.fit(sb.Scene.preset("fit", rho=0.2), d, F, R_L=R_L)
    assert right.quality == "good" and wrong.quality != "good"
    assert right.runs_p > 0.05 > wrong.runs_p
    assert abs(right.residual_autocorrelation) < 0.2 < wrong.residual_autocorrelation
    assert right.aic < wrong.aic and right.bic < wrong.bic
    c = right.correlation
    assert c.shape == (2, 2) and np.allclose(c, c.T) and np.allclose(np.diag(c), 1.0) and abs(c[0, 1]) < 1
    assert right.noise_sigma > 0


def test_a_wrong_rim_radius_warns_by_the_residuals_autocorrelation(data):
    """The example (R_L = 0.3 mm) fitted with its lengths in lab units and R_L given as 0.6 mm
    (rise, tip radius and thickness as measured): mu*H 2.4x the truth, and the residuals in depth
    order correlated far beyond AUTOCORRELATION_LEVEL (0.06 at the true R_L: no warning)."""
    d, F = data

    def lab(R):
        return sb.Scene.preset("fit", gamma=0.75e-3 / R, rho=0.1e-3 / R, thickness=52e-6 / R)

    right = sb.fit(lab(R_L), d, F, R_L=R_L, model="shell")
    wrong = sb.fit(lab(2 * R_L), d, F, R_L=2 * R_L, model="shell")
    assert "residual_autocorrelation" not in right.warning_codes
    assert right.residual_autocorrelation < AUTOCORRELATION_LEVEL
    assert "residual_autocorrelation" in wrong.warning_codes and wrong.mu_H > 2 * right.mu_H
    assert wrong.residual_autocorrelation > AUTOCORRELATION_LEVEL
    text = wrong.warnings[wrong.warning_codes.index("residual_autocorrelation")]
    assert "--radius" in text and f"{wrong.residual_autocorrelation:.2f}" in text


def test_aic_prefers_the_baseline_the_data_have(data):
    d, F = data
    shifted = F + 0.02 * F.max()  # the instrument reads a constant force before contact
    none = sb.fit(sb.Scene.preset("fit"), d, shifted, R_L=R_L, baseline="none")
    const = sb.fit(sb.Scene.preset("fit"), d, shifted, R_L=R_L, baseline="constant")
    assert const.aic < none.aic and const.fitted == ("mu_H", "offset", "baseline")
    assert const.correlation.shape == (3, 3)


def test_the_record_keeps_them(data, tmp_path, capsys):
    from shellbvp.cli import main
    from shellbvp.fitrecord import read_fit, write_fit

    rec = sb.read_instrument(example_data_path())
    res, used = sb.fit_record(sb.Scene.preset("fit"), rec, R_L=R_L)
    write_fit(tmp_path / "f.h5", res, rec, used)
    back = read_fit(tmp_path / "f.h5")
    np.testing.assert_allclose(back.correlation, res.correlation)
    assert back.quality == res.quality and back.parameters["aic"] == pytest.approx(res.aic)
    assert main(["info", str(tmp_path / "f.h5")]) == 0
    out = capsys.readouterr().out
    assert f"quality = {res.quality}" in out and "AIC" in out and "corr(mu_H, offset)" in out
