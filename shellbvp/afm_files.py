"""AFM files checked before afmformats reads them, and afmformats read inside one error boundary.

A JPK file is a zip archive: a few megabytes can declare a gigabyte of inflated members, and
its central directory alone can hold millions of entries.  An Asylum ``.ibw`` declares the sizes
of its parts in a header that igor2 trusts: a mutated size is a read of gigabytes.  Both are
checked here from the sizes the file declares, before anything is inflated or allocated
(:func:`check_afm_sizes`), against the bounds below (stated in docs/afm.md).

:func:`afmformats_boundary` turns every exception of afmformats, igor2, zipfile and numpy while a
file is decoded into one ``ValueError`` line naming the file (its text escaped), and keeps
afmformats' own log (a full traceback for each file it rejects) quiet unless asked for: a level
set on the ``afmformats`` logger, or verbose logging (``shellbvp -v``).
"""

from __future__ import annotations

import logging
import struct
import zipfile
from contextlib import contextmanager

__all__ = ["MAX_MAP_PIXELS", "MAX_ARCHIVE_MEMBERS", "MAX_CENTRAL_DIRECTORY_BYTES", "MAX_INFLATED_BYTES", "MAX_INFLATION_RATIO",
           "INFLATION_ALLOWANCE_BYTES", "check_afm_sizes", "afmformats_boundary", "AFMFileError"]

#: The most members a JPK archive may hold (a 128 x 128 force map has about 250,000).
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

#: Asylum (Igor) binary wave headers: version -> (struct layout after the version, names)
_IBW_HEADERS = {
    1: ("lh", ("wfmSize",)),
    2: ("lllh", ("wfmSize", "noteSize", "pictSize")),
    3: ("llllh", ("wfmSize", "noteSize", "formulaSize", "pictSize")),
    5: ("h15l", ("wfmSize", "formulaSize", "noteSize", "dataEUnitsSize", *(f"dimEUnitsSize[{i}]" for i in range(4)),
                 *(f"dimLabelsSize[{i}]" for i in range(4)), "sIndicesSize", "optionsSize1", "optionsSize2")),
}


class AFMFileError(ValueError):
    """A file refused by shellbvp's own checks (its message is already one line, naming the file)."""


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
    (shellbvp's own checks) passes unchanged; KeyboardInterrupt and SystemExit pass.  afmformats'
    logger is quiet meanwhile unless asked for (module docstring)."""
    from .textdata import printable

    logger = logging.getLogger("afmformats")
    asked = logger.level != logging.NOTSET or logging.getLogger().getEffectiveLevel() <= logging.INFO
    if not asked:
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
        if not asked:
            logger.setLevel(logging.NOTSET)
