"""Dimensional layer: nondimensional (delta, F) <-> SI, and unit strings.

Lengths scale with the rim radius ``R_L``, forces with ``mu H R_L``:
``delta_SI = R_L delta``, ``F_SI = mu_H R_L F`` (``mu_H`` = shear modulus times
thickness, N/m = um*MPa).  A shell of thickness H bends as a 3D plate of an
incompressible solid (``D = mu H^3/3``) with ``beta = (H/R_L)^2 / 3``
(:func:`beta_from_thickness`).
"""

from __future__ import annotations

import functools
import math
import numbers
import re
from dataclasses import dataclass

__all__ = ["Dimensions", "parse_quantity", "unit_factor", "unit_kind", "normalize_unit", "format_in",
           "beta_from_thickness", "plain_number", "parse_uncertain", "PLAIN_NUMBER", "PLUS_MINUS", "LENGTH_UNITS",
           "FORCE_UNITS", "TIME_UNITS", "MU_H_UNITS", "PRESSURE_UNITS", "UNIT_TABLES", "SI_UNITS", "split_quantity",
           "Quantity", "force_unit_of", "readable_unit"]

#: A number as a person or a CSV writes it: ASCII digits, optional sign, decimal point and
#: exponent.  Python's float() also takes "5_0", "inf", "nan", "1e999" and non-ASCII digits.
PLAIN_NUMBER = re.compile(r"[-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")
#: The separator of a value and its standard uncertainty: ``2.5+-0.2``, ``2.5+/-0.2``, ``2.5±0.2``
PLUS_MINUS = re.compile(r"\+-|\+/-|±")

#: SI factors of unit names (the micro sign: ``u``, U+00B5 or U+03BC; see :func:`normalize_unit`).
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "micron": 1e-6, "nm": 1e-9}
FORCE_UNITS = {"kN": 1e3, "N": 1.0, "mN": 1e-3, "uN": 1e-6, "µN": 1e-6, "nN": 1e-9, "pN": 1e-12}
TIME_UNITS = {"h": 3600.0, "min": 60.0, "s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}
#: mu*H is a force per length: N/m (= um*MPa = mN/mm = uN/um).
MU_H_UNITS = {"N/m": 1.0, "mN/m": 1e-3, "kN/m": 1e3, "mN/mm": 1.0, "uN/um": 1.0, "µN/µm": 1.0, "nN/nm": 1.0,
              "um*MPa": 1.0, "µm*MPa": 1.0, "mm*kPa": 1.0, "kPa*mm": 1.0, "MPa*um": 1.0, "MPa*µm": 1.0}
#: Pressures (turgor, inflation): Pa and its multiples, bar.
PRESSURE_UNITS = {"Pa": 1.0, "hPa": 1e2, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "bar": 1e5, "mbar": 1e2}
#: The unit table of each kind of quantity.
UNIT_TABLES = {"length": LENGTH_UNITS, "force": FORCE_UNITS, "time": TIME_UNITS, "mu_H": MU_H_UNITS,
               "pressure": PRESSURE_UNITS}
#: The SI unit of each kind (what a bare number would have meant).
SI_UNITS = {"length": "m", "force": "N", "time": "s", "mu_H": "N/m", "pressure": "Pa"}


def normalize_unit(unit: str) -> str:
    """A unit name as the tables spell it: micro as U+00B5, no brackets or spaces.

    Instruments write micro as ``u``, the micro sign U+00B5 or the Greek mu U+03BC
    (which NFKC-normalised text turns the micro sign into); all three are accepted.
    """
    u = str(unit).strip().strip("()[]{}").strip()
    u = u.replace("\u03bc", "\u00b5").replace("·", "*").replace("⋅", "*").replace(" ", "")
    return "micron" if u.lower() in ("micron", "microns", "micrometer", "micrometre") else u


#: A unit expression that may be handed to pint: names joined by ``*`` or ``/``, each with a
#: small integer power at most (no numbers, no nesting: pint parses it, and an exponent such as
#: ``m**99999999`` would be arithmetic on a huge integer)
_UNIT_EXPRESSION = re.compile(r"[A-Za-z\u00b5_]{1,24}(?:(?:\^|\*\*)-?[1-4])?"
                              r"(?:[*/][A-Za-z\u00b5_]{1,24}(?:(?:\^|\*\*)-?[1-4])?){0,3}")
PINT_HINT = "more units (gf, lbf, sec, millimeter, pN/nm, ...) with pint: pip install 'shellbvp[units]'"


@functools.lru_cache(maxsize=None)
def _pint_registry():
    import pint

    return pint.UnitRegistry()


@functools.lru_cache(maxsize=256)
def pint_unit(unit: str):
    """``(kind, SI factor)`` of a unit that the tables do not have but pint knows (``'gf'``,
    ``'lbf'``, ``'sec'``, ``'millimeter'``, ``'pN/nm'``), or None: pint not installed (the
    ``units`` extra), not a plain unit expression, unknown, or of no kind the package uses.
    pint is imported only here, for such a unit (0.4 s with its registry)."""
    u = normalize_unit(unit)
    if not _UNIT_EXPRESSION.fullmatch(u):
        return None
    try:
        ureg = _pint_registry()
    except ImportError:
        return None
    try:
        q = ureg.Quantity(1.0, u.replace("\u00b5", "u"))
        for kind, si in SI_UNITS.items():
            if q.dimensionality == ureg.Quantity(1.0, si).dimensionality:
                factor = float(q.to(si).magnitude)
                return (kind, factor) if math.isfinite(factor) and factor > 0 else None
    except Exception:  # pint's own errors: an undefined name, a syntax it refuses
        return None
    return None


def unit_kind(unit: str, *, extended: bool = False):
    """The kind ('length', 'force', 'time', 'mu_H', 'pressure') of a unit name, or None if it is
    none of them.  ``extended``: a name the tables lack is asked of pint (:func:`pint_unit`);
    for strings known to be units, not for every header cell (pint costs 0.4 s to load)."""
    u = normalize_unit(unit)
    for kind, table in UNIT_TABLES.items():
        if u in table:
            return kind
    found = pint_unit(u) if extended and u else None
    return found[0] if found else None


def unit_factor(unit: str, kind: str) -> float:
    """SI factor of a unit name of one kind ('length', 'force', 'time', 'mu_H' or 'pressure'):
    from the tables, else from pint (:func:`pint_unit`) where it is installed.

    Raises
    ------
    ValueError
        The unit is not one of that kind (the message lists the valid ones).
    """
    table = UNIT_TABLES[kind]
    u = normalize_unit(unit)
    if u in table:
        return table[u]
    found = pint_unit(u)
    if found is not None and found[0] == kind:
        return found[1]
    raise ValueError(f"unknown {kind} unit {unit!r}; use one of {', '.join(table)} ({PINT_HINT})")


def format_in(value: float, unit: str, kind: str, digits: int = 4) -> str:
    """``value`` (SI) written in ``unit``, e.g. ``format_in(1e-5, "um", "length") == "10 um"``."""
    return f"{value / unit_factor(unit, kind):.{digits}g} {normalize_unit(unit)}"


#: the units a value is shown in when its data came in bare SI (AFM files: m and N), largest first
READABLE_UNITS = {"length": ("m", "mm", "um", "nm"), "force": ("N", "mN", "uN", "nN", "pN")}


def readable_unit(scale: float, kind: str) -> str:
    """The largest unit of ``READABLE_UNITS[kind]`` in which ``scale`` (SI) is at least 1, e.g.
    ``readable_unit(2e-7, "length") == "nm"``, ``readable_unit(3e-9, "force") == "nN"``; the
    smallest for a smaller scale, the SI unit for a scale that is 0 or not finite."""
    units = READABLE_UNITS[kind]
    scale = abs(float(scale))
    if not math.isfinite(scale) or scale == 0:
        return units[0]
    return next((u for u in units if scale >= UNIT_TABLES[kind][u]), units[-1])


def plain_number(text: str, name: str = "value") -> float:
    """A finite float from plain decimal text; ValueError naming ``name`` otherwise."""
    t = str(text).strip()
    if not PLAIN_NUMBER.fullmatch(t) or not math.isfinite(v := float(t)):
        raise ValueError(f"{name} must be a plain finite number (e.g. 0.25 or 1e-3); got {text!r}")
    return v


def parse_uncertain(text: str, name: str = "value") -> tuple[float, float | None]:
    """``"2.5+-0.2"`` (or ``2.5±0.2``, ``2.5+/-0.2``) -> (2.5, 0.2); ``"2.5"`` -> (2.5, None).

    Both numbers are plain decimal text (nothing is evaluated); the uncertainty must be > 0.
    """
    parts = PLUS_MINUS.split(str(text))
    if len(parts) > 2:
        raise ValueError(f"{name} must be a number or VALUE+-UNCERTAINTY (e.g. 2.5+-0.2); got {text!r}")
    value = plain_number(parts[0], name)
    if len(parts) == 1:
        return value, None
    u = plain_number(parts[1], f"the uncertainty of {name}")
    if not u > 0:
        raise ValueError(f"the uncertainty of {name} must be > 0; got {parts[1].strip()!r}")
    return value, u


_EXAMPLE = {"length": "0.3mm", "force": "2mN", "time": "1.5s", "mu_H": "52N/m", "pressure": "0.2MPa"}
_SUGGEST = {"length": "mm", "force": "mN", "time": "s", "mu_H": "N/m", "pressure": "kPa"}


def split_quantity(text, kind: str = "length", name: str | None = None):
    """``'0.3mm'`` -> ``(0.3, 'mm')``; a bare number gives ``(value, '')``.

    The number must be plain (see :data:`PLAIN_NUMBER`) and finite; the unit one of
    ``UNIT_TABLES[kind]``.  ValueError naming ``name`` (or the kind) otherwise.
    """
    label = name or f"the {kind}"
    m = re.fullmatch(r"\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*([A-Za-z\u00b5\u03bc]\S*)?\s*",
                     str(text))
    if not m or not math.isfinite(float(m.group(1))):
        raise ValueError(f"cannot read {text!r} as {label}: a plain finite number and a unit, e.g. {_EXAMPLE[kind]}")
    unit = m.group(2) or ""
    if unit and unit_kind(unit, extended=True) != kind:
        raise ValueError(f"{label}: unknown {kind} unit {unit!r}; use one of {', '.join(UNIT_TABLES[kind])} "
                         f"({PINT_HINT})")
    return float(m.group(1)), normalize_unit(unit) if unit else ""


def parse_quantity(text, kind: str = "length", default_unit: str | None = None, *, require_unit: bool = False,
                   name: str | None = None) -> float:
    """A quantity in SI units: ``'0.3mm'`` -> 3e-4, ``'52N/m'`` (kind ``'mu_H'``) -> 52.0.

    Parameters
    ----------
    text : str or float
        A plain number with a unit (``0.3mm``, ``0.3 mm``, ``300µm``), or a bare number.
    kind : {'length', 'force', 'time', 'mu_H', 'pressure'}
    default_unit : str, optional
        Unit of a bare number (SI when not given).
    require_unit : bool
        A bare number is an error that says which unit to add (what the command line does:
        ``--radius 0.3`` might mean m or mm).
    name : str, optional
        Name of the quantity in error messages (e.g. ``--radius``).

    Returns
    -------
    float
        The value in SI units: m, N, s, N/m or Pa.

    Raises
    ------
    ValueError
        For text that is not a plain finite number and a unit, a unit of another kind,
        or (with ``require_unit``) a bare number; the message names the quantity.

    Examples
    --------
    >>> from shellbvp import parse_quantity
    >>> parse_quantity("0.3mm")
    0.0003
    >>> round(parse_quantity("15 uN", kind="force"), 12)
    1.5e-05
    >>> parse_quantity(300, default_unit="um")
    0.0003
    >>> parse_quantity("52 N/m", "mu_H")
    52.0
    >>> parse_quantity("0.3", require_unit=True, name="--radius")
    Traceback (most recent call last):
    ...
    ValueError: --radius needs a unit: write it as e.g. 0.3mm (length units: m, cm, mm, um, µm, micron, nm)
    """
    label = name or f"the {kind}"
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value, unit = float(text), ""
    else:
        value, unit = split_quantity(text, kind, name)
    if not unit:
        if require_unit:
            raise ValueError(f"{label} needs a unit: write it as e.g. {value:g}{_SUGGEST[kind]} "
                             f"({kind} units: {', '.join(UNIT_TABLES[kind])})")
        unit = default_unit
    return value * (unit_factor(unit, kind) if unit else 1.0)


@dataclass(frozen=True)
class Quantity:
    """A quantity as a person wrote it: ``value`` in ``unit``, and ``si`` in SI units.

    Examples
    --------
    >>> q = Quantity.parse("0.3mm", "length")
    >>> q.si, str(q)
    (0.0003, '0.3 mm')
    """

    si: float
    value: float
    unit: str
    kind: str

    @classmethod
    def parse(cls, text, kind: str = "length", name: str | None = None, positive: bool = True) -> "Quantity":
        """Parse ``text`` with a unit required (a bare number is an error saying which unit to add).

        ``positive``: also require a finite value > 0 (rim radius, mu*H).
        """
        value, unit = split_quantity(text, kind, name)
        si = parse_quantity(text, kind, require_unit=True, name=name)
        if positive and not si > 0:
            raise ValueError(f"{name or 'the ' + kind} must be > 0; got {text!r}")
        return cls(si=si, value=value, unit=unit, kind=kind)

    def __str__(self):
        return f"{self.value:g} {self.unit}"

    def show(self, si_value: float, digits: int = 4) -> str:
        """Another value of this kind (SI) in this quantity's unit."""
        return format_in(si_value, self.unit, self.kind, digits)


def force_unit_of(mu_H_unit: str) -> str:
    """The force unit of a mu*H unit: ``'mN/mm'`` -> ``'mN'``; ``'N'`` when it has none."""
    top = normalize_unit(mu_H_unit).split("/")[0]
    return top if unit_kind(top) == "force" else "N"


def beta_from_thickness(H: float, R_L: float = 1.0, bending=None) -> float:
    """The bending stiffness of a shell of thickness H: ``beta = (H/R_L)^2 / 3`` for the built-in
    bending energies.

    A plate of an incompressible solid (Poisson ratio 1/2, shear modulus mu) has the bending
    stiffness ``D = E H^3/(12 (1 - nu^2)) = mu H^3/3``; the shell model's ``U = W + beta B``
    bends a flat sheet with ``mu H R_L^2 beta k``, k = d2B/dkappa_s2 at rest (1 for the trace,
    rotation and koiter energies; ``symbolic.bending.plate_limit`` derives each).  So ``beta = eps^2/(3 k)``,
    ``eps = H/R_L``.  A 3D finite-element model agrees (``shellbvp validate``; the docs' page on
    the model's accuracy).  Builds before issue 41 returned the paper's ``eps^2/12``, 4x too small.

    Parameters
    ----------
    H : float
        Shell thickness (any length unit).
    R_L : float
        Rim radius, in the same unit as H (default 1: H is then eps = H/R_L).
    bending : Bending, optional
        The scene's bending energy (default the trace energy).

    Returns
    -------
    float
        beta, nondimensional.

    Examples
    --------
    >>> from shellbvp import beta_from_thickness
    >>> round(beta_from_thickness(H=50e-6, R_L=0.3e-3), 6)   # a 50 um endosperm, R_L = 0.3 mm
    0.009259
    """
    for name, v in (("H", H), ("R_L", R_L)):
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not (math.isfinite(v) and v > 0):
            raise ValueError(f"{name} must be a finite length > 0; got {v!r}")
    stiffness = 1.0 if bending is None else float(bending.plate_stiffness)
    return (H / R_L) ** 2 / (3 * stiffness)


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
    >>> round(dims.p(2e5), 6)                        # a turgor of 0.2 MPa
    1.153846
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

    def pressure(self, p):
        """Nondimensional pressure ``p R_L/(mu H)`` -> pascals."""
        return p * self.mu_H / self.R_L

    def p(self, pascals):
        """Pascals -> nondimensional pressure ``p R_L/(mu H)``."""
        return pascals * self.R_L / self.mu_H
