"""The record type of an instrument file: :class:`InstrumentRecord`, the rows in SI units and
file (time) order with the segment of each (:mod:`shellbvp.segments`)."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from .segments import FIT_SEGMENTS, SEGMENTS, estimate_contact, segment

__all__ = ["InstrumentRecord", "record_from_arrays", "sha256_of"]


@dataclass
class InstrumentRecord:
    """A force–displacement record as read from an instrument file (SI units, file order).

    Attributes
    ----------
    path : str
        The file read.
    sha256 : str
        SHA-256 of the file's bytes.
    displacement : ndarray, shape (n,)
        Indenter displacement in m (into the sample positive), one per data row kept.
    force : ndarray, shape (n,)
        Force in N.
    time : ndarray, shape (n,) or None
        Time in s when the file has a time column (rows are then in time order).
    line : ndarray of int, shape (n,)
        The line of the file each row comes from.
    segments : ndarray of str, shape (n,)
        Each row's segment, one of :data:`SEGMENTS` (:func:`segment`).
    columns : dict
        Header name (or index) of the ``displacement``, ``force`` and ``time`` columns used.
    units : dict
        The units the file's columns were in (``displacement``, ``force``, ``time``): results
        are also printed in these.
    header : list of str
    inverted : tuple of str
        The columns whose sign was flipped on reading (``read_instrument(..., invert=...)``).
    contact_estimate : float or None
        First estimate of the contact point (m) from the baseline (:func:`estimate_contact`),
        None when the loading starts in contact.
    notes : tuple of str
        What reading left out of the file and why (e.g. a time column whose unit is not a
        time), the file's text in them escaped; printed with a fit and kept in its record.
    """

    path: str
    sha256: str
    displacement: np.ndarray
    force: np.ndarray
    time: object
    line: np.ndarray
    segments: np.ndarray
    columns: dict
    units: dict
    header: list = field(default_factory=list)
    contact_estimate: object = None
    inverted: tuple = ()
    notes: tuple = ()

    def __len__(self):
        return self.displacement.size

    def mask(self, which: str = "loading") -> np.ndarray:
        """Rows used by a fit of segment ``which`` (one of :data:`FIT_SEGMENTS`).

        ``loading`` is the approach and the loading (the pushing part up to the deepest
        point), ``retraction`` the unloading branch, ``all`` every row.
        """
        if which not in FIT_SEGMENTS:
            raise ValueError(f"segment must be one of {FIT_SEGMENTS}; got {which!r}")
        if which == "all":
            return np.ones(len(self), bool)
        keep = ("approach", "loading") if which == "loading" else ("retraction",)
        return np.isin(self.segments, keep)

    def counts(self) -> dict:
        """Number of rows in each segment (those with any)."""
        return {s: int(np.sum(self.segments == s)) for s in SEGMENTS if np.any(self.segments == s)}

    def other_pushes(self, share=0.25) -> list:
        """Pushes the loading segment left out: runs of ``other`` rows over which the tip moves in
        by at least ``share`` of the loading's depth span (a second loading pass, a re-test), as
        ``(first row, last row, depth moved in)``, rows as indices of the record."""
        load = np.flatnonzero(self.segments == "loading")
        if load.size < 2:
            return []
        span = float(np.ptp(self.displacement[load]))
        found = []
        other = self.segments == "other"
        edges = np.flatnonzero(np.diff(np.r_[0, other.astype(int), 0]))
        for a, b in zip(edges[0::2], edges[1::2]):
            d = self.displacement[a:b]
            moved = float(np.max(d - np.minimum.accumulate(d))) if d.size else 0.0
            if span > 0 and moved >= share * span:
                found.append((int(a), int(b - 1), moved))
        return found

    def relabel(self, contact):
        """Split the pushing rows at the contact point ``contact`` (m): before it 'approach'."""
        push = np.isin(self.segments, ("approach", "loading"))
        self.segments = np.where(push, np.where(self.displacement < contact, "approach", "loading"), self.segments)


def sha256_of(path) -> str:
    """Hex SHA-256 of a file's bytes (a fit record names the data it was made from)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def record_from_arrays(path, displacement, force, time, line, *, columns, units, header=(), inverted=(),
                       sha256=None, notes=()) -> InstrumentRecord:
    """An :class:`InstrumentRecord` from SI arrays in the package's signs (any row order with a
    time column): sorted by time, segmented, the contact estimated.  ``line``: each row's line
    in the file (or its index)."""
    arr = {"displacement": np.asarray(displacement, float), "force": np.asarray(force, float)}
    line = np.asarray(line)
    t = None if time is None else np.asarray(time, float)
    if t is not None:
        order = np.argsort(t, kind="stable")  # rows in time order: the segments follow time
        arr = {role: a[order] for role, a in arr.items()}
        line, t = line[order], t[order]
    labels = segment(arr["displacement"], t)
    rec = InstrumentRecord(path=str(path), sha256=sha256 or sha256_of(path), displacement=arr["displacement"],
                           force=arr["force"], time=t, line=line, segments=labels, columns=dict(columns),
                           units=dict(units), header=list(header), inverted=tuple(inverted), notes=tuple(notes))
    push = rec.mask("loading")
    if push.sum() >= 3:
        rec.contact_estimate = estimate_contact(rec.displacement[push], rec.force[push])
        if rec.contact_estimate is not None:
            rec.relabel(rec.contact_estimate)
    return rec
