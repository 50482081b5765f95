"""A cap on the tip and the free shell touching the indenter's cylinder on one circle
(family ``wall``)."""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Line, Point, Region, Rim
from .registry import Configuration, Switch

__all__ = ["cap_line_cylinder_chain"]

ORDER = 70


def cap_line_cylinder_chain(eps: float, L: float, model: str = "smooth") -> Chain:
    """A cap on the tip and the free shell touching the cylinder on one circle S1: tip
    [zeta, Sc], free [Sc, S1], free [S1, L]; unknowns ln Sc, ln S1, chi1 (the wall point touched)."""
    Sc, S1 = Point("Sc", "ln_Sc"), Point("S1", "ln_S1")
    return Chain("cap+line(cylinder)", (Region("contact", Point("zeta", "ln_Sc", math.log(eps)), Sc),
                                        Region("free", Sc, S1), Region("free", S1, Point("L", None, math.log(L)))),
                 (ContactPole(0), Edge(0, 1, model), Line(1, "cylinder"), Rim(2)), ("ln_Sc", "ln_S1", "chi1"), eps)


CONFIGURATIONS = (
    Configuration("cap+line(cylinder)", "wall", cap_line_cylinder_chain, contacts=("smooth",), askable=True,
                  needs_tip_end=True),
)
SWITCHES = (
    # the free shell reaches the cylinder (or the contact the tip's end)
    Switch(frozenset({"cap", "cap+line(cylinder)"}), "cap", ("wall_gap", "tip_end_margin")),
)
