"""Parameter sweeps: one curve per combination of parameter values, computed through any
``concurrent.futures.Executor``, gathered into one resumable HDF5 file.

Workers compute curves and return plain records (:func:`run_curve`: arrays, strings and
numbers; no module objects); the parent alone writes the file, so no two processes ever
write it.  The generated code is derived in the parent, once per structure, before any work
is sent out: workers on this machine (a process pool, a Dask LocalCluster) then load it from
the code cache instead of deriving it concurrently.

Layout (format ``shellbvp-sweep``, version 1)::

    /                      attrs: format, format_version, package_version, created, updated,
                           default = "sweep" (NeXus)
    /sweep                 NXentry, default = "overview"; attrs: base_scene (JSON), parameters (JSON list of the swept names),
                           grid (JSON {name: [values]}), delta_max, settings (JSON: the curve
                           settings), units = "nondimensional"
    /sweep/index/<name>    (n,) each swept parameter's value of combination i (units nondimensional)
    /sweep/index/status    (n,) "pending", "complete", "stopped" (the curve ended before its
                           stopping rule) or "error" (the curve raised; see message)
    /sweep/index/stop_reason, message, group   (n,) strings (units "none"); group names the curve
    /sweep/index/points    (n,) points of each curve (units "count")
    /sweep/index/wall_time (n,) seconds spent on each curve in its worker (units "s")
    /sweep/curves/curve_<i>  the curve of combination i, in the layout of a curve file's
                           ``/entry/curve`` group (``shellbvp.io``), every dataset with a units attribute
    /sweep/overview        NXdata: F at delta_max of every combination (NaN where its curve did not
                           reach it) over the swept values, or over "combination" (_write_overview)

Every write goes to a copy of the file in the same directory, which then replaces the file
by ``os.replace`` (atomic on POSIX): a reader, a crash or a ``kill -9`` only ever sees the
file as it was after some complete write, never a half-written one.  The copy costs a full
file write per batch of finished curves; the batches are whatever has finished while the
previous write ran, so the writer keeps up as long as writing the file is faster than the
workers finish curves (see the README for the arithmetic).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import inspect
import glob
import itertools
import json
import logging
import math
import multiprocessing
import os
import re
import shutil
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .continuation import curve
from .io import Curve, read_curve_group, write_curve_group
from .materials import Gent, MooneyRivlin
from .config import OPTIONS
from .paths import atomic_file, open_hdf5
from .version import __version__

log = logging.getLogger(__name__)

__all__ = ["sweep", "check_grid", "MAX_CELLS", "die_with_parent", "read_sweep", "run_curve", "Sweep", "SWEEP_PARAMETERS", "STATUSES", "FORMAT",
           "FORMAT_VERSION", "is_sweep_file", "dask_executor", "local_pool", "scene_at"]

FORMAT = "shellbvp-sweep"
FORMAT_VERSION = 1
#: Parameters a sweep may vary (run-time parameters of the generated code: no new derivation).
SWEEP_PARAMETERS = ("beta", "rho", "gamma", "alpha", "Jm", "pressure")
#: Status of a combination in the index.
STATUSES = ("pending", "complete", "stopped", "error")
#: Settings of :func:`shellbvp.curve` a sweep passes on (the rest are fixed by the sweep).
_CURVE_SETTINGS = tuple(k for k in inspect.signature(curve).parameters if k not in ("scene", "delta_max", "callback"))
_INDEX_UNITS = {"status": "none", "stop_reason": "none", "message": "none", "group": "none",
                "points": "count", "wall_time": "s"}


# -- the grid ------------------------------------------------------------------------------------
def scene_at(base_scene, values: dict):
    """``base_scene`` with the swept parameters set (``alpha``: Mooney-Rivlin, ``Jm``: Gent)."""
    changes = {k: v for k, v in values.items() if k in ("beta", "rho", "gamma", "pressure")}
    if "alpha" in values:
        changes["material"] = MooneyRivlin(values["alpha"])
    if "Jm" in values:
        changes["material"] = Gent(values["Jm"])
    return base_scene.replace(**changes)


#: The most combinations a sweep takes unless told otherwise (``max_cells``, ``--max-cells``): a
#: grid is counted before anything is allocated for it; 1e8 combinations would take GBs first.
MAX_CELLS = 10_000


def check_grid(base_scene, grid, max_cells=MAX_CELLS) -> dict:
    """The grid as {name: tuple of floats}, checked (its size first, against ``max_cells``);
    ValueError naming the parameter."""
    if not isinstance(grid, dict) or not grid:
        raise ValueError(f"grid must be a non-empty mapping of parameter names to values, names from "
                         f"{SWEEP_PARAMETERS}; got {grid!r}")
    if isinstance(max_cells, bool) or not isinstance(max_cells, int) or max_cells < 1:
        raise ValueError(f"max_cells must be an integer >= 1; got {max_cells!r}")
    sizes = {}
    for name, values in grid.items():
        try:
            sizes[name] = len(values) if hasattr(values, "__len__") else 1
        except TypeError:
            sizes[name] = 1
    if math.prod(sizes.values()) > max_cells:
        shape = " x ".join(f"{sizes[n]} {n}" for n in sizes)
        raise ValueError(f"grid: {math.prod(sizes.values())} combinations ({shape}) exceed max_cells = {max_cells}; "
                         f"pass max_cells= (CLI: --max-cells) to allow more")
    out = {}
    for name, values in grid.items():
        if name not in SWEEP_PARAMETERS:
            raise ValueError(f"grid: {name!r} is not a parameter a sweep varies; choose from {SWEEP_PARAMETERS}")
        if name == "alpha" and not isinstance(base_scene.material, MooneyRivlin):
            raise ValueError(f"grid: alpha needs a Mooney-Rivlin base scene; its material is {base_scene.material!r}")
        if name == "Jm" and not isinstance(base_scene.material, Gent):
            raise ValueError(f"grid: Jm needs a Gent base scene; its material is {base_scene.material!r}")
        try:
            vals = tuple(float(v) for v in np.atleast_1d(values))
        except (TypeError, ValueError):
            raise ValueError(f"grid: {name} must be a list of numbers; got {values!r}") from None
        if not vals or not all(math.isfinite(v) for v in vals):
            raise ValueError(f"grid: {name} must be a non-empty list of finite numbers; got {values!r}")
        if len(set(vals)) != len(vals):
            raise ValueError(f"grid: {name} lists a value twice: {list(vals)}")
        out[name] = vals
    if "alpha" in out and "Jm" in out:
        raise ValueError("grid: alpha (Mooney-Rivlin) and Jm (Gent) belong to different materials")
    return out


def _combinations(grid: dict) -> list[tuple]:
    return list(itertools.product(*grid.values()))


def _check_settings(settings: dict) -> dict:
    unknown = sorted(set(settings) - set(_CURVE_SETTINGS))
    if unknown:
        raise ValueError(f"unknown curve setting {unknown[0]!r}; a sweep passes on {_CURVE_SETTINGS}")
    try:  # stored in the file as JSON: only plain data (and compared on a re-run)
        return json.loads(json.dumps(settings, sort_keys=True))
    except TypeError:
        raise ValueError(f"curve settings must be plain numbers, strings or lists; got {settings!r}") from None


def _check_scenes(base_scene, names, combos, delta_max, settings):
    """Every combination's scene and depth, checked before any curve (ValueError naming it)."""
    from .bounds import check_delta, check_tol

    tol = settings.get("tol", 1e-6)
    check_tol(tol)
    if isinstance(delta_max, bool) or not isinstance(delta_max, (int, float)) or not math.isfinite(delta_max) \
            or delta_max <= 0:
        raise ValueError(f"delta_max must be a finite number > 0; got {delta_max!r}")
    scenes = []
    for combo in combos:
        where = ", ".join(f"{n}={v:g}" for n, v in zip(names, combo))
        try:
            scene = scene_at(base_scene, {n: float(v) for n, v in zip(names, combo)})
            check_delta("delta_max", delta_max, scene, tol)
        except ValueError as exc:
            raise ValueError(f"grid point {where}: {exc}") from None
        scenes.append(scene)
    return scenes


# -- the work (runs in a worker) -----------------------------------------------------------------
def run_curve(index: int, scene, delta_max: float, settings: dict) -> dict:
    """Compute one curve of a sweep and return it as a plain record (what a worker sends back).

    A curve that raises is recorded with status "error" and the exception's text: it is a
    result (the same inputs raise again), not a lost task.
    """
    t0 = time.perf_counter()
    try:
        c = curve(scene, delta_max, **settings)
    except Exception as exc:  # recorded in the index with its message, never hidden
        return {"index": index, "status": "error", "message": f"{type(exc).__name__}: {exc}",
                "wall_time": time.perf_counter() - t0}
    return {"index": index, "status": "complete" if c.complete else "stopped", "message": "",
            "stop_reason": c.stop_reason, "complete": c.complete, "interrupted": c.interrupted,
            "points": {k: np.asarray(v) for k, v in c.points.items()}, "flags": list(c.flags),
            "settings": c.settings, "version": c.version, "wall_time": time.perf_counter() - t0}


def _curve_of(record, scene) -> Curve:
    return Curve(scene=scene, points=record["points"], flags=record["flags"], stop_reason=record["stop_reason"],
                 complete=record["complete"], interrupted=record["interrupted"], settings=record["settings"],
                 version=record.get("version", ""))


# -- the result ----------------------------------------------------------------------------------
@dataclass
class Sweep:
    """A sweep's grid and curves (from :func:`sweep` or :func:`read_sweep`).

    Attributes
    ----------
    parameters : tuple of str
        Swept names, in grid order (the axes of the gridded arrays).
    values : dict of ndarray
        Each parameter's values (an axis of the grid).
    base_scene : Scene
    delta_max : float
    settings : dict
        Curve settings of every curve.
    index : dict of ndarray
        One entry per combination (file order): each parameter's value, ``status``,
        ``stop_reason``, ``message``, ``points``, ``wall_time``.
    curves : dict
        Combination number -> :class:`Curve` (finished curves only).
    computed : int
        Curves computed by the call that returned this (0 from :func:`read_sweep`).
    lost : int
        Curves the executor failed to run in that call (a worker died): still pending.
    delta : ndarray
        The common depths ``linspace(0, delta_max, 101)`` of :attr:`force`.
    force : ndarray, shape ``(len(values[p0]), len(values[p1]), ..., delta.size)``
        Each curve's F at :attr:`delta` (monotone cubic in delta through (0, 0) and its points
        up to its first turn in delta); NaN beyond each curve's deepest point and where the
        combination has no curve.
    status, points, wall_time : ndarray, shape of the grid
        From the index ("" / -1 / NaN where the grid has no such combination).

    Examples
    --------
    >>> import shellbvp as sb
    >>> res = sb.sweep(sb.Scene.preset("base"), {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}, delta_max=0.1,
    ...                workers=1, deltas=[0.05, 0.1], estimate_error=False)
    >>> res.parameters, res.shape, res.force.shape
    (('beta', 'rho'), (2, 2), (2, 2, 101))
    >>> res.counts(), res.finished
    ({'complete': 4}, True)
    >>> bool(res.force[1, 0, -1] > res.force[0, 0, -1])       # a stiffer shell pushes back harder
    True
    """

    parameters: tuple
    values: dict
    base_scene: object
    delta_max: float
    settings: dict
    index: dict
    curves: dict = field(default_factory=dict, repr=False)
    computed: int = 0
    lost: int = 0
    delta: np.ndarray = field(default=None, repr=False)
    force: np.ndarray = field(default=None, repr=False)
    status: np.ndarray = field(default=None, repr=False)
    points: np.ndarray = field(default=None, repr=False)
    wall_time: np.ndarray = field(default=None, repr=False)

    def __post_init__(self):
        from scipy.interpolate import PchipInterpolator

        shape = tuple(len(self.values[p]) for p in self.parameters)
        self.delta = np.linspace(0.0, self.delta_max, 101)
        self.force = np.full(shape + (self.delta.size,), np.nan)
        self.status = np.full(shape, "", dtype=object)
        self.points = np.full(shape, -1, dtype=int)
        self.wall_time = np.full(shape, np.nan)
        for i in range(len(self.index["status"])):
            pos = tuple(int(np.flatnonzero(self.values[p] == self.index[p][i])[0]) for p in self.parameters)
            self.status[pos] = self.index["status"][i]
            self.points[pos] = self.index["points"][i]
            self.wall_time[pos] = self.index["wall_time"][i]
            c = self.curves.get(i)
            if c is None or len(c) < 2:
                continue
            d, F = np.asarray(c.delta, float), np.asarray(c.force, float)
            turn = np.flatnonzero(np.diff(d) <= 0)
            n = turn[0] + 1 if turn.size else d.size  # up to the first turn: F as a function of delta
            x, y = np.r_[0.0, d[:n]], np.r_[0.0, F[:n]]
            ok = np.r_[True, np.diff(x) > 0]
            self.force[pos] = PchipInterpolator(x[ok], y[ok], extrapolate=False)(self.delta)

    @property
    def shape(self):
        return self.status.shape

    def counts(self) -> dict:
        """Number of combinations by status (only the statuses present)."""
        st = list(self.index["status"])
        return {s: st.count(s) for s in STATUSES if s in st}

    @property
    def finished(self) -> bool:
        """No combination is pending."""
        return "pending" not in set(self.index["status"])


# -- the file ------------------------------------------------------------------------------------
def is_sweep_file(path) -> bool:
    """True if ``path`` is an HDF5 file of format ``shellbvp-sweep``."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
    except OSError:
        return False
    return (fmt.decode() if isinstance(fmt, bytes) else fmt) == FORMAT


def _rewrite(path: Path, edit, *, fresh: bool = False) -> None:
    """Apply ``edit(h5file)`` to a copy of ``path`` (a new file if there is none or ``fresh``) and
    rename it into place.

    The rename is the only moment the file changes: an interruption at any point before it
    (Ctrl-C, kill -9, a full disk) leaves the previous complete file, and at most a hidden
    ``.<name>.*.tmp`` beside it (removed here on any Python-level failure).
    """
    import h5py

    with atomic_file(path) as tmp:
        copy = path.exists() and not fresh
        if copy:
            shutil.copyfile(path, tmp)
        with h5py.File(tmp, "a" if copy else "w") as f:
            edit(f)
            f.attrs["updated"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _label_units(g) -> None:
    """A units attribute on every dataset of a curve group (its own layout has them on the group)."""
    for name, d in g.items():
        if hasattr(d, "dtype") and "units" not in d.attrs:
            d.attrs["units"] = {"wall_time": "s", "delta_m": "m", "force_N": "N"}.get(
                name, "none" if d.dtype.kind in "OSU" else "nondimensional")


def _write_index(s, names, index) -> None:
    import h5py

    if "index" in s:
        del s["index"]
    ig = s.create_group("index")
    ig.attrs["NX_class"] = "NXcollection"
    for name in names:
        ig.create_dataset(name, data=np.asarray(index[name], float)).attrs["units"] = "nondimensional"
    for key in ("status", "stop_reason", "message", "group"):
        ig.create_dataset(key, data=np.array(index[key], dtype=object), dtype=h5py.string_dtype())
    ig.create_dataset("points", data=np.asarray(index["points"], np.int64))
    ig.create_dataset("wall_time", data=np.asarray(index["wall_time"], float))
    for key, units in _INDEX_UNITS.items():
        ig[key].attrs["units"] = units


def _write_overview(s, names, meta, index) -> None:
    """``/sweep/overview``, the file's plottable NXdata: F at delta_max of every combination whose
    curve reached it (NaN otherwise), over the swept parameters' values when the combinations are
    their full product in grid order (an image for two), else over the combination number."""
    if "overview" in s:
        del s["overview"]
    o = s.create_group("overview")
    dmax = float(meta["delta_max"])
    force = np.full(len(index["status"]), np.nan)
    for i, (status, group) in enumerate(zip(index["status"], index["group"])):
        if status == "complete" and group and group in s:
            d, f = s[group]["delta"], s[group]["force"]
            if d.shape[0] and abs(float(d[-1]) - dmax) <= 1e-9 * (1 + dmax):
                force[i] = float(f[-1])
    grid = meta["grid"]
    full = list(itertools.product(*(grid[n] for n in names)))
    here = list(zip(*(index[n] for n in names)))
    axes = list(names) if here == [tuple(map(float, c)) for c in full] else ["combination"]
    if axes == ["combination"]:
        o.create_dataset("combination", data=np.arange(force.size)).attrs["units"] = "count"
    else:
        force = force.reshape([len(grid[n]) for n in names])
        for n in names:
            o.create_dataset(n, data=np.asarray(grid[n], float)).attrs["units"] = "nondimensional"
    ds = o.create_dataset("force", data=force)
    ds.attrs.update({"units": "nondimensional", "long_name": f"F / (mu H R_L) at delta = {dmax:g}"})
    o.attrs.update({"NX_class": "NXdata", "signal": "force", "axes": axes})
    s.attrs["default"] = "overview"


def _new_index(names, combos) -> dict:
    n = len(combos)
    index = {name: [c[k] for c in combos] for k, name in enumerate(names)}
    index.update(status=["pending"] * n, stop_reason=[""] * n, message=[""] * n, group=[""] * n,
                 points=[0] * n, wall_time=[float("nan")] * n)
    return index


def _read_attrs(path):
    """(meta, index) of a sweep file; ValueError with one line naming what is wrong.

    Every item is checked before use (``shellbvp.schema``), and the file's claims are not taken
    on trust: a cell is complete (or stopped) only with its own readable curve group
    (``curves/curve_<i>``); one without is read as pending, so that a resume computes it.
    """
    import h5py

    from . import schema as sc

    with open_hdf5(path, fmt=FORMAT, group="sweep", kind="sweep") as f:
        try:
            version = sc.attr_int(f, "format_version")
        except ValueError as exc:
            raise ValueError(f"{path}: sweep {exc}") from None
        if version != FORMAT_VERSION:
            raise ValueError(f"{path}: sweep format version {version} is not one this shellbvp reads "
                             f"({FORMAT_VERSION})")
        s = f["sweep"]
        try:
            meta = {k: sc.parse_json(sc.attr_text(s, k), f"attribute {k}")
                    for k in ("base_scene", "parameters", "grid", "settings")}
            delta_max = s.attrs["delta_max"]
            if isinstance(delta_max, (bool, np.bool_)) or not isinstance(delta_max, (int, float, np.number)) \
                    or not math.isfinite(float(delta_max)):
                raise ValueError(f"attribute delta_max must be a number; got {delta_max!r}")
            meta["delta_max"] = float(delta_max)
            meta["package_version"] = sc.attr_text(f, "package_version") if "package_version" in f.attrs else ""
            names = meta["parameters"]
            if not (isinstance(names, list) and set(names) <= set(SWEEP_PARAMETERS)
                    and isinstance(meta["grid"], dict) and list(meta["grid"]) == names):
                raise ValueError("attributes parameters and grid do not agree")
            for n in names:
                if not (isinstance(meta["grid"][n], list) and all(isinstance(v, (int, float)) and
                                                                  not isinstance(v, bool) for v in meta["grid"][n])):
                    raise ValueError(f"attribute grid: {n} must be a list of numbers")
            if math.prod(len(meta["grid"][n]) for n in names) > 10 * MAX_CELLS:
                raise ValueError(f"the grid holds more than {10 * MAX_CELLS} combinations")
            ig = s["index"]
            status = sc.text_dataset(ig, "status")
            n = len(status)
            index = {name: sc.dataset(ig, name, length=n) for name in names}
            for name in names:
                off = [float(v) for v in index[name] if float(v) not in meta["grid"][name]]
                if off:
                    raise ValueError(f"index/{name} holds {off[0]!r}, which is not on the grid")
            index["status"] = status
            for key in ("stop_reason", "message", "group"):
                index[key] = sc.text_dataset(ig, key, length=n)
            index["points"] = sc.dataset(ig, "points", kind="int", length=n).tolist()
            index["wall_time"] = sc.dataset(ig, "wall_time", length=n).tolist()
            bad = sorted(set(index["status"]) - set(STATUSES))
            if bad:
                raise ValueError(f"index/status holds {bad[0]!r}; expected one of {STATUSES}")
            for i, st in enumerate(index["status"]):
                if st not in ("complete", "stopped"):
                    continue
                own = f"curves/curve_{i:06d}"
                if index["group"][i] != own or not isinstance(s.get(own), h5py.Group):
                    why = ("its curve is missing" if index["group"][i] in ("", own)
                           else f"it names another curve ({index['group'][i]})")
                    index["status"][i], index["group"][i] = "pending", ""
                    index["message"][i] = f"read as pending: the file called it {st} but {why}"
        except KeyError as exc:
            raise ValueError(f"{path}: attribute or dataset {exc} missing") from None
        except (TypeError, RecursionError) as exc:
            raise ValueError(f"{path}: malformed sweep metadata ({exc})") from None
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
    return meta, index


def read_sweep(path) -> Sweep:
    """Read a sweep file written by :func:`sweep` (finished curves and the gridded arrays).

    Parameters
    ----------
    path : str or Path
        A file of format ``shellbvp-sweep`` (complete or not: pending combinations are listed).

    Returns
    -------
    Sweep
        With ``computed = 0``.

    Raises
    ------
    ValueError
        A one-line reason for a missing, foreign or malformed file.

    Examples
    --------
    >>> import shellbvp as sb
    >>> _ = sb.sweep(sb.Scene.preset("base"), {"rho": [0.2, 0.25]}, delta_max=0.1, out="rho.h5", workers=1,
    ...              deltas=[0.05, 0.1], estimate_error=False)
    >>> grid = sb.read_sweep("rho.h5")
    >>> grid.index["status"].tolist(), grid.computed
    (['complete', 'complete'], 0)
    >>> c = grid.curves[1]                                     # a Curve: rho = 0.25
    >>> c.scene.rho, len(c)
    (0.25, 2)
    >>> bool(abs(grid.force[1, -1] - c.force[-1]) < 1e-12)     # F at delta_max, on the common grid
    True
    """
    import h5py

    from .scene import Scene

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    meta, index = _read_attrs(path)
    curves = {}
    with h5py.File(path, "r") as f:
        for i, name in enumerate(index["group"]):
            if name:
                try:
                    curves[i] = read_curve_group(f["sweep"][name], meta["package_version"])
                except (ValueError, KeyError) as exc:
                    raise ValueError(f"{path}: sweep/{name}: {exc}") from None
    names = meta["parameters"]
    return Sweep(parameters=tuple(names), values={n: np.asarray(meta["grid"][n], float) for n in names},
                 base_scene=Scene.from_dict(meta["base_scene"]), delta_max=meta["delta_max"],
                 settings=meta["settings"], index={k: np.asarray(v) for k, v in index.items()}, curves=curves)


def _reconcile(path, meta_new, extend) -> tuple[dict, dict] | None:
    """The existing file's (grid, index), extended with the new combinations if asked; None if
    there is no file.  A file made with other settings is refused with what differs."""
    if not path.exists():
        return None
    meta, index = _read_attrs(path)
    for key, what in (("base_scene", "base scene"), ("delta_max", "delta_max"), ("settings", "curve settings")):
        if meta[key] != meta_new[key]:
            raise ValueError(f"{path} holds a sweep with another {what} ({json.dumps(meta[key], sort_keys=True)}; "
                             f"asked {json.dumps(meta_new[key], sort_keys=True)}): choose another output file "
                             f"(or --overwrite to start it anew)")
    old, new = meta["grid"], meta_new["grid"]
    if list(old) != list(new):
        raise ValueError(f"{path} sweeps {list(old)}; asked {list(new)}: the parameters of a sweep file cannot "
                         f"change (choose another output file)")
    if all(list(old[n]) == list(new[n]) for n in old):
        return old, index
    if not extend:
        diff = "; ".join(f"{n}: file {old[n]}, asked {list(new[n])}" for n in old if list(old[n]) != list(new[n]))
        raise ValueError(f"{path} holds another grid ({diff}): pass extend=True (--extend) to add the new "
                         f"combinations to it, or choose another output file")
    have = set(zip(*(index[n] for n in old)))
    grid = {n: list(old[n]) + [v for v in new[n] if v not in old[n]] for n in old}
    added = [c for c in _combinations(new) if c not in have]
    more = _new_index(list(old), added)
    for k in index:
        index[k] = list(index[k]) + more[k]
    log.info("extending %s by %d combinations", path, len(added))
    return grid, index


# -- executors -----------------------------------------------------------------------------------
#: Scheduler addresses a sweep connects to: plain TCP (``tcp://host:port`` or ``host:port``).
#: TLS needs certificates set up in Dask's own configuration, UCX a build of its own, inproc a
#: scheduler in this process: each is refused with a line saying so.
SCHEDULER_ADDRESS = re.compile(r"^(?:tcp://)?(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9_.-]+):([0-9]{1,5})$")


def dask_executor(address: str, timeout: float = 10.0):
    """A ``concurrent.futures.Executor`` on the Dask cluster at ``address`` (needs ``shellbvp[dask]``).

    The address is checked before anything is imported or contacted; the connection, handshake
    included, must succeed within ``timeout`` seconds (a peer that accepts and never answers, or
    answers junk, is one line, not a hang or a traceback).
    """
    import threading

    text = str(address).strip()
    scheme = text.split("://", 1)[0] if "://" in text else "tcp"
    if not text:
        raise ValueError("--scheduler: the address is empty; give host:port or tcp://host:port")
    if scheme != "tcp":
        raise ValueError(f"--scheduler {text!r}: only tcp:// addresses are supported (host:port or "
                         f"tcp://host:port); {scheme}:// is not")
    m = SCHEDULER_ADDRESS.match(text)
    if not m or not 0 < int(m.group(1)) < 65536:
        raise ValueError(f"--scheduler {text!r}: not an address host:port or tcp://host:port (port 1-65535)")
    try:
        from dask.distributed import Client
        # a lost scheduler is reported once, as the curves it leaves pending (_compute), not as the
        # client's multi-line tracebacks of every reconnection attempt
        for name in ("distributed.client", "distributed.core", "distributed.comm"):
            logging.getLogger(name).setLevel(logging.CRITICAL)
    except ImportError:
        raise ValueError("a Dask scheduler needs the dask extra: pip install 'shellbvp[dask]' "
                         "(dask[distributed])") from None
    result = {}

    def connect():  # in a daemon thread: a handshake that never ends must not keep the process
        try:
            result["client"] = Client(text, timeout=f"{timeout}s")
        except BaseException as exc:  # noqa: BLE001 -- any failure of the peer is reported as one line
            result["error"] = exc

    worker = threading.Thread(target=connect, daemon=True, name="dask-connect")
    worker.start()
    worker.join(timeout + 5.0)
    if worker.is_alive():
        raise ValueError(f"the Dask scheduler at {text!r} did not answer within {timeout + 5:g} s")
    if "error" in result:
        exc = result["error"]
        raise ValueError(f"cannot use the Dask scheduler at {text!r}: {type(exc).__name__}: "
                         f"{' '.join(str(exc).split())[:200]}") from None
    return result["client"].get_executor()


def local_pool(workers=None):
    """A process pool of ``workers`` processes (default: all cores), started by spawn; each
    worker ends when the process that started it does (:func:`die_with_parent`)."""
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers must be an integer >= 1; got {workers!r}")
    # spawn, not fork: workers start clean whatever threads the parent runs (Dask, h5py)
    return ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1,
                               mp_context=multiprocessing.get_context("spawn"),
                               initializer=die_with_parent, initargs=(os.getpid(),))


def die_with_parent(parent_pid: int, period: float = 0.5) -> None:
    """In a worker: exit as soon as ``parent_pid`` is no longer this process's parent (the
    parent was killed, even by ``kill -9``, and the worker was handed to init), instead of
    living on with the dead parent's pipes open (a caller reading them would never see EOF).
    A daemon thread polls ``os.getppid()``; ``prctl(PR_SET_PDEATHSIG)`` is not used: it fires
    when the *thread* that started the worker ends, which a pool's thread may do early."""
    import threading

    def watch():
        while os.getppid() == parent_pid:
            time.sleep(period)
        os._exit(1)

    if os.getppid() != parent_pid:  # the parent died before the worker got here
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()


# -- the writer ----------------------------------------------------------------------------------
class _Lock:
    """An exclusive lock on ``<file>.lock`` for as long as a sweep writes ``<file>``.

    Two sweeps writing one file would each replace the other's additions (every write is a
    copy of the file as that process last saw it), so a second one is refused.  ``flock`` is
    released by the kernel when the process ends, however it ends (a ``kill -9`` leaves no
    stale lock).  Where ``fcntl`` does not exist (Windows) no lock is taken.
    """

    def __init__(self, path: Path):
        self.path = path.with_name(path.name + ".lock")
        self.fh = None

    def __enter__(self):
        try:
            import fcntl
        except ImportError:
            return self
        while True:
            try:
                fh = open(self.path, "a+")  # held open for the sweep: the lock lives with it
            except OSError as exc:
                raise ValueError(f"{self.path}: cannot be the sweep's lock file ({exc.strerror}); remove it or "
                                 f"choose another output file") from None
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                fh.close()
                raise ValueError(f"{self.path.with_suffix('')} is being written by another sweep (lock "
                                 f"{self.path}); wait for it to end, or choose another output file") from None
            try:  # the file locked must still be the one at the path (another sweep may have removed it)
                same = os.stat(self.path).st_ino == os.fstat(fh.fileno()).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self.fh = fh
                return self
            fh.close()

    def __exit__(self, *exc):
        if self.fh is not None:
            self.path.unlink(missing_ok=True)  # while still locked: a waiting sweep sees it gone and retries
            self.fh.close()


class _Writer:
    """The sweep file as this process writes it: the index in memory, each write atomic (_rewrite)."""

    def __init__(self, path: Path | None, names, index, meta):
        self.path, self.names, self.index, self.meta = path, names, index, meta

    def start(self, fresh: bool):
        """Write the metadata and the index (every combination pending or as found)."""
        if self.path is None:
            return
        # a killed writer's temporary files (we hold the lock); the name is escaped: run[12].h5 is
        # a name, not a pattern that matches other writers' files
        for debris in self.path.parent.glob(f".{glob.escape(self.path.name)}.*.tmp"):
            debris.unlink(missing_ok=True)

        def edit(f):
            f.attrs["format"], f.attrs["format_version"] = FORMAT, FORMAT_VERSION
            f.attrs["package_version"] = __version__
            if "created" not in f.attrs:
                f.attrs["created"] = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
            f.attrs["default"] = "sweep"  # NeXus: root -> sweep (NXentry) -> overview (NXdata)
            s = f.require_group("sweep")
            s.attrs["NX_class"] = "NXentry"
            s.require_group("curves").attrs["NX_class"] = "NXcollection"
            for key in ("base_scene", "settings"):
                s.attrs[key] = json.dumps(self.meta[key], sort_keys=True)
            for key in ("parameters", "grid"):  # in grid order
                s.attrs[key] = json.dumps(self.meta[key])
            s.attrs["delta_max"] = self.meta["delta_max"]
            s.attrs["units"] = "nondimensional"
            _write_index(s, self.names, self.index)
            _write_overview(s, self.names, self.meta, self.index)

        _rewrite(self.path, edit, fresh=fresh)

    def add(self, records, curves):
        """Enter finished records in the index and write their curves (one atomic write)."""
        for rec in records:
            i = rec["index"]
            for key in ("status", "message", "wall_time"):
                self.index[key][i] = rec[key]
            if i in curves:
                self.index["stop_reason"][i] = rec["stop_reason"]
                self.index["points"][i] = len(rec["points"]["delta"])
                self.index["group"][i] = f"curves/curve_{i:06d}"
        if self.path is None:
            return

        def edit(f):
            s = f["sweep"]
            for rec in records:
                name = self.index["group"][rec["index"]]
                if name:
                    if name in s:  # a pending combination has no group; kept safe all the same
                        del s[name]
                    write_curve_group(s.create_group(name), curves[rec["index"]])
                    _label_units(s[name])
            _write_index(s, self.names, self.index)
            _write_overview(s, self.names, self.meta, self.index)

        _rewrite(self.path, edit)




def _executor_gone(executor) -> bool:
    """A Dask executor whose client has closed (its scheduler gone, reconnection given up)."""
    status = getattr(getattr(executor, "_client", None), "status", None)
    return status is not None and status not in ("running", "connecting", "newly-created")


def _compute(todo, args_of, executor, on_records):
    """Run :func:`run_curve` on ``args_of(i)`` for each i in ``todo``, through ``executor`` (None:
    in this process), passing finished records on in batches (whatever finished meanwhile).

    Returns (computed, lost): tasks the executor could not run (a worker died, or a Dask client
    closed: checked whenever ``OPTIONS.health_seconds`` pass without a finished curve) are lost,
    logged and left pending.  On an interruption, tasks not yet started are cancelled.
    """
    if executor is None:
        for i in todo:
            on_records([run_curve(*args_of(i))])
        return len(todo), 0
    computed = lost = 0
    futures = {}
    try:
        futures = {executor.submit(run_curve, *args_of(i)): i for i in todo}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, timeout=OPTIONS.health_seconds, return_when=FIRST_COMPLETED)
            if not done and _executor_gone(executor):  # a cluster that went away never finishes them
                lost += len(pending)
                log.warning("the Dask client is %s: %d curves were not computed; they stay pending",
                            executor._client.status, len(pending))
                break
            records = []
            for fut in done:
                try:
                    records.append(fut.result())
                except Exception as exc:  # the executor failed (a worker died): logged, stays pending
                    lost += 1
                    log.warning("curve %d was not computed (%s: %s); it stays pending", futures[fut],
                                type(exc).__name__, exc)
            computed += len(records)
            if records:
                on_records(records)
    finally:
        for fut in futures:  # after an interruption: what has not started never starts
            fut.cancel()
    return computed, lost


def _plan(base_scene, grid, delta_max, settings, path, extend, restart):
    """(meta, index, scenes) of a sweep, every input checked and an existing file reconciled."""
    names = list(grid)
    meta = {"base_scene": base_scene.to_dict(), "parameters": names, "grid": {n: list(v) for n, v in grid.items()},
            "settings": settings, "delta_max": delta_max}
    found = None
    if path is not None and path.exists() and not restart:
        found = _reconcile(path, json.loads(json.dumps(meta)), extend)
    if found is None:
        index = _new_index(names, _combinations(grid))
    else:
        meta["grid"], index = found
    combos = list(zip(*(index[n] for n in names)))
    return meta, index, _check_scenes(base_scene, names, combos, delta_max, settings), found is None


# -- the sweep -----------------------------------------------------------------------------------
def sweep(base_scene, grid, *, delta_max, executor=None, out=None, workers=None, extend=False,
          restart=False, progress=None, max_cells=MAX_CELLS, **curve_settings) -> Sweep:
    """One curve per combination of ``grid`` values, through an executor, into one file.

    Parameters
    ----------
    base_scene : Scene
        Every parameter not in ``grid`` comes from it.
    grid : dict
        ``{name: values}`` with names from :data:`SWEEP_PARAMETERS` (``alpha`` needs a
        Mooney-Rivlin, ``Jm`` a Gent base scene); every combination is one curve, in the
        order of ``itertools.product`` over the values as given.
    delta_max : float
        Depth of every curve (checked against each scene's :func:`shellbvp.delta_bounds`
        before any work).
    executor : concurrent.futures.Executor, optional
        Where the curves are computed (e.g. ``dask_executor(address)``, any pool); not shut
        down here.  Default: a local process pool of ``workers`` processes (all cores), or,
        with ``workers=1``, this process.
    out : str or Path, optional
        The sweep file.  If it exists and was made with the same base scene, delta_max and
        settings, its finished curves are kept and only pending ones computed (resume); a
        different grid is refused unless ``extend`` (new combinations are then added).
    workers : int, optional
    extend : bool
    restart : bool
        Start ``out`` anew, whatever it holds (the old file stays intact until the new one's
        first write replaces it).
    progress : callable, optional
        ``progress(record, done, total)`` in this process after each curve (``record`` is
        what :func:`run_curve` returned).  Raising ``KeyboardInterrupt`` there stops the
        sweep like Ctrl-C: the file keeps every curve written so far.
    max_cells : int
        The most combinations the grid may have (:data:`MAX_CELLS`, 10,000), counted before
        anything is allocated.
    **curve_settings
        Passed on to :func:`shellbvp.curve` (``tol``, ``max_steps``, ``topology``, ...).

    Returns
    -------
    Sweep
        ``computed``: the curves computed by this call; ``lost``: tasks that the executor
        failed to run (a worker died): they stay pending in the file, and a re-run computes them.

    Raises
    ------
    ValueError
        Before any curve: an unknown parameter or setting, a value that makes an invalid scene
        or a depth outside its :func:`shellbvp.delta_bounds` (naming the grid point), a file
        made with other settings or another grid (without ``extend``), a file another sweep
        is writing.

    Examples
    --------
    Two curves into a file (here in this process; by default on all cores), then the same
    call again: nothing is left to compute.

    >>> import shellbvp as sb
    >>> base = sb.Scene.preset("base")
    >>> kw = dict(delta_max=0.1, out="beta.h5", workers=1, deltas=[0.05, 0.1], estimate_error=False)
    >>> res = sb.sweep(base, {"beta": [0.005, 0.01]}, **kw)
    >>> res.computed, res.counts()
    (2, {'complete': 2})
    >>> sb.sweep(base, {"beta": [0.005, 0.01]}, **kw).computed
    0
    >>> sb.sweep(base, {"beta": [0.005, 0.01, 0.02]}, **kw)    # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: beta.h5 holds another grid (beta: file [0.005, 0.01], asked [0.005, 0.01, 0.02]): pass extend=True ...
    >>> sb.sweep(base, {"beta": [0.005, 0.01, 0.02]}, extend=True, **kw).computed
    1
    """
    from .model import load_module
    from .paths import check_output_path

    grid = check_grid(base_scene, grid, max_cells)
    settings = _check_settings(curve_settings)
    if executor is not None and workers is not None:
        raise ValueError("workers sets the size of the default local pool; an executor given has its own workers")
    if isinstance(delta_max, (int, float)) and not isinstance(delta_max, bool):
        delta_max = float(delta_max)
    path = None if out is None else check_output_path(out, overwrite=True)  # a directory we can write in
    with _Lock(path) if path is not None else contextlib.nullcontext():
        meta, index, scenes, fresh = _plan(base_scene, grid, delta_max, settings, path, extend, restart)
        names = meta["parameters"]
        writer = _Writer(path, names, index, meta)
        writer.start(fresh)  # the file exists (every combination listed) before the first curve
        # derive each structure's code here, once, before any worker needs it (they load it from the cache)
        for desc in {json.dumps(sc.structure(), sort_keys=True): sc.structure() for sc in scenes}.values():
            load_module(desc)
        curves = {}

        def on_records(records):
            for rec in records:
                if rec["status"] != "error":
                    curves[rec["index"]] = _curve_of(rec, scenes[rec["index"]])
            writer.add(records, curves)
            if progress is not None:
                for rec in records:
                    done[0] += 1
                    progress(rec, done[0], len(todo))

        # pending cells, and those in error: an exception may be passing (memory, a worker killed);
        # a curve that stopped early is a result and stays
        todo = [i for i, st in enumerate(index["status"]) if st in ("pending", "error")]
        done = [0]
        t0 = time.perf_counter()
        own = local_pool(workers) if executor is None and workers != 1 and todo else None
        try:
            computed, lost = _compute(todo, lambda i: (i, scenes[i], delta_max, settings), executor or own,
                                      on_records)
        finally:
            if own is not None:
                own.shutdown(wait=True, cancel_futures=True)
    log.info("sweep: %d curves computed in %.1f s (%d lost)", computed, time.perf_counter() - t0, lost)
    if path is not None:
        result = read_sweep(path)
    else:
        result = Sweep(parameters=tuple(names), values={n: np.asarray(meta["grid"][n], float) for n in names},
                       base_scene=base_scene, delta_max=delta_max, settings=settings,
                       index={k: np.asarray(v) for k, v in index.items()}, curves=curves)
    result.computed, result.lost = computed, lost
    return result
