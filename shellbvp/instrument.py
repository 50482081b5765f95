"""Instrument files: reading force–displacement exports and cutting them into segments.

An indentation record, as instruments export it, is a table in time order:
the indenter approaches the sample (force at its baseline), presses into it
(loading), may hold its position, and retracts (the force follows a lower
branch: hysteresis).  Fitting an elastic model to all of it at once -- rows
sorted by displacement -- merges loading and retraction into one curve and
biases mu*H with a confident but wrong interval.  So a record is segmented
first and the fit uses the loading segment by default.

* :func:`read_instrument` -- an :class:`InstrumentRecord` from a file, read by its reader
  (:mod:`shellbvp.readers`): a text export's displacement and force (and time) columns found
  by unit and name, converted to SI, in the file's (time) order, with the segment of every
  row; an AFM file's one curve through afmformats.
* :func:`read_table` -- the text layer (:mod:`shellbvp.readers.text_table`): encodings,
  ``#``/``%`` comment lines, ``,`` ``;``, tab or whitespace delimiters, decimal commas, one or
  two header rows (names, then units; also as comment lines just above the data), plain
  numbers only.
* :func:`segment` -- approach / loading / hold / retraction / other, by the
  direction of the displacement over time (or over rows).
* :func:`estimate_contact` -- a first contact point from the baseline.
* :func:`read_force_csv` -- the older two-column reader (rows sorted by displacement).

The readers are in :mod:`shellbvp.readers` (one module per format), the segmentation and the
contact estimate in :mod:`shellbvp.segments`, the record type in
:mod:`shellbvp.instrument_record`; their names are importable from here too.
"""

from __future__ import annotations

import numpy as np

from .instrument_record import InstrumentRecord, record_from_arrays, sha256_of
from .readers import read_record, read_table
from .readers.text_table import MAX_PREAMBLE_LINES, Table, bare_name, cell_number, header_name_and_unit, unit_of
from .segments import FIT_SEGMENTS, SEGMENTS, estimate_contact, segment, smoothed_slope

__all__ = ["InstrumentRecord", "Table", "read_table", "read_instrument", "read_force_csv", "segment",
           "record_from_arrays", "header_name_and_unit", "cell_number", "MAX_PREAMBLE_LINES",
           "estimate_contact", "SEGMENTS", "FIT_SEGMENTS", "sha256_of", "smoothed_slope"]

#: The names these helpers had when the text layer lived here
_bare_name, _unit_of = bare_name, unit_of


def read_instrument(path, *, columns=None, units=None, invert=()) -> InstrumentRecord:
    """Read an instrument's force–displacement export and segment it.

    Parameters
    ----------
    path : str or Path
        Delimited text (see :func:`read_table`); an AFM file (a reader of :mod:`shellbvp.readers`
        recognises it) is read through afmformats (:func:`shellbvp.afm.read_afm`), its one curve
        returned.
    columns : sequence, optional
        Displacement and force columns (and, third, time) by name or 0-based index.
        Default: found by unit (a length, a force, a time) and name (``Displacement``,
        ``Indentation``, ``Force``, ``Time``, ...).
    units : sequence of str, optional
        Units of the displacement and force (and time) columns, e.g. ``("um", "uN")``,
        when the header gives none (micro as ``u``, µ or μ; ``pN`` .. ``kN``, ``nm`` .. ``m``).
    invert : sequence of {"displacement", "force"}
        Columns whose sign to flip: an AFM height that falls as the tip goes in, or a
        compression recorded as a negative force.  The record is then in the package's
        convention: displacement grows into the sample, the force pushing into it is positive.

    Returns
    -------
    InstrumentRecord
        In the file's order (sorted by time when there is a time column); rows with a
        missing value dropped.

    Raises
    ------
    ValueError
        Naming the file and, for a bad row, its line; for columns that cannot be found,
        the header and ``--columns``.

    Examples
    --------
    A record in um and uN with a time column: an approach at a 5 uN baseline, the
    loading from contact at 20 um, and the retraction.

    >>> import os, tempfile, shellbvp as sb
    >>> disp = list(range(0, 44, 4)) + list(range(36, 16, -4))          # um: in, then out
    >>> force = ([5 + 0.5 * max(d - 20, 0) ** 2 for d in disp[:11]]        # uN: loading,
    ...          + [5 + 0.4 * max(d - 20, 0) ** 2 for d in disp[11:]])     # retraction below it
    >>> path = os.path.join(tempfile.mkdtemp(), "seed.tsv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("# exported by my indenter\\nTime (s)\\tDisplacement (um)\\tForce (uN)\\n")
    ...     _ = fh.writelines(f"{0.5 * i}\\t{d}\\t{f:.1f}\\n" for i, (d, f) in enumerate(zip(disp, force)))
    >>> rec = sb.read_instrument(path)
    >>> len(rec), rec.units
    (16, {'displacement': 'um', 'force': 'uN', 'time': 's'})
    >>> rec.counts()
    {'approach': 5, 'loading': 6, 'retraction': 5}
    >>> print(f"contact near {rec.contact_estimate * 1e6:.0f} um; first rows {rec.displacement[:2]} m")
    contact near 20 um; first rows [0.e+00 4.e-06] m
    """
    return read_record(path, columns=columns, units=units, invert=invert)


def read_force_csv(path, *, columns=None, units=None):
    """Read displacement and force columns from a CSV file, sorted by displacement.

    The reading of :func:`read_instrument` (header detection, units, comments,
    decimal commas, encodings), without segments: every row with numbers, sorted by
    displacement.  For instrument records with approach and retraction use
    :func:`read_instrument` (``shellbvp fit`` does): sorting merges the branches.
    Without a header the first two columns are read (``columns=[1, 0]`` swaps them).

    Parameters
    ----------
    path : str or Path
        The file (see :func:`read_table`).
    columns : (str or int, str or int), optional
        Displacement and force columns, by header name or 0-based index.
    units : (str, str), optional
        Their units (e.g. ``("mm", "mN")``) when the header has none.

    Returns
    -------
    displacement_m, force_N : ndarray
        Sorted by displacement.

    Raises
    ------
    ValueError
        Naming the line (counted in the file, comments included) of a malformed row.

    Examples
    --------
    >>> import os, tempfile, shellbvp as sb
    >>> path = os.path.join(tempfile.mkdtemp(), "run1.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("# sample 1\\ntime (s),disp (um),force [uN]\\n0,20,150\\n1,10,40\\n2,30,300\\n")
    >>> d, F = sb.read_force_csv(path, columns=("disp", "force"))
    >>> [round(float(x), 9) for x in d], [round(float(x), 9) for x in F]
    ([1e-05, 2e-05, 3e-05], [4e-05, 0.00015, 0.0003])
    """
    rec = read_instrument(path, columns=columns, units=units)
    order = np.argsort(rec.displacement, kind="stable")
    return rec.displacement[order], rec.force[order]
