"""Batch fitting (issue 15 item 4) and progress bars (item 5).

Three instrument-style records of known mu*H (generated from the model) and a broken one:
``shellbvp fit DIR --table results.csv`` gives one row per file, the broken file's row says
why, the others are fitted with one shared model curve.
"""

import csv
import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.config import OPTIONS
from shellbvp.batch import TABLE_COLUMNS, expand_inputs, fit_files

R_L = 0.3e-3
TRUTH = {"seed_a": (35.0, 20e-6, 0.40), "seed_b": (40.0, 30e-6, 0.36), "seed_c": (47.0, 25e-6, 0.38)}


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True, cwd=cwd,
                          env=dict(os.environ), timeout=600)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """Three records (approach, loading, retraction with hysteresis, 80 uN baseline) and a broken file."""
    c = sb.curve(sb.Scene.preset("fit"), deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    root = tmp_path_factory.mktemp("batch")
    data = root / "data"
    data.mkdir()
    for k, (name, (mu_H, d0, depth)) in enumerate(TRUTH.items()):
        rng = np.random.default_rng(k)
        top = d0 + depth * R_L
        d = np.r_[np.linspace(0, top, 120), np.linspace(top, 0, 120)]
        x = np.clip((d - d0) / R_L, 0, None)
        f = mu_H * R_L * shape(x)
        f[120:] *= 0.85  # hysteresis
        f = f * (1 + 0.02 * rng.standard_normal(d.size)) + 80e-6 + 1e-6 * rng.standard_normal(d.size)
        (data / f"{name}.tsv").write_text("Time (s)\tDisplacement (um)\tForce (uN)\n" + "\n".join(
            f"{0.1 * i:.1f}\t{a * 1e6:.5f}\t{b * 1e6:.5f}" for i, (a, b) in enumerate(zip(d, f))) + "\n")
    (data / "broken.csv").write_text("Time (s),Displacement (um),Force (uN)\n0,1,2\n0.1,x,3\n")
    (data / "notes.md").write_text("not data: skipped")  # a directory's other files are not inputs
    return root


def test_batch_of_three_files_gives_a_table_of_three_rows(folder):
    files = sorted(str(p) for p in (folder / "data").glob("seed_*.tsv"))
    r = run("fit", *files, "--preset", "fit", "--radius", "0.3mm", "--table", "three.csv", "-o", "fits",
            cwd=folder)
    assert r.returncode == 0, r.stderr
    with open(folder / "three.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3 and list(rows[0]) == list(TABLE_COLUMNS)
    for row in rows:
        mu_H, d0, _ = TRUTH[os.path.basename(row["file"]).split(".")[0]]
        assert row["status"] == "ok" and row["baseline model"] == "constant"
        assert float(row["mu_H 95% low (N/m)"]) < mu_H < float(row["mu_H 95% high (N/m)"]), row
        assert abs(float(row["offset (m)"]) - d0) < 2e-6
        assert float(row["baseline 95% low (N)"]) < 80e-6 < float(row["baseline 95% high (N)"])
        assert float(row["residual rms (N)"]) > 0 and int(row["points"]) >= 110 and len(row["sha256"]) == 64
    assert sorted(p.name for p in (folder / "fits").iterdir()) == ["seed_a.h5", "seed_b.h5", "seed_c.h5"]
    assert "3 of 3 files fitted" in r.stdout
    # the batch names its sample in lab units, as a single fit does
    assert "scene  = preset fit; shell: spheroidal bowl (indented from inside), rise 750 um (gamma 2.5) on a rim radius of 300 um" in r.stdout


def test_a_broken_file_gets_its_row_and_the_others_are_fitted(folder):
    r = run("fit", "data", "--preset", "fit", "--radius", "0.3mm", "--table", "four.csv", "--json", cwd=folder)
    assert r.returncode == 1, r.stderr  # not every file was fitted
    doc = json.loads(r.stdout)
    assert doc["exit_status"] == 1 and len(doc["files"]) == 4
    with open(folder / "four.csv", newline="") as fh:
        rows = {os.path.basename(row["file"]): row for row in csv.DictReader(fh)}
    assert set(rows) == {"broken.csv", "seed_a.tsv", "seed_b.tsv", "seed_c.tsv"}
    assert rows["broken.csv"]["status"] == "error" and "line 3" in rows["broken.csv"]["message"]
    assert rows["broken.csv"]["mu_H (N/m)"] == ""
    assert all(rows[f"{n}.tsv"]["status"] == "ok" for n in TRUTH)


def test_the_model_curve_is_computed_once_for_the_batch(folder, monkeypatch):
    from shellbvp import fitting

    fitting.clear_model_curves()  # an empty cache: count every curve
    files = expand_inputs([str(folder / "data" / "seed_*.tsv")])
    assert [os.path.basename(f) for f in files] == ["seed_a.tsv", "seed_b.tsv", "seed_c.tsv"]
    seen = []
    rows = fit_files(sb.Scene.preset("fit"), files + [str(folder / "missing.tsv")], R_L=R_L, on_file=seen.append)
    assert [r.status for r in rows] == ["ok", "ok", "ok", "error"] and len(seen) == 4
    assert [r.result.curves_computed for r in rows[:3]] == [1, 0, 0]
    assert "cannot read" in rows[3].message


def test_batch_outputs_are_checked_before_any_fit(folder, cli_main):
    run = cli_main  # the command's main in this process
    (folder / "taken.csv").write_text("x")
    r = run("fit", "data", "--preset", "fit", "--radius", "0.3mm", "--table", "taken.csv", cwd=folder)
    assert r.returncode == 2 and "exists" in r.stderr
    r = run("fit", "data", "--preset", "fit", "--radius", "0.3mm", "-o", "taken.csv", cwd=folder)
    assert r.returncode == 2 and "must be a directory" in r.stderr
    r = run("fit", "nothing-*.csv", "--preset", "fit", "--radius", "0.3mm", cwd=folder)
    assert r.returncode == 2 and "no file matches" in r.stderr



def test_a_given_thickness_fills_the_tables_thickness_mu_and_E(folder, tmp_path):
    """Issue 56 item 7: with --thickness given (not fitted), the table carried mu*H only; the
    thickness, mu = mu*H / H and E = 3 mu are known, so their columns are filled (no interval on H)."""
    from shellbvp.batch import write_table

    H = 5e-6
    files = [str(folder / "data" / f"{name}.tsv") for name in ("seed_a", "seed_b")]
    rows = fit_files(sb.Scene.preset("fit", thickness=H / R_L), files, R_L=R_L)
    assert [r.status for r in rows] == ["ok", "ok"], [r.message for r in rows]
    write_table(tmp_path / "t.csv", rows)
    with open(tmp_path / "t.csv", newline="") as fh:
        table = list(csv.DictReader(fh))
    for row, r in zip(table, rows):
        mu_H, low, high = (float(row[c]) for c in ("mu_H (N/m)", "mu_H 95% low (N/m)", "mu_H 95% high (N/m)"))
        assert float(row["thickness (m)"]) == pytest.approx(H, rel=1e-6)
        assert row["thickness 95% low (m)"] == row["thickness 95% high (m)"] == ""
        assert float(row["mu (Pa)"]) == pytest.approx(mu_H / H, rel=1e-6)
        assert float(row["mu 95% low (Pa)"]) == pytest.approx(low / H, rel=1e-6)
        assert float(row["E (Pa)"]) == pytest.approx(3 * mu_H / H, rel=1e-6)
        assert float(row["E 95% high (Pa)"]) == pytest.approx(3 * high / H, rel=1e-6)
        assert r.result.E == pytest.approx(3 * r.result.mu) and r.result.to_dict()["E"] is not None


# -- progress bars ----------------------------------------------------------------------------------
def test_progress_bar_is_silent_without_tqdm_or_when_not_wanted(monkeypatch, capsys):
    from shellbvp import progress

    with open(os.devnull, "w") as null:
        assert progress.wanted(quiet=False, stream=null) == "lines"   # a log, not a terminal
    assert not progress.wanted(quiet=True)
    monkeypatch.setitem(sys.modules, "tqdm", None)  # tqdm not installed
    bar = progress.progress_bar(3, enabled=True)
    bar.update(2)
    bar.close()
    assert bar.n == 2 and capsys.readouterr().err == ""


def test_progress_lines_go_to_a_log_now_and_then(monkeypatch, capsys):
    """Not a terminal: a line every options.progress_seconds and one at the end, none for a short task."""
    from shellbvp import progress

    bar = progress.progress_bar(3, desc="fit", unit="file", enabled="lines")
    bar.update(1)
    bar.close()
    assert capsys.readouterr().err == ""          # shorter than progress_seconds: nothing
    monkeypatch.setattr(OPTIONS, "progress_seconds", 0.0)
    bar = progress.progress_bar(3, desc="fit", unit="file", enabled="lines")
    bar.set_postfix_str("a.csv: ok")
    bar.update(2)
    bar.close()
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("fit: file 2/3, a.csv: ok (") and lines[-1].endswith("; done")


def test_curve_progress_moves_with_delta(capsys):
    pytest.importorskip("tqdm")
    from shellbvp.progress import curve_progress

    class Sol:
        delta, force = 0.25, 1.5

    bar, callback = curve_progress(0.5, "test", enabled=True)
    callback([1, 2], Sol())
    assert bar.n == pytest.approx(0.25)
    bar.close()
    err = capsys.readouterr().err
    assert "test" in err and "delta 0.250/0.500" in err and "2 points" in err


def _on_a_terminal(args, cwd):
    """Run shellbvp with stderr on a pseudo-terminal; (return code, what the terminal showed)."""
    import fcntl
    import struct
    import termios

    master, slave = os.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))  # a new pty has 0 columns
    chunks = []

    def read():
        while True:
            try:
                data = os.read(master, 4096)
            except OSError:
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    p = subprocess.run([sys.executable, "-m", "shellbvp", *args], stdout=subprocess.PIPE, stderr=slave, cwd=cwd,
                       env=dict(os.environ), timeout=600)
    os.close(slave)
    reader.join(timeout=10)
    os.close(master)
    return p.returncode, b"".join(chunks).decode("utf-8", "replace")


def test_curve_and_fit_show_progress_on_a_terminal_and_not_with_q(folder, tmp_path):
    pytest.importorskip("tqdm")
    code, shown = _on_a_terminal(["curve", "--points", "4", "--delta-max", "0.2", "-o", "c.h5"], tmp_path)
    assert code == 0 and "curve base" in shown and "delta" in shown and "/0.200" in shown, shown
    code, shown = _on_a_terminal(["curve", "--points", "4", "--delta-max", "0.2", "-o", "q.h5", "-q"], tmp_path)
    assert code == 0 and shown == ""
    code, shown = _on_a_terminal(["fit", str(folder / "data"), "--preset", "fit", "--radius", "0.3mm",
                                  "--table", str(tmp_path / "t.csv")], tmp_path)
    assert code == 1 and "file" in shown and "4/4" in shown, shown
