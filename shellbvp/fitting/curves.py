"""The model curves a fit interpolates: each computed once per process (memoised by scene,
depths and tolerance), checked to start at the data's shallowest depth and to reach its
deepest, and :class:`ModelCurves`, the nondimensional force F(delta; theta) interpolated
across curves at nodes theta of a shape parameter (monotone cubic in delta, cubic spline in
theta)."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

__all__ = ["N_DEPTHS", "ModelCurves", "clear_model_curves"]

#: Depths of every model curve (equally spaced up to delta_max).
N_DEPTHS = 40

# the model curves memoised in this process, the least recently used dropped first
_CACHE: OrderedDict = OrderedDict()
_CACHE_SIZE = 32


def clear_model_curves():
    """Forget the model curves memoised in this process (the next fit computes its own)."""
    _CACHE.clear()


def _model_curve(scene, deltas, tol, counter=None, progress=None):
    """The curve of ``scene`` at ``deltas`` (memoised per process: repeated fits reuse it);
    ``progress(description, delta_max) -> (bar, callback)`` draws its progress."""
    from ..continuation import curve

    try:
        key = (scene, tuple(float(x) for x in deltas), float(tol))
        hash(key)
    except TypeError:
        key = None
    if key is not None and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    _check_model_start(scene, float(deltas[0]), tol)
    bar, callback = progress("model curve", float(deltas[-1])) if progress is not None else (None, None)
    try:
        c = curve(scene, deltas=deltas, tol=tol, estimate_error=False, callback=callback)
    finally:
        if bar is not None:
            bar.close()
    if counter is not None:
        counter[0] += 1
    c.solutions = []  # profiles are not needed here; keep the cache small
    if scene.transverse_shear:
        c = _with_shear(c)
    if key is not None:
        _CACHE[key] = c
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return c


def _with_shear(c):
    """The model curve's force at its own depths taken as the thick shell's (``delta +
    shear_delta``, :mod:`shellbvp.thickness`), up to the deepest one it reaches."""
    import dataclasses

    F = c.force_at(c.delta)
    n = int(np.argmax(~np.isfinite(F))) if not np.all(np.isfinite(F)) else F.size
    points = {k: np.asarray(v)[:n] for k, v in c.points.items()}
    points["force"] = F[:n]
    return dataclasses.replace(c, points=points, flags=list(c.flags[:n]))


def _check_model_start(scene, delta, tol):
    """ValueError unless the model curve can start at its shallowest depth ``delta`` (one solve).

    A curve at requested depths starts from a single contact cap; at depths where
    the scene's contact is the point-load limit (far shallower than the shell's
    size) it cannot start, so data that shallow are reported before the curve.
    """
    from ..configurations import is_single_cap
    from ..state import solve

    sol = solve(scene, delta=delta, tol=tol, estimate_error=False, topology="cap")
    if not (sol.success and is_single_cap(sol)):
        why = (sol.message if not sol.success else "the contact there is the point-load limit (the contact cap "
               "is exponentially small), from which the model curve cannot start")
        raise ValueError(f"the model curve cannot start at its shallowest depth delta = {delta:.3g} "
                         f"(1/{N_DEPTHS} of delta_max = 1.2 x the deepest data depth / R_L): {why}. "
                         f"Check the displacement units and the rim radius R_L (--radius): data this shallow "
                         f"against R_L do not determine mu*H with this scene")


def _beyond_message(c, need):
    return (f"the data reach delta = {need:.4g} (deepest displacement / R_L) but the model curve ends at "
            f"delta = {c.delta[-1]:.4g} ({c.stop_reason}): the model cannot explain the deepest points; "
            f"fit the data up to delta = {c.delta[-1]:.4g} x R_L, or check the units and R_L (--radius)")


class ModelCurves:
    """Nondimensional force F(delta; theta) from model curves at nodes theta_k on one delta grid.

    Every node must reach ``need`` (the deepest datum): without a shape
    parameter (one node, theta None) a curve that ends before it is a
    ValueError; with one, ``add`` returns False.  F is a cubic spline across
    the nodes at each depth and a monotone cubic (PCHIP) in delta.
    """

    def __init__(self, scene_at, grid, tol, need, counter, progress=None):
        self.scene_at, self.grid, self.tol, self.need, self.counter = scene_at, grid, tol, need, counter
        self.progress = progress
        self.nodes = {}  # theta -> curve
        self._spline = None

    def add(self, theta):
        """Compute the node curve at theta; False if it does not reach the data."""
        c = _model_curve(self.scene_at(theta), self.grid, self.tol, self.counter, self.progress)
        if len(c) < 3:
            raise ValueError(f"the model curve of this scene could not be computed to the data's depths "
                             f"({c.stop_reason})")
        if c.delta[-1] < self.need * (1 - 1e-12):
            if theta is not None:
                return False
            raise ValueError(_beyond_message(c, self.need))
        self.nodes[theta] = c
        self._spline = None
        return True

    @property
    def thetas(self):
        return sorted(self.nodes)

    def _table(self):
        if self._spline is None:
            th = self.thetas
            m = min(len(self.nodes[t]) for t in th)
            rows = np.array([np.r_[0.0, self.nodes[t].force[:m]] for t in th])
            self.top = float(self.grid[m - 1])
            self.x = np.r_[0.0, self.grid[:m]]
            self._spline = rows[0] if len(th) == 1 else CubicSpline(th, rows, axis=0)
        return self._spline

    def at(self, theta):
        """(F, dF/ddelta, top): PCHIP of F in delta at theta."""
        sp = self._table()
        vals = sp if isinstance(sp, np.ndarray) else sp(theta)
        P = PchipInterpolator(self.x, vals, extrapolate=False)
        return P, P.derivative(), self.top
