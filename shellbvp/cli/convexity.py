"""The ``convexity`` command: where the scene's energy is convex."""

from __future__ import annotations

from .common import quantity
from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``convexity`` subcommand's arguments, on ``sub`` (the subparsers)."""
    cv = sub.add_parser("convexity", help="where the scene's energy is convex in stretch and curvature "
                                          "(the Legendre condition; beyond it the contact edge becomes a corner)")
    add_scene_options(cv, solver=())
    cv.add_argument("--radius", "--rim-radius", type=quantity("length"),
                    help="rim radius with its unit, for the lengths of --indenter-radius, --rise, --thickness")
    cv.set_defaults(func=run)


def run(args):
    """The handler (``handlers/convexity.py``), imported now: the parser loads no numpy."""
    from .handlers import convexity

    return convexity.run(args)
