"""A force map whose geometry varies per pixel, given by a table (issue 46, item 3): the table
read and checked before any curve, model curves at a few nodes spanning its range (not one per
pixel), each pixel's mu*H fitted with its value fixed on the interpolated curve."""


import numpy as np
import pytest

import shellbvp as sb
from shellbvp.afm import AFMCurve
from shellbvp.batch import fit_map, write_table
from shellbvp.cli import main
from shellbvp.fitting import clear_model_curves
from shellbvp.instrument import record_from_arrays
from shellbvp.pixel_table import PixelTable, read_pixel_table

R_L = 10e-6
CONTACT = 0.3e-6


def _closed_form_force(scene, delta):
    """tests/fake_curves.FakeCurve's force: the closed form the ``closed_form`` fixture fits with."""
    return np.asarray(delta) ** (1.3 + 20 * scene.beta) * (1 + scene.beta)


def _map(n, thickness_um, mu_h, force_of, noise=0.01, seed=5):
    """An n x n map of records (approach then loading), pixel (ix, iy) at thickness_um[iy, ix] and
    mu_h[iy, ix], its nondimensional force ``force_of(scene, delta)``."""
    rng = np.random.default_rng(seed)
    scene = sb.Scene.preset("fit")
    depth = np.linspace(0, CONTACT + 0.3 * R_L, 160)
    curves = []
    for iy in range(n):
        for ix in range(n):
            s = scene.replace(thickness=thickness_um[iy, ix] * 1e-6 / R_L)
            x = np.clip((depth - CONTACT) / R_L, 0, None)
            force = mu_h[iy, ix] * R_L * force_of(s, x) * (1 + noise * rng.standard_normal(depth.size))
            # an instrument's additive noise too (0.1 % of the largest force): approach rows of exactly
            # zero noise bias the mixed weights (mu*H +0.6 %, its interval covering the truth in 0 of 64
            # pixels; uniform 58 of 64), and the weights check fails those fits
            force += 1e-3 * np.max(force) * rng.standard_normal(depth.size)
            rec = record_from_arrays("map.jpk-force-map", depth, force, 0.01 * np.arange(depth.size),
                                     np.arange(depth.size), columns={"displacement": "d", "force": "f"},
                                     units={"displacement": "m", "force": "N"}, sha256="0" * 64)
            curves.append(AFMCurve(rec, iy * n + ix, (ix, iy), (ix * 1e-6, iy * 1e-6), None))
    return curves


def _table_file(tmp_path, thickness_um, header="ix,iy,thickness_um", skip=()):
    ny, nx = thickness_um.shape
    path = tmp_path / "heights.csv"
    sep = ";" if ";" in header else ","
    rows = [sep.join((str(ix), str(iy), f"{thickness_um[iy, ix]:.6g}")) for iy in range(ny) for ix in range(nx) if (ix, iy) not in skip]
    path.write_text("\n".join([header, *rows]) + "\n")
    return path


def test_each_pixel_fitted_at_its_own_thickness_with_curves_at_nodes_only(closed_form, tmp_path):
    """Closed-form curves (fast): 64 pixels at 64 thicknesses; the curves computed are the
    nodes across the table's range, fewer than the pixels, and each pixel's mu*H is its truth."""
    clear_model_curves()
    n = 8
    iy, ix = np.mgrid[0:n, 0:n]
    thickness = 0.4 + 0.8 * (ix * n + iy) / (n * n - 1)          # um: 64 values, 0.4 .. 1.2
    mu_h = 0.4e-3 + 0.4e-3 * (0.6 * ix + 0.4 * iy) / (n - 1)
    curves = _map(n, thickness, mu_h, _closed_form_force)
    table = read_pixel_table(_table_file(tmp_path, thickness))
    assert table.name == "thickness" and table.unit == "um" and len(table.values) == n * n
    fm = fit_map(sb.Scene.preset("fit"), curves, R_L=R_L, pixel_values=table)
    assert all(r.status == "ok" for r in fm.rows), [r.message for r in fm.rows if r.status != "ok"]
    np.testing.assert_allclose(fm.image("mu_H"), mu_h, rtol=0.01)
    assert fm.curves_computed == len(fm.pixel_nodes) < n * n / 2
    assert min(fm.pixel_nodes) == pytest.approx(0.4e-6) and max(fm.pixel_nodes) == pytest.approx(1.2e-6)
    assert all(r.result.curves_computed == 0 for r in fm.rows)
    assert fm.interpolation_error is not None and fm.interpolation_error <= 1e-6
    # each pixel's result carries its own thickness (the scene it was fitted in)
    # (the table holds 6 significant digits)
    np.testing.assert_allclose(fm.pixel_image(), thickness * 1e-6, rtol=1e-5)
    r = fm.rows[n + 1]
    assert r.result.scene.thickness == pytest.approx(thickness[1, 1] * 1e-6 / R_L, rel=1e-5)
    assert r.result.derived["mu"].value == pytest.approx(r.result.mu_H / (thickness[1, 1] * 1e-6), rel=1e-5)


def test_the_map_file_and_table_carry_the_geometry_per_pixel(closed_form, tmp_path):
    import csv

    import h5py

    from shellbvp.nexus import missing_units

    n = 3
    iy, ix = np.mgrid[0:n, 0:n]
    thickness = 0.5 + 0.1 * ix + 0.05 * iy
    mu_h = np.full((n, n), 0.5e-3)
    curves = _map(n, thickness, mu_h, _closed_form_force)
    table = read_pixel_table(_table_file(tmp_path, thickness * 1e3, header="ix;iy;thickness (nm)", skip={(2, 1)}))
    assert table.unit == "nm"
    fm = fit_map(sb.Scene.preset("fit"), curves, R_L=R_L, pixel_values=table)
    missing = fm.rows[1 * n + 2]
    assert missing.status == "error" and "pixel (2, 1) is not in the pixel table" in missing.message
    assert sum(r.status == "ok" for r in fm.rows) == n * n - 1
    out = tmp_path / "map.h5"
    fm.to_hdf5(out)
    assert missing_units(out) == []
    with h5py.File(out) as f:
        img = f["entry/map/thickness"]
        assert img.attrs["units"] == "m"
        expect = thickness * 1e-6
        expect[1, 2] = np.nan
        np.testing.assert_allclose(img[()], expect)
        np.testing.assert_allclose(f["entry/curves/thickness"][()], expect.ravel())
        assert f["entry/curves/thickness_nodes"].size == fm.curves_computed
    csv_path = tmp_path / "map.csv"
    write_table(csv_path, fm.rows)
    rows = list(csv.DictReader(csv_path.open()))
    assert float(rows[0]["thickness per pixel (m)"]) == pytest.approx(0.5e-6)
    assert rows[1 * n + 2]["thickness per pixel (m)"] == "" and rows[1 * n + 2]["status"] == "error"


@pytest.mark.parametrize("text, match", [
    ("ix,thickness_um\n0,0.5\n", "needs one column 'iy'"),
    ("ix,iy,height_um\n0,0,0.5\n", "needs exactly one geometry column.*found no"),
    ("ix,iy,thickness_um,beta\n0,0,0.5,0.01\n", "exactly one geometry column.*found 2"),
    ("ix,iy,thickness (N)\n0,0,0.5\n", "'N' is not a length unit"),
    ("ix,iy,beta (um)\n0,0,0.5\n", "beta is nondimensional"),
    ("ix,iy,thickness_um\n0,0,0.5\n1.5,0,0.5\n", "line 3: column 'ix' must be a grid index"),
    ("ix,iy,thickness_um\n0,0,0.5\n1,0,-2\n", "line 3: column 'thickness_um' must be a finite number > 0"),
    ("ix,iy,thickness_um\n0,0,0.5\n0,0,0.6\n", r"line 3: pixel \(0, 0\) again \(first on line 2\)"),
])
def test_bad_tables_are_one_line_naming_column_or_row(tmp_path, text, match):
    path = tmp_path / "t.csv"
    path.write_text(text)
    with pytest.raises(ValueError, match=match) as info:
        read_pixel_table(path)
    assert "\n" not in str(info.value)


def test_a_table_invalid_for_the_map_is_refused_before_any_curve(closed_form, tmp_path, monkeypatch):
    import shellbvp.batch as batch

    def no_curves(*a, **k):
        raise AssertionError("a model curve was asked for")

    monkeypatch.setattr(batch, "shared_curves", no_curves)
    n = 2
    curves = _map(n, np.full((n, n), 0.5), np.full((n, n), 0.5e-3), _closed_form_force)
    scene = sb.Scene.preset("fit")
    outside = PixelTable("thickness", {(0, 0): 0.5, (2, 0): 0.5}, unit="um", path="t.csv",
                         lines={(0, 0): 2, (2, 0): 3})
    with pytest.raises(ValueError, match=r"t.csv, line 3: pixel \(2, 0\) is outside the map's 2 x 2 grid"):
        fit_map(scene, curves, R_L=R_L, pixel_values=outside)
    thick = PixelTable("thickness", {(0, 0): 0.5, (1, 0): 6.0}, unit="um", path="t.csv", lines={(1, 0): 3})
    with pytest.raises(ValueError, match=r"t.csv, line 3: thickness \(um\) = 6 is out of the range"):
        fit_map(scene, curves, R_L=R_L, pixel_values=thick)
    with pytest.raises(ValueError, match="no shape parameter is fitted with it"):
        fit_map(scene, curves, R_L=R_L, pixel_values=PixelTable("beta", {(0, 0): 0.01}), free=("beta",))
    with pytest.raises(ValueError, match="fit_alpha needs a Mooney-Rivlin material"):
        fit_map(scene.replace(material=sb.NeoHookean()), curves, R_L=R_L,
                pixel_values=PixelTable("alpha", {(0, 0): 0.1}))


@pytest.mark.slow  # 25-55 s: a JPK map fitted pixel by pixel with its own thickness; the text-table cases stay
def test_a_jpk_map_with_its_own_thickness_per_pixel_recovers_every_mu_h(tmp_path, capsys):
    """benchmarks/make_force_map.py with a thickness per pixel: each pixel's curve from its own
    scene (the full model), read by afmformats; `shellbvp fit --pixel-table` recovers every
    pixel's mu*H within 1 % (1 % force noise), computing the nodes' curves, not the pixels'."""
    import importlib.util
    import json
    from pathlib import Path

    import h5py

    pytest.importorskip("afmformats")
    bench = Path(__file__).resolve().parent.parent / "benchmarks" / "make_force_map.py"
    spec = importlib.util.spec_from_file_location("_bench_make_force_map", bench)
    maker = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(maker)
    path = tmp_path / "cells.jpk-force-map"
    thickness = maker.thickness_pattern(4, 0.5e-6, 0.7e-6, levels=5)
    assert np.unique(thickness).size == 3
    truth = maker.write_map(path, n=4, points=150, thickness=thickness)
    table = tmp_path / "thickness.csv"
    maker.write_thickness_table(table, thickness)
    clear_model_curves()
    out = tmp_path / "cells.h5"
    argv = ["fit", str(path), "--preset", "fit", "--radius", "10um", "--pixel-table", str(table), "-q", "-o", str(out)]
    assert main(argv + ["--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    per_pixel = doc["per_pixel"]
    assert per_pixel["parameter"] == "thickness" and per_pixel["unit"] == "m"
    assert per_pixel["curves_computed"] == len(per_pixel["nodes"]) < 16
    assert per_pixel["interpolation_error"] <= 1e-6
    with h5py.File(out) as f:
        np.testing.assert_allclose(f["entry/map/mu_H"][()], truth, rtol=0.01)
        np.testing.assert_allclose(f["entry/map/thickness"][()], thickness, rtol=1e-9)
    # one geometry for all (the preset's beta) fits the same map worse than the table's
    assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "-q", "-o", str(tmp_path / "one.h5")]) in (0, 1)
    with h5py.File(tmp_path / "one.h5") as f:
        one = f["entry/map/mu_H"][()]
    assert np.nanmax(np.abs(one / truth - 1)) > 0.05


def test_cli_refuses_a_bad_pixel_table_in_one_line(tmp_path, capsys):
    path = tmp_path / "cells.jpk-force-map"
    path.write_bytes(b"")
    bad = tmp_path / "t.csv"
    bad.write_text("ix,iy,thickness_um\n0,0,0.5\n0,x,0.5\n")
    assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "--pixel-table", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "t.csv, line 3: column 'iy' must be a grid index" in err and err.count("\n") == 1
    good = tmp_path / "g.csv"
    good.write_text("ix,iy,thickness_um\n0,0,0.5\n")
    assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "--thickness", "1um",
                 "--pixel-table", str(good)]) == 2
    assert "gives the thickness per pixel: leave out --thickness" in capsys.readouterr().err
    csv_file = tmp_path / "one.csv"
    csv_file.write_text("d,f\n0,0\n1,1\n2,2\n")
    assert main(["fit", str(csv_file), "--preset", "fit", "--radius", "10um", "--pixel-table", str(good)]) == 2
    assert "--pixel-table is for one force map" in capsys.readouterr().err


def test_a_pixel_table_has_at_most_a_row_per_cell_of_the_largest_map(tmp_path, monkeypatch):
    """Bounded before its text is split (issue 59, item 5): a 100 MB table once peaked at 3.6 GB."""
    from shellbvp import afm_read

    monkeypatch.setattr(afm_read, "MAX_MAP_PIXELS", 16)
    path = tmp_path / "pixels.csv"
    path.write_text("ix,iy,thickness_um\n" + "".join(f"{i % 5},{i // 5},0.5\n" for i in range(17)))
    with pytest.raises(ValueError, match=r"17 rows; a pixel table .*has at most 16"):
        read_pixel_table(path)
    path.write_text("ix,iy,thickness_um\n" + "".join(f"{i % 4},{i // 4},0.5\n" for i in range(16)))
    assert len(read_pixel_table(path).values) == 16
