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

__all__ = ["closed_chain", "closed_name", "CONTACTS", "HALVES", "LOWER_NAMES"]

ORDER = 110

#: A lower half's unknowns by their rimmed counterpart's names
LOWER_NAMES = {"ln_Sc": "ln_Sb", "lambda0": "lambda0_b", "ln_S1": "ln_S1_b", "chi1": "chi1_b", "ln_S2": "ln_S2_b"}


def closed_name(upper: str, lower: str) -> str:
    """The configuration's name for the upper and lower halves' contacts (each in CONTACTS)."""
    return f"closed-{upper}-{lower}"


def _name(name, lower):
    return LOWER_NAMES[name] if lower else name


def _point(k, on, end, eps, lower):
    """The point-load limit: the free shell from its pole (the substrate's pole does not move)."""
    return (Region("free", Point("s0", None, math.log(POINT_S0)), end),), (PointPole(k, not lower),), ()


def _cap(k, on, end, eps, lower):
    """A cap on the indenter from the pole, the free shell beyond it."""
    Sc = Point("Sc", _name("ln_Sc", lower))
    return ((Region(on, Point("zeta", Sc.unknown, math.log(eps)), Sc), Region("free", Sc, end)),
            (ContactPole(k, _name("lambda0", lower)), Edge(k, k + 1)), (Sc.unknown,))


def _line(k, on, end, eps, lower):
    """The pole lifted, a ring on the indenter carrying a ring force."""
    S1 = Point("S1", _name("ln_S1", lower))
    return ((Region("free", Point("zeta", S1.unknown, math.log(eps)), S1), Region("free", S1, end)),
            (FreePole(k), Line(k, on, _name("chi1", lower))), (S1.unknown, _name("chi1", lower)))


def _annulus(k, on, end, eps, lower):
    """The pole lifted, an annulus on the indenter."""
    S1, S2 = Point("S1", _name("ln_S1", lower)), Point("S2", _name("ln_S2", lower))
    return ((Region("free", Point("zeta", S1.unknown, math.log(eps)), S1), Region(on, S1, S2),
             Region("free", S2, end)), (FreePole(k), Edge(k + 1, k), Edge(k + 1, k + 2)), (S1.unknown, S2.unknown))


#: Each half's regions, junctions and unknowns from its pole, by how it touches its indenter (the
#: ``half`` of the rimmed configuration it matches); a half at a point has no force condition
HALVES = {"point": _point, "cap": _cap, "line": _line, "annulus": _annulus}
CONTACTS = tuple(HALVES)
_DELTA_ONLY = frozenset({"point"})


def closed_chain(upper: str, lower: str):
    """``chain(eps, L)`` of a closed shell whose upper half touches the tip by ``upper`` and lower
    half the plane by ``lower``; ``L``: both halves' meridians' ends, or ``(L_upper, L_lower)``
    where the halves differ (``UserShell.closed_halves``)."""
    def chain(eps: float, L) -> Chain:
        L_upper, L_lower = (L, L) if isinstance(L, (int, float)) else map(float, L)
        ru, ju, uu = HALVES[upper](0, "contact", Point("L", None, math.log(L_upper)), eps, False)
        rl, jl, ul = HALVES[lower](len(ru), "plane", Point("L_b" if L_lower != L_upper else "L", None,
                                                          math.log(L_lower)), eps, True)
        seam = Seam(len(ru) - 1, len(ru) + len(rl) - 1)
        return Chain(closed_name(upper, lower), ru + rl, jl + ju + (seam,), uu + ul, eps)
    return chain


def _parts(upper, lower):
    """(chain, contacts, controls) of the configuration touching by ``upper`` and ``lower``."""
    return (without_edge_model(closed_chain(upper, lower)), ("smooth",),
            ("delta",) if upper in _DELTA_ONLY else ("delta", "force"))


# every name written out, as the registry's other modules declare theirs (closed_name(u, l))
CONFIGURATIONS = (
    Configuration("closed-point-point", "closed", *_parts("point", "point")),
    Configuration("closed-point-cap", "closed", *_parts("point", "cap")),
    Configuration("closed-point-line", "closed", *_parts("point", "line")),
    Configuration("closed-point-annulus", "closed", *_parts("point", "annulus")),
    Configuration("closed-cap-point", "closed", *_parts("cap", "point")),
    Configuration("closed-cap-cap", "closed", *_parts("cap", "cap")),
    Configuration("closed-cap-line", "closed", *_parts("cap", "line")),
    Configuration("closed-cap-annulus", "closed", *_parts("cap", "annulus")),
    Configuration("closed-line-point", "closed", *_parts("line", "point")),
    Configuration("closed-line-cap", "closed", *_parts("line", "cap")),
    Configuration("closed-line-line", "closed", *_parts("line", "line")),
    Configuration("closed-line-annulus", "closed", *_parts("line", "annulus")),
    Configuration("closed-annulus-point", "closed", *_parts("annulus", "point")),
    Configuration("closed-annulus-cap", "closed", *_parts("annulus", "cap")),
    Configuration("closed-annulus-line", "closed", *_parts("annulus", "line")),
    Configuration("closed-annulus-annulus", "closed", *_parts("annulus", "annulus")),
)
