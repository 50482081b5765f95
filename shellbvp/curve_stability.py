"""Where a curve stops being axisymmetric: the stability of its states, per point and located.

:func:`assess` runs :func:`shellbvp.modal_stability.stability` on the states of a finished
:class:`~shellbvp.io.Curve` and fills

* per point ``stability_min`` (the smallest eigenvalue of the second variation over the modes
  n = 0..N, in the package's units ``mu H / R_L^2`` per squared displacement; NaN: not computed)
  and ``critical_mode`` (its n; -1: not computed);
* per curve :attr:`Curve.first_instability <shellbvp.io.Curve.first_instability>`: the first
  depth along the branch where a state is unstable, with its mode.

``"points"`` evaluates every recorded state.  ``"locate"`` evaluates about
:data:`LOCATE_SAMPLES` states spread along the curve, then every state between the last stable
and the first unstable one of them, brackets the first sign change of ``stability_min`` between
two neighbouring states and narrows it by regula falsi on states solved at depths in between
(the modes next to the critical one only; all modes again on the stable side of the final
bracket).  It assumes that a curve does not go unstable and back between two sampled states
(an unstable window shorter than the sample's spacing is missed); ``"points"`` makes no such
assumption, at the cost of every state.  A state the stability analysis does not handle gives
NaN, and the reason is kept in the curve's settings (``stability_note``): nothing is guessed for it.
"""

from __future__ import annotations

import math
import time

import numpy as np

from .io import STABILITY_FIELDS, FirstInstability
from .modal_stability import checked_modes, default_modes, stability
from .state import solve

__all__ = ["STABILITY_CHOICES", "STABILITY_FIELDS", "FirstInstability", "check_choice", "point_stability",
           "assess", "locate_zero", "verdict"]

#: What ``curve(stability=...)`` accepts
STABILITY_CHOICES = ("off", "points", "locate")
#: Modes each side of the critical one evaluated while a bracket is narrowed
NEAR_MODES = 2
#: Largest number of states solved to narrow a bracket
MAX_REFINE = 12
#: ``"locate"`` analyses about this many recorded states spread along the curve first
LOCATE_SAMPLES = 8


def check_choice(stability) -> str:
    """``stability`` if it is one of :data:`STABILITY_CHOICES`, else a one-line ValueError."""
    if not (isinstance(stability, str) and stability in STABILITY_CHOICES):
        raise ValueError(f"stability must be one of {STABILITY_CHOICES}; got {stability!r}")
    return stability


def point_stability(state, modes=None):
    """(smallest eigenvalue, its mode, "") of ``state``, or (NaN, -1, why) where the analysis does
    not handle it or fails."""
    if state is None or not state.success:
        return math.nan, -1, "the state did not converge"
    try:
        res = stability(state, modes=modes)
    except (ValueError, NotImplementedError) as exc:
        return math.nan, -1, " ".join(str(exc).split())
    return res.minimum, res.critical_mode, ""


def locate_zero(f, a, fa, b, fb, *, xtol, max_evals=MAX_REFINE):
    """Narrow a sign change of ``f`` from ``fa >= 0`` at ``a`` to ``fb < 0`` at ``b`` (Illinois
    regula falsi): ``(a, fa, b, fb, evaluations)`` with ``|b - a| <= xtol`` or the evaluations
    spent.  ``f(x)`` returns a number, or NaN where it cannot be evaluated (then the narrowing
    stops there)."""
    side = 0
    n = 0
    while abs(b - a) > xtol and n < max_evals:
        x = b - fb * (b - a) / (fb - fa) if fa != fb else 0.5 * (a + b)
        lo, hi = min(a, b), max(a, b)
        margin = 0.05 * (hi - lo)  # keep the trial inside: regula falsi may stall on an end
        x = min(max(x, lo + margin), hi - margin)
        fx = f(x)
        n += 1
        if not math.isfinite(fx):
            break
        if fx >= 0:
            a, fa = x, fx
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb = x, fx
            if side == 1:
                fa *= 0.5
            side = 1
    return a, fa, b, fb, n


def assess(curve, choice: str = "points", *, delta_tol: float = 1e-4, samples: int = LOCATE_SAMPLES,
           progress=None) -> None:
    """Fill ``curve``'s stability fields and ``first_instability`` (see the module docstring).

    Parameters
    ----------
    curve : Curve
        A curve with its states in memory (``curve.solutions``, as :func:`shellbvp.curve`
        returns it).
    choice : {"off", "points", "locate"}
    delta_tol : float
        ``"locate"``: the width of the final bracket in delta.
    samples : int
        ``"locate"``: about how many states spread along the curve are analysed first.
    progress : callable, optional
        Called as ``progress(delta)`` after each state analysed (a bar's step).
    """
    choice = check_choice(choice)
    n = len(curve)
    mins = np.full(n, math.nan)
    modes = np.full(n, -1, dtype=int)
    curve.points["stability_min"], curve.points["critical_mode"] = mins, modes
    curve.first_instability = None
    curve.learned(stability=choice)
    if choice == "off" or n == 0:
        return

    t0 = time.perf_counter()
    notes = []
    curve.learned(stability_modes=int(default_modes(curve.scene)[-1]))

    def analyse(i):
        mins[i], modes[i], why = point_stability(curve.solutions[i])
        if why and why not in notes:
            notes.append(why)
        if progress is not None:
            progress(float(curve.points["delta"][i]))
        return mins[i] < 0

    try:
        if choice == "points":
            for i in range(n):
                analyse(i)
        else:  # a sample first; every state only between its last stable and first unstable one
            stride = max(1, math.ceil(n / samples))
            sample = sorted(set(range(0, n, stride)) | {n - 1})
            hit = next((k for k, i in enumerate(sample) if analyse(i)), None)
            if hit is not None:
                start = sample[hit - 1] + 1 if hit else 0
                next((i for i in range(start, sample[hit]) if analyse(i)), None)
        first = next((i for i in range(n) if mins[i] < 0), None)
        if first is not None:
            curve.first_instability = _first(curve, first, mins, modes, choice, delta_tol)
    except KeyboardInterrupt:  # the curve is finished work: keep it, with what was assessed
        notes.append("stability interrupted")
    curve.learned(stability_note="; ".join(notes), stability_time=time.perf_counter() - t0)


def verdict(curve) -> str:
    """One line: whether the states' stability was checked (:func:`assess`, also on a curve read
    back from its file) and what it found -- a stable curve is said to be so, and to what depth."""
    choice = curve.settings.get("stability", "off")
    mins = np.asarray(curve.points.get("stability_min", ()), float)
    checked = np.isfinite(mins)
    if choice in (None, "off") or not len(curve):
        return "stability: not checked"
    if not checked.any():
        return f"stability: not checked at any state ({curve.settings.get('stability_note') or 'none analysed'})"
    top = curve.settings.get("stability_modes")
    modes = f", modes n = 0..{int(top)}" if isinstance(top, (int, float)) and math.isfinite(top) else ""
    analysed = f"{int(checked.sum())} of {len(curve)} states analysed{modes}"
    if curve.first_instability is not None:
        return f"stability: checked ({analysed}); {curve.first_instability.summary()}"
    deepest = float(np.max(np.asarray(curve.points["delta"], float)[checked]))
    return f"stability: checked, stable to delta = {deepest:.4g} ({analysed})"


def _first(curve, i, mins, modes, choice, delta_tol):
    d, F = curve.points["delta"], curve.points["force"]
    stable = [j for j in range(i) if np.isfinite(mins[j]) and mins[j] >= 0]
    unlocated = dict(delta=float(d[i]), force=float(F[i]), mode=int(modes[i]), located=False)
    if not stable:
        return FirstInstability(**unlocated, bracket=(math.nan, float(d[i])),
                                message="unstable from the first state analysed")
    j = stable[-1]
    bracket = (float(d[j]), float(d[i]))
    if choice != "locate":
        return FirstInstability(**unlocated, bracket=bracket, message="between two recorded points")
    if j != i - 1 or not np.all(np.diff(d[j:i + 1]) > 0):
        return FirstInstability(**unlocated, bracket=bracket,
                                message="not narrowed: states between the bracket's ends were not analysed")
    return _narrowed(curve, j, i, mins, modes, delta_tol)


def _narrowed(curve, j, i, mins, modes, delta_tol):
    sols, d = curve.solutions, curve.points["delta"]
    st = curve.settings
    near = {int(modes[i]), int(modes[j])}
    every = set(checked_modes(curve.scene).tolist())  # a closed shell's n = 1 (rigid motions) left out
    chosen = np.array(sorted({int(m) for c in near for m in range(c - NEAR_MODES, c + NEAR_MODES + 1)
                              if m in every}))
    states = {}

    def f(delta):
        guess = sols[j] if abs(delta - d[j]) <= abs(delta - d[i]) else sols[i]
        try:
            s = solve(curve.scene, delta=delta, guess=guess, tol=st["tol"], max_nodes=st["max_nodes"],
                      estimate_error=False)
        except ValueError:
            return math.nan
        if not s.success or s.topology not in (sols[j].topology, sols[i].topology):
            return math.nan
        lam, n, _ = point_stability(s, modes=chosen)
        states[delta] = (s, n)
        return lam

    a, fa, b, fb, evals = locate_zero(f, float(d[j]), float(mins[j]), float(d[i]), float(mins[i]),
                                      xtol=delta_tol)
    mode = states[b][1] if b in states else int(modes[i])
    stable_state = states[a][0] if a in states else sols[j]
    check, check_mode, _ = point_stability(stable_state)  # every mode on the stable side
    if a in states and check < 0:
        return FirstInstability(delta=float(d[i]), force=float(curve.points["force"][i]), mode=int(modes[i]),
                                located=False, bracket=(float(d[j]), float(d[i])),
                                message=f"not narrowed: mode {check_mode} is unstable inside the bracket")
    Fa = float(states[a][0].force) if a in states else float(curve.points["force"][j])
    Fb = float(states[b][0].force) if b in states else float(curve.points["force"][i])
    t = fa / (fa - fb) if fa != fb else 0.5
    located = abs(b - a) <= delta_tol
    message = (f"narrowed to {abs(b - a):.2g} in delta by {evals} states" if located
               else f"narrowed to {abs(b - a):.2g} in delta by {evals} states (not to {delta_tol:g})")
    return FirstInstability(delta=a + t * (b - a), force=Fa + t * (Fb - Fa), mode=int(mode), located=located,
                            bracket=(float(a), float(b)), message=message)

