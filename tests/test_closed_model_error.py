"""The shell model's measured error for closed shells (issue 55): the closed shells' map
(``benchmarks/thick_fits.py --set closed-mapped``) in ``shellbvp.thickness``, the line a shell fit
of a closed shell prints, and the check off the map (``--closed-map-check``).

The tables are read back from the benchmark's results (their rows are the largest errors there);
the off-map check recomputes the printed bound for the two thick records of ``--set closed``.
"""

import json
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.thickness import (CLOSED_EPS, CLOSED_FIT_MODEL_ERROR, CLOSED_MEASURED_MODEL_ERROR,
                                closed_mapped_support, model_error, model_error_line)

RESULTS = Path(__file__).parents[1] / "benchmarks/results"
NH = sb.NeoHookean()


def plates(eps, **over):
    return sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, material=NH, thickness=eps, **over)


def substrate(eps, rho=0.5, **over):
    return sb.Scene(closed=True, support="substrate", tip=sb.SphereTip(), rho=rho, gamma=1.0, material=NH,
                    thickness=eps, **over)


def test_the_closed_tables_are_the_largest_errors_of_the_closed_map():
    """Each row is the largest abs(error) of the shell (with or without transverse shear) on the map's
    records of that support: in a fitted mu*H (every record fitted whole, without its approach and
    cut to its shallower half; a fit that ran and failed a check counts: its mu*H is printed) and in
    F at equal depth (where the shell does
    not wrap the tip).  An eps a support was not measured at is None and says so in the JSON too."""
    checked = 0
    for i, eps in enumerate(CLOSED_EPS):
        r = json.loads((RESULTS / f"thick_fits_closed-mapped_eps{eps:g}.json").read_text())
        for (support, shear), row in CLOSED_FIT_MODEL_ERROR.items():
            label = "shell, shear" if shear else "shell"
            fits = [f for f in r["fits"] if f["fit"] == label and r["scenes"][f["scene"]]["support"] == support]
            curves = [f for f in r["f_error"] if f["fit"] == label and r["scenes"][f["scene"]]["support"] == support]
            if row[i] is None:
                assert not fits and CLOSED_MEASURED_MODEL_ERROR[(support, shear)][i] is None, (support, eps)
                continue
            assert len(fits) >= 3 and all(np.isfinite(f["mu_H"]) for f in fits), (support, shear, eps)
            assert sum(not f["success"] for f in fits) <= 1   # one ran and failed its residual check (counted)
            assert row[i] == pytest.approx(max(abs(f["error"]) for f in fits), abs=5e-4), (support, shear, eps)
            in_f = [abs(e) for f in curves for e, w in zip(f["error"], f["wraps"]) if not w]
            assert len(in_f) >= 10 and np.all(np.isfinite(in_f))
            assert CLOSED_MEASURED_MODEL_ERROR[(support, shear)][i] == pytest.approx(max(in_f), abs=5e-4)
            checked += 1
    assert checked >= 6


def test_closed_shells_outside_the_map_print_no_bound():
    assert closed_mapped_support(plates(0.03)) == "plates"
    assert closed_mapped_support(substrate(0.03)) == "substrate"
    assert closed_mapped_support(substrate(0.03).replace(tip=sb.FlatTip())) == "plates"  # the same problem
    assert model_error(plates(0.03, pressure=0.1)) is None
    assert model_error(plates(0.03, sealed=True)) is None
    assert model_error(sb.Scene(closed=True, support="plates", tip=sb.SphereTip(), rho=0.3, gamma=1.0,
                                thickness=0.03)) is None                              # two curved indenters
    assert model_error(sb.Scene(closed=True, support="plates", tip=sb.FlatTip(), gamma=1.0, beta=1e-3)) is None
    meridian = sb.UserShell("sin(S)", "cos(S)", "pi/2")
    assert model_error(plates(0.03).replace(shell=meridian)) is None                 # a user meridian
    line = model_error_line(plates(0.03, pressure=0.1))
    assert "not mapped for this closed shell" in line and "--model solid" in line


def test_a_shell_fit_of_a_closed_shell_prints_its_measured_error(tmp_path, capsys):
    from shellbvp.cli import main

    R_L, mu_H, eps = 30e-6, 0.5, 0.03
    depths = np.linspace(0.01, 0.15, 15)
    c = sb.curve(plates(eps), deltas=depths, estimate_error=False)
    F = mu_H * R_L * np.asarray(c.points["force"])[np.isin(c.points["delta"], depths)]
    d = np.r_[np.linspace(0, 1e-6, 5, endpoint=False), 1e-6 + depths * R_L]
    data = tmp_path / "capsule.tsv"
    data.write_text("Displacement (um)\tForce (uN)\n" + "".join(f"{a * 1e6:.9f}\t{b * 1e6:.9f}\n"
                                                                for a, b in zip(d, np.r_[np.zeros(5), F])))
    main(["fit", str(data), "--closed", "--support", "plates", "--flat-tip", "--gamma", "1", "--radius", "30um",
          "--thickness", f"{eps * 30:g}um", "--neo-hookean", "--model", "shell"])
    text = capsys.readouterr().out
    error = model_error(plates(eps))
    sheared = model_error(plates(eps, transverse_shear=True))
    assert error[1] is False and 0 < sheared[0] and 0 < error[0]
    line = next(t for t in text.splitlines() if t.startswith("model  ="))
    assert f"up to {100 * error[0]:.2g} %" in line and "closed shells between plates" in line
    assert f"--transverse-shear: up to {100 * sheared[0]:.2g} %" in line and "extrapolated" not in line
    thick = model_error_line(plates(0.1))                       # beyond the map: extrapolated, and it says so
    assert model_error(plates(0.1))[1] and "extrapolated" in thick and "--model solid" in thick
    below = model_error_line(substrate(0.01))
    assert "on a substrate under a sphere tip" in below and model_error(substrate(0.01))[1]
    assert "extrapolated: measured at eps 0.05 only" in below                    # the substrate's one thickness


def test_the_printed_closed_bound_holds_on_the_two_thick_closed_records_off_the_map():
    """The two records of ``thick_fits.py --set closed`` (a capsule between plates at eps 0.1, a cell
    on a substrate under a sphere rho 0.5 at eps 0.15) lie outside the closed shells' map: the
    bound printed there is extrapolated, and the shell's error in every fit (whole, loading only,
    shallow half; with and without transverse shear) is within it."""
    r = json.loads((RESULTS / "thick_fits_closed.json").read_text())
    checked = 0
    for f in r["fits"]:
        if not f["fit"].startswith("shell"):
            continue
        s = r["scenes"][f["scene"]]
        scene = (plates(s["eps"]) if s["support"] == "plates" else substrate(s["eps"], rho=s["rho"])).replace(
            gamma=s["gamma"], transverse_shear=f["fit"] == "shell, shear")
        bound, extrapolated = model_error(scene)
        assert extrapolated and abs(f["error"]) <= bound, f
        checked += 1
    assert checked == 12
    kept = json.loads((RESULTS / "thick_fits_closed_check.json").read_text())
    assert [w["bound"] for w in kept["rows"]] == pytest.approx([
        model_error((plates(0.1) if "plates" in w["scene"] else substrate(0.15)).replace(
            transverse_shear=w["fit"] == "shell, shear"))[0] for w in kept["rows"]])
