"""A closed shell on a substrate under a curved tip (family ``closed``): both halves in one
chain, each from its own pole to the equator where they meet (:class:`~shellbvp.chain.Seam`;
the lower half in the mirror image z -> -z).  Each half touches its indenter -- the tip above,
the plane below -- as a rimmed shell does: at a point (the point-load limit), with a cap from
its pole, or, its pole lifted, on a ring carrying a ring force or on an annulus
(:mod:`~shellbvp.configurations.point`, ``cap``, ``line``, ``annulus``): sixteen
configurations, ``closed-<upper>-<lower>``.

The lower half's junctions come first, so that a force control is the upper contact's; the
lower half's unknowns carry ``_b`` (``ln_Sb``, ``lambda0_b``, ``ln_S1_b``, ``chi1_b``,
``ln_S2_b``).  The substrate does not move: the lower half's conditions on it are evaluated
at delta = 0, so delta is the approach of tip and substrate.  :mod:`shellbvp.closed` solves
them.
"""

from __future__ import annotations

import math

from ..chain import Chain, ContactPole, Edge, FreePole, Line, Point, PointPole, Region, Seam
from .point import POINT_S0
from .registry import Configuration, without_edge_model

__all__ = ["closed_chain", "closed_name", "CONTACTS", "LOWER_NAMES"]

ORDER = 110

#: How each half touches its indenter (the topology of its rimmed counterpart)
CONTACTS = ("point", "cap", "line", "annulus")
#: A lower half's unknowns by their rimmed counterpart's names
LOWER_NAMES = {"ln_Sc": "ln_Sb", "lambda0": "lambda0_b", "ln_S1": "ln_S1_b", "chi1": "chi1_b", "ln_S2": "ln_S2_b"}


def closed_name(upper: str, lower: str) -> str:
    """The configuration's name for the upper and lower halves' contacts (each in CONTACTS)."""
    return f"closed-{upper}-{lower}"


def _name(name, lower):
    return LOWER_NAMES[name] if lower else name


def _half(contact, k, on, end, eps, lower):
    """(regions, junctions, unknowns) of one half from its pole (its first region ``k``)."""
    if contact == "point":
        return (Region("free", Point("s0", None, math.log(POINT_S0)), end),), (PointPole(k, not lower),), ()
    if contact == "cap":
        Sc = Point("Sc", _name("ln_Sc", lower))
        return ((Region(on, Point("zeta", Sc.unknown, math.log(eps)), Sc), Region("free", Sc, end)),
                (ContactPole(k, _name("lambda0", lower)), Edge(k, k + 1)), (Sc.unknown,))
    S1 = Point("S1", _name("ln_S1", lower))
    pole = Point("zeta", S1.unknown, math.log(eps))
    if contact == "line":
        return ((Region("free", pole, S1), Region("free", S1, end)),
                (FreePole(k), Line(k, on, _name("chi1", lower))), (S1.unknown, _name("chi1", lower)))
    S2 = Point("S2", _name("ln_S2", lower))
    return ((Region("free", pole, S1), Region(on, S1, S2), Region("free", S2, end)),
            (FreePole(k), Edge(k + 1, k), Edge(k + 1, k + 2)), (S1.unknown, S2.unknown))


def closed_chain(upper: str, lower: str):
    """``chain(eps, L)`` of a closed shell whose upper half touches the tip by ``upper`` and lower
    half the plane by ``lower``."""
    def chain(eps: float, L: float) -> Chain:
        end = Point("L", None, math.log(L))
        ru, ju, uu = _half(upper, 0, "contact", end, eps, False)
        rl, jl, ul = _half(lower, len(ru), "plane", end, eps, True)
        seam = Seam(len(ru) - 1, len(ru) + len(rl) - 1)
        return Chain(closed_name(upper, lower), ru + rl, jl + ju + (seam,), uu + ul, eps)
    return chain


CONFIGURATIONS = tuple(
    Configuration(closed_name(u, l), "closed", without_edge_model(closed_chain(u, l)), contacts=("smooth",),
                  controls=("delta",) if u == "point" else ("delta", "force"))
    for u in CONTACTS for l in CONTACTS)
