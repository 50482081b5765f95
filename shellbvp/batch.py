"""Fitting many instrument files with one scene and one set of settings.

Experimenters measure dozens of seeds: :func:`fit_files` fits each file's segment with
the same scene, radius and settings, continues past a file that cannot be read or
fitted (its row says why), and reuses the model curve: every file whose depth is
comparable shares one delta grid (1.2 x the deepest file's depth), so the curve is
computed once (the fit's curve cache) instead of once per file.  :func:`write_table`
writes one row per file (CSV, units in the header, written atomically).
"""

from __future__ import annotations

import csv
import glob
import io
import logging
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import readers
from .afm import ForceMap, map_shape
from .afm_read import AFMCurve
from .fitting import N_DEPTHS, fit, fit_record
from .fitting.curves import ModelCurves
from .map_fit import finish, fit_pixels, read_pixels, record_depth
from .map_pixels import curve_rows, rows_per_curve
from .paths import atomic_file, check_output_path
from .scene_parameters import LiveNames, scene_parameter
from .shape_parameters import DERIVED, SHAPE_PARAMETERS, shape_parameter
from .textdata import table_cell

log = logging.getLogger(__name__)

__all__ = ["BatchRow", "fit_files", "fit_records", "fit_map", "shared_curves", "read_record", "expand_inputs", "write_table",
           "TABLE_COLUMNS", "DATA_SUFFIXES"]

#: The file name endings a directory given as input contributes: each reader's
#: (:mod:`shellbvp.readers`; text tables, AFM single curves)
DATA_SUFFIXES = readers.folder_suffixes()


def _with_unit(name, unit):
    return name if unit == "1" else f"{name} ({unit})"


def _estimate_columns(name, unit):
    return tuple(_with_unit(f"{name}{part}", unit) for part in ("", " 95% low", " 95% high"))


#: Columns of the results table, with their units: a shape parameter's and its derived
#: quantities' (:mod:`shellbvp.shape_parameters`) are filled where it was fitted.
TABLE_COLUMNS = LiveNames(lambda: (
    "file", "status", "quality", "model", "model error (1)", "mu_H (N/m)", "mu_H 95% low (N/m)", "mu_H 95% high (N/m)",
    "offset (m)", "offset 95% low (m)", "offset 95% high (m)", "baseline (N)", "baseline 95% low (N)",
    "baseline 95% high (N)", "baseline slope (N/m)", "baseline model",
    *(c for p in SHAPE_PARAMETERS.values() for c in _estimate_columns(p.name, p.unit)),
    *(c for d in DERIVED.values() for c in _estimate_columns(d.name, d.unit)),
    "residual rms (N)", "points", "segment", "warnings", "message", "sha256"))


@dataclass
class BatchRow:
    """The outcome for one file of a batch.

    Attributes
    ----------
    file : str
    status : str
        ``"ok"`` (the fit succeeded; warnings allowed), ``"failed"`` (the fit ran but failed
        its checks) or ``"error"`` (the file could not be read or fitted: ``message`` says why).
    result : FitResult or None
    record : InstrumentRecord or None
    used : ndarray of bool or None
        The rows fitted.
    message : str
    extra : dict
        More columns of its table row (a map's: the file's ``sha256``, a pixel table's value).
    curve_rows : CurveRows or None
        A force map's row (:func:`fit_map`, which keeps no ``record``): the rows fitted, thinned,
        with the model at them (:class:`shellbvp.map_pixels.CurveRows`), for the pixel's view.
    """

    file: str
    status: str
    result: object = None
    record: object = None
    used: object = None
    message: str = ""
    extra: dict = field(default_factory=dict)
    curve_rows: object = None

    def table_row(self, segment: str) -> dict:
        """This file's row of the results table (:data:`TABLE_COLUMNS`)."""
        row = dict.fromkeys(TABLE_COLUMNS, "")
        # names and messages are text from files: escaped for terminals and spreadsheets
        row.update({"file": table_cell(self.file), "status": self.status, "segment": segment,
                    "message": table_cell(self.message)})
        row.update(self.extra)
        if self.record is not None:
            row["sha256"] = self.record.sha256
        r = self.result
        if r is None:
            return row

        def put(key, value, ci=None, unit="1"):
            columns = _estimate_columns(key, unit)
            row[columns[0]] = _num(value)
            if ci is not None:
                row[columns[1]], row[columns[2]] = _num(ci[0]), _num(ci[1])

        put("mu_H", r.mu_H, r.mu_H_ci95, "N/m")
        if "offset" in r.fitted:
            put("offset", r.offset, r.offset_ci95, "m")
        if r.baseline_model != "none":
            put("baseline", r.baseline, r.baseline_ci95, "N")
        if r.baseline_model == "linear":
            put("baseline slope", r.baseline_slope, None, "N/m")
        for name, p in SHAPE_PARAMETERS.items():
            if name in r.fitted:
                put(name, r.shape_values[name], r.shape_ci95[name], p.unit)
        if "thickness" not in r.fitted and r.thickness is not None:  # given: exact, no interval; H in m
            put("thickness", r.thickness, None, SHAPE_PARAMETERS["thickness"].unit)
        for name, e in r.derived.items():  # a fitted parameter's, and mu and E of a given thickness
            put(name, e.value, e.ci95, e.unit)
        row["quality"] = r.quality
        row["model"] = r.model
        row["model error (1)"] = "" if r.model_error is None else _num(r.model_error[0])
        row["baseline model"] = r.baseline_model
        row["residual rms (N)"] = _num(r.residual_rms)
        row["points"] = str(r.n)
        row["warnings"] = " | ".join(r.warnings)
        return row


def _num(v):
    return "" if v is None or not math.isfinite(v) else f"{v:.8g}"


def expand_inputs(inputs) -> list:
    """File names from files, directories (their files ending as the readers take them in a folder,
    :func:`shellbvp.readers.folder_suffixes`, sorted) and glob patterns (for shells that do not
    expand them); order kept, no repeats.

    Raises
    ------
    ValueError
        An input that is no file, directory or matching pattern; a directory without data files.
    """
    out = []
    for item in inputs:
        p = Path(item)
        if p.is_dir():
            # every entry named like data, files or not: a FIFO, a folder named x.csv or a
            # symlink loop gets its own row saying why it was not read, instead of vanishing
            taken = readers.folder_suffixes()
            found = sorted(q for q in p.iterdir() if q.suffix.lower() in taken)
            if not found:
                raise ValueError(f"{item}: a directory without data files ({', '.join(taken)})")
            out += [str(q) for q in found]
        elif p.exists():
            out.append(str(p))
        elif any(ch in str(item) for ch in "*?["):
            found = sorted(glob.glob(str(item)))
            if not found:
                raise ValueError(f"{item}: no file matches this pattern")
            out += found
        else:
            out.append(str(p))  # a missing file: its row will say so
    seen, unique = set(), []
    for name in out:
        if name not in seen:
            seen.add(name)
            unique.append(name)
    return unique


def fit_files(scene, paths, *, R_L, segment="loading", baseline="auto", columns=None, units=None,
              invert=(), spring_constant=None, sensitivity=None, on_file=None, **options) -> list:
    """Fit each file with the same scene and settings; one :class:`BatchRow` per file.

    Parameters
    ----------
    scene : Scene
    paths : sequence of str
        Instrument files (:func:`expand_inputs` turns directories and patterns into these).
    R_L : float
        Rim radius (m), the same for every file.
    segment, baseline : str
        As :func:`shellbvp.fitting.fit_record`.
    columns, units, invert : sequence, optional
        As :func:`shellbvp.instrument.read_instrument`.
    spring_constant, sensitivity : float, optional
        AFM text exports' calibration (:func:`shellbvp.afm.read_afm`).
    on_file : callable, optional
        Called as ``on_file(row)`` after each file (a progress bar over files).
    **options
        Passed to :func:`shellbvp.fitting.fit` (``fit_offset``, ``free``, ``weights``, ``tol``,
        ``progress`` of the model curves...).

    Returns
    -------
    list of BatchRow
        In the order of ``paths``.  A file that cannot be read or fitted (a ``ValueError``)
        gets status ``"error"`` with the message; the others are fitted regardless.

    Examples
    --------
    Two seeds made from the shipped example (mu*H = 52 N/m; the second with 1.5 x the
    force, 78 N/m) and a file that is not a record: one model curve serves both fits.

    >>> import os, tempfile, shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> folder = tempfile.mkdtemp()
    >>> rows = open(example_data_path()).read().splitlines()[2:]      # after the comment and header
    >>> for name, scale in (("seed_a.csv", 1.0), ("seed_b.csv", 1.5)):
    ...     with open(os.path.join(folder, name), "w") as fh:
    ...         _ = fh.write("displacement (mm),force (mN)\\n")
    ...         _ = fh.writelines(f"{a},{scale * float(b):.6f}\\n" for a, b in (r.split(",") for r in rows))
    >>> with open(os.path.join(folder, "notes.csv"), "w") as fh:
    ...     _ = fh.write("seed,remark\\na,cracked\\n")
    >>> paths = [os.path.join(folder, n) for n in ("seed_a.csv", "seed_b.csv", "notes.csv")]
    >>> out = sb.fit_files(sb.Scene.preset("fit"), paths, R_L=0.3e-3)
    >>> [(os.path.basename(r.file), r.status) for r in out]
    [('seed_a.csv', 'ok'), ('seed_b.csv', 'ok'), ('notes.csv', 'error')]
    >>> [round(r.result.mu_H) for r in out[:2]]
    [52, 78]
    >>> out[2].message
    '...notes.csv: ...'
    """
    read = []
    for path in paths:  # read every file first: the common depth of the model curves
        try:
            read.append((path, read_record(path, columns=columns, units=units, invert=invert,
                                           spring_constant=spring_constant, sensitivity=sensitivity)))
        except ValueError as exc:
            read.append((path, exc))
    return fit_records(scene, read, R_L=R_L, segment=segment, baseline=baseline, on_file=on_file, **options)


def read_record(path, *, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None):
    """One record from a file, read by its reader (:func:`shellbvp.readers.read_record`): an AFM
    curve through afmformats (:mod:`shellbvp.afm`; an AFM text export with the cantilever's
    ``spring_constant`` and ``sensitivity``), a text export as
    :func:`shellbvp.instrument.read_instrument` reads it.  A force map is refused here (it is
    fitted on its own: :func:`fit_map`)."""
    return readers.read_record(path, columns=columns, units=units, invert=invert, spring_constant=spring_constant,
                               sensitivity=sensitivity)


def fit_records(scene, named, *, R_L, segment="loading", baseline="auto", on_file=None, **options) -> list:
    """:func:`fit_files` on records already read: ``named`` is a list of ``(name, record)``, a
    ``ValueError`` in place of a record that could not be read (its row says why).  Records of
    comparable depth share one model curve."""
    paths = [name for name, _ in named]
    records, rows = {}, {}
    for path, rec in named:
        if isinstance(rec, Exception):
            rows[path] = BatchRow(file=path, status="error", message=" ".join(str(rec).split()))
        else:
            records[path] = rec
    depths = _depths(records, segment, R_L)
    finite = [v for v in depths.values() if math.isfinite(v) and v > 0]
    common = 1.2 * max(finite) if finite else None
    out = []
    for path in paths:
        if path not in rows:
            rec = records[path]
            own = depths.get(path)
            # files of comparable depth share one grid, hence one model curve (cached)
            dm = common if (common is not None and own is not None and 1.2 * own >= 0.5 * common
                            and "delta_max" not in options) else options.get("delta_max")
            kwargs = {k: v for k, v in options.items() if k != "delta_max"}
            try:
                res, used = fit_record(scene, rec, R_L=R_L, segment=segment, baseline=baseline, delta_max=dm,
                                       **kwargs)
                rows[path] = BatchRow(file=path, status="ok" if res.success else "failed", result=res, record=rec,
                                      used=used, message=res.message)
            except ValueError as exc:
                rows[path] = BatchRow(file=path, status="error", record=rec, message=" ".join(str(exc).split()))
        log.info("batch: %s: %s", path, rows[path].status)
        out.append(rows[path])
        if on_file is not None:
            on_file(rows[path])
    return out


def _depths(records, segment, R_L) -> dict:
    """``{name: deepest datum's delta}`` of each record's ``segment`` beyond its contact estimate
    (records whose segment cannot be read are left out: their fits say why)."""
    depths = {path: record_depth(rec, segment, R_L) for path, rec in records.items()}
    return {path: v for path, v in depths.items() if v is not None}


def fit_map(scene, curves, *, R_L, path=None, segment="loading", baseline="auto", on_curve=None,
            pixel_values=None, **options):
    """Fit every curve of a force map (:func:`shellbvp.afm.read_afm`, or one at a time
    :func:`shellbvp.afm_read.iter_afm`) with one scene: a :class:`shellbvp.afm.ForceMap`.

    The curves are taken once, in order: of each only the rows fitted are kept (in a temporary
    file) and its place on the map (:func:`shellbvp.map_fit.read_pixels`).  Curves of comparable
    depth share one model curve (as :func:`fit_records`), and their fits run together on it in
    chunks (:func:`shellbvp.map_fit.fit_pixels`, :mod:`shellbvp.fitting.batched`): a map costs
    about one model curve plus a cheap least-squares fit per curve, its results per curve the
    same as one :func:`shellbvp.fitting.fit_record` each.  The rows keep each fit's numbers and
    its fitted rows thinned with the model at them (``BatchRow.curve_rows``: what the map file
    keeps for a pixel's view, :mod:`shellbvp.map_pixels`), not the records (``BatchRow.record``
    and ``used`` are None; the file's checksum is in ``extra``).

    With ``pixel_values`` (a :class:`shellbvp.pixel_table.PixelTable`: a shape parameter per
    pixel, e.g. the thickness from :func:`shellbvp.pixel_table.read_pixel_table`) each pixel's
    scene is ``scene`` with that value, held fixed: model curves are computed at a few nodes
    spanning the table's range (:func:`shared_curves`), and each pixel's mu*H, offset and
    baseline are fitted on the curve interpolated at its value -- no curve per pixel.  A pixel
    of the map missing from the table gets an error row naming it; a table that is not valid for
    this map and scene (a pixel outside the grid, a value out of range, a map without grid
    indices) is a ``ValueError`` before any curve.
    """
    pixels, store = read_pixels(curves, path, R_L=R_L, segment=segment, baseline=baseline,
                                fit_offset=options.get("fit_offset", True))
    try:
        if not pixels:
            raise ValueError("fit_map: no curves")
        path = path or pixels[0].name.rsplit("#", 1)[0]
        light = [p.curve for p in pixels]
        shape = map_shape(light, path)  # bounded before any curve is fitted
        settings = {"baseline": baseline, **{k: v for k, v in options.items() if k != "progress"}}
        sha = pixels[0].sha256
        if pixel_values is not None:
            return _fit_map_per_pixel(scene, pixels, store, shape, pixel_values, R_L=R_L, path=path,
                                      segment=segment, on_curve=on_curve, settings=settings, **options)
        fitted, rows = fit_pixels(scene, pixels, store, R_L=R_L, **options), []
        budget = rows_per_curve(len(pixels))
        for p in pixels:  # the fits come in the pixels' order, with their rows
            res, data = next(fitted)[1:] if p.rows is not None else (None, None)
            rows.append(_map_row(p, res, data, budget))
            if on_curve is not None:
                on_curve(rows[-1])
    finally:
        store.close()
    if not any(c.grid is not None for c in light):  # no grid in the file: one row in file order
        light = [AFMCurve(None, c.index, (i, 0), c.position, c.grid_geometry) for i, c in enumerate(light)]
    return ForceMap(path=str(path), curves=light, rows=rows, shape=shape, scene=scene, R_L=R_L, segment=segment,
                    settings=settings, sha256=sha)


def _map_row(pixel, res, data, budget, extra=None, message=None):
    """A map's :class:`BatchRow` of ``pixel`` and its fit (a FitResult or the ValueError; None:
    its segment could not be read, ``pixel.error``, or ``message`` says why it was not fitted),
    with its fitted rows ``data`` (``(d, f)``, or None) thinned to ``budget`` rows."""
    extra = {"sha256": pixel.sha256, **(extra or {})}
    if res is None:
        row = BatchRow(file=pixel.name, status="error", message=message or pixel.error, extra=extra)
    elif isinstance(res, Exception):
        row = BatchRow(file=pixel.name, status="error", message=" ".join(str(res).split()), extra=extra)
    else:
        row = BatchRow(file=pixel.name, status="ok" if res.success else "failed", result=res, message=res.message,
                       extra=extra)
    if data is not None:
        row.curve_rows = curve_rows(*data, res if row.status != "error" else None, budget)
    log.info("map: %s: %s", pixel.name, row.status)
    return row


#: The most model curves a map with a geometry per pixel computes (nodes and checks)
MAX_PIXEL_CURVES = 40


def _pixel_values_checked(scene, curves, shape, table, R_L, options):
    """``{(ix, iy): x}``: the table's nondimensional values, each checked against the scene and
    the map (ValueError naming the table's line otherwise)."""
    if options.get("free") or any(options.get(f"fit_{name}") for name in SHAPE_PARAMETERS):
        raise ValueError(f"a map with {table.name} per pixel fits mu*H, the offset and the baseline on the "
                         f"table's geometry: no shape parameter is fitted with it")
    missing_grid = [c.index for c in curves if c.grid is None]
    if missing_grid:
        raise ValueError(f"curve {missing_grid[0]} of the map has no grid index: a pixel table needs every "
                         f"curve's (ix, iy)")
    nx, ny = shape
    param, declared = shape_parameter(table.name), scene_parameter(table.name)
    if declared.material:  # the scene's material must have it (a given thickness needs no start value)
        why = param.unavailable(scene)
        if why:
            raise ValueError(f"{table.path}: {why}")
    xs = table.nondimensional(R_L)
    for pixel, x in xs.items():
        if not (pixel[0] < nx and pixel[1] < ny):
            raise ValueError(f"{table.where(pixel)}: pixel {pixel} is outside the map's {nx} x {ny} grid")
        given = f"{table.column} = {table.values[pixel]:g}"
        if not (math.isfinite(x) and param.low_ok(x) and param.high_ok(x)):
            raise ValueError(f"{table.where(pixel)}: {given} is out of the range of {param.description}"
                             + (f" ({declared.symbol} = {x:.4g}, R_L = {R_L:g} m)" if table.unit else ""))
        try:
            param.set(scene, x)
        except ValueError as exc:
            raise ValueError(f"{table.where(pixel)}: {given}: {exc}") from None
    return xs


def shared_curves(scene, name, values, grid, need, tol, *, interpolation_tol=None, progress=None,
                  max_curves=MAX_PIXEL_CURVES):
    """Model curves at nodes spanning ``values`` of the shape parameter ``name`` (nondimensional),
    for fits with that parameter fixed at each value: a
    :class:`~shellbvp.fitting.curves.ModelCurves` on ``grid`` whose nodes reach ``need``.

    Nodes are spaced as the parameter's own search (:attr:`ShapeParameter.step`: a factor
    sqrt 2 in the thickness) from the least to the largest value, three at least.  Then, as the profile
    likelihood checks its estimate, a curve is computed at the middle of each interval between
    nodes and compared with the curve interpolated there before it: where
    ``max |F_interp - F| / max |F|`` exceeds ``interpolation_tol`` (default ``tol``, the
    curves' own collocation tolerance) the interval's halves are checked in turn.  Every curve
    computed joins the nodes, so the curves computed are the nodes; ``.interpolation_error`` is
    the largest error of the last check of each interval (None with a single value), and
    ``.notes`` says if ``max_curves`` stopped the refinement first.

    Raises
    ------
    ValueError
        A node's curve ends before ``need`` (the deepest data), or cannot be computed.
    """
    param = shape_parameter(name)
    limit = tol if interpolation_tol is None else float(interpolation_tol)
    curves = ModelCurves(lambda th: param.set(scene, param.from_theta(th)), grid, tol, need, [0], progress)
    curves.notes = []

    def add(theta):
        if not curves.add(theta):
            raise ValueError(f"the model curve at {name} = {param.from_theta(theta):.4g} ends before the deepest "
                             f"data (delta = {need:.4g}): fit shallower data (--max-depth), or check the units and R_L")

    lo, hi = (param.to_theta(v) for v in (min(values), max(values)))
    # at least three nodes: across two a spline in theta is a straight line
    n = max(2, math.ceil((hi - lo) / param.step(scene) - 1e-9)) if hi > lo else 0
    for theta in np.linspace(lo, hi, n + 1):
        add(float(theta))
    errors, todo = [], [(a, b) for a, b in zip(curves.thetas[:-1], curves.thetas[1:])]
    while todo:
        a, b = todo.pop(0)
        if curves.counter[0] >= max_curves:
            curves.notes.append(f"stopped at {max_curves} model curves with intervals between nodes unchecked; "
                                f"the interpolation error there is not known")
            errors.append(math.nan)
            break
        mid = 0.5 * (a + b)
        P, _, top = curves.at(mid)
        add(mid)
        c = curves.nodes[mid]
        k = min(len(c), int(np.sum(grid <= top + 1e-15)))
        err = float(np.max(np.abs(P(c.delta[:k]) - c.force[:k])) / np.max(np.abs(c.force[:k])))
        log.info("shared curves: %s = %.4g: interpolation error %.2g", name, param.from_theta(mid), err)
        if err > limit:
            todo += [(a, mid), (mid, b)]
        else:
            errors.append(err)
    curves.interpolation_error = max(errors) if errors else None
    return curves


def _fit_map_per_pixel(scene, pixels, store, shape, table, *, R_L, path, segment, on_curve, settings,
                       tol=1e-6, delta_max=None, progress=None, **options):
    """:func:`fit_map` with a shape parameter per pixel from ``table``."""
    param = shape_parameter(table.name)
    curves = [p.curve for p in pixels]
    xs = _pixel_values_checked(scene, curves, shape, table, R_L, options)
    inside = [p for p in pixels if p.curve.grid in xs]
    if not inside:
        raise ValueError(f"{table.path}: none of the map's pixels is in the table")
    depths = [p.depth for p in inside if p.depth is not None and math.isfinite(p.depth) and p.depth > 0]
    shared = None
    if depths:
        need = max(depths)
        dm = float(delta_max) if delta_max is not None else 1.2 * need
        grid = dm * np.arange(1, N_DEPTHS + 1) / N_DEPTHS
        shared = shared_curves(scene, table.name, [xs[p.curve.grid] for p in inside], grid, need, tol,
                               progress=progress)
    out, budget = [], rows_per_curve(len(pixels))
    for p in pixels:
        grid_at = p.curve.grid
        data = store.get(p.rows) if p.rows is not None else None
        if grid_at not in xs:
            row = _map_row(p, None, data, budget, message=f"pixel {grid_at} is not in the pixel table {table.path}")
        else:
            x = xs[grid_at]
            res = None
            if data is not None:
                try:
                    if shared is None:
                        raise ValueError("no depth of indentation could be read from any curve of the map")
                    res = fit(param.set(scene, x), *data, R_L=R_L, baseline=p.baseline, contact_guess=p.guess,
                              shared=(shared, param.to_theta(x)), tol=tol, **options)
                    res = finish(res, p)
                except ValueError as exc:
                    res = exc
            row = _map_row(p, res, data, budget, {_pixel_column(param): _num(param.reported(x, R_L))})
        out.append(row)
        if on_curve is not None:
            on_curve(row)
    nodes = tuple(float(param.reported(param.from_theta(t), R_L)) for t in shared.thetas) if shared else ()
    return ForceMap(path=str(path), curves=curves, rows=out, shape=shape, scene=scene, R_L=R_L, segment=segment,
                    settings=settings, pixel_values=table,
                    pixel_nodes=nodes, curves_computed=shared.counter[0] if shared else 0,
                    interpolation_error=shared.interpolation_error if shared else None,
                    notes=list(shared.notes) if shared else [], sha256=pixels[0].sha256)


def _pixel_column(param) -> str:
    """The results table's column of a per-pixel geometry value, with its unit."""
    return _with_unit(f"{param.name} per pixel", param.unit)


def write_table(path, rows, segment="loading", *, overwrite=False):
    """Write the results table (CSV, :data:`TABLE_COLUMNS`, then the rows' extra columns such as
    a force map's geometry per pixel) atomically.

    Raises
    ------
    FileExistsError
        ``path`` exists and ``overwrite`` is False.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (CLI: --overwrite) to replace it")
    check_output_path(path, overwrite=True)
    buf = io.StringIO()
    extra = list(dict.fromkeys(k for row in rows for k in row.extra))
    w = csv.DictWriter(buf, fieldnames=TABLE_COLUMNS + tuple(extra), lineterminator="\n")
    w.writeheader()
    for row in rows:
        w.writerow({**dict.fromkeys(extra, ""), **row.table_row(segment)})
    with atomic_file(path) as tmp:
        tmp.write_text(buf.getvalue(), encoding="utf-8", newline="")
