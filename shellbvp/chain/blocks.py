"""The blocks a chain is declared with: its regions' kinds and states, the points that bound
them, the junctions between them, and :class:`Chain` (the stacked layout they make is described
in :mod:`shellbvp.chain`)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Point", "Region", "ContactPole", "FreePole", "PointPole", "Edge", "TipEnd", "Line", "Kink", "Rim",
           "Chain", "SIZES", "FREE_STATES", "CONTACT_STATES", "CONTACT_KINDS", "REGION_CODES"]

FREE_STATES = ("lt", "phiS", "ls", "ks", "rQ", "z")
CONTACT_STATES = ("chi", "ls")
SIZES = {"free": len(FREE_STATES), "contact": len(CONTACT_STATES), "cylinder": len(CONTACT_STATES)}
CONTACT_KINDS = ("contact", "cylinder")  # the shell on the tip; on the indenter's cylinder r = rho A(omega_max)
#: ``region`` codes of profiles: 0 on the tip, 1 free, 2 on the cylinder
REGION_CODES = {"contact": 0, "free": 1, "cylinder": 2}


@dataclass(frozen=True)
class Point:
    """A point on the S axis: ``ln S = ln_offset + p[unknown]``, or ``ln S = ln_offset`` if fixed."""

    name: str
    unknown: str | None = None
    ln_offset: float = 0.0


@dataclass(frozen=True)
class Region:
    kind: str  # "free" | "contact" (on the tip) | "cylinder" (on the indenter's side)
    start: Point
    end: Point


@dataclass(frozen=True)
class ContactPole:
    """Regular pole of a contact cap (region ``k`` starts at zeta): 2 rows, uses lambda0."""

    k: int
    rows = 2


@dataclass(frozen=True)
class FreePole:
    """Regular pole of a free cap (region ``k`` starts at zeta): 3 rows."""

    k: int
    rows = 3


@dataclass(frozen=True)
class PointPole:
    """Point-load pole of the free region ``k`` at its start s0: 3 rows, uses delta."""

    k: int
    rows = 3


@dataclass(frozen=True)
class Edge:
    """Contact edge between contact region ``kc`` and free region ``kf`` (adjacent): 5 rows.

    ``model`` is ``"smooth"`` (variational) or ``"paper"``; see SPEC section 2b.
    """

    kc: int
    kf: int
    model: str = "smooth"
    rows = 5


@dataclass(frozen=True)
class TipEnd:
    """The shell passes from the tip (region ``k``) onto the cylinder (region ``k + 1``): 3 rows.

    omega = omega_max at the end of one and the start of the other, and
    ``[lambda_s dU/dlambda_s - U] = 0`` (``symbolic.equations.Derivation._build_tip_end``).
    """

    k: int
    rows = 3


@dataclass(frozen=True)
class Line:
    """Line contact between free regions ``k`` and ``k + 1`` at the indenter point ``chi1``: 8 rows.

    r, phi, z on the indenter (3 rows, the smooth junction's first three; ``on`` the tip,
    ``"contact"``, or the cylinder, ``"cylinder"``); lt, phiS, ls, ks, z continuous (5);
    rQ jumps (the ring force).
    """

    k: int
    on: str = "contact"
    rows = 8


@dataclass(frozen=True)
class Kink:
    """Interior Weierstrass-Erdmann corner between free regions ``k`` and ``k + 1``: 7 rows.

    lt, phiS, rQ, z continuous (4); lambda_s and kappa_s jump with [tau_s] = [M_s] = 0 and the
    Eshelby condition [lambda_s dU/dlambda_s - U] = 0 (3, ``kink_res``).  Where U is convex
    the jump is 0 (the rows then hold for any S_k): only a state with a jump is a corner.
    """

    k: int
    rows = 7


@dataclass(frozen=True)
class Rim:
    """Simply supported rim at the end of region ``k``: 3 rows."""

    k: int
    rows = 3


@dataclass(frozen=True)
class Chain:
    """A contact configuration: regions pole to rim, junctions, unknowns of its own."""

    name: str
    regions: tuple
    junctions: tuple
    unknowns: tuple  # configuration unknowns (before lambda0, delta)
    eps: float | None = None  # pole start zeta = eps * (first contact or lift-off edge), if a regular pole

    def layout(self) -> str:
        """A table of the stacked layout (rows, S ranges, junction rows)."""
        lines, row = [f"{self.name}: y rows, t in [0, 1]"], 0
        for k, reg in enumerate(self.regions):
            n = SIZES[reg.kind]
            states = FREE_STATES if reg.kind == "free" else CONTACT_STATES
            lines.append(f"  y[{row}:{row + n}]  region {k} {reg.kind:<7s} S in [{reg.start.name}, {reg.end.name}]"
                         f"  ({', '.join(states)})")
            row += n
        lines.append("conditions:")
        r = 0
        for j in self.junctions:
            lines.append(f"  [{r}:{r + j.rows}]  {type(j).__name__}{_fields(j)}")
            r += j.rows
        return "\n".join(lines)


def _fields(j):
    return "(" + ", ".join(f"{k}={v!r}" for k, v in j.__dict__.items()) + ")"
