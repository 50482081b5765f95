"""One step of a curve's natural continuation in delta: the predictor (a quadratic through
the last three states of one configuration, else their secant, else a warm start) and the
solve, from a point-load state or past the smooth cap's convexity limit where needed.
"""

from __future__ import annotations

import numpy as np

from .corner import edge_model, near_limit
from .config import OPTIONS
from .pointload import solve_point_load
from .solution import SECANT_MAX_RATIO, secant_ratio, warm_mesh
from .state import cross_convexity_limit, solve, solve_from, system_like, warm_guess
from .configurations import is_point_load

__all__ = ["solve_at_delta", "step_from_point", "step_nodes", "quadratic_guess", "secant_guess", "configuration_key"]


def configuration_key(sol):
    return sol.topology, sol.contact_edge




def solve_at_delta(scene, delta, prev, prev2, settings, prev3=None):
    """Delta-controlled solve warm-started from prev: with the quadratic predictor through
    prev, prev2 and prev3 where it applies, else the secant through prev and prev2.  A closed
    shell on a substrate: :func:`shellbvp.state.solve` from prev (its configuration again, or
    a cold start where that is not valid)."""
    if scene.two_contacts:
        return solve(scene, delta=delta, guess=prev, tol=settings.tol, max_nodes=step_nodes(prev, settings),
                     bc_tol=settings.bc_tol, eps=settings.eps, estimate_error=False)
    if is_point_load(prev):
        return step_from_point(scene, delta, prev, settings)
    sysm = system_like(prev, "delta", delta, settings.eps)
    guess = None
    a = secant_ratio(delta, prev, prev2)
    if a is not None and not is_point_load(prev2) and edge_model(prev2) == edge_model(prev) \
            and abs(a * (prev.p[0] - prev2.p[0])) <= OPTIONS.secant_max_ln_sc:
        guess = quadratic_guess(sysm, (prev, prev2, prev3), delta) or secant_guess(sysm, prev, prev2, a)
    if guess is None:
        guess = warm_guess(sysm, prev)
    kw = dict(tol=settings.tol, max_nodes=step_nodes(prev, settings), bc_tol=settings.bc_tol)
    sol = solve_from(sysm, guess, **kw)
    if not sol.success and delta > prev.delta and near_limit(prev):
        sol = cross_convexity_limit(prev, prev2, delta, eps=settings.eps, **kw) or sol
    return sol


def step_from_point(scene, delta, prev, settings):
    """A step from a point-load state (no cap to warm-start from).  Deeper, the cap may
    come back within double precision: a cold solve finds the cap there, or the point-load
    limit again; shallower, the point-load limit from ``prev``."""
    if delta > prev.delta:  # (solve takes a point-load guess for its point-load limit only)
        return solve(scene, delta=delta, guess=prev, tol=settings.tol, max_nodes=settings.max_nodes,
                     bc_tol=settings.bc_tol, estimate_error=False, topology="cap")
    return solve_point_load(scene, delta, tol=settings.tol, max_nodes=settings.max_nodes, guess=prev)


def step_nodes(prev, settings):
    """Node budget of one continuation step: a few times the previous mesh, so that a
    step towards a singularity (e.g. a boundary layer forming) fails fast and is halved."""
    return int(min(settings.max_nodes, max(2000, 4 * prev.nodes)))


def quadratic_guess(sysm, states, at):
    """Guess at delta = ``at`` from the quadratic in delta through ``states`` (three, newest
    first), on the newest one's warm-start mesh; None where it does not apply: a missing state
    or one of another configuration, depths not monotone towards ``at``, a step more than
    ``SECANT_MAX_RATIO`` times the one before, or ln Sc moved by more than ``OPTIONS.secant_max_ln_sc``
    (the secant's guards)."""
    s1, s2, s3 = states
    if not OPTIONS.quadratic_predictor or s3 is None or is_point_load(s3) \
            or not configuration_key(s3) == configuration_key(s2) == configuration_key(s1):
        return None
    u1, u2, u3 = s1.delta, s2.delta, s3.delta
    if not ((u3 < u2 < u1 < at) or (u3 > u2 > u1 > at)) \
            or max(abs((at - u1) / (u1 - u2)), abs((u1 - u2) / (u2 - u3))) > SECANT_MAX_RATIO:
        return None
    w1 = (at - u2) * (at - u3) / ((u1 - u2) * (u1 - u3))  # Lagrange's weights (they sum to 1)
    w2 = (at - u1) * (at - u3) / ((u2 - u1) * (u2 - u3))
    w3 = (at - u1) * (at - u2) / ((u3 - u1) * (u3 - u2))
    X = [np.array([s.p[0], s.lambda0, s.delta]) for s in states]
    ln_Sc, lambda0, delta = w1 * X[0] + w2 * X[1] + w3 * X[2]
    if not abs(ln_Sc - X[0][0]) <= OPTIONS.secant_max_ln_sc:
        return None
    x = warm_mesh(s1)
    y = w1 * s1.sol(x) + w2 * s2.sol(x) + w3 * s3.sol(x)
    return x, y, sysm.pack(ln_Sc=ln_Sc, lambda0=lambda0, delta=delta)


def secant_guess(sysm, cur, prev, a):
    """Guess cur + a (cur - prev) on cur's warm-start mesh (states and parameters)."""
    x = warm_mesh(cur)
    y = cur.sol(x)
    if a:
        y = y + a * (y - prev.sol(x))
    X = np.array([cur.p[0], cur.lambda0, cur.delta])
    Xp = np.array([prev.p[0], prev.lambda0, prev.delta])
    ln_Sc, lambda0, delta = X + a * (X - Xp)
    return x, y, sysm.pack(ln_Sc=ln_Sc, lambda0=lambda0, delta=delta)
