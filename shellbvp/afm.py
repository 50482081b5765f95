"""AFM files through afmformats (optional extra ``[afm]``): single curves and force maps.

afmformats, the AFM community's reader (nanite and PyJibe use it), reads JPK's
``.jpk-force``, ``.jpk-force-map``, ``.jpk-qi-data`` and ``.jpk-qi-series`` and Asylum's
``.ibw``: each curve's force (N), the cantilever's height (m), time and spring constant, and
on a map each curve's grid index and position.  The tip's position is the height plus the
cantilever's deflection ``force / spring constant`` (nanite's tip-sample separation, JPK's
"Vertical Tip Position"); the height falls as the tip goes in, so the displacement into the
sample is minus the tip's position: the package's signs, no ``--invert`` needed.

* :func:`read_afm` -- the curves of a file as :class:`AFMCurve` (an
  :class:`~shellbvp.instrument.InstrumentRecord` with its place on the map), by its reader
  (:mod:`shellbvp.readers`); :func:`iter_afm` one at a time.  The file's declared sizes are
  checked first and every failure of decoding is one line (:mod:`shellbvp.afm_read`).  AFM Workshop CSV and NT-MDT Nova text exports go through
  afmformats too (:func:`afm_text_format`), with the cantilever's calibration given.
* :class:`ForceMap` -- a force map fitted (:func:`shellbvp.batch.fit_map`): the per-curve rows
  of a batch (each fit's numbers and its fitted rows thinned with the model, not the records),
  images of mu*H and its interval, a NeXus file, a figure.
* :func:`read_map_file` -- that NeXus file read back (:class:`MapFile`), for ``shellbvp info``
  and ``shellbvp plot``; one pixel's data against its fitted model from it
  (:meth:`MapFile.plot_pixel`, ``shellbvp plot map.h5 --pixel IX,IY``; :mod:`shellbvp.map_pixels`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import afm_read, readers
from . import schema as sc
from .afm_read import AFMCurve, curves_from_afm
from .map_pixels import MapPixel, locate, pixel_of_row, read_curves, write_curve_data
from .nexus import new_file, number_dataset, string_dataset
from .paths import open_hdf5
from .plotting import map_pixel_notes, plot_map_pixel, require_matplotlib, save_figure
from .shape_parameters import shape_parameter
from .textdata import printable
from .units import format_in

__all__ = ["AFM_SUFFIXES", "AFMCurve", "ForceMap", "MapFile", "is_afm_file", "afm_text_format", "read_afm", "iter_afm",
           "curves_from_afm", "single_curve", "refuse_text_options", "map_shape", "MAP_FORMAT", "is_map_file",
           "read_map_file", "draw_map", "draw_pixel"]

#: File name endings of the files read for their curves (:mod:`shellbvp.readers`: JPK, Asylum)
AFM_SUFFIXES = readers.curve_suffixes()


def is_afm_file(path) -> bool:
    """True for a file read for its curves (an AFM file: :mod:`shellbvp.readers` recognises it by
    its name or its first bytes), False for a text table."""
    return readers.reader_for(path).curves


def afm_text_format(path):
    """The name of the AFM text export ``path`` is (``"AFM Workshop"``, ``"NT-MDT Nova"``: read with
    the cantilever's calibration given), or None.  Only the first bytes of a regular file are read."""
    found = readers.reader_for(path)
    return found.name if found.curves and "spring_constant" in found.requires else None


def read_afm(path, *, spring_constant=None, sensitivity=None) -> list:
    """The curves of an AFM file as :class:`AFMCurve`, in file order, read by its reader
    (:func:`shellbvp.readers.read_curves`; a file no reader recognises through afmformats' own
    loader).

    The file's declared sizes are checked first (an archive's members and inflated sizes, an
    ``.ibw`` header's parts), then afmformats reads it inside one error boundary
    (:func:`shellbvp.afm_read.afmformats_boundary`): whatever fails while the file is decoded is
    one ``ValueError`` line.

    Parameters
    ----------
    spring_constant, sensitivity : float, optional
        The cantilever's spring constant (N/m) and deflection sensitivity (m/V; for NT-MDT
        m/A), for the text exports that do not carry them (:func:`afm_text_format`); JPK and
        Asylum files carry their own.

    Raises
    ------
    ValueError
        afmformats is not installed, or cannot read the file, or a curve lacks the force,
        a height or the spring constant, or the file declares sizes beyond the bounds.
    """
    return readers.read_curves(path, spring_constant=spring_constant, sensitivity=sensitivity)


def iter_afm(path, *, spring_constant=None, sensitivity=None):
    """:func:`read_afm` one curve at a time (:func:`shellbvp.readers.iter_curves`): a force map's
    curves are never all in memory (:func:`shellbvp.batch.fit_map` takes them so).  The options
    are checked at once; the file's sizes, and its curve count against
    :data:`~shellbvp.afm_read.MAX_MAP_CURVES`, before its first curve is read."""
    return readers.iter_curves(path, spring_constant=spring_constant, sensitivity=sensitivity)


def single_curve(path, *, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None):
    """The record of an AFM file's one curve (:func:`read_afm`); a force map is refused, pointing
    to :func:`read_afm` and :func:`shellbvp.batch.fit_map`, as reading options of text exports."""
    return readers.read_record(path, columns=columns, units=units, invert=invert, spring_constant=spring_constant,
                               sensitivity=sensitivity, curves=True)


def refuse_text_options(path, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None):
    """ValueError when reading options of text exports are given for an AFM file (the
    calibration options are the AFM reader's: accepted)."""
    readers.check_options(readers.reader_for(path, curves=True), path,
                          {"columns": columns, "units": units, "invert": invert})


MAP_FORMAT = "shellbvp-force-map"
MAP_FORMAT_VERSION = 1


def map_shape(curves, path="the map") -> tuple:
    """``(nx, ny)``: the grid a force map's curves span (their largest grid indices + 1), or
    ``(len(curves), 1)`` when they carry none.

    Raises
    ------
    ValueError
        The grid spans more than :data:`~shellbvp.afm_read.MAX_MAP_PIXELS` cells (a map's
        images are allocated at this size): a header declaring a 100000 x 100000 grid for the
        few curves present is refused before any curve is fitted.
    """
    grids = [c.grid for c in curves if c.grid is not None]
    if not grids:
        return (len(curves), 1)
    shape = (max(g[0] for g in grids) + 1, max(g[1] for g in grids) + 1)
    if min(min(g) for g in grids) < 0:
        raise ValueError(f"{printable(path)}: a curve has a negative grid index")
    if shape[0] * shape[1] > afm_read.MAX_MAP_PIXELS:
        raise ValueError(f"{printable(path)}: its {len(curves)} curves' grid indices span a {shape[0]} x {shape[1]} "
                         f"grid ({shape[0] * shape[1]} cells); a map has at most {afm_read.MAX_MAP_PIXELS} cells "
                         f"(MAX_MAP_PIXELS; the header's grid size or the curves' positions are wrong)")
    return shape


def mu_H_spread(mu, with_range=False) -> str:
    """Median and quartiles (and range) of mu*H values (N/m) in one unit that suits their size:
    N/m, mN/m or uN/m (a cell wall's 0.0006 N/m reads 0.6 mN/m)."""
    scale, unit = next(((f, u) for f, u in ((1.0, "N/m"), (1e-3, "mN/m"), (1e-6, "uN/m"))
                        if abs(np.median(mu)) >= 0.1 * f), (1e-6, "uN/m"))
    q = np.percentile(mu, [25, 50, 75]) / scale
    text = f"median {q[1]:.4g} {unit}, quartiles {q[0]:.4g}..{q[2]:.4g} {unit}"
    return text + (f", range {mu.min() / scale:.4g}..{mu.max() / scale:.4g} {unit}" if with_range else "")


@dataclass
class ForceMap:
    """Every curve of a force map fitted with one scene (:func:`shellbvp.batch.fit_map`).

    Attributes
    ----------
    path : str
        The map's file.
    curves : list of AFMCurve
        Each curve's place on the map (from :func:`~shellbvp.batch.fit_map` without its record).
    rows : list of BatchRow
        One per curve, in the same order (status ``ok``, ``failed`` or ``error``; from
        :func:`~shellbvp.batch.fit_map` with its fitted rows thinned, ``BatchRow.curve_rows``,
        for :meth:`pixel`).
    shape : tuple of int
        ``(nx, ny)``: the grid's size (from the curves' indices).
    scene : Scene
    R_L : float
    pixel_values : PixelTable or None
        A shape parameter per pixel (:mod:`shellbvp.pixel_table`), each pixel fitted with it
        fixed; ``scene`` is then the scene the table's values were put into.
    pixel_nodes : tuple of float
        With ``pixel_values``: the values of the parameter (in its unit, the thickness in m)
        at which model curves were computed; every pixel's curve is interpolated across them.
    curves_computed : int or None
        With ``pixel_values``: the model curves computed (the nodes, not the pixels).
    interpolation_error : float or None
        With ``pixel_values``: the largest ``max |F_interp - F| / max |F|`` at the curves
        checked between nodes (:func:`shellbvp.batch.shared_curves`).
    notes : list of str
    sha256 : str
        The map file's checksum (else its first curve's record's, where it has one).
    """

    path: str
    curves: list
    rows: list
    shape: tuple
    scene: object
    R_L: float
    segment: str = "loading"
    settings: dict = field(default_factory=dict)
    pixel_values: object = None
    pixel_nodes: tuple = ()
    curves_computed: object = None
    interpolation_error: object = None
    notes: list = field(default_factory=list)
    sha256: str = ""

    def pixel_image(self) -> np.ndarray:
        """``(ny, nx)`` image of the per-pixel geometry value in its unit (the thickness in m,
        :meth:`pixel_unit`), NaN where the table has none."""
        nx, ny = self.shape
        img = np.full((ny, nx), np.nan)
        if self.pixel_values is None:
            return img
        param = shape_parameter(self.pixel_values.name)
        for (ix, iy), x in self.pixel_values.nondimensional(self.R_L).items():
            if ix < nx and iy < ny:
                img[iy, ix] = param.reported(x, self.R_L)
        return img

    def pixel_unit(self) -> str:
        return shape_parameter(self.pixel_values.name).unit if self.pixel_values is not None else ""

    def image(self, quantity="mu_H") -> np.ndarray:
        """``(ny, nx)`` image of ``mu_H``, ``mu_H_low``, ``mu_H_high`` (N/m), ``offset`` (m) or
        ``pressure_Pa``: NaN where a curve is missing or its fit did not succeed."""
        nx, ny = self.shape
        img = np.full((ny, nx), np.nan)
        for c, row in zip(self.curves, self.rows):
            if c.grid is None or row.status != "ok":
                continue
            r = row.result
            value = {"mu_H": r.mu_H, "mu_H_low": r.mu_H_ci95[0], "mu_H_high": r.mu_H_ci95[1],
                     "offset": r.offset, "pressure_Pa": r.pressure_Pa}[quantity]
            img[c.grid[1], c.grid[0]] = np.nan if value is None else value
        return img

    def status_image(self) -> np.ndarray:
        """``(ny, nx)`` codes: 0 fitted, 1 the fit failed its checks, 2 error, -1 no curve."""
        nx, ny = self.shape
        img = np.full((ny, nx), -1, dtype=np.int8)
        code = {"ok": 0, "failed": 1, "error": 2}
        for c, row in zip(self.curves, self.rows):
            if c.grid is not None:
                img[c.grid[1], c.grid[0]] = code.get(row.status, 2)
        return img

    def axes(self):
        """``(x, y)``: the grid's cell centres (m) from the file's grid centre and size, else each
        column's and row's mean curve position; ``(None, None)`` where neither is known."""
        nx, ny = self.shape
        geometry = {c.grid_geometry for c in self.curves}
        if len(geometry) == 1 and None not in geometry:
            (cx, cy), (sx, sy) = geometry.pop()
            return (cx - sx / 2 + (np.arange(nx) + 0.5) * sx / nx, cy - sy / 2 + (np.arange(ny) + 0.5) * sy / ny)
        xs, ys = [[] for _ in range(nx)], [[] for _ in range(ny)]
        for c in self.curves:
            if c.grid is not None and c.position is not None:
                xs[c.grid[0]].append(c.position[0])
                ys[c.grid[1]].append(c.position[1])
        x = np.array([np.mean(v) if v else np.nan for v in xs])
        y = np.array([np.mean(v) if v else np.nan for v in ys])
        return (x, y) if np.all(np.isfinite(x)) and np.all(np.isfinite(y)) else (None, None)

    def summary(self) -> str:
        counts = {s: sum(r.status == s for r in self.rows) for s in ("ok", "failed", "error")}
        mu = np.array([r.result.mu_H for r in self.rows if r.status == "ok"])
        spread = f"; mu*H {mu_H_spread(mu)}" if mu.size else ""
        nx, ny = self.shape
        text = (f"{len(self.rows)} curves on a {nx} x {ny} grid: {counts['ok']} fitted, {counts['failed']} failed "
                f"their checks, {counts['error']} errors{spread}")
        rated = [r.result.quality for r in self.rows if r.result is not None and r.status != "error"]
        if rated:
            text += "; quality " + ", ".join(f"{q} {rated.count(q)}" for q in ("good", "fair", "poor"))
        warned = self.warning_counts()
        if warned:
            text += "; warnings: " + ", ".join(f"{code} in {len(where)}" for code, (where, _) in warned.items())
        if self.pixel_values is not None and self.pixel_nodes:
            unit = self.pixel_unit()
            show = ((lambda v: format_in(v, "um", "length")) if unit == "m" else (lambda v: f"{v:.4g}"))
            err = self.interpolation_error
            text += (f"; {self.pixel_values.name} per pixel from {self.pixel_values.path} "
                     f"({show(min(self.pixel_nodes))} .. {show(max(self.pixel_nodes))}): {self.curves_computed} "
                     f"model curves computed, {len(self.pixel_nodes)} nodes"
                     + (f", interpolation error {err:.2g}" if err is not None else ""))
        return text

    def warning_counts(self) -> dict:
        """``{code: (grid cells or indices of the curves with that warning, its first text)}``
        over the curves fitted (codes of :data:`shellbvp.fit_checks.FIT_WARNINGS`)."""
        out, seen = {}, set()  # seen: (code, cell), so that a map's cells are not searched per curve
        for c, row in zip(self.curves, self.rows):
            if row.result is None or row.status == "error":
                continue
            cell = c.grid if c.grid is not None else c.index
            for code, text in zip(row.result.warning_codes, row.result.warnings):
                where, _ = out.setdefault(code, ([], text))
                if (code, cell) not in seen:
                    seen.add((code, cell))
                    where.append(cell)
        return out

    def to_hdf5(self, out, *, overwrite=False):
        """The map as a NeXus file, written atomically: ``/entry/map`` (NXdata: ``mu_H`` image
        over ``y``, ``x``, its interval, offset, pressure where fitted, status codes) and
        ``/entry/curves`` (one row per curve: index, grid, position, results, status, message)."""
        import json

        x, y = self.axes()
        with new_file(out, MAP_FORMAT, MAP_FORMAT_VERSION, overwrite=overwrite) as f:
            f.attrs["default"] = "entry"
            entry = f.create_group("entry")
            entry.attrs.update({"NX_class": "NXentry", "default": "map"})
            m = entry.create_group("map")
            m.attrs.update({"NX_class": "NXdata", "signal": "mu_H", "axes": ["y", "x"] if x is not None else
                            [".", "."]})
            number_dataset(m, "mu_H", self.image("mu_H"), "N/m", "shear modulus x thickness, fitted per curve")
            number_dataset(m, "mu_H_low", self.image("mu_H_low"), "N/m", "lower end of mu*H's 95 % interval")
            number_dataset(m, "mu_H_high", self.image("mu_H_high"), "N/m", "upper end of mu*H's 95 % interval")
            number_dataset(m, "offset", self.image("offset"), "m", "fitted contact point")
            if any(r.status == "ok" and r.result.pressure_Pa is not None for r in self.rows):
                number_dataset(m, "pressure_Pa", self.image("pressure_Pa"), "Pa", "fitted pressure")
            number_dataset(m, "status", self.status_image(), "1", "0 fitted, 1 failed its checks, 2 error, -1 no curve")
            if self.pixel_values is not None:
                name = self.pixel_values.name
                number_dataset(m, name, self.pixel_image(), self.pixel_unit(),
                               f"{name} per pixel, given (from {printable(self.pixel_values.path)}); NaN: not given")
            if x is not None:
                number_dataset(m, "x", x, "m", "position x of the grid's columns")
                number_dataset(m, "y", y, "m", "position y of the grid's rows")
            c = entry.create_group("curves")
            c.attrs["NX_class"] = "NXcollection"
            grid = np.array([cv.grid if cv.grid is not None else (-1, -1) for cv in self.curves], dtype=int)
            pos = np.array([cv.position if cv.position is not None else (np.nan, np.nan) for cv in self.curves], float)
            res = [r.result if r.status in ("ok", "failed") else None for r in self.rows]

            def col(fn):
                return np.array([np.nan if r is None or fn(r) is None else fn(r) for r in res], float)

            number_dataset(c, "index", np.array([cv.index for cv in self.curves], dtype=int), "1", "curve in the file")
            number_dataset(c, "grid_index", grid.reshape(-1, 2), "1", "(ix, iy) on the grid; -1: none")
            number_dataset(c, "position", pos.reshape(-1, 2), "m", "(x, y) on the sample")
            number_dataset(c, "mu_H", col(lambda r: r.mu_H), "N/m", "shear modulus x thickness")
            number_dataset(c, "mu_H_ci95", np.column_stack([col(lambda r: r.mu_H_ci95[0]),
                                                            col(lambda r: r.mu_H_ci95[1])]).reshape(-1, 2),
                           "N/m", "95 % interval of mu*H")
            number_dataset(c, "offset", col(lambda r: r.offset), "m", "fitted contact point")
            if self.pixel_values is not None:
                img = self.pixel_image()
                per_curve = np.array([img[cv.grid[1], cv.grid[0]] if cv.grid is not None else np.nan
                                      for cv in self.curves], float)
                number_dataset(c, name, per_curve, self.pixel_unit(), f"{name} per pixel, given")
                number_dataset(c, f"{name}_nodes", np.array(self.pixel_nodes, float), self.pixel_unit(),
                               f"the {name} values of the model curves computed (nodes); every pixel's curve "
                               f"interpolated across them")
                number_dataset(c, "interpolation_error", np.nan if self.interpolation_error is None
                               else float(self.interpolation_error), "1",
                               "largest max|F_interpolated - F|/max|F| at curves checked between nodes")
            string_dataset(c, "status", [r.status for r in self.rows], "ok, failed (its checks) or error")
            string_dataset(c, "message", [printable(r.message) for r in self.rows], "the fit's message")
            write_curve_data(entry, self.rows, self.segment)  # ratings, warnings, each curve's rows and model
            s = entry.create_group("sample")
            s.attrs.update({"NX_class": "NXsample", "scene": self.scene.to_json(),
                            "description": self.scene.describe(self.R_L)
                            + ("" if self.pixel_values is None else
                               f"; in place of its {self.pixel_values.name}: {self.pixel_values.name} per pixel "
                               f"from {printable(self.pixel_values.path)} (map/{self.pixel_values.name})"),
                            "R_L_m": float(self.R_L)})
            src = entry.create_group("source")
            src.attrs["NX_class"] = "NXnote"
            string_dataset(src, "file_name", str(self.path))
            first = self.curves[0].record if self.curves else None
            string_dataset(src, "sha256", self.sha256 or (first.sha256 if first is not None else ""))
            string_dataset(src, "settings", json.dumps({"segment": self.segment, **self.settings}, default=str))

    def plot(self, out=None, ax=None):
        """The mu*H image (curves whose fit did not succeed left blank), with a colour bar."""
        x, y = self.axes()
        title = (f"{Path(self.path).name}: {sum(r.status == 'ok' for r in self.rows)} of {len(self.rows)} "
                 "curves fitted")
        return draw_map(self.image("mu_H"), x, y, title, out=out, ax=ax)

    def pixel(self, ix, iy) -> MapPixel:
        """The curve at grid index ``(ix, iy)`` as a :class:`~shellbvp.map_pixels.MapPixel`: its
        fit's numbers and its fitted rows with the model at them, thinned as the map file keeps
        them; ValueError (one line, the valid range) outside the grid or where no curve is."""
        i = locate([c.grid if c.grid is not None else (-1, -1) for c in self.curves], self.shape, ix, iy)
        return pixel_of_row(self.curves[i], self.rows[i], len(self.rows), self.segment, source=str(self.path))

    def plot_pixel(self, ix, iy, out=None, axes=None, dpi=150):
        """One pixel's data, model and residuals (:func:`shellbvp.plotting.plot_map_pixel`; its
        2 x 2 axes returned), saved to ``out`` when given."""
        return draw_pixel(self.pixel(ix, iy), out=out, axes=axes, dpi=dpi)


def draw_pixel(pixel, out=None, axes=None, dpi=150):
    """:func:`shellbvp.plotting.plot_map_pixel` of ``pixel`` with its message and warnings
    under it (on a figure of its own), saved to ``out`` (atomically) and closed when given;
    ValueError when the pixel has no rows to draw."""
    if pixel.displacement is None or pixel.displacement.size == 0:
        raise ValueError(f"pixel {pixel.grid}: no rows to draw ({pixel.status}: {printable(pixel.message)})")
    plt = require_matplotlib()
    axes = plot_map_pixel(pixel, axes)
    fig = axes[0, 0].figure
    notes = map_pixel_notes(pixel)
    if notes and len(fig.axes) == 4:  # a figure of its own: the notes below the axes
        lines = notes.count("\n") + 1
        fig.subplots_adjust(left=0.09, right=0.98, top=0.93, hspace=0.08, wspace=0.22, bottom=0.1 + 0.022 * lines)
        fig.text(0.01, 0.01, notes, fontsize=7, va="bottom", ha="left", family="monospace")
    if out is not None:
        try:
            save_figure(fig, out, dpi=dpi)
        finally:
            plt.close(fig)
    return axes


def draw_map(img, x, y, title, out=None, ax=None, dpi=150):
    """A ``(ny, nx)`` image of mu*H (N/m) over the grid's cell centres ``x``, ``y`` (m; None: grid
    indices), with a colour bar; saved to ``out`` when given."""
    plt = require_matplotlib()
    fig = None
    if ax is None:
        fig, ax = plt.subplots(figsize=(5.5, 4.5))
    ny, nx = img.shape
    if x is not None and nx > 1 and ny > 1:
        dx, dy = np.ptp(x) / (nx - 1) * 1e6, np.ptp(y) / (ny - 1) * 1e6
        extent = (x.min() * 1e6 - dx / 2, x.max() * 1e6 + dx / 2, y.min() * 1e6 - dy / 2, y.max() * 1e6 + dy / 2)
        ax.set_xlabel("x (um)")
        ax.set_ylabel("y (um)")
    else:
        extent = None
        ax.set_xlabel("grid index x")
        ax.set_ylabel("grid index y")
    im = ax.imshow(img, origin="lower", extent=extent, interpolation="nearest")
    (fig or ax.figure).colorbar(im, ax=ax, label="mu*H (N/m)")
    ax.set_title(title, fontsize=9)
    if out is not None:
        (fig or ax.figure).savefig(out, dpi=dpi, bbox_inches="tight")
        plt.close(fig or ax.figure)
    return ax


@dataclass
class MapFile:
    """What a force-map file (:meth:`ForceMap.to_hdf5`) holds, as :func:`read_map_file` reads it.

    Attributes
    ----------
    path : str
    mu_H, mu_H_low, mu_H_high : ndarray, shape (ny, nx)
        mu*H and its 95 % interval (N/m); NaN where no curve was fitted.
    status : ndarray of int, shape (ny, nx)
        0 fitted, 1 failed its checks, 2 error, -1 no curve.
    x, y : ndarray or None
        The grid's cell centres (m), when the map file has them.
    sample : str
        The scene in lab units, as the fit described it.
    source : str
        The AFM file fitted.
    curves : MapCurves or None
        Each curve's numbers and, in a file written since the per-curve view, its fitted rows
        and model (:mod:`shellbvp.map_pixels`); None where the file has no ``/entry/curves``.
    """

    path: str
    mu_H: np.ndarray
    mu_H_low: np.ndarray
    mu_H_high: np.ndarray
    status: np.ndarray
    x: object
    y: object
    sample: str
    source: str
    curves: object = None

    def summary_lines(self) -> list:
        """What ``shellbvp info`` prints."""
        ny, nx = self.status.shape
        counts = {name: int(np.sum(self.status == code)) for code, name in
                  ((0, "fitted"), (1, "failed their checks"), (2, "errors"), (-1, "no curve"))}
        mu = self.mu_H[self.status == 0]
        lines = [f"source:    {self.source}", f"sample:    {self.sample}",
                 f"grid:      {nx} x {ny}: " + ", ".join(f"{v} {k}" for k, v in counts.items())]
        if mu.size:
            lines.append(f"mu*H:      {mu_H_spread(mu, with_range=True)}")
        if self.x is not None:
            lines.append(f"area:      x {self.x.min() * 1e6:.4g}..{self.x.max() * 1e6:.4g} um, "
                         f"y {self.y.min() * 1e6:.4g}..{self.y.max() * 1e6:.4g} um (cell centres)")
        if self.curves is not None:
            lines += self.curves.summary_lines()
        return lines

    def plot(self, out=None, ax=None, dpi=150):
        fitted = int(np.sum(self.status == 0))
        title = f"{Path(self.source).name}: {fitted} of {int(np.sum(self.status >= 0))} curves fitted"
        return draw_map(self.mu_H, self.x, self.y, title, out=out, ax=ax, dpi=dpi)

    def pixel(self, ix, iy) -> MapPixel:
        """The curve at grid index ``(ix, iy)`` (:class:`~shellbvp.map_pixels.MapPixel`; its rows
        None in a file written before the per-curve view); ValueError (one line, the valid
        range) outside the grid or where no curve was measured."""
        if self.curves is None:
            raise ValueError(f"{self.path}: no per-curve rows (/entry/curves)")
        return self.curves.pixel(ix, iy)

    def plot_pixel(self, ix, iy, out=None, axes=None, dpi=150):
        """One pixel's data, model and residuals (``shellbvp plot map.h5 --pixel IX,IY``), saved
        to ``out`` when given; ValueError for a file that stores no curve data (what it can
        show instead) and for a pixel off the grid."""
        pixel = self.pixel(ix, iy)
        if not self.curves.has_data:
            raise ValueError(self.curves.no_data_reason())
        return draw_pixel(pixel, out=out, axes=axes, dpi=dpi)

    def pixels(self, which="all") -> list:
        """Grid indices ``(ix, iy)`` of every curve (``"all"``) or of those whose fit did not
        succeed (``"failed"``: failed its checks, or an error)."""
        if self.curves is None:
            raise ValueError(f"{self.path}: no per-curve rows (/entry/curves)")
        return self.curves.select(which)


def is_map_file(path) -> bool:
    """True when ``path`` is an HDF5 file of format :data:`MAP_FORMAT`."""
    import h5py

    try:
        with h5py.File(path, "r") as h:
            fmt = h.attrs.get("format")
    except (OSError, ValueError):
        return False
    return isinstance(fmt, (str, bytes)) and (fmt.decode() if isinstance(fmt, bytes) else fmt) == MAP_FORMAT


def read_map_file(path) -> MapFile:
    """A force-map file, every item checked as data (:mod:`shellbvp.schema`).

    Raises
    ------
    ValueError
        Not a force-map file, or an item missing or malformed (naming it).
    """
    with open_hdf5(path, fmt=MAP_FORMAT, group="entry/map", kind="force-map") as h:
        try:
            sc.format_version(h, MAP_FORMAT_VERSION)
            m = h["entry/map"]
            images = {k: sc.dataset(m, k, ndim=2) for k in ("mu_H", "mu_H_low", "mu_H_high")}
            status = sc.dataset(m, "status", kind="int", ndim=2)
            shapes = {a.shape for a in (*images.values(), status)}
            if len(shapes) != 1:
                raise ValueError(f"map images differ in shape ({sorted(shapes)})")
            ny, nx = status.shape
            x = y = None
            if "x" in m and "y" in m:
                x, y = sc.dataset(m, "x", length=nx), sc.dataset(m, "y", length=ny)
            sample = sc.attr_text(h["entry/sample"], "description") if "entry/sample" in h else ""
            source = sc.text_dataset(h["entry/source"], "file_name", ndim=0) if "entry/source" in h else ""
            curves = read_curves(h, (nx, ny), path, printable(source)) if "entry/curves" in h else None
        except (ValueError, KeyError, TypeError, OSError) as exc:
            what = str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"
            raise ValueError(f"{path}: incomplete or corrupt force-map file ({what})") from None
    return MapFile(path=str(path), **images, status=status.astype(int), x=x, y=y, sample=sample, source=source,
                   curves=curves)
