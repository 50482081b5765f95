"""The internal pressure of the 3D reference (:mod:`shellbvp.fe`): a follower load on the solid's
inner surface, the one away from the indenter.

The shell model's pressure ``p R_L/(mu H)`` acts on its deformed mid-surface with the potential
``-p V``; the solid's acts on its deformed inner surface, ``P = p H/R_L`` in units of mu, with the
potential ``-P V`` of the volume below that surface.  Its virtual work on a quadratic edge of the
surface (axisymmetric, ``dA = 2 pi r ds``)

    f_a = P Int N_a 2 pi r n ds,    n ds = (dr, -dz) per dxi in (z, r) components

(``n`` the normal towards the indenter, the tangent running from the pole to the rim), and its
derivative in the nodes' positions (the load stiffness: r and the normal both follow the
surface) at Gauss points.  The volume ``V`` is the one below the surface, closed by a cylinder at
the surface's end down to the plane of that end's reference height; ``f`` is then exactly
``P dV/dx``: the surface's load plus ``2 pi r_e (z_e - z_e0) P`` on the end's radius (nil until
the end moves), so the load stiffness is the Hessian of ``P V``, symmetric.  The residual gains
``-f`` and the tangent ``-df/dx``.  A sealed shell (volume control) holds ``V`` at ``V0`` with
P an unknown (:class:`shellbvp.fe_newton.Newton`): ``gradient`` is ``dV/dx``.

Points are ``(z, r)``, FElupe's axisymmetric order.  Nondimensional: mu = 1, R_L = 1.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix

__all__ = ["FollowerPressure"]


class FollowerPressure:
    """The pressure ``P`` (in units of mu) on the surface edge ``bottom`` (quadratic nodes from
    the pole to the rim), times ``scale`` (a load factor: 0 to 1 while inflating).

    Parameters
    ----------
    points : ndarray, shape (n, 2)
        The reference nodes ``(z, r)``.
    bottom : ndarray of int
        The surface's nodes in order from the pole (odd count: quadratic edges).
    P : float
    ndof : int
        Size of the residual (every field's dofs; the displacement's come first).
    n_gauss : int
    """

    def __init__(self, points, bottom, P, ndof, n_gauss=4):
        self.P, self.ndof, self.scale = float(P), int(ndof), 1.0
        self.X = np.asarray(points, float)
        self.edges = np.stack([bottom[0:-1:2], bottom[1::2], bottom[2::2]], axis=1)
        xi, self.w = np.polynomial.legendre.leggauss(n_gauss)
        self.N = np.stack([xi * (xi - 1) / 2, 1 - xi**2, xi * (xi + 1) / 2], axis=1)   # (g, 3)
        self.dN = np.stack([xi - 0.5, -2 * xi, xi + 0.5], axis=1)
        dof = 2 * self.edges[:, :, None] + np.arange(2)[None, None, :]                # (e, 3, 2)
        self.dof = dof.reshape(-1, 6)
        self.end = int(bottom[-1])
        self.z_end = float(self.X[self.end, 0])  # the closing plane's height

    def _surface(self, u):
        x = (np.asarray(u)[: self.X.size].reshape(-1, 2) + self.X)[self.edges]        # (e, 3, 2)
        xq = np.einsum("ga,ead->egd", self.N, x)
        dx = np.einsum("ga,ead->egd", self.dN, x)
        return x, xq[..., 1], dx

    def volume(self, u):
        """The volume below the surface displaced by ``u`` (closed as the module says)."""
        _, rq, dx = self._surface(u)
        z_e, r_e = np.asarray(u)[2 * self.end: 2 * self.end + 2] + self.X[self.end]
        return float(-np.pi * np.sum(self.w[None, :] * rq**2 * dx[..., 0]) + np.pi * r_e**2 * (z_e - self.z_end))

    def gradient(self, u):
        """``dV/du`` (full size)."""
        return self._times_gradient(u, 1.0, False)[0]

    def evaluate(self, u, with_matrix=True):
        """``(r, K)``: the residual's part ``-scale P dV/du`` (full size) and its derivative
        (sparse, or None) at the displacement ``u`` (the displacement field's values, flat)."""
        return self._times_gradient(u, -self.scale * self.P, with_matrix)

    def _times_gradient(self, u, factor, with_matrix):
        """``factor * dV/du`` and, with ``with_matrix``, ``factor`` times V's Hessian."""
        x, rq, dx = self._surface(u)                                                   # rq: (e, g)
        m = np.stack([dx[..., 1], -dx[..., 0]], axis=-1)                               # n ds / dxi
        c = factor * 2 * np.pi * self.w[None, :]
        vec = np.einsum("eg,ga,egi->eai", c * rq, self.N, m)                          # (e, 3, 2)
        r = np.zeros(self.ndof)
        np.add.at(r, self.dof.ravel(), vec.ravel())
        # the closing cylinder: d(pi r_e^2 (z_e - z_e0)) less the surface's end term pi r_e^2 dz_e
        z_e, r_e = np.asarray(u)[2 * self.end: 2 * self.end + 2] + self.X[self.end]
        ce = factor * 2 * np.pi
        r[2 * self.end + 1] += ce * r_e * (z_e - self.z_end)
        if not with_matrix:
            return r, None
        # d/dx_(b,j) of r N_a m_i: N_a N_b m_i [j = r]  +  r N_a dm_i/dx_(b,j)
        # with dm_z/dr_b = dN_b, dm_r/dz_b = -dN_b
        e = x.shape[0]
        blk = np.zeros((e, 3, 2, 3, 2))
        blk[:, :, :, :, 1] += np.einsum("eg,ga,gb,egi->eaib", c, self.N, self.N, m)
        blk[:, :, 0, :, 1] += np.einsum("eg,ga,gb->eab", c * rq, self.N, self.dN)
        blk[:, :, 1, :, 0] -= np.einsum("eg,ga,gb->eab", c * rq, self.N, self.dN)
        full = blk.reshape(e, 6, 6)
        end_r, end_z = 2 * self.end + 1, 2 * self.end
        rows = np.r_[np.broadcast_to(self.dof[:, :, None], full.shape).ravel(), end_r, end_r]
        cols = np.r_[np.broadcast_to(self.dof[:, None, :], full.shape).ravel(), end_r, end_z]
        vals = np.r_[full.ravel(), ce * (z_e - self.z_end), ce * r_e]  # d/dr_e, d/dz_e of the end term
        K = coo_matrix((vals, (rows, cols)), shape=(self.ndof, self.ndof)).tocsr()
        return r, K
