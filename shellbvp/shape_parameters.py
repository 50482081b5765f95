"""What a fit may fit besides mu*H: the shape parameters, the fit's view of the registry of
scene parameters (:mod:`shellbvp.scene_parameters`).

mu*H only scales the nondimensional curve F(delta); a shape parameter changes its shape
(the bending stiffness beta, the Mooney-Rivlin alpha, the pressure below the shell, the
thickness).  A fit estimates one of them by its profile likelihood on a few model curves at
trial values (:func:`shellbvp.fitting.fit`, ``free=(name,)``).  Everything that handles a shape
parameter -- the fit's search, ``FitResult`` and its JSON, the CLI's ``--fit-NAME`` and
``--NAME-range``, the batch table, the fit file and its report, the uncertainty of the
geometry -- iterates over :data:`SHAPE_PARAMETERS`.

To add one: give its :class:`~shellbvp.scene_parameters.SceneParameter` a
:class:`~shellbvp.scene_parameters.FitSearch` (a scene field's, in
``shellbvp/scene_parameters.py``), or set ``fit=True`` on a material's
:class:`~shellbvp.materials.Parameter` (searched over its range); then test it.  Its lab-unit
quantities that also depend on mu*H (the pressure in Pa) are :class:`Derived` quantities,
reported with a linearised interval from the fit's covariance.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

from .scene_parameters import Derived, LiveMapping, SceneParameter, parameters_that, scene_with

__all__ = ["ShapeParameter", "Derived", "SHAPE_PARAMETERS", "DERIVED", "shape_parameter"]


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


@functools.lru_cache(maxsize=None)
def _of(p: SceneParameter) -> ShapeParameter:
    """The fit's declaration of a registered parameter with a :class:`FitSearch`."""
    f = p.fit

    def set_(scene, x):
        if f.clamp:
            x = min(max(x, p.low), p.high)
        return scene_with(scene, {p.name: float(x)})

    return ShapeParameter(
        p.name, f.description or " ".join(t for t in (p.label, p.symbol) if t), get=p.get, set=set_,
        default_bounds=f.default_bounds, step=f.step, fit_help=f.fit_help, range_help=f.range_help,
        unavailable=f.unavailable or (lambda scene: None), low_ok=p.low_ok, high_ok=p.high_ok, log_scale=f.log_scale,
        unit=p.lab.unit if f.report_lab else "1", unit_text="" if f.report_lab or not p.symbol else p.unit_text,
        report_scale=p.lab.factor if f.report_lab else (lambda R_L: 1.0),
        display_unit=f.display_unit, unit_kind=p.lab.kind if f.report_lab else "", note=f.note, sets=p.sets,
        derived=f.derived)


#: The shape parameters by name, in the order of the batch table's and the file's columns (the
#: registry's; live: a material registered later joins it).
SHAPE_PARAMETERS = LiveMapping(lambda: {p.name: _of(p) for p in parameters_that("fit")})
#: The derived quantities of all of them by name.
DERIVED = LiveMapping(lambda: {d.name: d for p in SHAPE_PARAMETERS.values() for d in p.derived})


def shape_parameter(name) -> ShapeParameter:
    """The declaration of ``name``; ValueError naming the known ones otherwise."""
    if name not in SHAPE_PARAMETERS:
        raise ValueError(f"unknown shape parameter {name!r}; a fit may fit {', '.join(SHAPE_PARAMETERS)}")
    return SHAPE_PARAMETERS[name]
