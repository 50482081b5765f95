"""The point-load limit of the smooth model: the free region alone, delta prescribed.

When the contact cap is exponentially small (``Sc`` below ~1e-30, which happens
as delta -> 0) the cap's own equations leave double precision and the state is
the point-load solution to exponential accuracy (``shellbvp.configurations.point``).
"""

from __future__ import annotations

import math
import time

import numpy as np

from .configurations import POINT_S0, configuration, is_point_load
from .diagnosis import diagnose
from .inflation import start_shape
from .march import Steps, march
from .solution import thin_mesh

__all__ = ["solve_point_load", "SC_POINT", "POINT_S0"]


#: Caps smaller than this are replaced by the point-load limit (their own equations
#: leave double precision near Sc ~ 1e-75; the difference is exponentially small).
SC_POINT = 1e-30


def _point_guess(sysm, prev):
    """Free states for the point-load problem from a cap or point solution."""
    if is_point_load(prev):
        # every third node, not solution.warm_mesh: the march towards a larger depth fails
        # often (the state passes through the tip), and a failed step refines from the whole
        # mesh (base, a cap from a point-load guess: 28 s against 4.5 s)
        x = thin_mesh(prev.x)
        return x, prev.sol(x)
    x = np.linspace(0.0, 1.0, 61)
    cap = prev.system
    tp = np.clip(cap.t_of(1, sysm.S(0, x, None), prev.p), 0.0, 1.0)
    return x, prev.sol(tp)[cap.rows(1)]


def _crude_point_guess(sysm):
    """The undeformed shell (stretches 1: a 5 % compression overflowed Newton at beta 1e-5),
    the pole moved down by delta and linearly back to the rim, on a mesh geometric in S
    towards the pole and uniform in S over the rest: the rim's boundary layer (width ~
    sqrt(beta)) starts resolved (a spheroidal dome, gamma -0.2 at beta 1e-5, converged
    from the geometric mesh alone only below delta ~ 1e-5)."""
    t_outer = sysm.t_of(0, sysm.L * np.linspace(0.05, 1.0, 100), None)
    x = np.union1d(np.linspace(0.0, 1.0, 61), t_outer[(t_outer > 0) & (t_outer < 1 - 1e-9)])
    x = x[np.r_[True, np.diff(x) > 1e-9]]  # no near-duplicate nodes; 0 and 1 stay
    S = sysm.S(0, x, None)
    y = start_shape(sysm.scene, S)  # the reference shell, or the inflated one under pressure
    y[4] = 0.0
    y[5] -= sysm.value * (1 - (S - S[0]) / (S[-1] - S[0]))
    return x, y


def solve_point_load(scene, delta, *, tol=1e-6, max_nodes=10000, guess=None, bc_tol=1e-10, march_up=True):
    """The point-load limit of the smooth model at pole displacement ``delta``.

    When the contact cap is exponentially small (``Sc`` below ~1e-30, which
    happens as delta -> 0) the cap's own equations leave double precision and
    the state is the point-load solution to exponential accuracy: the free
    region alone on ``[s0, L]`` with the point-load pole conditions
    (``shellbvp.configurations.point``).

    Started from ``guess`` (a cap or point-load state at a nearby depth) if given, else
    (or if that fails) from the undeformed shell, and where that fails too, from the
    undeformed shell at a smaller depth, continued in delta (:func:`_from_smaller_depth`;
    ``march_up=False``: not, for a caller with cheaper routes left to try first).
    """
    t0 = time.perf_counter()
    kw = dict(tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    res = _point_run(scene, delta, guess, **(kw if guess is not None else _crude(kw)))
    if guess is not None and not res.success:  # e.g. a cap of 1e-30 whose free region is no start
        res = _point_run(scene, delta, None, **_crude(kw))
    if not res.success and march_up:
        res = _from_smaller_depth(scene, delta, **kw) or res
    return res.with_(wall_time=time.perf_counter() - t0)


def _point_run(scene, delta, guess, *, tol, max_nodes, bc_tol):
    """One solve_bvp run of the point-load problem from ``guess`` (a state) or the crude guess."""
    sysm = configuration("point").system(scene, "delta", delta, None)
    x, y = _point_guess(sysm, guess) if guess is not None else _crude_point_guess(sysm)
    with np.errstate(all="ignore"):
        bvp = sysm.solve(x, y, None, tol=tol, bc_tol=bc_tol, max_nodes=max_nodes)
        return diagnose(sysm, bvp, tol, " (point-load limit: the contact cap is exponentially small)")


#: Node budget of a run from the crude guess: one that needs more is far from the state
#: (seconds each at 8000 nodes); the march from a smaller depth then takes over.
_CRUDE_MAX_NODES = 3000


def _crude(kw):
    return dict(kw, max_nodes=min(kw["max_nodes"], _CRUDE_MAX_NODES))


#: Depths (fractions of the asked one) from which the crude guess is tried when it fails at
#: the asked depth, and the largest and smallest ratios of a step up from there.
_START_FRACTIONS = (0.1, 0.01, 0.001)
_STEP_MAX, _STEP_MIN = 4.0, 1.02


def _from_smaller_depth(scene, delta, **kw):
    """The point-load state at ``delta`` by natural continuation from a smaller depth, or None.

    The crude guess (the undeformed shell, the pole moved down linearly to the rim) is
    near the state only while the depth is small against the bending length (the
    shallow dome of radius 5 at beta 1e-5 converges from it at delta 0.01, not at
    0.05).  Steps grow by 1.5 after a success and shrink to the square root of the
    ratio tried after a failure, with a node budget of a few times the last state's
    so that a step towards a singular state fails fast; a fold on the way ends the
    march (None), and so does a state that passes through the tip (the contact is then
    resolved and no longer a point: ``shellbvp.state`` grows a cap from such a state).
    """
    start = None
    for fraction in _START_FRACTIONS:
        if delta * fraction < 10 * kw["tol"]:  # below, delta is in the solver's noise
            break
        start = _point_run(scene, delta * fraction, None, **_crude(kw))
        if start.success:
            break
    if start is None or not start.success:
        return None

    def solve_at(d, states):
        prev = states[-1]
        return _point_run(scene, d, prev, **dict(kw, max_nodes=int(min(kw["max_nodes"], max(2000, 4 * prev.nodes)))))

    def passes_the_tip(nxt, d, states):  # short of the depth asked: the contact is no longer a point
        return "invalid" if nxt.success and d < delta and not nxt.valid else None

    # steps are ratios of depths: d = delta_prev * ratio
    steps = Steps(_STEP_MAX / 2, advance=lambda u, r, t: min(t, u * r), grow=lambda r: min(_STEP_MAX, 1.5 * r),
                  shrink=lambda r, u, tried: math.sqrt(tried / u), too_small=lambda r, u: r < _STEP_MIN)
    marched = march(start.delta, delta, solve_at, steps, history=[start], position=lambda s: s.delta,
                    stop=passes_the_tip)
    return marched.last if marched.reached else None
