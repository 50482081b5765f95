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
    keyed by how they are called, 128 entries): a map's cost grew faster than its curves."""
    parsed = []
    load = jprops.load_properties

    def counting(fd, *args, **kwargs):
        parsed.append(getattr(fd, "name", "?"))
        return load(fd, *args, **kwargs)

    monkeypatch.setattr(jprops, "load_properties", counting)
    curves = read_afm(QI)
    per_segment = [p for p in parsed if p.endswith("segment-header.properties")]
    assert len(curves) == 4
    assert len(per_segment) == len(set(per_segment)) == 4 * 2, sorted(per_segment)


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
