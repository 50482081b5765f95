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

from .chain import Edge

__all__ = ["LEGENDRE_WATCH", "edge_model", "limit_estimate", "is_corner", "near_limit"]

#: Below this edge_legendre (relative to mid-region) a smooth cap is near its convexity
#: limit: steps that fail, or that are predicted to pass the limit, try the corner.
LEGENDRE_WATCH = 0.1


def edge_model(sol) -> str:
    """The contact-edge model of a cap state's system ("smooth", "corner" or "paper")."""
    sysm = sol.get("system")
    if sysm is None:
        return sol.scene.contact
    models = {j.model for j in sysm.junctions if isinstance(j, Edge)}
    return "corner" if "corner" in models else sol.scene.contact


def limit_estimate(a, b):
    """Depth where edge_legendre reaches 0, extrapolated linearly from smooth cap states
    ``a`` and ``b``; None if it is not decreasing towards it."""
    if a is None or b is None or edge_model(a) != "smooth" or edge_model(b) != "smooth":
        return None
    la, lb = a.get("edge_legendre", math.nan), b.get("edge_legendre", math.nan)
    if not (math.isfinite(la) and math.isfinite(lb)) or a.delta == b.delta:
        return None
    slope = (lb - la) / (b.delta - a.delta)
    if not slope < 0:
        return None
    return b.delta - lb / slope


def is_corner(sol, tol) -> bool:
    """A converged cap whose edge jumps (beyond solver noise) with a convex free region."""
    return bool(sol.success and edge_model(sol) == "corner" and abs(sol.get("edge_jump_ls", 0.0)) > 10 * tol
                and sol.get("legendre_min", -1.0) > 0)


def near_limit(sol) -> bool:
    """A smooth-edge cap state of the smooth model close to its convexity limit."""
    return bool(sol.get("topology") == "cap" and sol.scene.contact == "smooth" and edge_model(sol) == "smooth"
                and sol.get("edge_legendre", math.inf) < LEGENDRE_WATCH)
