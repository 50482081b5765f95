"""The shell's thickness as a fitted shape parameter (shellbvp.shape_parameters, issue 43 item 5):
H with its interval, and the modulus mu = mu*H / H and E = 3 mu with intervals that carry H's
uncertainty; a reparametrisation of beta (beta = (H/R_L)^2/3), so it must give beta's fit."""

import json

import numpy as np
import pytest

import shellbvp as sb
import shellbvp.fitting
from shellbvp.units import beta_from_thickness

from fake_curves import FakeCurve

R_L, MU_H, D0 = 0.3e-3, 52.0, 0.01e-3
H_TRUE = 40e-6  # eps = 0.133, beta = 0.00593


def _data(scene, seed=0, noise=0.02):
    x = np.linspace(0.01, 0.4, 40)
    rng = np.random.default_rng(seed)
    force = MU_H * R_L * FakeCurve(scene, x).force * (1 + noise * rng.standard_normal(x.size))
    return R_L * x + D0, force


def test_thickness_recovers_h_and_the_modulus_within_their_intervals(closed_form):
    d, F = _data(sb.Scene.preset("fit", thickness=H_TRUE / R_L))
    start = sb.Scene.preset("fit", thickness=25e-6 / R_L)
    r = sb.fit(start, d, F, R_L=R_L, free=("thickness",))
    assert r.success and r.fitted == ("mu_H", "offset", "thickness")
    lo, hi = r.thickness_ci95
    assert lo < H_TRUE < hi and hi - lo < 0.5 * H_TRUE, (r.thickness, r.thickness_ci95)
    assert r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1]
    mu_true = MU_H / H_TRUE
    assert r.mu_ci95[0] < mu_true < r.mu_ci95[1], (r.mu, r.mu_ci95, mu_true)
    assert r.mu == pytest.approx(r.mu_H / r.thickness, rel=1e-12)
    assert r.E == pytest.approx(3 * r.mu, rel=1e-12) and r.E_ci95 == pytest.approx([3 * v for v in r.mu_ci95])
    # mu's interval carries H's uncertainty: wider than mu*H's over an exact H; positive (ln mu linearised)
    assert r.mu_ci95[1] - r.mu_ci95[0] > 2 * (r.mu_H_ci95[1] - r.mu_H_ci95[0]) / r.thickness
    assert 0 < r.mu_ci95[0] < r.mu < r.mu_ci95[1]
    # the reported beta is the fitted thickness's, by the package's map
    assert r.beta == pytest.approx(beta_from_thickness(r.thickness, R_L), rel=1e-12)
    out = json.loads(json.dumps(r.to_dict()))
    assert out["thickness"] == pytest.approx(r.thickness) and out["E_ci95"] == pytest.approx(list(r.E_ci95))
    assert out["units"]["thickness"] == "m" and out["units"]["E"] == "Pa"


def test_thickness_gives_the_fit_of_beta(closed_form):
    """The same data, the same start (a scene with a thickness) and the same range: fitting the
    thickness is fitting beta on the other side of the map, trial value for trial value."""
    d, F = _data(sb.Scene.preset("fit", thickness=H_TRUE / R_L), seed=4)
    start = sb.Scene.preset("fit", thickness=30e-6 / R_L)
    beta_range = (2e-3, 2e-2)
    eps_range = tuple(np.sqrt(3 * np.array(beta_range)))  # the same range through beta = eps^2/3
    rb = sb.fit(start, d, F, R_L=R_L, fit_beta=True, beta_bounds=beta_range)
    rt = sb.fit(start, d, F, R_L=R_L, free=("thickness",), bounds={"thickness": eps_range})
    assert rb.success and rt.success and rb.curves_computed == rt.curves_computed
    assert rt.mu_H == pytest.approx(rb.mu_H, rel=1e-9)
    assert rt.mu_H_ci95 == pytest.approx(rb.mu_H_ci95, rel=1e-7)
    assert rt.offset == pytest.approx(rb.offset, rel=1e-9)
    assert rt.beta == pytest.approx(rb.beta, rel=1e-8)
    beta_ci = [beta_from_thickness(h, R_L) for h in rt.thickness_ci95]
    assert beta_ci == pytest.approx(list(rb.beta_ci95), rel=1e-6)
    assert rb.thickness is None and rb.mu is None  # a fitted beta leaves the thickness unknown


def test_thickness_options_are_checked_before_any_curve(closed_form):
    scene = sb.Scene.preset("fit", thickness=0.1)
    d, F = _data(scene)
    with pytest.raises(ValueError, match="starts from the scene's thickness"):
        sb.fit(sb.Scene.preset("fit"), d, F, R_L=R_L, fit_thickness=True)
    with pytest.raises(ValueError, match="thickness_bounds"):
        sb.fit(scene, d, F, R_L=R_L, free=("thickness",), bounds={"thickness": (0.05, 0.8)})
    with pytest.raises(ValueError, match="one of beta, alpha, pressure, thickness"):
        sb.fit(scene, d, F, R_L=R_L, free=("thickness", "beta"))
    from shellbvp.uncertainty import fit_with_geometry

    with pytest.raises(ValueError, match="beta is fitted"):
        fit_with_geometry(scene, d, F, R_L=R_L, uncertainty={"beta": 1e-3}, workers=1, fit_thickness=True)


def test_cli_fit_thickness_prints_h_and_mu_and_writes_them(closed_form, tmp_path, capsys):
    from shellbvp.cli import main
    from shellbvp.fitrecord import read_fit
    from shellbvp.plotting import fit_summary_lines

    d, F = _data(sb.Scene.preset("fit", thickness=H_TRUE / R_L))
    data = tmp_path / "seed.csv"  # displacements from the contact point (the fit's offset is fixed)
    data.write_text("displacement (um),force (mN)\n"
                    + "".join(f"{(a - D0) * 1e6:.6f},{b * 1e3:.8g}\n" for a, b in zip(d, F)))
    argv = ["fit", str(data), "--preset", "fit", "--radius", "0.3mm", "--thickness", "30um", "--fit-thickness",
            "--no-offset", "--baseline", "none", "--thickness-range", "10um,100um", "-q"]
    assert main(argv + ["-o", str(tmp_path / "fit.h5")]) == 0
    text = capsys.readouterr().out
    line = next(ln for ln in text.splitlines() if ln.startswith("thickness = "))
    assert " um   95% CI [" in line and "profile likelihood" in line
    assert "mu     = " in text and "E      = " in text and "MPa" in text
    rec = read_fit(tmp_path / "fit.h5")
    assert rec.fitted == ["mu_H", "thickness"]
    lo, hi = rec.intervals["thickness"]
    assert lo < H_TRUE < hi and rec.intervals["mu"][0] < MU_H / H_TRUE < rec.intervals["mu"][1]
    assert rec.parameters["E"] == pytest.approx(3 * rec.parameters["mu"])
    report = fit_summary_lines(rec)
    assert any(ln.startswith("E = ") for ln in report) and any("3D elasticity" in ln for ln in report)
    assert main(argv[:-3] + ["--thickness-range", "10um", "-q"]) == 2
    assert "--thickness-range must be two numbers" in capsys.readouterr().err
    # batch table: one column each for H, mu and E and their intervals
    from shellbvp.batch import TABLE_COLUMNS

    assert {"thickness (m)", "mu 95% low (Pa)", "E 95% high (Pa)"} <= set(TABLE_COLUMNS)


@pytest.mark.slow
def test_thickness_from_model_curves():
    """Real model curves of the preset fit at H = 40 um on R_L = 0.3 mm, mu*H = 52 N/m, 1 %
    proportional noise; the fit starts from H = 30 um.  H and mu are recovered within their
    intervals, and beta fitted from the same start gives the same mu*H."""
    truth = sb.Scene.preset("fit", thickness=H_TRUE / R_L)
    c = sb.curve(truth, deltas=np.linspace(0.01, 0.4, 30), estimate_error=False)
    rng = np.random.default_rng(7)
    d = R_L * np.asarray(c.delta) + D0
    F = MU_H * R_L * np.asarray(c.force) * (1 + 0.01 * rng.standard_normal(len(c.delta)))
    start = sb.Scene.preset("fit", thickness=30e-6 / R_L)
    rt = sb.fit(start, d, F, R_L=R_L, free=("thickness",))
    assert rt.success, rt.message
    assert rt.thickness_ci95[0] < H_TRUE < rt.thickness_ci95[1], (rt.thickness, rt.thickness_ci95)
    assert rt.mu_ci95[0] < MU_H / H_TRUE < rt.mu_ci95[1], (rt.mu, rt.mu_ci95)
    assert rt.mu_H_ci95[0] < MU_H < rt.mu_H_ci95[1]
    rb = sb.fit(start, d, F, R_L=R_L, free=("beta",))
    assert rb.success
    assert rt.mu_H == pytest.approx(rb.mu_H, rel=1e-6) and rt.beta == pytest.approx(rb.beta, rel=1e-5)
