"""The rim of the 3D reference (:mod:`shellbvp.fe`): the shell model's simple support as a
condition on the solid's rim face.

The shell model holds its rim at the mid-surface (``r = 1``, ``z = 0``) and lets it turn
(``M_s = 0``).  On a solid, pinning one mid-thickness node is a ring constraint whose
compliance grows without bound as the mesh is refined (measured: -0.8 % at the default mesh,
-3 to -5 % at fine ones on the paper's seed); the rim face held plane and free to turn about
its mid-thickness point converges (:class:`HingedFace`).

A hinged face is a nonlinear constraint: its nodes stay on a straight line (in the meridian
plane: a cone in 3D) through the fixed mid-thickness point, at an angle ``theta`` shared by
all of them and at distances ``s_k`` of their own (the face may stretch and thin along itself).
Newton runs in those coordinates: ``u_k = X_m + s_k e(theta) - X_k`` with ``e(theta)`` the
face's reference direction turned by theta, so the reduced tangent is ``J^T K J + G`` with the
second derivatives of the map in ``G``.

Points are ``(z, r)``, FElupe's axisymmetric order.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

__all__ = ["HingedFace", "RIM_FACES"]

#: How the rim face is held: ``"plane"`` (plane, turning about its mid-thickness point: the
#: simple support that converges) or ``"point"`` (only the mid-thickness node pinned: the
#: earlier model, kept to compare with it and with SPEC section 8's reference).
RIM_FACES = ("plane", "point")


def _turned(e0, theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([c * e0[0] - s * e0[1], s * e0[0] + c * e0[1]])


class HingedFace:
    """The rim face's nodes on a line through its fixed mid-thickness node, turning freely.

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        Reference node positions (z, r).
    face : ndarray of int
        The rim face's nodes, the mid-thickness node among them.
    mid : int
        The mid-thickness node (held fixed by the caller).
    """

    def __init__(self, points, face, mid):
        self.nodes = np.array([k for k in face if k != mid], dtype=int)
        self.X = points[self.nodes]
        self.Xm = points[mid]
        D = self.X - self.Xm
        far = np.argmax(np.hypot(D[:, 0], D[:, 1]))
        self.e0 = D[far] / np.hypot(*D[far])
        if np.max(np.abs(D[:, 0] * self.e0[1] - D[:, 1] * self.e0[0])) > 1e-9 * np.hypot(*D[far]):
            raise ValueError("the rim face's nodes are not on a straight line")  # a mesh error, not user input
        self.dofs = (2 * self.nodes[:, None] + np.arange(2)[None, :]).ravel()

    def coordinates(self, u):
        """``(s, theta)`` of the face in the displacement ``u`` (node-major, (z, r) per node): the
        line through the mid node closest to the face's nodes (their principal direction)."""
        y = self.X + u.reshape(-1, 2)[self.nodes] - self.Xm
        e = np.linalg.svd(y, full_matrices=False)[2][0]
        if e @ self.e0 < 0:
            e = -e
        theta = float(np.arctan2(self.e0[0] * e[1] - self.e0[1] * e[0], self.e0 @ e))
        return y @ e, theta

    def displacement(self, s, theta):
        """The face nodes' displacements, shape (m, 2), at coordinates ``(s, theta)``."""
        return self.Xm + s[:, None] * _turned(self.e0, theta)[None, :] - self.X

    def project(self, values):
        """Put the face of the displacement array ``values`` (shape (n, 2)) on its line."""
        s, theta = self.coordinates(values.ravel())
        values[self.nodes] = self.displacement(s, theta)

    def residual(self, r, u):
        """The residual's components along the face's coordinates ``(s..., theta)``."""
        s, theta = self.coordinates(u)
        e = _turned(self.e0, theta)
        rf = r[self.dofs].reshape(-1, 2)
        return np.r_[rf @ e, np.sum(s * (rf @ np.array([-e[1], e[0]])))]

    def reduce(self, r, K, free, u):
        """The Newton system in the reduced unknowns ``(free dofs, s, theta)``.

        Returns ``(Kq, rq, J)`` with ``J`` the map's Jacobian (full dofs by reduced unknowns):
        the full step of a reduced step ``dq`` is ``J @ dq`` to first order.
        """
        s, theta = self.coordinates(u)
        e = _turned(self.e0, theta)
        de = np.array([-e[1], e[0]])
        m, nf, ndof = self.nodes.size, free.size, r.size
        rows = np.r_[free, self.dofs, self.dofs]
        cols = np.r_[np.arange(nf), np.repeat(nf + np.arange(m), 2), np.full(2 * m, nf + m)]
        vals = np.r_[np.ones(nf), np.tile(e, m), (s[:, None] * de[None, :]).ravel()]
        J = sparse.csc_matrix((vals, (rows, cols)), shape=(ndof, nf + m + 1))
        rf = r[self.dofs].reshape(-1, 2)
        coupling = rf @ de                                  # d2u/(ds dtheta) = e'
        face = nf + np.arange(m)
        G = sparse.csc_matrix((np.r_[coupling, coupling, -float(np.sum(s * (rf @ e)))],   # d2u/dtheta2 = -s e
                               (np.r_[face, np.full(m, nf + m), nf + m], np.r_[np.full(m, nf + m), face, nf + m])),
                              shape=(nf + m + 1, nf + m + 1))
        Kq = (J.T @ K @ J + G).tocsc()
        return Kq, J.T @ r, J

    def step(self, values, dq_face, scale):
        """Move the face in ``values`` (shape (n, 2)) by ``scale`` times the reduced step of its
        coordinates ``dq_face = (ds..., dtheta)``, exactly on its line."""
        s, theta = self.coordinates(values.ravel())
        values[self.nodes] = self.displacement(s + scale * dq_face[:-1], theta + scale * dq_face[-1])
