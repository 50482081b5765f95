"""The contact configurations, registered in one place.

A :class:`Configuration` is what a state's ``topology`` names: its chain of regions
(``shellbvp.chain``), the contact models and controls it exists for, its family (what
kind of search finds it) and how its system is built.  Every other module asks the
registry (:func:`configuration`, :func:`names`) instead of listing names itself.

Families:

``cap``
    one contact region from the pole (the single cap);
``point``
    the point-load limit, no contact region;
``lifted``
    the pole lifted off the tip, contact further out (line, annulus, line+corner);
``split``
    a cap and, beyond a lifted gap, a second zone on the tip;
``wall``
    contact on the indenter's cylinder beyond the tip's end.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Callable

from . import chain as ch
from .inflation import system_parameters
from .solution import attach_tip_table

__all__ = ["Configuration", "CONFIGURATIONS", "CONFIGURATION_NAMES", "FAMILIES", "configuration", "names",
           "register", "family_of", "of", "is_single_cap", "is_point_load", "resolve", "CAP_REPLACEMENTS", "ASKED",
           "Switch", "SWITCHES", "switch_between"]

FAMILIES = ("cap", "point", "lifted", "split", "wall")
#: Start of the point-load state's free region (its own eps; truncation error O(s0^2 ln^2 s0)).
POINT_S0 = 1e-12


@dataclass(frozen=True)
class Configuration:
    """One contact configuration.

    Attributes
    ----------
    name : str
        What ``Solution.topology`` and a curve's ``topology`` column hold.
    family : str
        One of :data:`FAMILIES`.
    chain : callable
        ``chain(eps, L, edge)`` -> :class:`shellbvp.chain.Chain` (``edge``: the contact
        edge's model, "smooth", "corner", "paper" or "pinned").
    contacts : tuple of str
        The scene contact models it exists for.
    controls : tuple of str
        What may be prescribed.
    askable : bool
        Whether ``solve(topology=name)`` may ask for it.
    needs_tip_end : bool
        Whether it needs a tip that ends on a cylinder (``model.OMEGA_MAX``).
    again : str or None
        ``"module:function"`` that solves this configuration again from one of its states
        (``solve(guess=...)``): ``again(guess, control, value, *, topology, tol, max_nodes,
        eps, bc_tol, estimate_error)`` returns the finished state, or None to fall back to
        the single cap.  None: the cap's own warm start serves.
    inner_edge : bool
        Its contact zone has an inner edge ``S1`` besides ``Sc`` (the annulus): guessed with
        the edge near the cap's middle, refused once the edge runs to the pole.
    line_contact : bool
        Its outer contact on the tip is one circle carrying a ring force (zero width), whose
        ``curvature_excess`` says when it opens into a band.
    measured : (str, str) or None
        Where a switch criterion is measured on this configuration (``SWITCHES``), how to get
        its state: ``"module:function"`` of ``state_at(recorded, name, settings)``, its state
        at a recorded point's depth (None if there is none), and of ``solved_at(scene, name,
        delta, near, settings)``, its state at another depth from a neighbour.
    pole_branch_end : bool
        A smooth lifted pole whose branch may end where its Legendre determinant vanishes
        (:mod:`shellbvp.lifted_ends`).
    """

    name: str
    family: str
    chain: Callable
    contacts: tuple = ("smooth", "paper")
    controls: tuple = ("delta", "force", "lambda0")
    askable: bool = False
    needs_tip_end: bool = False
    again: str | None = None
    inner_edge: bool = False
    line_contact: bool = False
    pole_branch_end: bool = False
    measured: tuple | None = None

    @property
    def single_cap(self) -> bool:
        """One contact region from the pole: the state every other configuration is searched from."""
        return self.family == "cap"

    @property
    def point_load(self) -> bool:
        """No contact region (the point-load limit, solved by ``shellbvp.pointload``)."""
        return self.family == "point"

    def check(self, scene, control):
        """A clear ValueError where ``scene`` or ``control`` does not allow this configuration."""
        if self.needs_tip_end and scene.model().OMEGA_MAX is None:
            raise ValueError("this tip has no end where it meets a cylinder (A' never vanishes): no wall contact")
        self.check_contact(scene)
        if control not in self.controls:
            raise ValueError(f"control must be one of {self.controls} for {self.name} contact; got {control!r}")

    def check_contact(self, scene):
        """A clear ValueError where the scene's contact model does not have this configuration."""
        if scene.contact not in self.contacts:
            raise ValueError(f"topology={self.name!r} needs contact='smooth': the paper's contact model has the "
                             f"single cap only" + (", which may run onto the cylinder ('cap+cylinder')"
                                                   if self.family == "wall" else ""))

    def system(self, scene, control, value, eps, edge=None):
        """The ChainBVP of this configuration for ``scene`` with ``control`` = ``value``, its
        tip tabulated for the admissibility checks."""
        self.check(scene, control)
        model = scene.model()
        sysm = ch.ChainBVP(scene, self.chain(eps, scene.shell_length, edge or scene.contact), control, value,
                           model=model, par=system_parameters(scene, model))
        attach_tip_table(sysm)
        return sysm


#: Every configuration, by name, in the order of :func:`register`
CONFIGURATIONS: dict[str, Configuration] = {}


def register(conf: Configuration) -> Configuration:
    if conf.family not in FAMILIES:
        raise ValueError(f"family must be one of {FAMILIES}; got {conf.family!r}")
    if conf.name in CONFIGURATIONS:
        raise ValueError(f"configuration {conf.name!r} is registered already")
    CONFIGURATIONS[conf.name] = conf
    return conf


def configuration(name: str) -> Configuration:
    """The registered configuration ``name`` (ValueError naming the known ones otherwise)."""
    try:
        return CONFIGURATIONS[name]
    except KeyError:
        raise ValueError(f"topology must be one of {tuple(CONFIGURATIONS)}; got {name!r}") from None


def names(family: str | None = None, *, having: str | None = None) -> tuple:
    """The names of every configuration, or of one family's, in registration order; ``having``:
    only those with that trait (an attribute, e.g. ``"pole_branch_end"``)."""
    return tuple(n for n, c in CONFIGURATIONS.items()
                 if (family is None or c.family == family) and (having is None or getattr(c, having)))


def family_of(state) -> str:
    """The family of a state's configuration (``"inflated"`` for the inflated shell)."""
    conf = CONFIGURATIONS.get(state.topology)
    return state.topology if conf is None else conf.family


def of(state) -> Configuration | None:
    """The registered configuration of a state (None for the inflated shell)."""
    return CONFIGURATIONS.get(state.topology)


def is_single_cap(state) -> bool:
    conf = of(state)
    return conf is not None and conf.single_cap


def is_point_load(state) -> bool:
    conf = of(state)
    return conf is not None and conf.point_load


def resolve(path: str) -> Callable:
    """The function a ``"module:function"`` path names (imported when first asked for: a
    configuration's numerics live in its family's module, which imports this registry)."""
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


#: How a single cap is replaced where a state of another family is suspected, in the order tried:
#: ``replace(cap, topology, kw)`` returns the replacement or the cap (with what was tried in its flags)
CAP_REPLACEMENTS = (("wall", "shellbvp.cylinder:cap_onto_wall"), ("lifted", "shellbvp.liftoff:cap_lifted_off"))


def _lifted(chain):
    return lambda eps, L, edge: chain(eps, L)


_LIFTED_AGAIN = "shellbvp.liftoff:lifted_again"
_SPLIT_AGAIN = "shellbvp.liftoff:split_again"
_WALL_AGAIN = "shellbvp.cylinder:wall_again"
register(Configuration("cap", "cap", ch.cap_chain, controls=("delta", "force", "lambda0", "arclength"), askable=True,
                       measured=("shellbvp.switches:cap_state_at", "shellbvp.switches:cap_solved_at")))
register(Configuration("point", "point", lambda eps, L, edge: ch.point_chain(POINT_S0, L), controls=("delta",)))
register(Configuration("line", "lifted", _lifted(ch.line_chain), contacts=("smooth",), askable=True,
                       again=_LIFTED_AGAIN, line_contact=True, pole_branch_end=True,
                       measured=("shellbvp.switches:line_state_at", "shellbvp.switches:lifted_solved_at")))
register(Configuration("annulus", "lifted", _lifted(ch.annulus_chain), contacts=("smooth",), askable=True,
                       again=_LIFTED_AGAIN, inner_edge=True, pole_branch_end=True))
register(Configuration("cap+line(tip)", "split", _lifted(ch.cap_line_tip_chain), contacts=("smooth",),
                       again=_SPLIT_AGAIN))
register(Configuration("cap+band(tip)", "split", _lifted(ch.cap_band_tip_chain), contacts=("smooth",),
                       again=_SPLIT_AGAIN))
register(Configuration("cap+line(cylinder)", "wall", ch.cap_line_cylinder_chain, contacts=("smooth",), askable=True,
                       needs_tip_end=True, again=_WALL_AGAIN,
                       measured=("shellbvp.switches:wall_state_at", "shellbvp.switches:wall_solved_at")))
register(Configuration("cap+band(cylinder)", "wall", ch.cap_band_cylinder_chain, contacts=("smooth",), askable=True,
                       needs_tip_end=True, again=_WALL_AGAIN))
register(Configuration("cap+cylinder", "wall", ch.cylinder_chain, askable=True, needs_tip_end=True,
                       again=_WALL_AGAIN))
register(Configuration("line+corner", "lifted", _lifted(ch.line_kink_chain), contacts=("smooth",),
                       again=_LIFTED_AGAIN))

@dataclass(frozen=True)
class Switch:
    """Where a curve passes from one configuration to a neighbour: the depth at which
    ``criterion`` of the ``measured_on`` configuration's state crosses zero (``sign`` times it
    is positive on the side of the first configuration's validity).  Of ``criteria`` the first
    that both neighbouring points have finite is used (else the last)."""

    between: frozenset
    measured_on: str
    criteria: tuple
    sign: float = 1.0


#: The switches a curve locates between neighbouring configurations
SWITCHES = [
    # the cap's contact pressure at its edge: where a lifted pole or a split contact takes over
    *(Switch(frozenset({"cap", other}), "cap", ("pressure_min",)) for other in ("line", "annulus", "cap+line(tip)")),
    # the lifted pole comes down onto the tip: a cap grows there
    Switch(frozenset({"line", "cap+line(tip)"}), "line", ("pole_clearance",)),
    # the line's curvature reaches the indenter's: the line opens into an annulus
    Switch(frozenset({"line", "annulus"}), "line", ("curvature_excess",), -1.0),
    # the free shell reaches the cylinder (or the contact the tip's end)
    *(Switch(frozenset({"cap", wall}), "cap", ("wall_gap", "tip_end_margin"))
      for wall in ("cap+line(cylinder)", "cap+band(cylinder)", "cap+cylinder")),
    # the line on the cylinder opens into a band
    Switch(frozenset({"cap+line(cylinder)", "cap+band(cylinder)"}), "cap+line(cylinder)", ("curvature_excess",), -1.0),
]


def switch_between(a: str, b: str):
    """The :class:`Switch` between configurations ``a`` and ``b`` (None if there is none)."""
    pair = frozenset({a, b})
    return next((s for s in SWITCHES if s.between == pair), None)


#: Every configuration's name (``Solution.topology``, a curve's per-point ``topology``)
CONFIGURATION_NAMES = names()
#: What ``solve(topology=...)`` accepts
ASKED = ("auto",) + tuple(n for n, c in CONFIGURATIONS.items() if c.askable)
