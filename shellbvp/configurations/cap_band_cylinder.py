"""A cap on the tip and a band of contact on the indenter's cylinder (family ``wall``)."""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Point, Region, Rim
from .registry import Configuration, Switch

__all__ = ["cap_band_cylinder_chain"]

ORDER = 80


def cap_band_cylinder_chain(eps: float, L: float, model: str = "smooth") -> Chain:
    """A cap on the tip and a band of contact on the cylinder: tip [zeta, Sc], free [Sc, S1],
    cylinder [S1, S2], free [S2, L]; unknowns ln Sc, ln S1, ln S2."""
    Sc, S1, S2 = Point("Sc", "ln_Sc"), Point("S1", "ln_S1"), Point("S2", "ln_S2")
    return Chain("cap+band(cylinder)", (Region("contact", Point("zeta", "ln_Sc", math.log(eps)), Sc),
                                        Region("free", Sc, S1), Region("cylinder", S1, S2),
                                        Region("free", S2, Point("L", None, math.log(L)))),
                 (ContactPole(0), Edge(0, 1, model), Edge(2, 1, model), Edge(2, 3, model), Rim(3)),
                 ("ln_Sc", "ln_S1", "ln_S2"), eps)


CONFIGURATIONS = (
    Configuration("cap+band(cylinder)", "wall", cap_band_cylinder_chain, contacts=("smooth",), askable=True,
                  needs_tip_end=True),
)
SWITCHES = (
    # the free shell reaches the cylinder (or the contact the tip's end)
    Switch(frozenset({"cap", "cap+band(cylinder)"}), "cap", ("wall_gap", "tip_end_margin")),
    # the line on the cylinder opens into a band
    Switch(frozenset({"cap+line(cylinder)", "cap+band(cylinder)"}), "cap+line(cylinder)", ("curvature_excess",),
           -1.0),
)
