"""A lifted pole touching the tip on an annulus (family ``lifted``): the free cap from a
regular pole, a contact region between an inner edge S1 and an outer edge S2, the free
shell to the rim."""

from __future__ import annotations

import math

from ..chain import Chain, Edge, FreePole, Point, Region, Rim
from .registry import Configuration, Switch, without_edge_model

__all__ = ["annulus_chain"]

ORDER = 40


def annulus_chain(eps: float, L: float) -> Chain:
    """Lifted pole, contact on an annulus: free [zeta, S1], contact [S1, S2], free [S2, L]."""
    S1, S2 = Point("S1", "ln_S1"), Point("S2", "ln_S2")
    return Chain("annulus", (Region("free", Point("zeta", "ln_S1", math.log(eps)), S1), Region("contact", S1, S2),
                             Region("free", S2, Point("L", None, math.log(L)))),
                 (FreePole(0), Edge(1, 0), Edge(1, 2), Rim(2)), ("ln_S1", "ln_S2"), eps)


CONFIGURATIONS = (
    Configuration("annulus", "lifted", without_edge_model(annulus_chain), contacts=("smooth",), askable=True,
                  inner_edge=True, pole_branch_end=True, half="annulus"),
)
SWITCHES = (
    # the cap's contact pressure at its edge: where the pole lifts off
    Switch(frozenset({"cap", "annulus"}), "cap", ("pressure_min",)),
    # the line's curvature reaches the indenter's: the line opens into an annulus
    Switch(frozenset({"line", "annulus"}), "line", ("curvature_excess",), -1.0),
)
