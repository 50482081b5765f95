r"""A sticking tip, the other bound of the frictionless one (shellbvp.modal_stability, "Friction";
issue 44, open point 4).

* the sticking perturbations are a subspace of the frictionless ones: mode by mode every
  eigenvalue with sticking is at least the frictionless one, on a cap and on a line state;
* without contact the option changes nothing; with a point contact n = 1 holds the pole and its
  sliding term ``-F kappa_apex U^2/pi`` is gone, n = 0 and n >= 2 (which hold the pole already)
  are unchanged;
* the stuck region's kink (``u'`` may jump where the mode leaves it) converges on the graded mesh.

Where the sticking tip moves the first instability: benchmarks/stability_friction.py.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import shellbvp as sb
from shellbvp import modal_stability as st


@pytest.fixture(scope="module", params=[0.1, 0.3], ids=["line", "cap"])
def contact_state(request):
    state = sb.solve(sb.Scene.preset("base"), delta=request.param, estimate_error=False)
    assert state.success and state.valid and state.topology in ("line", "cap")
    return state


def test_sticking_eigenvalues_are_at_least_the_frictionless_ones(contact_state):
    modes = range(5)
    free = st.stability(contact_state, modes=modes, count=3)
    stuck = st.stability(contact_state, modes=modes, count=3, friction="sticking")
    # the eigensolver's tolerance (1e-12) is far below what the constraint adds
    assert np.all(stuck.eigenvalues >= free.eigenvalues * (1 - 1e-9)), (stuck.eigenvalues, free.eigenvalues)
    # n = 1 is the tip sliding sideways: holding it raises the eigenvalue (measured 1.10 -> 1.93 on
    # the line, 1.53 -> 2.51 on the cap)
    assert stuck.smallest[1] > 1.5 * free.smallest[1]


def test_sticking_converges_in_the_mesh():
    """The mode's u' may jump where it leaves the stuck cap; the graded mesh resolves it (measured:
    n = 0..4 within 5e-5 with twice the elements)."""
    state = sb.solve(sb.Scene.preset("base"), delta=0.3, estimate_error=False)
    ref = st.stability(state, modes=range(5), friction="sticking")
    fine = st.stability(state, modes=range(5), friction="sticking", elements=2 * ref.elements)
    assert np.allclose(fine.smallest, ref.smallest, rtol=1e-4)


def test_no_contact_is_unchanged():
    state = sb.inflate(sb.Scene(gamma=1, beta=1e-3, pressure=0.02))
    free = st.stability(state, modes=range(4), elements=20)
    stuck = st.stability(state, modes=range(4), elements=20, friction="sticking")
    # the same eigenproblem: equal up to the Lanczos iteration's own start (ARPACK's random vector)
    assert np.allclose(free.eigenvalues, stuck.eigenvalues, rtol=1e-10, atol=0)


def test_point_contact_sticking_holds_the_pole_without_its_sliding_term():
    """The dome preset's point contact: with sticking, n = 1 does not depend on the force the pole
    term carries (frictionless it does), n = 0 and n = 2 are the frictionless ones."""
    state = sb.solve(sb.Scene.preset("dome"), delta=0.01, estimate_error=False)
    assert state.success
    L = float(state.system.L)

    def n012(friction, force_factor):
        contact = st.contact_of(state, friction=friction)
        assert contact.pole_held and contact.pole_force > 0
        contact = dataclasses.replace(contact, pole_force=force_factor * contact.pole_force)
        return st.spectrum(state.scene, contact.base, contact.S0, L, range(3), contact=contact).smallest

    free = [n012("frictionless", k) for k in (0.0, 1.0, 10.0)]
    stuck = [n012("sticking", k) for k in (0.0, 1.0, 10.0)]
    assert free[0][1] > free[1][1] > free[2][1]  # the pole term lowers n = 1
    assert stuck[0][1] == stuck[1][1] == stuck[2][1]
    assert stuck[1][1] > free[0][1]  # holding U = 0 costs more than sliding without the term
    assert np.allclose(stuck[1][[0, 2]], free[1][[0, 2]], rtol=1e-12)


def test_an_unknown_friction_is_refused_in_one_line():
    state = sb.inflate(sb.Scene(gamma=1, beta=1e-3))
    with pytest.raises(ValueError, match="friction must be one of 'frictionless', 'sticking'") as err:
        st.stability(state, friction="coulomb")
    assert "\n" not in str(err.value)
