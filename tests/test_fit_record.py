"""A fit is a record (issue 15 item 3): ``fit -o`` writes a NeXus file holding the data as
read, the rows used, the model, the parameters with intervals, weights, warnings, the scene
and the source file's name and hash; ``plot`` and ``report`` read it; every dataset of every
file the package writes has a ``units`` attribute."""

import hashlib
import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

import shellbvp as sb
from shellbvp.fitrecord import is_fit_file, read_fit
from shellbvp.nexus import missing_units

R_L, MU_H, D0, BASE = 0.3e-3, 52.0, 12e-6, 40e-6


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True, cwd=cwd,
                          env=dict(os.environ), timeout=600)


@pytest.fixture(scope="module")
def instrument_file(tmp_path_factory):
    """An instrument-style record (approach, loading, retraction, a 40 uN baseline) in um and uN."""
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.4, 40), estimate_error=False)
    rng = np.random.default_rng(5)
    d_push = np.r_[np.linspace(-15e-6, D0, 20, endpoint=False), D0 + R_L * c.delta]
    f_push = np.r_[np.zeros(20), MU_H * R_L * c.force]
    d = np.r_[d_push, d_push[::-1]]
    f = np.r_[f_push, 0.9 * f_push[::-1]] * (1 + 0.02 * rng.standard_normal(2 * d_push.size)) + BASE
    path = tmp_path_factory.mktemp("inst") / "seed1.tsv"
    path.write_text("# exported\nTime (s)\tDisplacement (um)\tForce (uN)\n"
                    + "\n".join(f"{0.1 * i:.1f}\t{a * 1e6:.5f}\t{b * 1e6:.5f}" for i, (a, b) in enumerate(zip(d, f)))
                    + "\n")
    return path


@pytest.fixture(scope="module")
def fit_file(instrument_file):
    out = instrument_file.with_name("seed1.h5")
    r = run("fit", str(instrument_file), "--preset", "fit", "--radius", "0.3mm", "-o", str(out),
            "--report", str(out.with_suffix(".png")), "--json")
    assert r.returncode == 0, r.stderr
    return out, json.loads(r.stdout)


def test_the_record_holds_data_model_parameters_and_source(instrument_file, fit_file):
    path, out = fit_file
    assert is_fit_file(path) and not is_fit_file(instrument_file)
    rec = read_fit(path)
    assert rec.success and rec.fitted == ["mu_H", "offset", "baseline"]
    assert rec.parameters["mu_H"] == pytest.approx(out["mu_H"], rel=1e-12)
    assert rec.intervals["mu_H"] == pytest.approx(tuple(out["mu_H_ci95"]), rel=1e-12)
    assert rec.intervals["mu_H"][0] < MU_H < rec.intervals["mu_H"][1]
    assert rec.intervals["baseline"][0] < BASE < rec.intervals["baseline"][1]
    # the data as read (every row, file order) and which rows were used: the loading, not the retraction
    n = len(instrument_file.read_text().splitlines()) - 2
    assert rec.data["displacement"].size == n and rec.data["time"][0] == 0.0
    assert rec.data["used"].sum() == rec.parameters["n_points"] and not rec.data["used"][n // 2 + 3:].any()
    assert set(rec.data["segment"][rec.data["used"]]) <= {"approach", "loading"}
    used = rec.data["used"]
    np.testing.assert_allclose(rec.data["residual"], rec.data["model_force"] - rec.data["force"])
    rms = np.sqrt(np.mean(rec.data["residual"][used] ** 2))
    assert rms == pytest.approx(rec.parameters["residual_rms"], rel=1e-9)
    assert np.all(np.isfinite(rec.data["weight"][used])) and np.all(np.isnan(rec.data["weight"][~used]))
    # the source: its name and hash, the columns and units it was read with
    assert rec.source["sha256"] == hashlib.sha256(instrument_file.read_bytes()).hexdigest()
    assert rec.source["file_name"].endswith("seed1.tsv") and rec.source["units"]["force"] == "uN"
    assert rec.scene == sb.Scene.preset("fit") and rec.version == sb.__version__
    assert rec.model["force"][0] == pytest.approx(rec.parameters["baseline"])  # the model starts at the baseline


def test_nexusformat_loads_it_and_finds_the_plottable_signal(fit_file):
    nx = pytest.importorskip("nexusformat.nexus")
    root = nx.nxload(str(fit_file[0]))
    signal = root.plottable_data.nxsignal
    assert signal.nxname == "force" and signal.attrs["units"] == "N"
    assert root.plottable_data.nxaxes[0].nxname == "displacement"
    assert root["fit"].nxclass == "NXentry" and root["fit/model"].nxclass == "NXdata"


def test_a_curve_file_is_nexus_with_the_default_chain(tmp_path):
    """Root -> NXentry -> NXdata F(delta), as nexusformat finds it (issue 45, item 4)."""
    nx = pytest.importorskip("nexusformat.nexus")
    path = tmp_path / "c.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.15], estimate_error=False).to_hdf5(path)
    root = nx.nxload(str(path))
    assert root["entry"].nxclass == "NXentry" and root["entry/curve"].nxclass == "NXdata"
    data = root.plottable_data
    assert data.nxsignal.nxname == "force" and data.nxaxes[0].nxname == "delta"
    assert [k for k in root if root[k].nxclass == "NXdata"] == []   # no NXdata under the root


def test_every_file_the_package_writes_has_units_on_every_dataset(fit_file, tmp_path):
    curve = tmp_path / "c.h5"
    r = run("curve", "--preset", "base", "--points", "3", "--delta-max", "0.15", "--radius", "1mm", "--muH", "5N/m",
            "-o", str(curve))
    assert r.returncode == 0, r.stderr
    c = sb.read_curve(curve)
    c.to_hdf5(tmp_path / "nondim.h5")
    sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.15]).to_hdf5(tmp_path / "profiles.h5", profiles=True)
    files = [fit_file[0], curve, tmp_path / "nondim.h5", tmp_path / "profiles.h5"]
    for path in files:
        assert missing_units(path) == [], path
    with h5py.File(curve) as f:  # and the units are right, not just present
        g = f["entry/curve"]
        assert g["delta_m"].attrs["units"] == "m" and g["force_N"].attrs["units"] == "N"
        assert g["delta"].attrs["units"] == "1" and g["wall_time"].attrs["units"] == "s"
        assert g["topology"].attrs["units"] == ""
    with h5py.File(tmp_path / "profiles.h5") as f:
        assert len(f["entry/curve/profiles"]) == 2
    # the check can fail
    with h5py.File(tmp_path / "bare.h5", "w") as f:
        f["x"] = [1.0]
    assert missing_units(tmp_path / "bare.h5") == ["x"]


def test_plot_and_report_of_a_fit_file(fit_file, tmp_path, cli_main):
    pytest.importorskip("matplotlib")
    run = cli_main  # the commands' main in this process (the fit itself: the fixture's subprocess)
    path, _ = fit_file
    png = path.with_suffix(".png")  # written by fit --report
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 30_000
    r = run("plot", str(path), "-o", str(tmp_path / "fit.png"))
    assert r.returncode == 0 and (tmp_path / "fit.png").stat().st_size > 20_000, r.stderr
    r = run("report", str(path), "-o", str(tmp_path / "report.pdf"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "report.pdf").read_bytes()[:5] == b"%PDF-"
    r = run("info", str(path))
    assert r.returncode == 0 and "(a fit)" in r.stdout and "mu_H = " in r.stdout
    r = run("report", str(path), "-o", str(tmp_path / "report.txt"))
    assert r.returncode == 2 and ".png or .pdf" in r.stderr
    from shellbvp.plotting import fit_summary_lines

    rec = read_fit(path)
    lines = fit_summary_lines(rec)
    assert any(ln.startswith("mu_H = ") and "95% CI" in ln for ln in lines)
    assert any(ln.startswith("sha256: ") for ln in lines)
    # lengths and forces in the data's own units, as the fit command prints them (not raw SI)
    du, fu = rec.source["units"]["displacement"], rec.source["units"]["force"]
    assert du != "m" and fu != "N"
    offset = next(ln for ln in lines if ln.startswith("offset = "))
    assert offset.endswith(f"] {du}") and f"{rec.parameters['offset']:.5g} m" not in offset
    assert any(ln.startswith("rms residual = ") and f" {fu}; R_L = " in ln for ln in lines)


def test_a_fit_file_is_not_replaced_without_force_and_a_corrupt_one_is_named(fit_file, instrument_file, tmp_path,
                                                                             cli_main):
    path, _ = fit_file
    before = path.read_bytes()
    r = cli_main("fit", str(instrument_file), "--preset", "fit", "--radius", "0.3mm", "-o", str(path))
    assert r.returncode == 2 and "exists" in r.stderr and path.read_bytes() == before
    bad = tmp_path / "bad.h5"
    bad.write_bytes(before)
    with h5py.File(bad, "r+") as f:
        del f["fit/parameters/mu_H"]
    with pytest.raises(ValueError, match="bad.h5: incomplete or corrupt fit file"):
        read_fit(bad)
    with pytest.raises(ValueError, match="seed1.tsv: not a readable HDF5 file"):
        read_fit(instrument_file)
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f.attrs["format"] = "shellbvp-curve"
    with pytest.raises(ValueError, match="not a shellbvp fit file"):
        read_fit(tmp_path / "other.h5")
