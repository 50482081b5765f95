"""The ``sweep`` command's handler: one curve per combination of parameter values, into one
resumable file (its parser: ``shellbvp/cli/sweep.py``)."""

from __future__ import annotations

import sys
import time

import numpy as np

from ... import units
from ...materials import NeoHookean, material_class
from ...scene import Scene
from ...scene_parameters import parameters_that
from ...sweeps import check_grid, dask_executor, sweep
from ..common import MAX_POINTS, nondimensional

__all__ = ["run"]


MAX_SWEEP_VALUES = 10_000  # values of one swept parameter: more is a typo, not a grid


def _sweep_values(text, name):
    """Values of a swept parameter: ``a,b,c``, ``lo:hi:n`` (n equally spaced) or ``lo:hi:n:log``
    (n spaced evenly in log), each number plain decimal text (nothing is evaluated)."""
    parts = text.split(":")
    if len(parts) == 1:
        return [units.plain_number(v, name) for v in text.split(",")]
    if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] != "log"):
        raise ValueError(f"{name} must be a list a,b,c or a range LOW:HIGH:N[:log]; got {text!r}")
    lo, hi = units.plain_number(parts[0], name), units.plain_number(parts[1], name)
    if not parts[2].strip().isdigit() or not 1 <= int(parts[2]) <= MAX_SWEEP_VALUES:
        raise ValueError(f"{name}: N of LOW:HIGH:N must be an integer in [1, {MAX_SWEEP_VALUES}]; got {parts[2]!r}")
    n = int(parts[2])
    if len(parts) == 4:
        if not (lo > 0 and hi > 0):
            raise ValueError(f"{name}: a log range needs LOW, HIGH > 0; got {text!r}")
        return np.geomspace(lo, hi, n).tolist()
    return np.linspace(lo, hi, n).tolist()


def run(args):
    """``shellbvp sweep``: exit 0 every curve complete, 1 some stopped early, failed or were lost
    (the index says which), 2 bad input, 130 interrupted (the file keeps the finished curves)."""
    grid, swept = {}, parameters_that("sweep")
    for p in swept:  # the grid's axes in the registry's order
        text = getattr(args, p.dest, None)
        if text is not None:
            grid[p.name] = _sweep_values(text, p.option)
    if not grid:
        raise ValueError(f"give at least one of {', '.join(p.option for p in swept)} to sweep")
    over = {k: getattr(args, k) for k in ("xi", "contact") if getattr(args, k) is not None}
    if args.neo_hookean:
        over["material"] = NeoHookean()
    elif args.material is not None:
        over["material"] = args.material
    base = Scene.preset(args.preset, **over)
    for p in swept:  # a swept material parameter: the preset's material if of its family, else that family's
        if p.material and p.name in grid and base.material.family != p.material:
            base = base.replace(material=material_class(p.material)(**{p.name: grid[p.name][0]}))
    args.delta_max = nondimensional(args, args.delta_max, "--delta-max")
    args.force_max = nondimensional(args, args.force_max, "--force-max")
    check_grid(base, grid, args.max_cells)  # before a scheduler is asked for anything
    settings = {"tol": args.tol, "max_nodes": args.max_nodes, "max_steps": args.max_steps, "topology": args.topology}
    if args.force_max is not None:
        settings["force_max"] = args.force_max
    if args.points is not None:
        if not 2 <= args.points <= MAX_POINTS:
            raise ValueError(f"--points must be in [2, {MAX_POINTS}]; got {args.points}")
        settings["deltas"] = [args.delta_max * (i + 1) / args.points for i in range(args.points)]
    if args.scheduler is not None and args.workers is not None:
        raise ValueError("--workers sets the local pool; with --scheduler the cluster has its own workers")
    executor = dask_executor(args.scheduler) if args.scheduler is not None else None  # '' is an error, not local

    def progress(rec, done, total):
        if not args.quiet:
            what = rec["status"] + (f", {len(rec['points']['delta'])} points" if "points" in rec else "")
            print(f"  [{done}/{total}] curve {rec['index']}: {what}, {rec['wall_time']:.1f} s"
                  + (f" ({rec['message']})" if rec["message"] else ""), file=sys.stderr, flush=True)

    t0 = time.perf_counter()
    res = sweep(base, grid, delta_max=args.delta_max, executor=executor, out=args.output, workers=args.workers,
                extend=args.extend, restart=args.force, progress=progress, max_cells=args.max_cells, **settings)
    counts = ", ".join(f"{v} {k}" for k, v in res.counts().items())
    print(f"wrote {args.output}: {res.status.size} combinations ({counts}); {res.computed} curves computed "
          f"in {time.perf_counter() - t0:.1f} s" + (f"; {res.lost} lost (still pending)" if res.lost else ""))
    return 0 if res.counts() == {"complete": res.status.size} else 1
