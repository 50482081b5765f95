"""One pixel of a force map: its data against its fitted model (issue 56, item B).

A force-map file (:meth:`shellbvp.afm.ForceMap.to_hdf5`) keeps, beside its images, each curve's
fitted rows and the fitted model at them, compactly (float32, gzip), so that one pixel's fit can
be drawn from the file alone (``shellbvp plot map.h5 --pixel IX,IY``;
:meth:`shellbvp.afm.MapFile.plot_pixel`)::

    /entry/curve_data     NXcollection: curve i's rows are start[i]:start[i+1] of the arrays
      start         (n+1,)  1   where each curve's rows begin (curves in the order of /entry/curves)
      displacement  (N,)    m   displacement as read (float32)
      force         (N,)    N   force as read (float32)
      model_force   (N,)    N   the fitted model at those rows, baseline included (NaN: no fit)
      rows_fitted   (n,)    1   the rows the fit used, before thinning
    /entry/curves         gains quality, warning_codes and warnings (text per curve; several
                          codes joined by ",", several warnings by " | ")

Thinning (:func:`thin_rows`): of a curve's fitted rows at most :data:`MAX_ROWS_PER_CURVE` are
kept, half of them at or beyond the fitted contact point, a quarter within one contact depth
before it and a quarter from the rest, and at most :data:`MAX_STORED_ROWS` over the whole map (a
map of more than 2097 curves keeps fewer per curve).  A map file written before this layout has neither: it still
shows the map and each curve's numbers (:meth:`MapCurves.pixel`), not its data and model.

A map fitted in one pass (:func:`shellbvp.batch.fit_map`) keeps no records: each curve's rows are
thinned when it is fitted, with the model at them (:func:`curve_rows`, :class:`CurveRows` in its
row), so that a map holds at most :data:`MAX_STORED_ROWS` rows whatever its size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import schema as sc
from .nexus import number_dataset, string_dataset
from .textdata import printable

__all__ = ["MapPixel", "MapCurves", "CurveRows", "curve_rows", "MAX_ROWS_PER_CURVE", "MAX_STORED_ROWS",
           "PIXEL_CHOICES", "thin_rows", "rows_per_curve", "write_curve_data", "read_curves", "parse_pixel",
           "pixel_of_row", "locate"]

#: At most this many of a curve's fitted rows are stored (enough for a figure)
MAX_ROWS_PER_CURVE = 1000
#: At most this many rows over the whole map (3 float32 arrays: 24 MiB before compression)
MAX_STORED_ROWS = 2**21
#: Which pixels ``--pixels`` draws: every curve's, or those whose fit did not succeed
PIXEL_CHOICES = ("all", "failed")


def _evenly(a, k):
    """``k`` elements of ``a`` evenly spaced in it, its first and last among them (k >= 2)."""
    if k <= 0 or a.size == 0:
        return a[:0]
    if k >= a.size:
        return a
    return a[np.unique(np.linspace(0, a.size - 1, k).round().astype(int))]


def thin_rows(rows, displacement, offset, budget=MAX_ROWS_PER_CURVE) -> np.ndarray:
    """The row indices kept of ``rows`` (sorted indices into ``displacement``): all of them when
    at most ``budget``; otherwise half the budget from the rows at or beyond the contact point
    ``offset``, a quarter from the rows within one contact depth before it and a quarter from the
    rest (a group with fewer rows leaves its share to the next, in that order), each evenly
    spaced in the rows' order with its first and last row.

    Examples
    --------
    >>> import numpy as np
    >>> d = np.arange(40.0)        # contact at 30, the deepest row 9 beyond it
    >>> thin_rows(np.arange(40), d, offset=30.0, budget=16).tolist()
    [0, 7, 13, 20, 21, 24, 26, 29, 30, 31, 33, 34, 35, 36, 38, 39]
    """
    rows = np.asarray(rows, dtype=np.int64)
    if rows.size <= budget:
        return rows
    if not math.isfinite(offset):
        return _evenly(rows, budget)
    x = np.asarray(displacement, float)[rows]
    depth = max(float(np.max(x)) - offset, 0.0)
    groups = [rows[x >= offset], rows[(x < offset) & (x >= offset - depth)], rows[x < offset - depth]]
    take = [min(g.size, share) for g, share in zip(groups, (budget // 2, budget // 4, budget - 3 * (budget // 4)))]
    spare = budget - sum(take)
    for i, g in enumerate(groups):
        extra = min(spare, g.size - take[i])
        take[i], spare = take[i] + extra, spare - extra
    return np.sort(np.concatenate([_evenly(g, k) for g, k in zip(groups, take)]))


@dataclass
class CurveRows:
    """One curve's fitted rows as a map keeps them without its record: thinned
    (:func:`thin_rows`), with the fitted model at them, float32 as the map file stores them.

    Attributes
    ----------
    displacement, force, model_force : ndarray
        m, N, N (``model_force`` NaN: no fit).
    rows_fitted : int
        The rows the fit used, before thinning.
    offset : float
        The fitted contact point (m; NaN: no fit), where a thinner file thins them again.
    """

    displacement: np.ndarray
    force: np.ndarray
    model_force: np.ndarray
    rows_fitted: int
    offset: float = math.nan


def curve_rows(d, f, result, budget=MAX_ROWS_PER_CURVE) -> CurveRows:
    """The :class:`CurveRows` of a curve's fitted rows ``d``, ``f`` (m, N, in the record's
    order) and its fit ``result`` (a FitResult, or None: no model), at most ``budget`` rows."""
    d, f = np.asarray(d, float), np.asarray(f, float)
    offset = result.offset if result is not None and result.offset is not None else math.nan
    keep = thin_rows(np.arange(d.size), d, offset, budget)
    model = np.asarray(result.model_force(d[keep]), float) if result is not None else np.full(keep.size, np.nan)
    return CurveRows(*(a.astype(np.float32) for a in (d[keep], f[keep], model)), rows_fitted=int(d.size),
                     offset=float(offset))


def _row_arrays(row, result, segment, budget):
    """``(displacement, force, model_force, rows fitted)`` of one curve of a map (its
    :class:`~shellbvp.batch.BatchRow`: its kept :class:`CurveRows`, else its record's rows),
    thinned, float32 (empty arrays when its rows cannot be read)."""
    empty = np.empty(0, np.float32)
    kept = getattr(row, "curve_rows", None)
    if kept is None:
        record, used = row.record, row.used
        if record is None:
            return empty, empty, empty, 0
        if used is None:  # an error row: the segment's rows, if they can be read
            try:
                used = record.mask(segment)
            except ValueError:
                return empty, empty, empty, 0
        rows = np.flatnonzero(np.asarray(used, bool))
        kept = curve_rows(record.displacement[rows], record.force[rows], result, budget)
    arrays = (kept.displacement, kept.force, kept.model_force)
    if kept.displacement.size > budget:  # kept for a larger budget: thinned again
        keep = thin_rows(np.arange(kept.displacement.size), kept.displacement, kept.offset, budget)
        arrays = tuple(a[keep] for a in arrays)
    return (*arrays, kept.rows_fitted)


def rows_per_curve(n_curves, max_rows=MAX_STORED_ROWS) -> int:
    """How many of a curve's fitted rows a map of ``n_curves`` curves keeps: at most
    :data:`MAX_ROWS_PER_CURVE`, and ``max_rows`` over the map (at least one).

    Examples
    --------
    >>> rows_per_curve(4), rows_per_curve(128 * 128), rows_per_curve(1024 * 1024)
    (1000, 128, 2)
    """
    return max(1, min(MAX_ROWS_PER_CURVE, max_rows // max(n_curves, 1)))


def _joined(result, attr, sep):
    return "" if result is None else sep.join(printable(str(w)) for w in getattr(result, attr))


def write_curve_data(entry, rows, segment="loading", max_rows=MAX_STORED_ROWS):
    """Each curve's quality and warnings into ``entry/curves`` and its thinned fitted rows with
    the model at them into ``entry/curve_data`` (module docstring); ``rows`` are the map's
    :class:`~shellbvp.batch.BatchRow` in the order of ``entry/curves``, ``max_rows`` the most
    rows over the map (:func:`rows_per_curve`)."""
    c = entry["curves"]
    results = [r.result if r.status in ("ok", "failed") else None for r in rows]
    string_dataset(c, "quality", ["" if r is None else r.quality for r in results],
                   "good, fair or poor (the fit's rating); empty: no fit")
    string_dataset(c, "warning_codes", [_joined(r, "warning_codes", ",") for r in results],
                   "the kinds of the fit's warnings, joined by ','")
    string_dataset(c, "warnings", [_joined(r, "warnings", " | ") for r in results],
                   "the fit's warnings, joined by ' | '")
    budget = rows_per_curve(len(rows), max_rows)
    parts = [_row_arrays(r, res, segment, budget) for r, res in zip(rows, results)]
    start = np.r_[0, np.cumsum([p[0].size for p in parts])].astype(np.int64)
    g = entry.create_group("curve_data")
    g.attrs.update({"NX_class": "NXcollection", "max_rows_per_curve": budget})
    number_dataset(g, "start", start, "1", "curve i's rows are start[i]:start[i+1] (order of /entry/curves)")
    for k, (name, unit, what) in enumerate((("displacement", "m", "displacement as read, the fitted rows (thinned)"),
                                             ("force", "N", "force as read, the fitted rows (thinned)"),
                                             ("model_force", "N", "fitted model at those rows, baseline included; "
                                              "NaN: no fit"))):
        data = np.concatenate([p[k] for p in parts]).astype(np.float32, copy=False) if parts else \
            np.empty(0, np.float32)
        ds = g.create_dataset(name, data=data, compression="gzip" if data.size else None,
                              shuffle=bool(data.size))
        ds.attrs.update({"units": unit, "long_name": what})
    number_dataset(g, "rows_fitted", np.array([p[3] for p in parts], dtype=np.int64), "1",
                   "rows the fit used, before thinning")


@dataclass
class MapPixel:
    """One curve of a force map: its fit's numbers and (where stored) its fitted rows with the
    model at them (SI units).

    Attributes
    ----------
    grid : (int, int)
        ``(ix, iy)`` on the map's grid.
    index : int
        The curve in the AFM file.
    status : str
        ``ok``, ``failed`` (its checks) or ``error``.
    message : str
    mu_H : float
        N/m (NaN without a fit).
    mu_H_ci95 : (float, float)
    offset : float
        The fitted contact point, m.
    quality : str
        ``good``, ``fair``, ``poor``; ``""`` without a fit or from an older file.
    warnings, warning_codes : list of str
    displacement, force, model_force : ndarray or None
        The stored rows (m, N, N); None: the file stores no curve data.
    rows_fitted : int or None
    source : str
        The AFM file.
    """

    grid: tuple
    index: int
    status: str
    message: str
    mu_H: float
    mu_H_ci95: tuple
    offset: float
    quality: str = ""
    warnings: list = field(default_factory=list)
    warning_codes: list = field(default_factory=list)
    displacement: object = None
    force: object = None
    model_force: object = None
    rows_fitted: object = None
    source: str = ""

    @property
    def residual(self):
        """model - data at the stored rows (N), or None."""
        return None if self.force is None else self.model_force - self.force

    def line(self) -> str:
        """One line: the pixel, its status, mu*H and its interval, its rating."""
        lo, hi = self.mu_H_ci95
        fit = (f"mu*H = {self.mu_H:.4g} N/m, 95% CI [{lo:.4g}, {hi:.4g}]" if math.isfinite(self.mu_H)
               else "no mu*H")
        return (f"pixel {self.grid}: {self.status}; {fit}" + (f"; quality {self.quality}" if self.quality else "")
                + (f"; warnings: {', '.join(self.warning_codes)}" if self.warning_codes else ""))


def pixel_of_row(curve, row, n_curves, segment="loading", source="") -> MapPixel:
    """The :class:`MapPixel` of one curve of an in-memory map (``curve``, its ``row``), thinned
    as :func:`write_curve_data` stores it for a map of ``n_curves`` curves."""
    res = row.result if row.status in ("ok", "failed") else None
    *arrays, n = _row_arrays(row, res, segment, rows_per_curve(n_curves))
    d, f, m = (np.asarray(a, float) for a in arrays)
    nan = math.nan
    return MapPixel(grid=tuple(curve.grid), index=int(curve.index), status=row.status, message=row.message,
                    mu_H=nan if res is None else float(res.mu_H),
                    mu_H_ci95=(nan, nan) if res is None else tuple(float(v) for v in res.mu_H_ci95),
                    offset=nan if res is None or res.offset is None else float(res.offset),
                    quality="" if res is None else res.quality,
                    warnings=[] if res is None else list(res.warnings),
                    warning_codes=[] if res is None else list(res.warning_codes),
                    displacement=d, force=f, model_force=m, rows_fitted=n, source=source)


@dataclass
class MapCurves:
    """The per-curve rows of a force-map file (``/entry/curves`` and, where stored,
    ``/entry/curve_data``), as :func:`read_curves` reads them.  ``shape`` is the map's ``(nx, ny)``."""

    shape: tuple
    index: np.ndarray
    grid: np.ndarray
    status: list
    message: list
    mu_H: np.ndarray
    mu_H_ci95: np.ndarray
    offset: np.ndarray
    quality: object = None
    warning_codes: object = None
    warnings: object = None
    start: object = None
    displacement: object = None
    force: object = None
    model_force: object = None
    rows_fitted: object = None
    path: str = ""
    source: str = ""

    @property
    def has_data(self) -> bool:
        return self.start is not None

    def where(self, ix, iy) -> int:
        """The curve at ``(ix, iy)`` (:func:`locate`)."""
        return locate(self.grid, self.shape, ix, iy)

    def pixel(self, ix, iy) -> MapPixel:
        """The :class:`MapPixel` at grid index ``(ix, iy)`` (its data None in an older file)."""
        i = self.where(ix, iy)
        text = (lambda col, sep: [] if col is None or not col[i] else col[i].split(sep))
        out = MapPixel(grid=(int(ix), int(iy)), index=int(self.index[i]), status=self.status[i],
                       message=self.message[i], mu_H=float(self.mu_H[i]),
                       mu_H_ci95=(float(self.mu_H_ci95[i, 0]), float(self.mu_H_ci95[i, 1])),
                       offset=float(self.offset[i]), quality="" if self.quality is None else self.quality[i],
                       warnings=text(self.warnings, " | "), warning_codes=text(self.warning_codes, ","),
                       source=self.source)
        if self.has_data:
            a, b = int(self.start[i]), int(self.start[i + 1])
            out.displacement, out.force, out.model_force = (np.asarray(x[a:b], float) for x in
                                                           (self.displacement, self.force, self.model_force))
            out.rows_fitted = int(self.rows_fitted[i])
        return out

    def select(self, which) -> list:
        """Grid indices ``(ix, iy)`` of the curves ``which`` names (:data:`PIXEL_CHOICES`): every
        curve's, or those whose fit did not succeed (failed its checks or an error)."""
        if which not in PIXEL_CHOICES:
            raise ValueError(f"--pixels must be one of {', '.join(PIXEL_CHOICES)}; got {printable(which)!r}")
        return [(int(g[0]), int(g[1])) for g, s in zip(self.grid, self.status) if g[0] >= 0
                and (which == "all" or s != "ok")]

    def summary_lines(self) -> list:
        """What ``shellbvp info`` adds about the curves: their ratings and whether each curve's
        rows are stored (what ``shellbvp plot --pixel`` draws)."""
        lines = []
        if self.quality is not None:
            rated = [q for q in self.quality if q]
            lines.append("quality:   " + ", ".join(f"{q} {rated.count(q)}" for q in ("good", "fair", "poor")))
        if self.has_data:
            lines.append(f"curves:    each curve's fitted rows and model stored ({int(self.start[-1])} rows of "
                         f"{int(np.sum(self.rows_fitted))} fitted): shellbvp plot FILE --pixel IX,IY")
        else:
            lines.append("curves:    no rows stored (a file from before the per-curve view): the map and each "
                         "curve's numbers only")
        return lines

    def no_data_reason(self) -> str:
        """Why an older file cannot show a pixel's fit (one line)."""
        return (f"{self.path}: this map file stores no curve data (written before the per-curve view): it "
                f"shows the map and each curve's mu*H, status and message (`shellbvp info`), not a pixel's "
                f"data and model; fit the map again with this version to view its pixels")


def locate(grid, shape, ix, iy) -> int:
    """The position in ``grid`` (``(n, 2)`` grid indices of a map's curves) of the curve at
    ``(ix, iy)``; ValueError (one line, with the valid range) outside the map's ``shape``
    ``(nx, ny)`` or where no curve was measured."""
    nx, ny = shape
    if not (0 <= ix < nx and 0 <= iy < ny):
        raise ValueError(f"pixel ({ix}, {iy}) is outside the map's {nx} x {ny} grid: ix 0..{nx - 1}, iy 0..{ny - 1}")
    grid = np.asarray(grid, dtype=np.int64).reshape(-1, 2)
    hit = np.flatnonzero((grid[:, 0] == ix) & (grid[:, 1] == iy))
    if hit.size == 0:
        cells = ", ".join(str((int(g[0]), int(g[1]))) for g in grid[:8]) + (", ..." if len(grid) > 8 else "")
        raise ValueError(f"pixel ({ix}, {iy}): no curve was measured there; the map's {len(grid)} curves are at "
                         f"{cells}")
    return int(hit[0])


def read_curves(h, shape, path="", source="") -> MapCurves:
    """``/entry/curves`` (and ``/entry/curve_data`` where present) of an open map file, every
    item checked (:mod:`shellbvp.schema`; ValueError naming it)."""
    import h5py

    for name in ("entry/curves", "entry/curve_data"):
        if name in h and not isinstance(h[name], h5py.Group):
            raise ValueError(f"{name.split('/')[-1]} must be a group")
    c = h["entry/curves"]
    index = sc.dataset(c, "index", kind="int")
    n = index.size
    grid = sc.dataset(c, "grid_index", kind="int", ndim=2)
    ci = sc.dataset(c, "mu_H_ci95", ndim=2)
    if grid.shape != (n, 2) or ci.shape != (n, 2):
        raise ValueError(f"grid_index and mu_H_ci95 must have shape ({n}, 2)")
    out = MapCurves(shape=tuple(shape), index=index, grid=grid, status=sc.text_dataset(c, "status", length=n),
                    message=[printable(m) for m in sc.text_dataset(c, "message", length=n)],
                    mu_H=sc.dataset(c, "mu_H", length=n), mu_H_ci95=ci, offset=sc.dataset(c, "offset", length=n),
                    path=str(path), source=source)
    for name in ("quality", "warning_codes", "warnings"):
        if name in c:
            setattr(out, name, [printable(t) for t in sc.text_dataset(c, name, length=n)])
    if "entry/curve_data" in h:
        g = h["entry/curve_data"]
        start = sc.dataset(g, "start", kind="int", length=n + 1)
        arrays = [sc.dataset(g, name) for name in ("displacement", "force", "model_force")]
        total = arrays[0].size
        if start[0] != 0 or start[-1] != total or np.any(np.diff(start) < 0) or any(a.size != total for a in arrays):
            raise ValueError(f"curve_data: start must rise from 0 to the {total} rows of displacement, force "
                             f"and model_force")
        out.start = start
        out.displacement, out.force, out.model_force = arrays
        out.rows_fitted = sc.dataset(g, "rows_fitted", kind="int", length=n)
    return out


def parse_pixel(text) -> tuple:
    """``"IX,IY"`` (two integers >= 0) as ``(ix, iy)``; ValueError naming ``--pixel`` otherwise.

    Examples
    --------
    >>> parse_pixel("3, 0")
    (3, 0)
    """
    parts = str(text).split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        ix, iy = (int(p.strip()) for p in parts)
    except ValueError:
        raise ValueError(f"--pixel takes the grid index IX,IY (two integers >= 0, as the map's warnings name "
                         f"pixels); got {printable(text)!r}") from None
    if ix < 0 or iy < 0:
        raise ValueError(f"--pixel {ix},{iy}: grid indices start at 0")
    return ix, iy
