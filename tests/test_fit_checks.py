"""A fit must not report success on data it cannot explain (issue 11, sections 2 and 4 (CSV)).

One test per defect input of the issue: each gets a clear error (ValueError before any
model curve where possible; CLI exit 2), a failed status (exit 1) or a warning.
"""

import json
import os
import subprocess
import sys

import h5py
import numpy as np
import pytest

import shellbvp as sb
from shellbvp import fitting

R_L, MU_H, D0 = 0.3e-3, 52.0, 0.01e-3
N = 40


@pytest.fixture(scope="module")
def good():
    """Data of the preset fit (2 % proportional noise) on a fixed set of depths: every fit below
    on these depths reuses one model curve."""
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.01, 0.45, 80), estimate_error=False)
    idx = np.linspace(0, len(c) - 1, N).astype(int)
    F = MU_H * R_L * c.force[idx]
    disp = R_L * c.delta[idx] + D0
    rng = np.random.default_rng(7)
    return scene, disp, F, F * (1 + 0.02 * rng.standard_normal(N))


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True, cwd=cwd,
                          env=dict(os.environ), timeout=600)


def write_csv(path, disp, force, header="displacement (mm),force (mN)"):
    path.write_text(header + "\n" + "\n".join(f"{a * 1e3:.9g},{b * 1e3:.9g}" for a, b in zip(disp, force)) + "\n")
    return path


# -- the good case: success, no spurious warning --------------------------------------------------
def test_good_data_succeed_without_warnings(good):
    scene, disp, F, force = good
    r = sb.fit(scene, disp, force, R_L=R_L)
    assert r.status == 0 and r.success and r.warnings == [] and r.warning_codes == []
    assert abs(r.mu_H - MU_H) < 0.02 * MU_H and r.mu_H_ci95[1] - r.mu_H_ci95[0] < 0.1 * MU_H
    out = r.to_dict()
    assert out["status"] == 0 and out["success"] is True and out["warnings"] == []
    assert fitting.FIT_STATUS[0] in out["message"]


def test_runs_test_on_known_sequences():
    runs, p = fitting.runs_test([1, -1] * 10)  # alternating: as many runs as possible
    assert runs == 20 and p > 0.99
    runs, p = fitting.runs_test([1] * 10 + [-1] * 10)  # two runs
    assert runs == 2 and p < 1e-4
    # independent signs: the p-value is about uniform (fraction below 0.05 near 0.05)
    rng = np.random.default_rng(0)
    ps = np.array([fitting.runs_test(rng.standard_normal(40))[1] for _ in range(2000)])
    assert 0.02 < np.mean(ps < 0.05) < 0.08, np.mean(ps < 0.05)


# -- checks before fitting: ValueError before any model curve ------------------------------------
@pytest.fixture
def no_model_curves(monkeypatch):
    """Any model curve computed fails the test: these checks must come first."""
    def forbidden(*a, **k):
        raise AssertionError("a model curve was computed before the data were checked")

    monkeypatch.setattr(fitting.curves, "_model_curve", forbidden)


def test_pure_noise_is_an_error(good, no_model_curves):
    scene, disp, F, _ = good
    noise = np.abs(np.random.default_rng(1).normal(0.5e-3, 0.3e-3, N))
    with pytest.raises(ValueError, match="force does not increase with displacement"):
        sb.fit(scene, disp, noise, R_L=R_L)


def test_constant_force_is_an_error(good, no_model_curves):
    scene, disp, F, _ = good
    with pytest.raises(ValueError, match="force is constant"):
        sb.fit(scene, disp, np.full(N, 1e-3), R_L=R_L)


def test_decreasing_force_is_an_error_that_names_the_remedy(good, no_model_curves):
    scene, disp, F, force = good
    with pytest.raises(ValueError, match=r"falls as the displacement grows.*-1\.00.*--invert displacement"):
        sb.fit(scene, disp, force[::-1], R_L=R_L)
    rng = np.random.default_rng(3)
    with pytest.raises(ValueError, match=r"does not increase"):   # no trend either way
        sb.fit(scene, disp, rng.permutation(force), R_L=R_L)


def test_all_displacements_equal_is_an_error(good, no_model_curves):
    scene, disp, F, force = good
    with pytest.raises(ValueError, match="at least 4 distinct values.*got 1"):
        sb.fit(scene, np.full(N, 5e-5), force, R_L=R_L)


def test_a_single_repeated_point_is_an_error(good, no_model_curves):
    scene = good[0]
    with pytest.raises(ValueError, match="distinct values.*got 1"):
        sb.fit(scene, np.full(N, 5e-5), np.full(N, 1e-3), R_L=R_L)
    # three distinct depths do not carry mu*H, the offset and beta (5 needed)
    d = np.repeat([2e-5, 4e-5, 6e-5], 4)
    with pytest.raises(ValueError, match="at least 5 distinct values to fit 3 parameters; got 3"):
        sb.fit(scene, d, d * 10, R_L=R_L, fit_beta=True)


def test_infinite_values_are_an_error(good, no_model_curves):
    scene, disp, F, force = good
    bad = force.copy()
    bad[3] = np.inf
    with pytest.raises(ValueError, match="force must be finite; got inf at index 3"):
        sb.fit(scene, disp, bad, R_L=R_L)
    nan = force.copy()
    nan[3] = np.nan  # a missing value is dropped, not an error (documented)
    assert fitting.fit_data._check_data(disp, nan, 2)[0].size == N - 1


@pytest.mark.slow  # the model curve is computed before the depths are compared (~25 s)
def test_data_shallower_than_the_model_starts(good):
    """nm-scale data against a 0.3 mm rim (or a radius too large): a clear error, not an IndexError."""
    scene, disp, F, force = good
    with pytest.raises(ValueError, match="cannot start at its shallowest depth.*point-load limit"):
        sb.fit(scene, disp * 1e-3, force * 1e-3, R_L=R_L)


def test_data_deeper_than_the_model_reaches(good, monkeypatch):
    """A model curve that ends (here: a closed-form one, stopped at delta = 0.2) before the data."""
    class Short:
        def __init__(self, scene, deltas):
            keep = np.asarray(deltas) <= 0.2
            self.delta = np.asarray(deltas)[keep]
            self.force = 3 * self.delta ** 1.5
            self.stop_reason, self.solutions, self.scene = "the contact reached the end of the tip", [], scene

        def __len__(self):
            return self.delta.size

    monkeypatch.setattr(fitting.curves, "_model_curve", lambda scene, deltas, tol, counter=None, progress=None: Short(scene, deltas))
    scene, disp, F, force = good
    with pytest.raises(ValueError, match=r"data reach delta = 0\.48.* model curve ends at delta = 0\.18.*end of the tip"):
        sb.fit(scene, disp, force, R_L=R_L)
    with pytest.raises(ValueError, match="ends before the deepest data point"):
        sb.fit(scene, disp, force, R_L=R_L, fit_beta=True)


# -- checks after fitting -------------------------------------------------------------------------
def test_step_function_gets_a_residual_pattern_warning(good):
    scene, disp, F, _ = good
    step = np.where(disp > disp.mean(), F.max(), 0.02 * F.max())
    r = sb.fit(scene, disp, step, R_L=R_L)
    assert "residual_runs" in r.warning_codes, (r.mu_H, r.warnings)
    assert any("runs test" in w for w in r.warnings)


def _undetermined(F):
    """A rising trend under large alternating noise: passes the trend check, mu*H not determined."""
    return F + F.max() * (1 + (-1.0) ** np.arange(F.size))


def test_interval_wider_than_the_estimate_fails(good):
    scene, disp, F, _ = good
    r = sb.fit(scene, disp, _undetermined(F), R_L=R_L)
    lo, hi = r.mu_H_ci95
    assert hi - lo > r.mu_H > 0
    assert r.status == 5 and not r.success and r.message.startswith(fitting.FIT_STATUS[5])
    assert r.to_dict()["success"] is False


def test_header_in_kN_on_data_in_mN(good, tmp_path):
    """The header's units are respected: a true kN file gives the same mu*H; mN numbers under a kN
    header give 1e6 x mu*H, which the plausibility check flags."""
    scene, disp, F, force = good
    p = tmp_path / "kn.csv"
    p.write_text("displacement (mm),force (kN)\n" + "\n".join(f"{a * 1e3:.9g},{b * 1e-3:.9g}"
                                                              for a, b in zip(disp, force)))
    d, f = sb.read_force_csv(p)
    np.testing.assert_allclose(f, force, rtol=1e-8)
    ok = sb.fit(scene, d, f, R_L=R_L)
    assert ok.success and "implausible_mu_H" not in ok.warning_codes
    d, f = sb.read_force_csv(write_csv(tmp_path / "mislabelled.csv", disp, force, "displacement (mm),force (kN)"))
    r = sb.fit(scene, d, f, R_L=R_L)
    assert r.mu_H == pytest.approx(1e6 * ok.mu_H, rel=1e-6)
    assert r.warning_codes == ["implausible_mu_H"] and "check the units" in r.warnings[0]


# -- CLI: exit status, warnings, one JSON document -------------------------------------------------
def test_cli_failed_fit_exits_1_with_json(good, tmp_path, cli_main):
    run = cli_main  # the command's main in this process
    scene, disp, F, _ = good
    p = write_csv(tmp_path / "undetermined.csv", disp, _undetermined(F))
    r = run("fit", str(p), "--preset", "fit", "--radius", "0.3mm", "--json", "-o", str(tmp_path / "x.h5"))
    assert r.returncode == 1, r.stderr
    out = json.loads(r.stdout)
    assert out["success"] is False and out["status"] == 5 and out["exit_status"] == 1
    assert not (tmp_path / "x.h5").exists() and "not writing" in r.stderr
    r = run("fit", str(p), "--preset", "fit", "--radius", "0.3mm")
    assert r.returncode == 1 and "fit failed (status 5)" in r.stdout


def test_cli_warnings_in_text_json_and_saved_file(good, tmp_path, cli_main):
    run = cli_main  # in this process
    scene, disp, F, _ = good
    step = np.where(disp > disp.mean(), F.max(), 0.02 * F.max())
    p = write_csv(tmp_path / "step.csv", disp, step)
    r = run("fit", str(p), "--preset", "fit", "--radius", "0.3mm", "-o", str(tmp_path / "step.h5"))
    assert r.returncode == 0, r.stderr
    assert any(ln.startswith("warning: the residuals' signs") for ln in r.stdout.splitlines()), r.stdout
    from shellbvp.fitrecord import read_fit

    rec = read_fit(tmp_path / "step.h5")
    # a step the shell cannot follow: its residuals run and are correlated, the model misses the
    # contact region, rated poor
    codes = ["residual_runs", "residual_autocorrelation", "contact_misfit"]
    assert rec.status == 0 and rec.warning_codes == codes
    assert "runs test" in rec.warnings[0]
    with h5py.File(tmp_path / "step.h5") as f:
        assert f["fit/parameters/mu_H"][()] == pytest.approx(rec.parameters["mu_H"])
    r = run("fit", str(p), "--preset", "fit", "--radius", "0.3mm", "--json")
    out = json.loads(r.stdout)
    assert r.returncode == 0 and out["warning_codes"] == codes and out["status"] == 0
    assert out["quality"] == "poor"


@pytest.mark.parametrize("name,make,words", [
    ("noise.csv", lambda d, F: np.abs(np.random.default_rng(1).normal(0.5e-3, 0.3e-3, d.size)), ["increase"]),
    ("nm.csv", None, ["shallowest depth", "--radius"]),
])
def test_cli_bad_data_exit_2_with_one_line_and_one_json(good, tmp_path, cli_main, name, make, words):
    scene, disp, F, force = good
    if make is None:  # nm-scale depths against a 0.3 mm rim
        p = write_csv(tmp_path / name, disp * 1e3, force, "displacement (nm),force (mN)")  # 1e-3 x the depths
    else:
        p = write_csv(tmp_path / name, disp, make(disp, F))
    r = cli_main("fit", str(p), "--preset", "fit", "--radius", "0.3mm", "--json")  # in this process
    assert r.returncode == 2 and "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("shellbvp: error: "), r.stderr
    out = json.loads(r.stdout)
    assert out["success"] is False and out["exit_status"] == 2 and out["message"] in lines[0]
    for w in words:
        assert w in lines[0], lines[0]


# -- CSV reading (issue 11, section 4) ------------------------------------------------------------
BODY = "0.01,0.1\n0.02,0.4\n0.03,0.9\n0.04,1.5\n"


@pytest.mark.parametrize("cell", ["5_0", "1e999", "inf", "-Infinity", "0x10", "\uff15"])
def test_numbers_python_reads_but_a_csv_should_not(tmp_path, cell):
    p = tmp_path / "bad.csv"
    p.write_text("displacement (mm),force (mN)\n0.01,0.1\n0.02," + cell + "\n0.03,0.9\n0.04,1.5\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"line 3: cannot read '0\.02', '" + cell.replace("+", r"\+") + "'"):
        sb.read_force_csv(p)


def test_utf16_with_bom(tmp_path):
    p = tmp_path / "u16.csv"
    p.write_bytes("displacement (µm);force (µN)\n0,01;0,1\n0,02;0,4\n0,03;0,9\n".encode("utf-16"))
    assert p.read_bytes()[:2] in (b"\xff\xfe", b"\xfe\xff")
    d, f = sb.read_force_csv(p)
    np.testing.assert_allclose(d, [1e-8, 2e-8, 3e-8])
    np.testing.assert_allclose(f, [1e-7, 4e-7, 9e-7])
    p.write_bytes("displacement (mm),force (mN)\n".encode("utf-16-le") + BODY.encode("utf-16-le"))  # no BOM
    assert sb.read_force_csv(p)[0].size == 4


def test_latin1_with_micro_sign_in_the_header(tmp_path):
    p = tmp_path / "latin1.csv"
    p.write_bytes("# Messung vom 3. März\nWeg (µm),Kraft (mN)\n".encode("latin-1") + BODY.encode())
    assert b"\xb5" in p.read_bytes()  # not valid UTF-8
    d, f = sb.read_force_csv(p)
    np.testing.assert_allclose(d, [1e-8, 2e-8, 3e-8, 4e-8])
    p.write_text("disp (μm),force (mN)\n" + BODY, encoding="utf-8")  # Greek mu, as some software writes it
    np.testing.assert_allclose(sb.read_force_csv(p)[0], d)


def test_undecodable_file(tmp_path):
    p = tmp_path / "data.csv"
    p.write_bytes(b"PK\x03\x04\x14\x00\x06\x00\x08\x00\x00\x00!\x00\x9d\x81\xff\xfe" * 20)  # an .xlsx, say
    with pytest.raises(ValueError, match="data.csv: not a text file in a known encoding"):
        sb.read_force_csv(p)


def test_line_numbers_count_comment_and_blank_lines(tmp_path):
    p = tmp_path / "c.csv"
    p.write_text("# instrument X\n# operator Y\ndisplacement (mm),force (mN)\n\n0.01,0.1\n0.02,oops\n0.03,0.9\n")
    with pytest.raises(ValueError, match=r"c\.csv: line 6: cannot read '0\.02', 'oops'"):
        sb.read_force_csv(p)
    p.write_text("# header follows\nd (mm),F (mN)\n1,2\n# note\n3\n4,5\n")
    with pytest.raises(ValueError, match="line 5 has 1 columns"):
        sb.read_force_csv(p)


def test_cli_data_deeper_than_the_scene_allows(good, tmp_path, cli_main):
    """Data deeper than the scene's geometric bound (delta 4.69 for preset fit) exit 2 at once, one
    line, no traceback.  (Until the corner edge, the model curve of preset fit ended at its convexity
    limit, delta 1.56, and 8x deeper data failed there after ~40 s; it now reaches such data.)"""
    scene, disp, F, force = good
    p = write_csv(tmp_path / "deep.csv", 20 * disp, 20 * force)
    r = cli_main("fit", str(p), "--preset", "fit", "--radius", "0.3mm")  # in this process
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "outside [" in r.stderr and "4.692" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_the_rank_trend_is_spearmans_test_as_scipy_computes_it():
    """fit_checks.rank_trend (scipy.special only: scipy.stats costs 0.4 s to import) against
    scipy.stats.spearmanr, ties and perfect correlation included."""
    import numpy as np
    from scipy import stats

    from shellbvp.fit_checks import rank_trend

    rng = np.random.default_rng(7)
    for n in (3, 6, 25, 120):
        for sign in (1, -1):
            d = np.round(rng.random(n), 2)
            for f in (np.round(sign * d + 0.3 * rng.standard_normal(n), 1), sign * d):
                rho, p_up, p_down = rank_trend(d, f)
                up = stats.spearmanr(d, f, alternative="greater")
                assert rho == pytest.approx(up[0], rel=1e-12, abs=1e-15)
                assert p_up == pytest.approx(up[1], rel=1e-10, abs=1e-300)
                assert p_down == pytest.approx(stats.spearmanr(d, f, alternative="less")[1], rel=1e-10, abs=1e-300)
