"""Which depths and tolerances a state accepts, checked before any solve.

A depth below the collocation tolerance is in the solver's noise; one beyond the meridian's
reach (:func:`delta_bounds`) would stretch it more than any curve goes.  Curves, sweeps and
single solves refuse such input with a one-line error naming the parameter.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["delta_bounds", "check_delta", "check_tol", "MEAN_STRETCH_LIMIT"]


#: Mean meridional stretch taken as beyond reach (see :func:`delta_bounds`).
MEAN_STRETCH_LIMIT = 2.5


def delta_bounds(scene, tol: float) -> tuple[float, float]:
    """The pole displacements ``(low, high)`` for which a state is computed.

    ``low = tol``: the states are O(1)-scaled and solve_bvp's tolerance is
    absolute for them, so a displacement below ``tol`` is in the solver's noise
    (measured on the base scene at tol 1e-6, point-load limit F/delta -> 1.2625:
    within 0.03 % at delta = 10 tol, 7 % off at delta = tol (and ``force_error``
    says so), of either sign at tol/100).

    ``high = Z(0) - Z(L) + 2.5 l`` (l the reference meridian's length, Z(0) the pole's
    and Z(L) the rim's height): the deformed meridian joins the pole, at height
    ``Z(0) - delta``, to the fixed rim, so it is at least as long as their height
    difference ``Z(L) - Z(0) + delta``; beyond ``high`` its mean stretch would
    exceed 2.5 even hanging straight down (``MEAN_STRETCH_LIMIT``).  The dome: 4.93
    (delta = 5 is refused at once), the base hemisphere: 2.93 (a wide indenter,
    rho = 0.6, pushes it to delta = 2.5 with every state valid), a flat plate: 2.5.

    Parameters
    ----------
    scene : Scene
    tol : float
        The collocation tolerance the states will be solved with.

    Returns
    -------
    (float, float)
        The smallest and the largest pole displacement accepted.

    Examples
    --------
    >>> import shellbvp as sb
    >>> low, high = sb.delta_bounds(sb.Scene.preset("dome"), 1e-6)
    >>> low, round(high, 2)
    (1e-06, 4.93)
    """
    return float(tol), _delta_high(scene)


@functools.lru_cache(maxsize=64)  # a scene is frozen and hashable, as for scene._reference_volume
def _delta_high(scene) -> float:
    """``high`` of :func:`delta_bounds`, measured once per scene (each curve checks up to five
    depths against it, each solve one; tabulating the shell at 4001 points costs ~0.2 ms)."""
    mod = scene.model()
    S = np.linspace(0.0, scene.shell_length, 4001)
    ref = mod.reference_shell(S, scene.parameters(mod))
    R, Z = np.broadcast_to(ref["R"], S.shape), np.broadcast_to(ref["Z"], S.shape)
    length = float(np.sum(np.hypot(np.diff(R), np.diff(Z))))
    return float(Z[0] - Z[-1] + MEAN_STRETCH_LIMIT * length)


def check_tol(tol):
    """ValueError unless ``tol`` (solve_bvp's tolerance) is a number in [1e-12, 1e-1]."""
    if isinstance(tol, bool) or not (isinstance(tol, (int, float, np.floating)) and 1e-12 <= tol <= 1e-1):
        raise ValueError(f"tol must be in [1e-12, 1e-1]; got {tol!r}")


def check_delta(name, value, scene, tol):
    """ValueError naming ``name`` unless ``value`` is within :func:`delta_bounds`."""
    low, high = delta_bounds(scene, tol)
    if not low <= value <= high:
        raise ValueError(f"{name} = {value:g} is outside [{low:g}, {high:.4g}] for this scene: below tol "
                         f"= {low:g} a displacement is in the solver's noise (loosen tol for smaller ones), "
                         f"above {high:.4g} the meridian would be more than doubled in length")
