"""The ``sweep`` command: one curve per combination of parameter values, into one resumable file."""

from __future__ import annotations

from ..edge_models import contact_models
from ..scene_parameters import parameters_that
from .common import add_mu_h_option, add_overwrite_option, add_radius_option, node_budget, number_or, plain_number
from .scene_options import material_help, material_spec

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


def run(args):
    """The handler (``handlers/sweep.py``), imported now: the parser loads no numpy."""
    from .handlers import sweep

    return sweep.run(args)
