"""The ``compile`` command: compile the kernels (numba) of the built-in scenes or of one scene, once."""

from __future__ import annotations

from .scene_options import add_scene_options

__all__ = ["add_parser", "run"]


def add_parser(sub):
    """The ``compile`` subcommand's arguments, on ``sub`` (the subparsers)."""
    c = sub.add_parser("compile", help="compile the solver's kernels with numba, once (the [fast] extra): every "
                                       "preset's, or the scene's given by the options")
    scene = add_scene_options(c, solver=())
    c.add_argument("--radius", "--rim-radius", help="rim radius with its unit, for lengths given in lab units")
    # the scene's options: given, they mean "this scene", not "every preset"
    c.set_defaults(func=run, scene_keys=tuple(a.dest for a in scene._group_actions))


def run(args):
    """The handler (``handlers/compile.py``), imported now: the parser loads no numpy."""
    from .handlers import compile

    return compile.run(args)
