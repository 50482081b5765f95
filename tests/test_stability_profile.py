r"""Stability of a wall whose thickness varies (shellbvp.modal_stability with a ThicknessProfile; issue 58).

The energy per reference area is ``t W + beta t^3 B``; its second variation is the uniform
wall's with the membrane part times t(S) and the bending part times t(S)^3, t at the
quadrature points of the modal mesh.  Checked here:

* a uniform profile (a table of constant rows: the profiled code with t = 1) gives the uniform scene's
  eigenvalues to 1e-8;
* the generated form of a profiled structure is the uniform structure's generated form taken
  apart into its membrane, bending and pressure parts and scaled by t, t^3 and 1 (random points,
  every mode number), and the generated t(S) is the profile's own (a formula and a table);
* the energy along a profiled cap's branch: ``dF/d delta`` (from the axisymmetric solutions)
  equals the n = 0 second variation on the branch tangent (as tests/test_stability_contact.py
  for the uniform wall); with t = 1 in the form it misses by more than 20 %;
* on the unstressed shell the form is the sum of a membrane and a bending part, each positive
  semidefinite, so (min-max, same mesh) ``t_min lambda_k(H0 t_min) <= lambda_k(profile) <=
  lambda_k(H0)`` for a wall with ``t_min <= t <= 1``: a wall thinner everywhere than the
  uniform H0 wall has smaller eigenvalues, and larger ones than the uniform wall of its
  thinnest thickness (in the units of the pole's thickness, hence the factor t_min).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from branch_tangent import branch_check, neighbours

import shellbvp as sb
from shellbvp import modal_stability as st
from shellbvp.modal_stability import form
from shellbvp.thickness_profile import ThicknessProfile


L = math.pi / 2
THINNING = ThicknessProfile.formula("0.05*(1 - 0.5*S/L)")  # half as thick at the rim


@pytest.fixture(scope="module")
def uniform():
    return sb.Scene.preset("base", beta=None, thickness=0.05)


def test_a_uniform_profile_gives_the_uniform_walls_eigenvalues(uniform):
    flat = uniform.replace(thickness=ThicknessProfile.table(np.linspace(0, L, 7), np.full(7, 0.05)))  # the tests' shared table
    assert flat.structure() != uniform.structure()  # the profiled code, with t = 1
    ref = sb.solve(uniform, delta=0.3, tol=1e-8, estimate_error=False)
    state = sb.solve(flat, delta=0.3, tol=1e-8, estimate_error=False)
    a = st.stability(ref, modes=range(8))
    b = st.stability(state, modes=range(8))
    assert a.elements == b.elements
    np.testing.assert_allclose(b.eigenvalues, a.eigenvalues, rtol=1e-8)


@pytest.mark.slow  # two stability derivations (~15 s); the uniform profile's eigenvalues stay in the default run
def test_the_profiled_form_is_the_uniform_ones_parts_scaled():
    """``form(..., thk, beta, p, ...) = thk A(0, 0) + thk^3 (A(beta, 0) - A(0, 0)) + A(0, p) - A(0, 0)``
    with ``A(beta, p)`` the uniform structure's generated form (linear in beta and p)."""
    pressure = dict(pressure=0.02)
    f, upper, params, shell_params, ref = form.form_functions(sb.Scene.preset("base", **pressure))
    fp, upper_p, params_p, shell_params_p, ref_p = form.form_functions(
        sb.Scene.preset("base", beta=None, thickness=THINNING, **pressure))
    assert upper_p == upper and params_p == params == ["beta", "pressure", "alpha"]
    assert shell_params_p == shell_params
    rng = np.random.default_rng(5)
    for n in (0, 1, 2, 7):
        base = list(rng.uniform(0.3, 1.5, 11))
        beta, p, alpha, thk = rng.uniform(0.05, 0.5, 4)

        def A(beta, p):
            return np.array(f(*base, beta, p, alpha, n), float)

        want = thk * A(0, 0) + thk**3 * (A(beta, 0) - A(0, 0)) + (A(0, p) - A(0, 0))
        got = np.array(fp(*base, thk, beta, p, alpha, n), float)
        assert np.max(np.abs(A(beta, 0) - A(0, 0))) > 1e-3 and np.max(np.abs(A(0, 0))) > 1e-3
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-12 * np.max(np.abs(want)))


@pytest.mark.parametrize("wall", [THINNING, ThicknessProfile.table([0.0, 0.5, L], [0.05, 0.04, 0.03])])
def test_the_generated_thickness_is_the_profiles(wall):
    scene = sb.Scene.preset("base", beta=None, thickness=wall)
    S = np.linspace(0.0, L, 13)
    got = form.wall_thickness(scene, S)
    np.testing.assert_allclose(got, wall.relative(S, L=L), rtol=1e-12)
    assert got.min() < 0.65
    assert form.wall_thickness(sb.Scene.preset("base"), S) is None


def test_energy_along_a_profiled_cap_branch(uniform, monkeypatch):
    """The wall thinning to half at the rim, delta 0.3 (cap): dF/ddelta 2.2255, the form on the
    tangent with the contact's terms 2.5e-5 off (the uniform wall's check: 2.4e-5); with t = 1 in
    the form 28 % off, with t^2 in place of t 20 %."""
    lo, mid, hi = neighbours(uniform.replace(thickness=THINNING), 0.3)
    assert mid.topology == "cap" and mid.valid
    dF, elastic, contact = branch_check(lo, mid, hi)
    assert abs(elastic + contact - dF) < 2e-4 * dF, (dF, elastic, contact)
    monkeypatch.setattr(form, "wall_thickness", lambda scene, S: np.ones_like(S))
    dF1, elastic1, contact1 = branch_check(lo, mid, hi)
    assert abs(elastic1 + contact1 - dF) > 0.2 * dF


def test_unstressed_profiled_wall_is_bracketed_by_uniform_walls(uniform):
    """Unstressed shells (inflated at p = 0), 60 elements each, n = 0..8, the two smallest
    eigenvalues of each mode: ``0.5 lambda_k(H 0.025) <= lambda_k(profile) <= lambda_k(H 0.05)``."""
    t_min = 0.5
    walls = {"thick": uniform, "profile": uniform.replace(thickness=THINNING),
             "thin": uniform.replace(thickness=0.05 * t_min)}
    lam = {}
    for name, scene in walls.items():
        state = sb.inflate(scene)
        assert state.success and np.max(np.abs(state.profile()["tau_s"])) < 1e-12
        lam[name] = st.stability(state, modes=range(9), elements=60).eigenvalues
    assert np.all(lam["thin"] > 0)
    assert np.all(lam["profile"] <= lam["thick"] * (1 + 1e-9))
    assert np.all(lam["profile"] >= t_min * lam["thin"] * (1 - 1e-9))
    # and strictly inside: the profile is neither wall
    assert np.all(lam["profile"][:, 0] < 0.99 * lam["thick"][:, 0])
    assert np.all(lam["profile"][:, 0] > 1.01 * t_min * lam["thin"][:, 0])
