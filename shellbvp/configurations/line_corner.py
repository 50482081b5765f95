"""A lifted pole whose free cap has an interior Weierstrass-Erdmann corner, and a line of
contact (family ``lifted``): declared and checked, not searched (docs/limits-derivations.md)."""

from __future__ import annotations

import math

from ..chain import Chain, FreePole, Kink, Line, Point, Region, Rim
from .registry import Configuration, without_edge_model

__all__ = ["line_kink_chain"]

ORDER = 100


def line_kink_chain(eps: float, L: float) -> Chain:
    """Lifted pole, an interior corner at S_k, contact on one circle S1: free [zeta, S_k],
    free [S_k, S1], free [S1, L]; unknowns ln S_k, ln S1, chi1."""
    Sk, S1 = Point("Sk", "ln_Sk"), Point("S1", "ln_S1")
    return Chain("line+corner", (Region("free", Point("zeta", "ln_Sk", math.log(eps)), Sk), Region("free", Sk, S1),
                                 Region("free", S1, Point("L", None, math.log(L)))),
                 (FreePole(0), Kink(0), Line(1), Rim(2)), ("ln_Sk", "ln_S1", "chi1"), eps)


CONFIGURATIONS = (
    Configuration("line+corner", "lifted", without_edge_model(line_kink_chain), contacts=("smooth",)),
)
