"""Fitting mu*H to measured data, units, CSV input (issue: fitting)."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import shellbvp as sb

R_L, MU_H, D0 = 0.3e-3, 52.0, 0.01e-3  # Lepidium-like: 0.3 mm rim, 52 um*MPa


@pytest.fixture(scope="module")
def model():
    scene = sb.Scene.preset("fit")
    return scene, sb.curve(scene, deltas=np.linspace(0.01, 0.45, 80), estimate_error=False)


def synthetic(model, n, seed):
    scene, c = model
    idx = np.linspace(0, len(c) - 1, n).astype(int)
    rng = np.random.default_rng(seed)
    disp = R_L * c.delta[idx] + D0
    force = MU_H * R_L * c.force[idx] * (1 + 0.02 * rng.standard_normal(n))
    return disp, force


def test_fit_recovers_mu_H_and_offset_within_interval_and_2_percent(model):
    disp, force = synthetic(model, 40, seed=3)
    r = sb.fit(model[0], disp, force, R_L=R_L)
    assert r.success
    lo, hi = r.mu_H_ci95
    assert lo < MU_H < hi, (r.mu_H, r.mu_H_ci95)
    assert abs(r.mu_H - MU_H) < 0.02 * MU_H
    assert r.offset_ci95[0] < D0 < r.offset_ci95[1]


def test_interval_shrinks_with_more_data(model):
    widths = []
    for n in (10, 80):
        r = sb.fit(model[0], *synthetic(model, n, seed=n), R_L=R_L)
        widths.append(r.mu_H_ci95[1] - r.mu_H_ci95[0])
    assert widths[1] < 0.7 * widths[0], widths


def test_dimensional_round_trip_and_units():
    dim = sb.Dimensions(R_L=0.3e-3, mu_H=52.0)
    delta, F = 0.237, 0.8123
    assert dim.delta(dim.displacement(delta)) == pytest.approx(delta, rel=1e-15)
    assert dim.F(dim.force(F)) == pytest.approx(F, rel=1e-15)
    assert dim.force(1.0) == pytest.approx(52.0 * 0.3e-3)  # N = (N/m) * m
    assert sb.parse_quantity("0.3mm") == pytest.approx(3e-4)
    assert sb.parse_quantity("2 mN", "force") == pytest.approx(2e-3)
    assert sb.parse_quantity(5, "length", default_unit="um") == pytest.approx(5e-6)
    assert sb.beta_from_thickness(50e-6, 0.3e-3) == pytest.approx((50 / 300) ** 2 / 12)
    with pytest.raises(ValueError, match="unit"):
        sb.parse_quantity("3 furlongs")
    with pytest.raises(ValueError, match="R_L"):
        sb.Dimensions(R_L=-1.0)


def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_csv_formats(tmp_path):
    rows = [(0.03, 0.5), (0.01, 0.1), (0.02, 0.3), (0.02, 0.31)]  # descending/repeated order
    body = "\n".join(f"{a};{b}" for a, b in rows)
    p = _write(tmp_path, "semi.csv", "Displacement (mm);Force (mN)\n" + body + "\n;\nnan;1\n")
    d, f = sb.read_force_csv(p)
    np.testing.assert_allclose(d, [1e-5, 2e-5, 2e-5, 3e-5])
    assert f[0] == pytest.approx(1e-4)
    p = _write(tmp_path, "tab.csv", "\n".join(f"{b}\t{a}" for a, b in rows))
    d, f = sb.read_force_csv(p, columns=[1, 0], units=("mm", "mN"))
    assert d.size == 4 and d[-1] == pytest.approx(3e-5)
    p = _write(tmp_path, "named.csv", "time,force [uN],disp [um]\n" + "\n".join(f"0,{b},{a}" for a, b in rows))
    d, f = sb.read_force_csv(p, columns=["disp", "force"])
    assert d[-1] == pytest.approx(3e-8) and f[-1] == pytest.approx(5e-7)


@pytest.mark.parametrize("text,kwargs,match", [
    ("a,b\n1,2\n3,x\n4,5\n", dict(units=("mm", "mN")), "line 3"),
    ("1,2\n3,4\n5,6\n", {}, "units"),
    ("d (mm),F (mN)\n1,2\n3\n4,5\n", {}, "line 3"),
    ("d (mm),F (mN)\n1,2\n", {}, "fewer than 3"),
    ("d (mm),F (mN)\n1,2\n2,3\n3,4\n", dict(columns=["depth", "F"]), "no column named"),
    ("d (furlong),F (mN)\n1,2\n2,3\n3,4\n", {}, "unknown length unit"),
])
def test_malformed_csv_messages(tmp_path, text, kwargs, match):
    p = _write(tmp_path, "bad.csv", text)
    with pytest.raises(ValueError, match=match):
        sb.read_force_csv(p, **kwargs)


def test_fit_cli_with_csv(model, tmp_path):
    disp, force = synthetic(model, 30, seed=5)
    p = _write(tmp_path, "data.csv", "displacement (mm),force (mN)\n"
               + "\n".join(f"{a * 1e3:.8g},{b * 1e3:.8g}" for a, b in zip(disp, force)))
    r = subprocess.run([sys.executable, "-m", "shellbvp", "fit", str(p), "--preset", "fit", "--radius", "0.3mm",
                        "--json", "-o", str(tmp_path / "fit.h5")], capture_output=True, text=True,
                       env=dict(os.environ), timeout=600)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert abs(out["mu_H"] - MU_H) < 0.02 * MU_H and out["mu_H_ci95"][0] < out["mu_H"] < out["mu_H_ci95"][1]
    assert sb.read_curve(tmp_path / "fit.h5").scene == sb.Scene.preset("fit")


def test_plots_headless_produce_png(model, tmp_path):
    pytest.importorskip("matplotlib")
    from shellbvp.plotting import plot_fit, require_matplotlib

    scene, c = model
    c.to_hdf5(tmp_path / "m.h5")
    out = tmp_path / "fig.png"
    r = subprocess.run([sys.executable, "-m", "shellbvp", "plot", str(tmp_path / "m.h5"), "-o", str(out),
                        "--profiles", "0.1,0.3"], capture_output=True, text=True, env=dict(os.environ),
                       timeout=600)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 10_000 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    disp, force = synthetic(model, 30, seed=9)
    res = sb.fit(scene, disp, force, R_L=R_L)
    plt = require_matplotlib()
    ax = plot_fit(res, disp, force)
    ax.figure.savefig(tmp_path / "fit.png")
    plt.close("all")
    assert (tmp_path / "fit.png").stat().st_size > 10_000


def test_fit_example_shipped_with_the_package():
    r = subprocess.run([sys.executable, "-m", "shellbvp", "fit", "--example", "--preset", "fit", "--radius",
                        "0.3mm", "--json"], capture_output=True, text=True, env=dict(os.environ), timeout=600)
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["mu_H_ci95"][0] < 52.0 < out["mu_H_ci95"][1]
    assert abs(out["offset"] - 10e-6) < 1e-6
