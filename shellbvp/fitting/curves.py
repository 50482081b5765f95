"""The model curves a fit interpolates: each computed once (memoised per process by scene,
depths and tolerance, and kept in the code cache's ``curves/`` folder for the next process),
checked to start at the data's shallowest depth and to reach its deepest, and
:class:`ModelCurves`, the nondimensional force F(delta; theta) interpolated across curves at
nodes theta of a shape parameter (monotone cubic in delta, cubic spline in theta).

A curve kept on disk is a curve file (``read_curve`` reads it as data, checked) named by a key
of everything it depends on: the scene, the depths, the tolerance, the solver's options and the
package's source (any edit of the code makes new keys).  A fit of a sample fitted before, in
any process, then computes no curve (``FitResult.curves_computed`` counts the computed ones);
``sb.options(model_curve_cache=False)`` turns the disk off.  A kept curve is data from disk
(:mod:`shellbvp.fitting.kept`): used only when it is this user's, carries a checksum of its
contents that matches, and holds the requested scene and depths with finite forces; a bad one
is set aside with a warning and computed again."""

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

from ..config import OPTIONS
from ..configurations import is_single_cap
from ..continuation import curve
from ..io import read_curve, write_curve
from ..pointload import solve_point_load
from ..state import solve
from ..version import __version__
from .kept import keep, kept_folder, read_kept

__all__ = ["N_DEPTHS", "ModelCurves", "clear_model_curves", "code_fingerprint", "beyond_message"]

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
    try:
        key = (scene, tuple(float(x) for x in deltas), float(tol))
        hash(key)
    except TypeError:
        key = None
    if key is not None and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    path, disk_key = _disk_place(scene, deltas, tol)
    c = _read_kept(path, disk_key, scene, deltas)
    if c is None:
        first = _model_start(scene, deltas, tol)  # shallower depths: the point-load limit (ModelCurves)
        bar, callback = progress("model curve", float(deltas[-1])) if progress is not None else (None, None)
        try:
            c = curve(scene, deltas=deltas[first:], tol=tol, estimate_error=False, callback=callback)
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
    where the disk cache is off, the scene does not describe itself as data, or the folder
    cannot hold curves (:func:`shellbvp.fitting.kept.kept_folder`: one warning)."""
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
    folder = kept_folder("curves", KEPT_WHAT)
    if folder is None:
        return None, None
    return folder / f"curve_{key[:32]}.h5", key


#: Options that do not change a curve's numbers (not part of a kept curve's key)
_NOT_NUMERICS = ("progress_seconds", "health_seconds", "compile_in_background", "model_curve_cache", "max_fe_dofs",
                 "max_stability_dofs")

#: What the cache's warnings call a kept shell curve
KEPT_WHAT = "model curves"

#: A kept model curve larger than this is not read (40 depths take about 50 kB).
MAX_KEPT_BYTES = 4 << 20


def content_checksum(c) -> str:
    """SHA-256 of everything a curve holds (scene, settings but this checksum, stop reason,
    completeness, flags and every point field): a kept curve carries it in
    ``settings["kept_sha256"]`` and is used only when it matches."""
    head = {"scene": c.scene.to_dict(), "settings": {k: v for k, v in c.settings.items() if k != "kept_sha256"},
            "stop_reason": str(c.stop_reason), "complete": bool(c.complete), "flags": [str(f) for f in c.flags]}
    h = hashlib.sha256(json.dumps(head, sort_keys=True, default=str).encode())
    for name in sorted(c.points):
        values = np.asarray(c.points[name])
        h.update(name.encode())
        h.update(np.ascontiguousarray(values, float).tobytes() if values.dtype.kind in "fiub"
                 else json.dumps([str(v) for v in values.tolist()]).encode())
    return h.hexdigest()


def _unsound(c, key, scene, deltas):
    """Why the curve ``c`` read from the cache cannot serve as ``scene``'s at ``deltas``, or None."""
    if c.settings.get("kept_sha256") != content_checksum(c):
        return "its checksum does not match its contents (damaged or edited)"
    if c.settings.get("model_curve_key") != key or not c.complete:
        return "made for another scene, grid or version, or not complete"
    if c.scene != scene:
        return "its scene is not the requested one"
    delta, force = np.asarray(c.delta, float), np.asarray(c.force, float)
    # a curve starts where a contact cap exists (``_model_start``): the grid's tail, the rest the
    # point-load limit's (added by ModelCurves, not kept)
    if not 0 < delta.size <= np.size(deltas) or not np.array_equal(delta, np.asarray(deltas, float)[-delta.size:]):
        return "its depths are not the requested ones"
    if not (np.all(np.isfinite(force)) and np.all(np.diff(delta) > 0)):
        return "a non-finite force or depths not increasing"
    return None


def _read_kept(path, key, scene, deltas):
    """The kept curve at ``path`` when it is sound and holds ``key``, ``scene`` and ``deltas``,
    else None (a bad one set aside with a warning)."""
    return read_kept(path, read_curve, lambda c: _unsound(c, key, scene, deltas), what="model curve",
                     max_bytes=MAX_KEPT_BYTES)


def _keep(c, path, key):
    """Write the complete curve ``c`` to ``path`` (atomically, read back and checked); a cache
    that cannot be written is skipped with one warning."""
    if path is None or not c.complete:
        return
    c.settings["model_curve_key"] = key
    c.settings["kept_sha256"] = content_checksum(c)

    def write(tmp):
        write_curve(c, tmp, overwrite=True)
        if (why := _unsound(read_curve(tmp), key, c.scene, c.delta)) is not None:
            raise ValueError(f"the curve read back is not the one written: {why}")

    keep(path, write, what=KEPT_WHAT)


def _with_shear(c):
    """The model curve's force at its own depths taken as the thick shell's (``delta +
    shear_delta``, :mod:`shellbvp.thickness`), up to the deepest one it reaches."""
    import dataclasses

    F = c.force_at(c.delta)
    n = int(np.argmax(~np.isfinite(F))) if not np.all(np.isfinite(F)) else F.size
    points = {k: np.asarray(v)[:n] for k, v in c.points.items()}
    points["force"] = F[:n]
    return dataclasses.replace(c, points=points, flags=list(c.flags[:n]))


#: The shallowest depths (indices of the curve's depths, doubling) a model curve may start from;
#: beyond the last the data are refused as too shallow against R_L.
START_TRIALS = (0, 1, 3, 7)


def _model_start(scene, deltas, tol):
    """The index of the first of ``deltas`` the model curve can start from (one solve per trial
    of :data:`START_TRIALS`), or ValueError.

    A curve at requested depths starts from a single contact cap; at depths where the scene's
    contact is the point-load limit (the cap exponentially small) it cannot, and there the
    point-load solution is the model's state (:func:`point_load_forces` gives its force).
    Data whose depths are nearly all in that limit are refused before the curve.  A closed shell
    on a substrate starts at the first depth: its configurations include the point loads.
    """
    if scene.two_contacts:  # a closed shell on a substrate has its point-load states in its own curve
        return 0
    why = ""
    for i in START_TRIALS:
        if i >= len(deltas) - 2:
            break
        sol = solve(scene, delta=float(deltas[i]), tol=tol, estimate_error=False, topology="cap")
        if sol.success and is_single_cap(sol):
            return i
        why = sol.message if not sol.success else "the contact there is the point-load limit (the contact cap is " \
                                                   "exponentially small)"
    raise ValueError(f"the model curve cannot start at its shallowest depths, up to delta = {deltas[i]:.3g} "
                     f"({i + 1}/{len(deltas)} of delta_max = 1.2 x the deepest data depth / R_L): {why}. The data are "
                     f"this shallow against R_L: check the displacement units and the rim radius R_L (--radius)")


def point_load_forces(scene, deltas, tol):
    """The model's nondimensional force at ``deltas`` shallower than its curve's first depth: the
    point-load limit of the smooth contact (:func:`shellbvp.pointload.solve_point_load`), each
    solved from the shallower one's state; NaN where a solve fails."""
    out, prev = [], None
    for d in deltas:
        sol = solve_point_load(scene, float(d), tol=tol, guess=prev)
        prev = sol if sol.success else None
        out.append(float(sol.force) if sol.success else np.nan)
    return np.array(out)


def beyond_message(c, need):
    return (f"the data reach delta = {need:.4g} (deepest displacement / R_L) but the model curve ends at "
            f"delta = {c.delta[-1]:.4g} ({c.stop_reason}): the model cannot explain the deepest points; "
            f"fit the data up to that depth (--max-depth {c.delta[-1]:.4g}, a fraction of R_L; fit(max_depth=...) in "
            f"m), or check the units and R_L (--radius)")


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
        self.forces = {}  # theta -> F at the grid's depths (the point-load limit's below the curve's first)
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
            raise ValueError(beyond_message(c, self.need))
        self.nodes[theta] = c
        shallow = self.grid[self.grid < c.delta[0] * (1 - 1e-9)] if self.source is _model_curve else self.grid[:0]
        F = np.r_[point_load_forces(self.scene_at(theta), shallow, self.tol), c.force]
        if not np.all(np.isfinite(F[:shallow.size])):
            raise ValueError(f"the point-load limit below the model curve's first depth delta = {c.delta[0]:.3g} "
                             f"could not be solved: the data are too shallow for this scene")
        self.forces[theta] = F
        self._spline = None
        return True

    @property
    def thetas(self):
        return sorted(self.nodes)

    def _table(self):
        if self._spline is None:
            th = self.thetas
            m = min(len(self.forces[t]) for t in th)
            rows = np.array([np.r_[0.0, self.forces[t][:m]] for t in th])
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
