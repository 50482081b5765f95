r"""Stability of a closed shell on a substrate under a curved tip (shellbvp.modal_stability.closed;
issue 55): both halves' modes tied at the equator.

* the energy along a branch: ``d^2E/d delta^2 = dF/d delta`` equals the n = 0 second variation
  summed over both halves on the branch tangent (each half in its own frame, the lower in its
  mirror image), and that tangent meets the seam's ties (:data:`SEAM_SIGNS`) -- the assembled
  stiffness (both halves' K with their rings) gives the same number;
* two mirror images of one half tied at the seam give the halved shell's symmetric and
  antisymmetric spectra (the plates' state, the ties' signs);
* the eigenvalues converge in the mesh; n = 1 is the shell slipping out sideways (negative, near
  the rigid ball's ``-F/(R + rho)`` per squared displacement over the sphere's area).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from branch_tangent import closed_offset, elastic, tangent

import shellbvp as sb
from shellbvp import modal_stability as st
from shellbvp.modal_stability import fem
from shellbvp.modal_stability.closed import SEAM_SIGNS, spectrum_closed


def on_substrate(beta=1e-2, rho=0.5, **kw):
    return sb.Scene(closed=True, tip=sb.SphereTip(), rho=rho, gamma=1.0, beta=beta, **kw)


@pytest.fixture(scope="module")
def branch():
    """A closed-line-cap state at delta 0.2 and its neighbours 2.5e-4 apart."""
    scene = on_substrate()
    mid = sb.solve(scene, delta=0.2, tol=1e-8, estimate_error=False)
    lo, hi = (sb.solve(scene, delta=0.2 + s * 1.25e-4, guess=mid, tol=1e-8, estimate_error=False) for s in (-1, 1))
    assert all(s.success and s.valid and s.topology == "closed-line-cap" for s in (lo, mid, hi))
    return lo, mid, hi


def _halves(state):
    seam = next(j for j in state.system.junctions if isinstance(j, sb.chain.Seam))
    return [list(range(seam.ku + 1)), list(range(seam.ku + 1, len(state.system.regions)))]


def _tangent(lo, mid, hi, regions, S, lift):
    """zeta of the branch tangent relative to the tip, ``x' + lift e_z`` in the half's frame (the tip
    moves down: lift +1 above, -1 in the mirror image); tests/branch_tangent.py."""
    return tangent(lo, mid, hi, S, regions, lift, closed_offset)


def _elastic(lo, mid, hi, regions, lift):
    """``8 pi Int zeta^T A_0 zeta dS`` of a half on the tangent (A_0 without the contact terms)."""
    return elastic(lo, mid, hi, regions, lift, z_offset=closed_offset)


def test_energy_along_the_branch_is_both_halves_n0_form(branch):
    """delta 0.2, the upper pole lifted (a ring on the tip at S1 0.014), a cap on the plane
    (Sb 0.11): dF/ddelta 0.45117, the two halves' elastic second variation on the tangent
    0.27425 + 0.17688, 1e-4 below it (the tangent's difference quotient).  The contact terms: none on the flat plane (kappa 0, sin(phi) 0 there),
    the ring's sliding term on the tip -f kappa u0^2, 5e-5 of dF here (a line rolls with the shell
    along its branch, test_stability_contact)."""
    lo, mid, hi = branch
    upper, lower = _halves(mid)
    dF = (hi.force - lo.force) / (hi.delta - lo.delta)
    eu, el = _elastic(lo, mid, hi, upper, 1.0), _elastic(lo, mid, hi, lower, -1.0)
    assert min(eu, el) > 0.2 * dF  # both halves carry the energy
    u_ring, _ = st.halves_of(mid)
    (S1, (uu, _, _, _)), = u_ring.rings
    zeta, _, _, _ = _tangent(lo, mid, hi, upper, np.array([S1]), 1.0)
    ring = 2 * math.pi * uu * float(zeta[0, 0]) ** 2
    assert abs(ring) < 1e-3 * dF
    assert abs(eu + el + ring - dF) < 1e-3 * dF, (dF, eu, el, ring)
    assert abs(eu - dF) > 0.2 * dF and abs(el - dF) > 0.2 * dF


@pytest.mark.slow  # a pressurised structure on a substrate: its own derivation
def test_energy_along_the_branch_under_pressure():
    """The same with pressure 0.1 (the pressure's terms of both halves: each half's volume closed
    across the equator, which the halves share): dF/ddelta 0.53200, the two halves' form 0.31992
    + 0.21203, 9e-5 below it; the assembled stiffness 3e-5 above."""
    scene = on_substrate(pressure=0.1)
    mid = sb.solve(scene, delta=0.2, tol=1e-8, estimate_error=False)
    lo, hi = (sb.solve(scene, delta=0.2 + s * 1.25e-4, guess=mid, tol=1e-8, estimate_error=False) for s in (-1, 1))
    assert all(s.success and s.valid and s.topology == "closed-line-cap" for s in (lo, mid, hi))
    upper, lower = _halves(mid)
    dF = (hi.force - lo.force) / (hi.delta - lo.delta)
    form = _elastic(lo, mid, hi, upper, 1.0) + _elastic(lo, mid, hi, lower, -1.0)
    assert abs(form - dF) < 3e-4 * dF
    total = _assembled_on_tangent(lo, mid, hi)
    assert total == pytest.approx(dF, rel=1e-3)
    assert st.stability(mid).stable


def test_the_branch_tangent_meets_the_seams_ties(branch):
    """The physical tangent (the same vector field, x' + e_z above, its mirror image below) at
    the equator in each half's frame: (u, u', w, w') tied by SEAM_SIGNS, each not small
    (measured: u -0.608, u' -0.0845, w 0.0455, w' -0.601; the ties hold to 1e-8)."""
    lo, mid, hi = branch
    L = np.array([float(mid.system.L)])
    zu, _, _, _ = _tangent(lo, mid, hi, _halves(mid)[0], L, 1.0)
    zl, _, _, _ = _tangent(lo, mid, hi, _halves(mid)[1], L, -1.0)
    for k, i in ((0, 0), (1, 1), (4, 6), (5, 7)):  # u, u', w, w' (dofs) in zeta's rows
        assert abs(zu[i, 0]) > 0.04
        assert zl[i, 0] == pytest.approx(SEAM_SIGNS[k] * zu[i, 0], rel=1e-5)


def _hermite_dofs(lo, mid, hi, regions, nodes, lift):
    """The tangent's (u, u', v, v', w, w') at the nodes, derivatives times the largest element."""
    zeta, _, _, _ = _tangent(lo, mid, hi, regions, nodes, lift)
    hs = np.diff(nodes).max()
    q = np.zeros((nodes.size, 6))
    q[:, 0], q[:, 1], q[:, 4], q[:, 5] = zeta[0], zeta[1] * hs, zeta[6], zeta[7] * hs
    return q.ravel()


def _assembled_on_tangent(lo, mid, hi):
    """Both halves' ``2 pi q^T K q`` on the branch tangent (twice the default elements)."""
    total = 0.0
    for regions, contact, lift in zip(_halves(mid), st.halves_of(mid), (1.0, -1.0)):
        nodes = fem.mesh(contact.S0, float(mid.system.L), 2 * fem.default_elements(mid.scene), contact.edges)
        K, _ = fem.stiffness(mid.scene, contact.base, 0, nodes, contact)
        q = _hermite_dofs(lo, mid, hi, regions, nodes, lift)
        total += 2 * math.pi * float(q @ (K @ q))
    return total


def test_the_assembled_stiffness_on_the_tangent_is_dF(branch):
    """Both halves' K (4 times the form, with the rings) on the tangent interpolated by the cubic
    Hermite elements of the default mesh (twice the elements): ``2 pi q^T K q`` within 1e-3 of
    dF/ddelta (measured 1.7e-4)."""
    lo, mid, hi = branch
    total = _assembled_on_tangent(lo, mid, hi)
    dF = (hi.force - lo.force) / (hi.delta - lo.delta)
    assert total == pytest.approx(dF, rel=1e-3)


def test_two_mirror_images_of_a_half_give_the_halved_spectra():
    """The plates' state (halved): its half and its mirror image tied at the seam have the
    halved spectra with the equator conditions symmetric and antisymmetric (three eigenvalues of
    n = 0, 2, 3, 5).  The ties also impose v' = 0 and u' = 0 there (natural conditions of the
    halved problem), so the tied eigenvalues lie above: by 1e-13 to 7e-9 (measured)."""
    s = sb.solve(sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=1e-3), delta=0.1,
                 estimate_error=False)
    assert s.success and s.valid and s.scene.halved
    modes = [0, 2, 3, 5]
    halved = st.stability(s, modes=modes, count=3, elements=40)
    contact = st.contact_of(s)
    tied = spectrum_closed(s.scene, (contact, contact), float(s.system.L), modes, elements=40, count=3)
    excess = tied.eigenvalues / halved.eigenvalues - 1
    assert np.all(excess > -1e-10) and np.all(excess < 1e-6), excess


def test_eigenvalues_converge_and_n1_slips_and_rolls(branch):
    """n = 0, 2, 3, 5 within 1e-4 with twice the elements.  n = 1: the shell slipping out
    sideways, negative, within 15 % of a rigid ball's -F/(R + rho)/(4 pi) (-0.00587 against
    -0.00552; R = 1 the sphere's radius, rho the tip's), and the shell rolling in place (its
    material turned through the unchanged deformed shape, a symmetry of the sphere) at zero (5e-7
    on the refined mesh); both held with friction="sticking"."""
    _, mid, _ = branch
    modes = [0, 2, 3, 5]
    ref = st.stability(mid, modes=modes)
    fine = st.stability(mid, modes=modes, elements=2 * ref.elements)
    assert np.allclose(fine.smallest, ref.smallest, rtol=1e-4)
    assert np.all(ref.smallest > 0.1)
    slip = st.stability(mid, modes=[1])
    rigid = -mid.force / (1 + mid.scene.rho) / (4 * math.pi)
    assert slip.eigenvalues[0, 0] == pytest.approx(rigid, rel=0.15)
    assert abs(slip.eigenvalues[0, 1]) < 1e-5
    assert st.stability(mid, modes=[1], friction="sticking").minimum > 0.1
    default = st.stability(mid, elements=40, vectors=True)
    assert 1 not in default.modes and 0 in default.modes and default.stable
    v = default.vectors[2]  # pole to pole: S from the upper pole through the equator (L) to 2 L - S0
    L = float(mid.system.L)
    assert np.all(np.diff(v["S"]) > 0) and v["S"][0] < 1e-3 and v["S"][-1] > 2 * L - 1e-3
    assert all(v[k].shape == v["S"].shape for k in ("u", "v", "w", "dw"))


def test_contact_of_a_shell_on_a_substrate_names_halves_of(branch):
    _, mid, _ = branch
    with pytest.raises(ValueError, match="halves_of"):
        st.contact_of(mid)


def test_a_closed_shells_crossing_is_narrowed_without_n1(monkeypatch):
    """Locating the first instability along a curve asks the modes near those found: of a closed
    shell never n = 1 (on a substrate under a curved tip negative at every depth: the narrowing
    would find its own bracket's end; between plates zero).  Measured before: the thin sphere on a
    substrate under rho 0.3 was reported unstable at delta 0.325 in n = 1 (n = 3 from 0.36)."""
    from types import SimpleNamespace

    from shellbvp import curve_stability as cs

    asked = []
    state = SimpleNamespace(success=True, topology="closed-cap-cap", force=1.0)
    monkeypatch.setattr(cs, "solve", lambda scene, delta, **kw: SimpleNamespace(**vars(state), delta=delta))

    def point(s, modes=None):
        asked.append(None if modes is None else [int(n) for n in modes])
        return 0.2 - s.delta if hasattr(s, "delta") else 0.1, 2, ""

    monkeypatch.setattr(cs, "point_stability", point)
    for scene in (on_substrate(), sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=1e-2)):
        curve = SimpleNamespace(solutions=[state, state], points={"delta": np.array([0.1, 0.3]),
                                "force": np.array([1.0, 2.0])}, settings={"tol": 1e-6, "max_nodes": 1000}, scene=scene)
        found = cs._narrowed(curve, 0, 1, np.array([0.1, -0.1]), np.array([0, 2]), 1e-3)
        assert found.located and found.delta == pytest.approx(0.2, abs=1e-3)
    chosen = [m for m in asked if m is not None]
    assert chosen and all(0 in m and 2 in m and 4 in m and 1 not in m for m in chosen)
    assert 1 in st.checked_modes(sb.Scene.preset("base")) and 1 not in st.checked_modes(on_substrate())


def test_the_mesh_starts_at_s0_with_a_contact_edge_next_to_the_pole():
    """A ring on the tip closer to the pole than half an element (the lifted pole of the state
    above: S1 0.0137, h 0.039): the mesh still starts at S0, where the pole's conditions are
    imposed, graded towards it (the edge's nodes used to take S0's place: the mesh started at
    0.0039), and without an edge near the pole the mesh is as it was."""
    S0, L = 1.57e-4, math.pi / 2
    nodes = fem.mesh(S0, L, 40, (0.0137,))
    assert nodes[0] == S0 and 0.0137 in nodes
    first = np.diff(nodes[:3])
    assert nodes[1] < 0.002 and first[1] > 2 * first[0]  # graded towards S0
    h = (L - S0) / 40
    plain = fem.mesh(S0, L, 40, (0.5,))
    assert plain[0] == S0 and plain[1] == pytest.approx(S0 + h / 16) and plain[2] == pytest.approx(S0 + h / 4)
