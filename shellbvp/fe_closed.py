"""Closed shells in the 3D reference (:mod:`shellbvp.fe`): the wall of a complete spheroid, no rim.

* Between plates (``support="plates"``, a flat plate or two identical tips) the solid is the
  half above the equator, as in the shell model: the equatorial face is the symmetry plane
  (``u_z = 0`` on all its nodes, free to move outwards), and the top plate or tip presses the
  outer surface.  Each plate moves by half the approach relative to the equator, so ``delta``
  (the approach of the mid-surface poles) is twice the top pole's displacement, and the
  indenter's approach twice the plate's.
* On a substrate (``support="substrate"``, any tip) the solid is the whole wall, from pole to
  pole, on a rigid frictionless plane (:class:`shellbvp.fe_contact.Plane`, a second penalty
  contact like the indenter's, fixed) under the tip.  ``delta`` is the approach of the two
  mid-surface poles; the indenter's approach is the tip's displacement (the substrate is fixed).
  The shell starts in touch with the substrate (its outer bottom pole on the plane); the one
  rigid motion the frictionless contacts leave free -- the axial translation, before the
  substrate carries a load -- is held by a soft axial spring on the outer bottom pole
  (:class:`AxialSpring`, stiffness ``SPRING`` eps^2 mu R_L, 1/200 of a thin sphere's own).  In
  contact that node sits about at the substrate's penetration (``~ pressure H / penalty``): the
  spring carries 1.3e-6 of the force (eps 0.1, delta 0.05), and as it pushes where the substrate
  does, the tip's force changes by less: 2e-9 with a spring ten times softer, 2.4e-7 with one
  a hundred times stiffer (``tests/test_fe_closed.py``).
* A shell whose halves differ (an egg, ``UserShell.closed_halves``) is the whole wall on a
  substrate and between plates alike (the same problem: the bottom plate is the fixed
  substrate, the top one moves by the whole approach): the upper half's meridian from its pole
  and the lower half's from its own, joined at the equator (:func:`mirrored`).

Points are ``(z, r)``, FElupe's axisymmetric order.  Nondimensional: mu = 1, R_L = 1 (the
equatorial radius).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix

from .fe_contact import PenaltyContact, Plane

__all__ = ["whole", "egg", "mirrored", "AxialSpring", "closed_boundary", "SPRING"]

#: The axial spring on a closed shell's outer bottom pole, in units of eps^2 mu R_L (a thin
#: sphere's stiffness between plates is ~2 eps^2 mu R_L).
SPRING = 0.01


def whole(scene) -> bool:
    """A closed shell solved as its whole wall (on a substrate, or one whose halves differ), not
    the half above the equator."""
    return bool(scene.closed and (scene.support == "substrate" or egg(scene)))


def egg(scene) -> bool:
    """A closed shell whose halves differ (``UserShell.closed_halves``): its lower half its own."""
    return getattr(scene.shell, "lower", None) is not None


def mirrored(upper, lower=None):
    """The whole wall's meridian table ``(s, R, Z, Phi, H, corners)`` from the upper half's and the
    lower half's (``lower``: its own table in its mirror image, as an upper half's; None: the upper
    half's), joined at the equator: the lower half continued from there to its pole (``z -> -z``,
    the normal's angle ``Phi -> -pi - Phi``, continuous at the equator, where both halves have
    ``R = 1``, ``Z = 0`` and a vertical tangent)."""
    s, R, Z, Phi, H, corners = upper
    sl, Rl, Zl, Phil, Hl, cl = upper if lower is None else lower
    total, low = s[-1], sl[-1]
    return (np.r_[s, total + low - sl[::-1][1:]], np.r_[R, Rl[::-1][1:]], np.r_[Z, -Zl[::-1][1:]],
            np.r_[Phi, -np.pi - Phil[::-1][1:]], np.r_[H, Hl[::-1][1:]], np.r_[corners, total + low - cl[::-1][1:]])


class AxialSpring:
    """Energy ``(k/2) u_z^2`` of one node: the interface of :class:`PenaltyContact` (``evaluate``
    returns the residual, its tangent, the spring's force and 0)."""

    def __init__(self, node, k, ndof):
        self.dof, self.k, self.ndof = 2 * int(node), float(k), int(ndof)

    def evaluate(self, u, with_matrix=True):
        r = np.zeros(self.ndof)
        f = self.k * float(np.asarray(u)[self.dof])
        r[self.dof] = f
        K = coo_matrix(([self.k], ([self.dof], [self.dof])), shape=(self.ndof, self.ndof)).tocsr() \
            if with_matrix else None
        return r, K, f, 0.0


def closed_boundary(scene, eps, points, node, n_t, ncol, field, *, penalty, gauss_points, band, equator=None):
    """A closed shell's conditions on the mesh ``node(i, j)`` (i through the thickness, j along
    the meridian from the upper pole, ``ncol`` columns; of the whole wall, ``equator`` the
    equator's column, the middle one by default).

    Returns ``(fixed, top, supports, delta_weights, approach)``: the held displacement dofs, the
    outer surface's nodes the tip presses (from the upper pole), the substrate's contact and
    spring (none between plates), delta's weights on the displacement dofs (``delta = pole0 -
    sum w u``) and the indenter's approach per displacement of the tip.
    """
    axis = np.flatnonzero(points[:, 1] == 0.0)
    outer = 2 * n_t
    if not whole(scene):  # the half above the equator: its face is the symmetry plane
        equator = np.array([node(i, ncol - 1) for i in range(2 * n_t + 1)])
        fixed = np.unique(np.concatenate([2 * axis + 1, 2 * equator]))
        top = np.array([node(outer, j) for j in range(ncol)])
        return fixed, top, [], {2 * node(n_t, 0): 2.0}, 2.0
    mid = (ncol - 1) // 2 if equator is None else int(equator)  # the equator's column
    top = np.array([node(outer, j) for j in range(mid + 1)])
    below = np.array([node(outer, j) for j in range(ncol - 1, mid - 1, -1)])  # from the lower pole
    ndof = int(np.sum(field.fieldsizes))
    substrate = PenaltyContact(Plane(+1), points, below, penalty / eps, gauss_points, field, band * eps)
    substrate.bind(points, apex=float(points[below[0], 0]))  # in touch at the lower pole
    spring = AxialSpring(below[0], SPRING * eps**2, ndof)
    weights = {2 * node(n_t, 0): 1.0, 2 * node(n_t, ncol - 1): -1.0}
    return 2 * axis + 1, top, [substrate, spring], weights, 1.0
