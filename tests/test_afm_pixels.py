"""One pixel of a force map against its fitted model (issue 56, item B): the map file keeps each
curve's fitted rows and the model at them (with units), `shellbvp plot map.h5 --pixel IX,IY`
and `--pixels all|failed -o DIR` draw them, the Python API the same; older map files still read
and say what they cannot show.  The map is benchmarks/make_force_map.py's synthetic JPK archive
(2 x 2, read through afmformats) with one curve made to fail its checks and one to be refused."""

import dataclasses
import importlib.util
import shutil
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main

pytest.importorskip("afmformats")
pytest.importorskip("matplotlib")

from shellbvp.afm import read_afm, read_map_file  # noqa: E402
from shellbvp.batch import fit_map  # noqa: E402

BENCH = Path(__file__).resolve().parent.parent / "benchmarks" / "make_force_map.py"
GOOD, FAILED, ERROR = (0, 0), (1, 0), (0, 1)


def _maker():
    spec = importlib.util.spec_from_file_location("_bench_make_force_map", BENCH)
    maker = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(maker)
    return maker


def _with_force(curve, force):
    return dataclasses.replace(curve, record=dataclasses.replace(curve.record, force=force))


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """``(ForceMap, map file, {grid: the curve's record})``: (0, 0) and (1, 1) the model's
    curves, (1, 0) with a wave on its loading (the fit runs and fails its checks), (0, 1) pulled
    instead of pushed (refused before a fit: an error row with its data).  The map keeps no
    records: the test keeps the curves it fitted."""
    maker = _maker()
    folder = tmp_path_factory.mktemp("pixels")
    path = folder / "cells.jpk-force-map"
    maker.write_map(path, n=2, points=150)
    curves = read_afm(path)
    at = {c.grid: i for i, c in enumerate(curves)}
    f, push = curves[at[FAILED]].record.force, curves[at[FAILED]].record.mask("loading")
    curves[at[FAILED]] = _with_force(curves[at[FAILED]],
                                     np.where(push, f + 0.3 * f.max() * np.sin(np.linspace(0, 40, f.size)), f))
    f, push = curves[at[ERROR]].record.force, curves[at[ERROR]].record.mask("loading")
    curves[at[ERROR]] = _with_force(curves[at[ERROR]], np.where(push, -f, f))
    records = {c.grid: c.record for c in curves}
    fm = fit_map(sb.Scene.preset("fit"), iter(curves), R_L=maker.R_L, path=str(path))
    status = {c.grid: r.status for c, r in zip(fm.curves, fm.rows)}
    assert status == {GOOD: "ok", (1, 1): "ok", FAILED: "failed", ERROR: "error"}, [r.message for r in fm.rows]
    assert all(r.record is None and r.used is None and r.curve_rows is not None for r in fm.rows)
    out = folder / "map.h5"
    fm.to_hdf5(out)
    return fm, out, records


def test_the_map_file_keeps_each_curves_fitted_rows_and_model_with_units(fitted):
    import h5py

    from shellbvp.nexus import missing_units

    fm, out, records = fitted
    assert missing_units(out) == []
    with h5py.File(out) as f:
        g = f["entry/curve_data"]
        assert {k: g[k].attrs["units"] for k in g} == {"start": "1", "displacement": "m", "force": "N",
                                                        "model_force": "N", "rows_fitted": "1"}
        assert g["displacement"].dtype == np.float32 and g["displacement"].compression == "gzip"
        assert list(f["entry/curves/quality"].asstr()[()]) == [r.result.quality if r.result else ""
                                                               for r in fm.rows]
    mf = read_map_file(out)
    for c, row in zip(fm.curves, fm.rows):
        px = mf.pixel(*c.grid)
        rec = records[c.grid]
        used = rec.mask("loading")  # the rows fitted (and an error row's segment)
        assert px.rows_fitted == used.sum() == px.displacement.size  # 150 rows or so: all kept
        np.testing.assert_allclose(px.displacement, rec.displacement[used], rtol=1e-6)
        np.testing.assert_allclose(px.force, rec.force[used], rtol=1e-6, atol=1e-6 * np.abs(rec.force).max())
        if row.result is None:
            assert np.isnan(px.model_force).all() and np.isnan(px.mu_H) and px.quality == ""
        else:
            model = row.result.model_force(rec.displacement[used])
            np.testing.assert_allclose(px.model_force, model, rtol=1e-6, atol=1e-6 * np.abs(model).max())
            assert (px.mu_H, px.quality, px.warning_codes) == (row.result.mu_H, row.result.quality,
                                                              list(row.result.warning_codes))
        assert (px.status, px.message) == (row.status, row.message)
        mem = fm.pixel(*c.grid)  # the in-memory map's pixel: the same rows as the file's
        np.testing.assert_allclose(mem.force, px.force, rtol=1e-6, atol=1e-6 * np.abs(px.force).max())


def test_the_view_of_a_good_and_a_failed_pixel_shows_their_residuals(fitted, tmp_path):
    import matplotlib.pyplot as plt

    fm, out, _ = fitted
    mf = read_map_file(out)
    rms = {}
    for grid, verdict in ((GOOD, "fit, quality good"), (FAILED, "FAILED fit, quality poor")):
        axes = mf.plot_pixel(*grid)
        fig = axes[0, 0].figure
        try:
            assert fig._suptitle.get_text().endswith(f"pixel {grid} (curve {mf.pixel(*grid).index}): {verdict}")
            (res_line,) = [ln for ln in axes[1, 0].get_lines() if len(ln.get_xdata()) > 2]
            px = mf.pixel(*grid)
            np.testing.assert_allclose(res_line.get_ydata(), px.model_force - px.force)
            rms[grid] = np.sqrt(np.mean(res_line.get_ydata() ** 2)) / np.max(px.force)
            notes = "\n".join(t.get_text() for t in fig.texts)
            if grid == FAILED:
                assert "weights_disagree" in notes  # the reason it failed, under the figure
        finally:
            plt.close(fig)
    assert rms[GOOD] < 0.01 < 0.05 < rms[FAILED]  # 1 % noise; a wave of 30 % of the force
    png = tmp_path / "good.png"
    fm.plot_pixel(*GOOD, out=png)  # the in-memory map draws the same
    assert png.stat().st_size > 0


def test_an_error_pixel_shows_its_data_without_a_model(fitted):
    import matplotlib.pyplot as plt

    _, out, _ = fitted
    mf = read_map_file(out)
    px = mf.pixel(*ERROR)
    assert px.status == "error" and "force falls as the displacement grows" in px.message
    axes = mf.plot_pixel(*ERROR)
    try:
        assert axes[0, 0].figure._suptitle.get_text().endswith("no fit (error)")
        assert not axes[1, 0].get_lines()  # no residuals without a model
    finally:
        plt.close(axes[0, 0].figure)


def test_pixels_off_the_map_are_one_line_with_the_valid_range(fitted):
    fm, out, _ = fitted
    mf = read_map_file(out)
    for where in (mf, fm):
        with pytest.raises(ValueError, match=r"^pixel \(2, 0\) is outside the map's 2 x 2 grid: ix 0\.\.1, iy 0\.\.1$"):
            where.pixel(2, 0)
    from shellbvp.map_pixels import locate

    with pytest.raises(ValueError, match=r"pixel \(1, 1\): no curve was measured there; the map's 2 curves are at "
                                         r"\(0, 0\), \(0, 1\)$"):
        locate(np.array([[0, 0], [0, 1]]), (2, 2), 1, 1)
    with pytest.raises(ValueError, match="--pixels must be one of all, failed"):
        mf.pixels("poor")


def test_cli_draws_one_pixel_or_one_figure_per_pixel_and_refuses_too_many(fitted, tmp_path, capsys):
    _, out, _ = fitted
    png = tmp_path / "p.png"
    assert main(["plot", str(out), "--pixel", "0,0", "-o", str(png)]) == 0 and png.stat().st_size > 0
    figs = tmp_path / "figs"
    assert main(["plot", str(out), "--pixels", "failed", "-o", str(figs)]) == 0
    text = capsys.readouterr().out
    assert "2 figures (the pixels whose fit did not succeed)" in text
    assert sorted(p.name for p in figs.iterdir()) == ["map_pixel_0_1.png", "map_pixel_1_0.png"]
    assert main(["plot", str(out), "--pixels", "all", "-o", str(figs), "--max-figures", "3"]) == 2
    assert ("--pixels all would write 4 figures (every curve's) into" in capsys.readouterr().err)
    assert len(list(figs.iterdir())) == 2  # refused before any figure
    for argv, error in ((["--pixel", "2,0"], "--pixel 2,0: pixel (2, 0) is outside the map's 2 x 2 grid: ix 0..1, "
                                             "iy 0..1"),
                        (["--pixel", "1"], "--pixel takes the grid index IX,IY"),
                        (["--pixel", "0,-1"], "--pixel 0,-1: grid indices start at 0"),
                        (["--pixels", "all"], "--pixels writes one figure per pixel: give a directory with -o DIR"),
                        (["--pixels", "all", "-o", str(figs), "--max-figures", "0"], "--max-figures must be >= 1")):
        assert main(["plot", str(out), *argv]) == 2
        err = capsys.readouterr().err
        assert error in err and err.count("\n") == 1, err


def test_pixel_options_are_for_one_force_map_file(fitted, tmp_path, capsys):
    _, out, _ = fitted
    other = tmp_path / "data.csv"
    other.write_text("d,F\n0,0\n")
    assert main(["plot", str(other), "--pixel", "0,0"]) == 2
    assert "--pixel is for one force-map file" in capsys.readouterr().err
    assert main(["plot", str(out), str(out), "--pixels", "all", "-o", str(tmp_path)]) == 2
    assert "got 2 files" in capsys.readouterr().err


def test_an_older_map_file_reads_and_says_what_it_cannot_show(fitted, tmp_path, capsys):
    """A map file written before the per-curve view (no /entry/curve_data, no ratings) still
    reads: the map, each curve's numbers; the view says why it cannot draw a pixel."""
    import h5py

    _, out, _ = fitted
    old = tmp_path / "old.h5"
    shutil.copy(out, old)
    with h5py.File(old, "a") as f:
        del f["entry/curve_data"]
        for name in ("quality", "warning_codes", "warnings"):
            del f[f"entry/curves/{name}"]
    mf = read_map_file(old)
    px = mf.pixel(*GOOD)
    assert px.displacement is None and px.status == "ok" and px.mu_H > 0 and px.quality == ""
    with pytest.raises(ValueError, match="stores no curve data .*not a pixel's data and model; fit the map again"):
        mf.plot_pixel(*GOOD)
    assert main(["plot", str(old), "--pixel", "0,0", "-o", str(tmp_path / "p.png")]) == 2
    assert "stores no curve data" in capsys.readouterr().err
    assert main(["plot", str(old), "--pixels", "all", "-o", str(tmp_path / "figs")]) == 2
    assert "stores no curve data" in capsys.readouterr().err
    assert main(["plot", str(old), "-o", str(tmp_path / "map.png")]) == 0  # the map itself, as before
    assert main(["info", str(old)]) == 0
    assert "no rows stored (a file from before the per-curve view)" in capsys.readouterr().out


def test_damaged_curve_data_is_one_line_naming_it(fitted, tmp_path):
    import h5py

    _, out, _ = fitted
    bad = tmp_path / "bad.h5"
    shutil.copy(out, bad)
    with h5py.File(bad, "a") as f:
        start = f["entry/curve_data/start"]
        start[1] = start[2] + 5
    with pytest.raises(ValueError, match=r"incomplete or corrupt force-map file \(curve_data: start must rise"):
        read_map_file(bad)
    with h5py.File(bad, "a") as f:
        del f["entry/curve_data"]
        f["entry/curve_data"] = 1.0
    with pytest.raises(ValueError, match=r"incomplete or corrupt force-map file \(curve_data must be a group\)$"):
        read_map_file(bad)


def test_thinning_keeps_the_contact_and_bounds_the_rows(fitted, tmp_path):
    from shellbvp.map_pixels import thin_rows

    d = np.linspace(-30e-6, 3e-6, 12000)            # a long approach, contact at 0, 3 um deep
    keep = thin_rows(np.arange(d.size), d, 0.0, budget=1000)
    assert keep.size == 1000 and keep[-1] == d.size - 1 and np.all(np.diff(keep) > 0)
    assert np.sum(d[keep] >= 0) == 500 and np.sum((d[keep] < 0) & (d[keep] >= -3e-6)) == 250
    d = np.linspace(-30e-6, 0.5e-6, 12000)          # 197 rows in contact, 197 within 0.5 um before it
    keep = thin_rows(np.arange(d.size), d, 0.0, budget=1000)
    inside, near = np.sum(d >= 0), np.sum((d < 0) & (d >= -0.5e-6))
    assert np.sum(d[keep] >= 0) == inside and np.sum((d[keep] < 0) & (d[keep] >= -0.5e-6)) == near
    assert keep.size == 1000  # the far rows take what the contact left
    assert thin_rows(np.arange(10), d[:10], 0.0, budget=1000).tolist() == list(range(10))
    import h5py

    from shellbvp.map_pixels import read_curves, rows_per_curve, write_curve_data

    assert rows_per_curve(4) == 1000 and rows_per_curve(128 * 128) == 128 and rows_per_curve(1024 * 1024) == 2
    fm, out, records = fitted   # a map of many curves keeps fewer rows each: 200 rows over 4 curves here
    small = tmp_path / "small.h5"
    shutil.copy(out, small)
    with h5py.File(small, "a") as f:
        for name in ("curve_data", "curves/quality", "curves/warning_codes", "curves/warnings"):
            del f[f"entry/{name}"]
        write_curve_data(f["entry"], fm.rows, max_rows=200)
        curves = read_curves(f, fm.shape)
    assert np.diff(curves.start).max() == 50
    px = curves.pixel(*GOOD)
    used = records[GOOD].mask("loading")
    assert px.displacement.size == 50 < px.rows_fitted == used.sum()
    assert px.displacement.max() == pytest.approx(records[GOOD].displacement[used].max(), rel=1e-6)  # the deepest


def test_the_modules_docstring_examples_run():
    import doctest

    from shellbvp import map_pixels

    result = doctest.testmod(map_pixels, optionflags=doctest.ELLIPSIS)
    assert result.attempted >= 5 and result.failed == 0
