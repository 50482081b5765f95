"""The ``compile`` command: compile the kernels (numba) of the built-in scenes or of one scene, once."""

from __future__ import annotations

from .common import add_scene_options, quantity, scene_from_args

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
    from ..kernels import compile_for  # its importlib.metadata and subprocess: a third of the parser's time
    from ..scene import PRESETS, Scene

    given = any(getattr(args, k, None) not in (None, False) for k in args.scene_keys)
    if given:
        if args.radius is not None:
            args.radius = quantity("length")(args.radius)
        scenes = [("scene", scene_from_args(args))]
    else:
        scenes = [(name, Scene.preset(name)) for name in PRESETS]
    seen = set()
    for name, scene in scenes:
        key = scene.model().KEY
        if key in seen:
            continue
        seen.add(key)
        try:
            how, seconds = compile_for(scene)
        except ImportError as exc:
            raise ValueError(str(exc)) from None
        print(f"{name}: kernels {how} in {seconds:.1f} s ({key[:12]})")
    print(f"{len(seen)} structure(s) ready; curves, solves and fits load these kernels from now on")
    return 0
