r"""The eigenproblem of a closed shell on a substrate under a curved tip (``scene.two_contacts``,
issue 55): both halves' modes, pole to pole, as one problem.

The state is solved as two halves, each from its own pole to the equator, the lower one in the
mirror image z -> -z (:mod:`shellbvp.configurations.closed`).  Each half's form, contact
conditions and pole conditions are those of a shell on its indenter
(:mod:`shellbvp.modal_stability`): the upper half on the tip, the lower on the plane, each a
:class:`~.contact.Contact` (:func:`~.contact.halves_of`).  The plane is flat: its curvature
terms vanish (``kappa_s = 0`` and ``sin(phi) = 0`` on it), so on it the shell is held normally
(``w = w' = 0`` on a cap, ``w = 0`` at a ring) and slides freely.

*The seam.*  Each half's fields are in its own frame: ``u`` along its meridian away from its
pole, ``v`` along ``e_theta``, ``w`` along the outward normal, S from its pole.  At the equator
the two frames share ``e_theta`` and the normal and their tangents are opposite, and S runs the
other way: the displacement and its derivative along the meridian are continuous where

.. math:: u_l = -u_u,\ u_l' = u_u',\quad v_l = v_u,\ v_l' = -v_u',\quad w_l = w_u,\ w_l' = -w_u'

(the state itself is smooth there: the chain's seam holds r, z, the slope, lambda_s, kappa_s and
the shear continuous).  The lower half's equator dofs are given by the upper's.  For two mirror
images of one half these ties split the modes into those symmetric (``u = v' = w' = 0`` at the
equator) and antisymmetric (``v = w = u' = 0``) about it: the halved shell's two end conditions,
with the natural conditions ``v' = 0``, ``u' = 0`` imposed (tests/test_stability_closed.py).

*Rigid motions.*  At n = 0 the spin about the axis costs nothing on frictionless contacts: the
equator's ``v`` is held (with ``friction="sticking"``, which sticks both halves to their
indenters, the contacts hold it).  The vertical translation is held by both contacts.  At n = 1
two modes are the frictionless model's, not buckling:

* the slip: moved sideways, the shell's upper contact leaves the tip's apex and the squeezed
  shell slips out from under a curved tip on a frictionless plane (a rigid ball of radius R
  between a ball of radius rho and a plane loses ``F X^2/(2(R + rho))`` of energy when moved
  sideways by X): negative at every depth (measured: within 6 % of the rigid ball's
  ``-F/(R + rho)/(4 pi)`` at beta 0.01, delta 0.2; on a thin sphere 0.7 % at delta 0.018, 45 %
  more negative at 0.6 as it flattens; benchmarks/results/stability_contact.md);
* the roll: the sphere's material turned about a horizontal axis through its centre, the
  deformed shape unchanged (the reference sphere's symmetry), at zero (5e-7, falling with the
  mesh like h^2).

Sticking holds both (n = 1 positive).  :func:`shellbvp.stability` leaves n = 1 out by default
(:func:`.fem.checked_modes`), as between plates, and reports n = 0 and n >= 2 (the polygonal
modes); ``modes=[1]`` computes it.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse

from .fem import (Stability, constraints, default_elements, default_modes, held_nodes, mesh, smallest_pairs,
                  stiffness)

#: The lower half's equator dofs (u, u', v, v', w, w') as the upper's times these (the
#: derivative dofs also times the ratio of the halves' derivative scales).
SEAM_SIGNS = (-1.0, 1.0, 1.0, -1.0, 1.0, -1.0)


def _half(contact, L, elements):
    """The mesh and held nodes of one half (``contact``: its :class:`~.contact.Contact`)."""
    nodes = mesh(contact.S0, L, elements, contact.edges)
    held = held_nodes(nodes, contact.held)
    lines = tuple(int(np.flatnonzero(nodes == S)[0]) for S in contact.lines)
    stuck, points = (), ()
    if contact.friction == "sticking":
        stuck, points = held, lines + ((0,) if contact.pole_held else ())
    return dict(nodes=nodes, hs=float(np.diff(nodes).max()), held=held, lines=lines, stuck=stuck, stuck_points=points)


def _seam(Tu, Tl, mu, ml, ratio, hold_spin):
    """The matrix that ties the lower half's equator dofs to the upper's (:data:`SEAM_SIGNS`):
    ``(qu_free, ql_free) = T2 q``; ``hold_spin`` also holds the equator's v (n = 0)."""
    fu, fl = Tu.shape[1], Tl.shape[1]

    def column(T, dof):
        row = T.getrow(dof)
        if row.nnz != 1 or row.data[0] != 1.0:
            raise RuntimeError(f"the seam's dof {dof} is not free")
        return int(row.indices[0])

    up = [column(Tu, 6 * (mu - 1) + k) for k in range(6)]
    low = [fu + column(Tl, 6 * (ml - 1) + k) for k in range(6)]
    drop = set(low) | ({up[2]} if hold_spin else set())
    # the lower half's columns from its equator to its pole: pole to pole, so that K stays banded
    keep = [i for i in range(fu) if i not in drop] + [i for i in range(fu + fl - 1, fu - 1, -1) if i not in drop]
    index = {i: c for c, i in enumerate(keep)}
    rows, cols, vals = list(keep), list(range(len(keep))), [1.0] * len(keep)
    for k, (a, b) in enumerate(zip(up, low)):
        if a in index:
            rows.append(b)
            cols.append(index[a])
            vals.append(SEAM_SIGNS[k] * (ratio if k % 2 else 1.0))
    return scipy.sparse.csr_matrix((vals, (rows, cols)), shape=(fu + fl, len(keep)))


def spectrum_closed(scene, contacts, L, modes=None, *, elements=None, count=2, vectors=False):
    """The smallest eigenvalues per mode of a closed shell's two halves tied at the seam
    (``contacts``: upper and lower :class:`~.contact.Contact`, each on [S0, L] from its pole).
    The eigenvectors (``vectors``) are given pole to pole: ``S`` the reference arclength from the
    upper pole (``2 L - S`` on the lower half), ``u`` along the upper half's tangent, ``dw`` the
    derivative along that S."""
    t0 = time.perf_counter()
    ne = elements or default_elements(scene)
    halves = [_half(c, L, ne) for c in contacts]
    modes = default_modes(scene) if modes is None else np.asarray(sorted(set(int(n) for n in modes)))
    frictionless = all(c.friction == "frictionless" for c in contacts)
    out = np.empty((modes.size, count))
    vecs = {}
    for k, n in enumerate(modes):
        Ks, Ms, Ts = [], [], []
        for c, h in zip(contacts, halves):
            K, M = stiffness(scene, c.base, int(n), h["nodes"], c)
            Ts.append(constraints(int(n), h["nodes"].size, "seam", h["nodes"][0] / h["hs"], h["held"], c.pole_held,
                                   h["lines"], stuck=h["stuck"], stuck_points=h["stuck_points"]))
            Ks.append(K)
            Ms.append(M)
        (hu, hl) = halves
        T2 = _seam(*Ts, hu["nodes"].size, hl["nodes"].size, hl["hs"] / hu["hs"], int(n) == 0 and frictionless)
        T = (scipy.sparse.block_diag(Ts) @ T2).tocsr()
        K, M = scipy.sparse.block_diag(Ks).tocsr(), scipy.sparse.block_diag(Ms).tocsr()
        Kr, Mr = (T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr()
        Kr = ((Kr + Kr.T) / 2).tocsr()
        lam, X = smallest_pairs(Kr, Mr, count)
        out[k] = lam
        if vectors:
            vecs[int(n)] = _pole_to_pole(T @ X[:, 0], halves, L)
    return Stability(modes=modes, eigenvalues=out, elements=ne, S0=max(c.S0 for c in contacts), vectors=vecs,
                     wall_time=time.perf_counter() - t0)


def _pole_to_pole(q, halves, L):
    """An eigenvector's fields along the whole meridian from the upper pole (the lower half's
    equator node, the upper's twin, left out)."""
    hu, hl = halves
    qu = q[:6 * hu["nodes"].size].reshape(-1, 6)
    ql = q[6 * hu["nodes"].size:].reshape(-1, 6)[::-1][1:]
    return {"S": np.concatenate([hu["nodes"], 2 * L - hl["nodes"][::-1][1:]]),
            "u": np.concatenate([qu[:, 0], -ql[:, 0]]), "v": np.concatenate([qu[:, 2], ql[:, 2]]),
            "w": np.concatenate([qu[:, 4], ql[:, 4]]),
            "dw": np.concatenate([qu[:, 5] / hu["hs"], -ql[:, 5] / hl["hs"]])}
