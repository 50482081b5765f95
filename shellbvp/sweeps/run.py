"""The sweep itself: :func:`sweep` plans the grid against the file (every input checked, an
existing file reconciled), writes the file before the first curve, derives each structure's
code once in this process, runs the pending curves through an executor and writes each batch
of finished curves as it comes."""

from __future__ import annotations

import contextlib
import json
import logging
import time

import numpy as np

from ..model import load_module
from ..paths import check_output_path
from .executors import local_pool
from .grid import MAX_CELLS, check_grid, check_scenes, check_settings, combinations
from .layout import new_index, read_sweep, reconcile
from .result import Sweep
from .work import compute, curve_of
from .writer import Lock, Writer

log = logging.getLogger(__name__)

__all__ = ["sweep"]


def _plan(base_scene, grid, delta_max, settings, path, extend, restart):
    """(meta, index, scenes) of a sweep, every input checked and an existing file reconciled."""
    names = list(grid)
    meta = {"base_scene": base_scene.to_dict(), "parameters": names, "grid": {n: list(v) for n, v in grid.items()},
            "settings": settings, "delta_max": delta_max}
    found = None
    if path is not None and path.exists() and not restart:
        found = reconcile(path, json.loads(json.dumps(meta)), extend)
    if found is None:
        index = new_index(names, combinations(grid))
    else:
        meta["grid"], index = found
    combos = list(zip(*(index[n] for n in names)))
    return meta, index, check_scenes(base_scene, names, combos, delta_max, settings), found is None


def _compute_pending(index, scenes, delta_max, settings, writer, executor, workers, progress):
    """The index's pending combinations, and those in error, computed through ``executor`` (None:
    a local pool of ``workers``, or this process with ``workers=1``) and written by ``writer``
    batch by batch as they finish: (curves by combination, computed, lost)."""
    curves = {}

    def on_records(records):
        for rec in records:
            if rec["status"] != "error":
                curves[rec["index"]] = curve_of(rec, scenes[rec["index"]])
        writer.add(records, curves)
        if progress is not None:
            for rec in records:
                done[0] += 1
                progress(rec, done[0], len(todo))

    # pending cells, and those in error: an exception may be passing (memory, a worker killed);
    # a curve that stopped early is a result and stays
    todo = [i for i, st in enumerate(index["status"]) if st in ("pending", "error")]
    done = [0]
    own = local_pool(workers) if executor is None and workers != 1 and todo else None
    try:
        computed, lost = compute(todo, lambda i: (i, scenes[i], delta_max, settings), executor or own, on_records)
    finally:
        if own is not None:
            own.shutdown(wait=True, cancel_futures=True)
    return curves, computed, lost


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
    grid = check_grid(base_scene, grid, max_cells)
    settings = check_settings(curve_settings)
    if executor is not None and workers is not None:
        raise ValueError("workers sets the size of the default local pool; an executor given has its own workers")
    if isinstance(delta_max, (int, float)) and not isinstance(delta_max, bool):
        delta_max = float(delta_max)
    path = None if out is None else check_output_path(out, overwrite=True)  # a directory we can write in
    with Lock(path) if path is not None else contextlib.nullcontext():
        meta, index, scenes, fresh = _plan(base_scene, grid, delta_max, settings, path, extend, restart)
        names = meta["parameters"]
        writer = Writer(path, names, index, meta)
        writer.start(fresh)  # the file exists (every combination listed) before the first curve
        # derive each structure's code here, once, before any worker needs it (they load it from the cache)
        for desc in {json.dumps(sc.structure(), sort_keys=True): sc.structure() for sc in scenes}.values():
            load_module(desc)
        t0 = time.perf_counter()
        curves, computed, lost = _compute_pending(index, scenes, delta_max, settings, writer, executor, workers,
                                                  progress)
    log.info("sweep: %d curves computed in %.1f s (%d lost)", computed, time.perf_counter() - t0, lost)
    if path is not None:
        result = read_sweep(path)
    else:
        result = Sweep(parameters=tuple(names), values={n: np.asarray(meta["grid"][n], float) for n in names},
                       base_scene=base_scene, delta_max=delta_max, settings=settings,
                       index={k: np.asarray(v) for k, v in index.items()}, curves=curves)
    result.computed, result.lost = computed, lost
    return result
