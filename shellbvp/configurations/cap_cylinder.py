"""Contact running from the pole past the tip's end onto the indenter's cylinder (family
``wall``), under either contact model."""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Point, Region, Rim, TipEnd
from .registry import Configuration, Switch

__all__ = ["cylinder_chain"]

ORDER = 90


def cylinder_chain(eps: float, L: float, model: str = "smooth") -> Chain:
    """Contact running past the tip's end onto the cylinder: tip [zeta, S*], cylinder [S*, Sc],
    free [Sc, L]; unknowns ln S*, ln Sc."""
    Se, Sc = Point("S*", "ln_Send"), Point("Sc", "ln_Sc")
    return Chain("cap+cylinder", (Region("contact", Point("zeta", "ln_Send", math.log(eps)), Se),
                                  Region("cylinder", Se, Sc), Region("free", Sc, Point("L", None, math.log(L)))),
                 (ContactPole(0), TipEnd(0), Edge(1, 2, model), Rim(2)), ("ln_Send", "ln_Sc"), eps)


CONFIGURATIONS = (
    Configuration("cap+cylinder", "wall", cylinder_chain, askable=True, needs_tip_end=True),
)
SWITCHES = (
    # the free shell reaches the cylinder (or the contact the tip's end)
    Switch(frozenset({"cap", "cap+cylinder"}), "cap", ("wall_gap", "tip_end_margin")),
)
