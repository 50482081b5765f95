"""The Gent material (limiting chain extensibility)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Material, Parameter, register_material

__all__ = ["Gent"]


@register_material
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
    label, short_label = "Gent", "Gent"
    parameters = (Parameter("Jm", 0.0, low_open=True, help="the limit of I1 - 3", option="--gent-jm",
                            option_help="Gent model with this Jm (> 0)", sweep=True),)

    @staticmethod
    def energy(Jm):
        from symbolic.materials import gent

        return gent(Jm)

    def felupe_model(self, fem):
        import felupe.constitution.tensortrax as mat

        return mat.Hyperelastic(gent_3d, Jm=float(self.Jm))


def gent_3d(C, Jm):
    """Gent's energy on the isochoric first invariant, as the shell model's (shear modulus 1)."""
    from tensortrax.math import log, trace
    from tensortrax.math.linalg import det

    I1 = det(C) ** (-1 / 3) * trace(C)
    return -Jm / 2 * log(1 - (I1 - 3) / Jm)
