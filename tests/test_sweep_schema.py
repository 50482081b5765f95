"""Sweep files that lie, and resumes that must not trust them (issue 42)."""

import shutil

import h5py
import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main
from shellbvp.sweeps import read_sweep, sweep

KW = dict(delta_max=0.1, workers=1, deltas=[0.05, 0.1], estimate_error=False)
GRID = {"beta": [0.005, 0.01]}


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    path = tmp_path_factory.mktemp("sweep") / "good.h5"
    res = sweep(sb.Scene.preset("base"), GRID, out=path, **KW)
    assert res.counts() == {"complete": 2}
    return path


def copy(good, tmp_path, edit=None):
    bad = tmp_path / "bad.h5"
    shutil.copy(good, bad)
    if edit is not None:
        with h5py.File(bad, "r+") as h:
            edit(h)
    return bad


def _set_index(h, key, values, text=False):
    del h[f"sweep/index/{key}"]
    if text:
        h["sweep/index"].create_dataset(key, data=np.array(values, dtype=object), dtype=h5py.string_dtype())
    else:
        h["sweep/index"].create_dataset(key, data=values)


def test_a_complete_cell_without_its_curve_is_read_as_pending_and_recomputed(good, tmp_path):
    bad = copy(good, tmp_path, lambda h: h.__delitem__("sweep/curves/curve_000001"))
    back = read_sweep(bad)
    assert list(back.index["status"]) == ["complete", "pending"] and "curve is missing" in back.index["message"][1]
    res = sweep(sb.Scene.preset("base"), GRID, out=bad, **KW)
    assert res.computed == 1 and res.counts() == {"complete": 2}


def test_a_cell_pointing_at_another_cells_curve_is_not_shown_as_its_own(good, tmp_path):
    def edit(h):
        groups = [g.decode() if isinstance(g, bytes) else g for g in h["sweep/index/group"][()]]
        _set_index(h, "group", [groups[0], groups[0]], text=True)

    back = read_sweep(copy(good, tmp_path, edit))
    assert back.index["status"][1] == "pending" and 1 not in back.curves
    assert "names another curve" in back.index["message"][1]


def test_cells_in_error_are_retried_on_resume(good, tmp_path):
    bad = copy(good, tmp_path, lambda h: (h.__delitem__("sweep/curves/curve_000000"),
                                          _set_index(h, "status", ["error", "complete"], text=True),
                                          _set_index(h, "group", ["", "curves/curve_000001"], text=True)))
    assert read_sweep(bad).index["status"][0] == "error"
    res = sweep(sb.Scene.preset("base"), GRID, out=bad, **KW)
    assert res.computed == 1 and res.counts() == {"complete": 2}


@pytest.mark.parametrize("edit,match", [
    (lambda h: _set_index(h, "beta", [0.005, 0.7]), "not on the grid"),
    (lambda h: h.attrs.__setitem__("format_version", np.array([1, 1])), "must be an integer"),
    (lambda h: h.attrs.__setitem__("format_version", "1"), "must be an integer"),
    (lambda h: h["sweep"].attrs.__setitem__("grid", "{" * 100_000), "JSON nested deeper"),
    (lambda h: _set_index(h, "points", np.array(["a", "b"], dtype=object)), "points"),
])
def test_a_malformed_sweep_file_is_one_line_naming_it(good, tmp_path, capsys, edit, match):
    bad = copy(good, tmp_path, edit)
    with pytest.raises(ValueError, match=match) as err:
        read_sweep(bad)
    assert "bad.h5" in str(err.value)
    assert main(["info", str(bad)]) == 2
    out = capsys.readouterr().err
    assert out.count("\n") == 1 and "Traceback" not in out


def test_a_lock_that_is_a_directory_is_one_line(good, tmp_path, capsys):
    bad = copy(good, tmp_path)
    (tmp_path / "bad.h5.lock").mkdir()
    with pytest.raises(ValueError, match="lock file"):
        sweep(sb.Scene.preset("base"), GRID, out=bad, **KW)


def _peer(mode):
    import os
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(5)

    def serve():
        while True:
            conn, _ = srv.accept()
            if mode == "junk":
                conn.sendall(os.urandom(1 << 14))

    threading.Thread(target=serve, daemon=True).start()
    return f"127.0.0.1:{srv.getsockname()[1]}"


@pytest.mark.parametrize("mode,match", [("silent", "did not answer within"), ("junk", "cannot use the Dask")])
def test_a_scheduler_that_never_answers_or_answers_junk_is_one_line(mode, match):
    pytest.importorskip("dask.distributed")
    from shellbvp.sweeps import dask_executor

    with pytest.raises(ValueError, match=match):
        dask_executor(_peer(mode), timeout=1.0)


@pytest.mark.parametrize("address,match", [("", "empty"), ("ucx://h:1", "only tcp://"), ("tls://h:8786", "only tcp://"),
                                           ("inproc://foo", "only tcp://"), ("h:99999", "port 1-65535")])
def test_scheduler_addresses_are_checked_first(address, match, capsys):
    rc = main(["sweep", "--beta", "0.01", "--delta-max", "0.1", "--scheduler", address, "-o", "never.h5"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "Traceback" not in err
    import re

    assert re.search(match, err)


def test_workers_end_with_a_killed_parent(tmp_path):
    """kill -9 of `sweep --workers 2`: its workers had lived on for 20 min holding the dead
    parent's pipes (issue 42); now they exit within about a second."""
    import os
    import signal
    import subprocess
    import sys
    import time

    proc = subprocess.Popen([sys.executable, "-m", "shellbvp", "sweep", "--beta", "0.005,0.01,0.02,0.03",
                             "--delta-max", "0.5", "--workers", "2", "-q", "-o", "g.h5"], cwd=tmp_path,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)

    def children():
        out = []
        for pid in os.listdir("/proc"):
            if pid.isdigit():
                try:
                    with open(f"/proc/{pid}/stat") as f:
                        fields = f.read().rsplit(")", 1)[1].split()
                except OSError:
                    continue
                if int(fields[3]) == proc.pid or int(fields[2]) == proc.pid:  # ppid or process group
                    out.append(int(pid))
        return out

    deadline = time.monotonic() + 60
    while len(children()) < 2:
        assert proc.poll() is None and time.monotonic() < deadline, "no workers started"
        time.sleep(0.2)
    group = os.getpgid(proc.pid)
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 15
    alive = True
    while alive and time.monotonic() < deadline:
        time.sleep(0.3)
        try:
            os.killpg(group, 0)
        except ProcessLookupError:
            alive = False
    if alive:
        os.killpg(group, signal.SIGKILL)
    assert not alive, "workers outlived their parent by 15 s"
