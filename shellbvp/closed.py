"""A closed shell on a substrate under a curved tip (family ``closed``): both halves as one BVP,
each touching its indenter -- the tip above, the plane below -- with a cap or a ring
(:mod:`shellbvp.configurations.closed`).

A cold start begins from two problems the package solves as rimmed shells: the same shell
squeezed between two such tips, and between two plates, each symmetric about its equator
(``Scene.halved``).  Every horizontal section of a closed shell carries the same force, so
the state on the substrate is near the upper half of the first at an approach ``du`` and the
lower half of the second at ``dl``, where both carry the same force and ``(du + dl)/2`` is
the prescribed delta (each half's pole moves by half its problem's approach).  Those halves,
joined at the equator, are the guess; their contacts (cap or ring) choose the configuration.
Under force control the two problems are solved at that force directly, and delta is their
approaches' mean.
A state of a curve is solved again from its neighbour (``solve(guess=...)``,
:func:`closed_again`), and cold where that fails or is not valid.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .configurations import configuration
from .configurations.closed import LOWER_NAMES, closed_name
from .cylinder import solve_chain_from
from .geometry import FlatTip
from .march import Steps, march
from .solution import failure, richardson_error, warm_mesh

__all__ = ["closed_again", "closed_continued", "closed_cold", "symmetric_scenes"]

#: States of each symmetric problem computed up to twice the depth, to match their forces.
HALF_POINTS = 8
_Z = 5  # z in a free region's states


def symmetric_scenes(scene):
    """The shell squeezed between two of its tips, and between two plates: of a shell whose
    halves differ (``UserShell.closed_halves``) its upper half (mirrored) between two tips and its
    lower half (mirrored) between plates."""
    lower = getattr(scene.shell, "lower", None)
    if lower is None:
        return scene.replace(support="plates"), scene.replace(support="plates", tip=FlatTip())
    return (scene.replace(support="plates", shell=scene.shell.upper_half()),
            scene.replace(support="plates", tip=FlatTip(), shell=lower))


def _half(state):
    """How a symmetric problem's state touches its indenter, as a closed shell's half (None for
    a configuration no half has)."""
    return configuration(state.topology).half if state.topology else None


def _system(scene, name, control, value, eps):
    return configuration(name).system(scene, control, value, eps)


def _unknowns(state) -> dict:
    """A state's unknowns by name (with delta and the pressure of its solution)."""
    named = dict(zip(state.system.unknowns, state.p))
    named.setdefault("delta", state.delta)
    return named


def _walk(scene, depth, solve_half, kw):
    """States of a symmetric problem at HALF_POINTS depths up to ``depth`` (warm-started)."""
    states, prev = [], None
    for d in depth * (np.arange(1, HALF_POINTS + 1) / HALF_POINTS) ** 1.5:
        s = solve_half(scene, delta=float(d), guess=prev, estimate_error=False, **kw)
        if s.success:
            states.append(s)
            prev = s
    return states


def _matched(scene, delta, solve_half, kw):
    """The two symmetric halves at equal force with (du + dl)/2 = delta, or a reason why not."""
    halves = []
    for sym in symmetric_scenes(scene):
        walk = _walk(sym, 2 * delta, solve_half, kw)
        if len(walk) < 2:
            return None, f"the shell between two {'plates' if sym.tip == FlatTip() else 'tips'} was not solved"
        halves.append(walk)
    curves = [(np.r_[0.0, [s.delta for s in w]], np.r_[0.0, [s.force for s in w]]) for w in halves]

    def mismatch(du):
        return np.interp(du, *curves[0]) - np.interp(2 * delta - du, *curves[1])

    try:
        du = brentq(mismatch, 0.0, 2 * delta, xtol=1e-12 * delta)
    except ValueError:
        return None, "the two symmetric problems' forces do not cross below twice the depth"
    states = []
    for walk, d in zip(halves, (du, 2 * delta - du)):
        near = min(walk, key=lambda s: abs(s.delta - d))
        s = solve_half(near.scene, delta=float(d), guess=near, estimate_error=False, **kw)
        if not s.success or _half(s) is None:
            return None, f"a symmetric half at delta {d:.4g} gave {s.topology} ({s.message})"
        states.append(s)
    return states, ""


def _joined(sysm, upper, lower, delta):
    """(x, y, p) of ``sysm`` from the two symmetric halves: the upper half's states moved so its
    tip is at the scene's, the lower half's so its plate is the substrate (z + dl)."""
    x = np.union1d(upper.x, lower.x)
    parts = []
    for half, shift in ((upper, upper.delta - delta), (lower, lower.delta)):
        y = half.sol(x)[:half.system.n_shell].copy()
        for k, reg in enumerate(half.system.regions):
            if reg.kind == "free":
                y[half.system.offsets[k] + _Z] += shift
        parts.append(y)
    named = _unknowns(upper)
    named.update({LOWER_NAMES[k]: v for k, v in _unknowns(lower).items() if k in LOWER_NAMES})
    named.update(delta=delta, pressure=0.5 * (upper.pressure + lower.pressure))
    return x, np.vstack(parts), sysm.pack(**named)


def _at_force(scene, value, solve_half, kw):
    """The two symmetric halves at the force ``value``, or a reason why not."""
    halves = []
    for sym in symmetric_scenes(scene):
        s = solve_half(sym, force=value, estimate_error=False, **kw)
        if not s.success or _half(s) is None:
            return None, (f"the shell between two {'plates' if sym.tip == FlatTip() else 'tips'} at force "
                          f"{value:.6g} gave {s.topology} ({s.message})")
        halves.append(s)
    return halves, ""


def closed_cold(scene, control, value, *, solve_half, eps, tol, max_nodes, bc_tol):
    """A state of a closed shell on a substrate at ``control = value``, from the two symmetric
    problems at the same force (``solve_half``: :func:`shellbvp.state.solve`): under delta control
    matched so that their approaches average to delta, under force control solved at it."""
    def failed(message):
        return failure(5, f"closed shell on a substrate: {message}", scene=scene, control=control, value=value,
                       topology=closed_name("cap", "cap"))

    kw = dict(eps=eps, tol=tol, max_nodes=max_nodes, bc_tol=bc_tol)
    if control == "delta":
        halves, why = _matched(scene, value, solve_half, kw)
    else:
        halves, why = _at_force(scene, value, solve_half, kw)
    if halves is None:
        return failed(why)
    res = None
    for upper, lower in _contacts_tried(halves, solve_half, kw):
        name = closed_name(_half(upper), _half(lower))
        sysm = _system(scene, name, control, value, eps)
        delta = value if control == "delta" else 0.5 * (upper.delta + lower.delta)
        guess = _joined(sysm, upper, lower, delta)
        res = solve_chain_from(sysm, guess, tol=tol, max_nodes=_joined_budget(guess[0].size, max_nodes), bc_tol=bc_tol,
                               max_jacobians=_JOINED_JACOBIANS)
        if res.success and res.valid:
            return res
    if not res.success:
        return failed(f"the {res.topology} state from the symmetric halves did not converge ({res.message})")
    return res  # converged, not valid: its flags say why


#: Node budget of a joined state: the symmetric halves' mesh serves as it is where the join is
#: near the state (measured: no node added on the presets and the tests' shells); a join that
#: needs several times more is far from it (an egg's halves at small depths ground for minutes
#: at 10,000 nodes), and fails fast instead.
_JOINED_GROWTH, _JOINED_MIN_NODES = 4, 2000
#: ... and of collocation Jacobians (a join near the state converges in a few)
_JOINED_JACOBIANS = 30


def _joined_budget(guess_nodes, max_nodes):
    return min(max_nodes, max(_JOINED_MIN_NODES, _JOINED_GROWTH * guess_nodes))


def _contacts_tried(halves, solve_half, kw):
    """The symmetric halves as found, then, where a half touches on a ring (which near its
    switches the joined state may refuse: the shell bending more tightly than the indenter
    there), with that ring closed into a cap or opened into an annulus: the lower's, the
    upper's, both."""
    yield halves
    others = []
    for half in halves:
        found = []
        if configuration(half.topology).line_contact:
            for topology in ("cap", "annulus"):
                other = solve_half(half.scene, delta=half.delta, topology=topology, guess=half, estimate_error=False,
                                   **kw)
                if other.success:
                    found.append(other)
        others.append(found)
    upper, lower = halves
    yield from ((upper, other) for other in others[1])
    yield from ((other, lower) for other in others[0])
    yield from ((u, l) for u in others[0] for l in others[1])


def closed_again(guess, control, value, *, topology, tol, max_nodes, eps, bc_tol, estimate_error):
    """``solve(guess=...)`` of a closed shell on a substrate: its configuration from ``guess``;
    None (a cold start) where that does not converge or is not valid (a contact that pulls
    asks for the other configuration)."""
    sysm = _system(guess.scene, guess.topology, control, value, eps)
    x = warm_mesh(guess, tol)
    res = solve_chain_from(sysm, (x, guess.sol(x)[:sysm.n_shell], sysm.pack(**_unknowns(guess))), tol=tol,
                           max_nodes=max_nodes, bc_tol=bc_tol)
    if not (res.success and res.valid):
        return None
    if estimate_error:
        res = richardson_error(res.system, res, tol, bc_tol)
    return res


#: Solves of :func:`closed_continued` (its steps halved at most about that often) and its node
#: budget in multiples of the neighbour's mesh (a step that does not converge must fail fast)
_CONTINUATION_SOLVES, _CONTINUATION_NODES = 10, 3


def closed_continued(guess, control, value, *, tol, max_nodes, eps, bc_tol):
    """The valid state of ``guess``'s configuration at delta = ``value`` by natural continuation
    from it, the step halved while a step fails or lands on an invalid state; None where that
    does not reach ``value`` (or under force control).  Where a ring moves fast with the depth
    the whole step from a neighbour fails although its configuration is valid there: the thin
    egg (eps 0.02) between plates, whose blunt half's ring snaps outwards near delta 0.0825 (S
    0.265 at 0.082, 0.293 at 0.084; the branch from below folds back in delta at 0.08249 and one
    of the same configuration goes on, its force lower); the cold start's guess gives a contact
    that pulls.  A fold is not crossed by shorter steps: a depth just past it stays flagged."""
    if control != "delta" or guess.delta == value:
        return None
    budget = int(min(max_nodes, max(_JOINED_MIN_NODES, _CONTINUATION_NODES * guess.nodes)))

    def solve_at(delta, states):
        near = states[-1]
        sysm = _system(near.scene, near.topology, "delta", delta, eps)
        x = warm_mesh(near, tol)
        y, q = near.sol(x)[:sysm.n_shell], _unknowns(near)
        if len(states) > 1:  # along the secant through the state before it, over at most its length
            before = states[-2]
            a = (delta - near.delta) / (near.delta - before.delta)
            if abs(a) <= 1:
                qb = _unknowns(before)
                q = {k: v + a * (v - qb[k]) for k, v in q.items()}
                y = y + a * (y - before.sol(x)[:sysm.n_shell])
        return solve_chain_from(sysm, (x, y, sysm.pack(**q)), tol=tol, max_nodes=budget, bc_tol=bc_tol,
                                max_jacobians=_JOINED_JACOBIANS)

    # the whole step failed already (closed_again): half of it first; a step that succeeds is
    # kept.  Halved steps add up to value only to rounding: the last one lands on value itself.
    landed = []
    steps = Steps(0.5 * (value - guess.delta), grow=lambda s: s,
                  advance=lambda u, s, t: t if abs(t - u) <= abs(s) * (1 + 1e-9) else u + s)
    marched = march(guess.delta, value, solve_at, steps, history=[guess], position=lambda s: s.delta,
                    accept=lambda s: s.success and s.valid, arrived=lambda u: False,
                    on_accept=lambda s, u: landed.append(s) if u == value else None,
                    done=lambda states: "" if landed else None, max_solves=_CONTINUATION_SOLVES)
    return landed[0] if marched.reached else None
