"""The ``solve`` command: one state, printed."""

from __future__ import annotations

from .common import number_or, plain_number, quantity
from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``solve`` subcommand's arguments, on ``sub`` (the subparsers)."""
    s = sub.add_parser("solve", help="solve one state and print it")
    add_scene_options(s)
    g = s.add_mutually_exclusive_group()
    g.add_argument("--delta", type=number_or("length"),
                   help="pole displacement (default 0.2); with a unit (50um) it needs --radius")
    g.add_argument("--lambda0", type=plain_number, help="pole stretch")
    g.add_argument("--force", "--load", type=number_or("force"), dest="load",
                   help="indenter force F / (mu H R_L) (force control); with a unit (5mN) it needs --radius and --muH")
    s.add_argument("--radius", "--rim-radius", type=quantity("length"), help="rim radius with its unit, e.g. 0.3mm (with --muH: "
                   "the state also in these units)")
    s.add_argument("--muH", type=quantity("mu_H"), dest="mu_h", help="mu*H with its unit, e.g. 52N/m")
    s.add_argument("--profiles", action="store_true", help="print the fields over S")
    s.add_argument("--json", action="store_true", help="print JSON")
    s.add_argument("--topology", default="auto",
                   help="configuration of the contact, one the registry lets be asked for (an unknown one lists "
                        "them; default auto: the cap, or a valid lifted-off state where the cap would pull the shell)")
    s.set_defaults(func=run)


def run(args):
    """The handler (``handlers/solve.py``), imported now: the parser loads no numpy."""
    from .handlers import solve

    return solve.run(args)
