"""The ``convexity`` command's handler (its parser: ``shellbvp/cli/convexity.py``)."""

from __future__ import annotations

from ...convexity import convexity_report
from ..scene_options import scene_from_args

__all__ = ["run"]


def run(args):
    """``shellbvp convexity``: where the scene's energy is convex in stretch and curvature."""
    print(convexity_report(scene_from_args(args)))
    return 0
