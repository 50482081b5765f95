"""A force map's geometry per pixel, from a table (issue 46, item 3).

A CSV (or any table :func:`shellbvp.instrument.read_table` reads) with the columns ``ix`` and
``iy`` (the pixel on the map's grid, integers from 0) and ONE geometry column, named by a
parameter of :data:`PIXEL_PARAMETERS` (those of :mod:`shellbvp.scene_parameters` flagged
``per_pixel``) with its unit the way the package's tables write units:

* ``thickness_um``, ``thickness (um)``, ``thickness [nm]`` ... -- the shell's thickness H, any
  length unit; a bare ``thickness`` is the nondimensional ``H / R_L`` (as ``--thickness 0.05``):
  a parameter with a lab form over R_L may carry a unit of its kind;
* ``beta`` -- the bending stiffness ``B/(mu R_L^2)`` (nondimensional);
* ``alpha`` -- the Mooney-Rivlin alpha (nondimensional; needs a Mooney-Rivlin scene).

The pressure is not among them: its nondimensional value ``p R_L/(mu H)`` depends on the mu*H
the fit estimates, so a pressure in Pa cannot be held fixed before the fit.

:func:`read_pixel_table` reads and checks the file (one-line ``ValueError`` naming the column or
the row); :class:`PixelTable` holds it.  :func:`shellbvp.batch.fit_map` fits a map with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from . import afm_read
from .readers import read_table
from .readers.text_table import cell_number, header_name_and_unit
from .scene_parameters import LiveMapping, parameters_that, scene_parameter
from .units import unit_factor, unit_kind

__all__ = ["PIXEL_PARAMETERS", "PixelTable", "read_pixel_table"]


def _unit_kind(p) -> str:
    """The kind of unit a column of ``p`` may carry: its lab form's when that is a multiple of
    R_L (a length), else "" (nondimensional only)."""
    return p.lab.kind if p.lab is not None and p.lab.scale == "R_L" else ""


#: Shape parameters a pixel table may give, with the kind of unit their column may carry
#: ("" : nondimensional only); the registry's, in its order (live).
PIXEL_PARAMETERS = LiveMapping(lambda: {p.name: _unit_kind(p) for p in parameters_that("per_pixel")})


@dataclass
class PixelTable:
    """A geometry value per pixel of a force map.

    Attributes
    ----------
    name : str
        The shape parameter (a key of :data:`PIXEL_PARAMETERS`).
    values : dict
        ``{(ix, iy): value}`` in ``unit``.
    unit : str
        The values' unit as the table wrote it (``"um"``); ``""``: nondimensional (the scene's
        own value, e.g. ``H / R_L`` for the thickness).
    path : str
        Where the table came from (for messages).
    lines : dict
        ``{(ix, iy): line number in the file}`` (for messages).

    Examples
    --------
    >>> t = PixelTable("thickness", {(0, 0): 0.5, (1, 0): 0.7}, unit="um")
    >>> {p: round(x, 12) for p, x in t.nondimensional(R_L=10e-6).items()}      # H / R_L
    {(0, 0): 0.05, (1, 0): 0.07}
    """

    name: str
    values: dict
    unit: str = ""
    path: str = "the pixel table"
    lines: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.name not in PIXEL_PARAMETERS:
            raise ValueError(f"a pixel table gives one of {', '.join(PIXEL_PARAMETERS)}; got {self.name!r}")
        kind = PIXEL_PARAMETERS[self.name]
        if self.unit:
            if not kind:
                raise ValueError(f"{self.path}: column {self.name!r} is nondimensional; got the unit {self.unit!r}")
            self._factor = unit_factor(self.unit, kind)  # ValueError naming the unit's kind
        else:
            self._factor = None
        if not self.values:
            raise ValueError(f"{self.path}: no pixels")

    @property
    def column(self) -> str:
        return f"{self.name} ({self.unit})" if self.unit else self.name

    def where(self, pixel) -> str:
        line = self.lines.get(pixel)
        return f"{self.path}, line {line}" if line is not None else f"{self.path}, pixel {pixel}"

    def nondimensional(self, R_L) -> dict:
        """``{(ix, iy): x}``: the scene's nondimensional value of every pixel (a length over R_L)."""
        if self._factor is None:
            return dict(self.values)
        param = scene_parameter(self.name)  # a lab value (SI) over its scale, R_L
        return {p: param.from_lab(v * self._factor, R_L) for p, v in self.values.items()}


def read_pixel_table(path) -> PixelTable:
    """The table of a geometry value per pixel (module docstring): checked before any curve.

    Raises
    ------
    ValueError
        One line naming the file and the column or line: a missing ``ix``/``iy`` or geometry
        column, two geometry columns, an unknown unit, a pixel index that is not an integer
        >= 0, a value that is not a finite number > 0 (alpha: >= 0), a pixel given twice.
    """
    # at most one row per cell of the largest map; checked against the map's own grid by fit_map
    table = read_table(path, max_rows=afm_read.MAX_MAP_PIXELS, what="pixel table (one row per pixel, MAX_MAP_PIXELS)")
    if not table.header:
        raise ValueError(f"{path}: no header row; the pixel table needs the columns ix, iy and one of "
                         f"{', '.join(PIXEL_PARAMETERS)} (e.g. thickness_um)")
    names = [header_name_and_unit(h)[0] for h in table.header]
    for need in ("ix", "iy"):
        if names.count(need) != 1:
            raise ValueError(f"{path}: needs one column {need!r} (the pixel's grid index); its columns are "
                             f"{', '.join(repr(h) for h in table.header)}")
    geometry = [i for i, n in enumerate(names) if n in PIXEL_PARAMETERS]
    if len(geometry) != 1:
        what = "no" if not geometry else f"{len(geometry)} ({', '.join(table.header[i] for i in geometry)})"
        raise ValueError(f"{path}: needs exactly one geometry column, one of {', '.join(PIXEL_PARAMETERS)} with "
                         f"its unit (e.g. thickness_um, 'thickness (um)'); found {what}")
    g = geometry[0]
    name = names[g]
    unit = ""
    if table.header_units is not None and g < len(table.header_units) and table.header_units[g]:
        unit = table.header_units[g]
    elif header_name_and_unit(table.header[g])[1]:
        unit = header_name_and_unit(table.header[g])[1]
    if unit == "1":
        unit = ""
    kind = PIXEL_PARAMETERS[name]
    param = scene_parameter(name)
    if unit:
        if not kind:
            raise ValueError(f"{path}: column {table.header[g]!r}: {name} is nondimensional (no unit)")
        if unit_kind(unit, extended=True) != kind:
            raise ValueError(f"{path}: column {table.header[g]!r}: {unit!r} is not a {kind} unit")
    ix, iy = names.index("ix"), names.index("iy")
    values, lines = {}, {}
    for cells, line in zip(table.rows, table.line):
        where = f"{path}, line {line}"
        if len(cells) != len(table.header):
            raise ValueError(f"{where}: {len(cells)} cells, the header has {len(table.header)}")
        pixel = []
        for col in (ix, iy):
            v = cell_number(cells[col])
            if v is None or not math.isfinite(v) or v < 0 or v != int(v):
                raise ValueError(f"{where}: column {table.header[col]!r} must be a grid index (an integer >= 0); "
                                 f"got {cells[col]!r}")
            pixel.append(int(v))
        pixel = tuple(pixel)
        v = cell_number(cells[g])
        if v is None or not math.isfinite(v) or not param.low_ok(v):  # the upper bound: against R_L (fit_map)
            bound = "" if param.low == -math.inf else f" {'>' if param.low_open else '>='} {param.low:g}"
            raise ValueError(f"{where}: column {table.header[g]!r} must be a finite number{bound}; got {cells[g]!r}")
        if pixel in values:
            raise ValueError(f"{where}: pixel {pixel} again (first on line {lines[pixel]})")
        values[pixel], lines[pixel] = v, line
    return PixelTable(name, values, unit=unit, path=str(path), lines=lines)
