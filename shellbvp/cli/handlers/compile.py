"""The ``compile`` command's handler: the kernels (numba) of the built-in scenes or of one scene,
compiled once (its parser: ``shellbvp/cli/compile.py``)."""

from __future__ import annotations

from ...kernels import compile_for
from ...presets import PRESETS
from ...scene import Scene
from ..common import quantity
from ..scene_options import scene_from_args

__all__ = ["run"]


def run(args):
    """``shellbvp compile``: exit 0 once every structure's kernels are compiled."""
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
