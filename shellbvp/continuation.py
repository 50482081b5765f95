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

from .configurations import is_single_cap, names
from .corner import edge_model
from .curve_settings import CurveSettings
from .curve_stability import assess, check_choice
from .cylinder import best_wall_state, wall_contact_suspected
from .inflation import inflated_start
from .io import POINT_FIELDS, Curve
from .kernels import LONG_CURVE_POINTS, kernel_set
from .legs import Stop, adaptive, natural
from .lifted_ends import (
    lifted_pole_branch_end,
    lifted_pole_end_reason,
    lifted_pole_fold,
    lifted_pole_fold_reason,
    lifted_state_at,
)
from .liftoff import lift_off_suspected, lifted_replacement
from .recorder import Recorder
from .solution import Solution, default_eps
from .bounds import check_delta, check_tol
from .switches import locate_switches
from .version import __version__ as VERSION

__all__ = ["curve", "iter_curve", "CurveRun", "Stop"]

log = logging.getLogger(__name__)





def curve(scene, delta_max: float = 0.5, *, deltas=None, force_max=None, lambda0_max=None,
          max_steps: int = 400, delta_start=None, delta_min=None, tol: float = 1e-6,
          max_nodes: int = 10000, ds_max=None, estimate_error: bool | str = "auto", callback=None,
          topology: str = "auto", stability: str = "off"):
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
        ``"auto"``).  ``"full"``: a Richardson estimate (one Newton solve on the halved mesh;
        +15-60 % CPU time) at every point.  ``"auto"``: Richardson at the ends, where the
        configuration changes and at every ``RICHARDSON_EVERY``-th point, calibrated by the
        residual in between (:class:`shellbvp.recorder.Recorder`;
        ``benchmarks/results/error_estimates.md``); the point field ``error_method`` says which.
        A point whose estimated F error exceeds ``tol`` is solved again, tighter.
    callback : callable, optional
        ``callback(curve_so_far, solution)`` after each accepted point (progress,
        checkpoints).  It may raise ``KeyboardInterrupt`` to stop the curve.  (To act on the
        states as they come, iterate :func:`iter_curve` instead.)
    topology : {"auto", "cap"}
        ``"auto"`` (smooth model): where the single cap would pull the shell, record
        the valid line or annular contact at that delta (``shellbvp.liftoff``);
        ``"cap"``: single-cap states only (flagged where invalid).
    stability : {"off", "points", "locate"}
        Stability against non-axisymmetric modes at every recorded state, and where it is
        first lost (``Curve.first_instability``), narrowed by ``"locate"``
        (:mod:`shellbvp.curve_stability`).

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
    check_choice(stability)
    run = iter_curve(scene, delta_max, deltas=deltas, force_max=force_max, lambda0_max=lambda0_max,
                     max_steps=max_steps, delta_start=delta_start, delta_min=delta_min, tol=tol,
                     max_nodes=max_nodes, ds_max=ds_max, estimate_error=estimate_error, topology=topology)
    try:
        for sol in run:
            if callback is not None:
                callback(run.snapshot(), sol)
    except KeyboardInterrupt:
        run.interrupt()
    out = run.result()
    assess(out, stability if not out.interrupted else "off")
    return out


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

    settings = CurveSettings(tol=tol, max_nodes=max_nodes, delta_max=delta_max, force_max=force_max,
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

    def __init__(self, scene, settings: CurveSettings, deltas=None):
        self.scene, self.settings, self.deltas = scene, settings, deltas  # settings: read, never written
        # the curve's file record: the settings, and beside them what the run learns
        self.out = Curve(scene=scene, points={k: [] for k in POINT_FIELDS}, flags=[], stop_reason="",
                         complete=False, interrupted=False, settings=settings.to_dict(), version=VERSION)
        self.recorder = Recorder(self.out, settings.estimate_error, settings)
        self.branch = _Branch(settings)
        self.stop = None  # the Stop of the continuation, once it has ended
        self._states = None
        self._finished = False
        self._pending = []  # states recorded by the switch search, not yet yielded
        self.t0 = None  # when the iteration started

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

    def switch_located(self, switch: dict):
        """Record a switch the switch search located (``settings["topology_switches"]`` of the curve)."""
        self.out.settings["topology_switches"].append(switch)

    def _accept(self, sol, key):
        """(Stop or None, the recorded state or None) for a leg's state ``sol``."""
        shown, cap, line = self.branch.shown(sol)
        shown = self.recorder.estimated(shown)
        end = self.branch.end
        if end and self.settings.mode != "adaptive":  # requested depths only
            return Stop(end, complete=True), None
        self.recorder.record(shown, key, cap=cap, line=line)
        self.branch.last_shown = shown
        return (Stop(end, complete=True) if end else None), shown

    def _run(self):
        st, scene = self.settings, self.scene
        if self.deltas is None or self.deltas.size >= LONG_CURVE_POINTS:  # long enough to repay compiled kernels
            kernel_set(scene.model(), scene.structure).start_now()
        self.t0 = time.perf_counter()
        self.out.inflated = inflated_start(scene)  # the first step under pressure, passed on to the curve's file
        legs = natural(scene, self.deltas, self.branch, st) if self.deltas is not None else \
            adaptive(scene, self.branch, st)
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
        self.out.learned(after_last_point_s=time.perf_counter() - (self.recorder.last_accepted or self.t0))
        if st.topology == "auto":
            self.out.learned(topology_switches=[])  # filled as they are located (kept if interrupted)
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
            self.out.learned(after_last_point_s=time.perf_counter() - (
                self.recorder.last_accepted or self.t0 or time.perf_counter()))
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
        self.out.learned(wall_time=time.perf_counter() - (self.t0 or time.perf_counter()))
        log.info("curve: %s in %.2f s", self.out.summary(), self.out.settings["wall_time"])


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
        self.wall_from = None  # (the first wall state of a wall leg, the cap past the tip's end it was found from)

    def shown(self, sol: Solution) -> tuple:
        """(the state the curve records at ``sol``'s depth, the single cap it replaces or None, the
        line converged at its depth beside a split state or None): ``sol``, or the configuration that
        replaces it there.  No state holds another: the curve keeps the cap and the line beside the
        state it records (its switches are located from them)."""
        st = self.settings
        cap = self.wall_from[1] if self.wall_from is not None and self.wall_from[0] is sol else None
        if st.topology != "auto":
            return sol, cap, None
        kw = dict(tol=st.tol, max_nodes=st.max_nodes, bc_tol=st.bc_tol)
        shown, line = sol, None
        if sol.scene.contact_model.variational:  # the lifted-pole and split configurations exist
            last = self.last_shown  # the point computed before this one
            shown, replaced, line = lifted_replacement(sol, previous=self.last_liftoff, before=self.liftoff_before,
                                                       last=last, **kw)
            if replaced:
                cap = sol
                self.liftoff_before, self.last_liftoff = self.last_liftoff, shown
            elif lift_off_suspected(sol) and self.last_liftoff is not None and sol.delta > self.last_liftoff.delta \
                    and self.end_searched_from is not self.last_liftoff:
                # no lifted state here: has the lifted-pole branch ended before this depth?
                # (searched once from each last lifted state)
                self.end_searched_from = self.last_liftoff
                end = lifted_pole_branch_end(self.last_liftoff, self.liftoff_before, **kw)
                if end is not None and end.delta < sol.delta:
                    self.end = lifted_pole_end_reason(end)
                    return end, None, None
                if end is None:
                    shown, cap = self._before_fold(shown, kw)
        if is_single_cap(shown) and not edge_model(shown).held_at_tip_end and wall_contact_suspected(shown):
            wall = None
            if self.last_wall is not None:
                wall = best_wall_state(self.last_wall, control="delta", value=shown.delta, **kw)
            wall = wall or best_wall_state(shown, **kw)
            if wall is not None:
                cap = shown
                self.last_wall = shown = wall
        return shown, cap, line

    def _before_fold(self, cap, kw):
        """Where no lifted state was found at the invalid ``cap``'s depth: has the lifted-pole
        branch turned back in delta (a fold) before it?  Then the fold, recorded as the curve's
        physical end (the shell snaps there); if the branch reaches this depth (near a fold the
        warm starts of :func:`lifted_replacement` miss it), its state here, replacing the cap;
        else the cap.  Returns (that state, the cap it replaces or None)."""
        last, before = self.last_liftoff, self.liftoff_before
        # followed one curve step past this depth at most
        fold, on_way = lifted_pole_fold(last, before, delta_limit=2 * cap.delta - last.delta, **kw)
        if fold is not None and fold.delta < cap.delta:
            self.end = lifted_pole_fold_reason(fold)
            return fold, None
        lifted = lifted_state_at(cap.delta, on_way, fold, **kw)
        if lifted is None:
            return cap, None
        lifted = lifted.with_(cap_state=cap.summary())
        self.liftoff_before, self.last_liftoff = last, lifted
        return lifted, cap
