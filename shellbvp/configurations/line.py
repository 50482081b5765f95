"""A lifted pole touching the tip on one circle (family ``lifted``): the free cap from a
regular pole, a line of contact carrying a ring force, the free shell to the rim."""

from __future__ import annotations

import math

from ..chain import Chain, FreePole, Line, Point, Region, Rim
from .registry import Configuration, Switch, without_edge_model

__all__ = ["line_chain"]

ORDER = 30


def line_chain(eps: float, L: float) -> Chain:
    """Lifted pole, contact on one circle S1: free [zeta, S1], free [S1, L]; unknowns ln S1, chi1."""
    S1 = Point("S1", "ln_S1")
    return Chain("line", (Region("free", Point("zeta", "ln_S1", math.log(eps)), S1),
                          Region("free", S1, Point("L", None, math.log(L)))),
                 (FreePole(0), Line(0), Rim(1)), ("ln_S1", "chi1"), eps)


CONFIGURATIONS = (
    Configuration("line", "lifted", without_edge_model(line_chain), contacts=("smooth",), askable=True,
                  line_contact=True, pole_branch_end=True, half="line"),
)
SWITCHES = (
    # the cap's contact pressure at its edge: where the pole lifts off
    Switch(frozenset({"cap", "line"}), "cap", ("pressure_min",)),
)
