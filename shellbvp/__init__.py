"""shellbvp: indentation of thin curved hyperelastic shells as one multipoint BVP.

Quick use::

    import shellbvp as sb
    scene = sb.Scene.preset("base")
    model = scene.model()          # generated, cached equations of this structure
"""

from .geometry import SphereTip, Spheroid, UserShell, UserTip
from .materials import Gent, MooneyRivlin, NeoHookean, StrainEnergy
from .scene import PRESETS, Scene
from .solve import STATUS_MESSAGES, Solution, solve

__version__ = "0.1.0.dev0"

__all__ = [
    "Scene",
    "solve",
    "Solution",
    "STATUS_MESSAGES",
    "PRESETS",
    "MooneyRivlin",
    "NeoHookean",
    "Gent",
    "StrainEnergy",
    "Spheroid",
    "SphereTip",
    "UserShell",
    "UserTip",
]
