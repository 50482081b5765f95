"""A cap and, beyond a lifted gap, a line of contact on the tip (family ``split``)."""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Line, Point, Region, Rim
from .registry import Configuration, Switch, without_edge_model

__all__ = ["cap_line_tip_chain"]

ORDER = 50


def cap_line_tip_chain(eps: float, L: float) -> Chain:
    """A cap and, beyond a lifted gap, a line of contact on the tip: tip [zeta, Sc], free
    [Sc, S1], free [S1, L] with the line at S1 (on the tip); unknowns ln Sc, ln S1, chi1."""
    Sc, S1 = Point("Sc", "ln_Sc"), Point("S1", "ln_S1")
    return Chain("cap+line(tip)", (Region("contact", Point("zeta", "ln_Sc", math.log(eps)), Sc),
                                   Region("free", Sc, S1), Region("free", S1, Point("L", None, math.log(L)))),
                 (ContactPole(0), Edge(0, 1), Line(1, "contact"), Rim(2)), ("ln_Sc", "ln_S1", "chi1"), eps)


CONFIGURATIONS = (
    Configuration("cap+line(tip)", "split", without_edge_model(cap_line_tip_chain), contacts=("smooth",)),
)
SWITCHES = (
    # the cap's contact pressure at its edge: where the shell lifts off between two zones
    Switch(frozenset({"cap", "cap+line(tip)"}), "cap", ("pressure_min",)),
    # the lifted pole comes down onto the tip: a cap grows there
    Switch(frozenset({"line", "cap+line(tip)"}), "line", ("pole_clearance",)),
)
