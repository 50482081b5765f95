"""The registry of instrument readers (shellbvp/readers/, issue 57): each format recognised by
one reader, the options each takes and what it says of the others, hints for a file given
where another kind is wanted, and a new reader as one declaration."""

from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp import readers
from shellbvp.batch import expand_inputs
from shellbvp.cli import main
from shellbvp.readers import registry, text_table

DATA = Path(__file__).parent / "data" / "afm"


@pytest.mark.parametrize("name, reader", [
    ("spot3-0192.jpk-force", "JPK"), ("qi-data-2x2.jpk-qi-data", "JPK"), ("SiN_FD_plot.ibw", "Asylum"),
    ("afm-workshop-single.csv", "AFM Workshop"), ("ntmdt-gel4.txt", "NT-MDT Nova")])
def test_each_afm_file_is_recognised_by_its_reader(name, reader):
    assert readers.reader_for(DATA / name).name == reader
    assert readers.reader_for(DATA / name, curves=True).name == reader


def test_a_text_table_and_an_unknown_file_go_to_the_fallbacks(tmp_path):
    table = tmp_path / "seed.txt"
    table.write_text("d (um)\tF (uN)\n0\t0\n1\t1\n2\t4\n")
    assert readers.reader_for(table).name == "text table"
    assert readers.reader_for(tmp_path / "missing.csv").name == "text table"  # nothing opened
    assert readers.reader_for(table, curves=True).name == "afmformats"      # asked for its curves
    assert readers.reader_for(DATA / "spot3-0192.JPK-FORCE").name == "JPK"  # endings in any case


def test_every_reader_has_one_name_and_one_order():
    names = [r.name for r in readers.READERS]
    orders = [r.order for r in readers.READERS]
    assert len(set(names)) == len(names) and orders == sorted(set(orders))
    with pytest.raises(ValueError, match="clashes with 'JPK'"):
        registry.register(registry.Reader(name="JPK", order=1, what="", hint="", read=None))


def test_options_a_reader_does_not_take_are_refused_naming_those_that_do(tmp_path):
    csv = tmp_path / "seed.csv"
    csv.write_text("d (um),F (uN)\n0,0\n1,1\n2,4\n3,9\n")
    with pytest.raises(ValueError, match=r"not an AFM file: --spring-constant .*\(AFM Workshop, NT-MDT Nova\)"):
        readers.read_record(csv, spring_constant=0.1)
    with pytest.raises(ValueError, match="gives its own columns, units and signs"):
        readers.read_record(DATA / "spot3-0192.jpk-force", invert=("force",))
    with pytest.raises(ValueError, match=r"carries the cantilever's calibration.*\(AFM Workshop, NT-MDT Nova\)"):
        readers.read_curves(DATA / "SiN_FD_plot.ibw", spring_constant=0.1, sensitivity=1e-7)
    with pytest.raises(ValueError, match=r"the spring constant must be a finite number > 0; got -1"):
        readers.read_curves(DATA / "ntmdt-gel4.txt", spring_constant=-1, sensitivity=1e-7)
    with pytest.raises(ValueError, match=r"NT-MDT Nova export .* --spring-constant K --sensitivity S .*header row"):
        readers.read_curves(DATA / "ntmdt-gel4.txt", spring_constant=0.1)
    rec = readers.read_record(csv, units=("um", "uN"))
    assert rec.units == {"displacement": "um", "force": "uN"} and len(rec) == 4


def test_an_afm_file_given_as_a_table_says_what_it_is_and_how_it_is_read(tmp_path, capsys):
    with pytest.raises(ValueError, match=r"spot3-0192.jpk-force: a JPK archive, not a text table: `shellbvp fit"):
        readers.read_table(DATA / "spot3-0192.jpk-force")
    from shellbvp.pixel_table import read_pixel_table

    with pytest.raises(ValueError, match=r"an AFM Workshop export, not a text table"):
        read_pixel_table(DATA / "afm-workshop-single.csv")


def test_a_new_reader_is_one_declaration(tmp_path):
    """A format of its own (``.fdx``: rows of force in nN and depth in nm, no header) declared as
    one Reader: read_instrument, a folder's batch and the command line take it."""
    def read(path, *, invert=()):
        rec = text_table.read_text(path, columns=(1, 0), units=("nm", "nN"), invert=invert)
        rec.columns["displacement"], rec.columns["force"] = "depth", "force"
        return rec

    fdx = registry.register(registry.Reader(name="FDX", order=50, suffixes=(".fdx",), folder_suffixes=(".fdx",),
                                            what="an FDX record", hint="`shellbvp fit FILE` reads it",
                                            options=("invert",), read=read))
    try:
        rows = [(0.5 * max(d - 200, 0) ** 1.5, d) for d in range(0, 2000, 50)]
        path = tmp_path / "seed.fdx"
        path.write_text("".join(f"{f:.6g} {d}\n" for f, d in rows))
        rec = sb.read_instrument(path)
        assert rec.units == {"displacement": "nm", "force": "nN"}
        np.testing.assert_allclose(rec.displacement[:3], [0, 50e-9, 100e-9])
        with pytest.raises(ValueError, match="FDX record takes no --units"):
            sb.read_instrument(path, units=("um", "uN"))
        assert expand_inputs([str(tmp_path)]) == [str(path)]
        assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "--units", "um,uN"]) == 2
    finally:
        registry.READERS.remove(fdx)
    assert readers.reader_for(tmp_path / "seed.fdx").name == "text table"


def test_curves_stream_one_at_a_time_through_the_registry_and_a_map_is_bounded():
    """iter_curves (shellbvp.afm.iter_afm) gives the reader's curves lazily, the same as
    read_curves; its options are checked at once, and a file of more curves than MAX_MAP_CURVES
    is refused before its first curve is decoded."""
    from shellbvp import afm_read
    from shellbvp.afm import iter_afm, read_afm

    qi = DATA / "qi-data-2x2.jpk-qi-data"
    assert readers.reader_for(qi).iterate is not None
    whole, stream = read_afm(qi), iter_afm(qi)
    assert not isinstance(stream, list)
    first = next(stream)
    assert first.grid == whole[0].grid and np.array_equal(first.record.force, whole[0].record.force)
    assert [c.grid for c in stream] == [c.grid for c in whole[1:]]
    with pytest.raises(ValueError, match="carries the cantilever's calibration"):
        iter_afm(qi, spring_constant=0.1)  # not a generator: refused before any reading
    decoded = []

    class Declared:  # what a JPK archive of more curves than the bound gives: its count, then its curves
        def __len__(self):
            return afm_read.MAX_MAP_CURVES + 1

        def __iter__(self):
            decoded.append(1)
            return iter(())

    with pytest.raises(ValueError, match=rf"qi-data-2x2.jpk-qi-data: {afm_read.MAX_MAP_CURVES + 1} curves; "
                                         rf"shellbvp fits at most {afm_read.MAX_MAP_CURVES} curves of a map \(MAX_MAP_CURVES\): "
                                         rf"cut the map into parts"):
        next(afm_read.iter_afm(qi, load=lambda path, meta_override: Declared()))
    assert decoded == []  # refused before its first curve
