"""The Mooney–Rivlin material (the paper's)."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Material, Parameter, register_material

__all__ = ["MooneyRivlin"]


@register_material
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
    label, short_label = "Mooney-Rivlin", "MR"
    parameters = (Parameter("alpha", 0.0, 1.0, help="weight of the second invariant", option="--alpha", fit=True,
                            sweep=True, uncertainty=True, per_pixel=True),)

    @staticmethod
    def energy(alpha):
        from symbolic.materials import mooney_rivlin

        return mooney_rivlin(alpha)

    def felupe_model(self, fem):
        import felupe.constitution.tensortrax as mat

        return mat.Hyperelastic(mat.models.hyperelastic.mooney_rivlin,
                                C10=(1 - float(self.alpha)) / 2, C01=float(self.alpha) / 2)
