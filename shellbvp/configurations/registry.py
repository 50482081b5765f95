"""The registry of contact configurations: :class:`Configuration`, :class:`Switch`, the
look-ups every other module asks (:func:`configuration`, :func:`names`, :func:`of`,
:func:`switch_between`) and how the package finds its configuration modules
(:func:`discover`, :func:`install`).  The configurations themselves are declared in the
other modules of :mod:`shellbvp.configurations`, one module each.

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
    contact on the indenter's cylinder beyond the tip's end;
``closed``
    a closed shell on a substrate: a cap on the tip and a cap on the plane below
    (:mod:`shellbvp.closed` solves them).

A family's searches are functions of the modules above this registry that know it
(:mod:`shellbvp.liftoff`, :mod:`shellbvp.cylinder`), held by the modules that call them, by
family: how ``solve(guess=...)`` solves a state again (``shellbvp.state.AGAIN``), how a single
cap is replaced by a state of another family (``shellbvp.state.CAP_REPLACEMENTS``) and how a
switch criterion is measured on a configuration (``shellbvp.switches.MEASURED``).  The
registry names no module above it.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from typing import Callable

from .. import chain as ch
from ..edge_models import contact_models, edge_model
from ..inflation import enclosed_volume, lower_pole_rise, system_parameters
from ..solution import attach_tip_table

__all__ = ["Configuration", "CONFIGURATIONS", "FAMILIES", "configuration", "names", "register", "family_of", "of",
           "is_single_cap", "is_point_load", "Switch", "SWITCHES", "switch_between",
           "register_switch", "without_edge_model", "discover", "install", "asked"]

FAMILIES = ("cap", "point", "lifted", "split", "wall", "closed")


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
        edge's model, :mod:`shellbvp.edge_models`, or its name).
    contacts : tuple
        The scene contact models it exists for, declared by name (default every one), held as
        :class:`~shellbvp.edge_models.EdgeModel` (:meth:`allows`).
    controls : tuple of str
        What may be prescribed.
    askable : bool
        Whether ``solve(topology=name)`` may ask for it (of the lifted family, the ones
        :mod:`shellbvp.liftoff` searches).
    needs_tip_end : bool
        Whether it needs a tip that ends on a cylinder (``model.OMEGA_MAX``).
    inner_edge : bool
        Its contact zone has an inner edge ``S1`` besides ``Sc`` (the annulus): guessed with
        the edge near the cap's middle, refused once the edge runs to the pole.
    line_contact : bool
        Its outer contact on the tip is one circle carrying a ring force (zero width), whose
        ``curvature_excess`` says when it opens into a band.
    pole_branch_end : bool
        A smooth lifted pole whose branch may end where its Legendre determinant vanishes
        (:mod:`shellbvp.lifted_ends`).
    half : str or None
        How each half of a closed shell on a substrate touches its indenter where this
        configuration is that of a rimmed shell (``"point"``, ``"cap"``, ``"line"``,
        ``"annulus"``; :mod:`shellbvp.configurations.closed`), else None.
    """

    name: str
    family: str
    chain: Callable
    contacts: tuple = None
    controls: tuple = ("delta", "force", "lambda0")
    askable: bool = False
    needs_tip_end: bool = False
    inner_edge: bool = False
    line_contact: bool = False
    pole_branch_end: bool = False
    half: str = None

    def __post_init__(self):
        object.__setattr__(self, "contacts", tuple(edge_model(c) for c in self.contacts or contact_models()))

    def allows(self, scene) -> bool:
        """Whether it exists for the scene's contact model."""
        return scene.contact_model in self.contacts

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
        if (self.family == "closed") != scene.two_contacts:
            raise ValueError(f"topology={self.name!r} is " + ("a closed shell's on a substrate under a curved tip"
                             if self.family == "closed" else "a rimmed shell's (or a closed shell's half)"))
        if self.needs_tip_end and scene.model().OMEGA_MAX is None:
            raise ValueError("this tip has no end where it meets a cylinder (A' never vanishes): no wall contact")
        self.check_contact(scene)
        if control not in self.controls:
            raise ValueError(f"control must be one of {self.controls} for {self.name} contact; got {control!r}")

    def check_contact(self, scene):
        """A clear ValueError where the scene's contact model does not have this configuration."""
        if not self.allows(scene):
            needs = " or ".join(f"contact={m.name!r}" for m in self.contacts)
            raise ValueError(f"topology={self.name!r} needs {needs}: the paper's contact model has the "
                             f"single cap only" + (", which may run onto the cylinder ('cap+cylinder')"
                                                   if self.family == "wall" else ""))

    @staticmethod
    def enclosed_volume(scene) -> float:
        """V0 a sealed scene's system holds: its inflated state's, solved on the half above the
        equator of a closed shell, so both halves' where both are solved (solved whole where the
        halves differ)."""
        return enclosed_volume(scene) * (2 if scene.two_contacts and not getattr(scene.shell, "lower", None) else 1)

    def system(self, scene, control, value, eps, edge=None):
        """The ChainBVP of this configuration for ``scene`` with ``control`` = ``value``, its
        tip tabulated for the admissibility checks; a sealed scene's system holds the volume of
        its inflated state (solved here, once per scene, not by the system)."""
        self.check(scene, control)
        model = scene.model()
        lower = getattr(scene.shell, "lower", None)  # a closed shell's lower half of its own: its L
        L = (scene.shell_length, float(lower.geometry.L)) if lower is not None and self.family == "closed" else (
            scene.shell_length)
        sysm = ch.ChainBVP(scene, self.chain(eps, L, edge or scene.contact), control, value,
                           model=model, par=system_parameters(scene, model),
                           enclosed_volume=self.enclosed_volume(scene) if scene.sealed else None,
                           lower_pole_rise=lower_pole_rise(scene))
        attach_tip_table(sysm)
        return sysm


#: Every configuration, by name, in the order of :func:`register`
CONFIGURATIONS: dict[str, Configuration] = {}


def register(conf: Configuration) -> Configuration:
    """Add a configuration after those registered (ValueError for an unknown family or a name
    registered already)."""
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


def asked() -> tuple:
    """What ``solve(topology=...)`` accepts: ``"auto"`` and the configurations registered as
    ``askable``, in registration order."""
    return ("auto",) + names(having="askable")


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


#: The switches a curve locates between neighbouring configurations (each declared in the module
#: of the later of its two configurations, see :func:`register_switch`)
SWITCHES: list = []


def register_switch(switch: Switch) -> Switch:
    """Add a switch between two registered configurations (ValueError if either is not
    registered, if it is not measured on one of them, or if the pair has a switch already)."""
    unknown = sorted(n for n in switch.between if n not in CONFIGURATIONS)
    if unknown:
        raise ValueError(f"switch between {sorted(switch.between)}: {unknown} not registered")
    if switch.measured_on not in switch.between:
        raise ValueError(f"switch between {sorted(switch.between)} measured on {switch.measured_on!r}")
    if any(s.between == switch.between for s in SWITCHES):
        raise ValueError(f"the switch between {sorted(switch.between)} is registered already")
    SWITCHES.append(switch)
    return switch


def switch_between(a: str, b: str):
    """The :class:`Switch` between configurations ``a`` and ``b`` (None if there is none)."""
    pair = frozenset({a, b})
    return next((s for s in SWITCHES if s.between == pair), None)


def without_edge_model(chain: Callable) -> Callable:
    """A ``chain(eps, L)`` declared without a contact-edge model, called as the registry calls
    every chain, ``chain(eps, L, edge)``: ``edge`` is not used (such a configuration exists for
    the smooth contact model only, and its edges are the smooth ones)."""
    return lambda eps, L, edge: chain(eps, L)


def discover(package) -> list:
    """The configuration modules of ``package`` (every module in it but this registry and
    names starting with ``_``), imported, in the order of their ``ORDER`` numbers.

    ValueError where a module has no integer ``ORDER`` or two modules have the same: the
    order is that in which :func:`install` registers them, and :func:`names` lists them in it."""
    here = __name__.rpartition(".")[2]
    modules = [importlib.import_module(f"{package.__name__}.{info.name}")
               for info in pkgutil.iter_modules(package.__path__)
               if info.name != here and not info.name.startswith("_")]
    taken = {}
    for module in modules:
        order = getattr(module, "ORDER", None)
        if not isinstance(order, int) or isinstance(order, bool):
            raise ValueError(f"configuration module {module.__name__} has no integer ORDER")
        if order in taken:
            raise ValueError(f"configuration modules {taken[order]} and {module.__name__} have the same ORDER {order}")
        taken[order] = module.__name__
    return sorted(modules, key=lambda module: module.ORDER)


def install(module) -> None:
    """Register a configuration module's ``CONFIGURATIONS`` (a tuple of :class:`Configuration`),
    then its ``SWITCHES`` (a tuple of :class:`Switch`, optional), in their order."""
    for conf in module.CONFIGURATIONS:
        register(conf)
    for switch in getattr(module, "SWITCHES", ()):
        register_switch(switch)
