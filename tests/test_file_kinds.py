"""Every file the tool writes, it reads back (issue 56 item 6).

One small file of each kind -- a curve, a sweep, a fit, a force map and a validation -- is
written as the command line writes it, then read by ``info``, ``plot`` and ``report``: each
reads it, or (``report`` of a curve or sweep) says in one line which command does.  Every
root is a NeXus NXroot whose ``default`` names an NXentry; the validation file keeps R_L.
"""

import importlib.util

import h5py
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.cli import main
from shellbvp.filekinds import KINDS, file_kind

R_L = 10e-6


def _force_map(scene, path):
    """A 2 x 1 force map of a dome as afmformats gives it (the model's curve at two mu*H), fitted and
    written."""
    from afmformats.mod_force_distance import AFMForceDistance

    from shellbvp.afm import curves_from_afm
    from shellbvp.batch import fit_map

    c = sb.curve(scene, deltas=np.linspace(0.01, 0.3, 30), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    contact, top = 0.3e-6, 0.3e-6 + 0.25 * R_L
    depth = np.r_[np.linspace(0, top, 100), np.linspace(top, 0, 100)]
    rng = np.random.default_rng(3)
    datasets = []
    for ix, mu_H in enumerate((0.04, 0.06)):
        force = mu_H * R_L * shape(np.clip((depth - contact) / R_L, 0, 0.3)) * (1 + 0.01 * rng.standard_normal(200))
        data = {"force": force, "height (measured)": 5e-6 - depth - force / 0.1,
                "segment": np.r_[np.zeros(100, bool), np.ones(100, bool)], "time": 0.01 * np.arange(200)}
        md = {"spring constant": 0.1, "grid index x": ix, "grid index y": 0, "grid shape x": 2, "grid shape y": 1,
              "grid center x": 0.0, "grid center y": 0.0, "grid size x": 4e-6, "grid size y": 2e-6,
              "position x": -1e-6 + 2e-6 * ix, "position y": 0.0, "enum": ix, "path": "cells.jpk-force-map",
              "imaging mode": "force-distance"}
        datasets.append(AFMForceDistance(data, md))
    curves = curves_from_afm(datasets, "cells.jpk-force-map", sha256="0" * 64)
    fit_map(scene, curves, R_L=R_L, path="cells.jpk-force-map").to_hdf5(path)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """One file of each kind, small: the kind -> its path."""
    root = tmp_path_factory.mktemp("kinds")
    out = {kind: root / f"{kind}.h5" for kind in KINDS}
    lab = ["--radius", "10um", "--indenter-radius", "2.5um", "--thickness", "0.5um"]
    assert main(["curve", *lab, "--muH", "0.05N/m", "--rise", "-5um", "--points", "2", "--delta-max", "0.05",
                 "-q", "-o", str(out["curve"])]) == 0
    assert main(["sweep", "--beta", "0.01,0.02", "--points", "2", "--delta-max", "0.05", "--workers", "1",
                 "-o", str(out["sweep"])]) == 0
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "-o", str(out["fit"])]) == 0
    if importlib.util.find_spec("felupe"):  # the 3D solid: the extra [fe]
        assert main(["validate", "--preset", "base", "--neo-hookean", "--thickness", "0.1mm", "--radius", "1mm",
                     "--deltas", "0.1", "-o", str(out["validation"])]) == 0
    if importlib.util.find_spec("afmformats"):  # the extra [afm]
        _force_map(sb.Scene.preset("fit", gamma=-0.5, rho=0.25, thickness=0.03), out["force-map"])
    return out


def _written(files, kind):
    """The file of ``kind``; the test is skipped where its optional part is not installed."""
    if not files[kind].exists():
        pytest.skip(f"no {kind} file: its optional dependency is not installed")
    return files[kind]


@pytest.mark.parametrize("kind", KINDS)
def test_every_file_names_its_kind_under_a_nexus_root(files, kind):
    assert file_kind(_written(files, kind)) == kind
    with h5py.File(files[kind]) as f:
        assert f.attrs["NX_class"] == "NXroot"
        assert f[f.attrs["default"]].attrs["NX_class"] == "NXentry"


#: What ``info`` prints of each kind (one line at least).
INFO = {"curve": "sample:    own scene; shell: spheroidal dome (indented from outside), rise 5 um (gamma -0.5)",
        "sweep": "sweeps:    beta = 0.01, 0.02",
        "fit": "scene: preset fit; shell: spheroidal bowl (indented from inside), rise 750 um",
        "force-map": "grid:      2 x 1: 2 fitted",
        "validation": "eps = H/R_L = 0.1, R_L = 1 mm, H = 100 um"}


@pytest.mark.parametrize("kind", KINDS)
def test_info_reads_every_kind(files, kind, capsys):
    assert main(["info", str(_written(files, kind))]) == 0
    out = capsys.readouterr().out
    assert INFO[kind] in out, out
    if kind == "force-map":
        assert "spheroidal dome (indented from outside)" in out


@pytest.mark.parametrize("kind", KINDS)
def test_plot_draws_every_kind(files, kind, tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / f"{kind}.png"
    assert main(["plot", str(_written(files, kind)), "-o", str(png)]) == 0
    assert png.stat().st_size > 0


@pytest.mark.parametrize("kind", KINDS)
def test_report_summarises_fits_maps_and_validations_and_points_elsewhere(files, kind, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    pdf = tmp_path / f"{kind}.pdf"
    status = main(["report", str(_written(files, kind)), "-o", str(pdf)])
    if kind in ("curve", "sweep"):
        err = capsys.readouterr().err
        assert status == 2 and not pdf.exists()
        assert err.count("\n") == 1 and f"is a {kind} file" in err and "`shellbvp plot`" in err, err
    else:
        assert status == 0 and pdf.stat().st_size > 0


def test_the_validation_file_keeps_the_rim_radius(files):
    from shellbvp.validation import read_validation

    v = read_validation(_written(files, "validation"))
    assert v.R_L == pytest.approx(1e-3) and v.scene.thickness == pytest.approx(0.1)
    assert v.error[0] == pytest.approx(v.force_shell[0] / v.force_fe[0] - 1)
    with h5py.File(files["validation"]) as f:
        assert f["entry/sample/R_L"].attrs["units"] == "m" and f["entry/sample"].attrs["NX_class"] == "NXsample"
        assert f["entry/sample/thickness"][()] == pytest.approx(1e-4)


def test_a_damaged_validation_file_is_one_line_naming_the_item(files, tmp_path):
    import shutil

    from shellbvp.validation import read_validation

    broken = tmp_path / "broken.h5"
    shutil.copyfile(_written(files, "validation"), broken)
    with h5py.File(broken, "a") as f:
        del f["entry/comparison/force_fe"]
    with pytest.raises(ValueError, match="incomplete or corrupt validation file.*force_fe"):
        read_validation(broken)
