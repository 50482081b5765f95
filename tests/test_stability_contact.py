r"""Stability of states on the tip (shellbvp.modal_stability; issue 44, item 2).

* the energy along a branch: ``d^2E/d delta^2 = dF/d delta`` equals the n = 0 second variation
  of the Lagrangian on the branch tangent (at fixed material point S), with the tangent taken
  relative to the tip in the constraint's curvature terms (module docstring); on a cap state
  the pressure's and the ring force's terms, which fail with their sign reversed or without
  them; on a line state a consistency check (the ring's term is too small there to decide);
* the eigenvalues of cap and line states converge in the mesh and do not depend on where the
  mesh starts; for n = 1 that needs ``u' = v' = 0`` at the start (without it the eigenvalue
  follows the first element down);
* unsupported states are refused with one line that names what is not supported.

The dome's fold (n = 0) and where its n >= 2 eigenvalues cross zero:
benchmarks/stability_contact.py.  The branch tangent's check: tests/branch_tangent.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from branch_tangent import branch_check, neighbours

import shellbvp as sb
from shellbvp import modal_stability as st
from shellbvp.modal_stability import fem
from shellbvp.solution import Solution


def test_energy_along_a_cap_branch_fixes_the_contact_terms_sign():
    """Base scene at delta 0.6 (cap, Sc 0.14): dF/ddelta 3.6468; with the terms 3.6503
    (1e-3: the tangent's difference quotient, 3e-4 at h/4), reversed 3.895, without 3.772."""
    lo, mid, hi = neighbours(sb.Scene.preset("base"), 0.6)
    assert mid.topology == "cap" and mid.valid
    dF, elastic, contact = branch_check(lo, mid, hi)
    assert contact < -0.1  # the pressure's and the ring's terms are not small here
    assert abs(elastic + contact - dF) < 2e-3 * dF
    assert abs(elastic - contact - dF) > 0.05 * dF  # the opposite sign
    assert abs(elastic - dF) > 0.02 * dF  # without them


def test_energy_along_a_line_branch():
    """Base scene at delta 0.1: the pole lifted, a line contact at S1 0.0145 (curvature gap
    0.0018).  Only a consistency check: along the branch the line rolls with the shell
    (``w1 = gap (u0 + dsigma1/ddelta)``), which leaves the ring's term ``-f (kappa_T u0^2 - gap
    dsigma1^2)`` at about 1e-5 of dF/ddelta here: too small to tell its sign (the rolling
    term's sign rests on the derivation and the rigid-rotation check, module docstring)."""
    lo, mid, hi = neighbours(sb.Scene.preset("base"), 0.1, h=2.5e-4)
    assert mid.topology == "line" and mid.valid
    dF, elastic, contact = branch_check(lo, mid, hi)
    # measured: contact 3.9e-5 dF (2.1e-3 at h = 1e-3: the slope's extrapolation, 1/gap), the
    # sum 5e-5 dF off (the elastic term's difference quotient, O(h))
    assert abs(contact) < 1e-4 * dF
    assert abs(elastic + contact - dF) < 2e-4 * dF, (dF, elastic, contact)


# -- convergence --------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cap_state():
    state = sb.solve(sb.Scene.preset("base"), delta=0.3, estimate_error=False)
    assert state.topology == "cap" and state.valid
    return state


def test_cap_eigenvalues_converge_in_the_mesh_and_the_start(cap_state):
    state = cap_state
    modes = range(4)
    ref = st.stability(state, modes=modes)
    fine = st.stability(state, modes=modes, elements=2 * ref.elements)
    moved = st.stability(state, modes=modes, S0=1e-3)
    assert ref.stable and np.all(ref.smallest > 1)
    assert np.allclose(fine.smallest, ref.smallest, rtol=3e-4)
    assert np.allclose(moved.smallest, ref.smallest, rtol=3e-4)


def test_n1_needs_the_slopes_held_at_the_start(monkeypatch, cap_state):
    """Without ``u' = v' = 0`` at S0 the n = 1 eigenvalue of a cap state falls with the first
    element's length (a layer at S0 where the pole's bending prestress makes the ``u u''``
    terms large); with them it does not move."""
    state = cap_state
    contact = st.contact_of(state)
    plain = st.mesh

    def first_element(ratio):
        def mesh(S0, L, elements, edge=None):
            nodes = plain(S0, L, elements, edge)
            return np.unique(np.concatenate([[S0, S0 * ratio], nodes[nodes > S0 * ratio * 1.5]]))
        return mesh

    def n1(ratio, slopes_held=True):
        monkeypatch.setattr(fem, "mesh", first_element(ratio))
        if not slopes_held:
            full = fem.constraints

            def constraints(n, m, *args, **kwargs):
                T = full(n, m, *args, **kwargs)
                # release u'(S0), v'(S0): the columns of the reduced basis that carry them are absent,
                # so rebuild with the two dofs free
                return _release(T, (1, 3))
            monkeypatch.setattr(fem, "constraints", constraints)
        out = st.spectrum(state.scene, contact.base, contact.S0, float(state.system.L), [1], contact=contact)
        monkeypatch.undo()
        return out.smallest[0]

    held = [n1(r) for r in (2.0, 8.0, 32.0)]
    assert max(held) - min(held) < 1e-3 * abs(held[0])
    free = [n1(r, slopes_held=False) for r in (2.0, 32.0)]
    assert free[0] < 0 < free[1] and free[0] < -100 * abs(held[0])


def _release(T, dofs):
    """The reduced basis T with the given (held) dofs of node 0 free again (a unit column each)."""
    import scipy.sparse

    cols = [scipy.sparse.csr_matrix(([1.0], ([k], [0])), shape=(T.shape[0], 1)) for k in dofs]
    return scipy.sparse.hstack([T] + cols).tocsr()


def test_line_eigenvalues_converge():
    state = sb.solve(sb.Scene.preset("base"), delta=0.1, estimate_error=False)
    assert state.topology == "line" and len(st.contact_of(state).lines) == 1
    ref = st.stability(state, modes=range(4))
    fine = st.stability(state, modes=range(4), elements=2 * ref.elements)
    assert ref.stable
    assert np.allclose(fine.smallest, ref.smallest, rtol=3e-4)


def test_split_contact_eigenvalues_converge():
    """A cap and a line further out on the tip (the base curve's states at delta 0.1125 on the
    grid of tests/collocation_cases.py): both held, both rings; measured n = 0..4 at twice the
    elements within 5e-5."""
    curve = sb.curve(sb.Scene.preset("base"), deltas=np.linspace(0.0125, 0.5, 40)[:9], estimate_error=False)
    state = curve.solutions[-1]
    assert state.topology == "cap+line(tip)"
    contact = st.contact_of(state)
    assert len(contact.held) == 1 and len(contact.lines) == 1 and len(contact.rings) == 2
    ref = st.stability(state, modes=range(5))
    fine = st.stability(state, modes=range(5), elements=2 * ref.elements)
    assert ref.stable
    assert np.allclose(fine.smallest, ref.smallest, rtol=3e-4)


# -- refusals -----------------------------------------------------------------------------------
@pytest.mark.parametrize("state,match", [
    (Solution(success=True, status=0, topology="line+corner"), "topology 'line\\+corner' is not supported"),
    (Solution(success=True, status=0, topology="cap+cylinder"), "topology 'cap\\+cylinder' is not supported"),
    (Solution(success=True, status=0, topology="cap+cylinder"), "over the tip's end"),
    (Solution(success=True, status=0, topology="cap", scene=sb.Scene(contact="paper")), "contact='smooth'"),
])
def test_unsupported_states_are_refused_in_one_line(state, match):
    with pytest.raises(ValueError, match=match) as err:
        st.stability(state)
    assert "\n" not in str(err.value) and str(err.value).startswith("stability: ")


@pytest.mark.slow
def test_dome_n0_eigenvalue_changes_sign_at_its_fold():
    """The convex dome of tests/test_dome.py (rho 0.05, beta 1e-5) turns back in delta at
    0.18289: the n = 0 eigenvalue is positive along its curve and changes sign between two
    force-controlled states round the fold, within 1e-4 of it in delta
    (benchmarks/results/stability_contact.md: Brent in F puts the zero at 0.182894, the
    largest delta over F within 4e-11 of it)."""
    shell = sb.UserShell("5*sin(S/5)", "5*cos(S/5)", "5*asin(1/5)")
    scene = sb.Scene(rho=0.05, beta=1e-5, material=sb.MooneyRivlin(0.1), shell=shell)
    curve = sb.curve(scene, delta_max=0.25)
    assert "fold" in curve.stop_reason
    assert all(st.stability(s, modes=[0]).smallest[0] > 0 for s in curve.solutions)
    state, rows = curve.solutions[-1], []
    for F in np.linspace(state.force, 1.2e-4, 9)[1:]:
        state = sb.solve(scene, force=F, guess=state, estimate_error=False, tol=1e-8)
        assert state.success, state.message
        rows.append((state.delta, st.stability(state, modes=[0]).smallest[0]))
    k = next(i for i in range(1, len(rows)) if rows[i - 1][1] > 0 >= rows[i][1])
    assert all(lam > 0 for _, lam in rows[:k]) and all(lam < 0 for _, lam in rows[k:])
    assert abs(rows[k - 1][0] - 0.18289) < 1e-4 and abs(rows[k][0] - 0.18289) < 1e-4
