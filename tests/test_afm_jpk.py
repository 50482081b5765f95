"""JPK archives read curve by curve (shellbvp.afm_jpk, issue 56): the same curves as
afmformats' own loader, each property file parsed once."""

from pathlib import Path

import numpy as np
import pytest

from shellbvp.afm import curves_from_afm, read_afm

afmformats = pytest.importorskip("afmformats")
jprops = pytest.importorskip("jprops")

DATA = Path(__file__).parent / "data" / "afm"
QI = DATA / "qi-data-2x2.jpk-qi-data"  # four curves on a grid


@pytest.mark.parametrize("name", ["qi-data-2x2.jpk-qi-data", "spot3-0192.jpk-force"])
def test_jpk_curves_are_afmformats_own(name):
    """Every column, grid index, position and curve number as afmformats.load_data gives them."""
    path = DATA / name
    ours = read_afm(path)
    theirs = curves_from_afm(afmformats.load_data(str(path)), path, sha256=ours[0].record.sha256)
    assert len(ours) == len(theirs) >= 1
    for a, b in zip(ours, theirs):
        for column in ("displacement", "force", "time"):
            np.testing.assert_array_equal(getattr(a.record, column), getattr(b.record, column))
        assert (a.index, a.grid, a.position, a.grid_geometry) == (b.index, b.grid, b.position, b.grid_geometry)
    if name.startswith("qi"):
        assert [c.grid for c in ours] == [(0, 0), (1, 0), (2, 0), (3, 0)]


def test_each_property_file_is_parsed_once(monkeypatch):
    """afmformats' own reader parses a curve's property files again for its columns (its caches
    keyed by how they are called, 128 entries) and its header once per segment: a map's cost grew
    faster than its curves, and each curve paid for three parses."""
    from shellbvp import afm_jpk

    parsed = []
    read = afm_jpk.read_properties

    def counting(archive, member):
        parsed.append(member)
        return read(archive, member)

    monkeypatch.setattr(afm_jpk, "read_properties", counting)
    curves = read_afm(QI)
    per_segment = [p for p in parsed if p.endswith("segment-header.properties")]
    per_curve = [p for p in parsed if p.endswith("header.properties") and "segments" not in p]
    assert len(curves) == 4
    assert len(per_segment) == len(set(per_segment)) == 4 * 2, sorted(per_segment)
    assert len(per_curve) == len(set(per_curve)) == 4, sorted(per_curve)


@pytest.mark.parametrize("name", ["qi-data-2x2.jpk-qi-data", "spot3-0192.jpk-force",
                                  "flipsign_2015.05.22-15.31.49.352.jpk-force"])
def test_property_files_and_sets_are_afmformats_own(name):
    """Each property file as jprops parses it; each segment's property set and the metadata the
    package reads as afmformats' JPKReader builds them."""
    import io
    import zipfile

    from afmformats.formats.fmt_jpk.jpk_reader import JPKReader

    from shellbvp.afm_jpk import METADATA_KEYS, _reader_class, parse_properties

    path = str(DATA / name)
    with zipfile.ZipFile(path) as z:
        for member in (m for m in z.namelist() if m.endswith(".properties")):
            data = z.read(member)
            assert parse_properties(data) == jprops.load_properties(io.BytesIO(data)), member
    ours, theirs = _reader_class()(path), JPKReader(path)
    for index in range(len(theirs)):
        for seg in theirs.get_index_segment_numbers(index):
            assert ours._get_index_segment_properties(index, seg) == \
                JPKReader._get_index_segment_properties.__wrapped__(theirs, index, seg)
        md, light = theirs.get_metadata(index), ours.curve_metadata(index)
        for key in METADATA_KEYS + ("enum", "grid index x", "grid index y"):
            assert dict.get(md, key) == light.get(key), key


def test_property_lines_with_escapes_and_odd_separators_read_as_jprops_reads_them():
    from shellbvp.afm_jpk import parse_properties

    text = (b"# comment\n! also\n  a=1\nb : two words \nc\td\ne  =  :x\nf\ng=h\\:i\\u0041\n"
            b"k=continued \\\n  here\r\nl:=m\n\n=empty key\n")
    assert parse_properties(text) == jprops.load_properties(io_bytes(text))
    for line in (b"a b", b"a  = b", b"a:b:c", b"x\\ y=z", b"  # not=a property"):
        assert parse_properties(line) == jprops.load_properties(io_bytes(line)), line


def io_bytes(data):
    import io

    return io.BytesIO(data)


def test_another_afmformats_reader_falls_back_to_its_own_loader(monkeypatch):
    """When afmformats' reader is not built as shellbvp.afm_jpk expects (another version), the
    file is read by afmformats.load_data: the same curves."""
    from shellbvp import afm_jpk

    ours = read_afm(QI)
    monkeypatch.setattr(afm_jpk, "_reader_class", lambda: None)
    assert afm_jpk.jpk_datasets(QI) is None
    theirs = read_afm(QI)
    assert [c.grid for c in theirs] == [c.grid for c in ours]
    for a, b in zip(ours, theirs):
        np.testing.assert_array_equal(a.record.force, b.record.force)
