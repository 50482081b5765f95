"""The JPK reader: JPK Instruments' archives of force curves and force maps, read through
afmformats curve by curve (:mod:`shellbvp.afm_jpk`: time linear in the curves).

A JPK file is a zip archive: its declared members and inflated sizes are checked first
(:func:`shellbvp.afm_read.check_archive`).  The file carries the cantilever's calibration; its
columns, units and signs are its own.
"""

from __future__ import annotations

import zipfile

from .. import afm_jpk, afm_read
from ..afm_read import AFM_REFUSALS
from .registry import Reader

__all__ = ["READERS", "SUFFIXES"]

#: File name endings of JPK archives (afmformats' JPK recipes)
SUFFIXES = (".jpk-force", ".jpk-force-map", ".jpk-qi-data", ".jpk-qi-series")

def _load(path, meta_override):
    """afmformats' curves of a JPK archive one at a time (:func:`shellbvp.afm_jpk.jpk_datasets`),
    or afmformats' own loader for what that does not read (another measurement, another version)."""
    datasets = afm_jpk.jpk_datasets(path, meta_override)
    return datasets if datasets is not None else afm_read.load_with_afmformats(path, meta_override)


def _check_sizes(path, size):
    if zipfile.is_zipfile(path):  # not a zip: afmformats says what it is not
        afm_read.check_archive(path, size)


def read(path) -> list:
    """The curves of a JPK archive (:class:`~shellbvp.afm_read.AFMCurve`)."""
    return afm_read.read_afm(path, load=_load, check_sizes=_check_sizes)


def iterate(path):
    """The curves of a JPK archive one at a time (:func:`shellbvp.afm_read.iter_afm`): a force
    map's are never all in memory."""
    return afm_read.iter_afm(path, load=_load, check_sizes=_check_sizes)


READERS = (Reader(
    name="JPK", order=10, suffixes=SUFFIXES, folder_suffixes=(".jpk-force",), curves=True,
    what="a JPK archive",
    hint="`shellbvp fit FILE` fits its curve or its force map (in Python shellbvp.afm.read_afm)",
    refusals=AFM_REFUSALS, read=read, iterate=iterate),)
