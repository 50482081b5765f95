"""A sweep's grid: the parameters a sweep may vary, the grid checked (its size first) and
every combination's scene and depth checked before any curve, the curve settings passed on."""

from __future__ import annotations

import inspect
import itertools
import json
import math

import numpy as np

from ..bounds import check_delta, check_tol
from ..continuation import curve
from ..scene_parameters import LiveNames, parameters_that, scene_parameter, scene_with

__all__ = ["SWEEP_PARAMETERS", "MAX_CELLS", "scene_at", "check_grid", "combinations", "check_settings",
           "check_scenes"]

#: Parameters a sweep may vary (run-time parameters of the generated code: no new derivation):
#: those of the registry (:mod:`shellbvp.scene_parameters`) flagged ``sweep``, in its order.
SWEEP_PARAMETERS = LiveNames(lambda: [p.name for p in parameters_that("sweep")])
#: Settings of :func:`shellbvp.curve` a sweep passes on (the rest are fixed by the sweep).
_CURVE_SETTINGS = tuple(k for k in inspect.signature(curve).parameters if k not in ("scene", "delta_max", "callback"))


def scene_at(base_scene, values: dict):
    """``base_scene`` with the swept parameters set (a material's: that material's,
    :func:`shellbvp.scene_parameters.scene_with`)."""
    return scene_with(base_scene, values)


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
        why = scene_parameter(name).needs(base_scene, "base scene")
        if why:
            raise ValueError(f"grid: {why}")
        try:
            vals = tuple(float(v) for v in np.atleast_1d(values))
        except (TypeError, ValueError):
            raise ValueError(f"grid: {name} must be a list of numbers; got {values!r}") from None
        if not vals or not all(math.isfinite(v) for v in vals):
            raise ValueError(f"grid: {name} must be a non-empty list of finite numbers; got {values!r}")
        if len(set(vals)) != len(vals):
            raise ValueError(f"grid: {name} lists a value twice: {list(vals)}")
        out[name] = vals
    families = {scene_parameter(n).material for n in out} - {""}
    if len(families) > 1:  # (each is the base scene's: kept for a base scene checked elsewhere)
        raise ValueError("grid: " + " and ".join(f"{n} ({scene_parameter(n).material_label()})" for n in out
                                                 if scene_parameter(n).material) + " belong to different materials")
    return out


def combinations(grid: dict) -> list[tuple]:
    return list(itertools.product(*grid.values()))


def check_settings(settings: dict) -> dict:
    unknown = sorted(set(settings) - set(_CURVE_SETTINGS))
    if unknown:
        raise ValueError(f"unknown curve setting {unknown[0]!r}; a sweep passes on {_CURVE_SETTINGS}")
    try:  # stored in the file as JSON: only plain data (and compared on a re-run)
        return json.loads(json.dumps(settings, sort_keys=True))
    except TypeError:
        raise ValueError(f"curve settings must be plain numbers, strings or lists; got {settings!r}") from None


def check_scenes(base_scene, names, combos, delta_max, settings):
    """Every combination's scene and depth, checked before any curve (ValueError naming it)."""
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
