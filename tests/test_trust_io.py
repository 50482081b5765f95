"""Issue #11, sections 3 and 4: output paths, checkpoints, LAPACK noise, malformed files,
extreme values -- each gets an answer (a status or a one-line ValueError), never a traceback."""

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.pointload import solve_point_load
from shellbvp.state import delta_bounds


def run(*args, cwd=None, timeout=300):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ), timeout=timeout)


def one_line_error(r, *words):
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("shellbvp: error: "), r.stderr
    for w in words:
        assert w in lines[0], lines[0]
    return lines[0]


# -- LAPACK/BLAS messages ---------------------------------------------------------------------

def test_overflowing_jacobian_never_reaches_lapack_and_json_is_one_document():
    """The extreme scene's Newton iterates overflow; SuperLU used to get a NaN matrix and its
    BLAS printed '** On entry to DGEMV parameter number 2 had an illegal value' on stdout."""
    r = run("solve", "--gamma", "99.9999999", "--rho", "0.01", "--beta", "1e-4", "--xi", "0", "--neo-hookean",
            "--delta", "0.0184286", "--tol", "1e-3", "--json")
    assert "illegal value" not in r.stdout + r.stderr
    def refuse(token):
        raise AssertionError(f"{token} is not JSON")

    out = json.loads(r.stdout, parse_constant=refuse)  # one strict document: nothing before or after it
    assert out["force"] is None and out["delta"] == 0.0184286  # no state: NaN -> null
    assert r.returncode == 1 and not out["success"] and out["status"] != 0
    assert "overflowed" in out["message"]


def test_guard_returns_status_2_for_a_nan_guess():
    sol = sb.solve(sb.Scene.preset("base"), delta=0.1, estimate_error=False)
    sysm = sol.system
    from shellbvp.solution import solve_bvp

    y = sol.y.copy()
    y[3, 5] = np.nan
    bvp = solve_bvp(sysm.fun, sysm.bc, sol.x, y, sol.p, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=1e-6)
    assert bvp.status == 2 and not bvp.success and "NaN" in bvp.message
    assert np.all(np.isnan(bvp.sol(np.array([0.2, 0.7]))))
    x = sol.x.copy()
    x[3] = x[2]  # degenerate mesh: scipy would raise ValueError (read as bad user input)
    bvp = solve_bvp(sysm.fun, sysm.bc, x, sol.y, sol.p, fun_jac=sysm.fun_jac, bc_jac=sysm.bc_jac, tol=1e-6)
    assert bvp.status == 2 and "mesh" in bvp.message


# -- extreme values -----------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs,name", [
    (dict(deltas=[1e-300, 2e-300]), "deltas"),
    (dict(delta_max=1e-300), "delta_max"),
    (dict(delta_max=0.5, delta_min=1e-9), "delta_min"),
    (dict(delta_max=5.0), "delta_max"),
])
def test_curve_refuses_depths_outside_the_range_at_once(kwargs, name):
    scene = sb.Scene.preset("base")
    low, high = delta_bounds(scene, 1e-6)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=name) as err:
        sb.curve(scene, **kwargs)
    assert time.perf_counter() - t0 < 2.0
    assert f"[{low:g}, {high:.4g}]" in str(err.value)


def test_delta_bound_is_the_meridian_stretched_2_5_times():
    """high = Z(0) - Z(L) + 2.5 l: the dome's pole starts 1 above the rim, the bowl's 1 below,
    a hemisphere's meridian is pi/2 long; a flat plate's (R = sin S) 1."""
    assert delta_bounds(sb.Scene.preset("dome"), 1e-6)[1] == pytest.approx(1 + 1.25 * np.pi, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("base"), 1e-6)[1] == pytest.approx(1.25 * np.pi - 1, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("flat"), 1e-6)[1] == pytest.approx(2.5, rel=1e-6)
    assert delta_bounds(sb.Scene.preset("base"), 1e-8)[0] == 1e-8


def test_solve_dome_paper_at_delta_5_is_refused_at_once():
    scene = sb.Scene.preset("dome", contact="paper")
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"delta = 5 is outside \[1e-06, 4.927\]"):
        sb.solve(scene, delta=5.0)
    assert time.perf_counter() - t0 < 2.0
    with pytest.raises(ValueError, match="delta = 1e-300"):
        sb.solve(scene, delta=1e-300)


@pytest.mark.slow  # 35-70 s: a whole curve from point-load states; the cold start from one stays below
def test_curve_from_point_load_states_goes_up_without_index_error():
    """delta_max = 1e-3 on the base scene: every state is the point-load limit (the cap is
    below 1e-30), so the upward leg cannot follow a cap branch; it used to fail with an
    IndexError in state._state_params (a point state has no ln Sc)."""
    c = sb.curve(sb.Scene.preset("base"), delta_max=1e-3)  # "auto": Richardson at the last point
    assert c.complete and c.delta[-1] == pytest.approx(1e-3) and "delta_max" in c.stop_reason
    assert np.all(np.diff(c.delta) > 0) and np.all(c.status == 0)
    assert set(c.topology) == {"point"}
    # the point-load limit F/delta -> 1.2625 (README), the same whichever way it is reached:
    # within the two states' own (Richardson) errors, which depend on the mesh each path
    # ends with -- at tol 1e-6, F ~ 1e-3 carries an absolute error of up to a few 1e-8
    # (measured against tol 1e-10: the curve's last point 3.3e-5 relative, estimated 3.1e-5;
    # the cold solve 1.5e-6, estimated 1.5e-6)
    direct = sb.solve(sb.Scene.preset("base"), delta=1e-3)
    assert direct.topology == "point"
    assert c.error_method[-1] == "richardson" and c.force_error[-1] < 1e-4 * c.force[-1]
    assert abs(c.force[-1] - direct.force) <= c.force_error[-1] + direct.force_error


def test_natural_curve_from_a_point_state_reaches_the_cap_again():
    c = sb.curve(sb.Scene.preset("base"), deltas=[1e-4, 0.05, 0.1], topology="cap", estimate_error=False)
    assert c.complete and list(c.topology) == ["point", "cap", "cap"]
    ref = sb.solve(sb.Scene.preset("base"), delta=0.1, topology="cap", estimate_error=False)
    assert c.force[-1] == pytest.approx(ref.force, abs=1e-7)


def test_solve_with_a_point_load_guess_starts_cold():
    scene = sb.Scene.preset("base")
    point = solve_point_load(scene, 1e-3)
    sol = sb.solve(scene, delta=0.1, guess=point, topology="cap", estimate_error=False)
    assert sol.success and sol.topology == "cap"


# -- output paths ---------------------------------------------------------------------------------

@pytest.mark.parametrize("command", [["curve", "--delta-max", "0.1"], ["fit", "--example", "--radius", "0.3mm"],
                                     ["plot", "in.h5"]])
@pytest.mark.parametrize("output,words", [
    (".", ["is a directory"]),
    ("sub", ["sub is a directory"]),
    ("nonexistent/x.h5", ["directory nonexistent", "does not exist"]),
    ("/proc/x.h5", ["/proc", "not writable"]),
    ("", ["empty"]),
    ("in.h5/x.h5", ["in.h5", "not a directory"]),
])
def test_bad_output_paths_are_refused_before_any_work(tmp_path, cli_main, command, output, words):
    (tmp_path / "sub").mkdir()
    (tmp_path / "in.h5").write_bytes(b"")  # plot would fail on reading it: the path is checked first
    t0 = time.perf_counter()
    r = cli_main(*command, "-o", output, cwd=tmp_path)  # in this process: the command's own checks
    one_line_error(r, *words)
    assert time.perf_counter() - t0 < 20  # import only: no curve, no fit
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.h5", "sub"]  # nothing left behind


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a mode-555 directory")
def test_unwritable_directory_is_refused(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        one_line_error(run("curve", "-o", "ro/x.h5", cwd=tmp_path), "ro", "not writable")
    finally:
        ro.chmod(0o755)


def test_check_output_path_api(tmp_path):
    from shellbvp.paths import check_output_path, partial_path

    target = tmp_path / "a.h5"
    assert check_output_path(target, overwrite=False) == target
    target.write_bytes(b"old")
    with pytest.raises(ValueError, match="exists; use --overwrite"):
        check_output_path(target, overwrite=False)
    assert check_output_path(str(target), overwrite=True) == target
    assert partial_path(target) == tmp_path / "a.h5.partial"
    with pytest.raises(ValueError, match="is a directory"):
        check_output_path(str(tmp_path) + os.sep, overwrite=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.h5"]  # the write probe is removed


def test_points_and_delta_max_limits_on_the_command_line(tmp_path, cli_main):
    run = cli_main  # in this process: the command's own checks
    one_line_error(run("curve", "--points", "1000000000", "-o", "p.h5", cwd=tmp_path), "--points", "[2, 100000]")
    one_line_error(run("curve", "--delta-max", "1e-300", "-o", "p.h5", cwd=tmp_path), "delta_max = 1e-300",
                   "[1e-06, 2.927]")
    assert not list(tmp_path.iterdir())


# -- --force and checkpoints -------------------------------------------------------------------------

@pytest.fixture
def old_file(tmp_path):
    path = tmp_path / "X.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.12], estimate_error=False).to_hdf5(path)
    return path, path.read_bytes()


def _start_curve_and_wait_for_checkpoint(tmp_path, *extra):
    import signal

    env = dict(os.environ, SHELLBVP_CHECKPOINT_SECONDS="0")
    # SIGINT's default disposition in the child: a suite started in the background (nohup, `cmd &`)
    # passes SIGINT on ignored, and Python then installs no KeyboardInterrupt handler
    proc = subprocess.Popen([sys.executable, "-m", "shellbvp", "curve", "--force", "-o", "X.h5", "-q", *extra],
                            cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    partial = tmp_path / "X.h5.partial"
    deadline = time.monotonic() + 120
    while not partial.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no checkpoint within 120 s"
        time.sleep(0.05)
    return proc, partial


def test_killed_run_leaves_the_old_file_intact_and_a_labelled_checkpoint(tmp_path, old_file):
    path, before = old_file
    proc, partial = _start_curve_and_wait_for_checkpoint(tmp_path, "--delta-max", "0.5")
    proc.kill()  # SIGKILL: nothing runs after it
    proc.communicate()
    assert path.read_bytes() == before
    old = sb.read_curve(path)
    assert old.complete and list(old.delta) == [0.1, 0.12]
    ck = sb.read_curve(partial)
    assert ck.stop_reason == "running" and not ck.complete and not ck.interrupted and len(ck) >= 1
    info = run("info", "X.h5.partial", cwd=tmp_path)
    assert info.returncode == 0 and "running" in info.stdout and "complete:  False" in info.stdout


def test_sigint_keeps_the_old_file_as_kill_does_and_the_points_in_the_checkpoint(tmp_path, old_file):
    """Ctrl-C is at least as safe as kill -9 (issue 42): a --force rerun interrupted keeps the
    earlier complete file byte for byte; the finished points go to X.h5.partial, labelled
    interrupted."""
    import signal

    path, before = old_file
    proc, partial = _start_curve_and_wait_for_checkpoint(tmp_path, "--delta-max", "0.5")
    n_checkpoint = len(sb.read_curve(partial))
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert "Traceback" not in err and "interrupted" in err and "is kept" in err
    assert path.read_bytes() == before
    c = sb.read_curve(partial)
    assert c.interrupted and not c.complete and c.stop_reason == "interrupted"
    assert len(c) >= n_checkpoint and c.delta[0] != 0.1  # the new run's points, not the old file's


def test_sigint_without_an_earlier_file_writes_the_finished_points(tmp_path):
    import signal

    proc, partial = _start_curve_and_wait_for_checkpoint(tmp_path, "--delta-max", "0.5")
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    c = sb.read_curve(tmp_path / "X.h5")
    assert c.interrupted and not c.complete and len(c) >= 1
    assert not partial.exists()


def test_finished_run_replaces_the_file_and_removes_the_checkpoint(tmp_path, old_file):
    path, before = old_file
    env = dict(os.environ, SHELLBVP_CHECKPOINT_SECONDS="0")
    r = subprocess.run([sys.executable, "-m", "shellbvp", "curve", "--overwrite", "-o", "X.h5", "--points", "3",
                        "--delta-max", "0.15"], cwd=tmp_path, env=env, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    c = sb.read_curve(path)
    assert c.complete and c.stop_reason == "all requested deltas computed"
    np.testing.assert_allclose(c.delta, [0.05, 0.1, 0.15])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["X.h5"]
    # a leftover checkpoint is somebody's finished work: replaced only with --overwrite
    (tmp_path / "Y.h5.partial").write_bytes(b"points")
    r = run("curve", "-o", "Y.h5", cwd=tmp_path)
    one_line_error(r, "Y.h5.partial exists", "--overwrite")


# -- malformed files -----------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def good_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("good") / "good.h5"
    sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.12, 0.14], estimate_error=False).to_hdf5(path)
    return path


def _replace(name, data, **kw):
    def edit(f):
        del f["entry/curve"][name]
        f["entry/curve"].create_dataset(name, data=data, **kw)
    return edit


def _strings(values):
    import h5py

    return _replace("force", np.array(values, dtype=object), dtype=h5py.string_dtype())


TAMPERED = {
    "no_stop_reason": (lambda f: f["entry/curve"].attrs.__delitem__("stop_reason"), "attribute stop_reason missing"),
    "no_complete": (lambda f: f["entry/curve"].attrs.__delitem__("complete"), "attribute complete missing"),
    "no_interrupted": (lambda f: f["entry/curve"].attrs.__delitem__("interrupted"), "attribute interrupted missing"),
    "complete_text": (lambda f: f["entry/curve"].attrs.__setitem__("complete", "yes"), "complete must be a boolean"),
    "stop_reason_number": (lambda f: f["entry/curve"].attrs.__setitem__("stop_reason", 3.0),
                           "stop_reason must be a string"),
    "version_array": (lambda f: f.attrs.__setitem__("format_version", np.array([2, 2])),
                      "format_version must be a scalar integer"),
    "version_float": (lambda f: f.attrs.__setitem__("format_version", 2.5), "format_version must be a scalar integer"),
    "version_missing": (lambda f: f.attrs.__delitem__("format_version"), "format_version attribute missing"),
    "version_newer": (lambda f: f.attrs.__setitem__("format_version", 99), "format version 99"),
    "scalar_delta": (_replace("delta", 0.1), "delta must be a 1-D array; got shape ()"),
    "short_force": (_replace("force", [0.1, 0.2]), "force must be a 1-D array of 3 values"),
    "force_2d": (_replace("force", np.zeros((3, 2))), "force must be a 1-D array of 3 values"),
    "force_strings": (_strings(["a", "b", "c"]), "force must hold numbers; got strings"),
    "no_lambda0": (lambda f: f["entry/curve"].__delitem__("lambda0"), "dataset lambda0 missing"),
    "no_flags": (lambda f: f["entry/curve"].__delitem__("flags"), "dataset flags missing"),
    "status_fraction": (_replace("status", [0.5, 0.0, 0.0]), "status must hold integers"),
    "topology_numbers": (_replace("topology", [1, 2, 3]), "topology must hold strings"),
    "scene_not_json": (lambda f: f["entry/curve"].attrs.__setitem__("scene", "{nope"), "attribute scene is not valid JSON"),
    "scene_incomplete": (lambda f: f["entry/curve"].attrs.__setitem__("scene", '{"gamma": 1}'),
                         "attribute scene does not describe a scene"),
    "settings_list": (lambda f: f["entry/curve"].attrs.__setitem__("settings", "[1, 2]"),
                      "attribute settings must be a JSON object"),
}


@pytest.mark.parametrize("name", sorted(TAMPERED))
def test_read_curve_names_what_is_wrong_with_a_tampered_file(tmp_path, good_file, name):
    import shutil

    import h5py

    edit, message = TAMPERED[name]
    path = tmp_path / f"{name}.h5"
    shutil.copy(good_file, path)
    with h5py.File(path, "r+") as f:
        edit(f)
    with pytest.raises(ValueError) as err:
        sb.read_curve(path)
    text = str(err.value)
    assert text.startswith(f"{path}: ") and message in text and "\n" not in text, text


def test_info_answers_every_tampered_file_in_one_line(tmp_path, good_file, cli_main):
    import shutil

    run = cli_main  # in this process: info's own reading and one-line answers

    import h5py

    for name in ("no_stop_reason", "version_array", "scalar_delta", "short_force", "force_strings"):
        edit, message = TAMPERED[name]
        path = tmp_path / f"{name}.h5"
        shutil.copy(good_file, path)
        with h5py.File(path, "r+") as f:
            edit(f)
        one_line_error(run("info", path.name, cwd=tmp_path), path.name, message)
    r = run("info", str(good_file))
    assert r.returncode == 0 and "complete:  True" in r.stdout


def test_an_untouched_file_reads_back_with_its_types(good_file):
    c = sb.read_curve(good_file)
    assert c.complete and not c.interrupted and c.stop_reason == "all requested deltas computed"
    assert c.status.dtype.kind == "i" and c.valid.dtype == bool and c.delta.dtype == float
    assert set(c.topology) <= {"cap", "line", "annulus"} and len(c.topology) == len(c.flags) == 3
    again = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.12, 0.14], estimate_error=False)
    assert list(c.topology) == list(again.topology) and c.flags == again.flags
    np.testing.assert_array_equal(c.force, again.force)


def test_a_curve_without_points_round_trips(tmp_path):
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1], max_nodes=10, estimate_error=False)
    assert len(c) == 0 and not c.complete and "no solution" in c.stop_reason
    c.to_hdf5(tmp_path / "e.h5")
    back = sb.read_curve(tmp_path / "e.h5")
    assert len(back) == 0 and back.stop_reason == c.stop_reason and not back.complete
    r = run("info", "e.h5", cwd=tmp_path)
    assert r.returncode == 0 and "0 points" in r.stdout


def test_a_directory_is_not_a_curve_file(tmp_path):
    with pytest.raises(ValueError, match="is a directory"):
        sb.read_curve(tmp_path)


def test_csv_numbers_that_overflow_in_si_units_name_their_line(tmp_path):
    path = tmp_path / "big.csv"
    path.write_text("# a comment\nd (um),F (kN)\n1,1\n2,1e308\n3,2\n4,3\n")
    with pytest.raises(ValueError, match="line 4: .*overflow"):
        sb.read_force_csv(path)


@pytest.mark.parametrize("material", [lambda: sb.MooneyRivlin(True), lambda: sb.Gent(True)])
def test_booleans_are_not_material_parameters(material):
    with pytest.raises(ValueError, match="alpha|Jm"):
        sb.Scene.preset("base", material=material())


# -- a full disk, damaged compiled kernels (issue 59) ----------------------------------------------------

def _limited(limit_bytes):
    """A subprocess's preexec: files larger than ``limit_bytes`` cannot be written (EFBIG, as on
    a full disk; SIGXFSZ ignored so that the write fails instead of the process)."""
    import resource
    import signal

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return limit


@pytest.mark.parametrize("json_out", [False, True])
def test_fit_output_on_a_full_disk_prints_the_fit_then_one_error_line(tmp_path, json_out):
    """Before: the result, then 16-28 h5py tracebacks and a segfault, a hidden .tmp left."""
    sb.Scene.preset("fit").model()  # the generated code in the cache first: the limit is for the output
    r = subprocess.run([sys.executable, "-m", "shellbvp", "fit", "--example", "--preset", "fit", "--radius", "0.3mm",
                        "-o", "out.h5", *(["--json"] if json_out else [])], cwd=tmp_path, capture_output=True,
                       text=True, env=dict(os.environ), timeout=300, preexec_fn=_limited(12000))
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    errors = [ln for ln in r.stderr.splitlines() if ln.startswith("shellbvp: error:")]
    assert errors == ["shellbvp: error: cannot write out.h5: File too large"], r.stderr
    if json_out:
        out = json.loads(r.stdout)
        assert out["exit_status"] == 2 and out["success"] and "out.h5" in out["write_error"]
    else:
        assert "mu*H   = " in r.stdout  # the result stands, printed before the file failed
    assert list(tmp_path.iterdir()) == []  # neither out.h5 nor a hidden partial file


def test_a_curve_file_on_a_full_disk_is_one_oserror_naming_it(tmp_path):
    code = ("import resource, signal, sys, numpy as np, shellbvp as sb; "
            "c = sb.curve(sb.Scene.preset('base'), deltas=np.linspace(0.05, 0.2, 4), estimate_error=False); "
            "signal.signal(signal.SIGXFSZ, signal.SIG_IGN); resource.setrlimit(resource.RLIMIT_FSIZE, (6000, 6000))\n"
            "try:\n    c.to_hdf5(sys.argv[1], profiles=True)\nexcept OSError as exc:\n    print(exc.strerror)")
    r = subprocess.run([sys.executable, "-c", code, str(tmp_path / "c.h5")], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert r.stdout.strip() == f"cannot write {tmp_path / 'c.h5'}: File too large"
    assert list(tmp_path.iterdir()) == []


def test_damaged_compiled_kernels_are_discarded_and_compiled_again(tmp_path, monkeypatch, caplog):
    """numba's loader raises what unpickling a damaged cache file raises; `compile` (the
    foreground load) warns once, removes that structure's cache files and compiles; a background
    load removes them too, so later runs read the kernels as not compiled (no warning each run)."""
    import pickle

    from shellbvp import kernels as sk

    src = tmp_path / "kernels_0123.py"
    src.write_text("KEY = 'k'\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir(mode=0o700)
    files = [cache / "kernels_0123.rhs-12.py311.nbi", cache / "kernels_0123.rhs-12.py311.1.nbc",
             src.with_suffix(".ready")]
    other = cache / "kernels_9999.rhs-12.py311.nbi"  # another structure's: kept
    for f in [*files, other]:
        f.write_bytes(b"x")
    calls = []

    def damaged(path, key):
        calls.append("import")
        raise pickle.UnpicklingError("invalid load key, '\\xbb'.")

    monkeypatch.setattr(sk, "_import_kernels", damaged)
    monkeypatch.setattr(sk, "_compile_here", lambda path, key, desc: (calls.append("compile") or "module", 12.0))
    with caplog.at_level("WARNING", logger="shellbvp.kernels"):
        assert sk._load_compiled(src, "k", {}) == ("module", 12.0)
    assert calls == ["import", "compile"] and not any(f.exists() for f in files) and other.exists()
    assert len(caplog.records) == 1 and "UnpicklingError" in caplog.records[0].getMessage()
    for f in files:
        f.write_bytes(b"x")
    monkeypatch.setattr(sk, "_ready", lambda path, key: True)
    monkeypatch.setattr(sk, "kernel_path", lambda desc: src)
    ks = sk.KernelSet(type("M", (), {"KEY": "k"})(), "auto")
    with pytest.raises(RuntimeError, match="discarded: `shellbvp compile` builds it again"):
        ks._load({}, foreground=False)
    assert not any(f.exists() for f in files)
