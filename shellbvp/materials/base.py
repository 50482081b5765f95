"""What every material and bending energy declares, and the registries that find them by family.

A material is one class, registered with :func:`register_material`; the class says everything
the package does with it: its ``family`` (the name in structure descriptions, files and the
command line's ``--material``), its ``label`` and ``short_label`` (``Scene.describe``, plot
legends), its run-time ``parameters`` (names and valid ranges: what :meth:`Material.validate`
checks), its SymPy strain energy (:meth:`Material.energy`, built only when code is derived),
and optionally its 3D model for the FElupe reference (:meth:`Material.felupe_model`).  A
bending energy likewise (:class:`Bending`, :func:`register_bending`).

No SymPy here nor in the material modules' top level: a scene with cached generated code
loads without it.  Registering a family also registers its formula with the derivation
(``symbolic.energies``), which ``symbolic.build`` looks up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from symbolic.energies import register_bending_energy, register_strain_energy

__all__ = ["Parameter", "Material", "Bending", "register_material", "register_bending", "MATERIALS",
           "BENDINGS", "material_class", "bending_class"]

#: family -> Material subclass, in registration order
MATERIALS: dict = {}
#: family -> Bending subclass, in registration order
BENDINGS: dict = {}


@dataclass(frozen=True)
class Parameter:
    """A material's run-time parameter: its name (the generated code's, the files' and
    ``--material``'s) and its valid range ``low < value`` (``low_open``) or ``low <= value``,
    and ``value <= high``.

    It is also the parameter's entry in the registry of scene parameters
    (:mod:`shellbvp.scene_parameters`), which lists every registered material's parameters:
    the flags below say what the package may do with it.  A flag is all it takes: the sweep's
    grid, the geometry's uncertainty, the pixel tables, the fit and the command line read them
    there.
    """

    name: str
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    help: str = ""
    #: the SymPy assumption of its symbol in the derivation ("positive" or "nonnegative")
    assumption: str = "positive"
    #: its own option of the scene's command-line options (``"--alpha"``; it selects the family;
    #: default ``--NAME`` for a parameter swept or given an uncertainty, else none: then
    #: ``--material FAMILY:NAME=VALUE`` gives it), and that option's help (default: the label, the
    #: name and the range)
    option: str = ""
    option_help: str = ""
    #: ``fit(free=(name,))`` may fit it (searched over its range: it needs a finite one)
    fit: bool = False
    #: a sweep may vary it; it may be given an uncertainty; a pixel table may give it per pixel
    sweep: bool = False
    uncertainty: bool = False
    per_pixel: bool = False

    def range_text(self) -> str:
        if self.high == math.inf:
            return f"a finite number {'>' if self.low_open else '>='} {self.low:g}"
        return f"in {'(' if self.low_open else '['}{self.low:g}, {self.high:g}]"

    def check(self, value, owner: str) -> None:
        """ValueError naming the parameter, its material and its range unless ``value`` is in it."""
        inside = (not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
                  and (value > self.low if self.low_open else value >= self.low) and value <= self.high)
        if not inside:
            raise ValueError(f"{self.name} ({owner}) must be {self.range_text()}; got {value!r}")


class Material:
    """Base class: ``description()`` (structural, hashed) and ``values()`` (run-time)."""

    #: the name in descriptions, files and ``--material``
    family: str = ""
    #: the long name (``Scene.describe``, messages) and the legend's short one
    label: str = ""
    short_label: str = ""
    #: run-time parameters, in the order of the generated code's ``PARAMS``
    parameters: tuple = ()
    #: chosen on the command line by ``--material FAMILY[:NAME=VALUE,...]``
    cli: bool = True
    #: why the 3D reference (``shellbvp.fe``) has no model of it, when it has none
    no_3d_form: str = "it has no 3D model in shellbvp.fe"

    def description(self) -> dict:
        """The structural choice (family, a user formula): what generated code is keyed on."""
        return {"family": self.family}

    def values(self) -> dict:
        """Run-time parameters by name (alpha, Jm): they change no generated code."""
        return {p.name: float(getattr(self, p.name)) for p in self.parameters}

    def validate(self) -> None:
        """ValueError naming the parameter when it is out of range."""
        for p in self.parameters:
            p.check(getattr(self, p.name), self.label)

    def describe(self) -> str:
        """In words for ``Scene.describe``: ``Mooney-Rivlin alpha 0.1``."""
        return " ".join([self.label] + [f"{name} {value:g}" for name, value in self.values().items()])

    def legend(self) -> str:
        """Short, for a plot's legend: ``MR 0.1``, ``Yeoh c2=0.1 c3=0``."""
        v = self.values()
        if len(v) == 1:
            return f"{self.short_label} {next(iter(v.values())):g}"
        return " ".join([self.short_label] + [f"{name}={value:g}" for name, value in v.items()])

    @classmethod
    def from_data(cls, read) -> "Material":
        """The material of file data: ``read(key, types)`` returns the entry ``key`` of the
        material's data, checked to be of ``types`` (it raises ValueError naming the field)."""
        return cls(**{p.name: read(p.name, (int, float)) for p in cls.parameters})

    @staticmethod
    def energy(*parameters):
        """The SymPy strain energy W(lambda_s, lambda_theta) (the symbols of
        ``symbolic.materials``), nondimensional with small-strain shear modulus 1, of the
        parameters' symbols in the order of ``parameters``.  Import SymPy and ``symbolic`` inside."""
        raise NotImplementedError

    @classmethod
    def strain_energy(cls, description: dict):
        """(W, parameter symbols) of a description of this family: what the derivation calls."""
        import sympy as sp

        symbols = tuple(sp.Symbol(p.name, **{p.assumption: True}) for p in cls.parameters)
        return cls.energy(*symbols), symbols

    #: ``felupe_model(self, fem)``: the material of the 3D reference (``shellbvp.fe``;
    #: ``fem`` is the felupe module), the same W on the isochoric invariants; None: it has none
    felupe_model = None


class Bending:
    """Base class of bending energies ``B`` (U = W + beta B; formulas in ``symbolic.bending``).

    ``plate_stiffness`` and ``plate_poisson``: B's small-strain plate limit,
    ``B ~ plate_stiffness/2 (kappa_s^2 + kappa_theta^2 + 2 plate_poisson kappa_s kappa_theta)``
    (``symbolic.bending.plate_limit``; a test derives the built-ins' values).
    """

    #: the name in descriptions, files and ``--bending``
    family: str = ""
    plate_stiffness: float = 1.0
    plate_poisson: float = 1.0
    #: chosen on the command line by ``--bending FAMILY``
    cli: bool = True

    def description(self) -> dict:
        """The structural choice (family, a user formula): what generated code is keyed on."""
        return {"family": self.family}

    @classmethod
    def from_data(cls, read) -> "Bending":
        """The bending energy of file data (``read`` as in :meth:`Material.from_data`)."""
        return cls()

    @staticmethod
    def bending_energy(description: dict):
        """The SymPy B of a description of this family, or None for the paper's trace energy
        (which the equations hold themselves).  Import SymPy and ``symbolic`` inside."""
        raise NotImplementedError


def register_material(cls):
    """Class decorator: ``cls`` becomes the material of ``cls.family``, for files, the command
    line, the labels, the 3D reference and the derivation."""
    if MATERIALS.get(cls.family, cls) is not cls:
        raise ValueError(f"material family {cls.family!r} is registered twice")
    MATERIALS[cls.family] = cls
    register_strain_energy(cls.family, cls.strain_energy)
    return cls


def register_bending(cls):
    """Class decorator: ``cls`` becomes the bending energy of ``cls.family``."""
    if BENDINGS.get(cls.family, cls) is not cls:
        raise ValueError(f"bending family {cls.family!r} is registered twice")
    BENDINGS[cls.family] = cls
    register_bending_energy(cls.family, cls.bending_energy)
    return cls


def material_class(family: str):
    """The registered material of a family; ValueError naming the known ones."""
    if family not in MATERIALS:
        raise ValueError(f"unknown material family {family!r}; known: {', '.join(MATERIALS)}")
    return MATERIALS[family]


def bending_class(family: str):
    """The registered bending energy of a family; ValueError naming the known ones."""
    if family not in BENDINGS:
        raise ValueError(f"unknown bending family {family!r}; known: {', '.join(BENDINGS)}")
    return BENDINGS[family]
