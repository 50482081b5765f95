"""What a fit may fit besides mu*H: the shape parameters, each declared once.

mu*H only scales the nondimensional curve F(delta); a shape parameter changes its shape
(the bending stiffness beta, the Mooney-Rivlin alpha, the pressure below the shell, the
thickness).  A fit estimates one of them by its profile likelihood on a few model curves at
trial values (:func:`shellbvp.fitting.fit`, ``free=(name,)``).  Everything that handles a shape
parameter -- the fit's search, ``FitResult`` and its JSON, the CLI's ``--fit-NAME`` and
``--NAME-range``, the batch table, the fit file and its report, the uncertainty of the
geometry -- iterates over :data:`SHAPE_PARAMETERS`.

To add one: declare a :class:`ShapeParameter` below (how it reads and sets the scene, its
default search range, its search scale, how it is reported) and add it to the registry;
then test it.  Its lab-unit quantities that also depend on mu*H (the pressure in Pa) are
:class:`Derived` quantities, reported with a linearised interval from the fit's covariance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

__all__ = ["ShapeParameter", "Derived", "SHAPE_PARAMETERS", "DERIVED", "shape_parameter"]


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
class ShapeParameter:
    """One parameter a fit may fit besides mu*H.

    Attributes
    ----------
    name : str
        As ``fit(free=(name,))``, ``--fit-<name>``, ``res.<name>``, the fit file's key.
    description : str
        For the CLI's help and messages.
    get : callable
        ``get(scene)``: the scene's nondimensional value (the start of the search), or None
        where the scene has none (alpha of a neo-Hookean material).
    set : callable
        ``set(scene, x)``: the scene at value x.
    unavailable : callable
        ``unavailable(scene)``: why this scene cannot have it fitted (None: it can).
    default_bounds : callable
        ``default_bounds(scene) -> (low, high)``: the search range (nondimensional).
    low_ok, high_ok : callable
        Whether a given bound lies in the valid range.
    log_scale : bool
        Search in ``theta = ln x`` (else ``theta = x``).
    step : callable
        ``step(scene)``: the spacing of the trial values in theta.
    unit : str
        Unit of the reported value ("1": nondimensional).
    unit_text : str
        The unit as JSON's ``units`` names it, when it says more than ``unit``.
    report_scale : callable
        ``report_scale(R_L)``: the reported value is ``x * report_scale(R_L)`` (1 for a
        nondimensional report).
    display_unit, unit_kind : str
        How the CLI shows the value (``format_in``) and reads lab-unit ranges; "" when
        nondimensional.
    note : str
        Appended to the CLI's line of the fitted value.
    fit_help, range_help : str
        Help of ``--fit-<name>`` and ``--<name>-range``.
    sets : tuple of str
        The scene quantities that fitting it determines (a fitted quantity cannot also be
        given an uncertainty).
    derived : tuple of Derived

    Examples
    --------
    >>> import shellbvp as sb
    >>> from shellbvp.shape_parameters import SHAPE_PARAMETERS
    >>> beta = SHAPE_PARAMETERS["beta"]
    >>> beta.get(sb.Scene.preset("fit")), beta.log_scale, beta.default_bounds(None)
    (0.01, True, (0.0001, 1.0))
    >>> beta.set(sb.Scene.preset("fit"), 0.02).beta
    0.02
    """

    name: str
    description: str
    get: Callable
    set: Callable
    default_bounds: Callable
    step: Callable
    fit_help: str
    range_help: str
    unavailable: Callable = lambda scene: None
    low_ok: Callable = lambda v: True
    high_ok: Callable = lambda v: True
    log_scale: bool = False
    unit: str = "1"
    unit_text: str = ""
    report_scale: Callable = lambda R_L: 1.0
    display_unit: str = ""
    unit_kind: str = ""
    note: str = ""
    sets: tuple = ()
    derived: tuple = ()

    def to_theta(self, x):
        """The search variable of value x."""
        return math.log(x) if self.log_scale else float(x)

    def from_theta(self, theta):
        """The value at search variable theta."""
        return math.exp(theta) if self.log_scale else float(theta)

    def dx_dtheta(self, theta):
        return math.exp(theta) if self.log_scale else 1.0

    def reported(self, x, R_L):
        """The value x as ``FitResult`` reports it (in :attr:`unit`)."""
        scale = self.report_scale(R_L)
        return x if scale == 1.0 else x * scale


def _mooney_rivlin():
    from .materials import MooneyRivlin

    return MooneyRivlin


def _pressure_Pa():
    return Derived("pressure_Pa", "Pa", "p", "kPa", "p mu_H/R_L; linearised",
                   value=lambda p, mu_H, R_L: p * mu_H / R_L,
                   gradient=lambda p, mu_H, R_L: (p / R_L, mu_H / R_L))


def _pressure_scale(scene):
    return 4 * math.sqrt(3 * scene.beta)  # tau = 1 at a pole of unit curvature


BETA = ShapeParameter(
    "beta", "bending stiffness B/(mu R_L^2)",
    get=lambda scene: float(scene.beta),
    set=lambda scene, x: scene.replace(beta=x),
    default_bounds=lambda scene: (1e-4, 1.0),
    low_ok=lambda v: v > 0, log_scale=True, unit_text="1 (B/(mu R_L^2))",
    step=lambda scene: math.log(2.0),  # trial values a factor 2 apart
    fit_help="also fit beta (starting from the scene's; a few more model curves)",
    range_help="search range of --fit-beta, LOW,HIGH (default 1e-4,1)",
    sets=("beta",))

ALPHA = ShapeParameter(
    "alpha", "Mooney-Rivlin alpha",
    get=lambda scene: float(scene.material.alpha) if isinstance(scene.material, _mooney_rivlin()) else None,
    set=lambda scene, x: scene.replace(material=_mooney_rivlin()(float(min(max(x, 0.0), 1.0)))),
    unavailable=lambda scene: None if isinstance(scene.material, _mooney_rivlin()) else (
        f"fit_alpha needs a Mooney-Rivlin material (alpha); the scene's material is {scene.material.family}"),
    default_bounds=lambda scene: (0.0, 1.0),
    low_ok=lambda v: v >= 0, high_ok=lambda v: v <= 1,
    step=lambda scene: 0.2,
    fit_help="also fit the Mooney-Rivlin alpha (starting from the scene's)",
    range_help="search range of --fit-alpha, LOW,HIGH (default 0,1)",
    sets=("alpha",))

PRESSURE = ShapeParameter(
    "pressure", "pressure below the shell p R_L/(mu H)",
    get=lambda scene: float(scene.pressure),
    set=lambda scene, x: scene.replace(pressure=float(x)),
    default_bounds=lambda scene: (0.0, max(4 * abs(float(scene.pressure)), 10 * _pressure_scale(scene))),
    step=lambda scene: max(0.25 * abs(float(scene.pressure)), 0.5 * _pressure_scale(scene)),
    note="; nondimensional p R_L/(mu H)", unit_text="1 (p R_L/(mu H))",
    fit_help="also fit the pressure below the shell (turgor, inflation): mu*H and the pressure in Pa "
             "from one curve; --pressure (nondimensional p R_L/(mu H)) is the start",
    range_help="search range of --fit-pressure, nondimensional LOW,HIGH (default 0 to the larger of 4x "
               "the start and 40 sqrt(3 beta))",
    sets=("pressure",), derived=(_pressure_Pa(),))


def _eps_of_beta(beta, bending):
    """eps = H/R_L of a bending stiffness, by the package's map (beta is eps^2 times its value at eps = 1)."""
    from .units import beta_from_thickness

    return math.sqrt(beta / beta_from_thickness(1.0, 1.0, bending))


def _modulus(name, factor, note):
    """``factor * mu*H / H`` (Pa) of a fitted thickness: mu (factor 1) or E = 3 mu (incompressible)."""
    return Derived(name, "Pa", name, "MPa", note,
                   value=lambda eps, mu_H, R_L: factor * mu_H / (eps * R_L),
                   gradient=lambda eps, mu_H, R_L: (factor / (eps * R_L), -factor * mu_H / (eps ** 2 * R_L)),
                   log_interval=True)


# Fitting the thickness is fitting beta through the trace-bending map beta(eps) of
# shellbvp.units.beta_from_thickness (the scene applies it): the same curves at the same trial
# values (beta ~ eps^2, so a factor sqrt(2) in eps is beta's factor 2), reported as H = eps R_L,
# and mu*H splits into the modulus, mu = mu*H / H, E = 3 mu.
THICKNESS = ShapeParameter(
    "thickness", "shell thickness H (beta = (H/R_L)^2/3)",
    get=lambda scene: scene.thickness,
    set=lambda scene, eps: scene.replace(thickness=eps),
    unavailable=lambda scene: None if scene.thickness is not None else (
        "fit_thickness starts from the scene's thickness: give one (Scene(thickness=H/R_L); the CLI's --thickness)"),
    default_bounds=lambda scene: (_eps_of_beta(BETA.default_bounds(scene)[0], scene.bending), 0.5),
    low_ok=lambda v: v > 0, high_ok=lambda v: v <= 0.5, log_scale=True,
    step=lambda scene: 0.5 * math.log(2.0),
    unit="m", report_scale=lambda R_L: R_L, display_unit="um", unit_kind="length",
    note="; beta = (H/R_L)^2/3",
    fit_help="also fit the shell's thickness H (beta = (H/R_L)^2/3, a 3D plate's bending), which gives the "
             "modulus mu = mu*H / H and E = 3 mu; --thickness is the start",
    range_help="search range of --fit-thickness, LOW,HIGH as H/R_L or lengths with --radius (e.g. 10um,100um; "
               "default from beta = 1e-4 to H/R_L = 0.5)",
    sets=("thickness", "beta"),
    derived=(_modulus("mu", 1.0, "mu*H / H; linearised in ln mu, with H's uncertainty"),
             _modulus("E", 3.0, "E = 3 mu, incompressible; linearised in ln E")))


#: The shape parameters by name, in the order of the batch table's and the file's columns.
SHAPE_PARAMETERS = {p.name: p for p in (BETA, ALPHA, PRESSURE, THICKNESS)}
#: The derived quantities of all of them by name.
DERIVED = {d.name: d for p in SHAPE_PARAMETERS.values() for d in p.derived}


def shape_parameter(name) -> ShapeParameter:
    """The declaration of ``name``; ValueError naming the known ones otherwise."""
    if name not in SHAPE_PARAMETERS:
        raise ValueError(f"unknown shape parameter {name!r}; a fit may fit {', '.join(SHAPE_PARAMETERS)}")
    return SHAPE_PARAMETERS[name]
