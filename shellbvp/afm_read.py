"""AFM files read through afmformats: checked before it reads them, read inside one error boundary.

:func:`read_afm` gives a file's curves as :class:`AFMCurve`, loaded by the loader of its reader
(:mod:`shellbvp.readers`: which format a file is, which sizes it checks and which calibration it
needs are the readers' own; :func:`shellbvp.afm.read_afm` asks them).

A JPK file (or an AFM Workshop map) is a zip archive: a few megabytes can declare a gigabyte of
inflated members, and its central directory alone can hold millions of entries.  An archive is
checked here from the sizes it declares, before anything is inflated (:func:`check_archive`),
against the bounds below (stated in docs/fitting.md); an Asylum ``.ibw``'s header by its reader
(:mod:`shellbvp.readers.afmformats`).

:func:`afmformats_boundary` turns every exception of afmformats, igor2, zipfile and numpy while a
file is decoded into one ``ValueError`` line naming the file (its text escaped), and keeps
afmformats' own log (a full traceback for each file it rejects; igor2 logs a damaged wave's
bytes) quiet unless asked for: a level set on the ``afmformats`` or ``igor2`` logger, or
verbose logging (``shellbvp -v``).
"""

from __future__ import annotations

import logging
import math
import struct
import zipfile
from contextlib import contextmanager
from dataclasses import dataclass

import numpy as np

from .instrument_record import record_from_arrays, sha256_of
from .paths import read_input_bytes
from .textdata import printable

__all__ = ["AFMCurve", "read_afm", "iter_afm", "load_with_afmformats", "curves_from_afm", "curve_from_afm",
           "check_archive", "afmformats_boundary", "AFMFileError", "AFM_REFUSALS", "MAX_MAP_CURVES", "MAX_MAP_PIXELS",
           "MAX_ARCHIVE_MEMBERS", "MAX_CENTRAL_DIRECTORY_BYTES", "MAX_INFLATED_BYTES", "MAX_INFLATION_RATIO",
           "INFLATION_ALLOWANCE_BYTES", "READER_LOGGERS"]

#: The most members a JPK archive may hold (a 128 x 128 force map: about 330,000, 20 a curve).
MAX_ARCHIVE_MEMBERS = 500_000
#: The largest central directory (the archive's list of members) read: about 130 bytes a member.
MAX_CENTRAL_DIRECTORY_BYTES = 64 * 2**20
#: The largest sum of the members' inflated sizes of one archive.
MAX_INFLATED_BYTES = 1 * 2**30
#: ... and at most this many times the archive's own size, plus :data:`INFLATION_ALLOWANCE_BYTES`
#: (JPK's own files inflate 1.2-6x; a zip bomb 1000x).
MAX_INFLATION_RATIO = 20
INFLATION_ALLOWANCE_BYTES = 16 * 2**20

#: The most cells of a force map's grid (its images: 8 MiB each) and rows of a pixel table.
MAX_MAP_PIXELS = 1024 * 1024
#: The most curves of an AFM file read (a 256 x 256 map): a map keeps each curve's results
#: (a few kB) until it is written; a file declaring more (a JPK archive's count from its list
#: of members) is refused before its first curve.
MAX_MAP_CURVES = 256 * 256

#: Loggers of the readers below afmformats, quiet while a file is read unless asked for.
READER_LOGGERS = ("afmformats", "igor2")


#: What a reader of AFM files (:mod:`shellbvp.readers`) says of the reading options it does not take
AFM_REFUSALS = {
    "text": "an AFM file gives its own columns, units and signs: --columns, --units and --invert are for text "
            "exports",
    "calibration": "its file carries the cantilever's calibration: --spring-constant and --sensitivity are for "
                   "AFM text exports ({takers})",
}


class AFMFileError(ValueError):
    """A file refused by shellbvp's own checks (its message is already one line, naming the file)."""


@dataclass
class AFMCurve:
    """One curve of an AFM file.

    Attributes
    ----------
    record : InstrumentRecord
        Displacement into the sample (m), force (N), time (s), segments, contact estimate.
    index : int
        The curve's number in the file (afmformats' ``enum``).
    grid : tuple of int or None
        ``(ix, iy)`` on a force map.
    position : tuple of float or None
        ``(x, y)`` of the curve on the sample (m), as the file gives it.
    grid_geometry : tuple or None
        ``((center x, center y), (size x, size y))`` of the map's grid (m).
    """

    record: object
    index: int
    grid: tuple = None
    position: tuple = None
    grid_geometry: tuple = None  # ((center x, center y), (size x, size y)) of the map's grid, m


def _afmformats():
    try:
        import afmformats
    except ImportError:
        raise ValueError("reading AFM files needs afmformats: pip install 'shellbvp[afm]'") from None
    return afmformats


def read_afm(path, *, load, check_sizes=None, meta_override=None) -> list:
    """The curves of an AFM file as :class:`AFMCurve`, in file order, loaded by ``load``.

    The file is read whole once (a regular file of bounded size: never a FIFO, a device or a
    folder) and its declared sizes checked (``check_sizes(path, size)``, its reader's), then
    ``load(path, meta_override)`` (afmformats' curves, ``AFMForceDistance``) runs inside one error
    boundary (:func:`afmformats_boundary`): whatever fails while the file is decoded is one
    ``ValueError`` line.  Which loader, which checks and which calibration (``meta_override``:
    afmformats' ``{"spring constant": ..., "sensitivity": ...}``) a file gets is its reader's
    (:mod:`shellbvp.readers`); :func:`shellbvp.afm.read_afm` asks them.

    Raises
    ------
    ValueError
        afmformats is not installed, or cannot read the file, or a curve lacks the force,
        a height or the spring constant, or the file declares sizes beyond the bounds.
    """
    curves = list(iter_afm(path, load=load, check_sizes=check_sizes, meta_override=meta_override))
    if not curves:
        raise AFMFileError(f"{printable(path)}: afmformats found no force-distance curve in it")
    return curves


def iter_afm(path, *, load, check_sizes=None, meta_override=None):
    """:func:`read_afm` one curve at a time (a force map's curves are never all in memory; a
    JPK archive's are decoded one at a time too, :mod:`shellbvp.afm_jpk`): the file's sizes are
    checked and its curve count bounded by :data:`MAX_MAP_CURVES` before the first curve is
    read; every failure while the file is decoded is one ``ValueError`` line, raised when the
    curve is asked for.  A file without curves yields none."""
    _afmformats()
    size = len(read_input_bytes(path))  # a regular file of bounded size: never a FIFO, a device or a folder
    if check_sizes is not None:
        check_sizes(path, size)
    sha256 = sha256_of(path)
    with afmformats_boundary(path):
        datasets = load(path, meta_override)
        # a JPK archive's count from its list of members, before its first curve; any other as it is read
        declared = len(datasets) if hasattr(datasets, "__len__") else None
        over = declared is not None and declared > MAX_MAP_CURVES
        for i, ds in enumerate(() if over else datasets):
            if i >= MAX_MAP_CURVES:
                over = True
                break
            # afmformats loads a curve's columns when they are first read: inside the boundary too
            yield curve_from_afm(ds, i, path, sha256=sha256)
        if over:
            count = declared if declared is not None and declared > MAX_MAP_CURVES else f"more than {MAX_MAP_CURVES}"
            raise AFMFileError(f"{printable(path)}: {count} curves; shellbvp fits at most {MAX_MAP_CURVES} curves "
                               f"of a map (MAX_MAP_CURVES): cut the map into parts")


def load_with_afmformats(path, meta_override=None):
    """afmformats' own loader (``afmformats.load_data``): the curves of any file it knows."""
    return _afmformats().load_data(str(path), meta_override=meta_override)


def _meta(md, key):
    v = dict.get(md, key) if isinstance(md, dict) else None  # MetaData[key] raises a BaseException
    return v if isinstance(v, (int, float, np.integer, np.floating)) and math.isfinite(v) else None


def curves_from_afm(datasets, path, *, sha256=None) -> list:
    """:class:`AFMCurve` from afmformats' curves (``AFMForceDistance``) of the file ``path``."""
    return [curve_from_afm(ds, i, path, sha256=sha256) for i, ds in enumerate(datasets)]


def curve_from_afm(ds, i, path, *, sha256=None) -> AFMCurve:
    """The :class:`AFMCurve` of afmformats' curve ``ds``, the ``i``-th of the file ``path``."""
    columns = list(ds.columns)
    md = ds.metadata
    where = f"{printable(path)}, curve {i}"
    if "force" not in columns:
        raise AFMFileError(f"{where}: no force column (columns: {printable(', '.join(map(str, columns)))})")
    force = np.asarray(ds["force"], float)
    if "tip position" in columns:
        tip, how = np.asarray(ds["tip position"], float), "-(tip position)"
    else:
        height = next((h for h in ("height (measured)", "height (piezo)") if h in columns), None)
        k = _meta(md, "spring constant")
        if height is None or k is None or not k > 0:
            raise AFMFileError(f"{where}: needs a height column and the spring constant to place the tip "
                               f"(columns: {printable(', '.join(map(str, columns)))}; spring constant: {k})")
        tip, how = np.asarray(ds[height], float) + force / k, f"-({height} + force / spring constant)"
    time = np.asarray(ds["time"], float) if "time" in columns else None
    ok = np.isfinite(tip) & np.isfinite(force) & (np.isfinite(time) if time is not None else True)
    if ok.sum() < 3:
        raise AFMFileError(f"{where}: fewer than 3 rows with numbers")
    record = record_from_arrays(path, -tip[ok], force[ok], None if time is None else time[ok],
                                np.flatnonzero(ok), columns={"displacement": how, "force": "force",
                                                             **({"time": "time"} if time is not None else {})},
                                units={"displacement": "m", "force": "N", **({"time": "s"} if time is not None
                                                                           else {})},
                                header=columns, sha256=sha256)
    ix, iy = _meta(md, "grid index x"), _meta(md, "grid index y")
    x, y = _meta(md, "position x"), _meta(md, "position y")
    index = _meta(md, "enum")
    geometry = [_meta(md, f"grid {a} {b}") for a in ("center", "size") for b in "xy"]
    return AFMCurve(record=record, index=int(index) if index is not None else i,
                    grid=(int(ix), int(iy)) if ix is not None and iy is not None else None,
                    position=(float(x), float(y)) if x is not None and y is not None else None,
                    grid_geometry=((geometry[0], geometry[1]), (geometry[2], geometry[3]))
                    if None not in geometry else None)


def check_archive(path, size) -> None:
    """AFMFileError when the zip archive ``path`` (``size`` bytes) declares more members, a larger
    central directory or more inflated bytes than the bounds of this module.  Nothing is
    inflated."""
    count, cd_size = _central_directory(path)
    if count > MAX_ARCHIVE_MEMBERS or cd_size > MAX_CENTRAL_DIRECTORY_BYTES:
        raise AFMFileError(f"{path}: the archive declares {count} members in a {cd_size} byte directory; "
                           f"shellbvp reads at most {MAX_ARCHIVE_MEMBERS} members (MAX_ARCHIVE_MEMBERS) and "
                           f"{MAX_CENTRAL_DIRECTORY_BYTES // 2**20} MiB of directory")
    try:
        with zipfile.ZipFile(path) as z:
            infos = z.infolist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, struct.error) as exc:
        raise AFMFileError(f"{path}: not a readable zip archive ({type(exc).__name__}: {exc})") from None
    if len(infos) > MAX_ARCHIVE_MEMBERS:
        raise AFMFileError(f"{path}: the archive holds {len(infos)} members; shellbvp reads at most "
                           f"{MAX_ARCHIVE_MEMBERS} (MAX_ARCHIVE_MEMBERS)")
    inflated = sum(max(i.file_size, 0) for i in infos)
    allowed = min(MAX_INFLATED_BYTES, INFLATION_ALLOWANCE_BYTES + MAX_INFLATION_RATIO * size)
    if inflated > allowed:
        largest = max(infos, key=lambda i: i.file_size)
        raise AFMFileError(f"{path}: the archive's members inflate to {inflated / 2**20:.1f} MiB from "
                           f"{size / 2**20:.2f} MiB (largest {largest.filename!r}, {largest.file_size / 2**20:.1f} "
                           f"MiB); shellbvp inflates at most {allowed / 2**20:.0f} MiB here "
                           f"(min of {MAX_INFLATED_BYTES // 2**20} MiB and {MAX_INFLATION_RATIO} x the file + "
                           f"{INFLATION_ALLOWANCE_BYTES // 2**20} MiB)")


def _central_directory(path):
    """``(member count, central directory size)`` from the end-of-central-directory record
    (and its zip64 form), read before :mod:`zipfile` parses the directory."""
    with open(path, "rb") as fh:
        fh.seek(0, 2)
        end = fh.tell()
        fh.seek(max(0, end - (22 + 65535 + 20)))
        tail = fh.read()
    at = tail.rfind(b"PK\x05\x06")
    if at < 0 or len(tail) < at + 22:
        return 0, 0  # zipfile itself will say what is wrong
    count, cd_size = struct.unpack("<HL", tail[at + 10:at + 16])
    loc = tail.rfind(b"PK\x06\x07", 0, at)
    if loc >= 0 and at - loc == 20 and (count == 0xFFFF or cd_size == 0xFFFFFFFF):
        offset = struct.unpack("<Q", tail[loc + 8:loc + 16])[0]
        with open(path, "rb") as fh:
            fh.seek(min(offset, end))
            record = fh.read(56)
        if record[:4] == b"PK\x06\x06" and len(record) == 56:
            count, cd_size = struct.unpack("<QQ", record[32:48])
    return count, cd_size


@contextmanager
def afmformats_boundary(path):
    """Every exception of afmformats (and of igor2, zipfile, zlib, numpy below it) raised in
    the ``with`` block becomes one ``ValueError`` line naming ``path``; :class:`AFMFileError`
    (shellbvp's own checks) passes unchanged; KeyboardInterrupt and SystemExit pass.  The loggers
    of afmformats and igor2 (:data:`READER_LOGGERS`) are quiet meanwhile unless asked for (module
    docstring)."""
    verbose = logging.getLogger().getEffectiveLevel() <= logging.INFO
    quieted = [lg for lg in map(logging.getLogger, READER_LOGGERS) if lg.level == logging.NOTSET and not verbose]
    for logger in quieted:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    except AFMFileError:
        raise
    except (KeyboardInterrupt, SystemExit, GeneratorExit):
        raise
    except BaseException as exc:  # noqa: BLE001 -- afmformats raises BaseException subclasses on bad metadata
        text = printable(" ".join(str(exc).split()))
        text = text if len(text) <= 300 else text[:297] + "..."
        raise ValueError(f"{printable(path)}: afmformats cannot read it ({type(exc).__name__}: {text})") from None
    finally:
        for logger in quieted:
            logger.setLevel(logging.NOTSET)
