"""Text from files is data (issue 42): escapes, not terminal control; cells, not formulas."""

import csv

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main
from shellbvp.textdata import printable, table_cell

HOSTILE = "ok\x1b[2J\x1b[1;1Hmu*H = 1 N/m\u202e\x07\r\n\x9b"


def test_printable_escapes_every_control_and_format_character():
    out = printable(HOSTILE)
    assert not any(ord(c) < 0x20 or 0x7f <= ord(c) < 0xa0 or c == "\u202e" for c in out)
    assert out.startswith("ok\\x1b[2J") and "\\u202e" in out and "\\x9b" in out
    for ordinary in ("µm, mN — Lepidium (2018)", "a/b\\c", "naïve ΔF"):
        assert printable(ordinary) == ordinary


@pytest.mark.parametrize("text", ["=HYPERLINK(\"http://x\",\"y\")", "+1", "-1+2", "@SUM(A1)", "\tx", "\rx"])
def test_table_cells_never_start_a_formula(text):
    assert table_cell(text).startswith("'")
    assert table_cell("seed1.csv") == "seed1.csv"


def test_a_fit_file_with_escape_sequences_prints_them_as_data(tmp_path, capsys):
    import h5py

    out = tmp_path / "f.h5"
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "-o", str(out)]) == 0
    with h5py.File(out, "r+") as h:
        h["fit"].attrs["message"] = HOSTILE
        del h["fit/source/file_name"]
        h["fit/source"].create_dataset("file_name", data=HOSTILE, dtype=h5py.string_dtype())
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "\x1b" not in text and "\u202e" not in text and "\x07" not in text
    assert text.count("\\x1b[2J") == 2                      # message and source name, shown escaped


def test_batch_table_escapes_hostile_file_names(tmp_path, monkeypatch):
    from shellbvp.fitting import example_data_path

    monkeypatch.chdir(tmp_path)
    name = '=HYPERLINK("http:x","y").csv'
    (tmp_path / name).write_bytes(open(example_data_path(), "rb").read())
    table = tmp_path / "t.csv"
    assert main(["fit", name, "--preset", "fit", "--radius", "0.3mm", "--table", str(table)]) == 0
    with open(table, newline="") as f:
        rows = list(csv.DictReader(f))
    assert rows and all(r["file"].startswith("'=") for r in rows)


def test_sweep_cleanup_treats_the_output_name_as_a_name(tmp_path):
    """-o 'run[12].h5' must not delete .run1.h5.*.tmp, another writer's file in flight."""
    other = tmp_path / ".run1.h5.abc.tmp"
    other.write_text("another writer")
    out = tmp_path / "run[12].h5"
    from shellbvp.sweeps import sweep

    grid = sweep(sb.Scene.preset("base"), {"beta": [0.01]}, delta_max=0.05, out=out, workers=1)
    assert np.all(np.asarray(grid.index["status"]) == "complete")
    assert other.exists()


def test_a_sweep_grid_is_counted_before_anything_is_allocated(capsys):
    """1e8 combinations ended in MemoryError after 9 s: now one line, at once (issue 42)."""
    import time

    from shellbvp.sweeps import sweep

    t0 = time.perf_counter()
    v = ",".join(str(0.005 + i * 1e-5) for i in range(100))
    rc = main(["sweep", "--beta", v, "--rho", "0.1:0.3:100", "--gamma", "0.5:1.5:100", "--alpha", "0:1:100",
               "-o", "never.h5"])
    err = capsys.readouterr().err
    assert rc == 2 and "100000000 combinations" in err and "--max-cells" in err
    assert time.perf_counter() - t0 < 5
    with pytest.raises(ValueError, match="exceed max_cells = 3"):
        sweep(sb.Scene.preset("base"), {"beta": [0.01, 0.02], "rho": [0.2, 0.25]}, delta_max=0.1, max_cells=3)
    with pytest.raises(ValueError, match="max_cells must be an integer"):
        sweep(sb.Scene.preset("base"), {"beta": [0.01]}, delta_max=0.1, max_cells=0)


def test_a_second_loading_pass_is_never_dropped_silently(tmp_path, capsys):
    """Two loading passes, the second at 3x the force: the fit names both (issue 42: it had
    fitted 3x mu*H from the second alone, exit 0, no warning)."""
    from shellbvp.fitting import example_data_path

    d, F = np.loadtxt(example_data_path(), delimiter=",", skiprows=2, unpack=True)
    down = d[::-1]
    rows = [(x, y) for x, y in zip(d, F)] + [(x, 0.5 * y) for x, y in zip(down, F[::-1])] \
        + [(x, 3 * y) for x, y in zip(d, F)]
    path = tmp_path / "two.csv"
    path.write_text("displacement (mm),force (mN)\n" + "\n".join(f"{x:.6f},{y:.6f}" for x, y in rows) + "\n")
    rc = main(["fit", str(path), "--preset", "fit", "--radius", "0.3mm"])
    out = capsys.readouterr().out
    assert "2 loading passes" in out and "left out" in out, out
    assert rc in (0, 1)


def test_inputs_that_are_not_files_get_a_row_each_and_never_hang_the_batch(tmp_path, capsys):
    """A FIFO (no writer), /dev/zero, a folder named like data and a symlink loop: each is one
    error row saying what it is; the good file's result and the table survive (issue 42)."""
    import os
    import shutil

    from shellbvp.fitting import example_data_path

    folder = tmp_path / "data"
    folder.mkdir()
    shutil.copy(example_data_path(), folder / "good.csv")
    os.mkfifo(folder / "pipe.csv")
    (folder / "sub.csv").mkdir()
    os.symlink(folder / "loop.csv", folder / "loop.csv")
    table = tmp_path / "t.csv"
    rc = main(["fit", str(folder), "/dev/zero", "--preset", "fit", "--radius", "0.3mm", "--table", str(table)])
    out = capsys.readouterr().out
    assert rc == 1
    with open(table, newline="") as f:
        rows = {os.path.basename(r["file"]): r for r in csv.DictReader(f)}
    assert rows["good.csv"]["status"] == "ok"
    assert "FIFO" in rows["pipe.csv"]["message"] and "directory" in rows["sub.csv"]["message"]
    assert "symbolic links" in rows["loop.csv"]["message"] and "character device" in rows["zero"]["message"]
    assert "1 of 5 files fitted" in out


def test_the_afmformats_boundary_gives_one_escaped_line_for_any_exception():
    from shellbvp.afm_read import AFMFileError, afmformats_boundary

    for exc in (NotImplementedError("format '\x1b[2J'\nnot supported"), KeyError("x"), MemoryError()):
        with pytest.raises(ValueError) as info:
            with afmformats_boundary("a\x1b]0;x.jpk-force"):
                raise exc
        msg = str(info.value)
        assert type(info.value) is ValueError and "\n" not in msg and "\x1b" not in msg
        assert msg.startswith("a\\x1b]0;x.jpk-force: afmformats cannot read it (" + type(exc).__name__)
    with pytest.raises(AFMFileError, match="ours"):
        with afmformats_boundary("f.ibw"):
            raise AFMFileError("ours")
    with pytest.raises(KeyboardInterrupt):
        with afmformats_boundary("f.ibw"):
            raise KeyboardInterrupt
