"""Strain- and bending-energy choices a scene can make (formulas live in ``symbolic.materials``
and ``symbolic.bending``).

Built-in families are described by name, so that loading their cached
generated code does not import SymPy; a user energy carries its formula.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Material", "MooneyRivlin", "NeoHookean", "Gent", "StrainEnergy", "Bending", "TraceBending",
           "RotationBending", "BendingEnergy"]


class Material:
    """Base class: ``description()`` (structural, hashed) and ``values()`` (run-time)."""

    family: str = ""

    def description(self) -> dict:
        """The structural choice (family, a user formula): what generated code is keyed on."""
        return {"family": self.family}

    def values(self) -> dict:
        """Run-time parameters by name (alpha, Jm): they change no generated code."""
        return {}

    def validate(self) -> None:
        """ValueError naming the parameter when it is out of range."""
        pass


@dataclass(frozen=True)
class MooneyRivlin(Material):
    """Mooney–Rivlin, ``W = [(1-alpha)(I1-3) + alpha(I2-3)]/2``.

    Parameters
    ----------
    alpha : float
        In [0, 1]; 0 is neo-Hookean (computed with the Mooney–Rivlin code; use
        :class:`NeoHookean` for code without alpha terms).

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene(material=sb.MooneyRivlin(alpha=0.5)).material.values()
    {'alpha': 0.5}
    >>> sb.MooneyRivlin(alpha=2).validate()
    Traceback (most recent call last):
    ...
    ValueError: alpha (Mooney-Rivlin) must be in [0, 1]; got 2
    """

    alpha: float = 0.1
    family = "mooney-rivlin"

    def values(self):
        return {"alpha": float(self.alpha)}

    def validate(self):
        a = self.alpha
        if isinstance(a, bool) or not (isinstance(a, (int, float)) and math.isfinite(a) and 0.0 <= a <= 1.0):
            raise ValueError(f"alpha (Mooney-Rivlin) must be in [0, 1]; got {a!r}")


@dataclass(frozen=True)
class NeoHookean(Material):
    """Neo-Hookean, ``W = (I1 - 3)/2`` (its own code: no alpha terms).

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene.preset("base", material=sb.NeoHookean()).material
    NeoHookean()
    """

    family = "neo-hookean"


@dataclass(frozen=True)
class Gent(Material):
    """Gent, ``W = -(Jm/2) log(1 - (I1-3)/Jm)``: stiffens as ``I1 - 3`` approaches Jm.

    Parameters
    ----------
    Jm : float
        > 0: rubbers 97.2 or 114, stiff biological tissue down to 0.4.

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene.preset("gent1").material
    Gent(Jm=1.0)
    """

    Jm: float = 97.2
    family = "gent"

    def values(self):
        return {"Jm": float(self.Jm)}

    def validate(self):
        j = self.Jm
        if isinstance(j, bool) or not (isinstance(j, (int, float)) and math.isfinite(j) and j > 0):
            raise ValueError(f"Jm (Gent) must be a finite number > 0; got {j!r}")


class StrainEnergy(Material):
    """A user strain energy ``W(lambda_s, lambda_theta)``.

    Parameters
    ----------
    W : str or sympy expression
        In the symbols ``lambda_s`` and ``lambda_theta`` (shear modulus 1 in the
        nondimensionalisation), parsed without evaluating code
        (``symbolic.formula``: numbers, ``+ - * / **``, sin, exp, log, sqrt, ...).  Checked on construction: symmetric,
        ``W(1,1) = 0``, stress-free at (1,1), positive small-strain shear
        modulus (reported as ``shear_modulus``; it should be 1, or forces are in
        units of that modulus times mu).
    name : str, optional
        Label for output files.

    Raises
    ------
    ValueError
        Naming the formula and the offending piece (a name, call or construct
        outside the whitelist), or the check that failed.

    Examples
    --------
    >>> import shellbvp as sb
    >>> W = sb.StrainEnergy("(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2")
    >>> W.shear_modulus                      # the neo-Hookean energy, written out
    1.0
    >>> sb.StrainEnergy("lambda_s**2 - 1")
    Traceback (most recent call last):
    ...
    ValueError: ...
    """

    family = "user"

    def __init__(self, W, name: str = "user", *, legacy_srepr: bool = False):
        from symbolic import materials as sm
        from symbolic.formula import evaluation_errors, formula_text, parse_formula

        with evaluation_errors("W"):
            expr = parse_formula(W, {"lambda_s": sm.LS, "lambda_theta": sm.LT}, name="W", legacy_srepr=legacy_srepr)
            self.shear_modulus = float(sm.check_energy(expr, name="W"))
        self.W = expr
        self.name = str(name)
        self._text = formula_text(expr)

    def description(self):
        """The family and the formula as plain text (what files store)."""
        return {"family": "user", "W": self._text}

    def __repr__(self):
        return f"StrainEnergy({str(self.W)!r}, name={self.name!r})"

    def __eq__(self, other):
        return isinstance(other, StrainEnergy) and self.description() == other.description()

    def __hash__(self):
        return hash(str(self.description()))


class Bending:
    """Base class of bending energies ``B`` (U = W + beta B; formulas in ``symbolic.bending``).

    ``plate_stiffness`` and ``plate_poisson``: B's small-strain plate limit,
    ``B ~ plate_stiffness/2 (kappa_s^2 + kappa_theta^2 + 2 plate_poisson kappa_s kappa_theta)``
    (``symbolic.bending.plate_limit``; a test derives the built-ins' values).
    """

    family: str = ""
    plate_stiffness: float = 1.0
    plate_poisson: float = 1.0

    def description(self) -> dict:
        """The structural choice (family, a user formula): what generated code is keyed on."""
        return {"family": self.family}


@dataclass(frozen=True)
class TraceBending(Bending):
    """The paper's bending energy, ``B = (tr Delta)^2/2`` with
    ``tr Delta = lambda_s^2 kappa_s + lambda_theta^2 kappa_theta - kappa_s0 - kappa_theta0``.

    Not convex in the meridional stretch and curvature at large bending: past that limit the
    contact edge becomes a corner (see the docs' known limits).

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene().bending
    TraceBending()
    """

    family = "trace"


@dataclass(frozen=True)
class RotationBending(Bending):
    """``B = (lambda_s kappa_s + lambda_theta kappa_theta - kappa_s0 - kappa_theta0)^2/2``: the change
    of the rotation gradients per reference length (``phi'/Psi`` and ``sin(phi)/R``), as in the
    axisymmetric shell theories built on the rotation angle (Libai & Simmonds 1998).  U is
    convex in (lambda_s, kappa_s) wherever W is convex in lambda_s; same small-strain
    stiffness as :class:`TraceBending`.

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene.preset("base", bending=sb.RotationBending()).bending.description()
    {'family': 'rotation'}
    """

    family = "rotation"


class BendingEnergy(Bending):
    """A user bending energy per unit beta, ``B(lambda_s, lambda_theta, kappa_s, kappa_theta)``.

    Parameters
    ----------
    B : str or sympy expression
        In ``lambda_s``, ``lambda_theta``, ``kappa_s``, ``kappa_theta`` and the reference shell's
        curvatures ``kappa_s0``, ``kappa_theta0``; parsed without evaluating code
        (``symbolic.formula``).  Checked: zero, moment-free and with a positive bending
        stiffness ``d2B/dkappa_s2`` (reported as ``stiffness``; 1 for the built-ins) in the
        reference state.
    name : str, optional

    Examples
    --------
    >>> import shellbvp as sb
    >>> b = sb.BendingEnergy("(lambda_s**2*kappa_s + lambda_theta**2*kappa_theta - kappa_s0 - kappa_theta0)**2/2")
    >>> b.stiffness
    1.0
    >>> sb.BendingEnergy("kappa_s**2")
    Traceback (most recent call last):
    ...
    ValueError: B must vanish in the reference state (lambda = 1, kappa = kappa_0); it is kappa_s0**2
    """

    family = "user"

    def __init__(self, B, name: str = "user", *, legacy_srepr: bool = False):
        from symbolic import bending as sbend
        from symbolic.formula import evaluation_errors, formula_text, parse_formula

        with evaluation_errors("B"):
            expr = parse_formula(B, sbend.BENDING_SYMBOLS, name="B", legacy_srepr=legacy_srepr)
            stiffness = sbend.check_bending(expr, name="B")
            plate_stiffness, plate_poisson = sbend.plate_limit(expr)
        if not (plate_stiffness.is_number and float(plate_stiffness) > 0 and plate_poisson.is_number):
            raise ValueError(f"B must bend a flat plate with a positive stiffness; its plate limit is "
                             f"d2B/dkappa_s2 = {plate_stiffness}")
        self.B = expr
        self.name = str(name)
        self.stiffness = float(stiffness) if stiffness.is_number else str(stiffness)
        self.plate_stiffness, self.plate_poisson = float(plate_stiffness), float(plate_poisson)
        self._text = formula_text(expr)

    def description(self):
        return {"family": "user", "B": self._text}

    def __repr__(self):
        return f"BendingEnergy({str(self.B)!r}, name={self.name!r})"

    def __eq__(self, other):
        return isinstance(other, BendingEnergy) and self.description() == other.description()

    def __hash__(self):
        return hash(str(self.description()))
