"""The legs of a curve: how the continuation walks from state to state.

Each leg is a generator: it yields ``(state, order key)`` for every state it accepts (the
state the branch is at, before :class:`shellbvp.continuation.CurveRun` decides which
configuration is recorded there) and returns a :class:`Stop`.  :func:`natural` walks
requested depths by natural continuation in delta; :func:`adaptive` is the adaptive curve
(a small-delta leg down to ``delta_min``, then pseudo-arclength continuation in
``(delta, lambda0, F)``); both hand over to the wall leg where the contact reaches the
end of the tip.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from .configurations import is_point_load, is_single_cap
from .config import OPTIONS
from .corner import LEGENDRE_WATCH, edge_model, limit_estimate, near_limit
from .cylinder import best_wall_state
from .march import Steps, iter_march
from .materials import Gent
from .pointload import SC_POINT, solve_point_load
from .solution import passed_tip_end
from .state import cross_convexity_limit, make_system, solve, solve_from, system_like, warm_guess
from .steps import configuration_key, secant_guess, solve_at_delta, step_nodes

__all__ = ["Stop", "natural", "adaptive", "GENT_LOCK", "MAX_PLOT_TURN", "gent_lock_ratio", "plot_turn"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Stop:
    """Why a curve (or one leg of it) ended, and whether that is the end asked for."""

    reason: str
    complete: bool = False


def _X(sol):
    return np.array([sol.delta, sol.lambda0, sol.force])


def _first_point(scene, delta, settings):
    """The curve's first state (the single cap: the branch followed is the cap's), or a Stop."""
    sol = solve(scene, delta=delta, tol=settings.tol, max_nodes=settings.max_nodes,
                estimate_error=False, topology="cap")
    if not sol.success:
        return Stop(f"no solution at the first point delta = {delta:g}: {sol.message}")
    return sol


def _points(marching, point):
    """Run an :func:`~shellbvp.march.iter_march`, yielding ``point(state, u)`` for each accepted
    state where that is not None; returns the march's :class:`~shellbvp.march.Marched`."""
    while True:
        try:
            sol, u = next(marching)
        except StopIteration as end:
            return end.value
        p = point(sol, u)
        if p is not None:
            yield p


#: A Gent material's strain energy ``-Jm/2 ln(1 - (I1 - 3)/Jm)`` diverges as ``(I1 - 3)/Jm``
#: reaches 1 (the chains' limiting extensibility): F grows without bound before some
#: depth, and arclength steps go into F.  Past this ratio (its stiffness in I1 is 50x the
#: small-strain one) the curve stops with that physical reason instead of running into max_steps.
GENT_LOCK = 0.98


def gent_lock_ratio(sol) -> float:
    """max (I1 - 3)/Jm over a state of a Gent scene (NaN for other materials)."""
    material = sol.scene.material
    if not isinstance(material, Gent):
        return float("nan")
    prof = sol.profile()
    ls, lt = prof["lambda_s"], prof["lambda_theta"]
    return float(np.max(ls**2 + lt**2 + 1 / (ls * lt) ** 2 - 3) / material.Jm)


def _stop_rule(sol, settings):
    if settings.force_max is not None and sol.force >= settings.force_max:
        return f"force_max = {settings.force_max:g} reached"
    if settings.lambda0_max is not None and sol.lambda0 >= settings.lambda0_max:
        return f"lambda0_max = {settings.lambda0_max:g} reached"
    return None


def _physical_end(sol):
    """Why no state beyond ``sol`` can be reached on the way to delta_max, or None."""
    ratio = gent_lock_ratio(sol)
    if ratio >= GENT_LOCK:
        return (f"the Gent material locks: max (I1 - 3)/Jm = {ratio:.4f} >= {GENT_LOCK} at delta = "
                f"{sol.delta:.6g}, where F = {sol.force:.4g} grows without bound before delta_max")
    return None


def natural(scene, deltas, branch, settings, first=None, key0=0):
    """Natural continuation through ``deltas`` (from ``first``, already recorded, if given):
    yields ``(state, order key)``; returns the Stop, or None where every depth was computed."""
    if first is None:
        prev = _first_point(scene, float(deltas[0]), settings)
        if isinstance(prev, Stop):
            return prev
        yield prev, key0
    else:
        prev = first
    history = [prev]

    def solve_at(nd, states):
        prev, prev2, prev3 = (states[-k] if len(states) >= k else None for k in (1, 2, 3))
        return solve_at_delta(scene, nd, prev, prev2, settings, prev3)

    for i, target in enumerate(deltas[1:], key0 + 1):
        steps = Steps(target - prev.delta, too_small=lambda s, u, t=target: s < min(1e-6, 1e-3 * t))
        m = yield from _points(
            iter_march(prev.delta, target, solve_at, steps, history=history[-3:], position=lambda s: s.delta,
                       arrived=lambda u, t=target: not u < t,
                       stop=lambda sol, nd, states: "tip end" if passed_tip_end(sol) else None),
            lambda sol, nd, i=i, t=target: (sol, i) if nd == t else None)
        history = m.states
        prev, prev2 = history[-1], (history[-2] if len(history) > 1 else None)
        if m.reason == "tip end":
            return (yield from _wall_leg(scene, branch, settings, m.failed, i,
                                         deltas=[d for d in deltas if d > prev.delta],
                                         reason=f"the contact reached the end of the tip (the indenter's "
                                                f"cylinder) just after delta = {prev.delta:.6g}"))
        if m.reason == "step":
            return Stop(f"no solution near delta = {m.tried:.6g}: {m.failed.message}{_fold_note(prev, prev2)}")
        rule = _stop_rule(prev, settings)
        if rule:
            return Stop(rule)
        if is_single_cap(prev) and prev.Sc * prev.y[0, -1] / scene.rho > scene.tip_omega_max:
            return (yield from _wall_leg(scene, branch, settings, prev, i, deltas=[d for d in deltas if d > prev.delta],
                                         reason="the contact reached the end of the tip (the indenter's cylinder)"))
    return None  # every requested depth computed


def _fold_note(prev, prev2):
    """What the last two states say where natural continuation in delta stalls: a force
    falling with delta announces a turning point in delta (a fold; under displacement
    control the shell snaps there), which no delta-controlled step passes."""
    if prev2 is None or not prev.delta > prev2.delta:
        return ""
    slope = (prev.force - prev2.force) / (prev.delta - prev2.delta)
    if not slope < 0:
        return ""
    return (f" (the force falls with delta before it, dF/ddelta = {slope:.3g} between delta = {prev2.delta:.6g} "
            f"and {prev.delta:.6g}: likely a turning point in delta, a fold past which the shell snaps)")


def _wall_leg(scene, branch, st, last_cap, key, *, reason, deltas=None):
    """Past the cap's branch (its contact at the tip's end): follow the configurations with
    contact on the indenter's cylinder by natural continuation in delta (the valid one of
    lowest energy at each depth, from the last such state), to delta_max or through the
    remaining ``deltas``.  Yields ``(state, order key)``; returns the Stop, with ``reason`` if no
    wall state is found."""
    kw = dict(tol=st.tol, max_nodes=st.max_nodes, bc_tol=st.bc_tol)
    if st.topology != "auto" or scene.model().OMEGA_MAX is None:
        return Stop(reason, complete=True)  # the cap's branch ends at the tip's end: the end asked for
    tried = []
    targets = list(deltas) if deltas is not None else None
    prev = branch.last_wall
    if prev is None:
        outcomes = []
        prev, past_end = best_wall_state(last_cap, tried=tried, outcomes=outcomes, **kw), last_cap
        if prev is None and is_single_cap(last_cap) and _room_may_help(outcomes):
            prev, past_end = _wall_state_deeper(scene, last_cap, st, kw, tried)
        held = scene.contact_model.next
        if prev is None and held is not None and held.held_at_tip_end and is_single_cap(last_cap):
            prev = _pinned_state(scene, last_cap, last_cap.delta, st, tried)
        if prev is None:  # not a physical end: a configuration that is missing or not found
            return Stop(f"{reason}; no valid contact with the cylinder ({'; '.join(tried)})")
        branch.wall_from = (prev, past_end)  # the cap past the tip's end: where the switch is located from
        branch.last_wall = prev
        if targets is None or any(abs(prev.delta - t) < 1e-12 for t in targets):  # (a requested depth)
            key += 1
            yield prev, key
    d_end = st.delta_max if targets is None else (targets[-1] if targets else prev.delta)

    def advance(u, step, t):
        return min(t, u + step) if targets is None else min(min(d for d in targets if d > u), u + step)

    def solve_at(nxt_target, states):  # the valid wall state of lowest energy, or None
        prev = states[-1]
        tried.clear()
        sol = None
        if edge_model(prev).held_at_tip_end:  # held at the tip's end while its ring force pushes
            sol = _pinned_state(scene, prev, nxt_target, st, tried)
        return sol if sol is not None else best_wall_state(prev, control="delta", value=nxt_target, tried=tried, **kw)

    def record(sol, _):
        nonlocal key
        key += 1
        branch.last_wall = sol
        if targets is None or any(abs(sol.delta - t) < 1e-12 for t in targets):
            return sol, key
        return None

    steps = Steps(max(1e-3, (d_end - prev.delta) / 20), advance=advance, too_small=lambda s, u: s < 1e-5 * (1 + u))
    m = yield from _points(
        iter_march(prev.delta, d_end, solve_at, steps, history=[prev], position=lambda s: s.delta,
                   arrived=lambda u: not u < d_end * (1 - 1e-12), accept=lambda s: s is not None,
                   done=lambda states: _stop_rule(states[-1], st)),
        record)
    if m.reason == "step":
        return Stop(f"no valid contact configuration beyond delta = {m.at:.6g} ({'; '.join(tried)})")
    if m.reason:  # a stop rule
        return Stop(m.reason, complete=True)
    return Stop(f"delta_max = {st.delta_max:g} reached" if targets is None else "all requested deltas computed",
                complete=True)


def _pinned_state(scene, start, delta, st, tried):
    """The paper's cap held at the tip's end (``contact_edge = "pinned"``) at ``delta``, warm
    from ``start`` (a cap near or past the tip's end, or a pinned cap); None unless valid.

    Where the indenter's meridional curvature jumps (the tip meets the cylinder) the paper's
    edge can stay while the indenter pushes the edge's circle (a ring force normal to the
    shell: at a hemispherical tip's end it is radial and carries no axial force); xi = 0: from
    delta 0.9295, where the free cap's edge reaches the end, to delta 1, where no cap+cylinder
    state exists (its band on the cylinder would have a negative length)."""
    sysm = make_system(scene, "delta", delta, st.eps, edge=scene.contact_model.next)
    sol = solve_from(sysm, warm_guess(sysm, start), tol=st.tol, max_nodes=step_nodes(start, st),
                     bc_tol=st.bc_tol)
    if sol.success and sol.valid:
        return sol
    tried.append(f"cap held at the tip's end: {sol.message if not sol.success else '; '.join(sol.flags)}")
    return None


def _cross(cur, prev, delta, st):
    """The corner cap at ``delta`` past the smooth cap's convexity limit (or None)."""
    sol = cross_convexity_limit(cur, prev, delta, eps=st.eps, tol=st.tol, max_nodes=step_nodes(cur, st),
                                bc_tol=st.bc_tol, exact=False)
    if sol is not None:
        log.info("past the convexity limit near delta = %.6g: corner at the contact edge", cur.delta)
    return sol


def _room_may_help(outcomes):
    """Whether a deeper start may find the wall state that these attempts did not: only if one
    of them converged (to a state that is inadmissible, status 4, or not valid, status 0) --
    the contact running back onto the tip, which room on the cylinder cures.  Attempts that
    all end with a mesh running away (1), a singular Jacobian (2) or unmet conditions (3)
    found no state at all; going deeper then only repeats them (xi 0 with the paper's
    contact: 30 s of such attempts after the curve's last point)."""
    return any(s in (0, 4) for s in outcomes)


def _wall_state_deeper(scene, last_cap, st, kw, tried):
    """(a wall state a little deeper than ``last_cap``, the cap there), or (None, last_cap).  Just past the tip's end the
    contact's length on the cylinder is tiny and Newton from the cap lands on states whose
    contact runs back onto the tip; a few hundredths deeper it has room (paper's model, beta
    1e-3: from delta 0.94 where the end is reached at 0.915).  Deeper starts are tried while
    they may help (:func:`_room_may_help`).  The switch itself is located afterwards
    (``locate_switches``)."""
    for dd in (0.01, 0.02, 0.04, 0.08):
        if last_cap.delta + dd > st.delta_max:
            break
        deeper = solve_at_delta(scene, last_cap.delta + dd, last_cap, None, st)
        if deeper.status not in (0, 4):  # converged, possibly past the tip's end
            continue
        outcomes = []
        wall = best_wall_state(deeper, tried=tried, outcomes=outcomes, **kw)
        if wall is not None:
            return wall, deeper
        if not _room_may_help(outcomes):
            tried.append(f"no deeper start tried past delta = {deeper.delta:.6g}: no state found there")
            break
    return None, last_cap


def _land_on_delta_max(scene, cur, prev, st, key):
    """Delta-controlled solve at delta_max from the current point: yields it where it converges;
    returns (the state, the Stop that ends the curve there or None)."""
    sol = solve_at_delta(scene, st.delta_max, cur, prev, st)
    if sol.success:
        yield sol, key
        return sol, Stop(f"delta_max = {st.delta_max:g} reached", complete=True)
    return sol, None


#: The adaptive curve's steps also follow the force-displacement curve as it is plotted, on axes
#: (``delta / delta_max``, ``F / max |F|`` so far): a step whose chord turns by more than
#: MAX_PLOT_TURN (radians) from the previous chord is refused and halved, down to PLOT_TURN_MIN_DS
#: times ds_max.  The arclength itself is measured in (delta, lambda0, F), in which a shell whose
#: F is small (a thin dome: F ~ 1e-4) shows no turn where its force peaks: the dome's arclength
#: curve stepped over its force maximum (3.28e-4) from 2.93e-4 to 2.96e-4.
MAX_PLOT_TURN = 0.3
PLOT_TURN_MIN_DS = 1 / 16


def plot_turn(prev, cur, new, delta_max, force_scale):
    """Angle between the chords prev -> cur and cur -> new in (delta / delta_max, F / scale)."""
    scale = np.array([delta_max, max(force_scale, abs(new.force), 1e-300)])
    a = np.array([cur.delta - prev.delta, cur.force - prev.force]) / scale
    b = np.array([new.delta - cur.delta, new.force - cur.force]) / scale
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if not (na > 0 and nb > 0):
        return 0.0
    return _angle(np.dot(a, b) / (na * nb))


def _angle(cosine):
    """The angle (radians) of a cosine that rounding may have put just outside [-1, 1]."""
    return math.acos(min(1.0, max(-1.0, float(cosine))))


#: The small-delta leg's steps: delta times a factor 0.6, brought halfway to 1 after a failure,
#: until it exceeds 0.97.
SMALL_DELTA_STEPS = Steps(first=0.6, advance=lambda d, factor, target: max(target, d * factor),
                          grow=lambda factor: factor, shrink=lambda factor, d, tried: 1 - (1 - factor) / 2,
                          too_small=lambda factor, d: factor > 0.97)


def _small_delta_leg(scene, first, st):
    """From the first point down to delta_min (a march with :data:`SMALL_DELTA_STEPS`): yields
    ``(state, order key)``; returns ``(the first state it accepted or None, solves + 1)``."""
    solves = [1]

    def solve_at(nd, states):
        prev, prev2 = states[-1], (states[-2] if len(states) > 1 else None)
        solves[0] += 1
        if is_point_load(prev):
            return solve_point_load(scene, nd, tol=st.tol, max_nodes=st.max_nodes, guess=prev)
        sol = solve_at_delta(scene, nd, prev, prev2, st)
        if scene.contact_model.point_load_limit and not scene.two_contacts and prev.Sc < 1e-8 and \
                (not sol.success or sol.Sc < SC_POINT):
            # the cap is leaving double precision: continue with its point-load limit
            point = solve_point_load(scene, nd, tol=st.tol, max_nodes=st.max_nodes, guess=prev)
            sol = point if point.success else sol
        return sol

    marching = iter_march(first.delta, st.delta_min, solve_at, SMALL_DELTA_STEPS, history=[first],
                          max_solves=st.max_steps - 1)
    while True:
        try:
            sol, _ = next(marching)
        except StopIteration as end:
            marched = end.value
            break
        yield sol, -solves[0]
    if marched.reason == "step":
        log.info("small-delta leg stopped at delta = %.4g: %s", marched.at, marched.failed.message)
    return (marched.states[1] if len(marched.states) > 1 else None), solves[0]


def adaptive(scene, branch, settings):
    """The adaptive curve: yields ``(state, order key)``, returns the Stop."""
    st = settings
    first = _first_point(scene, st.delta_start, st)
    if isinstance(first, Stop):
        return first
    yield first, 0
    # Leg 1: down to delta_min (geometric), resolving the small-delta region.
    below, steps = yield from _small_delta_leg(scene, first, st)
    # Leg 2: pseudo-arclength upwards from the first point.
    if is_point_load(first) or scene.two_contacts:
        # the cap is below double precision there: no (delta, lambda0, F) branch to follow
        # until it comes back; natural continuation in delta instead (point-load limit or cap).
        # A closed shell on a substrate: natural continuation (shellbvp.closed)
        grid = np.linspace(first.delta, st.delta_max, 11)
        stop = yield from natural(scene, grid, branch, st, first=first, key0=steps)
        return Stop(f"delta_max = {st.delta_max:g} reached", complete=True) if stop is None else stop
    scale = np.array([1.0, 1.0, 1.0])
    cur = first
    if below is not None and below.topology != first.topology:
        below = None  # the small-delta leg went on in the point-load limit: no secant from a cap to it
    if below is None:  # need a second point for the tangent
        below = solve_at_delta(scene, first.delta * 0.9, first, None, st)
        if not below.success:
            return Stop(f"no second point near delta = {first.delta:g}: {below.message}")
    prev = below
    ds = min(st.ds_max, OPTIONS.first_step * np.linalg.norm((_X(cur) - _X(prev)) / scale))
    ds_min = 1e-4  # in (delta, lambda0, F): below this the branch is taken to end here
    force_scale = max(abs(cur.force), abs(prev.force))
    tangent = None
    crossed_from = None  # the smooth cap from which the corner was last tried
    while True:
        if steps >= st.max_steps:
            return Stop(f"max_steps = {st.max_steps} reached")
        rule = _stop_rule(cur, st)
        if rule:
            return Stop(rule, complete=True)
        end = _physical_end(cur)
        if end:
            return Stop(end)
        chord = (_X(cur) - _X(prev)) / scale
        norm = np.linalg.norm(chord)
        new_tangent = chord / norm
        if tangent is not None and np.dot(new_tangent, tangent) < 0:
            new_tangent = -new_tangent  # never reverse along the branch
        turn = 0.0 if tangent is None else _angle(np.dot(new_tangent, tangent))
        tangent = new_tangent
        Xhat = _X(cur) + ds * tangent * scale
        if Xhat[0] >= st.delta_max:
            steps += 1
            sol, stop = yield from _land_on_delta_max(scene, cur, prev, st, steps)
            if stop:
                return stop
            ds /= 2
            if ds < ds_min:
                return Stop(f"no solution at delta_max = {st.delta_max:g}: {sol.message}")
            continue
        sol = None
        crossing = near_limit(cur) and crossed_from is not cur  # the corner is tried once from each state
        if crossing:  # past the convexity limit the smooth cap ends: the corner takes over
            d_star = limit_estimate(prev, cur)
            if d_star is None or Xhat[0] > d_star:
                sol = _cross(cur, prev, Xhat[0], st)
                crossed_from = cur
        if sol is None:
            sysm = system_like(cur, "arclength", (Xhat, tangent, scale), st.eps)
            # no secant across a change of configuration (e.g. the smooth edge to the corner:
            # the states' difference is the jump forming, not the branch's direction)
            a = ds / max(norm, 1e-300) if configuration_key(cur) == configuration_key(prev) else 0.0
            guess = secant_guess(sysm, cur, prev, a)
            sol = solve_from(sysm, guess, tol=st.tol, max_nodes=step_nodes(cur, st), bc_tol=st.bc_tol)
            if not sol.success and crossing and crossed_from is not cur:
                sol = _cross(cur, prev, Xhat[0], st) or sol
                crossed_from = cur
            if not sol.success and crossed_from is cur and cur.edge_legendre < LEGENDRE_WATCH / 5:
                # at the limit, no smooth step and no corner: halving the step only stalls
                return Stop(f"continuation failed near delta = {cur.delta:.6g}: the energy loses convexity at "
                            f"the contact edge (Legendre determinant at Sc+ down to {cur.edge_legendre:.2g} of "
                            f"its mid-region value) and no corner state was found past it ({sol.message})")
        steps += 1
        if sol.success and sol.delta > st.delta_max:  # overshot: land from the current point
            steps += 1
            _, stop = yield from _land_on_delta_max(scene, cur, prev, st, steps)
            if stop:
                return stop
            ds /= 2
            continue
        if not sol.success and passed_tip_end(sol):
            return (yield from _wall_leg(scene, branch, st, sol, steps,
                                         reason=f"the contact reached the end of the tip (the indenter's "
                                                f"cylinder) just after delta = {cur.delta:.6g}"))
        if sol.success and sol.delta > 0:
            if ds > PLOT_TURN_MIN_DS * st.ds_max \
                    and plot_turn(prev, cur, sol, st.delta_max, force_scale) > MAX_PLOT_TURN:
                ds /= 2  # the force-displacement curve would bend too much in one step: a shorter one
                continue
            yield sol, steps
            force_scale = max(force_scale, abs(sol.force))
            prev, cur = cur, sol
            if sol.y[0, -1] * sol.Sc / scene.rho > scene.tip_omega_max:
                return (yield from _wall_leg(scene, branch, st, sol, steps,
                                             reason="the contact reached the end of the tip (the indenter's cylinder)"))
            # adapt: Newton effort and turning of the branch
            grow = 1.5 if sol.niter <= 3 else (1.0 if sol.niter <= 6 else 0.6)
            if turn > 0.3:
                grow = min(grow, 0.5)
            elif turn > 0.1:
                grow = min(grow, 1.0)
            ds = min(st.ds_max, ds * grow)
        else:
            ds /= 2
            if ds < ds_min:
                reason = sol.message if not sol.success else "the branch turned back to delta <= 0"
                leg = cur.edge_legendre
                if leg < 0.05 and edge_model(cur).convexity_limit:
                    reason = (f"the energy loses convexity at the contact edge (Legendre determinant at Sc+ "
                              f"down to {leg:.2g} of its mid-region value): the free region's equations "
                              f"become singular there, the smooth single-cap branch ends and no corner "
                              f"state was found ({reason})")
                return Stop(f"continuation failed near delta = {cur.delta:.6g}: {reason}")
