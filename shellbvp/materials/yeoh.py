"""The Yeoh material: a cubic in ``I1 - 3`` that stiffens at large strain."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Material, Parameter, register_material

__all__ = ["Yeoh"]


@register_material
@dataclass(frozen=True)
class Yeoh(Material):
    """Yeoh, ``W = [(I1-3) + c2 (I1-3)^2 + c3 (I1-3)^3]/2``.

    Yeoh's energy ``C10 (I1-3) + C20 (I1-3)^2 + C30 (I1-3)^3`` (O. H. Yeoh, Rubber Chem.
    Technol. 66 (1993) 754) in units of its small-strain shear modulus ``mu = 2 C10`` (as
    FElupe's ``constitution.tensortrax.models.hyperelastic.yeoh`` states it, FElupe 11.3):
    ``c2 = C20/C10``, ``c3 = C30/C10``.  ``c2 = c3 = 0`` is neo-Hookean.

    Parameters
    ----------
    c2, c3 : float
        >= 0.  Then ``dW/dI1 = [1 + 2 c2 (I1-3) + 3 c3 (I1-3)^2]/2 >= 1/2`` and
        ``d2W/dI1^2 >= 0`` at every ``I1 >= 3`` (every incompressible deformation), which
        makes an energy of ``I1`` alone strongly elliptic at every stretch, not only in the
        range a curve reaches.  Fits of rubbers often give ``C20 < 0`` (softening at moderate
        strain); such an energy loses ellipticity at large enough strain and is refused.

    Examples
    --------
    >>> import shellbvp as sb
    >>> sb.Scene.preset("base", material=sb.Yeoh(c2=0.1, c3=0.01)).material.values()
    {'c2': 0.1, 'c3': 0.01}
    >>> sb.Yeoh(c2=-0.1).validate()
    Traceback (most recent call last):
    ...
    ValueError: c2 (Yeoh) must be a finite number >= 0; got -0.1
    """

    c2: float = 0.0
    c3: float = 0.0
    family = "yeoh"
    label, short_label = "Yeoh", "Yeoh"
    parameters = (Parameter("c2", 0.0, help="C20/C10", assumption="nonnegative"),
                  Parameter("c3", 0.0, help="C30/C10", assumption="nonnegative"))

    @staticmethod
    def energy(c2, c3):
        from symbolic.materials import first_invariant

        x = first_invariant() - 3
        return (x + c2 * x**2 + c3 * x**3) / 2

    def felupe_model(self, fem):
        import felupe.constitution.tensortrax as mat

        return mat.Hyperelastic(mat.models.hyperelastic.yeoh, C10=0.5, C20=float(self.c2) / 2,
                                C30=float(self.c3) / 2)
