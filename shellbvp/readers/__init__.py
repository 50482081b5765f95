"""Instrument readers: one module per format, registered in one place.

A :class:`Reader` (:mod:`shellbvp.readers.registry`) is what reads one format of instrument
file: its name, how it recognises a file (its name's ending, its first bytes), the sizes it
checks before anything is decoded, the reading options it takes and what it says of the others
(pointing to the readers that take them), and what it returns: one
:class:`~shellbvp.instrument_record.InstrumentRecord` (a text table) or a file's curves,
:class:`~shellbvp.afm_read.AFMCurve` (an AFM file, possibly a force map).  Every caller asks the
registry (:func:`reader_for`, :func:`read_record`, :func:`read_curves`, :func:`iter_curves`,
:func:`read_table`, :func:`check_options`) instead of comparing a file's name with a format.

The modules of this package:

* ``text_table``: delimited text exports (columns by unit and name); reads what no other
  reader recognises;
* ``jpk``: JPK archives (``.jpk-force``, ``.jpk-force-map``, ``.jpk-qi-data``,
  ``.jpk-qi-series``), curve by curve (:mod:`shellbvp.afm_jpk`);
* ``afmformats``: the other formats afmformats reads: Asylum's ``.ibw``, AFM Workshop's CSV
  (and its ``.zip`` maps) and NT-MDT Nova's text exports (these two with the cantilever's
  calibration given), and any other file afmformats knows, asked for its curves.

Adding a reader is one new module here, declaring ``READERS``, a tuple of :class:`Reader`: the
package finds it on import (:func:`discover`) and registers it by its ``order`` (the order in
which the readers are asked whether they recognise a file; two readers of one order stop the
import).  An afmformats format reads through :func:`shellbvp.afm_read.read_afm` with its own
loader and size checks; copy ``afmformats.py``'s Asylum reader.  ``shellbvp fit``,
:func:`shellbvp.read_instrument`, :func:`shellbvp.afm.read_afm`, batches and pixel tables then
take it.
"""

from __future__ import annotations

import sys

from .registry import (OPTION_GROUPS, READERS, Reader, check_options, curve_suffixes, discover, folder_suffixes,
                       install, iter_curves, read_curves, read_record, read_table, reader, reader_for, register,
                       takers)

__all__ = ["Reader", "READERS", "OPTION_GROUPS", "register", "discover", "install", "reader", "reader_for",
           "takers", "check_options", "read_record", "read_curves", "iter_curves", "read_table", "curve_suffixes",
           "folder_suffixes"]

for _module in discover(sys.modules[__name__]):
    install(_module)
