"""A force map's curves read once, their fitted rows set aside, the pixels fitted together.

:func:`read_pixels` takes a map's curves one at a time (:func:`shellbvp.afm_read.iter_afm`):
of each it keeps what its fit needs -- the rows of the segment fitted (in an unnamed temporary
file, :class:`RowStore`, not in memory), the baseline and contact guess, the depth, the
warnings about its segments -- and its place on the map (an :class:`~shellbvp.afm_read.AFMCurve`
without its record).  :func:`fit_pixels` then fits the pixels in chunks of
:data:`CHUNK` in map order: together on one model curve (:func:`shellbvp.fitting.batched.fit_batch`)
where the options allow it, else one ``fit`` each; of a result only the numbers per pixel stay
(its per-point weights are dropped).  Memory is bounded by the chunk, not the map: a map of
4,096 curves of 1,000 rows held ~95 kB a curve in its records before.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile

import numpy as np

from .afm_read import AFMCurve
from .fitting import fit
from .fitting.batched import batchable, fit_batch
from .fitting.fit_data import record_rows, segment_warnings
from .instrument import estimate_contact

__all__ = ["CHUNK", "Pixel", "RowStore", "read_pixels", "fit_pixels", "finish", "record_depth", "pixel_delta_max"]

#: Pixels fitted together (and the most whose rows are in memory at once)
CHUNK = 256


class RowStore:
    """Each pixel's fitted rows (displacement and force, float64) in an unnamed temporary file,
    read back when the pixel is fitted."""

    def __init__(self):
        self._file = tempfile.TemporaryFile()
        self._end = 0

    def add(self, d, f):
        """Keep ``d`` and ``f`` (same length); returns their key."""
        data = np.concatenate([np.asarray(d, float), np.asarray(f, float)]).tobytes()
        self._file.seek(self._end)
        self._file.write(data)
        key = (self._end, len(d))
        self._end += len(data)
        return key

    def get(self, key):
        """``(d, f)`` kept under ``key``."""
        at, n = key
        self._file.seek(at)
        both = np.frombuffer(self._file.read(16 * n), float)
        return both[:n], both[n:]

    def close(self):
        self._file.close()


@dataclasses.dataclass
class Pixel:
    """One curve of a map as its fit needs it: ``name`` (``path#index``), ``curve`` (its place,
    no record), ``rows`` (the :class:`RowStore` key of its fitted rows, None when its segment
    could not be read: ``error`` says why), ``baseline`` and contact ``guess`` (m) of the fit, its
    ``depth`` (delta, for the model curve's depth; None when unknown), the ``warnings`` about its
    segments and the file's ``sha256``."""
    name: str
    curve: AFMCurve
    rows: tuple = None
    baseline: str = "none"
    guess: float = 0.0
    depth: float = None
    warnings: list = dataclasses.field(default_factory=list)
    error: str = ""
    sha256: str = ""


def record_depth(record, segment, R_L):
    """The deepest datum's delta of ``record``'s ``segment`` beyond its contact estimate (None
    when the segment cannot be read): what a batch's common model curve is computed to."""
    try:
        m = record.mask(segment)
        d, f = record.displacement[m], record.force[m]
        guess = estimate_contact(d, f)
        return (np.max(d) - (guess if guess is not None else min(0.0, np.min(d)))) / R_L
    except ValueError:
        return None


def read_pixels(curves, path, *, R_L, segment="loading", baseline="auto", fit_offset=True):
    """``(pixels, store)``: a :class:`Pixel` per curve of ``curves`` (an iterable, taken once)
    and the :class:`RowStore` holding their rows (close it when done)."""
    pixels, store = [], RowStore()
    for c in curves:
        rec = c.record
        px = Pixel(name=f"{path or getattr(rec, 'path', '')}#{c.index}",
                   curve=AFMCurve(None, c.index, c.grid, c.position, c.grid_geometry), sha256=getattr(rec, "sha256", ""))
        try:
            if rec is None:
                raise ValueError(f"{px.name}: the curve has no record")
            # the contact estimated once from the segment's rows, as fit_record estimates it (not
            # the record's own estimate: a record whose force was changed keeps its old one)
            used = rec.mask(segment)
            d = rec.displacement[used]
            est = estimate_contact(d, rec.force[used]) if d.size >= 3 else None
            if d.size:
                px.depth = (np.max(d) - (est if est is not None else min(0.0, np.min(d)))) / R_L
            rows = record_rows(rec, segment, baseline, fit_offset, est)
            px.rows = store.add(rows.d, rows.f)
            px.baseline, px.guess = rows.baseline, rows.guess
            px.warnings = segment_warnings(rec, segment, rows.used)
        except ValueError as exc:
            px.error = " ".join(str(exc).split())
        pixels.append(px)
    return pixels, store


def pixel_delta_max(pixels, delta_max=None) -> list:
    """Each pixel's ``delta_max``: the common 1.2 x the deepest pixel's depth for the pixels of
    comparable depth (one model curve for them all), else None (its own), as
    :func:`shellbvp.batch.fit_records` sets it; ``delta_max`` given: that for every pixel."""
    if delta_max is not None:
        return [delta_max] * len(pixels)
    finite = [p.depth for p in pixels if p.depth is not None and math.isfinite(p.depth) and p.depth > 0]
    common = 1.2 * max(finite) if finite else None
    return [common if (common is not None and p.depth is not None and 1.2 * p.depth >= 0.5 * common) else None
            for p in pixels]


def fit_pixels(scene, pixels, store, *, R_L, chunk=CHUNK, **options):
    """``(pixel, FitResult or ValueError, (d, f))`` for every pixel with rows (``d``, ``f``: its
    fitted rows, m and N), in order, fitted in chunks
    of ``chunk``: together where :func:`~shellbvp.fitting.batched.batchable`, else one
    :func:`~shellbvp.fitting.fit` each; the result's segment warnings added and its per-point
    weights dropped."""
    dms = pixel_delta_max(pixels, options.pop("delta_max", None))
    todo = [(p, dm) for p, dm in zip(pixels, dms) if p.rows is not None]
    together, curves = batchable(scene, options), {}
    for lo in range(0, len(todo), chunk):
        part = todo[lo:lo + chunk]
        data = [store.get(p.rows) for p, _ in part]
        if together:
            results = fit_batch(scene, [(d, f, p.baseline, p.guess, dm) for (p, dm), (d, f) in zip(part, data)],
                                R_L=R_L, curves=curves, **options)
        else:
            results = []
            for (p, dm), (d, f) in zip(part, data):
                try:
                    results.append(fit(scene, d, f, R_L=R_L, baseline=p.baseline, contact_guess=p.guess,
                                       delta_max=dm, **options))
                except ValueError as exc:
                    results.append(exc)
        for (p, _), res, rows in zip(part, results, data):
            yield p, res if isinstance(res, Exception) else finish(res, p), rows


def finish(res, pixel):
    """A map's FitResult of ``pixel``: its segment warnings added, its per-point weights dropped."""
    return dataclasses.replace(res, point_weights=None, warnings=res.warnings + [t for _, t in pixel.warnings],
                               warning_codes=res.warning_codes + [c for c, _ in pixel.warnings])
