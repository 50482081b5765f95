r"""Koiter's bending energy at Poisson ratio 1/2, the built-in family ``koiter`` (issue 58).

``B = (Ds + Dt)^2/2 - (1 - nu) Ds Dt``, nu = 1/2, ``Ds = lambda_s^2 kappa_s - kappa_s0``,
``Dt = lambda_theta^2 kappa_theta - kappa_theta0``.  Checked here:

* its plate limit is the 3D incompressible plate's ``(1, 1/2)`` and the class declares it; beta
  from a thickness stays ``eps^2/3``; the family is on the command line;
* the derived equilibrium equations are the Euler-Lagrange equations of its energy, written here
  by hand (``tests/test_variational.py``'s energy side), for a uniform wall and one whose
  thickness varies (``t W + beta t^3 B``); and they are not the trace energy's;
* F = dE/ddelta on a koiter state; the n = 0 stability form on a branch tangent is dF/ddelta,
  and with the trace energy's form it is not;
* the flat disk thickening to twice its thickness: with the built-in family the shell model's
  stiffness ratio is the user formula's (benchmarks/results/profile_solid.json: 1.9734), within
  0.5 % of the 3D solid's stored 1.9694 (the trace energy's: 1.6001).

The 2D form's own checks (axisymmetric restriction, first variation, rigid motions, the flat
plate's closed form, a harmonic deflection's cost) are in tests/test_second_variation.py.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import mpmath as mp
import pytest
import sympy as sp

import shellbvp as sb
from symbolic import bending as sbend
from symbolic import geometry
from symbolic.equations import BETA, Structure, derive
from symbolic.geometry import S
from symbolic.materials import LS, LT

import test_variational as tv
from benchmark_modules import load_benchmark
from test_bending import _energy_identity_error
from branch_tangent import branch_check, neighbours

RESULTS = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "profile_solid.json"


def test_plate_limit_is_the_incompressible_plates_and_beta_stays():
    stiffness, poisson = sbend.plate_limit(sbend.koiter_bending())
    assert (stiffness, poisson) == (1, sp.Rational(1, 2)) == (1, sbend.plate_3d()[1])
    assert (sb.KoiterBending.plate_stiffness, sb.KoiterBending.plate_poisson) == (1.0, 0.5)
    assert sbend.check_bending(sbend.koiter_bending()) == 1
    wall = sb.ThicknessProfile.formula("0.025*(1 + S/L)")
    assert sb.Scene.preset("base", thickness=wall, bending=sb.KoiterBending()).beta == pytest.approx(0.025**2 / 3)
    assert sb.beta_from_thickness(0.05, bending=sb.KoiterBending()) == sb.beta_from_thickness(0.05)
    # the documented user formula is this energy
    text = ("(lambda_s**2*kappa_s - kappa_s0 + lambda_theta**2*kappa_theta - kappa_theta0)**2/2"
            " - (lambda_s**2*kappa_s - kappa_s0)*(lambda_theta**2*kappa_theta - kappa_theta0)/2")
    assert sp.expand(sb.BendingEnergy(text).B - sbend.koiter_bending()) == 0
    # ... so its second variation is the family's (docs/stability.md); another formula is refused
    from symbolic.second_variation import bending_family

    assert bending_family(sb.BendingEnergy(text).B) == bending_family(sbend.koiter_bending()) == "koiter"
    with pytest.raises(ValueError, match="trace, rotation and koiter"):
        bending_family(sbend.koiter_bending() + (LS - 1) ** 2 * (sbend.KS - sbend.KS0) ** 2)


def test_the_family_is_registered_and_on_the_command_line(capsys):
    from shellbvp.cli import main
    from shellbvp.materials import bending_class

    assert bending_class("koiter") is sb.KoiterBending
    scene = sb.Scene.preset("base", bending=sb.KoiterBending())
    assert sb.Scene.from_dict(scene.to_dict()) == scene and scene.to_dict()["bending"] == {"family": "koiter"}
    with pytest.raises(SystemExit):
        main(["solve", "--help"])
    assert "koiter" in capsys.readouterr().out


def test_koiters_energy_is_not_convex_at_large_bending_as_the_trace_energy():
    """Bilinear in (psi, phi') like the trace energy (lambda_s^2 kappa_s = psi phi'/Psi^2): the
    Legendre determinant changes sign at large bending (Mooney-Rivlin 0.1, beta 0.01), as
    the class's docstring and docs/limits.md's corner say of both."""
    from symbolic import materials

    W = materials.mooney_rivlin(sp.Rational(1, 10))
    det = sbend.legendre_determinant(W, sbend.koiter_bending().xreplace({sbend.KS0: 1, sbend.KT0: 1}),
                                     beta=sp.Rational(1, 100))
    signs = {bool(det.evalf(subs={LS: ls, LT: 1.1, sbend.KS: ks, sbend.KT: ks}) > 0)
             for ls in (0.8, 1.2, 1.6) for ks in (0.0, 2.0, 5.0, 10.0)}
    assert signs == {True, False}


# ------------------------------------------------------------------ Euler-Lagrange
WALL = tv.WALL


def _koiter_energy(ls, lt, ks, kt):
    """B by hand: the trace energy less half the product of the two bending strains."""
    ds, dt = ls**2 * ks - tv.KS_REF, lt**2 * kt - tv.KT_REF
    return (ds + dt) ** 2 / 2 - ds * dt / 2


@pytest.mark.slow  # ~15-20 s each (the derivation and the energy side's lambdify)
@pytest.mark.parametrize("profiled", [False, True])
def test_equilibrium_is_euler_lagrange_of_koiters_energy(profiled):
    """At random smooth meridians (not solutions): ``E_x . e_s = -eq1``, ``E_x . n = r psi eq2``
    to 1e-25 with E_x the Euler-Lagrange vector of ``L = (t W + beta t^3 B) R Psi`` written here,
    and eq1, eq2 from the derivation's tau, M (Mooney-Rivlin; ``profiled``: t = tests/
    test_variational.py's WALL, else 1).  The trace energy's equations miss by more than 1e-3."""
    W, par = tv.MATERIALS["mooney_rivlin"]
    t = WALL if profiled else sp.S.One
    k = tv.KIN
    U = t * W.xreplace({LS: k["ls"], LT: k["lt"]}) + BETA * t**3 * _koiter_energy(k["ls"], k["lt"], k["ks"], k["kt"])
    L = U * tv.R_REF * tv.PSI_REF
    Er = sp.diff(L, tv.RJ[0]) - tv.D(sp.diff(L, tv.RJ[1])) + tv.D(tv.D(sp.diff(L, tv.RJ[2])))
    Ez = sp.diff(L, tv.ZJ[0]) - tv.D(sp.diff(L, tv.ZJ[1])) + tv.D(tv.D(sp.diff(L, tv.ZJ[2])))
    d = derive(Structure(W=W, material_params=par, shell=geometry.spheroid(), tip=geometry.sphere_tip(), xi=1,
                         B=sbend.koiter_bending(), thickness=WALL if profiled else None))
    args = (S, *tv.RJ[:5], *tv.ZJ[1:5], *d.params)
    r1, z1 = tv.RJ[1], tv.ZJ[1]
    el = sp.lambdify(args, [(Er * r1 + Ez * z1) / tv.PSI, (Er * z1 - Ez * r1) / tv.PSI], "mpmath")
    A, o = d.free_phys, d.free_phys_out
    r, phi, ls, ks, _ = d.free_phys_vars
    sub = {r: tv.RJ[0], phi: k["phi"], ls: k["ls"], ks: k["ks"]}
    f = {n: A.expand(o[n]).xreplace(sub) for n in ("tau_s", "tau_t", "M_s", "M_t", "kt")}
    Q = (tv.D(tv.RJ[0] * f["M_s"]) - r1 * f["M_t"]) / (tv.RJ[0] * tv.PSI)
    eq1 = tv.D(tv.RJ[0] * f["tau_s"]) - r1 * f["tau_t"] + k["ks"] * tv.RJ[0] * Q * tv.PSI
    eq2 = k["ks"] * f["tau_s"] + f["kt"] * f["tau_t"] - tv.D(tv.RJ[0] * Q) / (tv.RJ[0] * tv.PSI)
    eqs = sp.lambdify(args, [eq1, eq2], "mpmath")
    trace = None if profiled else tv.equilibrium_along_jet("mooney_rivlin", 1)
    n = 0
    with mp.workdps(tv.DPS):
        for p, rr, zz, S0 in tv.cases("mooney_rivlin", 2, 2, seed=9):
            jr, jz = tv.meridian_jet(rr, zz, S0)
            pars = [tv.mpq(p[s]) for s in d.params]
            Et, En = el(S0, *jr, *jz, *pars)
            e1, e2 = eqs(S0, *jr, *jz, *pars)
            psi = mp.sqrt(jr[1] ** 2 + jz[0] ** 2)
            assert abs(Et) > 1e-4 and abs(En) > 1e-4  # not a solution: a real comparison
            assert tv.rel(Et, -e1) < 1e-25, (Et, -e1)
            assert tv.rel(En, jr[0] * psi * e2) < 1e-25, (En, jr[0] * psi * e2)
            if trace is not None:  # the Gaussian term enters the equations
                v = trace(S0, *jr, *jz, *pars)
                assert tv.rel(En, jr[0] * psi * v["eq2"]) > 1e-3
            n += 1
    assert n == 4


# ------------------------------------------------------------------ states and stability
@pytest.mark.slow  # ~18 s: five solves and the structure's code
def test_force_is_the_energys_derivative_on_a_koiter_state():
    """F = dE/ddelta (Richardson-extrapolated central differences) on the base scene at delta 0.5."""
    err, scale = _energy_identity_error(sb.Scene.preset("base", bending=sb.KoiterBending()), 0.5)
    assert err < max(scale, 1e-6)


@pytest.mark.slow  # ~30 s: two structures' second variations and three solves
def test_energy_along_a_koiter_cap_branch(monkeypatch):
    """Base scene with Koiter's energy at delta 0.5 (cap): the n = 0 second variation on the
    branch tangent with the contact's terms is dF/ddelta (tests/branch_tangent.py);
    with the trace energy's generated form in its place it is not (the Gaussian term enters the
    axisymmetric modes)."""
    from shellbvp.modal_stability import form

    scene = sb.Scene.preset("base", bending=sb.KoiterBending())
    lo, mid, hi = neighbours(scene, 0.5)
    assert mid.topology == "cap" and mid.valid
    dF, elastic, contact = branch_check(lo, mid, hi)
    assert abs(elastic + contact - dF) < 2e-3 * dF, (dF, elastic, contact)
    trace_form = form.form_functions(sb.Scene.preset("base"))
    monkeypatch.setattr(form, "form_functions", lambda s: trace_form)  # what form_at evaluates
    dF1, elastic1, contact1 = branch_check(lo, mid, hi)
    assert abs(elastic1 + contact1 - dF) > 1e-2 * dF, (dF, elastic1, contact1)


def test_the_generated_codes_are_keyed_on_the_family():
    """The structure's and its second variation's generated modules are the koiter family's own
    (keys differ from the trace energy's; the description names the family)."""
    from shellbvp.model import description_key, stability_description
    from shellbvp.modal_stability import form

    scene, trace = sb.Scene.preset("base", bending=sb.KoiterBending()), sb.Scene.preset("base")
    assert scene.structure()["bending"] == {"family": "koiter"}
    assert description_key(scene.structure()) != description_key(trace.structure())
    keys = {description_key(stability_description(s.structure())) for s in (scene, trace)}
    assert len(keys) == 2 and form._key(scene) != form._key(trace)


@pytest.mark.slow  # ~10-30 s: the structure's code and its second variation's, generated
def test_stability_of_a_koiter_state():
    """``sb.stability`` takes a koiter state (no refusal, as a user energy gets)."""
    scene = sb.Scene.preset("base", bending=sb.KoiterBending())
    res = sb.stability(sb.solve(scene, delta=0.3, estimate_error=False), modes=range(3))
    assert res.stable and res.eigenvalues.shape == (3, 2) and (res.eigenvalues > 0).all()


@pytest.mark.slow  # ~11 s: two structures
def test_koiter_and_trace_eigenvalues_differ():
    """The same depth, the two energies: the modes' eigenvalues differ (by ~2-4 % at delta 0.3)."""
    states = {b: sb.solve(sb.Scene.preset("base", bending=b), delta=0.3, estimate_error=False)
              for b in (sb.TraceBending(), sb.KoiterBending())}
    res = {type(b).__name__: sb.stability(s, modes=range(4)) for b, s in states.items()}
    k, t = res["KoiterBending"].eigenvalues, res["TraceBending"].eigenvalues
    assert k.shape == t.shape
    assert abs(k[2, 0] / t[2, 0] - 1) > 1e-2


# ------------------------------------------------------------------ the 3D solid's flat disk
def _profile_solid():
    """benchmarks/profile_solid.py (its disk and its shell solve)."""
    return load_benchmark("profile_solid")


@pytest.mark.slow  # ~25 s: two structures' code (a profiled wall is structural)
def test_the_flat_disk_stiffens_as_the_solid_with_the_builtin_family():
    """The disk of benchmarks/profile_solid.py (eps 0.02 thickening to twice that at the rim,
    delta 0.05 H0): the built-in family's profiled/uniform stiffness ratio is the user formula's
    (stored, 1.9734) to 1e-4 and within 0.5 % of the stored 3D solid's (1.9694); the uniform
    disk's force within 1 % of the solid's (the trace energy: +16.9 %)."""
    bench = _profile_solid()
    PLATE_EPS, plate_shell = bench.PLATE_EPS, bench.plate_shell
    stored = json.loads(RESULTS.read_text())
    fe = {k: stored["plate"][k]["fe"] for k in ("uniform", "profile")}
    user = stored["gauss"]["plate"]
    disk = sb.Scene(gamma=0.0, rho=0.2, material=sb.NeoHookean(), bending=sb.KoiterBending())
    d = 0.05 * PLATE_EPS
    got = {"uniform": plate_shell(disk.replace(thickness=PLATE_EPS), d),
           "profile": plate_shell(disk.replace(thickness=sb.ThicknessProfile.formula(f"{PLATE_EPS:g}*(1 + S/L)")), d)}
    assert all(math.isfinite(v) for v in got.values())
    ratio = got["profile"] / got["uniform"]
    assert ratio == pytest.approx(user["profile"] / user["uniform"], rel=1e-4)
    assert ratio == pytest.approx(fe["profile"] / fe["uniform"], rel=5e-3)
    assert got["uniform"] == pytest.approx(fe["uniform"], rel=1e-2)
