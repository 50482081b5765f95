"""The readers of the other formats afmformats reads: Asylum Research's Igor binary waves
(``.ibw``), AFM Workshop's CSV exports (and their ``.zip`` maps), NT-MDT Nova's text exports,
and, asked for a file's curves, whatever else afmformats knows.

An ``.ibw`` declares the sizes of its parts in a header that igor2 trusts: a mutated size is a
read of gigabytes, so the header is checked against the file's size first.  A ``.zip`` is
checked as an archive (:func:`shellbvp.afm_read.check_archive`).  The two text exports carry no
calibration: the cantilever's spring constant and sensitivity are given with them
(``--spring-constant``, ``--sensitivity``), and they are recognised by their first bytes, never
by their names alone (a ``.csv`` or ``.txt`` is otherwise a text table).
"""

from __future__ import annotations

import re
import stat
import struct
import zipfile
from pathlib import Path

from .. import afm_read
from ..afm_read import AFM_REFUSALS, AFMFileError
from .registry import Reader

__all__ = ["READERS", "check_ibw"]

#: Asylum (Igor) binary wave headers: version -> (struct layout after the version, names)
_IBW_HEADERS = {
    1: ("lh", ("wfmSize",)),
    2: ("lllh", ("wfmSize", "noteSize", "pictSize")),
    3: ("llllh", ("wfmSize", "noteSize", "formulaSize", "pictSize")),
    5: ("h15l", ("wfmSize", "formulaSize", "noteSize", "dataEUnitsSize", *(f"dimEUnitsSize[{i}]" for i in range(4)),
                 *(f"dimLabelsSize[{i}]" for i in range(4)), "sIndicesSize", "optionsSize1", "optionsSize2")),
}
_NOVA_LINE = re.compile(rb"\s*-?\d+(,\d+)?\t-?\d+(,\d+)?\t-?\d+(,\d+)?\s*")


def check_ibw(path, size) -> None:
    """AFMFileError when an Igor binary wave's header declares parts that its ``size`` bytes
    cannot hold (or negative sizes), or is no such header.  Nothing else is read."""
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


def _check_zip(path, size):
    if zipfile.is_zipfile(path):
        afm_read.check_archive(path, size)


def _head(path, suffixes):
    """The first 4 KiB of a regular file named with one of ``suffixes`` (of a ``.zip``: of its
    first ``.csv`` member), or None (another name, not a regular file, unreadable).  A FIFO is
    never opened: it could block."""
    name = str(path).lower()
    if not name.endswith(suffixes):
        return None
    try:
        if not stat.S_ISREG(Path(path).stat().st_mode):
            return None
        if name.endswith(".zip"):
            with zipfile.ZipFile(path) as z:
                first = next((i for i in z.infolist() if i.filename.lower().endswith(".csv")), None)
                if first is None:
                    return None
                with z.open(first) as fh:
                    return fh.read(4096)
        with open(path, "rb") as fh:
            return fh.read(4096)
    except (OSError, ValueError, zipfile.BadZipFile, EOFError):
        return None


def _is_afm_workshop(path) -> bool:
    """A ``.csv`` (or ``.txt``) whose first line is ``Force-Distance Curve``, or a ``.zip`` of them (a map)."""
    head = _head(path, (".csv", ".txt", ".zip"))
    return head is not None and head.lstrip(b"\xef\xbb\xbf").startswith(b"Force-Distance Curve")


def _is_nova(path) -> bool:
    """A ``.txt`` of three tab-separated columns of numbers with decimal commas and no header:
    height, deflection approaching, deflection retracting."""
    head = _head(path, (".txt",))
    lines = head.splitlines()[:10] if head is not None else []
    return len(lines) >= 3 and all(_NOVA_LINE.fullmatch(ln) for ln in lines[:-1]) and any(b"," in ln for ln in lines)


def _read(check_sizes, how=afm_read.read_afm):
    """``read(path)``: the curves of a file through afmformats' own loader (``how``:
    :func:`~shellbvp.afm_read.read_afm`, or :func:`~shellbvp.afm_read.iter_afm` one at a time)."""
    def read(path):
        return how(path, load=afm_read.load_with_afmformats, check_sizes=check_sizes)
    return read


def _read_calibrated(check_sizes, how=afm_read.read_afm):
    """``read(path, spring_constant, sensitivity)``: as :func:`_read`, with the calibration given."""
    def read(path, *, spring_constant, sensitivity):
        return how(path, load=afm_read.load_with_afmformats, check_sizes=check_sizes,
                   meta_override={"spring constant": spring_constant, "sensitivity": sensitivity})
    return read


def _missing_calibration(what, unit, hint=""):
    return (f"{what} without the cantilever's calibration: give its spring constant (N/m) and sensitivity "
            f"({unit}): --spring-constant K --sensitivity S{hint}")


_CALIBRATION = ("spring_constant", "sensitivity")

READERS = (
    Reader(name="Asylum", order=20, suffixes=(".ibw",), folder_suffixes=(".ibw",), curves=True,
           what="an Asylum Research Igor binary wave",
           hint="`shellbvp fit FILE` fits its curve (in Python shellbvp.afm.read_afm)",
           refusals=AFM_REFUSALS, read=_read(check_ibw), iterate=_read(check_ibw, afm_read.iter_afm)),
    Reader(name="AFM Workshop", order=30, sniff=_is_afm_workshop, curves=True,
           what="an AFM Workshop export",
           hint="`shellbvp fit FILE --spring-constant K --sensitivity S` fits it (in Python shellbvp.afm.read_afm)",
           options=_CALIBRATION, requires=_CALIBRATION,
           refusals={**AFM_REFUSALS, "requires": _missing_calibration("an AFM Workshop export", "m/V")},
           read=_read_calibrated(_check_zip), iterate=_read_calibrated(_check_zip, afm_read.iter_afm)),
    Reader(name="NT-MDT Nova", order=40, sniff=_is_nova, curves=True,
           what="an NT-MDT Nova export",
           hint="`shellbvp fit FILE --spring-constant K --sensitivity S` fits it (in Python shellbvp.afm.read_afm)",
           options=_CALIBRATION, requires=_CALIBRATION,
           refusals={**AFM_REFUSALS, "requires": _missing_calibration(
               "an NT-MDT Nova export (height in nm, deflection in nA)", "m/A",
               " (if it is no such export, give it a header row naming its columns and their units)")},
           read=_read_calibrated(_check_zip), iterate=_read_calibrated(_check_zip, afm_read.iter_afm)),
    Reader(name="afmformats", order=90, fallback=True, curves=True,
           what="a file for afmformats",
           hint="in Python shellbvp.afm.read_afm reads the curves of any file afmformats knows",
           refusals=AFM_REFUSALS, read=_read(_check_zip), iterate=_read(_check_zip, afm_read.iter_afm)),
)
