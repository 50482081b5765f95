"""Natural continuation in one parameter, written once.

Every search that walks a family of states towards a target value of one parameter (the
depth delta of a curve or of a cold start, the pressure of the inflated shell) is a
:func:`march`: a step from the last accepted state, grown after a success and shrunk after a
failure, until the target is reached, the step is too small, the solves run out or a state
says that going on is pointless.  What differs between the searches is passed in: how a
state is solved at a value (its predictor included), how the step moves and adapts
(:class:`Steps`), which states are accepted, and what ends the march early.  The march
returns what happened (:class:`Marched`); it never raises.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

__all__ = ["Steps", "Marched", "march", "iter_march"]


@dataclass(frozen=True)
class Steps:
    """How a march's step moves the parameter and adapts.

    Attributes
    ----------
    first : float
        The first step.
    advance : callable
        ``advance(u, s, target)`` -> the next value from ``u`` with step ``s`` (not past
        ``target``).  Default ``min(target, u + s)`` towards a larger target.
    grow : callable
        ``grow(s)`` -> the step after a success.  Default ``1.5 s``.
    shrink : callable
        ``shrink(s, u, tried)`` -> the step after a failure at ``tried``.  Default ``s / 2``.
    too_small : callable
        ``too_small(s, u)`` -> True ends the march (reason ``"step"``).  Default never.
    """

    first: float
    advance: Callable = None
    grow: Callable = None
    shrink: Callable = None
    too_small: Callable = None

    def next_value(self, u, s, target):
        return min(target, u + s) if self.advance is None else self.advance(u, s, target)

    def after_success(self, s):
        return 1.5 * s if self.grow is None else self.grow(s)

    def after_failure(self, s, u, tried):
        return s / 2 if self.shrink is None else self.shrink(s, u, tried)

    def ends(self, s, u):
        return False if self.too_small is None else bool(self.too_small(s, u))


@dataclass
class Marched:
    """What a march did.

    Attributes
    ----------
    reached : bool
        The target was reached (or ``done`` said the march's aim was met).
    reason : str
        Why it stopped: ``""`` when reached, ``"step"`` (the step became too small),
        ``"solves"`` (``max_solves`` used up), ``"range"`` (``advance`` left the allowed
        range: it returned None), or what ``stop`` returned.
    states : list
        Every accepted state, oldest first, the ``history`` it started from included.
    failed : Solution or None
        The last attempt that was not accepted.
    at : float
        The value of the last accepted state (``u0`` if none was accepted).
    tried : float
        The value of the last attempt.
    solves : int
    """

    reached: bool
    reason: str
    states: list = field(default_factory=list)
    failed: Any = None
    at: float = math.nan
    tried: float = math.nan
    solves: int = 0

    @property
    def last(self):
        """The last accepted state (None if there is none)."""
        return self.states[-1] if self.states else None


def iter_march(u0, target, solve_at, steps: Steps, *, history=(), position=None, accept=None, stop=None,
               done=None, arrived=None, max_solves=None):
    """Natural continuation of a parameter u from ``u0`` to ``target``, as a generator: it yields
    ``(state, u)`` for every accepted state, as it is accepted, and returns the :class:`Marched`
    (``StopIteration.value``; :func:`march` collects it).

    Parameters
    ----------
    u0, target : float
    solve_at : callable
        ``solve_at(u, states)`` -> the state at ``u`` (``states``: the accepted ones, newest
        last, for warm starts and predictors).
    steps : Steps
    history : sequence
        Accepted states before ``u0`` (their newest is the state at ``u0``); None entries are
        dropped.
    position : callable, optional
        ``position(state)`` -> u of an accepted state (e.g. its computed delta); default the
        value it was solved at.
    accept : callable, optional
        ``accept(state)`` -> whether a state is kept; default ``state.success``.
    stop : callable, optional
        ``stop(state, u, states)`` -> a reason (str) that ends the march at this attempt, or
        None; asked of every attempt before ``accept``.
    done : callable, optional
        ``done(states)`` -> a reason (str, may be empty) that the march's aim is met before the
        target, or None; asked before every step.
    arrived : callable, optional
        ``arrived(u)`` -> whether u is at the target; default: u has reached it in the
        direction of the march.
    max_solves : int, optional
        The march stops (reason ``"solves"``) before a solve beyond this many.
    """
    states = [s for s in history if s is not None]
    accept = accept or (lambda s: s.success)
    sign = 1.0 if target >= u0 else -1.0
    if arrived is None:
        def arrived(u):
            return not sign * (target - u) > 0
    u, s = u0, steps.first
    out = Marched(False, "", states, at=u0)
    while not arrived(u):
        if done is not None:
            why = done(states)
            if why is not None:
                out.reached, out.reason = True, why
                return out
        if max_solves is not None and out.solves >= max_solves:
            out.reason = "solves"
            return out
        nu = steps.next_value(u, s, target)
        if nu is None:
            out.reason = "range"
            return out
        sol = solve_at(nu, states)
        out.solves += 1
        out.tried = nu
        why = None if stop is None else stop(sol, nu, states)
        if why:
            out.failed, out.reason = sol, why
            return out
        if accept(sol):
            states.append(sol)
            u = out.at = nu if position is None else position(sol)
            s = steps.after_success(s)
            yield sol, nu
        else:
            out.failed = sol
            s = steps.after_failure(s, u, nu)
            if steps.ends(s, u):
                out.reason = "step"
                return out
    out.reached = True
    return out


def march(u0, target, solve_at, steps: Steps, *, on_accept=None, **options) -> Marched:
    """:func:`iter_march` run to its end (same parameters); ``on_accept(state, u)`` is called for
    every accepted state, as it is accepted."""
    marching = iter_march(u0, target, solve_at, steps, **options)
    while True:
        try:
            sol, u = next(marching)
        except StopIteration as end:
            return end.value
        if on_accept is not None:
            on_accept(sol, u)
