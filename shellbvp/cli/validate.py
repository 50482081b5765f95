"""The ``validate`` command: the shell model against a 3D finite-element model."""

from __future__ import annotations

from .common import add_limit_options, add_overwrite_option, add_radius_option, number_or
from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``validate`` subcommand's arguments, on ``sub`` (the subparsers)."""
    v = sub.add_parser("validate", help="the shell model against a 3D finite-element model of the same scene "
                       "(needs FElupe: pip install 'shellbvp[fe]')")
    add_scene_options(v)
    v.add_argument("--delta-max", type=number_or("length"), default=0.5, dest="delta_max",
                   help="largest pole displacement (default 0.5, in rim radii; with a unit, 90um, it needs --radius); "
                        "the depths are delta/H = 0.25, 0.5, 1, 2, 5, 10, 25 below it and delta-max")
    v.add_argument("--deltas", help="these pole displacements instead, comma-separated (/R_L)")
    add_radius_option(v, "for --thickness and --delta-max with a unit")
    v.add_argument("--mesh-check", action="store_true", dest="mesh_check",
                   help="also solve the 3D model on a coarser mesh and report the difference (~1.5x the time)")
    v.add_argument("-o", "--output", help="output file (default <preset>-validate.h5, or -2, ... if that exists)")
    add_overwrite_option(v, "replace an existing output file")
    add_limit_options(v, "fe")
    v.set_defaults(func=run)


def run(args):
    """The handler (``handlers/validate.py``), imported now: the parser loads no numpy."""
    from .handlers import validate

    return validate.run(args)
