"""The models of a contact edge, as registered objects: what each one's edge conditions are,
what a curve does with it and which model it may switch to.

A scene's contact model (``Scene(contact=...)``, ``--contact``) is ``"smooth"`` or ``"paper"``
(SPEC section 2b).  Along a curve a cap's edge may change its model: the smooth edge past its
convexity limit becomes a Weierstrass-Erdmann ``"corner"`` (:mod:`shellbvp.corner`), and the
paper's edge reaching the tip's end is held there, ``"pinned"``.  Each is an :class:`EdgeModel`
in :data:`EDGE_MODELS`; a module that needs to know what an edge does asks its object
(``edge_model(name).variational``, ``.jumps``, ``.switches_to``), never its name.  Files,
``Solution.contact_edge``, ``Scene.contact`` and a chain's :class:`~shellbvp.chain.Edge` keep the
name (``EdgeModel.name``), and read back the same object through :func:`edge_model`.

This module imports nothing of the package (the command line's choices come from it before
numpy loads).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["EdgeModel", "EDGE_MODELS", "edge_model", "contact_models", "register_edge_model"]


@dataclass(frozen=True, eq=False)
class EdgeModel:
    """One model of a contact edge (registered once: compared by identity).

    Attributes
    ----------
    name : str
        What files, ``Scene.contact``, ``Solution.contact_edge`` and the generated code's
        functions (``junction_[cyl_|plane_]<name>_res``, ``_jac``, ``_jac_par``) call it.
    description : str
        One line for a user: what holds at the edge.
    conditions : tuple of str
        The five rows of its edge conditions, in the generated code's order
        (``symbolic.equations.Derivation._junction``).
    contact : bool
        A scene's contact model (``Scene(contact=name)`` takes it); otherwise a model a cap's
        edge switches to along a curve of the contact model ``of``.
    of : str or None
        For a model a curve switches to: the scene's contact model whose curves reach it.
    switches_to : str or None
        The model a cap of this one switches to along a curve (located by
        :func:`shellbvp.switches.locate_switches`), None if none.
    variational : bool
        The edge conditions are the energy's natural conditions (the Weierstrass-Erdmann
        conditions): the energy identity holds, the lifted-pole, split and closed-shell
        configurations exist and the stability against Fourier modes is defined.
    point_load_limit : bool
        As delta -> 0 the cap shrinks to the point load's state (SPEC 2b): a cap leaving double
        precision is continued by the point load, and cold starts go through it.
    convexity_limit : bool
        The cap's branch ends where the Legendre determinant at the edge's free side vanishes
        (``Solution.edge_legendre``), where the model it switches to (the corner) continues it.
    jumps : bool
        lambda_s and kappa_s may jump at the edge (a Weierstrass-Erdmann corner).
    held_at_tip_end : bool
        The edge is held at the tip's end, where the indenter's meridional curvature jumps.
    """

    name: str
    description: str
    conditions: tuple
    contact: bool = False
    of: str | None = None
    switches_to: str | None = None
    variational: bool = False
    point_load_limit: bool = False
    convexity_limit: bool = False
    jumps: bool = False
    held_at_tip_end: bool = False

    def __repr__(self) -> str:  # a chain's description prints ``Edge(kc=0, kf=1, model='smooth')`` as before
        return repr(self.name)

    def __str__(self) -> str:
        return self.name

    def __reduce__(self):  # pickled by name: a worker's chain holds the registered object
        return edge_model, (self.name,)

    def function(self, module, prefix: str, what: str):
        """The generated function of these edge conditions: ``what`` is ``res``, ``jac`` or
        ``jac_par``; ``prefix`` the contact region's (``""`` the tip, ``"cyl_"``, ``"plane_"``)."""
        return getattr(module, f"junction_{prefix}{self.name}_{what}")

    @property
    def next(self) -> EdgeModel | None:
        """The model a cap of this one switches to along a curve (None if none)."""
        return None if self.switches_to is None else EDGE_MODELS[self.switches_to]

    def leads_to(self, other: EdgeModel) -> bool:
        """Whether a cap of this model switches to ``other`` along a curve."""
        return self.next is other


#: Every edge model, by name, in the order registered
EDGE_MODELS: dict[str, EdgeModel] = {}


def register_edge_model(model: EdgeModel) -> EdgeModel:
    """Add an edge model (ValueError for a name registered already, or a model switched to or
    from that is not a registered one's name)."""
    if model.name in EDGE_MODELS:
        raise ValueError(f"edge model {model.name!r} is registered already")
    if model.contact == (model.of is not None):
        raise ValueError(f"edge model {model.name!r}: a scene's contact model has no 'of'; any other needs one")
    EDGE_MODELS[model.name] = model
    return model


def edge_model(name) -> EdgeModel:
    """The registered model ``name`` (a model is returned as it is); ValueError naming the
    known ones otherwise."""
    if isinstance(name, EdgeModel):
        return name
    try:
        return EDGE_MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"contact edge model must be one of {tuple(EDGE_MODELS)}; got {name!r}") from None


def contact_models() -> tuple:
    """The names of the scene's contact models (``Scene(contact=...)``, ``--contact``), in the
    order registered."""
    return tuple(n for n, m in EDGE_MODELS.items() if m.contact)


_CONTINUOUS = ("r continuous", "phi continuous", "z on the indenter")

register_edge_model(EdgeModel(
    "smooth", "variational, frictionless: stretch and curvature continuous, a ring force may push",
    _CONTINUOUS + ("lambda_s continuous", "kappa_s continuous"), contact=True, switches_to="corner",
    variational=True, point_load_limit=True, convexity_limit=True))
register_edge_model(EdgeModel(
    "corner", "Weierstrass-Erdmann corner past the smooth edge's convexity limit: lambda_s and kappa_s jump",
    _CONTINUOUS + ("[tau_s] + kappa_s^c [M_s] = 0 (sliding)", "[lambda_s dU/dlambda_s - U] = 0 (Eshelby)"),
    of="smooth", variational=True, jumps=True))
register_edge_model(EdgeModel(
    "paper", "the paper's eq. jumpeqns2: Q and tau_s continuous, kappa_s (and lambda_s) free to jump",
    _CONTINUOUS + ("Q continuous (no ring force)", "tau_s continuous"), contact=True, switches_to="pinned"))
register_edge_model(EdgeModel(
    "pinned", "the paper's edge held at the tip's end: the indenter pushes its circle (a ring force)",
    _CONTINUOUS + ("omega = omega_max (at the tip's end)", "tau_s continuous"), of="paper",
    held_at_tip_end=True))
