"""Force–displacement curves by continuation of single states.

Adaptive curves use pseudo-arclength continuation in ``X = (delta, lambda0, F)``
(so folds in any of them are passed, not stopped at), with a secant predictor
for the states and parameters, warm starts on a mesh that equidistributes the
previous state's residual (``solution.warm_mesh``: solve_bvp only ever adds nodes, and
on this mesh most steps converge in one pass), steps grown or shrunk with the Newton
effort and the turning of the branch, and halved on failure.  The small-delta
region is resolved by a leg from the first point down to ``delta_min``
(geometric steps; caps shrink exponentially there, and once a cap leaves
double precision the leg continues with its point-load limit).  Curves at requested
depths (``deltas=``) use natural continuation in delta.

A failure ends the curve cleanly: the points done so far are kept and the
reason is recorded; Ctrl-C does the same (``curve.interrupted``).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from dataclasses import dataclass

from .cylinder import best_wall_state, wall_contact_suspected
from .io import POINT_FIELDS, Curve
from .kernels import LONG_CURVE_POINTS, kernel_set
from .lifted_ends import (
    lifted_pole_branch_end,
    lifted_pole_end_reason,
    lifted_pole_fold,
    lifted_pole_fold_reason,
    lifted_state_at,
)
from .liftoff import lift_off_suspected, replace_invalid_cap
from .pointload import SC_POINT, solve_point_load
from .solution import Solution, default_eps, passed_tip_end
from .corner import LEGENDRE_WATCH, edge_model, limit_estimate, near_limit
from .march import Steps, iter_march
from .config import OPTIONS
from .recorder import Recorder
from .state import check_delta, check_tol, cross_convexity_limit, make_system, solve, solve_from, system_like, \
    warm_guess
from .steps import configuration_key, secant_guess, solve_at_delta, step_nodes
from .switches import locate_switches
from .version import __version__ as VERSION
from .configurations import is_point_load, is_single_cap, names

__all__ = ["curve", "iter_curve", "CurveRun", "Stop"]

log = logging.getLogger(__name__)

@dataclass(frozen=True)
class Stop:
    """Why a curve (or one leg of it) ended, and whether that is the end asked for."""

    reason: str
    complete: bool = False


def _X(sol):
    return np.array([sol.delta, sol.lambda0, sol.force])


def curve(scene, delta_max: float = 0.5, *, deltas=None, force_max=None, lambda0_max=None,
          max_steps: int = 400, delta_start=None, delta_min=None, tol: float = 1e-6,
          max_nodes: int = 10000, ds_max=None, estimate_error: bool | str = "auto", callback=None,
          topology: str = "auto"):
    """Force–displacement curve of a scene by continuation.

    Parameters
    ----------
    scene : Scene
    delta_max : float
        Stop when the pole displacement reaches it (> 0).
    deltas : sequence of float, optional
        Compute exactly these depths (natural continuation) instead of an adaptive curve.
    force_max, lambda0_max : float, optional
        Further stopping rules.  The curve also stops when the contact reaches
        the end of the tip (the indenter's cylinder).
    max_steps : int
        Largest number of continuation steps.
    delta_start, delta_min : float, optional
        First point (default ``min(0.05, delta_max/4)``) and the end of the
        small-delta leg (default ``delta_max/100``).
    tol, max_nodes : float, int
        solve_bvp settings for every point (see :func:`solve`).
    ds_max : float, optional
        Largest arclength step in (delta, lambda0, F) (default ``delta_max/10``).  A step
        that would turn the plotted curve (``delta / delta_max``, ``F / max |F|``) by more
        than ``MAX_PLOT_TURN`` is halved, so that a force maximum is resolved whatever
        the scale of F.
    estimate_error : {"auto", "full", False}
        Error estimates ``force_error``, ``delta_error`` at every point (``True`` means
        ``"auto"``).  ``"full"``: a Richardson estimate (one Newton solve on the halved
        mesh; +15-60 % CPU time on the work-precision scenes) at every point.  ``"auto"``: Richardson at the first and
        last point, at every point whose contact configuration (topology,
        contact_edge) differs from a neighbour's, and at every
        ``RICHARDSON_EVERY``-th point; in between, no solve: the larger Richardson
        ``error / max_residual`` of the two neighbouring Richardson points times the
        point's own residual (against tol-1e-10 references:
        ``benchmarks/results/error_estimates.md``).  The point field ``error_method``
        says which ("richardson" or "calibrated").  A point whose estimate puts its relative
        F error above ``tol`` (small F, at the end of the small-delta leg) is solved again at
        a tighter tolerance (10 times, or twice the estimate's excess, up to three times) and
        estimated by Richardson (``_Builder._tightened``).
    callback : callable, optional
        ``callback(curve_so_far, solution)`` after each accepted point (progress,
        checkpoints).  It may raise ``KeyboardInterrupt`` to stop the curve.  (To act on the
        states as they come, iterate :func:`iter_curve` instead.)
    topology : {"auto", "cap"}
        ``"auto"`` (smooth model): where the single cap would pull the shell, record
        the valid line or annular contact at that delta (``shellbvp.liftoff``);
        ``"cap"``: single-cap states only (flagged where invalid).

    Returns
    -------
    Curve
        The points found, in the order computed; ``complete``, ``stop_reason``
        say why the curve ended (it is returned, not raised, when the
        continuation fails or is interrupted).

    Examples
    --------
    >>> import shellbvp as sb
    >>> c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    >>> len(c), c.complete, c.stop_reason
    (2, True, 'all requested deltas computed')
    >>> print(", ".join(f"{f:.4f}" for f in c.force))
    0.1505, 0.3639
    >>> c.topology_summary()
    'line x1, cap x1 (switch line -> cap at delta = 0.113089)'
    """
    run = iter_curve(scene, delta_max, deltas=deltas, force_max=force_max, lambda0_max=lambda0_max,
                     max_steps=max_steps, delta_start=delta_start, delta_min=delta_min, tol=tol,
                     max_nodes=max_nodes, ds_max=ds_max, estimate_error=estimate_error, topology=topology)
    try:
        for sol in run:
            if callback is not None:
                callback(run.snapshot(), sol)
    except KeyboardInterrupt:
        run.interrupt()
    return run.result()


def iter_curve(scene, delta_max: float = 0.5, *, deltas=None, force_max=None, lambda0_max=None,
               max_steps: int = 400, delta_start=None, delta_min=None, tol: float = 1e-6,
               max_nodes: int = 10000, ds_max=None, estimate_error: bool | str = "auto",
               topology: str = "auto") -> CurveRun:
    """The curve of :func:`curve` as its states come.

    The arguments are checked here, before any solve; iterating the returned run computes
    the curve.

    Parameters
    ----------
    scene : Scene
    delta_max, deltas, force_max, lambda0_max, max_steps, delta_start, delta_min, tol, max_nodes, ds_max, \
estimate_error, topology
        As for :func:`curve`.

    Returns
    -------
    CurveRun
        Yields each recorded state (a :class:`~shellbvp.solution.Solution`) as it is accepted;
        ``result()`` is the :class:`~shellbvp.io.Curve`.

    Examples
    --------
    >>> import shellbvp as sb
    >>> run = sb.iter_curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    >>> [f"{s.topology} {s.force:.4f}" for s in run]
    ['line 0.1505', 'cap 0.3639']
    >>> c = run.result()
    >>> c.complete, c.stop_reason
    (True, 'all requested deltas computed')
    """
    _check_positive("delta_max", delta_max)
    check_tol(tol)
    check_delta("delta_max", delta_max, scene, tol)
    for name, v in (("force_max", force_max), ("lambda0_max", lambda0_max)):
        if v is not None:
            _check_positive(name, v)
    if not (isinstance(max_steps, (int, np.integer)) and max_steps >= 1):
        raise ValueError(f"max_steps must be an integer >= 1; got {max_steps!r}")
    if deltas is not None:
        deltas = np.asarray(deltas, float)
        if deltas.ndim != 1 or deltas.size == 0 or not np.all(np.isfinite(deltas)) or np.any(deltas <= 0):
            raise ValueError("deltas must be a non-empty 1-D sequence of finite numbers > 0")
        deltas = np.unique(deltas)
        check_delta("deltas", deltas[0], scene, tol)
        check_delta("deltas", deltas[-1], scene, tol)
    delta_start = max(tol, min(0.05, delta_max / 4)) if delta_start is None else float(delta_start)
    _check_positive("delta_start", delta_start)
    check_delta("delta_start", delta_start, scene, tol)
    delta_min = max(tol, delta_max / 100) if delta_min is None else float(delta_min)
    _check_positive("delta_min", delta_min)
    check_delta("delta_min", delta_min, scene, tol)
    ds_max = delta_max / 10 if ds_max is None else float(ds_max)
    _check_positive("ds_max", ds_max)
    if topology not in ("auto",) + names("cap"):
        raise ValueError(f"topology must be 'auto' or 'cap' for a curve; got {topology!r}")
    estimate_error = _error_mode(estimate_error)

    settings = dict(tol=tol, max_nodes=max_nodes, delta_max=delta_max, force_max=force_max,
                    lambda0_max=lambda0_max, max_steps=max_steps, delta_start=delta_start,
                    delta_min=delta_min, ds_max=ds_max, estimate_error=estimate_error,
                    mode="deltas" if deltas is not None else "adaptive", eps=default_eps(tol),
                    bc_tol=1e-10, topology=topology)

    settings = dict(tol=tol, max_nodes=max_nodes, delta_max=delta_max, force_max=force_max,
                    lambda0_max=lambda0_max, max_steps=max_steps, delta_start=delta_start,
                    delta_min=delta_min, ds_max=ds_max, estimate_error=estimate_error,
                    mode="deltas" if deltas is not None else "adaptive", eps=default_eps(tol),
                    bc_tol=1e-10, topology=topology)
    return CurveRun(scene, settings, deltas)


class CurveRun:
    """A curve as it is computed (made by :func:`iter_curve`).

    Iterating it runs the continuation and yields each recorded state; the located switches
    between configurations come last.  :meth:`result` gives the :class:`~shellbvp.io.Curve`
    (the points so far, if the iteration was left early); ``stop`` says why it ended.

    Examples
    --------
    >>> import shellbvp as sb
    >>> run = sb.iter_curve(sb.Scene.preset("base"), delta_max=0.3, estimate_error=False)
    >>> for state in run:
    ...     if state.force > 0.2:
    ...         break
    >>> c = run.result()
    >>> c.interrupted, c.stop_reason, bool(c.force.max() > 0.2)
    (True, 'interrupted', True)
    """

    def __init__(self, scene, settings, deltas=None):
        self.scene, self.settings, self.deltas = scene, settings, deltas
        self.out = Curve(scene=scene, points={k: [] for k in POINT_FIELDS}, flags=[], stop_reason="",
                         complete=False, interrupted=False, settings=settings, version=VERSION)
        self.recorder = Recorder(self.out, settings["estimate_error"], settings)
        self.branch = _Branch(settings)
        self.stop = None  # the Stop of the continuation, once it has ended
        self._states = None
        self._finished = False
        self._pending = []  # states recorded by the switch search, not yet yielded

    def __iter__(self):
        if self._states is None:
            self._states = self._run()
        return self._states

    @property
    def rows(self):
        return self.recorder.rows

    def add(self, sol: Solution, key: float):
        """Record a state found outside the legs (a located switch), as a leg's point is."""
        _, shown = self._accept(sol, key)
        if shown is not None:
            self._pending.append(shown)

    def _accept(self, sol, key):
        """(Stop or None, the recorded state or None) for a leg's state ``sol``."""
        shown = self.recorder.estimated(self.branch.shown(sol))
        end = self.branch.end
        if end and self.settings["mode"] != "adaptive":  # requested depths only
            return Stop(end, complete=True), None
        self.recorder.record(shown, key)
        self.branch.last_shown = shown
        return (Stop(end, complete=True) if end else None), shown

    def _run(self):
        st, scene = self.settings, self.scene
        if self.deltas is None or self.deltas.size >= LONG_CURVE_POINTS:  # long enough to repay compiled kernels
            kernel_set(scene.model(), scene.structure).start_now()
        self.t0 = time.perf_counter()
        legs = _natural(scene, self.deltas, self.branch, st) if self.deltas is not None else \
            _adaptive(scene, self.branch, st)
        while True:
            try:
                sol, key = next(legs)
            except StopIteration as end:
                self.stop = end.value or Stop("all requested deltas computed", complete=True)
                break
            stop, shown = self._accept(sol, key)
            if shown is not None:
                yield shown
            if stop is not None:
                legs.close()
                self.stop = stop
                break
        self.out.stop_reason, self.out.complete = self.stop.reason, self.stop.complete
        # what the stop cost: failed attempts after the last accepted point (issue 14: <= 2 s)
        st["after_last_point_s"] = time.perf_counter() - (self.recorder.last_accepted or self.t0)
        if st["topology"] == "auto":
            locate_switches(self, st)
            yield from self._pending
            self._pending = []
        self._finish()

    def snapshot(self) -> Curve:
        """The curve of the points so far (error estimates calibrated for now; for progress
        and checkpoints)."""
        return self.recorder.snapshot()

    def interrupt(self):
        """Stop here (Ctrl-C, or the caller left the iteration): the points so far are the curve."""
        if self._states is not None:
            self._states.close()
        self.out.interrupted = True
        if self.stop is None:
            self.out.stop_reason = "interrupted"
            self.settings["after_last_point_s"] = time.perf_counter() - (
                self.recorder.last_accepted or getattr(self, "t0", time.perf_counter()))
        self._finish()

    def result(self) -> Curve:
        """The curve: complete if the iteration ran to its end, else the points so far
        (``interrupted``)."""
        if not self._finished:
            self.interrupt()
        return self.out

    def _finish(self):
        if self._finished:
            return
        self._finished = True
        self.recorder.finish()
        self.settings["wall_time"] = time.perf_counter() - getattr(self, "t0", time.perf_counter())
        log.info("curve: %s in %.2f s", self.out.summary(), self.settings["wall_time"])


def _check_positive(name, v):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
            or not math.isfinite(v) or v <= 0:
        raise ValueError(f"{name} must be a finite number > 0; got {v!r}")


def _error_mode(estimate_error):
    """``estimate_error`` as "auto", "full" or False (bad values refused)."""
    if estimate_error is True or (isinstance(estimate_error, str) and estimate_error == "auto"):
        return "auto"
    if estimate_error is False or estimate_error is None:
        return False
    if isinstance(estimate_error, str) and estimate_error == "full":
        return "full"
    raise ValueError(f'estimate_error must be "auto" (or True), "full" or False; got {estimate_error!r}')


class _Branch:
    """What the continuation remembers of the configurations it meets, and which state it
    records at a depth.

    The continuation follows the single-cap branch; with ``topology="auto"`` a cap
    point that would pull the shell is recorded as the valid line or annular state
    at the same delta instead (found from the cap, or from the last lift-off state), and a cap
    whose shell reaches the indenter's cylinder as the valid wall state of lowest energy.
    At the switch the two coincide (the cap's pressure and the line's excess
    curvature vanish together), so F(delta) has no jump.  ``end`` is the reason where the
    followed branch ends physically (its last state recorded).
    """

    def __init__(self, settings):
        self.settings = settings
        self.last_liftoff = self.liftoff_before = None  # the last two lift-off states (warm starts)
        self.last_wall = None  # the last state with contact on the indenter's cylinder
        self.last_shown = None  # the state recorded last
        self.end = None  # the stop reason where the followed branch ends physically
        self.end_searched_from = None  # the lifted state from which that end was last searched

    def shown(self, sol: Solution) -> Solution:
        """The state the curve records at ``sol``'s depth: ``sol``, or the configuration that
        replaces it there."""
        st = self.settings
        if st["topology"] != "auto":
            return sol
        kw = dict(tol=st["tol"], max_nodes=st["max_nodes"], bc_tol=st["bc_tol"])
        shown = sol
        if sol.scene.contact == "smooth":
            last = self.last_shown  # the point computed before this one
            shown = replace_invalid_cap(sol, previous=self.last_liftoff, before=self.liftoff_before, last=last,
                                        **kw)
            if shown is not sol:
                self.liftoff_before, self.last_liftoff = self.last_liftoff, shown
            elif lift_off_suspected(sol) and self.last_liftoff is not None and sol.delta > self.last_liftoff.delta \
                    and self.end_searched_from is not self.last_liftoff:
                # no lifted state here: has the lifted-pole branch ended before this depth?
                # (searched once from each last lifted state)
                self.end_searched_from = self.last_liftoff
                end = lifted_pole_branch_end(self.last_liftoff, self.liftoff_before, **kw)
                if end is not None and end.delta < sol.delta:
                    self.end = lifted_pole_end_reason(end)
                    return end
                if end is None:
                    shown = self._before_fold(sol, kw)
        if is_single_cap(shown) and edge_model(shown) != "pinned" and wall_contact_suspected(shown):
            wall = None
            if self.last_wall is not None:
                wall = best_wall_state(self.last_wall, control="delta", value=shown.delta, **kw)
            wall = wall or best_wall_state(shown, **kw)
            if wall is not None:
                wall.cap_solution = shown
                self.last_wall = shown = wall
        return shown

    def _before_fold(self, cap, kw):
        """Where no lifted state was found at the invalid ``cap``'s depth: has the lifted-pole
        branch turned back in delta (a fold) before it?  Then the fold, recorded as the curve's
        physical end (the shell snaps there); if the branch reaches this depth (near a fold the
        warm starts of :func:`replace_invalid_cap` miss it), its state here, replacing the cap;
        else the cap."""
        last, before = self.last_liftoff, self.liftoff_before
        # followed one curve step past this depth at most
        fold, on_way = lifted_pole_fold(last, before, delta_limit=2 * cap.delta - last.delta, **kw)
        if fold is not None and fold.delta < cap.delta:
            self.end = lifted_pole_fold_reason(fold)
            return fold
        lifted = lifted_state_at(cap.delta, on_way, fold, **kw)
        if lifted is None:
            return cap
        lifted.cap_state = cap.summary()
        lifted.cap_solution = cap
        self.liftoff_before, self.last_liftoff = last, lifted
        return lifted


def _first_point(scene, delta, settings):
    """The curve's first state (the single cap: the branch followed is the cap's), or a Stop."""
    sol = solve(scene, delta=delta, tol=settings["tol"], max_nodes=settings["max_nodes"],
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
    from .materials import Gent

    material = sol.scene.material
    if not isinstance(material, Gent):
        return float("nan")
    prof = sol.profile()
    ls, lt = prof["lambda_s"], prof["lambda_theta"]
    return float(np.max(ls**2 + lt**2 + 1 / (ls * lt) ** 2 - 3) / material.Jm)


def _stop_rule(sol, settings):
    if settings["force_max"] is not None and sol.force >= settings["force_max"]:
        return f"force_max = {settings['force_max']:g} reached"
    if settings["lambda0_max"] is not None and sol.lambda0 >= settings["lambda0_max"]:
        return f"lambda0_max = {settings['lambda0_max']:g} reached"
    return None


def _physical_end(sol):
    """Why no state beyond ``sol`` can be reached on the way to delta_max, or None."""
    ratio = gent_lock_ratio(sol)
    if ratio >= GENT_LOCK:
        return (f"the Gent material locks: max (I1 - 3)/Jm = {ratio:.4f} >= {GENT_LOCK} at delta = "
                f"{sol.delta:.6g}, where F = {sol.force:.4g} grows without bound before delta_max")
    return None


def _natural(scene, deltas, branch, settings, first=None, key0=0):
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
    kw = dict(tol=st["tol"], max_nodes=st["max_nodes"], bc_tol=st["bc_tol"])
    if st["topology"] != "auto" or scene.model().OMEGA_MAX is None:
        return Stop(reason, complete=True)  # the cap's branch ends at the tip's end: the end asked for
    tried = []
    targets = list(deltas) if deltas is not None else None
    prev = branch.last_wall
    if prev is None:
        outcomes = []
        prev, past_end = best_wall_state(last_cap, tried=tried, outcomes=outcomes, **kw), last_cap
        if prev is None and is_single_cap(last_cap) and _room_may_help(outcomes):
            prev, past_end = _wall_state_deeper(scene, last_cap, st, kw, tried)
        if prev is None and scene.contact == "paper" and is_single_cap(last_cap):
            prev = _pinned_state(scene, last_cap, last_cap.delta, st, tried)
        if prev is None:  # not a physical end: a configuration that is missing or not found
            return Stop(f"{reason}; no valid contact with the cylinder ({'; '.join(tried)})")
        prev.cap_solution = past_end  # the cap past the tip's end: where the switch is located from
        branch.last_wall = prev
        if targets is None or any(abs(prev.delta - t) < 1e-12 for t in targets):  # (a requested depth)
            key += 1
            yield prev, key
    d_end = st["delta_max"] if targets is None else (targets[-1] if targets else prev.delta)

    def advance(u, step, t):
        return min(t, u + step) if targets is None else min(min(d for d in targets if d > u), u + step)

    def solve_at(nxt_target, states):  # the valid wall state of lowest energy, or None
        prev = states[-1]
        tried.clear()
        sol = None
        if edge_model(prev) == "pinned":  # held at the tip's end while its ring force pushes
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
    return Stop(f"delta_max = {st['delta_max']:g} reached" if targets is None else "all requested deltas computed",
                complete=True)


def _pinned_state(scene, start, delta, st, tried):
    """The paper's cap held at the tip's end (``contact_edge = "pinned"``) at ``delta``, warm
    from ``start`` (a cap near or past the tip's end, or a pinned cap); None unless valid.

    Where the indenter's meridional curvature jumps (the tip meets the cylinder) the paper's
    edge can stay while the indenter pushes the edge's circle (a ring force normal to the
    shell: at a hemispherical tip's end it is radial and carries no axial force); xi = 0: from
    delta 0.9295, where the free cap's edge reaches the end, to delta 1, where no cap+cylinder
    state exists (its band on the cylinder would have a negative length)."""
    sysm = make_system(scene, "delta", delta, st["eps"], edge="pinned")
    sol = solve_from(sysm, warm_guess(sysm, start), tol=st["tol"], max_nodes=step_nodes(start, st),
                     bc_tol=st["bc_tol"])
    if sol.success and sol.valid:
        return sol
    tried.append(f"cap held at the tip's end: {sol.message if not sol.success else '; '.join(sol.flags)}")
    return None


def _cross(cur, prev, delta, st):
    """The corner cap at ``delta`` past the smooth cap's convexity limit (or None)."""
    sol = cross_convexity_limit(cur, prev, delta, eps=st["eps"], tol=st["tol"], max_nodes=step_nodes(cur, st),
                                bc_tol=st["bc_tol"], exact=False)
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
        if last_cap.delta + dd > st["delta_max"]:
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
    sol = solve_at_delta(scene, st["delta_max"], cur, prev, st)
    if sol.success:
        yield sol, key
        return sol, Stop(f"delta_max = {st['delta_max']:g} reached", complete=True)
    return sol, None


#: The adaptive curve's steps also follow the force-displacement curve as it is plotted, on axes
#: (``delta / delta_max``, ``F / max |F|`` so far): a step whose chord turns by more than
#: MAX_PLOT_TURN (radians) from the previous chord is refused and halved, down to PLOT_TURN_MIN_DS
#: times ds_max.  The arclength itself is measured in (delta, lambda0, F), in which a shell whose
#: F is small (a thin dome: F ~ 1e-4) shows no turn where its force peaks: the dome's arclength
#: curve stepped over its force maximum (3.28e-4) from 2.93e-4 to 2.96e-4.
MAX_PLOT_TURN = 0.3
PLOT_TURN_MIN_DS = 1 / 16


def _plot_turn(prev, cur, new, delta_max, force_scale):
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


def _adaptive(scene, branch, settings):
    """The adaptive curve: yields ``(state, order key)``, returns the Stop."""
    st = settings
    first = _first_point(scene, st["delta_start"], st)
    if isinstance(first, Stop):
        return first
    yield first, 0
    steps = 1
    # Leg 1: down to delta_min (geometric), resolving the small-delta region.
    prev, prev2, below = first, None, None
    d = first.delta
    factor = 0.6
    while d > st["delta_min"] and steps < st["max_steps"]:
        nd = max(st["delta_min"], d * factor)
        if is_point_load(prev):
            sol = solve_point_load(scene, nd, tol=st["tol"], max_nodes=st["max_nodes"], guess=prev)
        else:
            sol = solve_at_delta(scene, nd, prev, prev2, st)
            if scene.contact == "smooth" and prev.Sc < 1e-8 and (not sol.success or sol.Sc < SC_POINT):
                # the cap is leaving double precision: continue with its point-load limit
                point = solve_point_load(scene, nd, tol=st["tol"], max_nodes=st["max_nodes"], guess=prev)
                sol = point if point.success else sol
        steps += 1
        if sol.success:
            yield sol, -steps
            below = below or sol
            prev2, prev, d = prev, sol, nd
        else:
            factor = 1 - (1 - factor) / 2
            if factor > 0.97:
                log.info("small-delta leg stopped at delta = %.4g: %s", d, sol.message)
                break
    # Leg 2: pseudo-arclength upwards from the first point.
    if is_point_load(first):
        # the cap is below double precision there: no (delta, lambda0, F) branch to follow
        # until it comes back; natural continuation in delta instead (point-load limit or cap)
        grid = np.linspace(first.delta, st["delta_max"], 11)
        stop = yield from _natural(scene, grid, branch, st, first=first, key0=steps)
        return Stop(f"delta_max = {st['delta_max']:g} reached", complete=True) if stop is None else stop
    scale = np.array([1.0, 1.0, 1.0])
    cur = first
    if below is not None and below.topology != first.topology:
        below = None  # the small-delta leg went on in the point-load limit: no secant from a cap to it
    if below is None:  # need a second point for the tangent
        below = solve_at_delta(scene, first.delta * 0.9, first, None, st)
        if not below.success:
            return Stop(f"no second point near delta = {first.delta:g}: {below.message}")
    prev = below
    ds = min(st["ds_max"], OPTIONS.first_step * np.linalg.norm((_X(cur) - _X(prev)) / scale))
    ds_min = 1e-4  # in (delta, lambda0, F): below this the branch is taken to end here
    force_scale = max(abs(cur.force), abs(prev.force))
    tangent = None
    crossed_from = None  # the smooth cap from which the corner was last tried
    while True:
        if steps >= st["max_steps"]:
            return Stop(f"max_steps = {st['max_steps']} reached")
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
        if Xhat[0] >= st["delta_max"]:
            steps += 1
            sol, stop = yield from _land_on_delta_max(scene, cur, prev, st, steps)
            if stop:
                return stop
            ds /= 2
            if ds < ds_min:
                return Stop(f"no solution at delta_max = {st['delta_max']:g}: {sol.message}")
            continue
        sol = None
        crossing = near_limit(cur) and crossed_from is not cur  # the corner is tried once from each state
        if crossing:  # past the convexity limit the smooth cap ends: the corner takes over
            d_star = limit_estimate(prev, cur)
            if d_star is None or Xhat[0] > d_star:
                sol = _cross(cur, prev, Xhat[0], st)
                crossed_from = cur
        if sol is None:
            sysm = system_like(cur, "arclength", (Xhat, tangent, scale), st["eps"])
            # no secant across a change of configuration (e.g. the smooth edge to the corner:
            # the states' difference is the jump forming, not the branch's direction)
            a = ds / max(norm, 1e-300) if configuration_key(cur) == configuration_key(prev) else 0.0
            guess = secant_guess(sysm, cur, prev, a)
            sol = solve_from(sysm, guess, tol=st["tol"], max_nodes=step_nodes(cur, st), bc_tol=st["bc_tol"])
            if not sol.success and crossing and crossed_from is not cur:
                sol = _cross(cur, prev, Xhat[0], st) or sol
                crossed_from = cur
            if not sol.success and crossed_from is cur and cur.edge_legendre < LEGENDRE_WATCH / 5:
                # at the limit, no smooth step and no corner: halving the step only stalls
                return Stop(f"continuation failed near delta = {cur.delta:.6g}: the energy loses convexity at "
                            f"the contact edge (Legendre determinant at Sc+ down to {cur.edge_legendre:.2g} of "
                            f"its mid-region value) and no corner state was found past it ({sol.message})")
        steps += 1
        if sol.success and sol.delta > st["delta_max"]:  # overshot: land from the current point
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
            if ds > PLOT_TURN_MIN_DS * st["ds_max"] \
                    and _plot_turn(prev, cur, sol, st["delta_max"], force_scale) > MAX_PLOT_TURN:
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
            ds = min(st["ds_max"], ds * grow)
        else:
            ds /= 2
            if ds < ds_min:
                reason = sol.message if not sol.success else "the branch turned back to delta <= 0"
                leg = cur.edge_legendre
                if leg < 0.05 and edge_model(cur) == "smooth":
                    reason = (f"the energy loses convexity at the contact edge (Legendre determinant at Sc+ "
                              f"down to {leg:.2g} of its mid-region value): the free region's equations "
                              f"become singular there, the smooth single-cap branch ends and no corner "
                              f"state was found ({reason})")
                return Stop(f"continuation failed near delta = {cur.delta:.6g}: {reason}")
