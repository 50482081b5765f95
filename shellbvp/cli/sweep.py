"""The ``sweep`` command: one curve per combination of parameter values, into one resumable file."""

from __future__ import annotations

import sys
import time

from .. import units
from ..edge_models import contact_models
from ..materials import NeoHookean, material_class
from ..scene_parameters import parameters_that
from .common import (
    MAX_POINTS, add_mu_h_option, add_overwrite_option, add_radius_option, material_help, material_spec, nondimensional,
    node_budget, number_or, plain_number,
)

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``sweep`` subcommand's arguments, on ``sub`` (the subparsers)."""
    w = sub.add_parser("sweep", help="one curve per combination of parameter values, into one resumable file",
                       description="One force-displacement curve per combination of the swept values, computed "
                       "in parallel (a local process pool, or a Dask cluster with --scheduler), into one HDF5 file "
                       "that is written after every finished curve. Re-running the same command computes only "
                       "the curves not yet in the file. Values: a,b,c or LOW:HIGH:N (N equally spaced) or "
                       "LOW:HIGH:N:log. Exit status: 0 every curve complete; 1 some stopped early or failed "
                       "(see `shellbvp info`); 2 bad input; 130 interrupted.")
    g = w.add_argument_group("scene (the preset, with the swept parameters replaced)")
    g.add_argument("--preset", default="base", help="built-in scene (see `shellbvp presets`; default base)")
    m = g.add_mutually_exclusive_group()  # a material's parameter selects its material
    chosen = False  # --neo-hookean and --material added (after the materials' parameters: one group)
    for p in parameters_that("sweep"):  # the registry's (shellbvp.scene_parameters), in its order
        if not p.material and m._group_actions and not chosen:
            _material_choices(m)
            chosen = True
        what = " ".join(t for t in (p.label, p.symbol) if t)
        (m if p.material else g).add_argument(p.option, dest=p.dest, help=f"{what}: values to sweep")
    if not chosen:
        _material_choices(m)
    g.add_argument("--xi", type=int, choices=(0, 1), help="1: full generalised tensions; 0: first approximation")
    g.add_argument("--contact", choices=contact_models(), help="contact-line model (default smooth)")
    w.add_argument("--delta-max", type=number_or("length"), default=0.5, dest="delta_max",
                   help="depth of every curve (default 0.5, in rim radii); with a unit (100um) it needs --radius")
    w.add_argument("--force-max", type=number_or("force"), dest="force_max",
                   help="stop every curve at this force; with a unit (10mN) it needs --radius and --muH")
    add_radius_option(w, "for --delta-max and --force-max with a unit")
    add_mu_h_option(w, "with --radius, for --force-max with a unit")
    w.add_argument("--points", type=int, help="N equally spaced depths up to delta-max (default: adaptive)")
    w.add_argument("--tol", type=plain_number, default=1e-6, help="collocation tolerance (default 1e-6)")
    w.add_argument("--max-nodes", type=node_budget, default=10000, dest="max_nodes",
                   help="largest collocation mesh of a state (default 10000, in [100, 1000000])")
    w.add_argument("--max-steps", type=int, default=400, dest="max_steps", help="most continuation steps of a curve (default 400)")
    w.add_argument("--topology", choices=("auto", "cap"), default="auto",
                   help="auto (default): lifted-off contact where the cap would pull the shell; cap: single cap only")
    w.add_argument("-o", "--output", required=True, help="the sweep file (HDF5); an existing one is resumed")
    w.add_argument("--workers", type=int, help="local worker processes (default: all cores)")
    w.add_argument("--max-cells", type=int, default=10_000, dest="max_cells",
                   help="the most combinations the grid may have (default 10000; checked before any work)")
    w.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786 (needs "
                                       "shellbvp[dask])")
    w.add_argument("--extend", action="store_true", help="add the new combinations of a changed grid to the file")
    add_overwrite_option(w, "start the file anew (its curves are discarded once the new file is first written)")
    w.add_argument("-q", "--quiet", action="store_true", help="no line per finished curve")
    w.set_defaults(func=run)


def _material_choices(m):
    """The material options that are not swept, in the materials' group."""
    m.add_argument("--neo-hookean", action="store_true", help="neo-Hookean material")
    m.add_argument("--material", type=material_spec, metavar="FAMILY[:NAME=VALUE,...]",
                   help=material_help() + " (the base scene's; not swept)")


MAX_SWEEP_VALUES = 10_000  # values of one swept parameter: more is a typo, not a grid


def _sweep_values(text, name):
    """Values of a swept parameter: ``a,b,c``, ``lo:hi:n`` (n equally spaced) or ``lo:hi:n:log``
    (n spaced evenly in log), each number plain decimal text (nothing is evaluated)."""
    import numpy as np


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
    from ..scene import Scene
    from ..sweep import check_grid, dask_executor, sweep

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
