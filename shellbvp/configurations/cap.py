"""The single cap: one contact region from the pole, the free shell beyond it to the rim.

The state every other configuration is searched from (family ``cap``), under every contact
model and control.
"""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, Point, Region, Rim
from .registry import Configuration

__all__ = ["cap_chain"]

ORDER = 10


def cap_chain(eps: float, L: float, model: str = "smooth") -> Chain:
    """Single contact cap: contact [zeta, Sc], free [Sc, L]; unknown ln Sc."""
    Sc = Point("Sc", "ln_Sc")
    return Chain("cap", (Region("contact", Point("zeta", "ln_Sc", math.log(eps)), Sc),
                         Region("free", Sc, Point("L", None, math.log(L)))),
                 (ContactPole(0), Edge(0, 1, model), Rim(1)), ("ln_Sc",), eps)


CONFIGURATIONS = (
    Configuration("cap", "cap", cap_chain, controls=("delta", "force", "lambda0", "arclength"), askable=True,
                  half="cap"),
)
