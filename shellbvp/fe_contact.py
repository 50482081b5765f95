"""The rigid indenter of the 3D reference (:mod:`shellbvp.fe`): its signed distance in the
meridian plane with gradient and Hessian (:class:`TipSurface`), and the frictionless penalty
contact of the solid's surface with it, with its exact tangent (:class:`PenaltyContact`).

Points are ``(z, r)``, FElupe's axisymmetric order.  Nondimensional: mu = 1, R_L = 1.
"""

from __future__ import annotations

import numpy as np

__all__ = ["TipSurface", "PenaltyContact", "Plane"]


class Plane:
    """A rigid plane ``z = apex`` with the solid on one side: ``facing = +1`` above it (a
    substrate), ``-1`` below it (a flat plate pressing down).  ``distance`` as :class:`TipSurface`'s."""

    def __init__(self, facing):
        self.facing = float(facing)

    def distance(self, x, apex):
        n = np.zeros((x.shape[0], 2))
        n[:, 0] = self.facing
        return self.facing * (x[:, 0] - apex), n, np.zeros((x.shape[0], 2, 2))


class TipSurface:
    """Signed distance to the rigid indenter (tip ``r = rho A(omega)``, ``z = z_apex + rho B(omega)``
    joined to the cylinder ``r = rho``) in the meridian plane, with its gradient and Hessian.

    Points are ``(z, r)`` (FElupe's axisymmetric order: axial first).  ``distance(x)`` returns
    ``(d, n, H)``: ``d < 0`` inside the indenter, ``n = grad d`` (unit, pointing out of the
    indenter), ``H = grad grad d``.  The sphere is written in closed form; other tips by the
    closest point on their meridian (Newton in omega); a flat tip is a plane (it has no end).
    """

    def __init__(self, scene):
        self.rho = float(scene.rho)
        kind = scene.tip.description()["kind"]
        self.sphere = kind == "sphere"
        self.plane = Plane(-1) if kind == "flat" else None
        self.omega_max = float(scene.tip_omega_max)
        if not self.sphere and self.plane is None:
            import sympy as sp

            from symbolic.geometry import OMEGA

            A, B = scene.tip.geometry.A, scene.tip.geometry.B
            # SymPy expressions parsed by the formula whitelist; lambdify prints them as numpy
            self._curve = sp.lambdify(OMEGA, [A, B, sp.diff(A, OMEGA), sp.diff(B, OMEGA),
                                              sp.diff(A, OMEGA, 2), sp.diff(B, OMEGA, 2)], "numpy")
            om = np.linspace(0.0, self.omega_max, 2001)
            a, b = (np.broadcast_to(np.asarray(v, float), om.shape) for v in self._curve(om)[:2])
            self._table = (om, self.rho * a, self.rho * b)
            self._top = self.rho * float(b[-1])  # where the tip meets the cylinder, above the apex

    def distance(self, x, apex):
        if self.plane is not None:
            return self.plane.distance(x, apex)
        z, r = x[:, 0] - apex, np.abs(x[:, 1])
        if self.sphere:
            return self._capsule(z, r)
        return self._profile(z, r)

    def _capsule(self, z, r):
        # points within rho of the half-line {r = 0, z >= rho}: a sphere on its cylinder
        zc = self.rho
        above = z > zc
        vz, vr = np.where(above, 0.0, z - zc), r
        dist = np.hypot(vz, vr)
        dist = np.maximum(dist, 1e-300)
        n = np.stack([vz / dist, vr / dist], axis=1)
        H = (np.eye(2)[None] - n[:, :, None] * n[:, None, :]) / dist[:, None, None]
        H[above] = 0.0  # the cylinder is straight in the meridian plane
        return dist - self.rho, n, H

    def _profile(self, z, r):
        om, ta, tb = self._table
        d = np.empty(z.size)
        n = np.zeros((z.size, 2))
        H = np.zeros((z.size, 2, 2))
        on_cyl = z > self._top
        # cylinder: horizontal distance
        d[on_cyl] = r[on_cyl] - self.rho
        n[on_cyl] = [0.0, 1.0]
        idx = np.flatnonzero(~on_cyl)
        if idx.size:
            zz, rr = z[idx], r[idx]
            k = np.argmin((ta[None, :] - rr[:, None]) ** 2 + (tb[None, :] - zz[:, None]) ** 2, axis=1)
            w = om[k]
            for _ in range(30):  # Newton on (p(w) - x) . p'(w) = 0
                a, b, da, db, dda, ddb = (np.broadcast_to(np.asarray(v, float), w.shape) for v in self._curve(w))
                pr, pz = self.rho * a - rr, self.rho * b - zz
                f = pr * da + pz * db
                fp = self.rho * (da * da + db * db) + pr * dda + pz * ddb
                step = f / fp
                w = np.clip(w - step, 0.0, self.omega_max)
                if np.max(np.abs(step)) < 1e-14:
                    break
            a, b, da, db, dda, ddb = (np.broadcast_to(np.asarray(v, float), w.shape) for v in self._curve(w))
            pr, pz = rr - self.rho * a, zz - self.rho * b
            dist = np.hypot(pr, pz)
            # outward normal of the tip (r grows, z falls on the outside): (dB, -dA) in (r, z) / |p'|
            sp_ = np.hypot(da, db)
            nr, nz = db / sp_, -da / sp_
            sign = np.where(pr * nr + pz * nz >= 0, 1.0, -1.0)
            d[idx] = sign * dist
            n[idx, 0], n[idx, 1] = nz, nr
            # curvature of the meridian (positive: convex tip); grad grad d = kappa/(1 + kappa d) t t
            kappa = (da * ddb - db * dda) / (self.rho * sp_**3)
            t = np.stack([db / sp_, da / sp_], axis=1)  # (z, r) components of the unit tangent
            coef = kappa / (1.0 + kappa * d[idx])
            H[idx] = coef[:, None, None] * t[:, :, None] * t[:, None, :]
        return d, n, H


class PenaltyContact:
    """Frictionless penalty contact of the surface edge ``top`` with the rigid tip.

    Energy ``(k/2) Int psi(-d) dA`` over the reference surface (dA = 2 pi R ds), ``psi(g) ~ g^2``
    for penetrations g beyond a small band (smoothed inside it), at Gauss points of each
    quadratic edge; gradient and exact Hessian (the distance's curvature included).
    """

    def __init__(self, tip, points, top, k, n_gauss, field, band):
        self.tip, self.k, self.band = tip, k, band
        self.ndof_u = points.shape[0] * 2
        self.ndof = int(np.sum(field.fieldsizes))
        edges = np.stack([top[0:-1:2], top[1::2], top[2::2]], axis=1)  # quadratic edges (3 nodes)
        xi, w = np.polynomial.legendre.leggauss(n_gauss)
        N = np.stack([xi * (xi - 1) / 2, 1 - xi**2, xi * (xi + 1) / 2], axis=1)       # (g, 3)
        dN = np.stack([xi - 0.5, -2 * xi, xi + 0.5], axis=1)
        X = points[edges]                                                           # (e, 3, 2)
        Xq = np.einsum("ga,ead->egd", N, X)
        dX = np.einsum("ga,ead->egd", dN, X)
        self.weight = (w[None, :] * np.hypot(dX[..., 0], dX[..., 1]) * 2 * np.pi * Xq[..., 1]).ravel()
        self.edges, self.N = edges, N
        # per Gauss point: the 6 displacement dofs of its edge and the 3 shape functions (fixed)
        e, ng = edges.shape[0], N.shape[0]
        dof = 2 * edges[:, None, :, None] + np.arange(2)[None, None, None, :]          # (e, 1, 3, 2)
        self.dof = np.broadcast_to(dof, (e, ng, 3, 2)).reshape(-1, 6)
        self.Nq = np.broadcast_to(N[None], (e, ng, 3)).reshape(-1, 3)
        self.z0 = float(points[top[0], 0])  # the surface's pole: where the tip first touches
        self.apex = self.z0

    def _at_points(self, u):
        x = (np.asarray(u).reshape(-1, 2))[self.edges] + self.X_ref
        xq = np.einsum("ga,ead->egd", self.N, x).reshape(-1, 2)
        return xq

    def bind(self, points, apex=None):
        """Fix the reference surface; ``z0`` becomes the apex height of first touch (or ``apex``:
        a support held there)."""
        self.X_ref = points[self.edges]
        self.z0 = self.apex = self.first_touch() if apex is None else float(apex)

    def first_touch(self, u=None):
        """The apex height at which the descending indenter first touches the surface, undeformed
        or displaced by ``u`` (at its Gauss points): at the pole, or on a ring where the surface
        is more curved than the tip (a bowl's inner surface under a blunter tip)."""
        from scipy.optimize import brentq

        u = np.zeros(self.ndof_u) if u is None else np.asarray(u)[: self.ndof_u]
        xq = self._at_points(u)
        pole = float(self.X_ref[0, 0, 0] + u[2 * self.edges[0, 0]])
        gap = lambda apex: float(np.min(self.tip.distance(xq, apex)[0]))  # noqa: E731
        hi = pole + 1.0
        while gap(hi) <= 0:  # the tip above every point it could reach
            hi += 1.0
        lo = pole  # the apex at the pole: touching there, or already through a ring
        return lo if gap(lo) >= 0 else brentq(gap, lo, hi, xtol=1e-14, rtol=1e-14)

    def evaluate(self, u, with_matrix=True):
        from scipy.sparse import coo_matrix

        xq = self._at_points(u)
        d, n, H = self.tip.distance(xq, self.apex)
        # penetration g = -d through (k/2) psi(g): g^2 - s g + s^2/3 beyond a band s, g^3/(3 s) in it,
        # 0 outside -- twice differentiable, so Newton does not chatter as points enter and leave
        g, s = -d, self.band
        active = g > 0
        dpsi = np.where(g >= s, 2 * g - s, np.where(active, g * g / s, 0.0))
        d2psi = np.where(g >= s, 2.0, np.where(active, 2 * g / s, 0.0))
        force = -0.5 * self.k * self.weight * dpsi            # (q,) minus the normal force * weight
        dof, Nq = self.dof, self.Nq
        vec = (force[:, None, None] * Nq[:, :, None] * n[:, None, :]).reshape(-1, 6)
        r = np.zeros(self.ndof)
        np.add.at(r, dof.ravel(), vec.ravel())
        # the indenter's force: minus the shell's reaction in z, positive pushing down
        F = float(np.sum(force * n[:, 0]))
        K = None
        if with_matrix:
            kq = 0.5 * self.k * self.weight
            block = kq[:, None, None] * (d2psi[:, None, None] * n[:, :, None] * n[:, None, :]
                                         - dpsi[:, None, None] * H)                        # (q, 2, 2)
            full = np.einsum("qa,qb,qij->qaibj", Nq, Nq, block).reshape(-1, 6, 6)
            rows = np.broadcast_to(dof[:, :, None], full.shape).ravel()
            cols = np.broadcast_to(dof[:, None, :], full.shape).ravel()
            K = coo_matrix((full.ravel(), (rows, cols)), shape=(self.ndof, self.ndof)).tocsr()
        rq = xq[active, 1]
        return r, K, F, (float(rq.max()) if rq.size else 0.0)
