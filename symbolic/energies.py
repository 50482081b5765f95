"""The strain and bending energies the derivation knows, by family name.

A family (``"gent"``, ``"trace"``, ...) maps to a function of the structure description's
``material`` (or ``bending``) entry that returns the energy as a SymPy expression.  The
families register themselves from ``shellbvp.materials`` (one module per material: its
run-time class, its formula, its parameters; issue 43, item 5), and the derivation
(``symbolic.build``) looks them up here.  So ``symbolic`` never imports ``shellbvp``: the
package imports the derivation, not the other way round, and the derivation stays usable
and testable by itself.  Free of imports, like ``symbolic.version``: registering a family
while ``shellbvp`` loads costs no SymPy.
"""

from __future__ import annotations

__all__ = ["register_strain_energy", "register_bending_energy", "strain_energy", "bending_energy",
           "STRAIN_ENERGIES", "BENDING_ENERGIES"]

#: family -> function(material description) -> (W, the run-time parameter symbols in order)
STRAIN_ENERGIES: dict = {}
#: family -> function(bending description) -> B, or None for the trace energy the equations
#: hold themselves
BENDING_ENERGIES: dict = {}


def register_strain_energy(family: str, formula) -> None:
    """Register ``formula(description) -> (W, params)`` under ``family`` (once)."""
    if STRAIN_ENERGIES.get(family, formula) is not formula:
        raise ValueError(f"material family {family!r} is registered twice")
    STRAIN_ENERGIES[family] = formula


def register_bending_energy(family: str, formula) -> None:
    """Register ``formula(description) -> B`` under ``family`` (once)."""
    if BENDING_ENERGIES.get(family, formula) is not formula:
        raise ValueError(f"bending family {family!r} is registered twice")
    BENDING_ENERGIES[family] = formula


def _lookup(table, kind, description):
    family = description["family"]
    if family not in table:
        raise ValueError(f"unknown {kind} family {family!r} (known: {', '.join(sorted(table))}; "
                         f"families register when shellbvp.materials is imported)")
    return table[family](description)


def strain_energy(description: dict):
    """(W, parameter symbols) of a material description ``{"family": ..., ...}``."""
    return _lookup(STRAIN_ENERGIES, "material", description)


def bending_energy(description: dict):
    """B of a bending description, or None for the paper's trace energy."""
    return _lookup(BENDING_ENERGIES, "bending", description)
