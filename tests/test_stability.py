r"""Stability of states without contact against Fourier modes (shellbvp.modal_stability; issue 44, item 2).

* the unstressed hemisphere with its rim held: every eigenvalue of n = 0..6 positive (the held
  rim leaves no rigid motion), converged in the mesh and in the pole start S0;
* the complete sphere (the hemisphere's symmetric and antisymmetric halves about its equator,
  membrane state): its rigid motions are null vectors at n = 0 and 1, and its eigenvalues
  depend on the degree of the spherical harmonic only, not on n (the classical degeneracy,
  which nothing in the derivation or the discretisation builds in: the pole is special in the
  coordinates);
* the sphere's smallest eigenvalue crosses zero at the classical pressure
  ``p_c = 4 sqrt(D Eh)/R^2 = 4 sqrt(3 beta)`` (Zoelly 1915; e.g. Hutchinson, Proc. R. Soc. A 472
  (2016) 20160577, eq. 2.2), within 3 % at beta 1e-6 (and 1e-4, where the finite strain of
  the base state shifts it by about 1 %);
* the hemisphere with its rim held buckles first in modes next to the rim, below p_c;
* the pinned shallow cap's n = 0 eigenvalue vanishes like a fold's where its inflation stops (slow:
  code is generated for its shell);
* a clamped rim (``Scene.rim``) holds the reference slope in the inflated state and ``w'`` in the
  modes; on the same base state (the unstressed shell) its eigenvalues are those of a subspace of
  the pinned rim's, so not below them, mode by mode.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import shellbvp as sb
from shellbvp import modal_stability as st
from shellbvp.solution import Solution


def classical(beta):
    return 4 * math.sqrt(3 * beta)


def test_unstressed_hemisphere_is_positive_definite_and_converged():
    scene = sb.Scene(gamma=1, beta=1e-3)
    state = sb.inflate(scene)
    coarse = st.stability(state, modes=range(7), elements=20)
    fine = st.stability(state, modes=range(7), elements=40)
    assert coarse.stable and fine.stable
    assert np.all(fine.eigenvalues > 0.5)  # no rigid motion left: the smallest is 0.865 (n = 1)
    assert np.allclose(fine.smallest, coarse.smallest, rtol=1e-4)
    moved = st.stability(state, modes=range(7), elements=40, S0=1e-3)
    assert np.allclose(moved.smallest, fine.smallest, rtol=2e-4)
    assert fine.critical_mode == 1
    assert fine.eigenvalues.shape == (7, 2) and np.all(np.diff(fine.eigenvalues, axis=1) >= 0)


def test_complete_sphere_rigid_motions_and_degeneracy():
    beta = 1e-3
    scene = sb.Scene(gamma=1, beta=beta, pressure=0.95 * classical(beta))
    base = st.sphere_base(st.sphere_stretch(scene))
    sym = st.spectrum(scene, base, 1.5e-4, math.pi / 2, modes=range(6), elements=40, end="symmetric", count=3)
    # (n = 0 and 1 checked here too: their normalisation and pole conditions; w = 0 instead of
    # w = S0 w' at S0 for n = 1 puts its values 9 % off)
    anti = st.spectrum(scene, base, 1.5e-4, math.pi / 2, modes=range(6), elements=40, end="antisymmetric",
                       count=3)
    scale = sym.eigenvalues[2:, 0].max()
    # rigid motions: rotation about z (n = 0, symmetric), translation along z (n = 0, anti),
    # translation along x (n = 1, sym), rotation about y (n = 1, anti)
    # (to the level of the rounding in the form's 1/r^3 coefficients at S0 = 1.5e-4: 1e-4 of the
    # scale measured, growing as S0 -> 0; the module docstring; the same floor below)
    for spec in (sym, anti):
        assert np.all(np.abs(spec.eigenvalues[:2, 0]) < 2e-4 * scale)
        assert np.all(spec.eigenvalues[:2, 1] > 0.1 * scale)
    # degree l: symmetric modes have l - n even, antisymmetric ones l - n odd; the lowest
    # eigenvalue (at l about (3/beta)^(1/4) = 7 near p_c) is shared by every n that reaches it with its parity
    floor = 2e-4 * scale
    assert sym.eigenvalues[2, 0] == pytest.approx(sym.eigenvalues[4, 0], abs=floor)
    assert sym.eigenvalues[2, 0] == pytest.approx(anti.eigenvalues[3, 0], abs=floor)
    assert anti.eigenvalues[2, 0] == pytest.approx(sym.eigenvalues[3, 0], abs=floor)
    assert anti.eigenvalues[2, 0] == pytest.approx(anti.eigenvalues[4, 0], abs=floor)
    assert abs(sym.eigenvalues[2, 0] - anti.eigenvalues[2, 0]) > 20 * floor  # even l and odd l differ
    # n = 0 and 1: the first non-rigid eigenvalue (the second) is the same degree's
    assert sym.eigenvalues[0, 1] == pytest.approx(sym.eigenvalues[2, 0], abs=floor)
    assert anti.eigenvalues[0, 1] == pytest.approx(anti.eigenvalues[2, 0], abs=floor)
    assert sym.eigenvalues[1, 1] == pytest.approx(sym.eigenvalues[3, 0], abs=floor)
    assert anti.eigenvalues[1, 1] == pytest.approx(anti.eigenvalues[3, 0], abs=floor)


def sphere_critical(beta, elements=None):
    """The pressure over p_c where the complete sphere's smallest eigenvalue crosses zero: the
    symmetric family at n = 2 and 3 holds every degree l >= 2 (l - n even), and the eigenvalues
    depend on l only (test above)."""
    def smallest(f):
        scene = sb.Scene(gamma=1, beta=beta, pressure=f * classical(beta))
        base = st.sphere_base(st.sphere_stretch(scene))
        return st.spectrum(scene, base, 1.5e-4, math.pi / 2, modes=[2, 3], elements=elements,
                           end="symmetric").minimum
    return brentq(smallest, 0.97, 1.05, xtol=1e-3)


def test_sphere_buckles_at_the_classical_pressure_beta_1e4():
    assert sphere_critical(1e-4) == pytest.approx(1.0, abs=0.03)


def test_sphere_buckles_at_the_classical_pressure_beta_1e6():
    f = sphere_critical(1e-6)
    assert f == pytest.approx(1.0, abs=0.03)
    assert sphere_critical(1e-6, elements=400) == pytest.approx(f, abs=2e-3)


def test_held_rim_hemisphere_buckles_below_the_classical_pressure_next_to_the_rim():
    beta = 1e-4
    below = st.stability(sb.inflate(sb.Scene(gamma=1, beta=beta, pressure=0.6 * classical(beta))))
    above = st.stability(sb.inflate(sb.Scene(gamma=1, beta=beta, pressure=0.8 * classical(beta))),
                         vectors=True)
    assert below.stable and not above.stable
    n = above.critical_mode
    assert n >= 2
    mode = above.vectors[n]
    peak = mode["S"][np.argmax(np.abs(mode["w"]))]
    assert math.pi / 2 - peak < 3 * (3 * beta) ** 0.25  # within a few bending lengths of the rim


def test_unsupported_states_are_refused():
    """States in contact: tests/test_stability_contact.py."""
    assert sb.stability is st.stability and sb.Stability is st.Stability
    with pytest.raises(ValueError, match="topology 'cap\\+cylinder' is not supported"):
        st.stability(Solution(success=True, status=0, topology="cap+cylinder"))
    with pytest.raises(ValueError, match="did not converge"):
        st.stability(Solution(success=False, topology="inflated", message="no"))


def test_clamped_rim_holds_the_reference_slope_and_takes_a_moment():
    scene = sb.Scene(gamma=0.5, beta=3e-3, pressure=-0.03)  # the bowl inflated from inside
    rims = {}
    for rim in ("pinned", "clamped"):
        state = sb.inflate(scene.replace(rim=rim))
        assert state.success, state.message
        rims[rim] = {k: v[-1] for k, v in state.profile().items()}
    L = scene.shell_length
    reference = float(scene.model().reference_shell(L, scene.parameters())["Phi"])
    assert reference == pytest.approx(math.pi / 2, abs=1e-14)  # the spheroid meets its rim vertically
    clamped, pinned = rims["clamped"], rims["pinned"]
    assert clamped["phi"] == pytest.approx(reference, abs=1e-9)
    assert abs(pinned["phi"] - reference) > 1e-3  # the pinned rim turns under this pressure
    for rim in (clamped, pinned):  # both hold the rim circle
        assert rim["r"] == pytest.approx(1.0, abs=1e-9) and abs(rim["z"]) < 1e-9
    assert abs(pinned["M_s"]) < 1e-9 < abs(clamped["M_s"])


def test_clamped_rim_holds_w_prime_and_stiffens_the_same_base_state():
    scene = sb.Scene(gamma=1, beta=1e-3)  # no pressure: both rims hold the unstressed shell
    modes = range(5)
    out = {rim: st.stability(sb.inflate(scene.replace(rim=rim)), modes=modes, elements=30, vectors=True)
           for rim in ("pinned", "clamped")}
    for n in modes:
        clamped, pinned = out["clamped"].vectors[n], out["pinned"].vectors[n]
        assert clamped["w"][-1] == 0 and clamped["dw"][-1] == 0
        assert abs(pinned["dw"][-1]) > 1e-3 * np.abs(pinned["dw"]).max()  # free: the wiring decides
    assert np.all(out["clamped"].eigenvalues[:, 0] >= out["pinned"].eigenvalues[:, 0] * (1 - 1e-12))
    assert np.any(out["clamped"].eigenvalues[:, 0] > out["pinned"].eigenvalues[:, 0] * 1.001)


def test_rim_is_validated_and_clamped_is_refused_in_contact():
    with pytest.raises(ValueError, match=r"^rim must be one of \('pinned', 'clamped'\); got 'fixed'$"):
        sb.Scene(rim="fixed")
    scene = sb.Scene.preset("base", rim="clamped")
    assert scene.structure() == sb.Scene.preset("base").structure()  # the generated code is shared
    assert "rim" not in sb.Scene.preset("base").to_dict()            # files of pinned scenes as before
    assert sb.Scene.from_dict(scene.to_dict()) == scene
    with pytest.raises(ValueError, match=r"rim='clamped' is offered for the shell under pressure before contact"):
        sb.solve(scene, delta=0.1)
    pytest.importorskip("felupe", reason="the 3D reference needs FElupe ('.[fe]')")
    clamped = sb.fe_curve(scene.replace(material=sb.NeoHookean()), thickness=0.1, deltas=[0.05])  # the face held
    hinged = sb.fe_curve(sb.Scene.preset("base", material=sb.NeoHookean()), thickness=0.1, deltas=[0.05])
    assert clamped.success and hinged.success and clamped.force[0] > hinged.force[0]


@pytest.mark.slow
def test_pinned_shallow_cap_n0_eigenvalue_vanishes_at_the_inflation_fold():
    """A spherical cap of radius 5 over the rim radius 1, beta 1e-5: the axisymmetric continuation
    stops at 0.850 p_c (benchmarks/results/stability_pressure.md); the n = 0 eigenvalue goes to 0
    there like the square root of the distance (a fold), and is positive before."""
    beta = 1e-5
    shell = sb.UserShell("5*sin(S/5)", "-5*cos(S/5)", "5*asin(1/5)")
    pc = classical(beta) / 25
    lam = {}
    for d in (1e-2, 1e-3):
        state = sb.inflate(sb.Scene(shell=shell, beta=beta, pressure=0.85 * (1 - d) * pc))
        lam[d] = st.stability(state, modes=[0]).smallest[0]
    assert lam[1e-3] > 0
    assert lam[1e-2] / lam[1e-3] == pytest.approx(math.sqrt(10), rel=0.15)


def test_the_generated_form_is_the_derived_one():
    """The form the eigenproblem evaluates (generated code in the code cache) against SymPy's
    own evaluation of the derived matrix, at random base states and modes."""
    import json

    from symbolic import second_variation as sv
    from symbolic.build import structure_from_description
    from symbolic.geometry import S as S_SYM

    scene = sb.Scene.preset("base")
    f, upper, params, shell_params, ref = st.form_functions(scene)
    structure = structure_from_description(json.loads(json.dumps(scene.structure(), sort_keys=True)))
    res = sv.second_variation_of(structure)
    assert [str(p) for p in res.params] == params
    rng = np.random.default_rng(3)
    args = sv.BASE + res.params + (sv.N_MODE,)
    for n in (0, 1, 5):
        values = [*rng.uniform(0.3, 1.5, len(sv.BASE)), *rng.uniform(0.05, 0.5, len(res.params)), n]
        got = f(*values)
        subs = dict(zip(args, values))
        for (i, j), g in zip(upper, got):
            want = float(res.matrix[i, j].subs(subs).evalf(30))
            assert float(g) == pytest.approx(want, rel=1e-11, abs=1e-12 * (1 + abs(want)))
    S = np.array([0.2, 0.7])
    R, Psi, dPsi, ks0, kt0 = (np.broadcast_to(v, S.shape) for v in ref(S, *[scene.values()[p] for p in shell_params]))
    shell = structure.shell
    for k, expr in enumerate((shell.R, shell.Psi)):
        want = [float(expr.subs({S_SYM: s, **{q: scene.values()[str(q)] for q in shell.params}})) for s in S]
        np.testing.assert_allclose((R, Psi)[k], want, rtol=1e-12)
