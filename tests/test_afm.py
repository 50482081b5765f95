"""AFM files through afmformats (issue 45, item 2): a real JPK curve read into the package's
signs, and a force map fitted curve by curve into a NeXus map whose values are known (made
from the model at four moduli)."""

from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.afm import curves_from_afm, read_afm
from shellbvp.batch import fit_map
from shellbvp.cli import main

afmformats = pytest.importorskip("afmformats")
from afmformats.mod_force_distance import AFMForceDistance  # noqa: E402

DATA = Path(__file__).parent / "data" / "afm"
R_L, K = 10e-6, 0.05          # rim radius (m), spring constant (N/m)
MU_H = np.array([[30.0, 40.0], [50.0, 60.0]]) * 1e-3  # N/m, rows y, columns x


def test_a_jpk_curve_reads_in_the_packages_signs():
    """The tip's position is the height plus the deflection force / k (nanite's tip-sample
    separation); the displacement into the sample is its negative and grows while approaching."""
    (curve,) = read_afm(DATA / "spot3-0192.jpk-force")
    rec = curve.record
    ds = afmformats.load_data(str(DATA / "spot3-0192.jpk-force"))[0]
    tip = ds["height (measured)"] + ds["force"] / ds.metadata["spring constant"]
    order = np.argsort(ds["time"], kind="stable")
    np.testing.assert_allclose(rec.displacement, -tip[order], rtol=0, atol=1e-15)
    np.testing.assert_allclose(rec.force, ds["force"][order])
    assert rec.units == {"displacement": "m", "force": "N", "time": "s"}
    push = rec.mask("loading")
    assert push.sum() > 1000 and rec.counts()["retraction"] > 1000
    assert np.corrcoef(rec.time[push], rec.displacement[push])[0, 1] > 0.99   # deeper while pushing
    assert rec.force[push][-1] > rec.force[push][0]
    assert rec.contact_estimate is not None and curve.grid is None and curve.position is not None


@pytest.fixture(scope="module")
def synthetic_map():
    """A 2 x 2 force map as afmformats gives it: the model's curve at four mu*H, approach then
    retract, heights from the tip's depth and the cantilever's deflection."""
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.005, 0.4, 160), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    contact, top = 0.3e-6, 0.3e-6 + 0.35 * R_L
    depth = np.r_[np.linspace(0, top, 200), np.linspace(top, 0, 200)]
    rng = np.random.default_rng(7)
    datasets = []
    for iy in range(2):
        for ix in range(2):
            x = np.clip((depth - contact) / R_L, 0, 0.4)
            force = MU_H[iy, ix] * R_L * shape(x) * (1 + 0.01 * rng.standard_normal(depth.size))
            data = {"force": force, "height (measured)": 5e-6 - depth - force / K,
                    "segment": np.r_[np.zeros(200, bool), np.ones(200, bool)], "time": 0.01 * np.arange(depth.size)}
            md = {"spring constant": K, "grid index x": ix, "grid index y": iy, "grid shape x": 2, "grid shape y": 2,
                  "grid center x": 1e-6, "grid center y": 2e-6, "grid size x": 4e-6, "grid size y": 4e-6,
                  "position x": 1e-6 - 1e-6 + 2e-6 * ix, "position y": 2e-6 - 1e-6 + 2e-6 * iy,
                  "enum": 2 * iy + ix, "path": "map.jpk-force-map", "imaging mode": "force-distance"}
            datasets.append(AFMForceDistance(data, md))
    return scene, curves_from_afm(datasets, "map.jpk-force-map", sha256="0" * 64)


def test_a_force_map_is_fitted_curve_by_curve(synthetic_map, tmp_path):
    import h5py
    from nexusformat.nexus import nxload

    from shellbvp.nexus import missing_units

    scene, curves = synthetic_map
    fm = fit_map(scene, curves, R_L=R_L)
    assert fm.shape == (2, 2) and all(r.status == "ok" for r in fm.rows), [r.message for r in fm.rows]
    lo, hi, mu = fm.image("mu_H_low"), fm.image("mu_H_high"), fm.image("mu_H")
    np.testing.assert_allclose(mu, MU_H, rtol=0.01)          # 1 % noise on 200 loading rows each
    assert np.all((lo < mu) & (mu < hi) & (hi - lo < 0.02 * mu))
    x, y = fm.axes()
    np.testing.assert_allclose(x, [0.0, 2e-6], atol=1e-12)
    np.testing.assert_allclose(y, [1e-6, 3e-6], atol=1e-12)
    out = tmp_path / "map.h5"
    fm.to_hdf5(out)
    assert missing_units(out) == []
    root = nxload(str(out))
    assert root.plottable_data.nxsignal.nxname == "mu_H"
    with h5py.File(out) as f:
        np.testing.assert_allclose(f["entry/map/mu_H"][()], mu)
        assert list(f["entry/curves/status"].asstr()[()]) == ["ok"] * 4
    with pytest.raises(FileExistsError):
        fm.to_hdf5(out)


def test_a_force_map_file_reads_back_and_info_and_plot_take_it(synthetic_map, tmp_path, capsys):
    """The map's NeXus file, read back as data (read_map_file), holds the fit's images; `shellbvp
    info` summarises it and `shellbvp plot` draws its mu*H; a damaged one is one line naming the item."""
    pytest.importorskip("matplotlib")
    import h5py

    from shellbvp.afm import is_map_file, read_map_file

    scene, curves = synthetic_map
    fm = fit_map(scene, curves, R_L=R_L, path="cells.jpk-force-map")
    out = tmp_path / "map.h5"
    fm.to_hdf5(out)
    assert is_map_file(out) and not is_map_file(tmp_path / "nothing.h5")
    back = read_map_file(out)
    np.testing.assert_array_equal(back.mu_H, fm.image("mu_H"))
    np.testing.assert_array_equal(back.mu_H_high, fm.image("mu_H_high"))
    np.testing.assert_array_equal(back.status, fm.status_image())
    np.testing.assert_allclose(back.x, fm.axes()[0])
    np.testing.assert_allclose(back.y, fm.axes()[1])
    assert back.sample == scene.describe(R_L) and back.source == "cells.jpk-force-map"
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "grid:      2 x 2: 4 fitted, 0 failed their checks, 0 errors, 0 no curve" in text
    assert f"median {np.median(fm.image('mu_H')) * 1e3:.4g} mN/m" in text  # 0.045 N/m reads in mN/m
    png = tmp_path / "map.png"
    assert main(["plot", str(out), "-o", str(png)]) == 0 and png.stat().st_size > 0
    with h5py.File(out, "a") as f:
        del f["entry/map/status"]
    with pytest.raises(ValueError, match="incomplete or corrupt force-map file.*status is missing"):
        read_map_file(out)


def test_cli_fits_a_map_into_a_table_a_file_and_a_figure(synthetic_map, tmp_path, monkeypatch, capsys):
    pytest.importorskip("matplotlib")
    import shellbvp.afm as afm

    scene, curves = synthetic_map
    path = tmp_path / "cells.jpk-force-map"
    path.write_bytes(b"")  # the file the command names; its curves come from the fixture
    monkeypatch.setattr(afm, "read_afm", lambda p: curves)
    argv = ["fit", str(path), "--preset", "fit", "--radius", "10um", "-o", str(tmp_path / "m.h5"),
            "--table", str(tmp_path / "m.csv"), "--report", str(tmp_path / "m.png")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "a force map of 4 curves" in out and "4 fitted" in out
    assert all((tmp_path / n).stat().st_size > 0 for n in ("m.h5", "m.csv", "m.png"))
    assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "--invert", "force"]) == 2
    assert "gives its own columns, units and signs" in capsys.readouterr().err


def test_a_force_map_in_a_batch_is_one_error_row(synthetic_map, tmp_path, monkeypatch):
    import shellbvp.afm as afm

    _, curves = synthetic_map
    path = tmp_path / "cells.jpk-force-map"
    path.write_bytes(b"")
    monkeypatch.setattr(afm, "read_afm", lambda p: curves)
    (row,) = sb.fit_files(sb.Scene.preset("fit"), [str(path)], R_L=R_L)
    assert row.status == "error" and "a force map of 4 curves: fit it on its own" in row.message


def test_a_file_afmformats_cannot_read_is_one_line(tmp_path):
    bad = tmp_path / "broken.jpk-force"
    bad.write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(ValueError, match="afmformats cannot read it"):
        read_afm(bad)


def test_a_synthetic_jpk_force_map_file_is_read_by_afmformats_and_fitted_to_its_truth(tmp_path, capsys):
    """benchmarks/make_force_map.py writes a JPK archive (afmformats' test map's property files,
    channels encoded anew); afmformats reads it back, with no monkeypatch: the grid, the positions
    and the tip from height and deflection, and `shellbvp fit` recovers every pixel's mu*H."""
    import importlib.util

    import h5py

    bench = Path(__file__).resolve().parent.parent / "benchmarks" / "make_force_map.py"
    spec = importlib.util.spec_from_file_location("_bench_make_force_map", bench)
    maker = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(maker)
    path = tmp_path / "cells.jpk-force-map"
    truth = maker.write_map(path, n=3, points=150)
    curves = read_afm(path)
    assert [c.grid for c in curves] == [(ix, iy) for iy in range(3) for ix in range(3)]
    assert curves[4].position == pytest.approx((0.0, 0.0), abs=1e-12)          # the middle of a 3 x 3 grid
    rec = curves[4].record
    assert rec.counts()["retraction"] == 150 and rec.contact_estimate is not None
    np.testing.assert_allclose(np.ptp(rec.displacement), maker.CONTACT + maker.TOP * maker.R_L, rtol=1e-6)
    out = tmp_path / "cells.h5"
    assert main(["fit", str(path), "--preset", "fit", "--radius", f"{maker.R_L * 1e6:g}um", "-q", "-o", str(out)]) == 0
    assert "9 fitted" in capsys.readouterr().out
    with h5py.File(out) as f:
        np.testing.assert_allclose(f["entry/map/mu_H"][()], truth, rtol=0.01)   # 1 % force noise, 150 rows


def test_a_maps_spread_of_mu_H_reads_in_a_unit_of_its_size():
    from shellbvp.afm import mu_H_spread

    assert mu_H_spread(np.array([0.0004, 0.0005998, 0.0009])) == \
        "median 0.5998 mN/m, quartiles 0.4999..0.7499 mN/m"
    assert mu_H_spread(np.array([39.9, 40.1, 52.0]), with_range=True) == \
        "median 40.1 N/m, quartiles 40..46.05 N/m, range 39.9..52 N/m"
    assert mu_H_spread(np.array([2e-7, 3e-7])).endswith("uN/m")
