"""The thickness map and the 3D reference (issue 41).

The map ``beta = eps^2/3`` is derived from the plate limit of the bending energies against
3D plate theory (symbolic); the 3D model (FElupe) is checked against a closed form (Kirchhoff's
simply supported plate under a central load, which holds ``D = mu H^3/3``) and against the
independent FE model of SPEC section 8; its contact tangent against finite differences.
"""

import math

import numpy as np
import pytest
import sympy as sp

import shellbvp as sb
from shellbvp.cli import main
from symbolic import bending as sbend


# ------------------------------------------------------------------ the thickness map
def test_plate_limits_are_derived_and_match_the_classes():
    assert sbend.plate_3d() == (sp.Rational(1, 3), sp.Rational(1, 2))  # D / (mu H^3), nu: incompressible
    for B, cls, want in ((sbend.trace_bending(), sb.TraceBending, (1.0, 1.0)),
                         (sbend.rotation_bending(), sb.RotationBending, (1.0, 1.0)),
                         (sbend.koiter_bending(), sb.KoiterBending, (1.0, 0.5))):   # the 3D plate's nu
        stiffness, poisson = sbend.plate_limit(B)
        assert (float(stiffness), float(poisson)) == (cls.plate_stiffness, cls.plate_poisson) == want
        assert sb.beta_from_thickness(0.05, bending=cls()) == pytest.approx(0.05**2 / 3)
    user = sb.BendingEnergy("(kappa_s - kappa_s0)**2 + (kappa_theta - kappa_theta0)**2"
                            " + (kappa_s - kappa_s0)*(kappa_theta - kappa_theta0)")
    assert (user.plate_stiffness, user.plate_poisson) == (2.0, 0.5)   # a 3D plate's Poisson ratio
    assert sb.beta_from_thickness(0.05, bending=user) == pytest.approx(0.05**2 / 6)
    # Koiter's energy written as a user formula: Kirchhoff's plate at Poisson ratio 1/2
    gauss = sb.BendingEnergy("(lambda_s**2*kappa_s - kappa_s0 + lambda_theta**2*kappa_theta - kappa_theta0)**2/2"
                             " - (lambda_s**2*kappa_s - kappa_s0)*(lambda_theta**2*kappa_theta - kappa_theta0)/2")
    assert (gauss.plate_stiffness, gauss.plate_poisson) == (1.0, 0.5)
    wall = sb.ThicknessProfile.formula("0.025*(1 + S/L)")
    assert sb.Scene.preset("base", bending=gauss, thickness=wall).beta == pytest.approx(0.025**2 / 3)


def test_beta_from_thickness_is_the_3d_plate():
    assert sb.beta_from_thickness(50e-6, 0.3e-3) == pytest.approx((50 / 300) ** 2 / 3, rel=1e-15)
    assert sb.beta_from_thickness(np.float64(0.1)) == pytest.approx(0.01 / 3)
    for bad in (0, -1, float("nan"), "0.1", True):
        with pytest.raises(ValueError, match="H must be a finite length > 0"):
            sb.beta_from_thickness(bad, 1.0)


def test_scene_thickness_sets_beta_and_replace_keeps_them_consistent():
    s = sb.Scene(thickness=0.05)
    assert s.beta == pytest.approx(0.05**2 / 3) and s.thickness == 0.05
    assert sb.Scene.from_dict(s.to_dict()) == s
    assert s.replace(beta=0.02).thickness is None                      # a beta of its own drops eps
    assert s.replace(thickness=0.1).beta == pytest.approx(0.01 / 3)
    assert sb.Scene(beta=0.02).replace(thickness=0.1).beta == pytest.approx(0.01 / 3)
    user = sb.BendingEnergy("(kappa_s - kappa_s0)**2 + (kappa_theta - kappa_theta0)**2")
    assert s.replace(bending=user).beta == pytest.approx(0.05**2 / 6)    # the plate limit of the energy
    assert sb.Scene.preset("fit", thickness=50 / 300).beta == pytest.approx((50 / 300) ** 2 / 3)
    with pytest.raises(ValueError, match="beta = 0.3 and thickness = 0.05 disagree"):
        sb.Scene(thickness=0.05, beta=0.3)
    for bad in (0, 0.6, float("inf")):
        with pytest.raises(ValueError, match="thickness"):
            sb.Scene(thickness=bad)
    assert "thickness" not in sb.Scene().to_dict()                     # files of scenes without it as before


def test_cli_thickness_with_a_unit_needs_the_radius(capsys):
    assert main(["solve", "--thickness", "50um", "--delta", "0.1"]) == 2
    assert "needs --radius" in capsys.readouterr().err
    from shellbvp.cli import build_parser, scene_from_args

    args = build_parser().parse_args(["solve", "--preset", "fit", "--thickness", "50um", "--radius", "0.3mm"])
    assert scene_from_args(args).beta == pytest.approx((50 / 300) ** 2 / 3)
    assert scene_from_args(build_parser().parse_args(["curve", "--thickness", "0.1"])).beta == pytest.approx(0.01 / 3)


# ------------------------------------------------------------------ the indenter's surface
def test_tip_surface_of_a_user_sphere_is_the_closed_form():
    """The closest-point distance of a general tip (Newton in omega) against the sphere's."""
    from shellbvp.fe import TipSurface

    sphere = TipSurface(sb.Scene(rho=0.3))
    user = TipSurface(sb.Scene(rho=0.3, tip=sb.UserTip("sin(omega)", "1 - cos(omega)")))
    rng = np.random.default_rng(1)
    # (z, r) below the sphere's centre (z < rho), outside and inside it
    x = np.stack([rng.uniform(-0.1, 0.29, 200), rng.uniform(0.0, 0.45, 200)], axis=1)
    d0, n0, H0 = sphere.distance(x, 0.0)
    d1, n1, H1 = user.distance(x, 0.0)
    assert np.any(d0 < 0) and np.any(d0 > 0)
    np.testing.assert_allclose(d1, d0, atol=1e-12)
    np.testing.assert_allclose(n1, n0, atol=1e-9)
    np.testing.assert_allclose(H1, H0, atol=1e-7)


# ------------------------------------------------------------------ the 3D model
felupe = pytest.importorskip("felupe", reason="the 3D reference needs FElupe ('.[fe]')")


def test_contact_tangent_is_the_derivative_of_its_force():
    from shellbvp import fe

    eps = 0.1
    model = fe._build(sb.Scene(), eps, through_thickness=2, element_length=1.0, pole_refinement=1, bulk=5000.0,
                      penalty=1e3, gauss_points=3)
    c = model.contact
    c.bind(model.mesh.points)
    c.apex = c.z0 - 0.02
    u = np.random.default_rng(0).normal(size=c.ndof_u) * 1e-3
    r, K, F, radius = c.evaluate(u)
    assert F > 0 and radius > 0
    K = K.toarray()
    h = 1e-7
    for j in np.flatnonzero(r[: c.ndof_u])[:8]:
        up, um = u.copy(), u.copy()
        up[j] += h
        um[j] -= h
        fd = (c.evaluate(up, False)[0] - c.evaluate(um, False)[0]) / (2 * h)
        np.testing.assert_allclose(K[:, j], fd, atol=1e-6 * np.abs(fd).max())


def test_flat_plate_bends_as_kirchhoff_with_d_mu_h3_over_3():
    """A thin flat disk, simply supported at mid-thickness, under a small central load: Kirchhoff's
    deflection ``w = F a^2 (3 + nu)/(16 pi (1 + nu) D)`` with nu = 1/2 and D = mu H^3/3 -- the 3D
    bending stiffness the thickness map rests on (eps^2/12 would be 4x off).  Transverse shear
    and the contact's spread add O(eps^2 ln) here (~1 %)."""
    eps = 0.02
    c = sb.fe_curve(sb.Scene(gamma=0.0, rho=0.2, material=sb.NeoHookean()), eps, [0.05 * eps])
    assert c.success, c.message
    nu, D = 0.5, eps**3 / 3
    F_kirchhoff = c.delta[0] * 16 * math.pi * (1 + nu) * D / (3 + nu) / eps    # F / (mu R_L H)
    assert c.force[0] / F_kirchhoff - 1 == pytest.approx(0.0, abs=0.03)


def test_hemisphere_matches_the_independent_fe_model():
    """SPEC section 8: at eps 0.05, delta = H, an independent FElupe model found the shell model
    (smooth, beta = eps^2/3, neo-Hookean) 10.3 % above the solid.  Target: within 1.5 %."""
    eps = 0.05
    scene = sb.Scene(gamma=1.0, rho=0.2, material=sb.NeoHookean(), thickness=eps)
    fe = sb.fe_curve(scene, eps, [eps])
    shell = sb.curve(scene, deltas=[eps], estimate_error=False)
    independent = shell.force[0] / 1.103
    assert fe.success
    assert fe.force[0] / independent - 1 == pytest.approx(0.0, abs=0.015)
    assert 0 < fe.contact_radius[0] < 0.2 and fe.indenter[0] > fe.delta[0]   # the wall thins under the tip


def test_validate_writes_both_curves(tmp_path, capsys):
    import h5py

    from shellbvp.nexus import missing_units

    out = tmp_path / "v.h5"
    rc = main(["validate", "--preset", "base", "--neo-hookean", "--thickness", "0.1", "--deltas", "0.05,0.1",
               "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "F_shell" in text and "wrote" in text
    with h5py.File(out) as f:
        cmp_ = f["entry/comparison"]
        assert cmp_.attrs["NX_class"] == "NXdata"
        np.testing.assert_allclose(cmp_["delta"][()], [0.05, 0.1])
        err = cmp_["force_shell"][()] / cmp_["force_fe"][()] - 1
        np.testing.assert_allclose(cmp_["error"][()], err)
        assert np.all(np.abs(err) < 0.5) and f["entry/fe"].attrs["success"]
        assert f["entry/shell/force"].shape == (2,)
    assert missing_units(out) == []
    assert main(["validate", "--preset", "base", "-o", str(tmp_path / "w.h5")]) == 2
    assert "needs --thickness" in capsys.readouterr().err


def test_fe_materials_map_to_the_shell_models(capsys):
    """Mooney-Rivlin through tensortrax with alpha = 0 is FElupe's own neo-Hooke; a user energy
    of a sheet (no unique 3D form) is refused before any work."""
    scene = sb.Scene.preset("base", thickness=0.1)
    nh = sb.fe_curve(scene.replace(material=sb.NeoHookean()), 0.1, [0.05])
    mr = sb.fe_curve(scene.replace(material=sb.MooneyRivlin(0.0)), 0.1, [0.05])
    assert nh.success and mr.success
    assert mr.force[0] == pytest.approx(nh.force[0], rel=1e-6)
    user = scene.replace(material=sb.StrainEnergy("(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2"))
    with pytest.raises(ValueError, match="no unique 3D form"):
        sb.fe_curve(user, 0.1, [0.05])
    with pytest.raises(ValueError, match="thickness"):
        sb.fe_curve(scene, 0.7, [0.05])
    with pytest.raises(ValueError, match="deltas"):
        sb.fe_curve(scene, 0.1, [0.1, 0.05])


def test_fit_with_a_thickness_reports_mu(tmp_path, capsys):
    """``--thickness 50um --radius 0.3mm``: beta from the thickness, mu = mu*H / H beside mu*H."""
    import json

    from shellbvp.fitting import example_data_path

    d, F = sb.read_force_csv(example_data_path())
    res = sb.fit(sb.Scene.preset("fit", thickness=50 / 300), d, F, R_L=0.3e-3, model="shell")
    assert res.success and res.thickness == pytest.approx(50e-6)
    assert res.mu == pytest.approx(res.mu_H / 50e-6) and res.mu_ci95[0] < res.mu < res.mu_ci95[1]
    assert json.loads(json.dumps(res.to_dict()))["mu"] == pytest.approx(res.mu)
    assert sb.fit(sb.Scene.preset("fit"), d, F, R_L=0.3e-3).mu is None
    out = tmp_path / "f.h5"
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--thickness", "50um",
                 "--model", "shell", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "mu     = " in text and "MPa" in text and "eps = H/R_L = 0.167" in text
    assert main(["info", str(out)]) == 0
    assert "thickness H = 50 um" in capsys.readouterr().out
