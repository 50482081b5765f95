"""The sweep file's layout (format ``shellbvp-sweep``, see :mod:`shellbvp.sweeps`): its index
and overview written, the file read back with every item checked (:func:`read_sweep`), and
an existing file reconciled with the sweep asked of it (resume, extend or refuse)."""

from __future__ import annotations

import itertools
import json
import logging
import math
from pathlib import Path

import numpy as np

from .. import schema as sc
from ..io import read_curve_group
from ..paths import open_hdf5
from ..scene import Scene
from .grid import MAX_CELLS, SWEEP_PARAMETERS, combinations
from .result import STATUSES, Sweep

log = logging.getLogger(__name__)

__all__ = ["FORMAT", "FORMAT_VERSION", "is_sweep_file", "label_units", "write_index", "write_overview",
           "new_index", "read_sweep", "reconcile"]

FORMAT = "shellbvp-sweep"
FORMAT_VERSION = 1
#: Units of the index's own datasets (each swept parameter's are "nondimensional").
_INDEX_UNITS = {"status": "none", "stop_reason": "none", "message": "none", "group": "none",
                "points": "count", "wall_time": "s"}


def is_sweep_file(path) -> bool:
    """True if ``path`` is an HDF5 file of format ``shellbvp-sweep``."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
    except OSError:
        return False
    return (fmt.decode() if isinstance(fmt, bytes) else fmt) == FORMAT


def label_units(g) -> None:
    """A units attribute on every dataset of a curve group (its own layout has them on the group)."""
    for name, d in g.items():
        if hasattr(d, "dtype") and "units" not in d.attrs:
            d.attrs["units"] = {"wall_time": "s", "delta_m": "m", "force_N": "N"}.get(
                name, "none" if d.dtype.kind in "OSU" else "nondimensional")


def write_index(s, names, index) -> None:
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


def write_overview(s, names, meta, index) -> None:
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


def new_index(names, combos) -> dict:
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


def reconcile(path, meta_new, extend) -> tuple[dict, dict] | None:
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
    added = [c for c in combinations(new) if c not in have]
    more = new_index(list(old), added)
    for k in index:
        index[k] = list(index[k]) + more[k]
    log.info("extending %s by %d combinations", path, len(added))
    return grid, index
