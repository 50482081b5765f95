"""Past the loss of convexity at the contact edge: the Weierstrass–Erdmann corner.

U = W + (beta/2) m^2 is not convex in (lambda_s, kappa_s) everywhere.  Where the
Legendre determinant det d(tau_s, M_s)/d(lambda_s, kappa_s) at the free side of the
contact edge (``Solution.edge_legendre``) reaches zero, the smooth cap's branch ends:
the free region's equations become singular.  Past that depth the state is a cap
whose edge is a corner (``chain.Edge(model="corner")``, derived in
``symbolic.equations.Derivation._edge``): lambda_s and kappa_s jump there while the
sliding and Eshelby conditions hold, and the free side lies in the convex domain.

On the scenes measured the corner grows out of the smooth branch with a jump that
vanishes at the limit (F continuous: a second-order switch); before the limit the
edge's other root has a free side with a negative Legendre determinant (not a
minimum), so the smooth cap is the only candidate there.  (The solves that cross the
limit: ``shellbvp.state.cross_convexity_limit``.)
"""

from __future__ import annotations

import math

import numpy as np

from .chain import Edge
from .configurations import is_single_cap
from .edge_models import EdgeModel

__all__ = ["LEGENDRE_WATCH", "edge_model", "edge_null_jump", "limit_estimate", "is_corner", "near_limit",
           "other_edge_root"]

#: Below this edge_legendre (relative to mid-region) a smooth cap is near its convexity
#: limit: steps that fail, or that are predicted to pass the limit, try the corner.
LEGENDRE_WATCH = 0.1


def edge_model(sol) -> EdgeModel:
    """The contact-edge model of a cap state's system (:mod:`shellbvp.edge_models`): the model
    its edge switched to along the curve (the corner; the paper's edge held at the tip's end),
    else the scene's contact model."""
    contact = sol.scene.contact_model
    sysm = sol.system
    if sysm is None:
        return contact
    return next((j.model for j in sysm.junctions if isinstance(j, Edge) and not j.model.contact), contact)


def limit_estimate(a, b):
    """Depth where edge_legendre reaches 0, extrapolated linearly from smooth cap states
    ``a`` and ``b``; None if it is not decreasing towards it."""
    if a is None or b is None or not edge_model(a).convexity_limit or not edge_model(b).convexity_limit:
        return None
    la, lb = a.edge_legendre, b.edge_legendre
    if not (math.isfinite(la) and math.isfinite(lb)) or a.delta == b.delta:
        return None
    slope = (lb - la) / (b.delta - a.delta)
    if not slope < 0:
        return None
    return b.delta - lb / slope


def is_corner(sol, tol) -> bool:
    """A converged cap whose edge jumps (beyond solver noise) with a convex free region."""
    return bool(sol.success and edge_model(sol).jumps and abs(sol.edge_jump_ls) > 10 * tol
                and sol.legendre_min > 0)


def near_limit(sol) -> bool:
    """A smooth-edge cap state of the smooth model close to its convexity limit."""
    return bool(is_single_cap(sol) and edge_model(sol).convexity_limit
                and sol.edge_legendre < LEGENDRE_WATCH)


def _edge_conditions(sol):
    """(G, v0, null): the corner's two natural conditions G(lambda_s+, kappa_s+) at the edge of
    the smooth cap ``sol`` (the other values held), the smooth root v0, and the null direction
    of their Jacobian there (rank 1 at zero jump)."""
    sysm = sol.system
    mod, par = sysm.model, sysm.par
    yc, yf = sol.y[sysm.rows(0), -1], sol.y[sysm.rows(1), 0]
    v0 = yf[2:4].copy()

    def G(v):
        y = yf.copy()
        y[2:4] = v
        return mod.junction_corner_res(sol.Sc, yc, y, sol.delta, 0.0, par)[3:5]

    h = 1e-7 * (1 + np.abs(v0))
    J = np.column_stack([(G(v0 + np.eye(2)[i] * h[i]) - G(v0 - np.eye(2)[i] * h[i])) / (2 * h[i]) for i in range(2)])
    return G, v0, np.linalg.svd(J)[2][-1]


def edge_null_jump(sol):
    """A jump (of lambda_s, of kappa_s) along the null direction of the corner conditions at the
    edge of the smooth cap ``sol``, per unit jump of lambda_s: the direction in which the
    corner leaves the smooth state (first order), whatever its size."""
    _, _, null = _edge_conditions(sol)
    return null / null[0] if abs(null[0]) > 1e-12 * np.linalg.norm(null) else None


def other_edge_root(sol):
    """The second root (jump of lambda_s, jump of kappa_s) of the corner conditions at the edge of
    the smooth cap ``sol``, the free side's other state values held; None if not found.

    At zero jump the two conditions are dependent (their Jacobian in the free side's
    (lambda_s, kappa_s) has rank 1): the other root lies along its null vector, and near the
    convexity limit it is close.  Before the limit it is the corner that is not convex; past it
    the corner continues with the opposite sign (a transcritical crossing), so a jump of the
    opposite sign, scaled with the distance to the limit, seeds the corner's Newton iteration.
    """
    from scipy.optimize import fsolve  # here: at module level it made `import shellbvp` load scipy.optimize

    G, v0, null = _edge_conditions(sol)
    n = null * (1 + np.abs(v0))  # null direction, scaled to the variables
    best = None
    for t in (1e-3, -1e-3, 1e-2, -1e-2, 5e-2, -5e-2):
        v, _, ier, _ = fsolve(G, v0 + t * n, full_output=True, xtol=1e-13)
        jump = v - v0
        if ier == 1 and np.max(np.abs(G(v))) < 1e-10 and abs(jump[0]) > 1e-7 * (1 + abs(v0[0])):
            if best is None or np.linalg.norm(jump) < np.linalg.norm(best):
                best = jump
    return best
