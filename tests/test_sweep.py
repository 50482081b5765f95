"""Sweeps (shellbvp.sweeps): results that travel between processes, the resumable sweep file,
executors (a process pool, Dask), and the fit with an uncertain geometry."""

import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.config import OPTIONS


def test_scene_round_trips_through_pickle_user_formulas_included():
    user = sb.Scene.preset("base", material=sb.StrainEnergy(
        "(lambda_s**2 + lambda_theta**2 + 1/(lambda_s*lambda_theta)**2 - 3)/2"),
        shell=sb.UserShell("sin(S)", "-cos(S)", "pi/2"), tip=sb.UserTip("omega", "omega**2/2"))
    for scene in (sb.Scene.preset("fit"), sb.Scene.preset("gent1"), user):
        back = pickle.loads(pickle.dumps(scene))
        assert back == scene and back.to_dict() == scene.to_dict()


def test_solution_and_curve_come_back_from_a_worker_process():
    """A Solution and a Curve computed in another process (spawned: an empty module table)
    equal those computed here, and their profiles work (the generated module is reloaded from
    the code cache, never pickled)."""
    scene = sb.Scene.preset("base")
    here_sol = sb.solve(scene, delta=0.1, estimate_error=False)
    here_curve = sb.curve(scene, deltas=[0.05, 0.1])
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as ex:
        there_sol = ex.submit(sb.solve, scene, delta=0.1, estimate_error=False).result()
        there_curve = ex.submit(sb.curve, scene, deltas=[0.05, 0.1]).result()
    assert b"shellbvp_generated" not in pickle.dumps(here_sol)  # no module object inside
    assert there_sol.force == here_sol.force and there_sol.topology == here_sol.topology
    np.testing.assert_array_equal(there_sol.profile()["r"], here_sol.profile()["r"])
    np.testing.assert_array_equal(there_curve.force, here_curve.force)
    assert there_curve.scene == scene
    np.testing.assert_array_equal(there_curve.solutions[-1].profile()["z"], here_curve.solutions[-1].profile()["z"])


# -- sweeps ---------------------------------------------------------------------------------------
def test_sb_sweep_stays_the_function_whatever_imported_the_subpackage_first():
    # the subpackage is `sweeps`: importing it (shellbvp.uncertainty does) does not replace sb.sweep
    import subprocess
    import sys

    code = ("import shellbvp as sb, shellbvp.uncertainty, shellbvp.sweeps.layout\n"
            "print(callable(sb.sweep), sb.sweep.__module__)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.stdout.split() == ["True", "shellbvp.sweeps.run"], (r.stdout, r.stderr)


BASE = sb.Scene.preset("base")
GRID = {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}
DELTA_MAX = 0.15
SETTINGS = {"deltas": [0.05, 0.1, 0.15], "estimate_error": False}  # short curves: ~0.5 s each


@pytest.fixture(scope="module")
def serial():
    """The 2x2 grid's curves by plain sb.curve calls in this process, by (beta, rho)."""
    return {(b, r): sb.curve(BASE.replace(beta=b, rho=r), DELTA_MAX, **SETTINGS)
            for b in GRID["beta"] for r in GRID["rho"]}


def _assert_same_curves(result, serial):
    assert result.counts() == {"complete": 4}
    for i, c in result.curves.items():
        key = (result.index["beta"][i], result.index["rho"][i])
        ref = serial[key]
        assert c.scene == ref.scene
        for name in ("delta", "force", "lambda0", "Sc", "energy", "topology"):
            np.testing.assert_array_equal(c.points[name], ref.points[name], err_msg=f"{name} at {key}")


def _spawn_pool(n):
    return ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"))


def test_a_2x2_sweep_on_two_processes_equals_serial_curves(tmp_path, serial):
    from shellbvp.sweeps import read_sweep, sweep

    out = tmp_path / "grid.h5"
    with _spawn_pool(2) as pool:
        res = sweep(BASE, GRID, delta_max=DELTA_MAX, executor=pool, out=out, **SETTINGS)
    assert res.computed == 4
    _assert_same_curves(res, serial)
    back = read_sweep(out)
    _assert_same_curves(back, serial)
    # the gridded arrays: axes (beta, rho, delta); F at the curves' own depths is the curve's F
    assert back.force.shape == (2, 2, back.delta.size) and back.parameters == ("beta", "rho")
    k = int(np.flatnonzero(np.isclose(back.delta, 0.105))[0])  # between two points: interpolated
    ref = serial[(0.01, 0.25)]
    assert ref.force[1] < back.force[1, 1, k] < ref.force[2]
    j = int(np.argmin(abs(back.delta - 0.15)))
    assert back.force[1, 1, j] == pytest.approx(ref.force[2], rel=1e-12)
    assert back.force[0, 0, j] == pytest.approx(serial[(0.005, 0.2)].force[2], rel=1e-12)


def test_every_dataset_of_a_sweep_file_has_units(tmp_path):
    import h5py

    from shellbvp.sweeps import sweep

    out = tmp_path / "one.h5"
    sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, deltas=[0.1], estimate_error=False)
    missing = []
    with h5py.File(out, "r") as f:
        f.visititems(lambda name, obj: missing.append(name) if isinstance(obj, h5py.Dataset)
                     and "units" not in obj.attrs else None)
    assert missing == []


class _CountingPool(ThreadPoolExecutor):
    """One thread (curves one after another), counting the curves submitted to it."""

    def __init__(self):
        super().__init__(max_workers=1)
        self.submitted = 0

    def submit(self, *args, **kwargs):
        self.submitted += 1
        return super().submit(*args, **kwargs)


def _contents(path):
    """Every dataset and attribute of a file, but for the clocks (wall times, dates)."""
    import json

    import h5py

    def attr(v):
        if isinstance(v, str) and v.startswith("{"):
            v = json.loads(v)
            v.pop("wall_time", None)  # a curve's settings record its time
            v.pop("after_last_point_s", None)  # ... and what its stop cost
        return np.asarray(v).tolist() if not isinstance(v, dict) else v

    out = {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            for k, v in obj.attrs.items():
                out[f"{name}@{k}"] = attr(v)
            if isinstance(obj, h5py.Dataset) and not name.endswith("wall_time"):
                out[name] = obj[()].tolist()
        f.visititems(visit)
        out.update({f"/@{k}": np.asarray(v).tolist() for k, v in f.attrs.items() if k not in ("created", "updated")})
    return out


def test_an_interrupted_sweep_resumes_with_only_the_rest(tmp_path, serial):
    from shellbvp.sweeps import read_sweep, sweep

    whole, broken = tmp_path / "whole.h5", tmp_path / "broken.h5"
    sweep(BASE, GRID, delta_max=DELTA_MAX, out=whole, workers=1, **SETTINGS)

    def stop_after_first(rec, done, total):
        raise KeyboardInterrupt  # as Ctrl-C after the first curve was written

    with pytest.raises(KeyboardInterrupt):
        sweep(BASE, GRID, delta_max=DELTA_MAX, out=broken, workers=1, progress=stop_after_first, **SETTINGS)
    assert read_sweep(broken).counts() == {"complete": 1, "pending": 3}
    pool = _CountingPool()
    with pool:
        res = sweep(BASE, GRID, delta_max=DELTA_MAX, out=broken, executor=pool, **SETTINGS)
    assert pool.submitted == 3 and res.computed == 3
    _assert_same_curves(res, serial)
    a, b = _contents(broken), _contents(whole)
    assert sorted(a) == sorted(b)
    np.testing.assert_equal(a, b)  # (NaN equals NaN here)
    again = _CountingPool()
    with again:
        assert sweep(BASE, GRID, delta_max=DELTA_MAX, out=broken, executor=again, **SETTINGS).computed == 0
    assert again.submitted == 0


def test_a_changed_sweep_is_refused_or_extended_when_asked(tmp_path):
    from shellbvp.sweeps import read_sweep, sweep

    out = tmp_path / "g.h5"
    kw = {"deltas": [0.1], "estimate_error": False}
    sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, **kw)
    with pytest.raises(ValueError, match="another grid .*extend"):
        sweep(BASE, {"beta": [0.01, 0.02]}, delta_max=0.1, out=out, workers=1, **kw)
    with pytest.raises(ValueError, match="another curve settings"):
        sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, deltas=[0.1], tol=1e-5)
    with pytest.raises(ValueError, match="another base scene"):
        sweep(BASE.replace(gamma=0.9), {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, **kw)
    with pytest.raises(ValueError, match="parameters of a sweep file cannot change"):
        sweep(BASE, {"rho": [0.2]}, delta_max=0.1, out=out, workers=1, **kw)
    res = sweep(BASE, {"beta": [0.02, 0.01]}, delta_max=0.1, out=out, workers=1, extend=True, **kw)
    assert res.computed == 1 and list(res.values["beta"]) == [0.01, 0.02]
    assert read_sweep(out).counts() == {"complete": 2}
    with pytest.raises(ValueError, match="beta .* must be > 0"):  # restart: refused before the old file goes
        sweep(BASE, {"beta": [-0.01]}, delta_max=0.1, out=out, workers=1, restart=True, **kw)
    assert read_sweep(out).counts() == {"complete": 2}
    res = sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, restart=True, deltas=[0.1], tol=1e-5)
    assert res.computed == 1 and res.settings["tol"] == 1e-5 and res.counts() == {"complete": 1}


@pytest.mark.parametrize("grid, kw, match", [
    ({"mu": [1.0]}, {}, "'mu' is not a parameter"),
    ({"beta": []}, {}, "beta must be a non-empty list"),
    ({"beta": [0.01, 0.01]}, {}, "lists a value twice"),
    ({"beta": [float("nan")]}, {}, "finite"),
    ({"Jm": [1.0]}, {}, "Jm needs a Gent base scene"),
    ({"rho": [0.2, -0.1]}, {}, "grid point rho=-0.1: rho .* must be > 0"),
    ({"gamma": [1.0, 6.0]}, {}, "grid point gamma=6: gamma"),
    ({"beta": [0.01]}, {"delta_max": 50.0}, "grid point beta=0.01: delta_max = 50 is outside"),
    ({"beta": [0.01]}, {"ds": 1}, "unknown curve setting 'ds'"),
])
def test_bad_sweeps_are_refused_before_any_curve(tmp_path, grid, kw, match):
    from shellbvp.sweeps import sweep

    kw = {"delta_max": 0.1, **kw}
    out = tmp_path / "never.h5"
    with pytest.raises(ValueError, match=match):
        sweep(BASE, grid, out=out, workers=1, progress=pytest.fail, **kw)
    assert not out.exists()


def test_the_same_2x2_sweep_on_a_dask_local_cluster(tmp_path, serial):
    distributed = pytest.importorskip("dask.distributed")
    from shellbvp.sweeps import sweep

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        res = sweep(BASE, GRID, delta_max=DELTA_MAX, executor=client.get_executor(), out=tmp_path / "dask.h5",
                    **SETTINGS)
    assert res.computed == 4
    _assert_same_curves(res, serial)


def test_a_dask_cluster_that_goes_away_mid_run_leaves_its_curves_pending(tmp_path, monkeypatch):
    """Futures that never finish on a client that has closed: the sweep stops waiting (issue 42),
    reports them lost and keeps them pending for the next run, instead of hanging."""
    import importlib
    from concurrent.futures import Future

    sw = importlib.import_module("shellbvp.sweeps")
    from shellbvp.sweeps.work import _executor_gone

    class Client:
        status = "closed"  # what a dask Client says once its scheduler is gone for good

    class GoneExecutor:
        _client = Client()

        def submit(self, fn, *args):
            return Future()  # never finishes

    monkeypatch.setattr(OPTIONS, "health_seconds", 0.05)
    res = sw.sweep(BASE, {"beta": [0.005, 0.01]}, delta_max=0.1, executor=GoneExecutor(), out=tmp_path / "g.h5",
                   deltas=[0.1], estimate_error=False)
    assert res.computed == 0 and res.lost == 2 and sw.read_sweep(tmp_path / "g.h5").counts() == {"pending": 2}
    Client.status = "running"  # a live cluster that is merely slow is waited for
    assert not _executor_gone(GoneExecutor())


def test_cli_sweep_and_info(tmp_path, capsys):
    from shellbvp.cli import main

    out = tmp_path / "cli.h5"
    argv = ["sweep", "--beta", "0.005,0.01", "--rho", "0.2:0.25:2", "--delta-max", "0.1", "--points", "2",
            "-o", str(out), "--workers", "1", "-q"]
    assert main(argv[:4] + ["0.2"] + argv[5:]) == 0  # rho = 0.2 only
    assert "2 curves computed" in capsys.readouterr().out
    assert main(argv) == 2 and "--extend" in capsys.readouterr().err
    assert main(argv + ["--extend"]) == 0
    assert "2 curves computed" in capsys.readouterr().out
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "4 combinations: 4 complete" in text and "sweeps:    rho = 0.2, 0.25" in text
    assert main(["sweep", "--beta", "0.01:0.02", "-o", str(tmp_path / "x.h5")]) == 2
    assert "LOW:HIGH:N" in capsys.readouterr().err
    assert main(["sweep", "--beta", "__import__('os')", "-o", str(tmp_path / "x.h5")]) == 2


def test_a_sweep_file_is_nexus_with_f_over_the_grid_and_plots(tmp_path):
    """Root -> sweep (NXentry) -> overview (NXdata): F at delta_max over the swept values, an image
    for two (issue 45, item 4); over the combination number once an extension breaks the product."""
    nx = pytest.importorskip("nexusformat.nexus")
    pytest.importorskip("matplotlib")
    from shellbvp.cli import main
    from shellbvp.sweeps import read_sweep, sweep

    out = tmp_path / "g.h5"
    kw = {"deltas": [0.05, 0.1], "estimate_error": False}
    sweep(BASE, {"beta": [0.005, 0.01], "rho": [0.2, 0.25]}, delta_max=0.1, out=out, workers=1, **kw)
    data = nx.nxload(str(out)).plottable_data
    assert [a.nxname for a in data.nxaxes] == ["beta", "rho"] and data.nxsignal.shape == (2, 2)
    np.testing.assert_allclose(data.nxsignal.nxvalue, read_sweep(out).force[..., -1], rtol=1e-12)
    sweep(BASE, {"beta": [0.005, 0.01], "rho": [0.2, 0.25, 0.3]}, delta_max=0.1, out=out, workers=1, extend=True,
          **kw)
    data = nx.nxload(str(out)).plottable_data
    assert [a.nxname for a in data.nxaxes] == ["combination"] and data.nxsignal.shape == (6,)
    assert main(["plot", str(out), "-o", str(tmp_path / "g.png")]) == 0
    assert (tmp_path / "g.png").stat().st_size > 0


# -- the fit with an uncertain geometry ----------------------------------------------------------
def test_geometry_uncertainty_widens_the_interval_to_the_truth():
    """Data made with rho = 0.35 (mu*H = 52), fitted with the nominal rho = 1/3 +- 0.02: the fit's own
    interval misses 52 (the geometry is off by 0.017), the interval with the geometry's uncertainty
    is wider and contains it."""
    from shellbvp.uncertainty import fit_with_geometry

    R_L, MU_H, D0 = 0.3e-3, 52.0, 0.01e-3
    c = sb.curve(sb.Scene.preset("fit", rho=0.35), deltas=np.linspace(0.02, 0.2, 10), estimate_error=False)
    rng = np.random.default_rng(7)
    disp, force = R_L * c.delta + D0, MU_H * R_L * c.force * (1 + 0.01 * rng.standard_normal(len(c)))
    r = fit_with_geometry(sb.Scene.preset("fit"), disp, force, R_L=R_L, uncertainty={"rho": 0.02}, workers=1,
                          tol=1e-4)
    assert r.success, r.message
    lo, hi = r.mu_H_ci95_fit
    assert not lo < MU_H < hi  # the data's noise alone: a confident, wrong interval
    assert r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1]
    assert r.mu_H_ci95[1] - r.mu_H_ci95[0] > 3 * (hi - lo)
    rho, noise = r.contributions
    # a larger indenter spreads the load: the same force needs a softer shell
    assert rho["sensitivity"] < 0 and rho["mu_H_plus"] < r.mu_H < rho["mu_H_minus"]
    assert rho["share"] + noise["share"] == pytest.approx(1.0)
    assert r.fits_computed == 3


def test_geometry_uncertainty_on_the_example_is_not_failed_by_the_weights_check():
    """The shipped example with gamma 2.5 +- 0.2: the fits at gamma +- u follow the data less well
    (their weightings disagree: status 6 when checked); they give mu*H's sensitivity, and the
    interval with the geometry's uncertainty is finite (it was NaN)."""
    from shellbvp.fitting import example_data_path
    from shellbvp.uncertainty import fit_with_geometry

    d, F = sb.read_force_csv(example_data_path())
    r = fit_with_geometry(sb.Scene.preset("fit"), d, F, R_L=0.3e-3, uncertainty={"gamma": 0.2}, workers=1)
    assert r.success, r.message
    assert r.nominal.weights_check["agree"]
    assert r.mu_H_ci95[0] < r.mu_H_ci95_fit[0] < r.mu_H < r.mu_H_ci95_fit[1] < r.mu_H_ci95[1]
    assert not sb.fit(sb.Scene.preset("fit", gamma=2.7), d, F, R_L=0.3e-3).success   # checked: status 6


@pytest.mark.parametrize("text, value", [("2.5+-0.2", (2.5, 0.2)), ("2.5 ± 0.2", (2.5, 0.2)),
                                         ("2.5+/-0.2", (2.5, 0.2)), ("0.01", (0.01, None))])
def test_plus_minus_is_parsed_without_evaluation(text, value):
    from shellbvp.uncertainty import parse_uncertain

    assert parse_uncertain(text) == value


@pytest.mark.parametrize("text", ["2.5+-", "2.5+-0", "2.5+--0.1", "2.5+-0.1+-0.1", "__import__('os')+-1",
                                  "2.5+-1e999", "2.5+-nan", "0.2*2+-0.1"])
def test_bad_plus_minus_is_refused(text):
    from shellbvp.uncertainty import parse_uncertain

    with pytest.raises(ValueError):
        parse_uncertain(text, "--gamma")


@pytest.mark.parametrize("uncertainty, kw, match", [
    ({"mu": 0.1}, {}, "'mu' is not a scene parameter"),
    ({"rho": 0.0}, {}, "uncertainty > 0"),
    ({"gamma": 1.0}, {}, r"gamma = 2.5 \+ 1 is not valid"),
    ({"beta": 0.005}, {"fit_beta": True}, "beta is fitted"),
    ({}, {}, "non-empty mapping"),
])
def test_bad_uncertainties_are_refused_before_any_fit(uncertainty, kw, match):
    from shellbvp.uncertainty import fit_with_geometry

    d = np.linspace(1e-5, 1e-4, 10)
    with pytest.raises(ValueError, match=match):
        fit_with_geometry(sb.Scene.preset("fit"), d, d, R_L=0.3e-3, uncertainty=uncertainty, workers=1, **kw)


@pytest.mark.parametrize("argv, match", [
    (["--rho", "0.333+-0"], "must be > 0"),
    (["--gamma", "2.5+-x"], "plain finite number"),
    (["--beta", "0.01+-0.005", "--fit-beta"], "beta is fitted"),
    (["--workers", "2"], "give a parameter as VALUE[+]-U"),
])
def test_fit_cli_uncertainty_errors(argv, match, capsys):
    import re

    from shellbvp.cli import main

    try:
        status = main(["fit", "--example", "--preset", "fit", "--radius", "0.3mm", *argv])
    except SystemExit as exc:  # argparse's own exit for a value its type refused
        status = exc.code
    assert status == 2
    assert re.search(match, capsys.readouterr().err)


def test_a_second_sweep_on_the_same_file_is_refused_while_one_runs(tmp_path):
    fcntl = pytest.importorskip("fcntl")
    from shellbvp.sweeps import sweep

    out = tmp_path / "g.h5"
    with open(tmp_path / "g.h5.lock", "a+") as held:  # as a running sweep holds it
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(ValueError, match="being written by another sweep"):
            sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, deltas=[0.1])
    assert not out.exists()
    (tmp_path / ".g.h5.abc.tmp").write_text("debris of a killed writer")
    res = sweep(BASE, {"beta": [0.01]}, delta_max=0.1, out=out, workers=1, deltas=[0.1], estimate_error=False)
    assert res.computed == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.h5"]  # no lock, no debris left
