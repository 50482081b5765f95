"""The scene's continuous parameters, each declared once: what the sweep, the geometry's
uncertainty, the pixel tables, the fit and the command line read.

Every parameter is one :class:`SceneParameter`: its name (the ``Scene`` field or material
attribute, the file key, the sweep's axis, ``FitResult``'s attribute), what it is in words and
as a ratio, its valid range and the one-line error that names it, its lab form (a length over
the rim radius R_L, a pressure over mu*H/R_L), how it enters the scene (:func:`scene_with`), and
what the package may do with it: fit it (:class:`FitSearch`), sweep it, give it an uncertainty,
take it per pixel of a force map.

Units.  A scene holds every parameter nondimensional (``unit`` is ``"1"``; ``symbol`` says
over what: the thickness is ``H/R_L``).  Its lab form (:class:`Lab`) is what files and the
command line may give with a unit and what a fit may report: the thickness ``H`` in m
(``FitResult.thickness``, a pixel table's ``thickness_um``), ``lab value = value * R_L``.
:meth:`SceneParameter.to_lab` and :meth:`SceneParameter.from_lab` are the conversions.

The scene's own parameters are declared below.  A material's are its :class:`~shellbvp.materials.Parameter`
declarations, with their flags (``fit``, ``sweep``, ``uncertainty``, ``per_pixel``, ``option``):
the registry lists every registered material's parameters where :data:`MATERIAL_PARAMETERS`
stands in :data:`DECLARED`, so a new material is its module (and its test), and a new
parameter of the scene is its declaration here (and its test).  The registry is read afresh
(:func:`scene_parameters`): a material registered later joins it.

Examples
--------
>>> import shellbvp as sb
>>> from shellbvp.scene_parameters import parameters_that, scene_parameter, scene_with
>>> [p.name for p in parameters_that("sweep")]
['beta', 'rho', 'gamma', 'alpha', 'Jm', 'pressure']
>>> thickness = scene_parameter("thickness")
>>> thickness.unit, thickness.symbol, thickness.lab.unit, thickness.to_lab(0.05, R_L=0.2e-3)
('1', 'H/R_L', 'm', 1e-05)
>>> scene_parameter("alpha").check(2)
Traceback (most recent call last):
...
ValueError: alpha (Mooney-Rivlin) must be in [0, 1]; got 2
>>> scene = scene_with(sb.Scene.preset("base"), {"alpha": 0.3, "rho": 0.25})
>>> scene.material, scene.rho
(MooneyRivlin(alpha=0.3), 0.25)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Callable

from .materials import MATERIALS, material_class
from .units import beta_from_thickness

__all__ = ["SceneParameter", "Lab", "FitSearch", "Derived", "DECLARED", "MATERIAL_PARAMETERS", "ROLES",
           "SCENE_PARAMETERS", "scene_parameters", "scene_parameter", "parameters_that", "scene_with",
           "LiveNames", "LiveMapping"]

#: What the package may do with a parameter (:func:`parameters_that`).
ROLES = ("fit", "sweep", "uncertainty", "per_pixel")


@dataclass(frozen=True)
class Lab:
    """A parameter's lab form: ``lab value = value * scale``, ``scale`` the rim radius R_L
    (``"R_L"``) or ``mu*H / R_L`` (``"mu_H/R_L"``: the pressure, known only with mu*H)."""

    name: str
    unit: str
    kind: str
    scale: str = "R_L"

    def factor(self, R_L, mu_H=None) -> float:
        if self.scale == "R_L":
            return R_L
        if mu_H is None:
            raise ValueError(f"{self.name} in {self.unit} needs mu*H: its scale is {self.scale}")
        return mu_H / R_L

    def to_lab(self, value, R_L, mu_H=None) -> float:
        if self.scale == "R_L":
            return value * R_L
        return value * self.factor(R_L, mu_H)  # p mu_H / R_L

    def from_lab(self, value, R_L, mu_H=None) -> float:
        if self.scale == "R_L":
            return value / R_L
        self.factor(R_L, mu_H)  # (mu*H given)
        return value * R_L / mu_H  # as units.Dimensions.p


@dataclass(frozen=True)
class Derived:
    """A lab quantity of a fitted shape parameter that depends on mu*H too.

    Its 95 % interval is linearised: the gradient in (mu_H, theta) against the fit's
    covariance of (mu_H, ..., theta), Student's t (as the Wald intervals of mu*H); with
    ``log_interval`` the gradient of its logarithm, and the interval ``value * exp(-+ half)``
    (positive, for a quantity that cannot change sign, such as a ratio).

    Attributes
    ----------
    name : str
        Its key in ``FitResult`` (``res.<name>``, ``res.<name>_ci95``), JSON, the fit file.
    unit : str
        SI unit.
    label, display_unit, note : str
        How the CLI shows it: ``label = value display_unit   95% CI [..] (note)``.
    value : callable
        ``value(x, mu_H, R_L)``: x the parameter's nondimensional value.
    gradient : callable
        ``gradient(x, mu_H, R_L) -> (d value / d mu_H, d value / d x)``.
    log_interval : bool
        Linearise its logarithm (a positive interval).
    """

    name: str
    unit: str
    label: str
    display_unit: str
    note: str
    value: Callable
    gradient: Callable
    log_interval: bool = False


@dataclass(frozen=True)
class FitSearch:
    """How a fit searches a parameter (``fit(free=(name,))``; :mod:`shellbvp.shape_parameters`).

    ``default_bounds(scene)`` and ``step(scene)``: the search range (nondimensional) and the
    spacing of its trial values in ``theta`` (``ln x`` with ``log_scale``, else ``x``);
    ``unavailable(scene)``: why this scene cannot have it fitted (None: it can; default: the
    scene lacks it); ``clamp``: trial values are held inside the valid range; ``report_lab``:
    ``FitResult`` reports it in its lab unit (the thickness: H in m), shown in
    ``display_unit``; ``note`` ends the CLI's line; ``derived``: its :class:`Derived`
    quantities; ``description`` (default: the label and the symbol)."""

    default_bounds: Callable
    step: Callable
    fit_help: str
    range_help: str
    log_scale: bool = False
    unavailable: Callable = None
    clamp: bool = False
    report_lab: bool = False
    display_unit: str = ""
    note: str = ""
    description: str = ""
    derived: tuple = ()


@dataclass(frozen=True)
class SceneParameter:
    """One continuous parameter of a scene.

    Attributes
    ----------
    name : str
        The ``Scene`` field or the material's attribute; the key of files, sweeps, pixel tables
        and ``FitResult``.
    label : str
        What it is, in words ("bending stiffness", "Mooney-Rivlin alpha").
    symbol : str
        Its value as a ratio, where that says more than the name (``"H/R_L"``).
    qualifier : str
        The words in parentheses of its range error (default: ``label``).
    low, high, low_open, high_open
        The valid range (``-inf``/``inf``: open ended).
    range : str
        The range as the error words it (default from the bounds, as a material's).
    material : str
        The material family it belongs to ("" for a field of ``Scene``).
    option, option_help : str
        Its option of the command line's scene (``--beta``; "" none).
    lab : Lab or None
        Its lab form (unit, scale).
    determines : tuple of str
        The scene quantities that setting it sets (default: itself; the thickness sets beta too).
    fit : FitSearch or None
        A fit may fit it (the search).
    sweep, uncertainty, per_pixel : bool
        A sweep may vary it; it may be given a standard uncertainty; a pixel table may give it.
    aliases : tuple of str
        Other names users meet for it (``eps`` for H/R_L in ``Scene.describe``).
    """

    name: str
    label: str
    symbol: str = ""
    qualifier: str = ""
    low: float = -math.inf
    high: float = math.inf
    low_open: bool = False
    high_open: bool = False
    range: str = ""
    material: str = ""
    option: str = ""
    option_help: str = ""
    lab: Lab = None
    determines: tuple = ()
    fit: FitSearch = None
    sweep: bool = False
    uncertainty: bool = False
    per_pixel: bool = False
    aliases: tuple = ()

    #: a scene holds every parameter nondimensional
    unit = "1"

    @property
    def unit_text(self) -> str:
        """The scene's unit with what it is over: ``1 (H/R_L)``."""
        return f"1 ({self.symbol})" if self.symbol else "1"

    @property
    def sets(self) -> tuple:
        return self.determines or (self.name,)

    @property
    def dest(self) -> str:
        """The attribute of the parsed command line that holds its option's value."""
        return self.option[2:].replace("-", "_") if self.option else ""

    def range_text(self) -> str:
        if self.range:
            return self.range
        if self.high == math.inf:
            return f"a finite number {'>' if self.low_open else '>='} {self.low:g}"
        return f"in {'(' if self.low_open else '['}{self.low:g}, {self.high:g}{')' if self.high_open else ']'}"

    def low_ok(self, v) -> bool:
        return self.low == -math.inf or (v > self.low if self.low_open else v >= self.low)

    def high_ok(self, v) -> bool:
        return self.high == math.inf or (v < self.high if self.high_open else v <= self.high)

    def contains(self, value) -> bool:
        return (not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)
                and self.low_ok(value) and self.high_ok(value))

    def check(self, value, shown=None) -> None:
        """ValueError ``name (qualifier) must be RANGE; got VALUE`` unless ``value`` is in the range
        (``shown``: the value as the user gave it, when that differs)."""
        if not self.contains(value):
            raise ValueError(f"{self.name} ({self.qualifier or self.label}) must be {self.range_text()}; "
                             f"got {value if shown is None else shown!r}")

    def material_label(self) -> str:
        return material_class(self.material).label if self.material else ""

    def needs(self, scene, what="scene"):
        """None if ``scene`` has this parameter, else ``NAME needs a LABEL <what>; its material is ...``."""
        if not self.material or scene.material.family == self.material:
            return None
        return f"{self.name} needs a {self.material_label()} {what}; its material is {scene.material!r}"

    def get(self, scene):
        """The scene's value (float), or None where it has none (another material; no thickness)."""
        if self.material:
            return float(getattr(scene.material, self.name)) if scene.material.family == self.material else None
        value = getattr(scene, self.name)
        return None if value is None else float(value)

    def to_lab(self, value, R_L, mu_H=None) -> float:
        """The value in its lab unit (``lab.unit``): ``value * scale``."""
        return self.lab.to_lab(value, R_L, mu_H)

    def from_lab(self, value, R_L, mu_H=None) -> float:
        """The scene's nondimensional value of a lab value (SI)."""
        return self.lab.from_lab(value, R_L, mu_H)


def scene_with(scene, values: dict):
    """``scene`` with parameters set by name, in one replace (the scene is checked once, with all
    of them): a material's parameter keeps the material's others, or makes the material of its
    family when the scene's is another."""
    fields, materials = {}, {}
    for name, value in values.items():
        p = scene_parameter(name)
        if p.material:
            materials.setdefault(p.material, {})[name] = value
        else:
            fields[name] = value
    if len(materials) > 1:
        raise ValueError(" and ".join(f"{', '.join(v)} ({material_class(f).label})" for f, v in materials.items())
                         + " belong to different materials")
    for family, given in materials.items():
        old = scene.material.values() if scene.material.family == family else {}
        fields["material"] = material_class(family)(**{**old, **given})
    return scene.replace(**fields)


# -- the scene's own parameters -------------------------------------------------------------------
def _pressure_Pa():
    return Derived("pressure_Pa", "Pa", "p", "kPa", "p mu_H/R_L; linearised",
                   value=lambda p, mu_H, R_L: p * mu_H / R_L,
                   gradient=lambda p, mu_H, R_L: (p / R_L, mu_H / R_L))


def _pressure_scale(scene):
    return 4 * math.sqrt(3 * scene.beta)  # tau = 1 at a pole of unit curvature


def _eps_of_beta(beta, bending):
    """eps = H/R_L of a bending stiffness, by the package's map (beta is eps^2 times its value at eps = 1)."""
    return math.sqrt(beta / beta_from_thickness(1.0, 1.0, bending))


def _modulus(name, factor, note):
    """``factor * mu*H / H`` (Pa) of a fitted thickness: mu (factor 1) or E = 3 mu (incompressible)."""
    return Derived(name, "Pa", name, "MPa", note,
                   value=lambda eps, mu_H, R_L: factor * mu_H / (eps * R_L),
                   gradient=lambda eps, mu_H, R_L: (factor / (eps * R_L), -factor * mu_H / (eps ** 2 * R_L)),
                   log_interval=True)


BETA = SceneParameter(
    "beta", "bending stiffness", symbol="B/(mu R_L^2)", low=0.0, low_open=True, range="> 0", option="--beta",
    sweep=True, uncertainty=True, per_pixel=True,
    fit=FitSearch(default_bounds=lambda scene: (1e-4, 1.0), log_scale=True,
                  step=lambda scene: math.log(2.0),  # trial values a factor 2 apart
                  fit_help="also fit beta (starting from the scene's; a few more model curves)",
                  range_help="search range of --fit-beta, LOW,HIGH (default 1e-4,1)"))

RHO = SceneParameter("rho", "indenter radius / rim radius", low=0.0, low_open=True, range="> 0", option="--rho",
                     lab=Lab("indenter radius", "m", "length"), sweep=True, uncertainty=True)

# gamma < 1/rho (first contact at the pole) is the scene's check: it takes two parameters
GAMMA = SceneParameter("gamma", "spheroid aspect parameter", range="a finite number", option="--gamma",
                       lab=Lab("rise", "m", "length"), sweep=True, uncertainty=True)

PRESSURE = SceneParameter(
    "pressure", "pressure below the shell", symbol="p R_L/(mu H)", option="--pressure",
    lab=Lab("p", "Pa", "pressure", scale="mu_H/R_L"), sweep=True,
    fit=FitSearch(
        default_bounds=lambda scene: (0.0, max(4 * abs(float(scene.pressure)), 10 * _pressure_scale(scene))),
        step=lambda scene: max(0.25 * abs(float(scene.pressure)), 0.5 * _pressure_scale(scene)),
        note="; nondimensional p R_L/(mu H)",
        fit_help="also fit the pressure below the shell (turgor, inflation): mu*H and the pressure in Pa "
                 "from one curve; --pressure (nondimensional p R_L/(mu H)) is the start",
        range_help="search range of --fit-pressure, nondimensional LOW,HIGH (default 0 to the larger of 4x "
                   "the start and 40 sqrt(3 beta))",
        derived=(_pressure_Pa(),)))

# Fitting the thickness is fitting beta through the trace-bending map beta(eps) of
# shellbvp.units.beta_from_thickness (the scene applies it): the same curves at the same trial
# values (beta ~ eps^2, so a factor sqrt(2) in eps is beta's factor 2), reported as H = eps R_L,
# and mu*H splits into the modulus, mu = mu*H / H, E = 3 mu.
THICKNESS = SceneParameter(
    "thickness", "shell thickness", symbol="H/R_L", qualifier="H / R_L", low=0.0, high=0.5, low_open=True,
    option="--thickness", lab=Lab("H", "m", "length"), determines=("thickness", "beta"), per_pixel=True,
    aliases=("eps",),
    fit=FitSearch(
        description="shell thickness H (beta = (H/R_L)^2/3)",
        unavailable=lambda scene: None if scene.thickness is not None else (
            "fit_thickness starts from the scene's thickness: give one (Scene(thickness=H/R_L); the CLI's "
            "--thickness)"),
        default_bounds=lambda scene: (_eps_of_beta(BETA.fit.default_bounds(scene)[0], scene.bending),
                                      0.5 * _thickest_over_pole(scene)),
        log_scale=True, step=lambda scene: 0.5 * math.log(2.0), report_lab=True, display_unit="um",
        note="; beta = (H/R_L)^2/3",
        fit_help="also fit the shell's thickness H (beta = (H/R_L)^2/3, a 3D plate's bending), which gives the "
                 "modulus mu = mu*H / H and E = 3 mu; --thickness is the start",
        range_help="search range of --fit-thickness, LOW,HIGH as H/R_L or lengths with --radius (e.g. 10um,100um; "
                   "default from beta = 1e-4 to H/R_L = 0.5)",
        derived=(_modulus("mu", 1.0, "mu*H / H; linearised in ln mu, with H's uncertainty"),
                 _modulus("E", 3.0, "E = 3 mu, incompressible; linearised in ln E"))))

def _thickest_over_pole(scene) -> float:
    """1, or a profiled wall's pole thickness over its thickest (a fitted thickness scales the
    profile: the whole wall stays within H/R_L <= 0.5)."""
    profile = scene.thickness_profile
    return 1.0 if profile is None else scene.thickness / profile.thickest(scene.shell_length)


#: Where the registered materials' parameters stand in :data:`DECLARED`.
MATERIAL_PARAMETERS = "the materials' parameters"
#: The registry's order: the sweep's axes (the command line's), the fit's columns in tables and
#: files, and the lists in messages follow it.
DECLARED = (BETA, RHO, GAMMA, MATERIAL_PARAMETERS, PRESSURE, THICKNESS)


# -- the registry ---------------------------------------------------------------------------------
def _of_material(cls, p) -> SceneParameter:
    """A material's parameter as an entry of the registry (its flags, its range, its family)."""
    label = f"{cls.label} {p.name}"
    fit = None
    if p.fit:
        if not (math.isfinite(p.low) and math.isfinite(p.high)):
            raise ValueError(f"{p.name} ({cls.label}): a fitted material parameter needs a finite range")
        fit = FitSearch(
            default_bounds=lambda scene, lo=p.low, hi=p.high: (lo, hi), step=lambda scene, s=(p.high - p.low) / 5: s,
            clamp=True, fit_help=f"also fit the {label} (starting from the scene's)",
            range_help=f"search range of --fit-{p.name}, LOW,HIGH (default {p.low:g},{p.high:g})",
            unavailable=lambda scene, n=p.name, f=cls.family, lb=cls.label: None if scene.material.family == f else (
                f"fit_{n} needs a {lb} material ({n}); the scene's material is {scene.material.family}"))
    return SceneParameter(p.name, label, qualifier=cls.label, low=p.low, high=p.high, low_open=p.low_open,
                          material=cls.family, option=p.option or (f"--{p.name}" if p.sweep or p.uncertainty else ""),
                          option_help=p.option_help or f"{label} {p.range_text()}", fit=fit, sweep=p.sweep,
                          uncertainty=p.uncertainty, per_pixel=p.per_pixel)


_BUILT = [None, None]  # (the materials' registration seen, the registry built from it)


def scene_parameters() -> dict:
    """``{name: SceneParameter}`` in the registry's order, the registered materials' included
    (built again when a material has joined).  ValueError if two declare one name."""
    key = tuple((family, cls, cls.parameters) for family, cls in MATERIALS.items())
    if _BUILT[0] != key:
        found = {}
        for entry in DECLARED:
            entries = [_of_material(cls, p) for _, cls, params in key for p in params] \
                if entry is MATERIAL_PARAMETERS else [entry]
            for p in entries:
                if p.name in found:
                    raise ValueError(f"scene parameter {p.name!r} is declared twice ({found[p.name].label}; "
                                     f"{p.label}): one name per quantity")
                if p.per_pixel and p.fit is None:
                    raise ValueError(f"{p.name}: a parameter given per pixel needs a fit search (the model curves "
                                     f"between pixels are spaced as the search's trial values)")
                if (p.sweep or p.uncertainty) and not p.option:
                    raise ValueError(f"{p.name}: a parameter swept or given an uncertainty needs a command-line "
                                     f"option")
                found[p.name] = p
        _BUILT[:] = [key, found]
    return _BUILT[1]


def scene_parameter(name) -> SceneParameter:
    """The declaration of ``name``; ValueError naming the known ones otherwise."""
    known = scene_parameters()
    if name not in known:
        raise ValueError(f"unknown scene parameter {name!r}; known: {', '.join(known)}")
    return known[name]


def parameters_that(role) -> tuple:
    """The parameters of a role of :data:`ROLES` (``"sweep"``: those a sweep may vary), in order."""
    if role not in ROLES:
        raise ValueError(f"unknown role {role!r}; one of {ROLES}")
    return tuple(p for p in scene_parameters().values() if getattr(p, role))


class LiveMapping(Mapping):
    """A mapping built from the registry by ``build()``, anew when the registry has changed
    (a material registered later): the public tables of the modules that read the registry."""

    def __init__(self, build):
        self._build, self._seen = build, (None, None)

    def _now(self):
        registry = scene_parameters()
        if self._seen[0] is not registry:
            self._seen = (registry, self._build())
        return self._seen[1]

    def __getitem__(self, key):
        return self._now()[key]

    def __iter__(self):
        return iter(self._now())

    def __len__(self):
        return len(self._now())

    def __repr__(self):
        return repr(self._now())


class LiveNames(Sequence):
    """A tuple built from the registry by ``build()`` (as :class:`LiveMapping`); it prints and
    compares as the tuple."""

    def __init__(self, build):
        self._map = LiveMapping(lambda: dict.fromkeys(build()))

    def __getitem__(self, i):
        return tuple(self._map)[i]

    def __len__(self):
        return len(self._map)

    def __iter__(self):
        return iter(self._map)

    def __contains__(self, item):
        return item in self._map

    def __eq__(self, other):
        return tuple(self) == (tuple(other) if isinstance(other, (list, tuple, LiveNames)) else other)

    __hash__ = None

    def __add__(self, other):
        return tuple(self) + tuple(other)

    def __repr__(self):
        return repr(tuple(self))


#: Every scene parameter by name (live: see :func:`scene_parameters`).
SCENE_PARAMETERS = LiveMapping(lambda: dict(scene_parameters()))
