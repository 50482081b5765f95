"""The ``curve`` command: a force-displacement curve into an HDF5 file."""

from __future__ import annotations

from .common import (
    add_limit_options, add_mu_h_option, add_overwrite_option, add_radius_option, number_or, plain_number,
)
from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``curve`` subcommand's arguments, on ``sub`` (the subparsers)."""
    c = sub.add_parser("curve", help="compute a force-displacement curve into an HDF5 file")
    add_scene_options(c)
    c.add_argument("--delta-max", type=number_or("length"), default=0.5, dest="delta_max",
                   help="largest pole displacement (default 0.5); with a unit (100um) it needs --radius")
    c.add_argument("--points", type=int, help="N equally spaced depths up to delta-max (default: adaptive)")
    c.add_argument("--force-max", type=number_or("force"), dest="force_max",
                   help="stop at this force; with a unit (10mN) it needs --radius and --muH")
    c.add_argument("--lambda0-max", type=plain_number, dest="lambda0_max", help="stop at this pole stretch")
    c.add_argument("--max-steps", type=int, default=400, dest="max_steps", help="most continuation steps of a curve (default 400)")
    c.add_argument("--profiles", action="store_true", help="store each point's profiles")
    add_radius_option(c, "with --muH: SI columns in the file")
    add_mu_h_option(c, "with --radius: SI columns in the file")
    c.add_argument("-o", "--output", help="output file (default <preset>.h5, or <preset>-2.h5, ... if that exists)")
    add_overwrite_option(c, "replace an existing output file")
    c.add_argument("-q", "--quiet", action="store_true", help="no progress bar (there is none when stderr is not "
                   "a terminal or tqdm is not installed: pip install 'shellbvp[progress]')")
    c.add_argument("--topology", choices=("auto", "cap"), default="auto",
                   help="auto (default): where the single contact cap would pull the shell, use the valid "
                        "lifted-off (line or annular) contact; cap: single cap only, flagged where invalid")
    c.add_argument("--stability", choices=("off", "points", "locate"), default="off",
                   help="stability of the states against non-axisymmetric modes: off (default); points: at "
                        "every point; locate: and the first instability narrowed between two points")
    add_limit_options(c, "stability")
    c.set_defaults(func=run)


def run(args):
    """The handler (``handlers/curve.py``), imported now: the parser loads no numpy."""
    from .handlers import curve

    return curve.run(args)
