"""Fit records that lie (issue 42): the reader checks every claim before use."""

import shutil

import h5py
import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    path = tmp_path_factory.mktemp("fit") / "good.h5"
    assert main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "-o", str(path)]) == 0
    return path


def tampered(good, tmp_path, edit):
    bad = tmp_path / "bad.h5"
    shutil.copy(good, bad)
    with h5py.File(bad, "r+") as h:
        edit(h)
    return bad


def _replace(h, name, data, **kw):
    del h[name]
    h.create_dataset(name, data=data, **kw)


EDITS = {
    "format_version 99": (lambda h: h.attrs.__setitem__("format_version", 99), "newer than this package reads"),
    "format_version text": (lambda h: h.attrs.__setitem__("format_version", "abc"), "must be an integer"),
    "format_version array": (lambda h: h.attrs.__setitem__("format_version", np.array([1, 2])), "must be an integer"),
    "success as text": (lambda h: h["fit"].attrs.__setitem__("success", "False"), "true or false"),
    "success against status": (lambda h: h["fit"].attrs.__setitem__("status", 3), "disagree"),
    "mu_H NaN, success": (lambda h: _replace(h, "fit/parameters/mu_H", np.nan), "mu_H > 0"),
    "R_L zero": (lambda h: _replace(h, "fit/parameters/R_L", 0.0), "R_L must be"),
    "R_L negative": (lambda h: _replace(h, "fit/parameters/R_L", -1.0), "R_L must be"),
    "displacements as text": (lambda h: _replace(h, "fit/data/displacement", np.array(["a"] * 40, dtype=object),
                                                 dtype=h5py.string_dtype()), "must hold numbers"),
    "a column too short": (lambda h: _replace(h, "fit/data/force", np.zeros(3)), "must have 40 values"),
    "JSON 200,000 deep": (lambda h: h["fit/sample"].attrs.__setitem__("scene", "[" * 200_000 + "]" * 200_000),
                          "JSON"),
    "3 GB compressed": (lambda h: _replace(h, "fit/data/displacement", shape=(400_000_000,), dtype="f8",
                                           compression="gzip", chunks=(1_000_000,), data=None), "MiB"),
}


@pytest.mark.parametrize("name", sorted(EDITS))
def test_a_tampered_fit_record_is_refused_with_one_line(good, tmp_path, capsys, name):
    edit, match = EDITS[name]
    bad = tampered(good, tmp_path, edit)
    with pytest.raises(ValueError, match=match):
        sb.read_fit(bad)
    for command in (["info", str(bad)], ["report", str(bad), "-o", str(tmp_path / "r.png")]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "bad.h5" in err and "Traceback" not in err


def test_the_good_record_still_reads(good):
    fr = sb.read_fit(good)
    assert fr.success and fr.status == 0 and fr.data["displacement"].shape == (40,)


def test_a_curve_file_bomb_is_refused_before_it_expands(tmp_path):
    """A curve file whose datasets claim GBs, or whose scene JSON nests 200,000 deep (issue 42)."""
    path = tmp_path / "c.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.12], estimate_error=False).to_hdf5(path)
    bomb = tmp_path / "bomb.h5"
    shutil.copy(path, bomb)
    with h5py.File(bomb, "r+") as h:
        for name in ("delta", "force"):
            del h[f"entry/curve/{name}"]
            h["entry/curve"].create_dataset(name, shape=(400_000_000,), dtype="f8", compression="gzip", chunks=(1_000_000,))
    with pytest.raises(ValueError, match="MiB"):
        sb.read_curve(bomb)
    deep = tmp_path / "deep.h5"
    shutil.copy(path, deep)
    with h5py.File(deep, "r+") as h:
        h["entry/curve"].attrs["scene"] = "[" * 200_000 + "]" * 200_000
    with pytest.raises(ValueError, match="nested deeper"):
        sb.read_curve(deep)
