"""A force map's pixels fitted together on their shared model curve (issue 56, maps at
instrument scale): the same values, intervals, checks, warnings and statuses as one
``fit_record`` per curve, a pixel that fails its checks and one that cannot be fitted included;
the map keeps no curve's rows."""

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.afm import curves_from_afm
from shellbvp.batch import fit_map
from shellbvp.fitting import fit_record
from shellbvp.fitting.batched import SharedShape, batchable, fit_batch
from shellbvp.fitting.least_squares import LeastSquaresModel
from shellbvp.map_fit import RowStore, pixel_delta_max, read_pixels

afmformats = pytest.importorskip("afmformats")
from afmformats.mod_force_distance import AFMForceDistance  # noqa: E402

R_L, K = 10e-6, 0.05
#: The tolerance the batched fits keep to one scipy fit each (measured: 1e-9 and below on mu*H
#: and its interval, 1e-9 on the weights check's refit; scipy stops at a cost change of 1e-8)
RTOL = 1e-6


@pytest.fixture(scope="module")
def cells():
    """Nine curves of a map: seven of the model at mu*H 30..90 mN/m with 1 % noise (one with a
    tilted baseline), one whose shape is not the model's (the square root of its force: the
    fit fails its checks) and one without any response (an error row)."""
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.005, 0.4, 160), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])
    contact, top = 0.3e-6, 0.3e-6 + 0.35 * R_L
    depth = np.r_[np.linspace(0, top, 200), np.linspace(top, 0, 200)]
    rng = np.random.default_rng(11)
    datasets = []
    for i in range(9):
        x = np.clip((depth - contact) / R_L, 0, 0.4)
        mu = (30.0 + 7.5 * i) * 1e-3
        force = mu * R_L * shape(x) * (1 + 0.01 * rng.standard_normal(depth.size))
        if i == 3:
            force = force + 2e-9 * depth / top + 1e-11 * rng.standard_normal(depth.size)
        if i == 7:  # not the model's shape
            force = np.sqrt(mu * R_L * shape(x) * 1e-7) * (1 + 0.01 * rng.standard_normal(depth.size))
        if i == 8:  # no response: refused before any fit
            force = 1e-12 * rng.standard_normal(depth.size)
        data = {"force": force, "height (measured)": 5e-6 - depth - force / K,
                "segment": np.r_[np.zeros(200, bool), np.ones(200, bool)], "time": 0.01 * np.arange(depth.size)}
        md = {"spring constant": K, "grid index x": i % 3, "grid index y": i // 3, "grid shape x": 3,
              "grid shape y": 3, "enum": i, "path": "cells.jpk-force-map", "imaging mode": "force-distance"}
        datasets.append(AFMForceDistance(data, md))
    return scene, curves_from_afm(datasets, "cells.jpk-force-map", sha256="0" * 64)


def one_by_one(scene, curves):
    """fit_record of each curve with the map's common model curve (as fit_records sets it)."""
    pixels, store = read_pixels(curves, "cells.jpk-force-map", R_L=R_L)
    store.close()
    out = []
    for c, dm in zip(curves, pixel_delta_max(pixels)):
        try:
            out.append(fit_record(scene, c.record, R_L=R_L, delta_max=dm)[0])
        except ValueError as exc:
            out.append(exc)
    return out


def test_pixels_fitted_together_are_the_fits_one_by_one(cells):
    scene, curves = cells
    single = one_by_one(scene, curves)
    fm = fit_map(scene, curves, R_L=R_L, path="cells.jpk-force-map")
    statuses = [r.status for r in fm.rows]
    assert statuses.count("ok") >= 6 and "failed" in statuses and statuses[8] == "error", statuses
    for row, one in zip(fm.rows, single):
        if isinstance(one, Exception):
            assert row.status == "error" and row.message == " ".join(str(one).split())
            continue
        res = row.result
        assert (row.status == "ok") == one.success and res.status == one.status, (res.message, one.message)
        assert res.warning_codes == one.warning_codes and res.quality == one.quality
        assert res.message.split(" (least squares:")[0] == one.message.split(" (least squares:")[0]
        for a, b in ((res.mu_H, one.mu_H), (res.offset, one.offset), (res.baseline, one.baseline)):
            assert a == pytest.approx(b, rel=RTOL, abs=RTOL * 1e-9)
        np.testing.assert_allclose(res.mu_H_ci95, one.mu_H_ci95, rtol=RTOL)
        np.testing.assert_allclose(res.offset_ci95, one.offset_ci95, rtol=RTOL, atol=RTOL * R_L)
        assert res.weights_check["agree"] == one.weights_check["agree"]
        np.testing.assert_allclose(res.weights_check["mu_H_ci95"], one.weights_check["mu_H_ci95"], rtol=RTOL)
        assert res.residual_rms == pytest.approx(one.residual_rms, rel=RTOL)
        assert res.n == one.n and res.fitted == one.fitted and res.model_note == one.model_note
    failed = [r.result for r in fm.rows if r.status == "failed"]
    assert failed and all(r.status != 0 and r.warning_codes for r in failed)


def test_a_map_keeps_no_curve_and_no_per_point_array(cells):
    scene, curves = cells
    fm = fit_map(scene, iter(curves), R_L=R_L, path="cells.jpk-force-map")  # taken once, one at a time
    assert all(c.record is None for c in fm.curves) and all(r.record is None and r.used is None for r in fm.rows)
    assert all(r.result is None or r.result.point_weights is None for r in fm.rows)
    assert fm.sha256 == "0" * 64 and fm.rows[0].table_row("loading")["sha256"] == "0" * 64


def test_what_a_batch_takes_and_what_it_leaves_to_one_fit_each():
    scene = sb.Scene.preset("fit")
    cli = {"fit_offset": True, "free": (), "bounds": {}, "weights": None, "tol": 1e-6, "stability": False,
           "model": "auto", "mesh_check": False, "max_depth": None, "max_force": None, "weights_check": True}
    assert batchable(scene, cli)
    assert not batchable(scene, dict(cli, free=("beta",)))
    assert not batchable(scene, dict(cli, stability=True))
    assert not batchable(scene, dict(cli, loss="soft_l1"))
    assert not batchable(scene, dict(cli, shared=object()))
    with pytest.raises(ValueError, match="one pixel at a time"):
        fit_batch(scene, [], R_L=R_L, free=("beta",))


def test_the_shared_shape_is_the_fits_own():
    """SharedShape evaluates the PCHIP and its slope as LeastSquaresModel.shape and the Jacobian do:
    0 before contact, NaN beyond the curve."""
    x = np.linspace(0, 0.42, 41)
    P = PchipInterpolator(x, x ** 1.5 + x ** 2, extrapolate=False)
    X = np.r_[-0.1, 0.0, x, np.linspace(0, 0.42, 997), 0.42 + 1e-12, 0.5]
    value, slope = SharedShape(P, 0.42)(X, slope=True)
    expected = LeastSquaresModel.shape(P, 0.42, X)
    np.testing.assert_array_equal(np.isnan(value), np.isnan(expected))
    np.testing.assert_allclose(value[~np.isnan(value)], expected[~np.isnan(expected)], rtol=1e-13, atol=1e-16)
    inside = (X > 0) & (X <= 0.42)
    np.testing.assert_allclose(slope[inside], P.derivative()(X[inside]), rtol=1e-12, atol=1e-14)
    assert np.all(slope[~inside] == 0)


def test_the_row_store_gives_back_what_it_kept():
    store = RowStore()
    a = store.add(np.arange(3.0), np.arange(3.0) * 2)
    b = store.add(np.linspace(0, 1, 500), np.ones(500))
    d, f = store.get(a)
    np.testing.assert_array_equal(d, [0, 1, 2]) and np.testing.assert_array_equal(f, [0, 2, 4])
    d, f = store.get(b)
    assert d.size == 500 and d[-1] == 1.0 and np.all(f == 1)
    store.close()
