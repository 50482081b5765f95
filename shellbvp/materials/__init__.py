"""Strain- and bending-energy choices a scene can make, found by family name.

One module of this package per material holds all of it: its class (registered with
:func:`register_material`), its SymPy strain energy, its run-time parameters and their
ranges, its labels and its 3D model for ``shellbvp.fe`` (see :mod:`shellbvp.materials.base`).
Files, ``Scene.describe``, plots, the 3D reference, the command line's ``--material`` and the
derivation (``symbolic.build``) look families up in the registry, so a new material is its
module here and its test file (``yeoh.py`` is an example).  Bending energies likewise
(:func:`register_bending`; ``bending.py``).

Built-in families are described by name, so that loading their cached generated code does not
import SymPy; a user energy carries its formula.
"""

from __future__ import annotations

import importlib
import pkgutil

from .base import (BENDINGS, MATERIALS, Bending, Material, Parameter, bending_class, material_class,
                   register_bending, register_material)
# the paper's materials first: the order in which messages and --help list them
from .mooney_rivlin import MooneyRivlin
from .neo_hookean import NeoHookean
from .gent import Gent
from .user import StrainEnergy
from .bending import BendingEnergy, RotationBending, TraceBending

__all__ = ["Material", "Bending", "Parameter", "register_material", "register_bending", "material_class",
           "bending_class", "MATERIALS", "BENDINGS", "MooneyRivlin", "NeoHookean", "Gent", "StrainEnergy",
           "TraceBending", "RotationBending", "BendingEnergy"]

# every other module here is a material (or bending energy) that registers itself on import
for _module in pkgutil.iter_modules(__path__):
    importlib.import_module(f"{__name__}.{_module.name}")
for _cls in (*MATERIALS.values(), *BENDINGS.values()):
    if _cls.__name__ not in __all__:
        globals()[_cls.__name__] = _cls
        __all__.append(_cls.__name__)


def _summary(cls) -> str:
    """The first paragraph of a class's docstring, on one line."""
    return " ".join((cls.__doc__ or "").strip().split("\n\n")[0].split())


if __doc__:  # the list of families in the docs and help() comes from the registry
    __doc__ += ("\n\nMaterials (``Scene(material=...)``; ``--material FAMILY``):\n\n"
                + "\n".join(f"* ``{c.family}``: ``{c.__name__}``, {_summary(c)}" for c in MATERIALS.values())
                + "\n\nBending energies (``Scene(bending=...)``; ``--bending FAMILY``, a user formula ``--bending-formula``):\n\n"
                + "\n".join(f"* ``{c.family}``: ``{c.__name__}``, {_summary(c)}" for c in BENDINGS.values()) + "\n")
