"""The model curves a fit interpolates: each computed once (memoised per process by scene,
depths and tolerance, and kept in the code cache's ``curves/`` folder for the next process),
checked to start at the data's shallowest depth and to reach its deepest, and
:class:`ModelCurves`, the nondimensional force F(delta; theta) interpolated across curves at
nodes theta of a shape parameter (monotone cubic in delta, cubic spline in theta).

A curve kept on disk is a curve file (``read_curve`` reads it as data, checked) named by a key
of everything it depends on: the scene, the depths, the tolerance, the solver's options and the
package's source (any edit of the code makes new keys).  A fit of a sample fitted before, in
any process, then computes no curve (``FitResult.curves_computed`` counts the computed ones);
``sb.options(model_curve_cache=False)`` turns the disk off."""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import logging
from collections import OrderedDict
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline, PchipInterpolator

__all__ = ["N_DEPTHS", "ModelCurves", "clear_model_curves", "code_fingerprint"]

#: Depths of every model curve (equally spaced up to delta_max).
N_DEPTHS = 40

log = logging.getLogger(__name__)

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
    path, disk_key = _disk_place(scene, deltas, tol)
    c = _read_kept(path, disk_key)
    if c is None:
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
        _keep(c, path, disk_key)
    if scene.transverse_shear:
        c = _with_shear(c)
    if key is not None:
        _CACHE[key] = c
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return c


@functools.cache
def code_fingerprint() -> str:
    """The package's and the derivation's source, hashed once per process (part of every key)."""
    from symbolic.version import source_fingerprint

    root = Path(__file__).resolve().parent.parent
    return source_fingerprint(*sorted({p.parent for p in root.rglob("*.py")}))


def _disk_place(scene, deltas, tol):
    """(path, key) of a model curve in the code cache's ``curves/`` folder, or (None, None)
    where the disk cache is off, the scene does not describe itself as data, or the folder is
    not trusted."""
    from ..config import OPTIONS
    from ..model import cache_dir, untrusted_reason
    from ..version import __version__

    if not OPTIONS.model_curve_cache:
        return None, None
    try:
        solver = {k: v for k, v in dataclasses.asdict(OPTIONS).items() if k not in _NOT_NUMERICS}
        payload = json.dumps({"scene": scene.to_dict(), "deltas": [float(x) for x in deltas], "tol": float(tol),
                              "options": solver, "code": code_fingerprint(), "version": __version__},
                             sort_keys=True)
    except (TypeError, ValueError, AttributeError):
        return None, None
    key = hashlib.sha256(payload.encode()).hexdigest()
    folder = cache_dir() / "curves"
    if folder.exists() and untrusted_reason(folder):
        return None, None
    return folder / f"curve_{key[:32]}.h5", key


#: Options that do not change a curve's numbers (not part of a kept curve's key)
_NOT_NUMERICS = ("progress_seconds", "health_seconds", "compile_in_background", "model_curve_cache", "max_fe_dofs",
                 "max_stability_dofs")


def _read_kept(path, key):
    """The kept curve at ``path`` if it is there and holds ``key``, else None."""
    from ..io import read_curve

    if path is None or not path.exists():
        return None
    try:
        c = read_curve(path)
    except (ValueError, OSError) as exc:
        log.info("ignoring the kept model curve %s: %s", path.name, exc)
        return None
    return c if c.settings.get("model_curve_key") == key and c.complete else None


def _keep(c, path, key):
    """Write the complete curve ``c`` to ``path`` (atomically); a cache that cannot be written is
    skipped."""
    if path is None or not c.complete:
        return
    c.settings["model_curve_key"] = key
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        c.to_hdf5(path, overwrite=True)
    except OSError as exc:
        log.info("model curve not kept (%s)", exc)


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

    ``source(scene, grid, tol, counter, progress)`` computes a node's curve: the shell model's
    (default; delta the mid-surface pole's displacement) or the solid's
    (:func:`shellbvp.fitting.solid.solid_curve`; delta the indenter's displacement).
    Every node must reach ``need`` (the deepest datum): without a shape
    parameter (one node, theta None) a curve that ends before it is a
    ValueError; with one, ``add`` returns False.  F is a cubic spline across
    the nodes at each depth and a monotone cubic (PCHIP) in delta.
    """

    def __init__(self, scene_at, grid, tol, need, counter, progress=None, source=None):
        self.scene_at, self.grid, self.tol, self.need, self.counter = scene_at, grid, tol, need, counter
        self.progress = progress
        # what computes a node's curve: the shell model's (default) or the solid's
        self.source = _model_curve if source is None else source
        self.nodes = {}  # theta -> curve
        self._spline = None

    def add(self, theta):
        """Compute the node curve at theta; False if it does not reach the data."""
        c = self.source(self.scene_at(theta), self.grid, self.tol, self.counter, self.progress)
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
