"""Dimensional layer: nondimensional (delta, F) <-> SI, and unit strings.

Lengths scale with the rim radius ``R_L``, forces with ``mu H R_L``:
``delta_SI = R_L delta``, ``F_SI = mu_H R_L F`` (``mu_H`` = shear modulus times
thickness, N/m = um*MPa).  A linearly elastic sheet of thickness H has
``beta = (H/R_L)^2 / 12``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

__all__ = ["Dimensions", "parse_quantity", "unit_factor", "beta_from_thickness", "plain_number", "PLAIN_NUMBER",
           "LENGTH_UNITS", "FORCE_UNITS"]

#: A number as a person or a CSV writes it: ASCII digits, optional sign, decimal point and
#: exponent.  Python's float() also takes "5_0", "inf", "nan", "1e999" and non-ASCII digits.
PLAIN_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")

LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6, "nm": 1e-9, "cm": 1e-2}
FORCE_UNITS = {"N": 1.0, "mN": 1e-3, "uN": 1e-6, "µN": 1e-6, "nN": 1e-9, "kN": 1e3}


def unit_factor(unit: str, kind: str) -> float:
    """SI factor of a length ('length') or force ('force') unit name."""
    table = LENGTH_UNITS if kind == "length" else FORCE_UNITS
    u = unit.strip()
    if u not in table:
        raise ValueError(f"unknown {kind} unit {unit!r}; use one of {', '.join(table)}")
    return table[u]


def plain_number(text: str, name: str = "value") -> float:
    """A finite float from plain decimal text; ValueError naming ``name`` otherwise."""
    t = str(text).strip()
    if not PLAIN_NUMBER.fullmatch(t) or not math.isfinite(v := float(t)):
        raise ValueError(f"{name} must be a plain finite number (e.g. 0.25 or 1e-3); got {text!r}")
    return v


def parse_quantity(text, kind: str = "length", default_unit: str | None = None) -> float:
    """A length or force with its unit, in SI units.

    Parameters
    ----------
    text : str or float
        A number and a unit, e.g. ``"0.3mm"``, ``"0.3 mm"``, ``"15uN"``; a number
        alone (str or float) is in ``default_unit``.
    kind : {"length", "force"}
        Which units are accepted (:data:`LENGTH_UNITS`, :data:`FORCE_UNITS`).
    default_unit : str, optional
        The unit of a bare number (default: SI, m or N).

    Returns
    -------
    float
        The value in metres or newtons.

    Raises
    ------
    ValueError
        For text that is not a number and a unit, or an unknown unit.

    Examples
    --------
    >>> from shellbvp import parse_quantity
    >>> parse_quantity("0.3mm")
    0.0003
    >>> round(parse_quantity("15 uN", kind="force"), 12)
    1.5e-05
    >>> parse_quantity(300, default_unit="um")
    0.0003
    """
    if isinstance(text, (int, float)):
        v = float(text)
        return v * (unit_factor(default_unit, kind) if default_unit else 1.0)
    m = re.fullmatch(r"\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*([A-Za-zµ]*)\s*", str(text))
    if not m:
        raise ValueError(f"cannot read {text!r} as a {kind} (e.g. 0.3mm)")
    value, unit = float(m.group(1)), m.group(2)
    if unit:
        return value * unit_factor(unit, kind)
    return value * (unit_factor(default_unit, kind) if default_unit else 1.0)


def beta_from_thickness(H: float, R_L: float) -> float:
    """The bending stiffness of a shell of thickness H: ``beta = (H/R_L)^2/12``.

    The paper's relation for an incompressible, linearly elastic sheet; a
    starting value when the thickness is known.

    Parameters
    ----------
    H : float
        Shell thickness (any length unit).
    R_L : float
        Rim radius, in the same unit as H.

    Returns
    -------
    float
        beta, nondimensional.

    Examples
    --------
    >>> from shellbvp import beta_from_thickness
    >>> round(beta_from_thickness(H=50e-6, R_L=0.3e-3), 6)   # a 50 um endosperm, R_L = 0.3 mm
    0.002315
    """
    for name, v in (("H", H), ("R_L", R_L)):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite length > 0; got {v!r}")
    return (H / R_L) ** 2 / 12


@dataclass(frozen=True)
class Dimensions:
    """Rim radius ``R_L`` (m) and ``mu_H`` (N/m) of an experiment: SI <-> nondimensional.

    Lengths scale with ``R_L``, forces with ``mu_H * R_L``.

    Parameters
    ----------
    R_L : float
        Rim radius of the sample, m (> 0).
    mu_H : float
        Shear modulus times thickness, N/m (= um*MPa; > 0).

    Examples
    --------
    >>> from shellbvp import Dimensions
    >>> dims = Dimensions(R_L=0.3e-3, mu_H=52.0)
    >>> round(float(dims.displacement(0.5)), 8)      # delta = 0.5 -> metres
    0.00015
    >>> round(float(dims.force(1.0)), 6)             # F = 1 -> newtons
    0.0156
    >>> round(float(dims.F(dims.force(0.7))), 12)
    0.7
    """

    R_L: float
    mu_H: float = 1.0

    def __post_init__(self):
        for name in ("R_L", "mu_H"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0; got {v!r}")

    def displacement(self, delta):
        """Nondimensional delta -> metres."""
        return self.R_L * delta

    def force(self, F):
        """Nondimensional F -> newtons."""
        return self.mu_H * self.R_L * F

    def delta(self, displacement):
        """Metres -> nondimensional delta."""
        return displacement / self.R_L

    def F(self, force):
        """Newtons -> nondimensional F."""
        return force / (self.mu_H * self.R_L)
