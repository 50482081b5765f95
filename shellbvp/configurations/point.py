"""The point-load limit: no contact region, the free shell from a point at the pole
(``shellbvp.pointload`` solves it; family ``point``)."""

from __future__ import annotations

import math

from ..chain import Chain, Point, PointPole, Region, Rim
from .registry import Configuration

__all__ = ["point_chain", "POINT_S0"]

ORDER = 20
#: Start of the point-load state's free region (its own eps; truncation error O(s0^2 ln^2 s0)).
POINT_S0 = 1e-12


def point_chain(s0: float, L: float) -> Chain:
    """Point-load limit: the free region on [s0, L] alone."""
    return Chain("point", (Region("free", Point("s0", None, math.log(s0)), Point("L", None, math.log(L))),),
                 (PointPole(0), Rim(0)), ())


CONFIGURATIONS = (
    Configuration("point", "point", lambda eps, L, edge: point_chain(POINT_S0, L), controls=("delta",), half="point"),
)
