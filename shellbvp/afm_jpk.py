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

import io
import re
from collections import OrderedDict, defaultdict
from pathlib import Path

import numpy as np

__all__ = ["METADATA_KEYS", "jpk_datasets", "parse_properties", "read_properties", "LightCurve", "Curves"]

#: The columns afmformats' ``load_jpk`` offers
_COLUMNS = ("force", "height (measured)", "height (piezo)", "segment", "time")
#: Property sets kept: a curve's segments (afmformats' own cache holds 128 of every curve's)
_CACHED_PROPERTIES = 8
_SEGMENT_FOLDER = re.compile(r"^(.*?segments/\d+/)")
#: Where a property's key ends (jprops: the first ``=``, ``:`` or whitespace)
_KEY_END = re.compile(r"[=: \t\n\r\x0b\x0c]")
#: The metadata :func:`shellbvp.afm_read.curves_from_afm` reads of a curve (and its time column needs)
METADATA_KEYS = ("spring constant", "sensitivity", "duration", "point count", "position x", "position y",
                 "grid center x", "grid center y", "grid shape x", "grid shape y", "grid size x", "grid size y")
#: ... compared with afmformats' own on a file's first curve before the fast path is taken
_CHECKED_KEYS = METADATA_KEYS + ("enum", "grid index x", "grid index y")


def parse_properties(data: bytes) -> dict:
    """A Java property file's ``{key: value}`` (text), as ``jprops.load_properties`` reads it.

    Lines without a backslash (nearly all of JPK's) are split here: the key ends at the first
    ``=``, ``:`` or whitespace, the value follows after whitespace and one ``=`` or ``:``;
    ``#`` and ``!`` start comments.  A line with a backslash (an escape such as JPK's
    ``13\\:57`` in a time stamp) goes through jprops on its own, and a file with a line
    continued by a trailing backslash through jprops whole: the same text, parsed about 10x
    faster than jprops alone."""
    import jprops

    text = data.decode("latin-1").replace("\r\n", "\n").replace("\r", "\n")
    lines = text.split("\n")
    if any(ln.endswith("\\") for ln in lines):
        return jprops.load_properties(io.BytesIO(data))
    out = {}
    for line in lines:
        body = line.lstrip()
        if not body or body[0] in "#!":
            continue
        if "\\" in body:
            out.update(jprops.load_properties(io.StringIO(body)))
            continue
        m = _KEY_END.search(body)
        if m is None:  # no terminator: the whole line is the key, the value empty
            out[body] = ""
            continue
        value = body[m.end():].lstrip()
        if m.group() not in "=:" and value[:1] in ("=", ":"):
            value = value[1:].lstrip()
        out[body[:m.start()]] = value
    return out


def read_properties(archive, member) -> dict:
    """The property file ``member`` of an open zip ``archive`` (:func:`parse_properties`)."""
    with archive.open(member, "r") as fd:
        return parse_properties(fd.read())


def _reader_class():
    """:class:`ArchiveReader`, or None when afmformats' reader is not built as this one expects
    (another version: its own loader is used)."""
    from afmformats import meta
    from afmformats.errors import MissingMetaDataError
    from afmformats.formats.fmt_jpk import jpk_data, jpk_meta
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
            self._index_header = None  # (index, its header.properties parsed, converted)
            self._segment_md = {}  # {"index": the curve, segment: its segment_metadata}
            self._numbers = {}  # property text -> afmformats' conversion (a float, or the text)
            self._substituted = {}  # channel keys and numbers -> the shared properties they stand for
            self._general = None  # header.properties converted
            self.fast = False  # columns and metadata without afmformats' MetaData (jpk_datasets)
            self._shared = None  # the shared header's properties by start (_shared_groups)

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
                self._properties[key] = self._segment_properties(int(index), segment)
                if len(self._properties) > _CACHED_PROPERTIES:
                    self._properties.popitem(last=False)
            return self._properties[key]

        def _parsed(self, member):
            return read_properties(ArchiveCache.get(self.path), member)

        def _segment_properties(self, index, segment):
            """afmformats' ``JPKReader._get_index_segment_properties`` (its steps 1-6, the same
            dict), built from parts parsed and converted once: the curve's header for all its
            segments, the shared header's channel properties for each set of channel numbers
            (found by their ``mediator.number.`` start, not by a scan of all of them per key),
            the general header once; the files parsed by :func:`parse_properties`."""
            if self._index_header is None or self._index_header[0] != index:
                raw = self._parsed(self.get_index_path(index) + "header.properties")
                self._index_header = (index, raw, {k: self._number(v) for k, v in raw.items()})
            raw = dict(self._index_header[1])
            prop = dict(self._index_header[2])
            if segment is not None:
                part = self._parsed(self.get_index_segment_path(index, segment) + "segment-header.properties")
                raw.update(part)
                prop.update((k, self._number(v)) for k, v in part.items())
            stars = tuple(sorted((k, v) for k, v in raw.items() if ".*" in k))
            if stars not in self._substituted:
                self._substituted[stars] = self._substitute(stars)
            prop.update(self._substituted[stars])
            if self._general is None:
                self._general = {k: self._number(v) for k, v in self._properties_general.items()}
            prop.update(self._general)
            for name in [k for k, v in prop.items() if v != v]:  # NaN: dropped, as afmformats drops it
                prop.pop(name)
            recipe = jpk_meta.get_primary_meta_recipe()
            for what, slot, unit in (("spring constant", "distance", "N"), ("sensitivity", "volts", "m")):
                if what in self._user_metadata:
                    for multiplier in recipe[what]:
                        base = multiplier.rsplit(".", 1)[0]
                        prop[multiplier] = self._user_metadata[what]
                        prop[base + ".offset"] = 0
                        prop[base + ".unit"] = unit
                        prop[multiplier.rsplit(".", 2)[0] + ".base-calibration-slot"] = slot
            return prop

        def _substitute(self, stars):
            """``{key: value}`` (converted) that afmformats' step 3 sets for the channel keys
            ``stars`` (``(key ending in .*, channel number)``, sorted): the shared header's
            properties of each channel number under the channel's name."""
            shared, work, out = self._shared_groups(), dict(stars), {}
            for name, _ in stars:
                number, mediator, head = work[name], ".".join(name.split(".")[-2:-1]), name.rsplit(".", 2)[0]
                start = f"{mediator}.{number}."
                found = shared.get(start) if start.count(".") == 2 else \
                    [(".".join(k.split(".")[2:]), v) for k, v in shared[None] if k.startswith(start)]
                for var, value in found or ():
                    out[f"{head}.{var}"] = value
                    if f"{head}.{var}" in work:
                        work[f"{head}.{var}"] = value
            return {k: self._number(v) for k, v in out.items()}

        def _number(self, text):
            """afmformats' conversion of a property: a float where ``float`` takes it, else the text."""
            value = self._numbers.get(text, self._numbers) if isinstance(text, str) else self._numbers
            if value is self._numbers:
                try:
                    value = float(text)
                except BaseException:  # noqa: BLE001 -- as afmformats: text stays text
                    value = text
                if isinstance(text, str) and len(self._numbers) < 100_000:
                    self._numbers[text] = value
            return value

        def _shared_groups(self):
            """The shared header's ``(key, value)`` sorted, grouped by the start ``a.b.`` of
            their keys (``None``: all of them)."""
            if self._shared is None:
                items = sorted(self._properties_shared.items())
                groups = defaultdict(list)
                for k, v in items:
                    parts = k.split(".")
                    if len(parts) > 2:
                        groups[f"{parts[0]}.{parts[1]}."].append((".".join(parts[2:]), v))
                self._shared = {**groups, None: items}
            return self._shared

        def set_metadata(self, metadata):
            self._user_metadata.clear()
            self._user_metadata.update(metadata)
            self.get_metadata.cache_clear()
            self._properties.clear()
            self._index_header = self._general = None
            self._segment_md, self._substituted = {}, {}

        def get_data(self, column, index, segment=None):
            if self.fast and segment is None:  # the segments' columns joined, as afmformats joins them
                return np.concatenate([self.get_data(column, index, seg)
                                       for seg in self.get_index_segment_numbers(index)])
            if segment is None or (column in ("time", "segment") and not self.fast):
                return super().get_data(column, index, segment)  # concatenates segments through this method
            md = self.segment_metadata(index, segment) if self.fast else self.get_metadata(index, segment)
            if column == "time":  # afmformats' own: the segment's samples after the earlier segments' time
                start = sum(self.segment_metadata(index, s)["duration"] for s in range(segment))
                return np.linspace(start, start + md["duration"], md["point count"], endpoint=False)
            if column == "segment":
                return np.ones(md["point count"], dtype=np.uint8) * segment
            prop = self._get_index_segment_properties(index, segment)
            folder = self.get_index_segment_path(index, segment)
            name, slot, dat = jpk_data.find_column_dat(self.files.under(folder), column)
            with ArchiveCache.get(self.path).open(dat, "r") as fd:
                data, unit, _ = jpk_data.load_dat_unit(fd, name=name, properties=prop, slot=slot)
            if unit != jpk_data.JPK_UNITS[column]:
                raise jpk_data.ReadJPKError(f"Unknown unit for {column}: {unit}")
            return data

        def segment_metadata(self, index, segment):
            """The items :data:`METADATA_KEYS` of afmformats' ``get_metadata(index, segment)``, the
            same values, without building its ``MetaData`` (whose every item set searches the
            grid again): the primary recipe's first property present, converted as afmformats
            converts it, the grid index from the position as its ``MetaData`` completes it."""
            if self._segment_md.get("index") != int(index):
                self._segment_md = {"index": int(index)}
            if segment in self._segment_md:
                return self._segment_md[segment]
            prop = self._get_index_segment_properties(index, segment)
            recipe = jpk_meta.get_primary_meta_recipe()
            md = {}
            for name in METADATA_KEYS:
                found = next((prop[v] for v in recipe.get(name, ()) if v in prop), None)
                if found is not None and not (isinstance(found, float) and np.isnan(found)):
                    md[name] = meta.DEF_ALL[name][2](found)
            missing = [k for k in ("spring constant", "sensitivity") if k not in md]
            if missing:
                raise MissingMetaDataError(missing, f"Missing meta data: '{missing}'")
            md["enum"] = int(self.get_index_numbers()[index])
            for ax in "xy":
                need = [f"grid center {ax}", f"grid shape {ax}", f"grid size {ax}", f"position {ax}"]
                if f"grid index {ax}" not in md and all(k in md for k in need):
                    md[f"grid index {ax}"] = meta.MetaData._convert_position_to_index(
                        pos_m=md[f"position {ax}"], size_m=md[f"grid size {ax}"], center_m=md[f"grid center {ax}"],
                        size_px=md[f"grid shape {ax}"])
            for name in ("grid shape x", "grid shape y", "grid index x", "grid index y", "point count"):
                if name in md:
                    md[name] = int(round(md[name]))
            self._segment_md[segment] = md
            return md

        def curve_metadata(self, index):
            """:meth:`segment_metadata` of the whole curve, merged as afmformats'
            ``get_metadata(index)`` merges its segments: the first segment's values, durations
            and point counts summed."""
            md = {}
            for seg in self.get_index_segment_numbers(index)[::-1]:
                part = dict(self.segment_metadata(index, seg))
                for name in ("duration", "point count"):
                    if name in md and name in part:
                        md[name] += part.pop(name)
                md.update(part)
            return md

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

    if not meta_override and len(reader) and _same_metadata(reader):
        reader.fast = True  # checked on the first curve: its metadata and time as afmformats gives them

        def light():
            for index in range(len(reader)):
                yield LightCurve(reader, index, reader.curve_metadata(index))

        return Curves(len(reader), light())

    def curves():
        for index in range(len(reader)):
            data = LazyData()
            for column in _COLUMNS:
                data.set_lazy_loader(column=column, func=reader.get_data, kwargs={"column": column, "index": index})
            metadata = reader.get_metadata(index=index)
            metadata["z range"] = LazyMetaValue(lambda d: np.ptp(d["height (piezo)"]), data)
            metadata["format"] = label
            yield AFMForceDistance(data=data, metadata=metadata)

    return Curves(len(reader), curves())


class Curves:
    """The curves of an archive, one at a time, and how many there are (``len``: from the
    archive's list of members, before any curve is read)."""

    def __init__(self, count, curves):
        self._count, self._curves = count, curves

    def __len__(self):
        return self._count

    def __iter__(self):
        return self._curves


def _same_metadata(reader) -> bool:
    """True when the fast path's metadata and time of the file's first and last curves are
    afmformats' own (:data:`_CHECKED_KEYS`); the reader is left on afmformats' path."""
    for index in {0, len(reader) - 1}:
        theirs = reader.get_metadata(index=index)
        ours = reader.curve_metadata(index)
        if any(dict.get(theirs, k) != ours.get(k) for k in _CHECKED_KEYS):
            return False
        slow = reader.get_data("time", index)
        reader.fast = True
        try:
            same = np.array_equal(slow, reader.get_data("time", index))
        finally:
            reader.fast = False
        if not same:
            return False
    return True


class LightCurve:
    """One curve of a JPK archive as :func:`shellbvp.afm_read.curves_from_afm` reads it:
    afmformats' columns (each read from the archive when asked for) and a plain dict of the
    metadata it uses (:data:`METADATA_KEYS`, ``enum``, the grid index)."""

    columns = _COLUMNS

    def __init__(self, reader, index, metadata):
        self._reader, self._index, self.metadata = reader, index, metadata

    def __getitem__(self, column):
        return self._reader.get_data(column=column, index=self._index)
