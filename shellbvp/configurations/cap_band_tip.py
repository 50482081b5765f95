"""A cap and, beyond a lifted gap, a band of contact on the tip (family ``split``)."""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Point, Region, Rim
from .registry import Configuration, without_edge_model

__all__ = ["cap_band_tip_chain"]

ORDER = 60


def cap_band_tip_chain(eps: float, L: float) -> Chain:
    """A cap and, beyond a lifted gap, a band of contact on the tip: tip [zeta, Sc], free [Sc, S1],
    tip [S1, S2], free [S2, L]; unknowns ln Sc, ln S1, ln S2."""
    Sc, S1, S2 = Point("Sc", "ln_Sc"), Point("S1", "ln_S1"), Point("S2", "ln_S2")
    return Chain("cap+band(tip)", (Region("contact", Point("zeta", "ln_Sc", math.log(eps)), Sc),
                                   Region("free", Sc, S1), Region("contact", S1, S2),
                                   Region("free", S2, Point("L", None, math.log(L)))),
                 (ContactPole(0), Edge(0, 1), Edge(2, 1), Edge(2, 3), Rim(3)), ("ln_Sc", "ln_S1", "ln_S2"), eps)


CONFIGURATIONS = (
    Configuration("cap+band(tip)", "split", without_edge_model(cap_band_tip_chain), contacts=("smooth",)),
)
