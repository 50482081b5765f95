"""States whose contact has lifted off at the pole: annular and line contact.

Where the single-cap state needs a negative contact pressure near the pole
(the indenter would have to pull the shell), the shell leaves the indenter
there: a free inner cap around the pole, then contact on an annulus
``[S1, S2]`` (``topology="annulus"``) or on one circle (``"line"``, a
zero-width annulus carrying a ring force), then the outer free region.  The
systems are the chains of ``shellbvp/configurations/annulus.py`` and ``line.py``; this module makes guesses,
runs solve_bvp and diagnoses the result into a :class:`~shellbvp.state.Solution`
with the same fields as a cap state, plus ``S1`` (inner edge), ``ring_force_inner``,
``contact_width`` and, for a line, ``curvature_excess`` (kappa_s at the line minus the
tip's: > 0 means the shell bends through the tip and the contact is an annulus).
``Sc`` is the outer contact edge.

Topology selection (:func:`valid_liftoff_state`) starts from an invalid cap: the line
first (or the topology of the previous point), then the annulus where a pressed band
is possible, and the point-load limit for contact circles below ``POINT_LIMIT_SC``.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .chain import ChainBVP
from .configurations import configuration, is_single_cap, names
from .march import Steps, march
from .config import OPTIONS
from .cylinder import solve_chain_from, transfer_guess
from .pointload import solve_point_load
from .solution import (
    RESIDUAL_ORDER,
    Solution,
    attach_tip_table,
    default_eps,
    finished,
    inadmissible,
    richardson_error,
    secant_ratio,
    warm_mesh,
)

__all__ = ["solve_liftoff", "solve_liftoff_from", "make_liftoff_system", "liftoff_guess_from_cap",
           "liftoff_warm_guess", "liftoff_state", "valid_liftoff_state", "lift_off_suspected",
           "replace_invalid_cap", "lifted_replacement", "pole_clearance", "split_state_from", "moved_guess",
           "lifted_again", "split_again", "cap_lifted_off", "searched_lifted"]


def searched_lifted() -> tuple:
    """The lifted-pole configurations that this module solves and searches, in the registry's
    order: those of the family that ``solve(topology=...)`` may ask for (``line+corner`` is
    declared, not searched)."""
    return names("lifted", having="askable")


def make_liftoff_system(scene, topology, control, value, eps):
    """The system of a lifted-pole configuration (``shellbvp.configurations``, family "lifted")."""
    lifted = searched_lifted()
    if topology not in lifted:
        raise ValueError(f"topology must be one of {lifted}; got {topology!r}")
    return configuration(topology).system(scene, control, value, eps)


# -- guesses --------------------------------------------------------------------------------
def _cap_states_at(cap, S):
    """Contact states (chi, ls) of a cap solution at S inside its cap."""
    csys = cap.system
    return cap.sol(np.clip(csys.t_of(0, S, cap.p), 0.0, 1.0))[csys.rows(0)]


def _cap_as_free(cap, S):
    """Free-region states (lt, phiS, ls, ks, rQ, z) of a cap solution inside its cap."""
    csys = cap.system
    pc = csys.model.contact_profile(S, _cap_states_at(cap, S), csys.par)
    return np.vstack([pc["lambda_theta"], pc["phi"] / S, pc["lambda_s"], pc["kappa_s"],
                      pc["r"] * pc["Q"], pc["z"] + cap.z_tip])


def _cap_free_at(cap, S):
    csys = cap.system
    return cap.sol(np.clip(csys.t_of(1, S, cap.p), 0.0, 1.0))[csys.rows(1)]


def liftoff_guess_from_cap(sysm: ChainBVP, cap: Solution, S1_fraction: float, n: int = 81):
    """Guess from a cap state: the pole region ``S < S1 = S1_fraction * Sc`` taken off the tip.

    Annulus: contact on ``[S1, Sc]``; line: the contact circle at S1.
    """
    Sc = cap.Sc
    S1 = S1_fraction * Sc
    t = np.linspace(0.0, 1.0, n)
    delta = cap.delta
    if configuration(sysm.topology).inner_edge:
        p = sysm.pack(ln_S1=math.log(S1), ln_S2=math.log(Sc), delta=delta)
        Sin, Scont, Sout = sysm.S(0, t, p), sysm.S(1, t, p), sysm.S(2, t, p)
        y = np.vstack([_cap_as_free(cap, Sin), _cap_states_at(cap, Scont), _cap_free_at(cap, Sout)])
    else:
        chi1 = float(_cap_states_at(cap, np.array([S1]))[0, 0])
        p = sysm.pack(ln_S1=math.log(S1), chi1=chi1, delta=delta)
        Sin, Sout = sysm.S(0, t, p), sysm.S(1, t, p)
        outer = np.where(Sout <= Sc, _cap_as_free(cap, np.minimum(Sout, Sc)), _cap_free_at(cap, Sout))
        y = np.vstack([_cap_as_free(cap, Sin), outer])
    return t, y, p


def liftoff_warm_guess(sysm: ChainBVP, prev: Solution, before: Solution | None = None, delta=None):
    """A neighbouring lift-off state of the same topology on its warm-start mesh; with ``before``
    (the state before ``prev`` on the curve, same topology) and the target ``delta``, moved
    along their secant to that depth (states, unknowns and delta)."""
    a = secant_ratio(delta, prev, before) if delta is not None else None
    return moved_guess(sysm, prev, before, a)


def moved_guess(sysm, prev, before=None, a=None):
    """``prev`` on its warm-start mesh, moved by ``a`` times (prev - before) when both are given
    (states, unknowns, delta and lambda0 -- whichever the system takes)."""
    x = warm_mesh(prev)
    q = dict(zip(prev.system.unknowns, prev.p), delta=prev.delta, lambda0=prev.lambda0)
    y = prev.sol(x)
    if before is not None and a is not None:
        qb = dict(zip(before.system.unknowns, before.p), delta=before.delta, lambda0=before.lambda0)
        q = {k: v + a * (v - qb[k]) for k, v in q.items()}
        y = y + a * (y - before.sol(x))
    return x, y, sysm.pack(**q)


# -- solving --------------------------------------------------------------------------------
def solve_liftoff(scene, topology, *, delta=None, force=None, lambda0=None, guess, tol=1e-6,
                  max_nodes=10000, eps=None, bc_tol=1e-10, estimate_error=False):
    """One annular or line-contact state from a guess.

    ``guess`` is a lift-off Solution of the same topology (warm start), or an
    ``(x, y, p)`` tuple made for this system (see :func:`liftoff_guess_from_cap`).
    Exactly one of ``delta`` (indenter displacement), ``force`` or ``lambda0`` (the
    stretch at the lifted pole) is prescribed.
    """
    given = [(k, v) for k, v in (("delta", delta), ("force", force), ("lambda0", lambda0)) if v is not None]
    if len(given) != 1:
        raise ValueError("give exactly one of delta, force or lambda0")
    (control, value), = given
    eps = default_eps(tol) if eps is None else eps
    t0 = time.perf_counter()
    sysm = make_liftoff_system(scene, topology, control, value, eps)
    if isinstance(guess, Solution):
        guess = liftoff_warm_guess(sysm, guess)
    res = solve_liftoff_from(sysm, guess, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    if res.success and estimate_error:
        res = richardson_error(sysm, res, tol, bc_tol)
    return res.with_(wall_time=time.perf_counter() - t0)


#: One run of a lift-off system from ``(x, y, p)``, diagnosed (the same for every chain).
solve_liftoff_from = solve_chain_from


# -- topology selection ------------------------------------------------------------------------
#: Below this ratio S1/S2 an annulus has reached the pole: it is the cap.
ANNULUS_CLOSED_AT_POLE = 1e-3


#: Below this contact radius a lifted-off state is taken as its point-load limit.
POINT_LIMIT_SC = 1e-8


def lift_off_suspected(cap: Solution) -> bool:
    """The cap state asks the indenter to pull: negative pressure or normal ring force (at a
    corner edge the axial ring force also carries the tangential force [tau_s] = -kappa [M_s],
    so its sign is not the test)."""
    normal = cap.edge_forces or [cap.ring_force]
    return bool(cap.success and is_single_cap(cap)
                and (cap.pressure_min < 0 or min(normal) < 0))


#: A lift-off state is continued from the previous one of its topology (``previous``) first
#: when their depths differ by at most this fraction of the larger; farther, the cap is the
#: better guess.
WARM_REACH = 0.5
#: Node budget of that warm start, in multiples of the previous state's mesh: a neighbour
#: needs about its own mesh, and a start that does not converge must fail fast.
WARM_NODES = 3


def _near(state, cap, topology):
    return (state is not None and state.topology == topology and state.success
            and abs(state.delta - cap.delta) <= WARM_REACH * max(state.delta, cap.delta))


def liftoff_state(cap: Solution, topology: str, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10,
                  previous: Solution | None = None, before: Solution | None = None):
    """The ``topology`` state at the cap's delta (or force), from ``previous`` or from the cap.

    ``previous`` (and ``before`` it) are the last lift-off states of a curve: when
    ``previous`` has this topology and a nearby depth (``WARM_REACH``), the state is
    continued from it first (along the secant through ``before`` when that is near too),
    with a node budget of ``WARM_NODES`` times its mesh; else, or if that fails, from
    guesses made from the cap, then from ``previous`` as it is.

    Returns a Solution (check ``success`` and ``valid``).  An annulus whose inner edge
    runs to the pole is the cap itself: it is returned as a failure saying so.
    """
    control = cap.control if cap.control in ("force", "lambda0") else "delta"
    value = {"force": cap.force, "lambda0": cap.lambda0, "delta": cap.delta}[control]
    sysm = make_liftoff_system(cap.scene, topology, control, value, cap.system.eps)
    # Far from a neighbour the cap is the better guess (the lift-off state is close to it
    # near the switch and its contact edge is where the cap's is).  A node budget of a few
    # times the cap's makes hopeless starts fail fast.
    kw = dict(tol=tol, max_nodes=int(min(max_nodes, max(2000, 4 * cap.nodes))), bc_tol=bc_tol)
    attempt = _solve_annulus if configuration(topology).inner_edge else solve_liftoff_from
    tries = []
    warm = OPTIONS.warm_first and _near(previous, cap, topology)
    if warm:
        secant = before if control == "delta" and _near(before, cap, topology) else None
        guess = liftoff_warm_guess(sysm, previous, secant, cap.delta if secant is not None else None)
        budget = int(min(kw["max_nodes"], WARM_NODES * previous.nodes))
        tries.append(attempt(sysm, guess, **dict(kw, max_nodes=budget)))
        if tries[-1].success and not _closed_at_pole(tries[-1]):
            return tries[-1]
    # The annulus equations also hold, degenerately, for the cap (S1 -> 0): Newton may run
    # there from one guess and find a true annulus from another, so every guess is tried.
    for frac in ((0.5, 0.9) if configuration(topology).inner_edge else (0.9, 0.5)):
        tries.append(attempt(sysm, liftoff_guess_from_cap(sysm, cap, frac), **kw))
        if tries[-1].success and not _closed_at_pole(tries[-1]):
            break
    else:
        if previous is not None and previous.topology == topology and not warm:
            tries.append(attempt(sysm, liftoff_warm_guess(sysm, previous), **kw))
    good = [r for r in tries if r.success and not _closed_at_pole(r)]
    closed = [r for r in tries if _closed_at_pole(r)]
    res = good[0] if good else (closed[0] if closed else tries[-1])
    if _closed_at_pole(res):
        res = inadmissible(res, f"the annulus reaches the pole (S1/S2 = {math.exp(res.p[0] - res.p[1]):.2g}): "
                                f"the state is the single cap")
    return res


def _closed_at_pole(res):
    """The annulus's inner edge has run to the pole: S1/S2 below ANNULUS_CLOSED_AT_POLE, read
    from the unknowns (ln S1, ln S2) -- of the converged state, or of the last iterate of a run
    that did not converge (Newton walking ln S1 down is how such a run fails)."""
    if not configuration(res.topology).inner_edge or res.p is None or len(res.p) < 2:
        return False
    ratio = math.exp(min(0.0, float(res.p[0]) - float(res.p[1])))
    return bool(math.isfinite(res.p[0]) and math.isfinite(res.p[1]) and ratio < ANNULUS_CLOSED_AT_POLE)


#: Probes (an annulus; a second zone, :func:`_probe_then_solve`): loose and small, so that a
#: guess that leads nowhere is seen fast; and short: probes that converged took at most 10
#: Jacobians, those that ran an annulus to the pole or found no split took solve_bvp's whole 10
#: restarts of Newton (33-39 Jacobians; 0.15 s each on base at 0.1125, 0.3 s on gamma -2).
_PROBE_TOL, _PROBE_NODES, _PROBE_JACOBIANS = 1e-3, 600, 16


def _solve_annulus(sysm, guess, *, tol, max_nodes, bc_tol):
    """Probe at a loose tolerance first: an annulus closing onto the pole makes Newton
    walk ln S1 down while solve_bvp adds nodes (seconds at tol 1e-6); the probe shows it
    in a fraction of that.  Then tighten from the probe."""
    probe = solve_liftoff_from(sysm, guess, tol=max(tol, _PROBE_TOL), max_nodes=min(max_nodes, _PROBE_NODES),
                               bc_tol=bc_tol, max_jacobians=_PROBE_JACOBIANS)
    if _closed_at_pole(probe):
        return probe
    if probe.success:
        return probe if tol >= _PROBE_TOL else solve_liftoff_from(
            sysm, liftoff_warm_guess(sysm, probe), tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    return solve_liftoff_from(sysm, guess, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)


def valid_liftoff_state(cap: Solution, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10, previous=None, before=None,
                        last=None):
    """A valid line or annular state where the cap is invalid: (state or None, what was tried,
    the line converged at a split state's depth or None, :func:`_line_beside`).

    A contact radius below ``POINT_LIMIT_SC`` is taken as its point-load limit
    (exponentially close; a line that small strains double precision in its inner cap).
    ``last``: the curve's previous point, if any; where it had its pole lifted and the line
    here still holds its pole above the tip, the split cap+line(tip) is not probed
    (:func:`_split_possible`).
    """
    tried = []
    # (a cap on an arclength step has its delta too: the curve's caps are such)
    if cap.Sc < POINT_LIMIT_SC and cap.control in ("delta", "arclength"):
        res = solve_point_load(cap.scene, cap.delta, tol=tol, max_nodes=max_nodes, guess=cap, bc_tol=bc_tol)
        if res.success and res.valid:
            return res, tried, None
        tried.append("point load: " + (res.message if not res.success else "; ".join(res.flags)))
    order = searched_lifted()
    if previous is not None and previous.topology in order:
        order = (previous.topology,) + tuple(t for t in order if t != previous.topology)
    line_too_curved = False
    line = None
    split_tried = False

    def split_here():  # the cap+line(tip) state from the cap and the line tried here, if valid
        res = second_zone_state(cap, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol, previous=previous,
                                before=before, line=line)
        if res.success and res.valid:
            return res
        tried.append(f"{res.topology}: {res.message if not res.success else '; '.join(res.flags)}")
        return None

    for topology in order:
        if configuration(topology).inner_edge and not (line_too_curved or _pressed_somewhere(cap)):
            # an annulus needs a pressed band: where the whole cap pulls and the line is not
            # bent through the tip, Newton only walks its inner edge to the pole (seconds)
            tried.append("annulus: not tried (the cap pulls everywhere)")
            continue
        if configuration(topology).inner_edge and OPTIONS.split_first and _pole_down(line, tol) and _pressed_at_the_pole(cap):
            split_tried = True
            split = split_here()
            if split is not None:
                return split, tried, _line_beside(line)
        res = liftoff_state(cap, topology, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol, previous=previous,
                            before=before)
        if res.success and res.valid:
            return res, tried, None
        line_too_curved |= configuration(topology).line_contact and res.curvature_excess > 0
        line = res if configuration(topology).line_contact else line
        why = res.message if not res.success else "; ".join(res.flags)
        tried.append(f"{topology}: {why}")
    if split_tried or not _pressed_at_the_pole(cap):
        return None, tried, None
    if OPTIONS.split_rule and not _split_possible(last, line, tol):
        tried.append("cap+line(tip): not tried (the pole was lifted at the previous point and the line here "
                     "keeps it above the tip)")
        return None, tried, None
    split = split_here()
    return split, tried, (_line_beside(line) if split is not None else None)


def _line_beside(line):
    """The (invalid) line converged at a split state's depth, which the caller keeps beside it:
    the switch line -> cap+line(tip) is located from it (``switches.line_state_at``), not solved
    again; None where it did not converge."""
    return line if line is not None and line.success else None


def _pole_down(line, tol) -> bool:
    """A converged line whose lifted pole is down on the tip (to 10 tol): the lifted-pole
    family ends there, and the contact splits into a cap and the line (cap+line(tip)).  An
    annulus lifts the pole as the line does, so it is probed after the split: base at delta
    0.1125 (the line also too curved) spent 34 ms of a 0.5 s curve on two annulus probes that
    ran onto the pole, before the split converged at once."""
    return bool(line is not None and line.success and pole_clearance(line) <= 10 * tol)


def _split_possible(last, line, tol):
    """Whether a cap+line(tip) state may be what follows the curve's previous point ``last``.

    The split (a cap at the pole, a lifted gap, a line further out) grows either from a cap
    whose edge starts to pull, or from a line whose lifted pole comes down onto the tip.  So
    after a point with the pole lifted (a valid line or annulus) it is probed only when the
    line at this depth touches the tip inside its contact circle (``penetration``), or did
    not converge.  Without this, base at delta 0.1125 (after the line at 0.1; the line too
    curved here, the cap still pulling at its edge) spent 1.7 s of a 4.7 s curve on split
    guesses that find no state.  Without ``last`` (a single solve) it is always probed."""
    if last is None or not (last.valid and last.topology in searched_lifted()):
        return True
    if line is None or not line.success:
        return True
    return bool(not line.penetration <= 10 * tol or pole_clearance(line) <= 10 * tol)


def pole_clearance(state) -> float:
    """Height of the tip's apex above a lifted pole (the gap there; <= 0 where the pole is down
    on the tip to the solver's accuracy): where the lifted pole of a line comes down, the
    contact splits into a cap and the line (base at delta 0.1125: -1e-8; Gent 0.03 at 0.119:
    -3e-8)."""
    prof = state.profile()
    return float(state.z_tip - prof["z"][0])


#: (Sc'/S_p, S1/Sc) of second-zone guesses from a cap pressed at the pole and pulling further out
#: (S_p: where its pressure first turns negative; the ring at the cap's old edge Sc)
_SECOND_ZONE_SPLITS = ((1.0, 1.0), (0.9, 1.0), (0.7, 1.0), (1.0, 0.97))


def _pressed_at_the_pole(cap):
    prof = cap.profile()
    P = prof["P"][prof["region"] == 0]
    return bool(P.size and P[0] > 0 and np.min(P) < 0)


#: S_c/S1 of second-zone guesses from a line state whose lifted pole has come down
_SECOND_ZONE_FROM_LINE = (0.7, 0.5)


def second_zone_state(cap: Solution, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10, previous=None, before=None,
                      line=None):
    """Where the cap is pressed at the pole but would pull further out: the contact splits into
    a smaller cap and, beyond a lifted gap, a line on the tip (``cap+line(tip)``) where the cap's
    edge was; from ``previous`` (the same configuration; along the secant through ``before``
    when that is one too) when given, else a few guesses from ``line`` (the line state at this
    depth, if one converged) and from the cap.  Returns a Solution (check ``success`` and
    ``valid``)."""
    t0 = time.perf_counter()
    control = cap.control if cap.control in ("force",) else "delta"
    value = cap.force if control == "force" else cap.delta
    scene, rho = cap.scene, cap.scene.rho
    sysm = configuration("cap+line(tip)").system(scene, control, value, cap.system.eps)
    kw = dict(tol=tol, max_nodes=int(min(max_nodes, max(2000, 4 * cap.nodes))), bc_tol=bc_tol)
    if _near(previous, cap, sysm.topology) and control == "delta":
        # near the closing of the gap (beta 0.1: S_c/S1 -> 1 at delta 0.394) the unknowns move
        # fast and a guess re-sampled from another state fails; the state itself on its mesh,
        # moved along the secant, and shorter steps towards the depth when that fails, do not
        # (its own node budget, not one from the cap's mesh: since warm meshes the caps there have
        # ~380 nodes, so 4x that, and the split needs ~2200 near the closing)
        res = _continue_in_delta(sysm, previous, before if _near(before, cap, sysm.topology) else None,
                                 cap.delta, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
        if res is not None:
            return res.with_(wall_time=time.perf_counter() - t0)
    guesses = []
    if previous is not None and previous.topology == sysm.topology:
        q = dict(zip(previous.system.unknowns, previous.p))
        guesses.append(transfer_guess(sysm, previous, ln_Sc=q["ln_Sc"], ln_S1=q["ln_S1"], chi1=q["chi1"]))
    if line is not None and line.success and line.topology in names("lifted", having="line_contact"):
        # a lifted pole coming down inside the line (base at delta 0.1125: the guesses from
        # the cap below leave the model's domain; from the line, 0.7 S1, it converges at once)
        q = dict(zip(line.system.unknowns, line.p))
        guesses += [transfer_guess(sysm, line, ln_Sc=q["ln_S1"] + math.log(a), ln_S1=q["ln_S1"], chi1=q["chi1"])
                    for a in _SECOND_ZONE_FROM_LINE]
    prof = cap.profile()
    on = prof["region"] == 0
    S_p = float(prof["S"][on][np.nonzero(prof["P"][on] < 0)[0][0]])
    w_edge = float(cap.Sc * cap.y[cap.system.rows(0), -1][0] / rho)  # the indenter point at the cap's edge
    for a, b in _SECOND_ZONE_SPLITS:
        S1 = b * cap.Sc
        guesses.append(transfer_guess(sysm, cap, ln_Sc=math.log(a * S_p), ln_S1=math.log(S1), chi1=rho * w_edge / cap.Sc))
    res = None
    for guess in guesses:
        res = _probe_then_solve(sysm, guess, solve_chain_from, **kw)
        if res.success and res.valid:
            break
    return res.with_(wall_time=time.perf_counter() - t0)


#: Solves of :func:`_continue_in_delta` at most (each a warm start of a few hundred to a few
#: thousand nodes), and its node budget: near the closing of a gap the mesh needs a few
#: thousand nodes for a while (beta 0.1: 2188 at delta 0.386), and a step that fails refines
#: up to it (gamma -2 from delta 0.82: 1.6-3.2 s per step with 5000)
_CONTINUATION_STEPS = 16
_CONTINUATION_NODES = 1200


def _continue_in_delta(sysm, previous, before, delta, *, tol, max_nodes, bc_tol):
    """The valid state of ``sysm``'s configuration at ``delta`` by natural continuation from
    ``previous`` (same configuration; secant through ``before`` if given, over at most its own
    length): the whole step first, halved while a step fails or lands on an invalid state (a
    narrow basin: beta 0.1 near the gap's closing, where Newton from a good guess finds another
    root with the gap nearly shut), at most ``_CONTINUATION_STEPS`` solves.  Returns the valid
    state at ``delta``, or None."""
    # a tighter tol than the state's needs (previous.tol / tol)^(1/3) times its nodes
    # (a split solved at 1e-6 with ~220 nodes asks ~2200 at 1e-9)
    finer = max(1.0, (previous.tol if math.isfinite(previous.tol) else tol) / tol) ** (1.0 / RESIDUAL_ORDER)
    budget = int(min(max_nodes, max(_CONTINUATION_NODES, WARM_NODES * previous.nodes * finer)))

    def solve_at(target, states):
        previous, before = states[-1], (states[-2] if len(states) > 1 else None)
        stepper = ChainBVP(sysm.scene, sysm.chain, "delta", target, model=sysm.model, par=sysm.par,
                           enclosed_volume=sysm.enclosed_volume)
        stepper.tip_A, stepper.tip_B = sysm.tip_A, sysm.tip_B
        secant = before if before is not None and abs(target - previous.delta) <= abs(previous.delta - before.delta) \
            else None
        return solve_chain_from(stepper, liftoff_warm_guess(stepper, previous, secant, target), tol=tol,
                                max_nodes=budget, bc_tol=bc_tol)

    # the whole step first; a step that succeeds is kept (a longer one fails there): no growth.
    # Halved steps add up to delta only to rounding: the last one lands on delta itself.
    steps = Steps(delta - previous.delta, grow=lambda s: s,
                  advance=lambda u, s, t: t if abs(t - u) <= abs(s) * (1 + 1e-9) else u + s)
    landed = []  # the state solved at delta itself

    def on_accept(state, target):
        if target == delta:
            landed.append(state)

    marched = march(previous.delta, delta, solve_at, steps, history=[before, previous], position=lambda s: s.delta,
                    accept=lambda s: s.success and s.valid, arrived=lambda u: False, on_accept=on_accept,
                    done=lambda states: "" if landed else None, max_solves=_CONTINUATION_STEPS)
    return landed[0] if marched.reached else None


def split_state_from(guess: Solution, control: str, value: float, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10):
    """The configuration of ``guess`` (a cap with a second zone on the tip: family "split")
    at another ``control`` value: under delta by natural continuation from it
    (:func:`_continue_in_delta`: halved steps, valid states only; None where none is found),
    under force or lambda0 by one solve from it (diagnosed, valid or not)."""
    if guess.topology not in names("split"):
        raise ValueError(f"guess must be a {' or '.join(names('split'))} state; got {guess.topology!r}")
    sysm = ChainBVP(guess.scene, guess.system.chain, control, value, model=guess.system.model, par=guess.system.par,
                    enclosed_volume=guess.system.enclosed_volume)
    attach_tip_table(sysm)
    if control == "delta":
        return _continue_in_delta(sysm, guess, None, value, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    return solve_chain_from(sysm, moved_guess(sysm, guess), tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)


def _probe_then_solve(sysm, guess, solve_from, *, tol, max_nodes, bc_tol):
    """``solve_from`` at tol, after a probe at a loose tolerance on a small mesh when tol is
    tighter: a guess from which Newton finds no state fails in the probe (a fraction of a
    second) instead of refining towards the node budget (base, delta 0.1125, where no second
    zone exists: 3 s); one that converges is tightened from the probe."""
    if tol >= _PROBE_TOL:
        return solve_from(sysm, guess, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    probe = solve_from(sysm, guess, tol=_PROBE_TOL, max_nodes=min(max_nodes, _PROBE_NODES), bc_tol=bc_tol,
                       max_jacobians=_PROBE_JACOBIANS)
    if not probe.success:
        return probe
    x = warm_mesh(probe, tol)
    return solve_from(sysm, (x, probe.sol(x), probe.p), tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)


def replace_invalid_cap(cap: Solution, **kw) -> Solution:
    """The state to report for a cap state (:func:`lifted_replacement`'s)."""
    return lifted_replacement(cap, **kw)[0]


def lifted_replacement(cap: Solution, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10, previous=None, before=None,
                       last=None) -> tuple:
    """(the state to report for a cap state, whether it replaces the cap, the line converged at
    its depth beside a split state or None): the cap itself if it does not pull, else the valid
    lift-off state (with the cap's numbers, ``cap_state``), else the cap flagged with what was
    tried.  ``previous``, ``before``: the last two lift-off states of a curve (warm starts,
    :func:`liftoff_state`); ``last``: the curve's previous point (:func:`valid_liftoff_state`)."""
    if not lift_off_suspected(cap):
        return cap, False, None
    alt, tried, line = valid_liftoff_state(cap, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol, previous=previous,
                                           before=before, last=last)
    if alt is None:
        return cap.with_(flags=list(cap.flags) + ["no valid lift-off state found (" + "; ".join(tried) + ")"]), \
            False, None
    return alt.with_(cap_state=cap.summary()), True, line


def _pressed_somewhere(cap):
    prof = cap.profile()
    return bool(np.max(prof["P"][prof["region"] == 0]) > 0)


# -- the end of a lifted-pole branch: loss of convexity at the free pole -----------------------------


def lifted_again(guess, control, value, *, topology, tol, max_nodes, eps, bc_tol, estimate_error):
    """``solve(guess=...)`` from a lifted-pole state: its configuration solved again; None
    (back to the single cap) where it fails or another configuration was asked for."""
    res = solve_liftoff(guess.scene, guess.topology, **{control: value}, guess=guess, tol=tol,
                        max_nodes=max_nodes, eps=eps, bc_tol=bc_tol, estimate_error=estimate_error)
    return res if topology in ("auto", guess.topology) and res.success else None


def split_again(guess, control, value, *, topology, tol, max_nodes, eps, bc_tol, estimate_error):
    """``solve(guess=...)`` from a split state (auto only): continued to ``value``
    (:func:`split_state_from`); None (back to the single cap) where that fails."""
    t0 = time.perf_counter()
    res = split_state_from(guess, control, value, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    if res is not None and res.success and topology == "auto":
        return finished(res, t0, estimate_error, tol, bc_tol)
    return None


def cap_lifted_off(cap, topology, kw):
    """The asked lifted configuration from the cap, or (auto, smooth model) a valid lifted or
    split state replacing an invalid cap (:func:`replace_invalid_cap`)."""
    if not cap.scene.contact_model.variational or not cap.success:
        return cap
    if topology in names("lifted"):
        return liftoff_state(cap, topology, **kw)
    return replace_invalid_cap(cap, **kw)
