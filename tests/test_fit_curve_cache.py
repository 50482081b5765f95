"""A fit's model curves kept on disk (shellbvp.fitting.curves): read back by the next fit of the
same scene and depths in any process, with the same numbers; missed when anything they depend
on changes; a damaged file is ignored."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.fitting import clear_model_curves, curves


def _fit(scene, d, F):
    return sb.fit(scene, d, F, R_L=1e-3)


@pytest.fixture
def data():
    scene = sb.Scene.preset("base")
    c = sb.curve(scene, deltas=np.linspace(0.02, 0.2, 10), estimate_error=False)
    return scene, c.delta * 1e-3, c.force * 50.0 * 1e-3


def _fit_twice(data, cache, between=lambda kept: None):
    """Two fits of ``data`` with the disk cache on, the process's memo forgotten between them
    (as in a new process); ``between(kept files)`` runs in between."""
    scene, d, F = data
    with sb.options(model_curve_cache=True):
        clear_model_curves()
        first = _fit(scene, d, F)
        kept = list((cache / "curves").glob("curve_*.h5"))
        between(kept)
        clear_model_curves()
        return first, _fit(scene, d, F), kept


def test_a_kept_curve_is_read_back_with_the_same_fit(data, tmp_path, monkeypatch):
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    first, again, kept = _fit_twice(data, tmp_path)
    assert first.curves_computed == 1 and again.curves_computed == 0 and len(kept) == 1
    assert again.mu_H == first.mu_H and again.offset == first.offset
    assert first.mu_H == pytest.approx(50.0, rel=1e-3)


def test_another_process_reads_the_kept_curve(data, tmp_path):
    scene, d, F = data
    code = ("import json, sys, numpy as np, shellbvp as sb; d, F = json.load(sys.stdin); "
            "r = sb.fit(sb.Scene.preset('base'), np.array(d), np.array(F), R_L=1e-3); "
            "print(r.curves_computed, repr(r.mu_H))")
    env = dict(__import__("os").environ, SHELLBVP_CACHE_DIR=str(tmp_path))
    module = Path(sb.Scene.preset("base").model().__file__)  # the structure's code: not derived again there
    (tmp_path / module.name).write_bytes(module.read_bytes())
    runs = [subprocess.run([sys.executable, "-c", code], input=json.dumps([list(d), list(F)]), capture_output=True,
                           text=True, env=env, timeout=600) for _ in range(2)]
    assert all(r.returncode == 0 for r in runs), runs[0].stderr
    (n1, mu1), (n2, mu2) = (r.stdout.split() for r in runs)
    assert (n1, n2) == ("1", "0") and mu1 == mu2


def test_a_change_of_scene_tolerance_or_options_misses(data, tmp_path, monkeypatch):
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    scene, d, F = data
    grid = np.linspace(0.01, 0.3, 5)
    with sb.options(model_curve_cache=True):
        base = curves._disk_place(scene, grid, 1e-6)[1]
        assert curves._disk_place(scene, grid, 1e-6)[1] == base
        assert curves._disk_place(sb.Scene.preset("base", beta=0.011), grid, 1e-6)[1] != base
        assert curves._disk_place(scene, grid, 1e-7)[1] != base
        assert curves._disk_place(scene, grid * 1.01, 1e-6)[1] != base
        with sb.options(equidistribute=False):
            assert curves._disk_place(scene, grid, 1e-6)[1] != base
        with sb.options(progress_seconds=3.0):  # not a numeric option: same curve
            assert curves._disk_place(scene, grid, 1e-6)[1] == base
    assert curves._disk_place(scene, grid, 1e-6) == (None, None)  # the tests' default: off


def test_a_damaged_or_foreign_kept_file_is_ignored(data, tmp_path, monkeypatch):
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    first, again, kept = _fit_twice(data, tmp_path, lambda kept: [k.write_bytes(b"not a curve") for k in kept])
    assert len(kept) == 1 and again.curves_computed == 1 and again.mu_H == first.mu_H


# -- issue 59: a kept curve is data from disk, checked before use ---------------------------------------

from shellbvp.fitting import kept as kept_records  # noqa: E402

GRID = np.linspace(0.02, 0.2, 6)


@pytest.fixture
def kept_curve(tmp_path, monkeypatch):
    """A kept model curve of the base scene on GRID (computed once per test: ~1 s) and its key."""
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    kept_records.forget_warnings()
    scene = sb.Scene.preset("base")
    with sb.options(model_curve_cache=True):
        clear_model_curves()
        c = curves._model_curve(scene, GRID, 1e-6)
        path, key = curves._disk_place(scene, GRID, 1e-6)
    assert path.is_file()
    return scene, c, path, key


def _h5_edit(path, edit):
    import h5py

    with h5py.File(path, "r+") as h:
        edit(h["entry/curve"])


def _flip_bit(g):
    force = g["force"][()]
    bits = force.view(np.uint64).copy()
    bits[3] ^= np.uint64(1) << np.uint64(40)
    g["force"][...] = bits.view(float)


def _double(g):
    g["force"][...] = 2 * g["force"][()]


def _nan(g):
    force = g["force"][()]
    force[2] = np.nan
    g["force"][...] = force


def _other_scene(g):
    scene = json.loads(g.attrs["scene"])
    scene["beta"] = 2 * scene["beta"]
    g.attrs["scene"] = json.dumps(scene)


TAMPERED = {"one bit flipped in the force": lambda p: _h5_edit(p, _flip_bit),
            "the force doubled": lambda p: _h5_edit(p, _double),
            "a NaN in the force": lambda p: _h5_edit(p, _nan),
            "another scene": lambda p: _h5_edit(p, _other_scene),
            "writable by others": lambda p: p.chmod(0o666),
            "a directory": lambda p: (p.unlink(), p.mkdir()),
            "a symbolic link": lambda p: (p.rename(p.with_name("elsewhere.h5")),
                                          p.symlink_to(p.with_name("elsewhere.h5")))}


@pytest.mark.parametrize("how", TAMPERED)
def test_a_tampered_kept_curve_is_set_aside_with_one_warning(kept_curve, how, caplog):
    scene, c, path, key = kept_curve
    assert curves._read_kept(path, key, scene, GRID) is not None  # untouched: read back
    TAMPERED[how](path)
    with caplog.at_level("WARNING", logger="shellbvp.fitting.kept"):
        assert curves._read_kept(path, key, scene, GRID) is None
        assert curves._read_kept(path, key, scene, GRID) is None  # gone: nothing to say again
    warned = [r.getMessage() for r in caplog.records]
    assert len(warned) == 1 and path.name in warned[0] and "set aside" in warned[0], warned
    assert not path.exists() and path.with_name(path.name + ".bad").exists()


def test_a_doubled_kept_curve_gives_the_fit_of_the_computed_one(data, tmp_path, monkeypatch, caplog):
    """Issue 59: doubling the kept force array halved mu*H and was rated good; now the file is
    set aside and the curve computed again, with the first fit's numbers."""
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    kept_records.forget_warnings()
    with caplog.at_level("WARNING", logger="shellbvp.fitting.kept"):
        first, again, kept = _fit_twice(data, tmp_path, lambda kept: [_h5_edit(k, _double) for k in kept])
    assert again.curves_computed == 1 and again.mu_H == first.mu_H and again.success
    assert any("checksum" in r.getMessage() for r in caplog.records)
    assert [p.name for p in (tmp_path / "curves").iterdir()] != []


def test_an_unusable_cache_folder_is_no_cache_with_one_warning(data, tmp_path, monkeypatch, caplog):
    """A `curves` that is a file, or a folder where no file can be made (read-only; simulated:
    root may write anywhere), leaves the fit to compute its curve; one warning each."""
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    kept_records.forget_warnings()
    scene, d, F = data
    (tmp_path / "curves").write_text("not a folder")
    with sb.options(model_curve_cache=True), caplog.at_level("WARNING", logger="shellbvp.fitting.kept"):
        assert curves._disk_place(scene, GRID, 1e-6) == (None, None)
        assert curves._disk_place(scene, GRID, 1e-6) == (None, None)
        (tmp_path / "curves").unlink()

        def read_only(*args, **kwargs):
            raise PermissionError(13, "Permission denied")

        monkeypatch.setattr(kept_records.tempfile, "mkstemp", read_only)
        clear_model_curves()
        res = _fit(scene, d, F)
    assert res.success and res.curves_computed == 1
    warned = [r.getMessage() for r in caplog.records]
    assert len(warned) == 2 and "not a folder" in warned[0] and "Permission denied" in warned[1], warned


def test_keeping_a_curve_on_a_full_disk_warns_and_leaves_no_partial_file(kept_curve, caplog):
    """RLIMIT_FSIZE makes writes past it fail with EFBIG (as on a full disk), in a subprocess."""
    scene, c, path, key = kept_curve
    path.unlink()
    code = ("import resource, signal, sys, logging; import shellbvp as sb; from pathlib import Path; "
            "from shellbvp.fitting import curves; logging.basicConfig(); "
            "c = sb.read_curve(sys.argv[1] + '.src'); "
            "signal.signal(signal.SIGXFSZ, signal.SIG_IGN); resource.setrlimit(resource.RLIMIT_FSIZE, (8000, 8000)); "
            "curves._keep(c, Path(sys.argv[1]), sys.argv[2]); print('done')")
    c.to_hdf5(str(path) + ".src")
    r = subprocess.run([sys.executable, "-c", code, str(path), key], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "done", r.stderr
    assert "Traceback" not in r.stderr and "cannot keep model curves" in r.stderr, r.stderr
    assert sorted(p.name for p in path.parent.iterdir()) == [path.name + ".src"]  # no .tmp left


def test_a_kept_curve_that_starts_deeper_than_its_grid_is_read_back(tmp_path, monkeypatch, caplog):
    """A shallow record's model curve starts at the first depth with a contact cap (the rest of
    the grid is the point-load limit's): kept, it is read back, not set aside as damaged."""
    monkeypatch.setenv("SHELLBVP_CACHE_DIR", str(tmp_path))
    kept_records.forget_warnings()
    scene, grid = sb.Scene.preset("base"), np.r_[1e-3, GRID]  # at 1e-3 the contact is the point-load limit
    with sb.options(model_curve_cache=True):
        clear_model_curves()
        computed = curves._model_curve(scene, grid, 1e-6)
        path, key = curves._disk_place(scene, grid, 1e-6)
        assert computed.delta[0] > grid[0] and path.is_file()
        again = curves._read_kept(path, key, scene, grid)
    assert again is not None and np.array_equal(again.force, computed.force)
    assert not list(tmp_path.rglob("*.bad")) and "set aside" not in caplog.text
