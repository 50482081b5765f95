"""AFM files through afmformats (issue 45, item 2): a real JPK curve read into the package's
signs, and a force map fitted curve by curve into a NeXus map whose values are known (made
from the model at four moduli)."""

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.afm import AFMCurve, curves_from_afm, read_afm
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
    import shellbvp.cli.handlers.fit as fit_command  # where the command reads the map's curves

    scene, curves = synthetic_map
    path = tmp_path / "cells.jpk-force-map"
    path.write_bytes(b"")  # the file the command names; its curves come from the fixture
    monkeypatch.setattr(fit_command, "iter_afm", lambda p, **calibration: iter(curves))
    argv = ["fit", str(path), "--preset", "fit", "--radius", "10um", "-o", str(tmp_path / "m.h5"),
            "--table", str(tmp_path / "m.csv"), "--report", str(tmp_path / "m.png")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "a force map of 4 curves" in out and "4 fitted" in out
    assert all((tmp_path / n).stat().st_size > 0 for n in ("m.h5", "m.csv", "m.png"))
    assert main(["fit", str(path), "--preset", "fit", "--radius", "10um", "--invert", "force"]) == 2
    assert "gives its own columns, units and signs" in capsys.readouterr().err


def test_a_force_map_in_a_batch_is_one_error_row(synthetic_map, tmp_path, monkeypatch):
    import shellbvp.afm_read as afm_read

    _, curves = synthetic_map
    path = tmp_path / "cells.jpk-force-map"
    path.write_bytes(b"")
    monkeypatch.setattr(afm_read, "read_afm", lambda p, **calibration: curves)
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


# -- damaged and oversized AFM files (issue 59, items 4 and 5) --------------------------------------------
SPOT = DATA / "spot3-0192.jpk-force"


def _rewrite(dst, edit=None, drop=(), extra=()):
    """A copy of SPOT, its property files passed through ``edit(text)``, members dropped or added."""
    import zipfile

    with zipfile.ZipFile(SPOT) as zi, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as zo:
        for info in zi.infolist():
            if info.filename not in drop:
                data = zi.read(info.filename)
                if edit and info.filename.endswith(".properties"):
                    data = edit(data.decode("latin-1")).encode("latin-1")
                zo.writestr(info.filename, data)
        for name, data in extra:
            zo.writestr(name, data)
    return dst


def _bad_crc(dst, member="segments/0/channels/vDeflection.dat"):
    """SPOT with the CRC of one member flipped in its local header and the central directory."""
    import struct
    import zipfile

    raw = bytearray(SPOT.read_bytes())
    with zipfile.ZipFile(SPOT) as z:
        raw[z.getinfo(member).header_offset + 14] ^= 0xFF
    at = raw.find(b"PK\x01\x02")
    while at >= 0:
        n = struct.unpack("<H", raw[at + 28:at + 30])[0]
        if raw[at + 46:at + 46 + n] == member.encode():
            raw[at + 16] ^= 0xFF
        at = raw.find(b"PK\x01\x02", at + 4)
    dst.write_bytes(bytes(raw))
    return dst


@pytest.mark.parametrize("damage, says", [
    ("crc", "BadZipFile"),
    ("no channel", "vDeflection"),
    ("nan scaling", "vDeflection"),
    ("unknown encoder", "\\x1b[2J"),   # the file's text, escaped
])
def test_a_damaged_jpk_archive_is_one_clean_line_and_afmformats_stays_quiet(tmp_path, damage, says, caplog):
    path = tmp_path / "damaged.jpk-force"
    if damage == "crc":
        _bad_crc(path)
    elif damage == "no channel":
        _rewrite(path, drop=("segments/0/channels/vDeflection.dat",))
    else:
        key, value = {"nan scaling": ("vDeflection.data.encoder.scaling.multiplier", "NaN"),
                      "unknown encoder": ("vDeflection.data.encoder.type", "\x1b[2Jfloat128")}[damage]
        _rewrite(path, edit=lambda text: "\n".join(f"{ln.split('=')[0]}={value}" if ln.split("=")[0].endswith(key)
                                                    else ln for ln in text.splitlines()))
    with pytest.raises(ValueError) as info:
        read_afm(path)
    msg = str(info.value)
    assert str(path) in msg and says in msg and "\n" not in msg and "\x1b" not in msg
    assert not [r for r in caplog.records if r.name.startswith("afmformats")]  # no traceback logged


def test_a_batch_keeps_the_good_files_row_beside_a_damaged_afm_file(tmp_path, capsys, closed_form):
    from shellbvp.fitting import example_data_path

    good, bad = str(example_data_path()), str(_bad_crc(tmp_path / "damaged.jpk-force"))
    rows = sb.fit_files(sb.Scene.preset("fit"), [good, bad], R_L=0.3e-3)
    assert [r.file for r in rows] == [good, bad]
    assert rows[0].status != "error" and rows[0].result is not None   # fitted (the closed-form model)
    assert rows[1].status == "error" and "BadZipFile" in rows[1].message and rows[1].result is None
    code = main(["fit", good, bad, "--preset", "fit", "--radius", "0.3mm", "--json", "-q"])
    doc = json.loads(capsys.readouterr().out)     # exactly one JSON document
    assert code == doc["exit_status"] == 1 and [d["file"] for d in doc["files"]] == [good, bad]
    assert "BadZipFile" in doc["files"][1]["message"] and "mu_H" in doc["files"][0]


def test_an_archive_inflating_far_beyond_its_size_is_refused_before_inflating(tmp_path, capsys):
    import zipfile

    from shellbvp import afm_read

    bomb = _rewrite(tmp_path / "bomb.jpk-force")
    with zipfile.ZipFile(bomb, "a", zipfile.ZIP_DEFLATED) as z:     # 48 MiB of zeros in ~50 kB
        z.writestr("segments/0/channels/big.dat", bytes(48 * 2**20))
    with pytest.raises(ValueError, match=r"inflate to 48\.\d MiB from 0\.\d+ MiB .*'segments/0/channels/big.dat'"):
        read_afm(bomb)
    assert main(["fit", str(bomb), "--preset", "fit", "--radius", "10um", "--json"]) == 2
    out, err = capsys.readouterr()
    assert err.startswith("shellbvp: error:") and len(err.strip().splitlines()) == 1
    assert "MiB" in json.loads(out)["message"]
    many = _rewrite(tmp_path / "many.jpk-force", extra=[(f"junk/{i}", b"") for i in range(20)])
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(afm_read, "MAX_ARCHIVE_MEMBERS", 25)
        with pytest.raises(ValueError, match="declares 32 members.*MAX_ARCHIVE_MEMBERS"):
            read_afm(many)


@pytest.mark.parametrize("offset, value, says", [(12, 0x7FFFFFF0, "noteSize = 2147483632"),
                                                 (4, 0x7FFFFFF0, "wfmSize = 2147483632"),
                                                 (12, -5, "negative sizes")])
def test_an_ibw_header_declaring_huge_sizes_is_refused_before_allocation(tmp_path, offset, value, says):
    import struct

    good = DATA / "SiN_FD_plot.ibw"
    assert len(read_afm(good)) == 1
    raw = bytearray(good.read_bytes())
    raw[offset:offset + 4] = struct.pack("<l", value)
    bad = tmp_path / "bad.ibw"
    bad.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match=f"Igor binary wave header declares .*{says}"):
        read_afm(bad)
    bad.write_bytes(good.read_bytes()[:5000])   # cut short: its parts do not fit
    with pytest.raises(ValueError, match="declares .* in a file of 5000 bytes"):
        read_afm(bad)


def test_a_map_grid_far_larger_than_its_curves_is_refused_before_any_fit():
    from shellbvp.afm import map_shape
    from shellbvp.afm_read import MAX_MAP_PIXELS

    curves = [AFMCurve(record=None, index=i, grid=g) for i, g in enumerate([(4999, 4999), (94977, 94967)])]
    with pytest.raises(ValueError, match=r"94978 x 94968 grid .*MAX_MAP_PIXELS"):
        fit_map(sb.Scene.preset("fit"), curves, R_L=R_L, path="m.jpk-force-map")
    side = int(MAX_MAP_PIXELS ** 0.5)
    assert map_shape([AFMCurve(None, 0, (side - 1, side - 1))]) == (side, side)


def test_afm_text_exports_go_through_afmformats_with_their_calibration():
    from shellbvp.afm import afm_text_format

    nt, ws = DATA / "ntmdt-gel4.txt", DATA / "afm-workshop-single.csv"
    assert (afm_text_format(nt), afm_text_format(ws), afm_text_format(SPOT)) == ("NT-MDT Nova", "AFM Workshop", None)
    for path in (nt, ws):
        with pytest.raises(ValueError, match="--spring-constant K --sensitivity S"):
            sb.read_instrument(path)
        (curve,) = read_afm(path, spring_constant=0.05, sensitivity=1e-7)
        assert len(curve.record) > 500 and np.all(np.isfinite(curve.record.force))
    with pytest.raises(ValueError, match="carries the cantilever's calibration"):
        read_afm(SPOT, spring_constant=0.05, sensitivity=1e-7)


def test_read_instrument_reads_an_afm_curve_and_points_a_map_to_its_reader(tmp_path, monkeypatch):
    import shellbvp.afm_read as afm_read

    rec = sb.read_instrument(SPOT)
    np.testing.assert_array_equal(rec.displacement, read_afm(SPOT)[0].record.displacement)
    with pytest.raises(ValueError, match="gives its own columns"):
        sb.read_instrument(SPOT, units=("um", "uN"))
    curves = [AFMCurve(record=None, index=i, grid=(i % 2, i // 2)) for i in range(4)]
    monkeypatch.setattr(afm_read, "read_afm", lambda p, **calibration: curves)
    with pytest.raises(ValueError, match="a force map of 4 curves.*shellbvp.batch.fit_map"):
        sb.read_instrument(tmp_path / "m.jpk-force-map")
