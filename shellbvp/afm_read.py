"""AFM files read through afmformats: checked before it reads them, read inside one error boundary.

:func:`read_afm` (re-exported by :mod:`shellbvp.afm`) gives a file's curves as :class:`AFMCurve`.

A JPK file is a zip archive: a few megabytes can declare a gigabyte of inflated members, and
its central directory alone can hold millions of entries.  An Asylum ``.ibw`` declares the sizes
of its parts in a header that igor2 trusts: a mutated size is a read of gigabytes.  Both are
checked here from the sizes the file declares, before anything is inflated or allocated
(:func:`check_afm_sizes`), against the bounds below (stated in docs/fitting.md).

:func:`afmformats_boundary` turns every exception of afmformats, igor2, zipfile and numpy while a
file is decoded into one ``ValueError`` line naming the file (its text escaped), and keeps
afmformats' own log (a full traceback for each file it rejects; igor2 logs a damaged wave's
bytes) quiet unless asked for: a level set on the ``afmformats`` or ``igor2`` logger, or
verbose logging (``shellbvp -v``).
"""

from __future__ import annotations

import logging
import math
import re
import struct
import zipfile
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .afm_jpk import JPK_SUFFIXES, jpk_datasets
from .textdata import printable

__all__ = ["AFM_SUFFIXES", "AFMCurve", "is_afm_file", "afm_text_format", "read_afm", "curves_from_afm",
           "single_curve", "refuse_text_options", "check_afm_sizes", "afmformats_boundary", "AFMFileError",
           "iter_afm", "curve_from_afm", "MAX_MAP_CURVES", "MAX_MAP_PIXELS", "MAX_ARCHIVE_MEMBERS", "MAX_CENTRAL_DIRECTORY_BYTES", "MAX_INFLATED_BYTES",
           "MAX_INFLATION_RATIO", "INFLATION_ALLOWANCE_BYTES", "READER_LOGGERS"]

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
#: (a few kB) until it is written; a JPK archive declaring more is refused before its first curve.
MAX_MAP_CURVES = 256 * 256

#: Asylum (Igor) binary wave headers: version -> (struct layout after the version, names)
_IBW_HEADERS = {
    1: ("lh", ("wfmSize",)),
    2: ("lllh", ("wfmSize", "noteSize", "pictSize")),
    3: ("llllh", ("wfmSize", "noteSize", "formulaSize", "pictSize")),
    5: ("h15l", ("wfmSize", "formulaSize", "noteSize", "dataEUnitsSize", *(f"dimEUnitsSize[{i}]" for i in range(4)),
                 *(f"dimLabelsSize[{i}]" for i in range(4)), "sIndicesSize", "optionsSize1", "optionsSize2")),
}


#: Loggers of the readers below afmformats, quiet while a file is read unless asked for.
READER_LOGGERS = ("afmformats", "igor2")


class AFMFileError(ValueError):
    """A file refused by shellbvp's own checks (its message is already one line, naming the file)."""


#: File name endings read through afmformats (other text files go through shellbvp.instrument).
AFM_SUFFIXES = (".jpk-force", ".jpk-force-map", ".jpk-qi-data", ".jpk-qi-series", ".ibw")


def is_afm_file(path) -> bool:
    """True for an AFM file afmformats reads: by its name (:data:`AFM_SUFFIXES`), or a text
    export of an AFM (:func:`afm_text_format`)."""
    return str(path).lower().endswith(AFM_SUFFIXES) or afm_text_format(path) is not None


def afm_text_format(path):
    """``"AFM Workshop"`` (a ``.csv`` whose first line is ``Force-Distance Curve``, or a ``.zip``
    of them: a map), ``"NT-MDT Nova"`` (a ``.txt`` of three tab-separated columns of numbers with
    decimal commas and no header: height, deflection approaching, deflection retracting) or
    None.  Only the first bytes of a regular file are read."""
    import stat
    import zipfile

    name = str(path).lower()
    if not name.endswith((".csv", ".txt", ".zip")):
        return None
    try:
        if not stat.S_ISREG(Path(path).stat().st_mode):
            return None  # a FIFO is never opened here: it could block
        if name.endswith(".zip"):
            with zipfile.ZipFile(path) as z:
                first = next((i for i in z.infolist() if i.filename.lower().endswith(".csv")), None)
                if first is None:
                    return None
                with z.open(first) as fh:
                    head = fh.read(4096)
        else:
            with open(path, "rb") as fh:
                head = fh.read(4096)
    except (OSError, ValueError, zipfile.BadZipFile, EOFError):
        return None
    if head.lstrip(b"\xef\xbb\xbf").startswith(b"Force-Distance Curve"):
        return "AFM Workshop"
    lines = head.splitlines()[:10] if name.endswith(".txt") else []
    if len(lines) >= 3 and all(re.fullmatch(rb"\s*-?\d+(,\d+)?\t-?\d+(,\d+)?\t-?\d+(,\d+)?\s*", ln)
                               for ln in lines[:-1]) and any(b"," in ln for ln in lines):
        return "NT-MDT Nova"
    return None


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


def refuse_text_options(path, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None):
    """ValueError when reading options of text exports are given for an AFM file (the
    calibration options are the AFM reader's: accepted)."""
    if columns or units or invert:
        raise ValueError(f"{path}: an AFM file gives its own columns, units and signs: --columns, --units and "
                         f"--invert are for text exports")


def _afmformats():
    try:
        import afmformats
    except ImportError:
        raise ValueError("reading AFM files needs afmformats: pip install 'shellbvp[afm]'") from None
    return afmformats


def read_afm(path, *, spring_constant=None, sensitivity=None) -> list:
    """The curves of an AFM file (:data:`AFM_SUFFIXES`) as :class:`AFMCurve`, in file order.

    The file's declared sizes are checked first (:func:`shellbvp.afm_read.check_afm_sizes`:
    an archive's members and inflated sizes, an ``.ibw`` header's parts), then afmformats
    reads it inside one error boundary (:func:`shellbvp.afm_read.afmformats_boundary`):
    whatever fails while the file is decoded is one ``ValueError`` line.

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
    curves = list(iter_afm(path, spring_constant=spring_constant, sensitivity=sensitivity))
    if not curves:
        raise AFMFileError(f"{printable(path)}: afmformats found no force-distance curve in it")
    return curves


def iter_afm(path, *, spring_constant=None, sensitivity=None):
    """:func:`read_afm` one curve at a time (a force map's curves are never all in memory): the
    file's sizes are checked and a JPK archive's curve count bounded by :data:`MAX_MAP_CURVES`
    before the first curve is read; every failure while the file is decoded is one
    ``ValueError`` line, raised when the curve is asked for."""
    from .instrument_record import sha256_of
    from .paths import read_input_bytes

    afmformats = _afmformats()
    size = len(read_input_bytes(path))  # a regular file of bounded size: never a FIFO, a device or a folder
    check_afm_sizes(path, size)
    override = _calibration(path, spring_constant, sensitivity)
    sha256 = sha256_of(path)
    with afmformats_boundary(path):
        # a JPK archive curve by curve (time linear in its curves: shellbvp.afm_jpk)
        datasets = jpk_datasets(path, override) if str(path).endswith(JPK_SUFFIXES) else None
        if datasets is None:
            datasets = afmformats.load_data(str(path), meta_override=override)
        if len(datasets) > MAX_MAP_CURVES:  # a JPK archive's count from its list of members
            raise AFMFileError(f"{printable(path)}: {len(datasets)} curves; shellbvp fits at most {MAX_MAP_CURVES} "
                               f"curves of a map (MAX_MAP_CURVES): cut the map into parts")
        # afmformats loads a curve's columns when they are first read: inside the boundary too
        for i, ds in enumerate(datasets):
            yield curve_from_afm(ds, i, path, sha256=sha256)


def _calibration(path, spring_constant, sensitivity):
    """afmformats' ``meta_override`` for a text export: the calibration it needs, checked."""
    given = {"spring constant": spring_constant, "sensitivity": sensitivity}
    given = {k: v for k, v in given.items() if v is not None}
    for key, value in given.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"the {key} must be a finite number > 0; got {value!r}")
    fmt = afm_text_format(path)
    if fmt is None:
        if given:
            raise ValueError(f"{printable(path)}: its file carries the cantilever's calibration: "
                             f"--spring-constant and --sensitivity are for AFM text exports (AFM Workshop, NT-MDT)")
        return None
    if len(given) < 2:
        what = ("an NT-MDT Nova export (height in nm, deflection in nA)" if fmt == "NT-MDT Nova" else
                "an AFM Workshop export")
        unit = "m/A" if fmt == "NT-MDT Nova" else "m/V"
        raise AFMFileError(f"{printable(path)}: {what} without the cantilever's calibration: give its spring "
                           f"constant (N/m) and sensitivity ({unit}): --spring-constant K --sensitivity S"
                           + (" (if it is no such export, give it a header row naming its columns and their units)"
                              if fmt == "NT-MDT Nova" else ""))
    return given


def single_curve(path, *, columns=None, units=None, invert=(), spring_constant=None, sensitivity=None):
    """The record of an AFM file's one curve (:func:`read_afm`); a force map is refused, pointing
    to :func:`read_afm` and :func:`shellbvp.batch.fit_map`, as reading options of text exports."""
    refuse_text_options(printable(path), columns, units, invert)
    curves = read_afm(path, spring_constant=spring_constant, sensitivity=sensitivity)
    if len(curves) > 1:
        raise ValueError(f"{printable(path)}: a force map of {len(curves)} curves: fit it on its own "
                         f"(shellbvp fit {printable(Path(path).name)} ... -o map.h5; in Python "
                         f"shellbvp.afm.read_afm and shellbvp.batch.fit_map)")
    return curves[0].record


def _meta(md, key):
    v = dict.get(md, key) if isinstance(md, dict) else None  # MetaData[key] raises a BaseException
    return v if isinstance(v, (int, float, np.integer, np.floating)) and math.isfinite(v) else None


def curves_from_afm(datasets, path, *, sha256=None) -> list:
    """:class:`AFMCurve` from afmformats' curves (``AFMForceDistance``) of the file ``path``."""
    return [curve_from_afm(ds, i, path, sha256=sha256) for i, ds in enumerate(datasets)]


def curve_from_afm(ds, i, path, *, sha256=None) -> AFMCurve:
    """The :class:`AFMCurve` of afmformats' curve ``ds``, the ``i``-th of the file ``path``."""
    from .instrument_record import record_from_arrays

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


def check_afm_sizes(path, size) -> None:
    """AFMFileError when the file's declared sizes exceed the bounds of this module: a zip
    archive's member count, central directory, inflated sizes; an ``.ibw`` header's part sizes
    against the file's own ``size`` (bytes).  Nothing is inflated."""
    if str(path).lower().endswith(".ibw"):
        _check_ibw(path, size)
    elif zipfile.is_zipfile(path):
        _check_archive(path, size)


def _check_archive(path, size):
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


def _check_ibw(path, size):
    with open(path, "rb") as fh:
        head = fh.read(64)
    if len(head) < 2:
        raise AFMFileError(f"{path}: not an Igor binary wave (the file holds {len(head)} bytes)")
    for order in "<>":
        version = struct.unpack(order + "h", head[:2])[0]
        if version in _IBW_HEADERS:
            break
    else:
        raise AFMFileError(f"{path}: not an Igor binary wave (version field {head[:2].hex()}; known: 1, 2, 3, 5)")
    layout, names = _IBW_HEADERS[version]
    fmt = order + layout
    need = 2 + struct.calcsize(fmt)
    if len(head) < need:
        raise AFMFileError(f"{path}: an Igor binary wave header of {need} bytes cut short at {len(head)} bytes")
    fields = struct.unpack(fmt, head[2:need])
    sizes = dict(zip(names, fields[1:] if version == 5 else fields))
    bad = {k: v for k, v in sizes.items() if v < 0}
    declared = sum(v for v in sizes.values() if v > 0)
    if bad or need + declared > size:
        what = (f"negative sizes ({', '.join(f'{k} = {v}' for k, v in bad.items())})" if bad else
                f"{declared} bytes of parts ({', '.join(f'{k} = {v}' for k, v in sizes.items() if v)})")
        raise AFMFileError(f"{path}: the Igor binary wave header declares {what} in a file of {size} bytes: "
                           f"damaged, not read")


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
