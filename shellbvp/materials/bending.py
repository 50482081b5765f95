"""The bending energies: the paper's trace energy, the rotation energy, Koiter's and a user formula."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Bending, register_bending

__all__ = ["TraceBending", "RotationBending", "KoiterBending", "BendingEnergy"]


@register_bending
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
    plate_stiffness, plate_poisson = 1.0, 1.0  # symbolic.bending.plate_limit (tests/test_fe.py derives them)

    @staticmethod
    def bending_energy(description):
        return None  # the equations' own (symbolic.equations)


@register_bending
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
    plate_stiffness, plate_poisson = 1.0, 1.0

    @staticmethod
    def bending_energy(description):
        from symbolic.bending import rotation_bending

        return rotation_bending()


@register_bending
@dataclass(frozen=True)
class KoiterBending(Bending):
    """Koiter's bending energy at the incompressible solid's Poisson ratio 1/2:
    ``B = (Ds + Dt)^2/2 - Ds Dt/2`` with ``Ds = lambda_s^2 kappa_s - kappa_s0`` and
    ``Dt = lambda_theta^2 kappa_theta - kappa_theta0``, the trace energy less half the product
    of the two bending strains.

    For a flat plate this is Kirchhoff's ``D/2 [(k1 + k2)^2 - 2 (1 - nu) k1 k2]`` at nu = 1/2,
    the Poisson ratio a 3D incompressible plate bends with; the trace energy is the same at
    nu = 1 and leaves out the energy of the Gaussian curvature.  That term matters where the
    wall's thickness changes along the meridian (a disk thickening to twice its thickness
    stiffens 1.97 times in the 3D solid and with this energy, 1.60 times with the trace energy)
    and at a simply supported edge; elsewhere the two agree within a few percent.  Same
    stiffness as the trace energy, so ``beta = (H/R_L)^2/3`` stays.  Koiter's energy
    ``nu (tr Delta)^2/2 + (1 - nu) tr(Delta^2)/2`` of the bending strain ``Delta = A^{-1} (b - b0)``
    (W. T. Koiter, On the nonlinear theory of thin elastic shells, Proc. Kon. Ned. Akad.
    Wetensch. B 69, 1966); ``sb.stability`` derives its second variation.  Like the trace
    energy it is not convex in the meridional stretch and curvature at large bending (a corner
    at the contact edge past that limit; ``sb.convexity_limits``).

    Examples
    --------
    >>> import shellbvp as sb
    >>> b = sb.KoiterBending()
    >>> b.description(), b.plate_stiffness, b.plate_poisson
    ({'family': 'koiter'}, 1.0, 0.5)
    >>> wall = sb.ThicknessProfile.formula("0.025*(1 + S/L)")
    >>> round(sb.Scene.preset("base", thickness=wall, bending=b).beta, 8)   # (H0/R_L)^2/3
    0.00020833
    """

    family = "koiter"
    plate_stiffness, plate_poisson = 1.0, 0.5  # symbolic.bending.plate_limit (tests/test_fe.py derives them)

    @staticmethod
    def bending_energy(description):
        from symbolic.bending import koiter_bending

        return koiter_bending()


@register_bending
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
    formula_sets_plate_limit = True
    cli = False  # given by --bending-formula

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

    @classmethod
    def from_data(cls, read):
        return cls(read("B", (str,)))

    @staticmethod
    def bending_energy(description):
        """B read back from the description's text (never evaluated as code)."""
        from symbolic.bending import BENDING_SYMBOLS
        from symbolic.formula import parse_formula

        return parse_formula(description["B"], BENDING_SYMBOLS, name="B", legacy_srepr=True)

    def __repr__(self):
        return f"BendingEnergy({str(self.B)!r}, name={self.name!r})"

    def __eq__(self, other):
        return isinstance(other, BendingEnergy) and self.description() == other.description()

    def __hash__(self):
        return hash(str(self.description()))
