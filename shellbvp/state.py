"""One equilibrium state: guesses, the solve_bvp call, diagnostics, the result.

``solve(scene, delta=...)`` (or ``lambda0=``, ``force=``) returns a
:class:`Solution` in the style of scipy's ``OptimizeResult``: it never raises
for a state that does not converge (``success=False``, a ``status`` and a
``message`` saying what to try); only invalid input raises ``ValueError``.
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from .chain import FREE_STATES, ChainBVP
from .closed import closed_again, closed_cold, closed_continued
from .configurations import ASKED, asked, configuration, is_point_load, is_single_cap, of
from .corner import edge_model, edge_null_jump, is_corner, limit_estimate, near_limit, other_edge_root
from .cylinder import cap_onto_wall, wall_again
from .diagnosis import as_failure, diagnose
from .inflation import start_shape
from .liftoff import POINT_LIMIT_SC, cap_lifted_off, lifted_again, split_again
from .bounds import check_delta, check_tol, delta_bounds
from .march import Steps, march
from .pointload import SC_POINT, solve_point_load
from .solution import (
    STATUS_MESSAGES,
    Solution,
    default_eps,
    failure,
    passed_tip_end,
    richardson_error,
    warm_mesh,
)

__all__ = ["solve", "solve_from", "make_system", "system_like", "cross_convexity_limit", "warm_guess", "delta_bounds", "check_delta", "check_tol",
           "TOPOLOGIES", "AGAIN", "CAP_REPLACEMENTS"]

log = logging.getLogger(__name__)

#: How ``solve(guess=...)`` solves a state of each family again from itself:
#: ``again(guess, control, value, *, topology, tol, max_nodes, eps, bc_tol, estimate_error)``
#: returns the finished state, or None to fall back to the single cap.  The cap and the point
#: load have none: the cap's own warm start serves them.
AGAIN = {"lifted": lifted_again, "split": split_again, "wall": wall_again, "closed": closed_again}
#: How a single cap is replaced where a state of another family is suspected, in the order tried:
#: ``replace(cap, topology, kw)`` returns the replacement or the cap (with what was tried in its flags)
CAP_REPLACEMENTS = (("wall", cap_onto_wall), ("lifted", cap_lifted_off))


def _undeformed_guess(sysm: ChainBVP, ln_Sc, lambda0, delta, n=41):
    """Crude start: the shell before indentation (the reference shell, or the inflated one
    under pressure) moved down by delta, a small cap at stretch lambda0 (times the pole's
    stretch before indentation)."""
    t = np.linspace(0.0, 1.0, n)
    Sf = sysm.S(1, t, sysm.pack(ln_Sc=ln_Sc, lambda0=lambda0, delta=delta))
    start = start_shape(sysm.scene, Sf)
    lambda0 = lambda0 * start[2, 0]
    p = sysm.pack(ln_Sc=ln_Sc, lambda0=lambda0, delta=delta)
    chi0 = -sysm.model.pole_res(0.0, 0.0, 1.0, sysm.par)[0]  # chi at the pole for lambda0 = 1
    Sc = np.exp(ln_Sc)
    w = (Sf - Sc) / (sysm.L - Sc)
    y = np.vstack([
        np.full(n, lambda0 * chi0),
        np.full(n, lambda0),
        lambda0 + (start[0] - lambda0) * w,
        start[1],
        start[2],
        start[3],
        start[4],
        start[5] - delta * (1.0 - w),
    ])
    return t, y, p


def warm_guess(sysm: ChainBVP, prev: "Solution", predictor=None, tol=None):
    """Previous cap solution on its warm-start mesh (for ``tol``, default the one ``prev`` was
    solved at; :func:`shellbvp.solution.warm_mesh`); optional predicted (y, p) shift."""
    x = warm_mesh(prev, tol)
    y = prev.sol(x)
    p = sysm.pack(ln_Sc=prev.p[0], lambda0=prev.lambda0, delta=prev.delta)
    if predictor is not None:
        dy, dp = predictor
        y = y + dy(x)
        p = p + dp
    return x, y, p


def _run_bvp(sysm, guess, tol, max_nodes, bc_tol):
    x, y, p = guess
    with np.errstate(all="ignore"):
        return sysm.solve(x, y, p, tol=tol, bc_tol=bc_tol, max_nodes=max_nodes)


def make_system(scene, control, value, eps, edge=None):
    """The single-cap system (``shellbvp.configurations.cap``) of a scene, control and value;
    ``edge`` (an :class:`~shellbvp.edge_models.EdgeModel` or its name) defaults to the scene's
    contact model."""
    return configuration("cap").system(scene, control, value, eps, edge)


def system_like(prev, control, value, eps):
    """The cap system of ``prev``'s scene with ``prev``'s contact edge (smooth or corner):
    ``prev``'s own system with the new value where it is that system, else a new one."""
    edge, sysm = edge_model(prev), prev.system
    if (isinstance(sysm, ChainBVP) and sysm.control == control and not sysm.volume_control
            and sysm.scene is prev.scene and hasattr(sysm, "tip_A")
            and sysm.chain == configuration("cap").chain(eps, prev.scene.shell_length, edge)):
        return sysm.with_value(value)
    return make_system(prev.scene, control, value, eps, edge)


def cross_convexity_limit(prev, prev2, delta, *, eps, tol, max_nodes, bc_tol, exact=True):
    """The corner cap at ``delta`` from the smooth cap ``prev`` near its convexity limit
    (``shellbvp.corner``), or None.

    Newton started at the limit itself meets a singular Jacobian (the corner's two edge
    conditions are dependent at zero jump), so the first corner state is solved a little
    past the limit estimated from ``prev2``, ``prev``.  If ``delta`` is nearer, that state is
    continued back to it when ``exact`` (before the limit that gives the smooth root again,
    which is the state there), else returned as it is (a continuation takes any depth).
    """
    d_star = limit_estimate(prev2, prev)
    gap = (d_star - prev.delta) if d_star is not None and d_star > prev.delta else 0.005
    # Newton's basin around the corner seen from a smooth state is narrow and uneven: try a
    # ladder of depths past the limit, nearest first
    # ladder of depths past the limit, nearest first, from prev and then from prev2 (a smooth
    # state further from the limit is often the better start)
    ladder = sorted({max(delta, prev.delta + k * gap, prev.delta + 0.005) for k in (3, 6, 12)}
                    | {max(delta, prev.delta + 0.02), max(delta, prev.delta + 0.04)})
    starts = [s for s in (prev, prev2) if s is not None and s.success and edge_model(s).convexity_limit]
    sol = None
    # seeds: the edge's other root scaled to d_far; else a jump of CORNER_SEED_JUMP in lambda_s
    # (either sign) along the null direction of the edge conditions (gamma = 0 with the numpy
    # functions: the other root is not found, the conditions are flat to 1e-15 near v0); none
    seeds = ("root", CORNER_SEED_JUMP, -CORNER_SEED_JUMP, None)
    for d_far, start, seeded in ((d, s, k) for s in starts for d in ladder for k in seeds):
        sysm = make_system(prev.scene, "delta", d_far, eps, "corner")
        guess = warm_guess(sysm, start)
        if seeded == "root":  # the jump expected at d_far put at the edge: Newton at zero jump is near-singular
            guess = _seed_corner(sysm, guess, start, d_star, d_far)
        elif seeded is not None:
            guess = _seed_along_null(sysm, guess, start, seeded)
        if guess is None:
            continue
        sol = solve_from(sysm, guess, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
        if is_corner(sol, tol):
            break
    else:
        return None
    if not exact or d_far == delta:
        return sol
    step = d_far - delta  # back to delta in steps that shrink where Newton fails
    while sol.delta > delta:
        d = max(delta, sol.delta - step)
        sysm = make_system(prev.scene, "delta", d, eps, "corner")
        nxt = solve_from(sysm, warm_guess(sysm, sol), tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
        if nxt.success:
            sol = nxt
        else:
            step /= 2
            if step < 1e-4 * (1 + delta):
                return None
    return sol if sol.success and sol.legendre_min > 0 else None


#: Size of the jump of lambda_s put at the edge of a corner guess along the null direction of
#: the edge conditions (the corner jumps grow from 0 at the limit: base 0.17 at 0.086 past it;
#: gamma 0: 0.017 at 0.009 past it, found from +-0.02 and +-0.05 alike)
CORNER_SEED_JUMP = 0.02


def _seed_along_null(sysm, guess, start, size):
    """``guess`` with a jump of ``size`` in lambda_s (and kappa_s along the null direction of the
    edge conditions of the smooth cap ``start``) at the edge's free side; None if degenerate."""
    direction = edge_null_jump(start)
    return None if direction is None else _with_edge_jump(sysm, guess, size * direction)


def _with_edge_jump(sysm, guess, jump):
    """``guess`` with ``jump`` added to (lambda_s, kappa_s) at the start of the free region (the
    edge's free side)."""
    x, y, p = guess
    y = y.copy()
    r = sysm.rows(1)
    y[r.start + 2:r.start + 4, 0] += jump
    return x, y, p


def _seed_corner(sysm, guess, start, d_star, d_far):
    """``guess`` (from the smooth cap ``start``) with a jump at the edge's free side: the edge's
    other root at ``start`` reflected through the limit ``d_star`` and scaled to ``d_far``."""
    if d_star is None or not start.delta < d_star < d_far:
        return None
    jump = other_edge_root(start)
    if jump is None or not jump[0] < 0:  # before the limit the other root stretches less
        return None
    return _with_edge_jump(sysm, guess, -jump * (d_far - d_star) / (d_star - start.delta))


def solve_from(sysm, guess, *, tol=1e-6, max_nodes=10000, bc_tol=None):
    """One solve_bvp run from a given (x, y, p) guess, diagnosed."""
    t0 = time.perf_counter()
    bvp = _run_bvp(sysm, guess, tol, max_nodes, bc_tol if bc_tol is not None else 1e-10)
    with np.errstate(all="ignore"):  # diagnostics of a failed run may overflow; flagged instead
        res = diagnose(sysm, bvp, tol)
    return res.with_(wall_time=time.perf_counter() - t0)


#: What ``solve(topology=...)`` accepts: "auto" and the configurations that may be asked for (as
#: the package registers them; ``solve`` asks the registry, which one registered later joins)
TOPOLOGIES = ASKED


def solve(scene, *, delta=None, lambda0=None, force=None, tol=1e-6, max_nodes=10000, guess=None,
          eps=None, bc_tol=1e-10, estimate_error=True, topology="auto"):
    """Solve one indentation state.

    Exactly one of ``delta`` (pole displacement), ``lambda0`` (pole stretch) or
    ``force`` (indenter force) is prescribed.

    Parameters
    ----------
    scene : Scene
    delta, lambda0, force : float
        The prescribed quantity (one of them); ``delta`` within :func:`delta_bounds`.
    tol : float
        solve_bvp's relative collocation tolerance (states are O(1)-scaled).
    max_nodes : int
        Largest number of mesh nodes.
    guess : Solution, optional
        A neighbouring solution to start from (warm start on a mesh equidistributing its
        residual, ``shellbvp.solution.warm_mesh``).  Its
        configuration is solved again (a lift-off, split or wall state; under delta
        control a split is continued to the depth), falling back to the single cap where
        that fails.
    eps : float, optional
        Pole start ``zeta = eps*Sc``; default ``min(1e-3, 0.1 sqrt(tol))``.
    bc_tol : float
        Tolerance on the boundary and contact-line conditions.
    estimate_error : bool
        Richardson error estimates ``force_error``, ``delta_error`` (one more Newton
        solve on the mesh with every interval halved; see :func:`richardson_error`).
    topology : {"auto", "cap", "line", "annulus", "cap+line(cylinder)", "cap+band(cylinder)", "cap+cylinder"}
        Contact configuration (``shellbvp.chain``).  ``"auto"``: the single cap,
        replaced by a valid line or annular contact where the cap would pull the
        shell (negative pressure or ring force; smooth model; ``shellbvp.liftoff``),
        or by the valid configuration of lowest energy with contact on the
        indenter's cylinder (a line, a band, or the contact running onto it;
        ``shellbvp.cylinder``; both contact models) where the cap passes the tip's
        end or its free shell passes through the indenter near it.  ``"cap"``: the
        cap only.  Any other: that configuration, started from the cap state (or
        from ``guess``), valid or not.  With a lifted pole, ``lambda0`` is the
        stretch there.

    Returns
    -------
    Solution
        Never raises for non-convergence: ``success``, ``status`` and ``message``
        say what happened (:data:`STATUS_MESSAGES`); ``valid`` and ``flags`` whether
        the contact pushes everywhere and the shell stays outside the indenter.

    Raises
    ------
    ValueError
        For arguments out of range (naming the argument and the range).

    Examples
    --------
    >>> import shellbvp as sb
    >>> scene = sb.Scene.preset("base")
    >>> sol = sb.solve(scene, delta=0.2)
    >>> print(f"{sol.force:.4f} {sol.topology} {sol.valid}")
    0.3639 cap True
    >>> round(sb.solve(scene, force=sol.force, guess=sol).delta, 6)    # force control
    0.2
    >>> print(sb.solve(scene, delta=0.05).topology)          # the pole has lifted off
    line
    """
    given = {k: v for k, v in (("delta", delta), ("lambda0", lambda0), ("force", force)) if v is not None}
    if len(given) != 1:
        raise ValueError("give exactly one of delta, lambda0 or force; got "
                         + (", ".join(given) if given else "none"))
    (control, value), = given.items()
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)) \
            or not math.isfinite(value):
        raise ValueError(f"{control} must be a finite number; got {value!r}")
    if control == "delta" and value <= 0:
        raise ValueError(f"delta must be > 0 (delta = 0 is the undeformed shell); got {value!r}")
    if control == "lambda0" and value <= 0:
        raise ValueError(f"lambda0 (pole stretch) must be > 0; got {value!r}")
    check_tol(tol)
    if not (isinstance(max_nodes, (int, np.integer)) and max_nodes >= 10):
        raise ValueError(f"max_nodes must be an integer >= 10; got {max_nodes!r}")
    eps = default_eps(tol) if eps is None else float(eps)
    if not 0 < eps < 0.5:
        raise ValueError(f"eps (pole start zeta = eps*Sc) must be in (0, 0.5); got {eps!r}")
    if topology not in asked():
        raise ValueError(f"topology must be one of {asked()}; got {topology!r}")
    if control == "delta":
        check_delta("delta", value, scene, tol)
    if control == "lambda0" and scene.two_contacts:
        raise ValueError("lambda0 control is not offered for a closed shell on a substrate under a curved tip "
                         "(its configurations take delta or force); give delta or force")
    if topology != "auto":
        configuration(topology).check_contact(scene)
    again = AGAIN.get(of(guess).family) if guess is not None and of(guess) is not None else None
    neighbour = None  # a valid closed state: continued in shorter steps where its cold start is not valid
    if again is not None:  # a lifted, split or wall state: its configuration solved again from it
        res = again(guess, control, value, topology=topology, tol=tol, max_nodes=max_nodes, eps=eps,
                    bc_tol=bc_tol, estimate_error=estimate_error)
        if res is not None:
            return res
        neighbour = guess if scene.two_contacts and of(guess).family == "closed" and guess.valid else None
        guess = None  # back to the cap

    near_point = None
    if guess is not None and is_point_load(guess):
        # a point-load state has no cap to start from: cold start, with the point-load limit
        # (tried where the crude caps fail) warm-started from it
        near_point, guess = guess, None

    t0 = time.perf_counter()
    kw = dict(tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    if scene.two_contacts:  # a closed shell on a substrate: its own configuration, from the flat plate's
        res = closed_cold(scene, control, value, solve_half=solve, eps=eps, **kw)
        if not (res.success and res.valid) and neighbour is not None:  # its configuration in shorter steps
            res = closed_continued(neighbour, control, value, eps=eps, **kw) or res
        if res.success and estimate_error:
            res = richardson_error(res.system, res, tol, bc_tol)
        return res.with_(wall_time=time.perf_counter() - t0)
    if guess is not None:
        sysm = system_like(guess, control, value, eps)
        res = solve_from(sysm, warm_guess(sysm, guess, tol=tol), **kw)
        if not res.success and control == "delta" and near_limit(guess):
            res = cross_convexity_limit(guess, None, value, eps=eps, **kw) or res
        sysm = res.system if res.success else sysm
    elif control == "delta":
        res = _cold_delta(make_system(scene, control, value, eps), value, near_point=near_point, **kw)
    else:
        res = _cold_other(scene, make_system(scene, control, value, eps), control, value, eps, **kw)
    for family, replace in CAP_REPLACEMENTS:
        if is_single_cap(res) and (topology == "auto" or configuration(topology).family == family):
            res = replace(res, topology, kw)
    if res.success and estimate_error:
        res = richardson_error(res.system, res, tol, bc_tol)
    else:
        res = res.with_(force_error=float("nan"), delta_error=float("nan"))
    return res.with_(wall_time=time.perf_counter() - t0)


_SC_GUESSES = (0.05, 0.2, 0.01, 0.002)
_CRUDE_MAX_NODES = 3000
_CRUDE_TOL = 1e-4


def _loose(kw):
    """Settings for getting near a solution from far away: fail fast, then tighten."""
    return dict(kw, tol=max(kw["tol"], _CRUDE_TOL), max_nodes=min(kw["max_nodes"], _CRUDE_MAX_NODES))


def _tighten(sysm, res, **kw):
    if not res.success or kw["tol"] >= _CRUDE_TOL:
        return res
    return solve_from(sysm, warm_guess(sysm, res, tol=kw["tol"]), **kw)


def _cold_delta(sysm, delta, near_point=None, **kw):
    """Crude guesses at a few cap sizes; then (smooth model) the point-load limit, or a cap
    grown from it; then continuation in delta from a moderate depth.  From ``near_point``
    (a point-load state at another depth) the point-load limit is tried first, from it and
    the undeformed shell only: the march up from a smaller depth (seconds) comes after the
    crude caps (milliseconds where they converge).

    Deeper than the continuation's start, where a cap of ``POINT_LIMIT_SC`` or more converges
    there, the continuation comes before the point-load limit: the contact is resolved at a
    smaller depth already, and the point-load march (from a tenth of the depth up) ends short
    of the depth (measured: base at 0.8 ends near 0.04, flat at 0.675 near 0.12, ~9 s of
    CPU each against 0.2-3 s for the continuation)."""
    scene, point_route = sysm.scene, sysm.scene.contact_model.point_load_limit
    if point_route and near_point is not None:
        res = _point_route(sysm, delta, near_point, march_up=False, **kw)
        if res is not None:
            return res
    best = None
    for Sc0 in _SC_GUESSES:
        res = solve_from(sysm, _undeformed_guess(sysm, math.log(Sc0), 1.0, delta), **_loose(kw))
        if res.success:
            return _tighten(sysm, res, **kw)
        best = best or res
    loose, started, start, continued = _loose(kw), False, None, None
    if point_route and near_point is None and delta > _CONTINUATION_STARTS[0]:
        started, start = True, _continuation_start(scene, sysm.eps, **loose)
        if start is not None and start.Sc >= POINT_LIMIT_SC:  # a resolved contact below: the continuation first
            continued = _continue_in_delta(scene, sysm.eps, delta, start, **loose)
            if continued is not None and continued.success and not is_point_load(continued):
                return _tighten(continued.system, continued, **kw)
            start = None  # run, and no state: not again
    if point_route and near_point is None:
        res = _point_route(sysm, delta, None, **kw)
        if res is not None:
            return res
    if not started:
        start = _continuation_start(scene, sysm.eps, **loose)
    if start is not None:
        continued = _continue_in_delta(scene, sysm.eps, delta, start, **loose)
    res = continued
    if res is not None and res.success:
        if is_point_load(res):
            return solve_point_load(scene, delta, tol=kw["tol"], max_nodes=kw["max_nodes"], guess=res)
        return _tighten(res.system, res, **kw)
    return as_failure(best, 5, STATUS_MESSAGES[5] + f" (first attempt: {best.message})")


#: Contact radii tried for a cap grown from a point-load state (:func:`_point_route`).
_SC_FROM_POINT = (1e-6, 1e-3)
#: How far a point-load state's free shell may reach above the tip's surface at a mesh node
#: and still be taken as touching it at the pole only: rounding of z = O(1) (measured
#: -2e-15 at the pole node of such states; a contact the mesh resolves shows as > 1e-8).
_POINT_CLEARANCE = 1e-12


def _point_route(sysm, delta, near_point=None, *, march_up=True, **kw):
    """The point-load limit at ``delta`` where the crude caps fail, or a cap grown from it;
    None if it does not converge or the free shell passes through the tip.

    The crude caps start at Sc = 0.002 .. 0.2; where the contact is exponentially small
    Newton runs ln Sc towards -200 and the iterate leaves double precision.  A shallow dome
    indented from its convex side is such a case throughout its early, softening range:
    sphere of radius 5, rho 0.05, beta 1e-5 (tests/test_solve.py), the cap that exists has
    Sc ~ 4e-28 at delta 0.01 and 2e-13 at 0.05 (the point force, softened, makes the
    shell's log-curvature reach the tip's only there), and it pulls: its lift-off state is
    the point-load limit (``shellbvp.liftoff.POINT_LIMIT_SC``).  The point-load problem
    has no Sc to lose, so it converges from the undeformed shell.

    Where a contact of ``POINT_LIMIT_SC`` or more exists after all, a cap started from the
    point state at ``_SC_FROM_POINT`` finds it, and it is returned instead (the caller
    replaces an invalid cap by its lift-off state as for any cap).
    """
    scene = sysm.scene
    pkw = dict(tol=kw["tol"], max_nodes=kw["max_nodes"], bc_tol=kw["bc_tol"])
    point = solve_point_load(scene, delta, guess=near_point, march_up=march_up, **pkw)
    if not point.success:
        return None
    touching = point.valid and point.penetration <= _POINT_CLEARANCE
    # a point state through the tip: the contact is about as large as where it is deepest
    sizes = _SC_FROM_POINT if touching else (_deepest_S(point), *_SC_FROM_POINT)
    for Sc in sizes:
        cap = solve_from(sysm, _cap_guess_from_point(sysm, point, Sc), **_loose(kw))
        if cap.success and cap.Sc >= POINT_LIMIT_SC:
            cap = _tighten(sysm, cap, **kw)
            if cap.success:
                return cap
    return point if touching else None


def _deepest_S(point):
    """S of the point-load state's mesh node that is deepest inside the tip."""
    prof = point.profile()
    A, B = point.system.tip_A, point.system.tip_B
    rho = point.scene.rho
    r = np.minimum(prof["r"], rho * A[-1])
    height = prof["z"] - (point.z_tip + rho * np.interp(r / rho, A, B))
    return float(prof["S"][int(np.argmax(np.where(prof["r"] < rho * A[-1], height, -np.inf)))])


def _cap_guess_from_point(sysm, point, Sc, n=81):
    """A cap of size ``Sc`` on the tip at the pole stretch of the point-load state ``point``
    (leading order of the pole series: chi = lambda0 chi(1)), its free region beyond."""
    t = np.linspace(0.0, 1.0, n)
    lambda0 = float(point.y[FREE_STATES.index("ls"), 0])
    p = sysm.pack(ln_Sc=math.log(Sc), lambda0=lambda0, delta=point.delta)
    chi0 = -sysm.model.pole_res(0.0, 0.0, 1.0, sysm.par)[0]  # chi at the pole for lambda0 = 1
    free = point.sol(np.clip(point.system.t_of(0, sysm.S(1, t, p), None), 0.0, 1.0))
    return t, np.vstack([np.full(n, lambda0 * chi0), np.full(n, lambda0), free]), p


#: Depths at which :func:`_continuation_start` tries the crude caps, in order.
_CONTINUATION_STARTS = (0.1, 0.05)


def _continuation_start(scene, eps, starts=_CONTINUATION_STARTS, **kw):
    """A cap from the crude guesses at the first of ``starts`` where one converges, or None."""
    for d in starts:
        sysm = make_system(scene, "delta", d, eps)
        for Sc0 in _SC_GUESSES:
            res = solve_from(sysm, _undeformed_guess(sysm, math.log(Sc0), 1.0, d), **kw)
            if res.success:
                return res
    return None


def _continue_in_delta(scene, eps, target, start, **kw):
    """Natural continuation in delta to ``target`` from ``start`` (:func:`_continuation_start`).

    Cold-start fallback.  Steps grow by 1.5 after a success and halve after a
    failure; downwards they are relative (delta * (1 - f)), since caps shrink
    fast as delta -> 0.
    """
    res, d = start, start.delta
    up = target > d

    def solve_at(nd, states):
        res, before = states[-1], (states[-2] if len(states) > 1 else None)
        if is_point_load(res):
            return solve_point_load(scene, nd, tol=kw["tol"], max_nodes=kw["max_nodes"], guess=res)
        sysm = system_like(res, "delta", nd, eps)
        nxt = solve_from(sysm, warm_guess(sysm, res), **kw)
        if up and not nxt.success and near_limit(res):
            nxt = cross_convexity_limit(res, before, nd, eps=eps, **kw) or nxt
        if not up and scene.contact_model.point_load_limit and (not nxt.success or nxt.Sc < SC_POINT) and res.Sc < 1e-8:
            # the cap is leaving double precision: continue with its point-load limit
            point = solve_point_load(scene, nd, tol=kw["tol"], max_nodes=kw["max_nodes"], guess=res)
            nxt = point if point.success else nxt
        return nxt

    # relative steps, delta (1 +- frac): caps shrink fast as delta -> 0
    steps = Steps(min(0.5, abs(target - d) / d) if up else 0.3,
                  advance=lambda u, f, t: min(t, u * (1 + f)) if up else max(t, u * (1 - f)),
                  grow=lambda f: min(1.5 * f, 0.5), too_small=lambda f, u: f < 1e-3)
    marched = march(d, target, solve_at, steps, history=[res])
    return marched.last if marched.reached else None


def _failure(status, message, control, value, scene):
    """A result without any state (``solution.failure``) of a cap search."""
    return failure(status, message, scene=scene, control=control, value=value, p=np.full(2, float("nan")))


_MARCH_DELTA_MAX = 1.0  # pole displacement of a rim radius: beyond any indentation test
_MARCH_MAX_SOLVES = 60


def _cold_other(scene, sysm, control, value, eps, **kw):
    """lambda0 or force prescribed: march in delta until the target is bracketed, then switch."""
    key = "lambda0" if control == "lambda0" else "force"

    def fail(message):
        return _failure(5, message, control, value, scene)

    d = 0.02
    lk = _loose(kw)
    cur = _cold_delta(make_system(scene, "delta", d, eps), d, **lk)
    if not cur.success:
        return fail(STATUS_MESSAGES[5])

    def bracketed(states):  # a point-load state's lambda0 is NaN: it brackets nothing
        if len(states) > 1 and (getattr(states[-2], key) - value) * (getattr(states[-1], key) - value) <= 0:
            return ""
        return None

    def solve_at(nd, states):
        cur, prev = states[-1], (states[-2] if len(states) > 1 else None)
        # a point-load state has no cap to warm-start from: a cold solve finds the cap or the limit again
        if is_point_load(cur):
            return _cold_delta(make_system(scene, "delta", nd, eps), nd, near_point=cur, **lk)
        dsys = system_like(cur, "delta", nd, eps)
        nxt = solve_from(dsys, warm_guess(dsys, cur), **lk)
        if not nxt.success and near_limit(cur):
            nxt = cross_convexity_limit(cur, prev, nd, eps=eps, **lk) or nxt
        return nxt

    def stop(nxt, nd, states):
        if nxt.success:
            return None
        if is_point_load(states[-1]):  # a cold solve does not start from cur: smaller steps do not help it
            return "point-load limit"
        return "tip end" if passed_tip_end(nxt) else None

    steps = Steps(0.02, advance=lambda u, s, t: u + s if u + s <= _MARCH_DELTA_MAX else None,
                  grow=lambda s: min(1.5 * s, 0.05), too_small=lambda s, u: s < 1e-3)
    m = march(d, math.inf, solve_at, steps, history=[cur], done=bracketed, stop=stop, max_solves=_MARCH_MAX_SOLVES)
    cur = m.last
    there = f"{key} there: {getattr(cur, key):.4g}"
    if m.reason == "solves":
        return fail(f"{control} = {value:g} was not bracketed within {_MARCH_MAX_SOLVES} "
                    f"continuation steps (delta reached {m.at:.3g}, {there})")
    if m.reason == "range":
        return fail(f"{control} = {value:g} was not reached on the branch for delta up to {m.at:.3g} ({there})")
    if m.reason == "point-load limit":
        return fail(f"{control} = {value:g} not reached: the states up to delta = {m.at:.3g} are point-load "
                    f"limits ({there}) and no state was found at delta = {m.tried:.3g} ({m.failed.message})")
    if m.reason == "tip end":
        return fail(f"{control} = {value:g} not reached before the contact reaches the end "
                    f"of the tip (the indenter's cylinder) near delta = {m.tried:.3g}")
    if m.reason == "step":
        return fail(f"continuation in delta towards {control} = {value:g} stalled at delta = {m.at:.3g}")
    prev, cur = m.states[-2], m.states[-1]
    start = min((prev, cur), key=lambda s: abs(getattr(s, key) - value))
    sysm = system_like(start, control, value, eps)
    return solve_from(sysm, warm_guess(sysm, start), **kw)
