"""Sweeps (shellbvp.sweep): results that travel between processes, the resumable sweep file,
executors (a process pool, Dask), and the fit with an uncertain geometry."""

import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import shellbvp as sb


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
