"""The blocks a chain is declared with: its regions' kinds and states, the points that bound
them, the junctions between them, and :class:`Chain` (the stacked layout they make is described
in :mod:`shellbvp.chain`)."""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..edge_models import EdgeModel, edge_model

__all__ = ["Point", "Region", "ContactPole", "FreePole", "PointPole", "Edge", "TipEnd", "Line", "Kink", "Rim",
           "Seam", "Chain", "SIZES", "FREE_STATES", "CONTACT_STATES", "CONTACT_KINDS", "REGION_CODES"]

FREE_STATES = ("lt", "phiS", "ls", "ks", "rQ", "z")
CONTACT_STATES = ("chi", "ls")
SIZES = {"free": len(FREE_STATES), "contact": len(CONTACT_STATES), "cylinder": len(CONTACT_STATES),
         "plane": len(CONTACT_STATES)}
#: the shell on the tip; on the indenter's cylinder r = rho A(omega_max); a closed shell's lower
#: half on the plane it rests on
CONTACT_KINDS = ("contact", "cylinder", "plane")
#: ``region`` codes of profiles: 0 on the tip, 1 free, 2 on the cylinder, 3 on the substrate
REGION_CODES = {"contact": 0, "free": 1, "cylinder": 2, "plane": 3}


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
    """Regular pole of a contact cap (region ``k`` starts at zeta): 2 rows, uses its stretch
    (``lambda0``; a closed shell's lower pole on the substrate, region kind ``plane``: its own,
    ``lambda0_b``)."""

    k: int
    stretch: str = "lambda0"
    rows = 2


@dataclass(frozen=True)
class FreePole:
    """Regular pole of a free cap (region ``k`` starts at zeta): 3 rows."""

    k: int
    rows = 3


@dataclass(frozen=True)
class PointPole:
    """Point-load pole of the free region ``k`` at its start s0: 3 rows, uses delta (a closed
    shell's lower pole on its substrate, which does not move: ``moving=False``, delta 0)."""

    k: int
    moving: bool = True
    rows = 3


@dataclass(frozen=True)
class Edge:
    """Contact edge between contact region ``kc`` and free region ``kf`` (adjacent): 5 rows.

    ``model``: its :class:`~shellbvp.edge_models.EdgeModel`, given by name (``"smooth"``,
    variational; ``"paper"``; ``"corner"``, ``"pinned"``; SPEC section 2b) or as the object.
    """

    kc: int
    kf: int
    model: EdgeModel = edge_model("smooth")
    rows = 5

    def __post_init__(self):
        object.__setattr__(self, "model", edge_model(self.model))


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
    ``"contact"``, the cylinder, ``"cylinder"``, or a closed shell's substrate, ``"plane"``);
    lt, phiS, ls, ks, z continuous (5);
    rQ jumps (the ring force).
    """

    k: int
    on: str = "contact"
    chi: str = "chi1"  # its unknown (a closed shell's lower ring on the plane: ``chi1_b``)
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
class Seam:
    """A closed shell's equator, where the end of its upper half's free region ``ku`` meets the
    end of its lower half's ``kl`` (each half running from its own pole, the lower in the
    mirror image z -> -z): r, z, the slope, lambda_s, kappa_s and the shear force continuous,
    6 rows, linear in the states (``lt``, ``ls``, ``ks`` equal; ``z``, ``rQ`` and the slopes'
    departures from the reference opposite).  Where the halves differ
    (``UserShell.closed_halves``: each its own module and L) their reference curvatures jump
    there: ``tau_s`` and ``M_s`` are continuous instead of ``ls`` and ``ks``."""

    ku: int
    kl: int
    rows = 6


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
    """A junction's fields, those at their defaults left out (the layouts of rimmed shells' chains
    read as before the fields closed shells added)."""
    shown = [f for f in fields(j) if getattr(j, f.name) != f.default]
    return "(" + ", ".join(f"{f.name}={getattr(j, f.name)!r}" for f in shown) + ")"
