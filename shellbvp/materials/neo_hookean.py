"""The neo-Hookean material."""

from __future__ import annotations

from dataclasses import dataclass

from .base import Material, register_material

__all__ = ["NeoHookean"]


@register_material
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
    label, short_label = "neo-Hookean", "NH"

    @staticmethod
    def energy():
        from symbolic.materials import neo_hookean

        return neo_hookean()

    def felupe_model(self, fem):
        return fem.NeoHooke(mu=1.0)
