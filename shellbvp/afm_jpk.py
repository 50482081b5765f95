"""JPK archives read by afmformats in time proportional to their curves.

afmformats 0.18.7 reads a JPK force map in time that grows with the square of its curves:
for every segment of every curve its ``JPKReader`` searches the archive's whole member list
(``path not in self.files``, and ``[ff for ff in self.files if ff.count(p_seg)]`` to find
the segment's channels), and its property caches (``functools.lru_cache``, 128 entries,
keyed differently by keyword and positional calls) are evicted on a map of more than 64
curves, so each segment's property files are parsed three times.  A 32 x 32 map took 5x
the time of a 16 x 16 one.

:class:`ArchiveReader` is afmformats' reader with those look-ups made O(1) (the member list
indexed once) and one small property cache keyed by ``(index, segment)``; :func:`jpk_datasets`
is afmformats' ``load_jpk`` as a generator: each curve's metadata is read just before its
columns are (by :func:`shellbvp.afm_read.curves_from_afm`), so each property file is parsed
once while it is in the cache, and no more than one curve's arrays wait in memory.  The
conversion of the channels (calibrations, units) is afmformats' own.
"""

from __future__ import annotations

import re
from collections import OrderedDict, defaultdict
from pathlib import Path

import numpy as np

__all__ = ["jpk_datasets"]

#: The columns afmformats' ``load_jpk`` offers
_COLUMNS = ("force", "height (measured)", "height (piezo)", "segment", "time")
#: Property sets kept: a curve's segments (afmformats' own cache holds 128 of every curve's)
_CACHED_PROPERTIES = 8
_SEGMENT_FOLDER = re.compile(r"^(.*?segments/\d+/)")


def _reader_class():
    """:class:`ArchiveReader`, or None when afmformats' reader is not built as this one expects
    (another version: its own loader is used)."""
    from afmformats.formats.fmt_jpk import jpk_data
    from afmformats.formats.fmt_jpk.jpk_reader import ArchiveCache, JPKReader

    if not (hasattr(getattr(JPKReader.files, "fget", None), "__wrapped__")
            and hasattr(JPKReader._get_index_segment_properties, "__wrapped__")
            and hasattr(JPKReader.get_metadata, "cache_clear")):
        return None

    class Members(list):
        """The archive's sorted member names, with O(1) membership and members per segment folder."""

        def __init__(self, names):
            super().__init__(names)
            self._set = frozenset(names)
            self._folders = defaultdict(list)
            for name in names:
                m = _SEGMENT_FOLDER.match(name)
                if m:
                    self._folders[m.group(1)].append(name)

        def __contains__(self, name):
            return name in self._set

        def under(self, folder):
            """The members whose path starts with a segment's folder (``.../segments/N/``)."""
            return self._folders.get(folder, [])

    class ArchiveReader(JPKReader):
        """afmformats' ``JPKReader`` with O(1) member look-ups and one property cache."""

        def __init__(self, path):
            super().__init__(path)
            self._members = None
            self._properties = OrderedDict()

        @property
        def files(self):
            if self._members is None:  # afmformats' sorted list, indexed once
                self._members = Members(JPKReader.files.fget.__wrapped__(self))
            return self._members

        def _get_index_segment_properties(self, index, segment):
            key = (int(index), segment)
            if key in self._properties:
                self._properties.move_to_end(key)
            else:
                self._properties[key] = JPKReader._get_index_segment_properties.__wrapped__(self, index, segment)
                if len(self._properties) > _CACHED_PROPERTIES:
                    self._properties.popitem(last=False)
            return self._properties[key]

        def set_metadata(self, metadata):
            self._user_metadata.clear()
            self._user_metadata.update(metadata)
            self.get_metadata.cache_clear()
            self._properties.clear()

        def get_data(self, column, index, segment=None):
            if segment is None or column in ("time", "segment"):
                return super().get_data(column, index, segment)  # concatenates segments through this method
            self.get_metadata(index, segment)  # as afmformats: a missing calibration raises here
            prop = self._get_index_segment_properties(index, segment)
            folder = self.get_index_segment_path(index, segment)
            name, slot, dat = jpk_data.find_column_dat(self.files.under(folder), column)
            with ArchiveCache.get(self.path).open(dat, "r") as fd:
                data, unit, _ = jpk_data.load_dat_unit(fd, name=name, properties=prop, slot=slot)
            if unit != jpk_data.JPK_UNITS[column]:
                raise jpk_data.ReadJPKError(f"Unknown unit for {column}: {unit}")
            return data

    return ArchiveReader


def jpk_datasets(path, meta_override=None):
    """afmformats' curves (``AFMForceDistance``) of a JPK archive, one at a time, or None when the
    file is no force-distance measurement (creep compliance, stress relaxation: left to
    ``afmformats.load_data``), as when afmformats' reader is not the one this module extends.
    Read each curve's columns before taking the next."""
    from afmformats.formats import formats_by_suffix
    from afmformats.lazy_loader import LazyData
    from afmformats.meta import LazyMetaValue
    from afmformats.mod_force_distance import AFMForceDistance

    recipes = formats_by_suffix.get(Path(path).suffix)
    reader_class = _reader_class()
    if not recipes or reader_class is None:
        return None
    reader = reader_class(str(path))
    reader.set_metadata(dict(meta_override or {}))
    if reader.get_imaging_mode() != "force-distance":
        return None
    recipe = recipes[0]
    label = f"{recipe['maker']} ({recipe['descr']})"

    def curves():
        for index in range(len(reader)):
            data = LazyData()
            for column in _COLUMNS:
                data.set_lazy_loader(column=column, func=reader.get_data, kwargs={"column": column, "index": index})
            metadata = reader.get_metadata(index=index)
            metadata["z range"] = LazyMetaValue(lambda d: np.ptp(d["height (piezo)"]), data)
            metadata["format"] = label
            yield AFMForceDistance(data=data, metadata=metadata)

    return curves()
