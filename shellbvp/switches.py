"""Where a curve switches configuration: the depth between two recorded points at which the
criterion of a switch (``shellbvp.configurations.SWITCHES``) crosses zero, found by regula
falsi on that configuration's states, and the switch onto a corner edge.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .configurations import configuration, is_single_cap, names, switch_between
from .corner import edge_model, is_corner, limit_estimate
from .cylinder import wall_state
from .liftoff import liftoff_state, pole_clearance, solve_liftoff
from .solution import cached
from .state import cross_convexity_limit, solve_from, system_like, warm_guess
from .steps import solve_at_delta, step_nodes

__all__ = ["locate_switches", "locate_corner_switch", "regula_falsi", "cap_of", "line_state_at", "cap_state_at",
           "cap_solved_at", "wall_state_at", "wall_solved_at", "lifted_solved_at", "MEASURED"]

log = logging.getLogger(__name__)


def cap_of(row):
    """The single-cap state behind a recorded point (its state, or the cap it replaced, which the
    curve keeps beside it: ``row.cap``)."""
    if is_single_cap(row.state):
        return row.state
    return row.cap


def _secant_distance(d, f, last):
    """|d - root| by the secant through (d, f) and ``last`` = (d0, f0); inf without a slope."""
    d0, f0 = last
    return abs(f * (d - d0) / (f - f0)) if f != f0 and d != d0 else math.inf


def regula_falsi(a, fa, sa, b, fb, sb, solve_at):
    """Root of f(delta) between a and b (Illinois); returns the last state with f >= 0: where
    the bracket is below 1e-7 (1 + delta) wide, or where the secant puts that state within a
    tenth of it from the root.

    Where ``solve_at`` finds no state (e.g. the cap's contact has passed the tip's end, just
    beyond a wall touch; beta 1e-3, paper model), that delta is taken as beyond the root: it
    replaces the end where f < 0 (whose f stays as a proxy) and the next point bisects."""
    best = sa if fa >= 0 else sb
    side = 0
    bisect, failures = False, 0
    last = (a, fa) if abs(fa) < abs(fb) else (b, fb)  # the latest true value of f (Illinois halves the ends')
    for _ in range(40):
        d = 0.5 * (a + b) if bisect else (a * fb - b * fa) / (fb - fa)
        sol, f = solve_at(d, sa if abs(d - a) < abs(d - b) else sb)
        bisect = sol is None
        if sol is None:
            failures += 1
            if fa < 0:
                a = d
            else:
                b = d
            side = 0
        else:
            if f >= 0:
                best = sol
                # the secant through the last two values puts the root within a tenth of the
                # tolerance of this state: another solve would only confirm it (2 of 9 solves
                # of base d40's two switch searches)
                if _secant_distance(d, f, last) < 1e-8 * (1 + abs(d)):
                    break
            last = (d, f)
            if f * fb > 0:
                b, fb, sb = d, f, sol
                fa = fa / 2 if side == -1 else fa
                side = -1
            else:
                a, fa, sa = d, f, sol
                fb = fb / 2 if side == 1 else fb
                side = 1
        if failures > 3 or abs(b - a) < 1e-7 * (1 + abs(d)) or f == 0:  # on delta: criteria's slopes differ
            break
    return best


def locate_switches(builder, st):
    """Add the point where the recorded topology switches between neighbouring points.

    Each switch is declared in ``shellbvp.configurations.SWITCHES``: the configuration whose
    criterion crosses zero there (cap <-> line, annulus or cap+line(tip): the cap's minimum
    contact pressure; line <-> cap+line(tip): the lifted pole's clearance above the tip;
    line <-> annulus and the line <-> band on the cylinder: the line's curvature excess over
    the indenter; cap <-> contact on the cylinder: the free shell's gap to the cylinder, or the
    contact's margin to the tip's end).  The root is found by regula falsi (Illinois) on that
    configuration's states; the point is added to an adaptive curve, and every switch is
    handed to ``builder.switch_located`` (the curve lists them in ``settings["topology_switches"]``;
    ``st``, the :class:`~shellbvp.curve_settings.CurveSettings`, is only read).  The corner edge and
    the paper cap held at the tip's end are located from the caps' edge models.
    """
    scene = builder.out.scene
    rows = sorted(builder.rows, key=lambda r: r[0])

    def cap_at(d, near):
        return solve_at_delta(scene, d, near, None, st)

    def cap_end_at(d, near):  # the cap whose contact edge is at the tip's end
        sol = cap_at(d, near)
        return (sol, sol.tip_end_margin) if sol.status in (0, 4) else (None, None)

    def state_of(on, row):  # the measured configuration's state at a recorded point's depth
        return MEASURED[configuration(on).family][0](row, on, st)

    def solve_on(on):  # ... and solved at another depth from a neighbour
        solve = MEASURED[configuration(on).family][1]
        return lambda d, near: solve(scene, on, d, near, st)

    for r1, r2 in zip(rows[:-1], rows[1:]):
        (k1, s1), (k2, s2) = (r1.key, r1.state), (r2.key, r2.state)
        c1, c2 = cap_of(r1), cap_of(r2)
        if c1 is not None and c2 is not None and c1.success and c2.success \
                and edge_model(c1).leads_to(edge_model(c2)) and edge_model(c2).jumps:
            builder.switch_located(locate_corner_switch(c1, c2, st))
            continue
        if s1.valid and s2.valid and edge_model(s1).leads_to(edge_model(s2)) and edge_model(s2).held_at_tip_end:
            # the free cap's edge reaches the tip's end: from the caps either side of it
            ends = [s1, r2.cap]
            if ends[1] is not None and ends[1].status in (0, 4) and ends[0].tip_end_margin > 0 > ends[1].tip_end_margin:
                best = regula_falsi(ends[0].delta, ends[0].tip_end_margin, ends[0], ends[1].delta,
                                     ends[1].tip_end_margin, ends[1], cap_end_at)
                _add_switch(builder, st, best, "cap", "cap (pinned at the tip's end)", k1, k2,
                            "tip_end_margin")
            continue
        frm, to = s1.topology, s2.topology
        switch = switch_between(frm, to)
        if not (s1.valid and s2.valid) or switch is None:
            continue
        on = switch.measured_on
        ends = [r.state if r.state.topology == on else state_of(on, r) for r in (r1, r2)]
        if switch.criteria == ("pole_clearance",):
            ends = [_with_pole_clearance(e) for e in ends]
            if any(e is None for e in ends) or not ends[0].pole_clearance * ends[1].pole_clearance < 0:
                # a line recorded as valid may have its pole down on the tip already (to 10 tol), and the
                # split state may have no line at its depth: the touch-down then lies between two of the
                # line points before it
                bracket = _touchdown_bracket([r[3] for r in rows], min(s1.delta, s2.delta))
                if bracket is not None:  # the switch point goes between those two, in branch order
                    ends = list(bracket)
                    k1, k2 = (next(r[0] for r in rows if r[3] is e) for e in bracket)
        if any(e is None for e in ends):
            continue
        criterion = next((c for c in switch.criteria if all(math.isfinite(getattr(e, c)) for e in ends)),
                         switch.criteria[-1])
        e1, e2 = sorted(ends, key=lambda e: e.delta)
        f1, f2 = (switch.sign * _criterion_value(e, criterion) for e in (e1, e2))
        if not f1 * f2 < 0:
            continue

        def solve_at(d, near, solve=solve_on(on), criterion=criterion, sign=switch.sign):
            sol = solve(d, near)
            usable = sol.status in (0, 4) if criterion == "tip_end_margin" else sol.success
            if usable and criterion == "pole_clearance":
                _with_pole_clearance(sol)
            if not usable or math.isnan(_criterion_value(sol, criterion)):
                return None, None
            return sol, sign * _criterion_value(sol, criterion)

        best = regula_falsi(e1.delta, f1, e1, e2.delta, f2, e2, solve_at)
        _add_switch(builder, st, best, frm, to, k1, k2, criterion)


def locate_corner_switch(smooth, corner, st, h=0.003):
    """Where the corner takes over from the smooth cap, located from both sides.

    From the smooth side: the depth where edge_legendre reaches 0 (quadratic through smooth
    caps at delta* - h, - 2h, - 3h, delta* first estimated linearly); from the corner side:
    where the jump of lambda_s at the edge reaches 0 (quadratic through three corner caps h
    apart from the first found past the limit, stepping away from it: Newton does not
    converge stepping from a corner towards the limit).  They agree when the corner grows
    out of the smooth branch (a continuous switch); F and E extrapolated from each side give
    their jumps at the switch.
    """
    kw = dict(tol=st.tol, max_nodes=step_nodes(smooth, st), bc_tol=st.bc_tol)  # fail fast
    sysm = system_like(smooth, "delta", 0.98 * smooth.delta, st.eps)
    d0 = limit_estimate(solve_from(sysm, warm_guess(sysm, smooth), **kw), smooth)
    d0 = d0 if d0 is not None and smooth.delta < d0 < corner.delta else 0.5 * (smooth.delta + corner.delta)
    lo = [smooth]
    for d in sorted((d0 - k * h for k in (1, 2, 3)), key=lambda d: abs(d - smooth.delta)):
        sysm = system_like(lo[-1], "delta", d, st.eps)
        s = solve_from(sysm, warm_guess(sysm, lo[-1]), **kw)
        if s.success and edge_model(s).convexity_limit:
            lo.append(s)
    lo = sorted(lo[1:], key=lambda s: s.delta)
    first = cross_convexity_limit(lo[-1], lo[0] if len(lo) > 1 else None, d0 + h, eps=st.eps, exact=False,
                                  **kw) if lo else None
    hi = [first] if first is not None and is_corner(first, st.tol) else []
    for k in (1, 2):
        if hi:
            sysm = system_like(hi[-1], "delta", hi[0].delta + k * h, st.eps)
            s = solve_from(sysm, warm_guess(sysm, hi[-1]), **kw)
            if is_corner(s, st.tol):
                hi.append(s)

    def root(states, key):
        x = np.array([s.delta for s in states])
        yv = np.array([getattr(s, key) for s in states])
        c = np.polyfit(x, yv, min(2, len(x) - 1))
        r = np.roots(c)
        r = r[np.isreal(r)].real
        return float(r[np.argmin(np.abs(r - d0))]) if r.size else math.nan

    def value_at(states, key, d):
        x = np.array([s.delta for s in states])
        return float(np.polyval(np.polyfit(x, [getattr(s, key) for s in states], min(2, len(x) - 1)), d))

    d_smooth = root(lo, "edge_legendre") if len(lo) >= 2 else math.nan
    d_corner = root(hi, "edge_jump_ls") if len(hi) >= 2 else math.nan
    d_star = d_smooth if math.isfinite(d_smooth) else d_corner
    f_lo, f_hi, e_lo, e_hi = (value_at(states, key, d_star) if len(states) >= 2 else math.nan
                              for key in ("force", "energy") for states in (lo, hi))
    if not (math.isfinite(d_smooth) and math.isfinite(d_corner)):
        kind = "not determined (the states either side of the limit did not converge)"
    elif abs(d_smooth - d_corner) <= 1e-2 * d_star:
        kind = "continuous: the corner grows from a zero jump at the convexity limit"
    else:
        kind = "first-order: the corner appears with a finite jump"
    log.info("switch to the corner edge at delta = %.6g (%s)", d_star, kind)
    return {"delta": d_star, "force": f_lo, "from": "cap", "to": "cap (corner edge)", "criterion": "edge_legendre",
            "value": 0.0, "kind": kind, "delta_from_jump": d_corner, "force_jump": f_hi - f_lo,
            "energy_jump": e_hi - e_lo,
            "jump_ls_after": float(corner.edge_jump_ls)}


# -- how a switch criterion is measured on a configuration of each family (``MEASURED``) ---------
def cap_state_at(row, topology, st):
    """The single cap at a recorded point's depth (its state, or the cap it replaced)."""
    return cap_of(row)


def cap_solved_at(scene, topology, d, near, st):
    return solve_at_delta(scene, d, near, None, st)


def wall_state_at(row, topology, st):
    """The ``topology`` wall state at a recorded wall point's delta (from it), or None."""
    line = wall_state(row.state, topology, tol=st.tol, max_nodes=st.max_nodes, bc_tol=st.bc_tol)
    return line if line.success and not math.isnan(line.curvature_excess) else None


def wall_solved_at(scene, topology, d, near, st):
    return wall_state(near, topology, control="delta", value=d, tol=st.tol, max_nodes=st.max_nodes,
                      bc_tol=st.bc_tol)


def lifted_solved_at(scene, topology, d, near, st):
    return solve_liftoff(scene, topology, delta=d, guess=near, tol=st.tol, max_nodes=st.max_nodes,
                         bc_tol=st.bc_tol)


def _touchdown_bracket(states, delta):
    """The two line states, not deeper than ``delta``, between which a line's lifted pole comes
    down onto the tip (its clearance crosses zero), or None."""
    lines = sorted((_with_pole_clearance(s) for s in states
                    if s.topology in names("lifted", having="line_contact") and s.success and s.delta <= delta),
                   key=lambda s: s.delta)
    for a, b in reversed(list(zip(lines[:-1], lines[1:]))):
        if a.pole_clearance > 0 > b.pole_clearance:
            return a, b
    return None


def _with_pole_clearance(line):
    """``line`` with its ``pole_clearance`` (computed once, kept on it: :func:`~shellbvp.solution.cached`;
    None passes).  The touch-down of a lifted pole is located on this gap, which closes
    transversally, not on the free shell's penetration: that one is the largest over the shell
    and sits at the contact line, where the shell touches tangentially, so near zero it is noise
    at the tabulated tip's accuracy."""
    return None if line is None else cached(line, "pole_clearance", pole_clearance)


def line_state_at(row, topology, st):
    """The line state (``topology``) at a lift-off point's delta (the one its search converged,
    kept beside it: ``row.line``, else from its cap), or None."""
    line = row.line
    if line is not None and line.topology == topology and line.success and not math.isnan(line.curvature_excess) \
            and line.delta == row.state.delta:
        return line
    cap = cap_of(row)
    if cap is None:
        return None
    line = liftoff_state(cap, topology, tol=st.tol, max_nodes=st.max_nodes, bc_tol=st.bc_tol)
    return line if line.success and not math.isnan(line.curvature_excess) else None


def _criterion_value(state, criterion):
    """A switch criterion of a state; ``wall_gap`` is inf where nothing is above the tip's end:
    capped at 1."""
    value = getattr(state, criterion)
    return min(value, 1.0) if criterion == "wall_gap" else value


def _add_switch(builder, st, best, frm, to, k1, k2, criterion):
    builder.switch_located({"delta": float(best.delta), "force": float(best.force), "from": frm, "to": to,
                            "criterion": criterion, "value": float(getattr(best, criterion))})
    log.info("topology switch %s -> %s at delta = %.6g", frm, to, best.delta)
    already = any(abs(r[3].delta - best.delta) <= 1e-12 * (1 + best.delta) for r in builder.rows)
    if st.mode == "adaptive" and not already:  # a curve at requested depths keeps exactly those
        builder.add(best, 0.5 * (k1 + k2))


#: How a switch criterion is measured on a configuration of each family (``Switch.measured_on``):
#: ``state_at(row, name, settings)``, its state at a recorded point's depth (``row``: the point's
#: :class:`~shellbvp.recorder.Row`; None if there is none), and ``solved_at(scene, name, delta,
#: near, settings)``, its state at another depth from a neighbour.  Every switch is measured on a
#: configuration of one of these families (a test checks it).
MEASURED = {"cap": (cap_state_at, cap_solved_at), "lifted": (line_state_at, lifted_solved_at),
            "wall": (wall_state_at, wall_solved_at)}
