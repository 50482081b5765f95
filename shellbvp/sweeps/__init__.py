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
                           reach it) over the swept values, or over "combination" (layout.write_overview)

Every write goes to a copy of the file in the same directory, which then replaces the file
by ``os.replace`` (atomic on POSIX): a reader, a crash or a ``kill -9`` only ever sees the
file as it was after some complete write, never a half-written one.  The copy costs a full
file write per batch of finished curves; the batches are whatever has finished while the
previous write ran, so the writer keeps up as long as writing the file is faster than the
workers finish curves (see the README for the arithmetic).

The package's modules, each one job: :mod:`~shellbvp.sweeps.grid` (the grid and its checks),
:mod:`~shellbvp.sweeps.run` (:func:`sweep`), :mod:`~shellbvp.sweeps.work` (a curve in a worker,
the queue through an executor), :mod:`~shellbvp.sweeps.executors` (local pools, Dask),
:mod:`~shellbvp.sweeps.layout` (the file's layout, reading it back, resuming),
:mod:`~shellbvp.sweeps.writer` (the lock and the atomic writes) and
:mod:`~shellbvp.sweeps.result` (:class:`Sweep`).
"""

from __future__ import annotations

from .executors import SCHEDULER_ADDRESS, dask_executor, die_with_parent, local_pool
from .grid import MAX_CELLS, SWEEP_PARAMETERS, check_grid, scene_at
from .layout import FORMAT, FORMAT_VERSION, is_sweep_file, read_sweep
from .result import STATUSES, Sweep
from .run import sweep
from .work import run_curve

__all__ = ["sweep", "check_grid", "MAX_CELLS", "die_with_parent", "read_sweep", "run_curve", "Sweep",
           "SWEEP_PARAMETERS", "STATUSES", "FORMAT", "FORMAT_VERSION", "is_sweep_file", "dask_executor",
           "local_pool", "scene_at", "SCHEDULER_ADDRESS"]
