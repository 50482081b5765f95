"""Instrument files (issue 15 item 1): reading exports as instruments write them, segmenting
approach / loading / hold / retraction, and fitting the loading with a force baseline.

The files are generated here from the model itself (preset fit, R_L = 0.3 mm, mu*H = 40 N/m)
with an approach before contact, a hold with creep, a retraction with hysteresis, a baseline
of 150 uN and 2 % noise: the truth is known.
"""

import json
import sys

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import shellbvp as sb
from shellbvp.fitting import fit_record
from shellbvp.instrument import estimate_contact, read_instrument, read_table, segment

R_L, MU_H, D0, BASE = 0.3e-3, 40.0, 25e-6, 150e-6
N_PUSH, N_HOLD, N_RET = 160, 20, 160


@pytest.fixture(scope="module")
def truth():
    """Time, displacement (m), force (N) of a record, and the rows of each segment."""
    scene = sb.Scene.preset("fit")
    c = sb.curve(scene, deltas=np.linspace(0.005, 0.45, 90), estimate_error=False)
    shape = PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])

    def model(d):
        x = (d - D0) / R_L
        return np.where(x > 0, MU_H * R_L * shape(np.clip(x, 0, 0.45)), 0.0)

    rng = np.random.default_rng(1)
    top = D0 + 0.4 * R_L
    d_push = np.linspace(-20e-6, top, N_PUSH)
    d_ret = np.linspace(top, -20e-6, N_RET)
    d = np.r_[d_push, np.full(N_HOLD, top), d_ret]
    f = model(d)
    f[N_PUSH:N_PUSH + N_HOLD] *= np.linspace(1, 0.97, N_HOLD)  # creep during the hold
    f[N_PUSH + N_HOLD:] = 0.97 * model(d_ret + 8e-6) * (1 - 0.1 * np.linspace(0, 1, N_RET))  # hysteresis
    f = f * (1 + 0.02 * rng.standard_normal(d.size)) + BASE + 0.5e-6 * rng.standard_normal(d.size)
    t = 0.05 * np.arange(d.size)
    return scene, t, d, f


def write(path, t, d, f, style):
    """The same record in the styles instruments write."""
    if style == "tab":  # tab-separated, '#' comments, Greek mu (U+03BC), time first
        lines = ["# exported by an indenter", "# sample: seed 1",
                 "Time (s)\tDisplacement (um)\tForce (\u03bcN)"]
        lines += [f"{a:.3f}\t{b * 1e6:.5f}\t{c * 1e6:.5f}" for a, b, c in zip(t, d, f)]
    elif style == "two_rows":  # names, then units (micro sign U+00B5); ';' and decimal commas
        lines = ["% instrument v2", "Force;Time;Indentation", "\u00b5N;s;\u00b5m"]
        lines += [f"{c * 1e6:.5f};{a:.3f};{b * 1e6:.5f}".replace(".", ",") for a, b, c in zip(t, d, f)]
    elif style == "nm_pN":  # nm and pN, comma-separated, time in ms
        lines = ["time [ms],force [pN],displacement [nm]"]
        lines += [f"{a * 1e3:.1f},{c * 1e12:.1f},{b * 1e9:.2f}" for a, b, c in zip(t, d, f)]
    elif style == "shuffled":  # rows in any order: the time column restores it
        lines = ["Time (s),Displacement (mm),Force (mN)"]
        order = np.random.default_rng(0).permutation(t.size)
        lines += [f"{t[i]:.3f},{d[i] * 1e3:.8f},{f[i] * 1e3:.8f}" for i in order]
    elif style == "spaces":  # whitespace columns, the header in comment lines (JPK's ASCII export style)
        lines = ["# instrument: an AFM", "# columns: time displacement force", "# units: s um uN"]
        lines += [f"{a:.3f}   {b * 1e6:.5f}  {c * 1e6:.5f}" for a, b, c in zip(t, d, f)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("style", ["tab", "two_rows", "nm_pN", "shuffled", "spaces"])
def test_every_style_reads_to_the_same_si_record_and_segments(truth, tmp_path, style):
    _, t, d, f = truth
    rec = read_instrument(write(tmp_path / f"{style}.txt", t, d, f, style))
    np.testing.assert_allclose(rec.displacement, d, atol=1e-11)
    np.testing.assert_allclose(rec.force, f, rtol=1e-6, atol=1e-10)
    np.testing.assert_allclose(rec.time, t, atol=1e-9)
    assert set(rec.columns) == {"displacement", "force", "time"}
    counts = rec.counts()
    push = counts["approach"] + counts["loading"]
    # the Savitzky-Golay window smears each corner by a few rows, no more
    assert abs(push - N_PUSH) <= 5 and abs(counts["retraction"] - N_RET) <= 5 and counts["hold"] >= N_HOLD - 8
    assert not np.any(rec.mask("loading")[N_PUSH + N_HOLD:])  # no retraction row among the loading
    assert abs(rec.contact_estimate - D0) < 10e-6


@pytest.mark.parametrize("style", ["tab", "two_rows", "nm_pN", "spaces"])
def test_fit_of_the_loading_recovers_mu_H_offset_and_baseline(truth, tmp_path, style):
    scene, t, d, f = truth
    rec = read_instrument(write(tmp_path / "rec.txt", t, d, f, style))
    res, used = fit_record(scene, rec, R_L=R_L)
    assert res.success and res.baseline_model == "constant"
    assert res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1], (res.mu_H, res.mu_H_ci95)
    assert abs(res.offset - D0) < 2e-6, res.offset
    assert res.baseline_ci95[0] < BASE < res.baseline_ci95[1], (res.baseline, res.baseline_ci95)
    assert res.fitted == ("mu_H", "offset", "baseline")
    assert used.sum() == np.sum(np.isin(rec.segments, ("approach", "loading")))
    assert not np.any(used & (rec.segments == "retraction"))
    # after the fit the approach is what lies before the fitted contact point
    assert np.all(rec.displacement[rec.segments == "approach"] < res.offset)


def test_the_merged_segments_mistake_needs_asking_and_then_warns(truth, tmp_path):
    """What the issue found: all rows sorted by displacement give a confident interval without the truth."""
    scene, t, d, f = truth
    rec = read_instrument(write(tmp_path / "rec.txt", t, d, f, "tab"))
    merged, used = fit_record(scene, rec, R_L=R_L, segment="all")
    assert used.all()
    assert not merged.mu_H_ci95[0] < MU_H < merged.mu_H_ci95[1]  # the bias the default avoids
    assert "mixed_segments" in merged.warning_codes
    with pytest.raises(ValueError, match="segment must be one of"):
        rec.mask("everything")


def test_linear_baseline_recovers_its_slope(truth, tmp_path):
    scene, t, d, f = truth
    slope = 0.5  # N/m: 10 uN over the 20 um approach
    tilted = f + slope * (d - D0)
    rec = read_instrument(write(tmp_path / "tilt.txt", t, d, tilted, "tab"))
    res, _ = fit_record(scene, rec, R_L=R_L, baseline="linear")
    assert res.success and res.fitted == ("mu_H", "offset", "baseline", "baseline_slope")
    assert res.baseline_slope_ci95[0] < slope < res.baseline_slope_ci95[1], (res.baseline_slope,
                                                                               res.baseline_slope_ci95)
    assert res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1] and abs(res.offset - D0) < 2e-6


def test_cli_fits_the_loading_by_default_and_prints_the_data_units(truth, tmp_path, cli_main):
    _, t, d, f = truth
    path = write(tmp_path / "rec.txt", t, d, f, "tab")
    r = cli_main("fit", str(path), "--preset", "fit", "--radius", "0.3mm")  # in this process
    assert r.returncode == 0, r.stderr
    assert "fitted the loading segment" in r.stdout and "retraction 1" in r.stdout
    offset_line = next(ln for ln in r.stdout.splitlines() if ln.startswith("offset"))
    assert offset_line.split()[3] == "um" and abs(float(offset_line.split()[2]) - 25) < 2, offset_line
    assert any(ln.startswith("baseline") and "\u00b5N" in ln for ln in r.stdout.splitlines()), r.stdout
    r = cli_main("fit", str(path), "--preset", "fit", "--radius", "0.3mm", "--json")
    out = json.loads(r.stdout)
    assert out["mu_H_ci95"][0] < MU_H < out["mu_H_ci95"][1] and out["baseline_model"] == "constant"


def test_columns_that_cannot_be_told_apart_list_the_header_and_suggest_columns(tmp_path):
    p = tmp_path / "two_lengths.csv"
    p.write_text("Time (s),Height (um),Z (um),Force (uN)\n" + "\n".join(f"{i},{i},{i},{i * i}" for i in range(10)))
    with pytest.raises(ValueError, match=r"more than one column could be the displacement.*'Height \(um\)'.*--columns"):
        read_instrument(p)
    rec = read_instrument(p, columns=["Z", "Force"])
    assert rec.columns == {"displacement": "Z (um)", "force": "Force (uN)"} and rec.time is None
    q = tmp_path / "unnamed.csv"
    q.write_text("a,b,c\n" + "\n".join(f"{i},{i},{i}" for i in range(10)))
    with pytest.raises(ValueError, match=r"0: 'a', 1: 'b', 2: 'c'.*--columns"):
        read_instrument(q)


def test_read_table_header_rows_comments_and_decimal_commas(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("# comment\n% another\nInstrument XY;serial 5\nDepth;Load\n\u03bcm;mN\n1,5;2,25\n3;4\n")
    tab = read_table(p)
    assert tab.header == ["Depth", "Load"] and tab.header_units == ["\u00b5m", "mN"] and tab.line == [6, 7]
    d = tmp_path / "d.csv"
    d.write_text("Depth;Load\n\u03bcm;mN\n" + "\n".join(f"{i},5;{i * 2},25" for i in range(5)))
    rec = read_instrument(d)
    np.testing.assert_allclose(rec.displacement, (np.arange(5) + 0.5) * 1e-6)
    np.testing.assert_allclose(rec.force, (np.arange(5) * 2 + 0.25) * 1e-3)


def test_segment_without_time_and_contact_estimate_edge_cases():
    d = np.r_[np.linspace(0, 1, 50), np.ones(10), np.linspace(1, 0.2, 40), np.linspace(0.2, 0.5, 20)]
    lab = segment(d)
    assert lab[10] == "loading" and lab[55] == "hold" and lab[80] == "retraction" and lab[-1] == "other"
    assert set(segment(np.linspace(1, 0, 30))) == {"retraction"}  # a file sorted the other way: no loading
    # a staircase (steps and holds) is one loading; two cycles: the deeper one is fitted
    stairs = np.r_[np.repeat(np.linspace(0.1, 1, 10), 12), np.ones(12), np.linspace(1, 0, 40)]
    lab = segment(stairs)
    assert set(lab[:105]) == {"loading"} and lab[115] == "hold" and lab[125] == "hold" and lab[150] == "retraction"
    two = np.r_[np.linspace(0, 0.5, 30), np.linspace(0.5, 0, 30), np.linspace(0, 1, 50), np.linspace(1, 0, 50)]
    lab = segment(two)
    assert lab[15] == "other" and lab[45] == "other" and lab[90] == "loading" and lab[150] == "retraction"
    x = np.linspace(0, 1, 50)
    assert estimate_contact(x, 0.1 + x) is None  # starts in contact: no baseline to read
    f = np.clip(x - 0.4, 0, None) ** 1.5 + 1e-4 * np.random.default_rng(0).standard_normal(50)
    assert abs(estimate_contact(x, f) - 0.4) < 0.1


def test_no_loading_segment_is_a_clear_error(tmp_path):
    p = tmp_path / "down.csv"
    p.write_text("displacement (mm),force (mN)\n" + "\n".join(f"{1 - i / 20},{(1 - i / 20) ** 2}" for i in range(20)))
    rec = read_instrument(p)
    with pytest.raises(ValueError, match=r"loading segment has 0 rows.*retraction.*--segment"):
        fit_record(sb.Scene.preset("fit"), rec, R_L=R_L)


def test_an_afm_height_and_a_negative_compression_are_flipped_on_request(truth, tmp_path, capsys):
    """A height that falls as the tip goes in and compression recorded as negative: the fit says
    which option flips them; with them the record is the package's convention and fits."""
    from shellbvp.cli import main

    scene, t, d, f = truth
    path = tmp_path / "afm.txt"
    lines = ["# xPosition: 1e-6", "# fancyNames: \"Height\" \"Vertical deflection\" \"Series time\"",
             "# columns: height vDeflection seriesTime", "# units: m N s"]
    lines += [f"{-b:.8e} {-c:.8e} {a:.3f}" for a, b, c in zip(t, d, f)]
    path.write_text("\n".join(lines) + "\n")
    plain = read_instrument(path)
    assert plain.columns == {"displacement": "height", "force": "vDeflection", "time": "seriesTime"}
    with pytest.raises(ValueError, match="--invert displacement or --invert force"):
        fit_record(scene, read_instrument(path, invert=["force"]), R_L=R_L)
    rec = read_instrument(path, invert=("displacement", "force"))
    np.testing.assert_allclose(rec.displacement, d, rtol=1e-8)
    np.testing.assert_allclose(rec.force, f, rtol=1e-8)
    assert rec.inverted == ("displacement", "force")
    res, _ = fit_record(scene, rec, R_L=R_L)
    assert res.success and res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1]
    with pytest.raises(ValueError, match="invert must name displacement and/or force"):
        read_instrument(path, invert=["height"])
    out = tmp_path / "afm.h5"
    assert main(["fit", str(path), "--preset", "fit", "--radius", "0.3mm", "--invert", "displacement",
                 "--invert", "force", "-o", str(out)]) == 0
    assert sb.read_fit(out).source["inverted"] == ["displacement", "force"]


def test_the_smoothed_slope_is_savitzky_golays():
    """instrument.smoothed_slope (no scipy.signal import: 0.37 s) against
    scipy.signal.savgol_filter(d, w, 2, deriv=1), ends included."""
    import numpy as np
    from scipy.signal import savgol_filter

    from shellbvp.instrument import smoothed_slope

    rng = np.random.default_rng(5)
    for n, w in ((7, 5), (60, 11), (3000, 51)):
        d = np.cumsum(rng.standard_normal(n))
        want = savgol_filter(d, w, 2, deriv=1)
        assert np.max(np.abs(smoothed_slope(d, w) - want)) <= 1e-12 * np.max(np.abs(want))


def test_a_unit_after_the_columns_last_underscore_is_read(tmp_path):
    """``displacement_mm,force_mN`` (a common export header) names its units; a name such as
    ``vertical_deflection`` does not."""
    from shellbvp.instrument import _bare_name, _unit_of

    path = tmp_path / "nu.csv"
    path.write_text("displacement_mm,force_mN\n" + "".join(f"{0.01 * i},{0.1 * i * i}\n" for i in range(8)))
    rec = sb.read_instrument(path)
    assert rec.units == {"displacement": "mm", "force": "mN"}
    assert rec.displacement[1] == pytest.approx(1e-5) and rec.force[2] == pytest.approx(4e-4)
    assert _unit_of("vertical_deflection") is None and _bare_name("force_mN") == "force"


def test_units_beyond_the_tables_come_from_pint_and_only_for_such_a_unit(tmp_path):
    pytest.importorskip("pint")
    import subprocess
    import sys

    from shellbvp.units import parse_quantity, pint_unit, unit_factor

    assert unit_factor("gf", "force") == pytest.approx(9.80665e-3, rel=1e-12)
    assert unit_factor("lbf", "force") == pytest.approx(4.4482216152605, rel=1e-12)
    assert unit_factor("sec", "time") == 1.0 and unit_factor("millimeter", "length") == pytest.approx(1e-3)
    assert unit_factor("pN/nm", "mu_H") == pytest.approx(1e-3) and parse_quantity("2 psi", "pressure") > 13e3
    with pytest.raises(ValueError, match="unknown force unit 'mm'"):
        unit_factor("mm", "force")  # a length, not a force
    for hostile in ("m**99999999", "10**10**10", "__import__('os')", "N" * 40, "m/m/m/m/m/m"):
        assert pint_unit(hostile) is None  # not a plain unit expression: pint is not asked
    path = tmp_path / "pu.csv"
    path.write_text("Height (millimeter),Force (gf)\n" + "".join(f"{0.01 * i},{0.1 * i * i}\n" for i in range(8)))
    rec = sb.read_instrument(path)
    assert rec.force[2] == pytest.approx(0.4 * 9.80665e-3) and rec.displacement[1] == pytest.approx(1e-5)
    # a file in the tables' units does not load pint (0.4 s)
    code = ("import sys, shellbvp as sb; from shellbvp.fitting import example_data_path; "
            "sb.read_instrument(example_data_path()); "
            "print('pint' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_time_column_whose_unit_is_not_a_time_is_dropped_and_the_record_says_so(truth, tmp_path, capsys):
    """The time only orders the rows: a header unit that is no time (here volts, with a
    right-to-left override in it, which would reorder a terminal line) drops that column, not the file; the note names it, escaped, and goes with the
    fit to its summary, its JSON and its record.  A unit the user gives with --units is still an error."""
    from shellbvp.cli import main

    scene, t, d, f = truth
    path = tmp_path / "volts.csv"
    lines = ["Time (volts\u202e),Displacement (um),Force (uN)"]
    lines += [f"{a:.3f},{b * 1e6:.6f},{c * 1e6:.6f}" for a, b, c in zip(t, d, f)]
    path.write_text("\n".join(lines) + "\n")
    rec = read_instrument(path)
    assert rec.time is None and set(rec.columns) == {"displacement", "force"}
    np.testing.assert_allclose(rec.displacement, d, rtol=1e-6, atol=1e-12)  # the file's order, every row
    assert len(rec.notes) == 1
    note = rec.notes[0]
    assert "time column" in note and "not a time" in note and "volts\\u202e" in note and "\u202e" not in note
    res, _ = fit_record(scene, rec, R_L=R_L)
    assert res.success and res.mu_H_ci95[0] < MU_H < res.mu_H_ci95[1]
    assert read_instrument(tmp_path / "volts.csv", units=("um", "uN", None)).notes == rec.notes
    with pytest.raises(ValueError, match="time column: unknown time unit 'volts'"):
        read_instrument(path, units=("um", "uN", "volts"))

    out = tmp_path / "volts.h5"
    capsys.readouterr()
    assert main(["fit", str(path), "--preset", "fit", "--radius", "0.3mm", "-q", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"note: {note}" in printed.splitlines() and "\u202e" not in printed
    assert sb.read_fit(out).source["notes"] == [note]
    assert main(["fit", str(path), "--preset", "fit", "--radius", "0.3mm", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["notes"] == [note]
    plain = tmp_path / "seconds.csv"
    plain.write_text("\n".join(["Time (s),Displacement (um),Force (uN)"] + lines[1:]) + "\n")
    assert read_instrument(plain).notes == () and read_instrument(plain).time is not None


# -- readers (issue 56, item 3) ------------------------------------------------------------------------------
@pytest.mark.parametrize("text, units", [
    ("0,0\t0,0\n1,0\t0,5\n2,0\t1,5\n3,0\t3,0\n", ("um", "mN")),                       # headerless decimal commas
    ("0,0;0,0\n1,0;0,5\n2,0;1,5\n3,0;3,0\n", ("um", "mN")),
    ("# displacement (mm)   force (mN)\n0.0   0.0\n1.0   0.5\n2.0   1.5\n3.0   3.0\n", None),   # commented header
    ("displacement (mm)   force (mN)\n0.0   0.0\n1.0   0.5\n2.0   1.5\n3.0   3.0\n", None),
    ("# displacement [mm] force [mN]\n0.0 0.0\n1.0 0.5\n2.0 1.5\n3.0 3.0\n", None),
])
def test_whitespace_and_decimal_comma_tables_read_every_row_with_their_units(tmp_path, text, units):
    path = tmp_path / "rec.txt"
    path.write_text(text)
    rec = sb.read_instrument(path, units=units)
    scale = (1e-6, 1e-3) if units else (1e-3, 1e-3)
    np.testing.assert_allclose(rec.displacement, np.array([0, 1, 2, 3]) * scale[0])
    np.testing.assert_allclose(rec.force, np.array([0, 0.5, 1.5, 3]) * scale[1])
    if units is None:
        assert rec.units == {"displacement": "mm", "force": "mN"}


def test_the_cli_fits_a_headerless_decimal_comma_file(tmp_path, capsys, closed_form):
    from shellbvp.cli import main

    (tmp_path / "dc.txt").write_text("0,0\t0,0\n1,0\t0,5\n2,0\t1,5\n3,0\t3,0\n")
    main(["fit", str(tmp_path / "dc.txt"), "--preset", "fit", "--radius", "0.3mm", "--units", "um,mN", "-q"])
    out = capsys.readouterr().out
    assert "dc.txt: 4 rows" in out


def test_a_table_bounded_in_rows_is_refused_before_it_is_split(tmp_path):
    from shellbvp.instrument import MAX_PREAMBLE_LINES, read_table

    path = tmp_path / "t.csv"
    path.write_text("a,b\n" + "1,2\n" * (100 + MAX_PREAMBLE_LINES + 1))
    with pytest.raises(ValueError, match=r"lines; a table has at most 100 rows"):
        read_table(path, max_rows=100)
    path.write_text("a,b\n" + "1,2\n" * 101)
    with pytest.raises(ValueError, match=r"101 rows; a table has at most 100"):
        read_table(path, max_rows=100)
    assert len(read_table(path, max_rows=101).rows) == 101
