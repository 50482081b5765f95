"""Fitting mu*H to measured data, units, CSV input (issue: fitting)."""

import json

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


def test_noise_models_under_proportional_noise(model):
    """2 % proportional noise: mixed and relative weights cover 52 with a narrower interval than uniform."""
    disp, force = synthetic(model, 40, seed=3)
    width = {}
    for w in ("uniform", "relative", "mixed"):
        r = sb.fit(model[0], disp, force, R_L=R_L, weights=w)
        assert r.weights == w and r.success
        assert r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1], (w, r.mu_H, r.mu_H_ci95)
        width[w] = r.mu_H_ci95[1] - r.mu_H_ci95[0]
    assert width["mixed"] < 0.8 * width["uniform"] and width["relative"] < 0.8 * width["uniform"], width
    assert sb.fit(model[0], disp, force, R_L=R_L).weights == sb.fitting.DEFAULT_WEIGHTS == "mixed"


def test_mixed_weights_follow_additive_noise(model):
    """Additive noise: the mixed model's weights come out nearly uniform, the relative model's do not."""
    scene, c = model
    idx = np.linspace(0, len(c) - 1, 40).astype(int)
    F = MU_H * R_L * c.force[idx]
    rng = np.random.default_rng(11)
    force = F + 0.02 * F.max() * rng.standard_normal(F.size)
    disp = R_L * c.delta[idx] + D0
    fits = {w: sb.fit(scene, disp, force, R_L=R_L, weights=w) for w in ("uniform", "mixed")}
    lo, hi = fits["mixed"].mu_H_ci95
    assert lo < MU_H < hi
    wu, wm = (fits[w].mu_H_ci95[1] - fits[w].mu_H_ci95[0] for w in ("uniform", "mixed"))
    assert abs(wm / wu - 1) < 0.25, (wu, wm)


def test_fit_shape_parameter_options_are_validated():
    scene = sb.Scene.preset("fit")
    d, f = np.linspace(1e-5, 1e-4, 10), np.linspace(1e-4, 1e-3, 10)
    cases = [
        (dict(fit_beta=True, fit_alpha=True), "one of beta, alpha"),
        (dict(fit_beta=True, beta_bounds=(0.0, 1.0)), "beta_bounds"),
        (dict(fit_beta=True, beta_bounds=(1e-3, 5e-3)), r"scene's beta = 0\.01"),
        (dict(fit_beta=True, beta_bounds="wide"), "beta_bounds"),
        (dict(fit_alpha=True, alpha_bounds=(0.2, 1.5)), "alpha_bounds"),
        (dict(fit_alpha=True, alpha_bounds=(0.5, 1.0)), r"scene's alpha = 0\.1"),
        (dict(weights="poisson"), "weights must be one of"),
        (dict(floor=0.0), "floor"),
    ]
    for kwargs, match in cases:
        with pytest.raises(ValueError, match=match):
            sb.fit(scene, d, f, R_L=R_L, **kwargs)
    with pytest.raises(ValueError, match="fit_alpha needs a Mooney-Rivlin material"):
        sb.fit(scene.replace(material=sb.Gent(1.0)), d, f, R_L=R_L, fit_alpha=True)
    with pytest.raises(ValueError, match="at least 5"):
        sb.fit(scene, d[:4], f[:4], R_L=R_L, fit_beta=True)


@pytest.mark.parametrize("argv,match", [
    (["--fit-beta", "--fit-alpha"], "one of beta, alpha"),
    (["--beta-range", "1e-3,0.1"], "--beta-range needs --fit-beta"),
    (["--fit-beta", "--beta-range", "1e-3"], "--beta-range must be two numbers"),
    (["--fit-alpha", "--gent-jm", "1"], "Mooney-Rivlin"),
    (["--weights", "poisson"], "invalid choice"),
])
def test_fit_cli_shape_options_errors(cli_main, argv, match):
    r = cli_main("fit", "--example", "--preset", "fit", "--radius", "0.3mm", *argv)  # in this process
    assert r.returncode == 2 and match in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


class _FakeCurve:
    """A model curve of closed form whose shape depends on beta and alpha (fast tests of the fit logic)."""

    def __init__(self, scene, deltas):
        self.scene, self.delta = scene, np.asarray(deltas, float)
        b, a = scene.beta, scene.material.alpha
        self.force = self.delta ** (1.3 + 20 * b - 0.4 * a) * (1 + b)
        self.stop_reason, self.solutions = "closed form", []

    def __len__(self):
        return self.delta.size


@pytest.mark.parametrize("name,truth,start", [("beta", 0.02, 0.01), ("alpha", 0.6, 0.1)])
def test_fit_shape_parameter_logic_on_closed_form_curves(monkeypatch, name, truth, start):
    """Nodes, interpolation across them, profile interval: recovers the parameter of a known curve family."""
    calls = []

    def fake(scene, deltas, tol, counter=None, progress=None):
        calls.append(scene)
        if counter is not None:
            counter[0] += 1
        return _FakeCurve(scene, deltas)

    monkeypatch.setattr(sb.fitting.curves, "_model_curve", fake)
    mat = (lambda a: sb.MooneyRivlin(a))
    scene0 = sb.Scene.preset("fit", **({"beta": start} if name == "beta" else {"material": mat(start)}))
    true_scene = scene0.replace(**({"beta": truth} if name == "beta" else {"material": mat(truth)}))
    x = np.linspace(0.01, 0.4, 40)
    rng = np.random.default_rng(0)
    force = MU_H * R_L * _FakeCurve(true_scene, x).force * (1 + 0.02 * rng.standard_normal(x.size))
    r = sb.fit(scene0, R_L * x + D0, force, R_L=R_L, **{f"fit_{name}": True})
    lo, hi = getattr(r, name + "_ci95")
    assert lo < truth < hi and hi - lo < 0.5 * truth, (getattr(r, name), lo, hi)
    assert r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1] and r.offset_ci95[0] < D0 < r.offset_ci95[1]
    assert r.fitted == ("mu_H", "offset", name) and r.success
    assert r.curves_computed == len(calls) <= 8 and r.interpolation_error < 1e-3
    fitted_value = r.scene.beta if name == "beta" else r.scene.material.alpha
    assert fitted_value == pytest.approx(getattr(r, name), rel=1e-9)  # the reported curve is the fitted one
    # the data decide: a clearly wrong value lies outside the interval
    assert not lo < start < hi


@pytest.mark.slow
def test_fit_beta_recovers_known_beta_within_interval():
    """Data at beta = 0.02 (preset fit, 2 % proportional noise); the fit starts from the preset's 0.01."""
    truth = sb.Scene.preset("fit", beta=0.02)
    c = sb.curve(truth, deltas=np.linspace(0.01, 0.45, 40), estimate_error=False)
    rng = np.random.default_rng(3)
    disp = R_L * c.delta + D0
    force = MU_H * R_L * c.force * (1 + 0.02 * rng.standard_normal(len(c)))
    r = sb.fit(sb.Scene.preset("fit"), disp, force, R_L=R_L, fit_beta=True)
    assert r.success and r.fitted == ("mu_H", "offset", "beta")
    assert r.beta_ci95[0] < 0.02 < r.beta_ci95[1], (r.beta, r.beta_ci95)
    assert r.beta_ci95[0] > 0.01 / 4 and r.beta_ci95[1] < 0.04, r.beta_ci95  # informative, not the search range
    assert r.mu_H_ci95[0] < MU_H < r.mu_H_ci95[1], (r.mu_H, r.mu_H_ci95)
    assert r.offset_ci95[0] < D0 < r.offset_ci95[1]
    assert r.interpolation_error < 2e-3 and r.curves_computed <= 6
    assert r.curve.scene.beta == pytest.approx(r.beta, rel=1e-3) and r.scene == r.curve.scene
    # beta fitted widens mu*H's interval against the fit at the (wrong) start value 0.01
    fixed = sb.fit(sb.Scene.preset("fit"), disp, force, R_L=R_L)
    assert fixed.mu_H_ci95[1] - fixed.mu_H_ci95[0] < r.mu_H_ci95[1] - r.mu_H_ci95[0]


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
    assert sb.beta_from_thickness(50e-6, 0.3e-3) == pytest.approx((50 / 300) ** 2 / 3)
    with pytest.raises(ValueError, match="unit"):
        sb.parse_quantity("3 blorps")
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
    ("d (blorp),F (mN)\n1,2\n2,3\n3,4\n", {}, "unknown length unit"),
])
def test_malformed_csv_messages(tmp_path, text, kwargs, match):
    p = _write(tmp_path, "bad.csv", text)
    with pytest.raises(ValueError, match=match):
        sb.read_force_csv(p, **kwargs)


def test_fit_cli_with_csv(model, tmp_path, cli_main):
    disp, force = synthetic(model, 30, seed=5)
    p = _write(tmp_path, "data.csv", "displacement (mm),force (mN)\n"
               + "\n".join(f"{a * 1e3:.8g},{b * 1e3:.8g}" for a, b in zip(disp, force)))
    r = cli_main("fit", str(p), "--preset", "fit", "--radius", "0.3mm", "--json", "-o", str(tmp_path / "fit.h5"))
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert abs(out["mu_H"] - MU_H) < 0.02 * MU_H and out["mu_H_ci95"][0] < out["mu_H"] < out["mu_H_ci95"][1]
    assert out["residual"] > 0 and out["offset"] > 0 and out["weights"] == "mixed"
    assert out["beta"] == 0.01 and out["beta_ci95"] is None and out["alpha"] == pytest.approx(0.1)
    assert out["fitted"] == ["mu_H", "offset"]
    from shellbvp.fitrecord import read_fit

    rec = read_fit(tmp_path / "fit.h5")
    assert rec.scene == sb.Scene.preset("fit") and rec.parameters["mu_H"] == pytest.approx(out["mu_H"], rel=1e-12)


def test_plots_headless_produce_png(model, tmp_path, cli_main):
    pytest.importorskip("matplotlib")
    from shellbvp.plotting import plot_fit, require_matplotlib

    scene, c = model
    c.to_hdf5(tmp_path / "m.h5")
    out = tmp_path / "fig.png"
    r = cli_main("plot", str(tmp_path / "m.h5"), "-o", str(out), "--profiles", "0.1,0.3")  # in this process
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 10_000 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    disp, force = synthetic(model, 30, seed=9)
    res = sb.fit(scene, disp, force, R_L=R_L)
    plt = require_matplotlib()
    ax = plot_fit(res, disp, force)
    ax.figure.savefig(tmp_path / "fit.png")
    plt.close("all")
    assert (tmp_path / "fit.png").stat().st_size > 10_000


def test_fit_example_shipped_with_the_package(cli_main):
    r = cli_main("fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--json")  # in this process
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["mu_H_ci95"][0] < 52.0 < out["mu_H_ci95"][1]
    assert abs(out["offset"] - 10e-6) < 1e-6


def test_model_force_at_another_mu_h_scales_the_shell_force_only(monkeypatch):
    """FitResult.model_force(x, mu_H=...) (the band of plot_fit): the shell's force scales with
    mu*H, the fitted offset and baseline stay."""
    def fake(scene, deltas, tol, counter=None, progress=None):
        if counter is not None:
            counter[0] += 1
        return _FakeCurve(scene, deltas)

    import shellbvp.fitting.curves

    monkeypatch.setattr(shellbvp.fitting.curves, "_model_curve", fake)
    scene = sb.Scene.preset("fit")
    x = np.linspace(-0.05, 0.4, 46)
    rng = np.random.default_rng(2)
    shell = MU_H * R_L * np.where(x > 0, _FakeCurve(scene, np.clip(x, 1e-9, None)).force, 0.0)
    force = shell * (1 + 0.02 * rng.standard_normal(x.size)) + 3e-6
    r = sb.fit(scene, R_L * x + D0, force, R_L=R_L, baseline="constant", contact_guess=D0)
    d = R_L * np.linspace(0.0, 0.35, 20) + r.offset
    base = r.baseline
    assert base != 0.0 and r.success, r.message
    np.testing.assert_allclose(r.model_force(d, mu_H=2 * r.mu_H) - base, 2 * (r.model_force(d) - base), rtol=1e-12)
    np.testing.assert_array_equal(r.model_force(d, mu_H=r.mu_H), r.model_force(d))
