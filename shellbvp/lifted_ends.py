"""Where a lifted-pole branch ends: the lifted pole's loss of convexity (the branch's end,
rho 0.05) and its fold in delta (a thick shell's sagging pole, beta 0.2-0.5), each located
from the branch's last two states, and the reasons a curve gives when it stops there.
"""

from __future__ import annotations

import math

import numpy as np

from .chain import FreePole
from .configurations import names
from .convexity import envelope_partner
from .liftoff import WARM_NODES, make_liftoff_system, moved_guess, pole_clearance, solve_liftoff, solve_liftoff_from
from .march import Steps, march
from .solution import Solution

__all__ = ["pole_legendre", "POLE_LEGENDRE_END", "lifted_pole_branch_end", "lifted_pole_end_reason",
           "pole_corner_partner", "lifted_pole_fold", "lifted_pole_fold_reason", "lifted_state_at"]


#: A lifted pole whose Legendre determinant (:func:`pole_legendre`) is below this is at the end
#: of its branch (rho 0.05: 0.2 at delta 0.16, 2e-3 at 0.17543, 0 at 0.1754322).
POLE_LEGENDRE_END = 1e-3


def pole_legendre(state) -> float:
    """det d(tau_s, M_s)/d(lambda_s, kappa_s) at a lifted pole relative to its value in the middle
    of the free region that ends at the rim (as ``edge_legendre``); NaN without a free pole.

    The lifted cap is nearly uniform, so its own median falls with it: the outer region is
    the scale that stays (rho 0.05: about 0.04 there while the pole's falls to 0)."""
    sysm = state.system
    if sysm is None or not state.success or not isinstance(sysm.junctions[0], FreePole):
        return math.nan
    last = len(sysm.regions) - 1
    pole = sysm.model.free_legendre(sysm.S(0, np.array([0.0]), state.p), state.sol(np.array([0.0]))[sysm.rows(0)],
                                    sysm.par)[0][0]
    mid = sysm.model.free_legendre(sysm.S(last, np.array([0.5]), state.p),
                                   state.sol(np.array([0.5]))[sysm.rows(last)], sysm.par)[0][0]
    return float(pole / mid) if mid != 0 else math.nan


#: Solves of :func:`lifted_pole_branch_end` at most; a step in lambda0 that lowers pole_legendre
#: by less than this factor ends the search (rho 0.05: each step lowers it 3-10x)
_END_STEPS = 24
_END_MIN_GAIN = 0.8
#: The smallest delta step of its natural continuation towards the end
_END_DELTA_STEP = 2e-3


def lifted_pole_branch_end(previous: Solution, before: Solution, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10):
    """Where a lifted-pole branch (line or annulus) ends: the state at which the energy loses
    convexity at the free pole (:func:`pole_legendre` below ``POLE_LEGENDRE_END``), or None if
    the branch through ``before`` and ``previous`` (two of its states, ``previous`` the deeper)
    is not heading there.

    First natural continuation in delta from ``previous`` (steps halved when one fails, down
    to ``_END_DELTA_STEP``) brings the search close to the end, where delta stops growing;
    then the branch is followed in the pole's stretch lambda0 (secant steps of 80 % towards
    the zero of pole_legendre, nearly linear in lambda0 close to it; 40 % or 15 % where a step
    fails).  Along lambda0, delta grows to a maximum where the determinant vanishes (rho 0.05:
    delta* = 0.1754322, lambda0 = 0.68291, kappa_s = 29.47 at the pole against the tip's 20),
    so natural continuation in delta stalls short of it and no lifted state of this kind
    exists deeper.  Past it the pole's state is not convex, and no interior Weierstrass-Erdmann
    corner continues it where the corner's other phase is a crease (:func:`pole_corner_partner`).
    A state of the continuation in delta that is not
    valid or whose pole determinant does not fall, or a step in lambda0 that does not lower
    it by ``_END_MIN_GAIN``, ends the search (beta 0.2: it levels off near 0.01 at delta 0.33
    and rises again towards a fold of the branch, :func:`lifted_pole_fold`).
    """
    if previous is None or before is None or previous.topology != before.topology \
            or previous.topology not in names(having="pole_branch_end") or not previous.delta > before.delta:
        return None
    g_prev, g = pole_legendre(before), pole_legendre(previous)
    if not (math.isfinite(g_prev) and math.isfinite(g) and 0 < g < g_prev):
        return None
    scene, topology = previous.scene, previous.topology

    def budget(state):  # past the end the mesh runs away: fail fast
        return int(min(max_nodes, max(2000, WARM_NODES * state.nodes)))

    a, b = before, previous
    step, solves = b.delta - a.delta, 0
    while step >= _END_DELTA_STEP and solves < _END_STEPS:
        res = solve_liftoff(scene, topology, delta=b.delta + step, guess=b, tol=tol, max_nodes=budget(b),
                            bc_tol=bc_tol)
        solves += 1
        if not res.success:
            step /= 2
        elif res.valid and 0 < pole_legendre(res) < pole_legendre(b):
            a, b = b, res
        else:  # the branch goes on, invalid or with the pole's determinant not falling: no such end
            return None
    g_prev, g = pole_legendre(a), pole_legendre(b)
    while solves < _END_STEPS:
        if g < POLE_LEGENDRE_END:
            return b if b.valid and b.delta >= previous.delta else None
        slope = (g - g_prev) / (b.lambda0 - a.lambda0)
        if not slope != 0:
            return None
        res = None
        for fraction in (0.8, 0.4, 0.15):
            res = solve_liftoff(scene, topology, lambda0=b.lambda0 - fraction * g / slope, guess=b, tol=tol,
                                max_nodes=budget(b), bc_tol=bc_tol)
            solves += 1
            if res.success:
                break
        if not res.success:
            return None
        a, b, g_prev, g = b, res, g, pole_legendre(res)
        if not math.isfinite(g) or g < 0 or g > _END_MIN_GAIN * g_prev:
            return None  # not falling to zero
    return None


#: The boxes of (lambda_s >= lambda_min, |kappa_s rho| <= kappa_rho_max), growing, in which the
#: lifted pole's interior-corner partner is sought (``convexity.envelope_partner``): where the
#: gap above the envelope keeps growing with the box, the partner is no state of the shell
#: (rho 0.05: 0.56 %, 1.2 %, 1.6 %; its partner lambda_s 0.21 -> 0.10)
_CORNER_BOXES = ((0.1, 100.0), (0.05, 1000.0), (0.02, 10000.0))


def pole_corner_partner(end: Solution) -> dict:
    """Is there an interior Weierstrass-Erdmann corner from the lifted pole of ``end``?

    The corner's other phase is the far end of U's convex-envelope segment from the pole's
    state (:func:`shellbvp.convexity.envelope_partner`), sought in the growing boxes
    ``_CORNER_BOXES``.  Returns ``gaps`` (U above its envelope, relative, per box),
    ``partners`` ((lambda_s, kappa_s) per box) and ``finite``: the gap settles (the last two
    boxes agree to 5 %), so the partner lies inside them.  Where the gap keeps growing the
    envelope's segment runs out with the box, towards lambda_s -> 0 and kappa_s -> infinity: a
    crease, not a corner between two states of the shell."""
    sysm = end.system
    t = np.array([0.0])
    S, y = float(sysm.S(0, t, end.p)[0]), end.sol(t)[sysm.rows(0), 0]
    found = [envelope_partner(sysm, S, y, lambda_min=lm, kappa_rho_max=km) for lm, km in _CORNER_BOXES]
    gaps = [f["gap"] for f in found]
    finite = bool(gaps[-1] > 0 and gaps[-1] < 1.05 * gaps[-2])
    return {"gaps": gaps, "partners": [f["partner"] for f in found], "finite": finite}


def lifted_pole_end_reason(end: Solution) -> str:
    """The stop reason of a curve at the end of its lifted-pole branch."""
    prof = end.profile()
    rho = end.scene.rho
    corner = pole_corner_partner(end)
    (l1, k1), (l2, k2), _ = corner["partners"]
    gaps = ", ".join(f"{100 * g:.2g}" for g in corner["gaps"])
    if corner["finite"]:
        beyond = (f"an interior Weierstrass-Erdmann corner to lambda_s = {l2:.3g}, kappa_s rho = {k2 * rho:.3g} "
                  f"may continue it; it is not searched")
    else:
        beyond = (f"no interior Weierstrass-Erdmann corner with a shell state on its other side continues it: the "
                  f"pole's state lies above the convex envelope of U in (lambda_s, lambda_s kappa_s) by a gap that "
                  f"grows with the box sampled ({gaps} %), whose other phase runs out with the box (lambda_s "
                  f"{l1:.2g} -> {l2:.2g}, kappa_s rho {k1 * rho:.3g} -> {k2 * rho:.3g}): a crease, not a state of "
                  f"the shell; a convex bending energy (bending='rotation') continues")
    return (f"the energy loses convexity at the lifted cap's free pole: the lifted-pole {end.topology} branch "
            f"ends at delta = {end.delta:.6g} (F = {end.force:.6g}; Legendre determinant at the pole "
            f"{pole_legendre(end):.2g} of the outer free region's, lambda0 = {end.lambda0:.5g}, kappa_s = "
            f"{float(prof['kappa_s'][0]):.4g} against the tip's {1 / rho:.4g}); delta is largest there "
            f"along the branch, and deeper the single cap pulls at the pole; {beyond}")


# -- the fold of a lifted-pole branch: delta turns back -------------------------------------------
#: Solves of :func:`lifted_pole_fold` at most; its smallest and largest steps in lambda0 (beta
#: 0.2: Newton from a secant guess converges for steps up to 0.005-0.01 in lambda0 only)
_FOLD_STEPS = 80
_FOLD_MIN_STEP = 1e-4
_FOLD_MAX_STEP = 0.006
#: The fold is located when delta at the parabola's vertex changes by less than this (relative):
#: delta is flat in lambda0 there, so lambda0* is known only to about sqrt(this)
_FOLD_DTOL = 1e-8


def _parabola_vertex(states):
    """lambda0 at the maximum of the parabola delta(lambda0) through three states, or None."""
    x = np.array([s.lambda0 for s in states])
    c = np.polyfit(x - x[1], [s.delta for s in states], 2)
    if not c[0] < 0:
        return None
    v = x[1] - c[1] / (2 * c[0])
    return float(v) if min(x) < v < max(x) else None


def lifted_pole_fold(previous: Solution, before: Solution, *, delta_limit=math.inf, tol=1e-6, max_nodes=10000,
                     bc_tol=1e-10):
    """Where a lifted-pole branch (line or annulus) turns back in delta: ``(fold, states)``, the
    state at the fold (valid, deeper than ``previous``) and the branch's states found on the way
    to it (increasing delta); ``(None, states)`` where the branch passes ``delta_limit`` before
    any fold (its states up to there); ``(None, [])`` where the search ends otherwise.

    The branch through ``before`` and ``previous`` (two valid states, ``previous`` the deeper)
    is followed first in delta (secant steps, halved where one fails or leaps in lambda0: near
    the fold the other side of the branch is close) until the steps stall, then in the lifted
    pole's stretch lambda0, which the line and annulus take as control, until delta falls;
    the maximum is then located by parabolas delta(lambda0) through the three deepest states.
    Under displacement control the shell snaps through at such a fold (beta 0.2:
    delta* = 0.356818, F 1.88275, lambda0 = 0.3758, the lifted pole sagging 0.011 below the
    tip's apex and bent to kappa_s = 71 against the tip's 5; past the fold the branch runs back
    in delta to where the pole loses convexity, lambda0 = 0.285 at delta 0.3523).  About 40
    solves (10-15 s) from two states 0.01-0.02 below it.  The search
    ends without a fold where a state is not valid, where delta passes ``delta_limit``, or after
    ``_FOLD_STEPS`` solves.
    """
    if previous is None or before is None or previous.topology != before.topology \
            or previous.topology not in names(having="pole_branch_end") or not previous.delta > before.delta \
            or not (previous.valid and before.valid) \
            or not (math.isfinite(previous.lambda0) and previous.lambda0 != before.lambda0):
        return None, []
    scene, topology = previous.scene, previous.topology
    kw = dict(tol=tol, max_nodes=int(min(max_nodes, max(2000, WARM_NODES * previous.nodes))), bc_tol=bc_tol)
    states, solves = [before, previous], 0

    def at(control, value, prev, before):
        """The state at ``control = value`` from prev, along the secant through before."""
        nonlocal solves
        solves += 1
        sysm = make_liftoff_system(scene, topology, control, value, previous.system.eps)
        a = (value - getattr(prev, control)) / (getattr(prev, control) - getattr(before, control))
        return solve_liftoff_from(sysm, moved_guess(sysm, prev, before, a), **kw)

    # 1. in delta while the steps go through (far from the fold delta is the better control)
    first, taken = previous.delta - before.delta, []

    def advance(u, step, _):
        taken.append(step)  # the step of the attempt, for its expected change of lambda0
        return u + step

    followed = []  # whether the last state is valid and has not leapt in lambda0 (onto the branch beyond the fold)

    def in_delta(d, st):
        b, a = st[-1], st[-2]
        res = at("delta", d, b, a)
        expected = (b.lambda0 - a.lambda0) * taken[-1] / (b.delta - a.delta)
        followed.append(res.success and res.valid and abs(res.lambda0 - b.lambda0) <= 2 * abs(expected) + 1e-3)
        return res

    m = march(previous.delta, math.inf, in_delta, Steps(first, advance=advance, too_small=lambda s, u: not s > first / 16),
              history=states, position=lambda s: s.delta, arrived=lambda u: False, max_solves=_FOLD_STEPS,
              stop=lambda res, d, st: "limit" if followed[-1] and res.delta > delta_limit else None,
              accept=lambda res: followed[-1])
    states = m.states
    if m.reason == "limit":
        return None, states + [m.failed]
    # 2. in lambda0 until delta falls: the maximum is bracketed
    grown = min(_FOLD_MAX_STEP, abs(states[-1].lambda0 - states[-2].lambda0))

    def bracketed(res, lam, st):
        if not (res.success and res.valid):
            return None
        return "limit" if res.delta > delta_limit else ("fold" if res.delta < st[-1].delta else None)

    m = march(states[-1].lambda0, math.nan, lambda lam, st: at("lambda0", lam, st[-1], st[-2]),
              Steps(math.copysign(grown, states[-1].lambda0 - states[-2].lambda0), advance=lambda u, s, _: u + s,
                    grow=lambda s: math.copysign(min(_FOLD_MAX_STEP, 1.5 * abs(s)), s),
                    too_small=lambda s, u: abs(s) < _FOLD_MIN_STEP),
              history=states, position=lambda s: s.lambda0, arrived=lambda u: False,
              accept=lambda res: res.success and res.valid, stop=bracketed, max_solves=_FOLD_STEPS - solves)
    states, res = m.states, m.failed
    if m.reason == "limit":
        return None, states + [res]
    if m.reason != "fold":
        return None, []
    # 3. the vertex of parabolas through the deepest state and its neighbours in lambda0
    pool, fold = states[-3:] + [res], None
    while solves < _FOLD_STEPS:
        top = max(pool, key=lambda s: s.delta)
        left = [s for s in pool if s.lambda0 < top.lambda0]
        right = [s for s in pool if s.lambda0 > top.lambda0]
        if not (left and right):
            return None, []
        triple = [max(left, key=lambda s: s.lambda0), top, min(right, key=lambda s: s.lambda0)]
        v = _parabola_vertex(triple)
        if v is None:
            return None, []
        res = at("lambda0", v, top, max(triple, key=lambda s: abs(s.lambda0 - v)))
        if not (res.success and res.valid):
            return None, []
        pool.append(res)
        if fold is not None and abs(res.delta - fold.delta) < _FOLD_DTOL * (1 + res.delta):
            fold = max(fold, res, key=lambda s: s.delta)
            break
        fold = res
    if fold is None or not fold.delta > previous.delta:
        return None, []
    return fold, [s for s in states if s.delta < fold.delta]


def lifted_state_at(delta, states, fold=None, *, tol=1e-6, max_nodes=10000, bc_tol=1e-10):
    """The lifted state at ``delta`` on the branch through ``states`` (:func:`lifted_pole_fold`'s,
    increasing delta), from the deepest of them not deeper than ``delta``; with ``fold`` (deeper
    than ``delta``), on the side of the branch that leads to it.  None if not found: close to a
    fold a warm start from afar misses the branch or lands on its other side."""
    below = [s for s in states if s.delta <= delta]
    if not below or (fold is not None and not delta < fold.delta):
        return None
    guess = max(below, key=lambda s: s.delta)
    res = solve_liftoff(guess.scene, guess.topology, delta=delta, guess=guess, tol=tol,
                        max_nodes=int(min(max_nodes, max(2000, WARM_NODES * guess.nodes))), bc_tol=bc_tol)
    if not (res.success and res.valid):
        return None
    if fold is not None and not (res.lambda0 - fold.lambda0) * (guess.lambda0 - fold.lambda0) > 0:
        return None
    return res


def lifted_pole_fold_reason(fold: Solution) -> str:
    """The stop reason of a curve at the fold of its lifted-pole branch."""
    return (f"the lifted-pole {fold.topology} branch turns back in delta at delta = {fold.delta:.6g} (F = "
            f"{fold.force:.6g}, lambda0 = {fold.lambda0:.4g}; a fold, the lifted pole {pole_clearance(fold):.3g} "
            f"below the tip's apex): under displacement control the shell snaps through there; deeper the single "
            f"cap pulls and no lift-off or split state is found: the state it snaps to is not built")
