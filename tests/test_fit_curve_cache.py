"""A fit's model curves kept on disk (shellbvp.fitting.curves): read back by the next fit of the
same scene and depths in any process, with the same numbers; missed when anything they depend
on changes; a damaged file is ignored."""

import json
import subprocess
import sys

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
