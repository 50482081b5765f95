"""Scripts of benchmarks/ that write files: each takes its output through an option, refuses
what it does not know, and does no work on ``--help`` or without the arguments it needs."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from benchmark_modules import BENCH, load_benchmark


def _run(name, *args):
    return subprocess.run([sys.executable, str(BENCH / f"{name}.py"), *args], capture_output=True, text=True,
                          cwd=BENCH.parent, timeout=600)


def _mtimes(folder):
    return {p.name: p.stat().st_mtime_ns for p in Path(folder).iterdir()}


def test_make_example_data_writes_only_when_told_where():
    """--help prints help and writes nothing; no arguments, an unknown one or a missing folder
    is refused before any curve is computed (it once took ``--help`` as "go" and rewrote a
    shipped record)."""
    med = load_benchmark("make_example_data")
    before = _mtimes(med.DATA)
    r = _run("make_example_data", "--help")
    assert r.returncode == 0 and "--write" in r.stdout and "--out-dir" in r.stdout
    for args in ([], ["--bogus"], ["--write", "--bogus"], ["--write", "--out-dir", "."],
                 ["--out-dir", str(BENCH / "nope")], ["--write", "--only", "nope.csv"]):
        with pytest.raises(SystemExit) as e:
            med.parse_args(args)
        assert e.value.code == 2, args
    assert _run("make_example_data", "--bogus").returncode == 2
    assert _mtimes(med.DATA) == before
    a = med.parse_args(["--out-dir", str(BENCH), "--only", "cell_glass_synthetic.csv"])
    assert a.out_dir == BENCH and a.only == ["cell_glass_synthetic.csv"] and not a.write


@pytest.mark.slow
def test_make_example_data_makes_the_shipped_records(tmp_path):
    """The records in shellbvp/data/ are what the script writes (~30 s CPU).  The curve of
    lepidium_synthetic.csv has moved by up to 3.4e-5 (relative) at five shallow depths since it was
    written (ad69fa8), so the forces are compared to 1e-4; the other two are the same bytes."""
    med = load_benchmark("make_example_data")
    med.main(["--out-dir", str(tmp_path)])
    for name, *_ in med.RECORDS:
        new, shipped = (np.loadtxt(d / name, delimiter=",", skiprows=2) for d in (tmp_path, med.DATA))
        assert new.shape == shipped.shape and np.array_equal(new[:, 0], shipped[:, 0]), name
        np.testing.assert_allclose(new[:, 1], shipped[:, 1], rtol=1e-4, atol=1e-6, err_msg=name)
        assert (tmp_path / name).read_text().splitlines()[:2] == (med.DATA / name).read_text().splitlines()[:2]


def test_regression_reference_writes_where_told_only(tmp_path):
    """The output is an explicit --out (was: the first argument, whatever it was); an existing
    file (tests/data/regression_states.json, written at 1109cdf) is kept unless --overwrite."""
    rr = load_benchmark("regression_reference")
    kept = BENCH.parent / "tests" / "data" / "regression_states.json"
    before = kept.stat().st_mtime_ns
    assert _run("regression_reference", "--help").returncode == 0
    for args in ([], [str(tmp_path / "x.json")], ["--out", str(kept)], ["--out", str(tmp_path / "x.txt")],
                 ["--out", str(tmp_path / "no" / "x.json")], ["--out", str(tmp_path / "x.json"), "--bogus"]):
        with pytest.raises(SystemExit) as e:
            rr.parse_args(args)
        assert e.value.code == 2, args
    assert _run("regression_reference", str(kept)).returncode == 2
    assert kept.stat().st_mtime_ns == before
    assert rr.parse_args(["--out", str(kept), "--overwrite"]).out == kept
    assert rr.parse_args(["--out", str(tmp_path / "x.json")]).out == tmp_path / "x.json"


def _table(text):
    return [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines()
            if line.startswith("| ") and not line.startswith("| mesh")]


def test_fe_convergence_reports_each_mesh_against_the_finest():
    """benchmarks/fe_convergence.py's table (step fe_convergence; docs/accuracy.md quotes it): the
    forces of each mesh, then each coarser mesh against the finest; the committed table's
    differences are those of its forces."""
    fc = load_benchmark("fe_convergence")
    rows = [dict(element_length=e, through_thickness=t, elements=[n, t], force=f, success=True, seconds=1.0)
            for e, t, n, f in ((0.5, 3, 167, [1.0, 2.0, 4.0]), (0.33, 4, 253, [1.001, 2.0, 3.96]),
                               (0.25, 6, 334, [1.002, 2.002, 4.0]))]
    doc = dict(scene="s", force_units="mu R_L H", rows=rows, machine="m", version="v", seconds=3.0)
    table = _table(fc.report(doc))
    assert "--finest" in fc.report(doc) and "--finest" not in fc.report(dict(doc, rows=rows[:2]))
    assert table[0][:3] == ["0.5, 3 (default)", "167x3", "1"] and len(table) == 5
    assert table[3] == ["0.5, 3 against 0.25, 6", "", "-0.200 %", "-0.100 %", "+0.000 %", ""]
    assert table[4][2:5] == ["-0.100 %", "-0.100 %", "-1.000 %"]
    committed = _table((BENCH / "results" / "fe_convergence.md").read_text())
    forces = [np.array([float(x) for x in row[2:5]]) for row in committed[:2]]
    stated = [float(x.rstrip(" %")) for x in committed[2][2:5]]
    np.testing.assert_allclose(100 * (forces[0] / forces[1] - 1), stated, atol=6e-4)


def test_stability_contact_says_which_run_wrote_each_section(tmp_path):
    """``--only SECTION`` reruns one section: the report's last lines name, for each section, the
    run that wrote it, and keep the last whole run's time (it once wrote today's date over all);
    ``--rewrite`` renders the committed report from the committed numbers."""
    sc = load_benchmark("stability_contact")
    committed = BENCH / "results" / "stability_contact.json"
    (tmp_path / "results").mkdir()
    shutil.copy(committed, tmp_path / "results")
    sc.main(["--rewrite", "--out-dir", str(tmp_path)])
    assert (tmp_path / "results" / "stability_contact.md").read_text() == committed.with_suffix(".md").read_text()
    res = json.loads(committed.read_text())
    assert set(res["runs"]) == set(sc.SECTIONS)
    sc.stamp(res, ["base"], commit="abc1234", date="2026-12-08")
    text = " ".join(sc.provenance(res))
    assert "fold, onset: committed in 1f0c934 (2026-12-06" in text and "base: run at abc1234 (2026-12-08" in text
    assert "lifted: committed in f4c37fc" in text and "took 311 s" in text
    sc.stamp(res, sc.SECTIONS, seconds=5.0, commit="def5678", date="2026-12-09")
    text = " ".join(sc.provenance(res))
    assert "fold, base, lifted, onset, closed: run at def5678 (2026-12-09" in text and "took 5 s" in text
    assert "1f0c934" not in text
    with pytest.raises(SystemExit):
        sc.main(["--only", "base", "--out-dir", str(tmp_path / "empty")])  # no stored sections to keep


def test_contact_estimate_reads_the_afm_files_the_repository_ships():
    """The step contact_estimate passes ``--afm-dir tests/data/afm`` (on a fresh machine there is no
    other); its estimates there are the committed table's for the same files, which was made on all
    of afmformats' test files (tests/data/afm/README.md names where each file came from)."""
    ce = load_benchmark("contact_estimate")
    step = {s.name: s for s in load_benchmark("steps").STEPS}["contact_estimate"]
    for args in (step.full, step.quick):
        afm = BENCH.parent / args[args.index("--afm-dir") + 1]
        assert afm.is_dir()
    rows = {r[0]: r[1:3] for r in _table("\n".join(ce.afm_lines(afm, None))) if "#" in r[0]}
    committed = {r[0]: r[1:3] for r in _table((BENCH / "results" / "contact_estimate.md").read_text())}
    renamed = {"SiN_FD_plot.ibw#1": "fmt-igor-fd_SiN_FD_plot.ibw#1",
               "flipsign_2015.05.22-15.31.49.352.jpk-force#0": "fmt-jpk-fd_flipsign_2015.05.22-15.31.49.352.jpk-#0",
               "spot3-0192.jpk-force#0": "fmt-jpk-fd_spot3-0192.jpk-force#0",
               **{f"qi-data-2x2.jpk-qi-data#{i}": f"fmt-jpk-fd_2020.02.07-16.29.05.036.jpk-qi-data#{i}"
                  for i in range(4)}}
    assert set(rows) == set(renamed)
    for name, row in rows.items():
        assert row == committed[renamed[name]], name


def test_profile_solid_quick_mode_is_its_own():
    """profile_solid.py --quick: its own walls and depths, afresh, into *-quick files; the report
    leaves out the pole thicknesses it did not solve."""
    ps = load_benchmark("profile_solid")
    for args in (["--quick", "--pole", "0.025"], ["--quick", "--recompute"], ["--pole", "0.3"]):
        with pytest.raises(SystemExit) as e:
            ps.main(args + ["--out-dir", str(BENCH / "nope")])
        assert e.value.code == 2, args
    assert not (BENCH / "nope").exists()
    committed = json.loads((BENCH / "results" / "profile_solid.json").read_text())
    cache = {ps.key(p, n): committed[ps.key(p, n)] for p, n in ps.QUICK_WALLS}
    text = ps.report(cache, ps.argparse.Namespace(quick=True, mesh_check=False))
    assert "--quick --no-mesh-check" in text and "# H0 = 0.025" in text and "# H0 = 0.0125" not in text
    assert "profile, Kirchhoff | profile, shear | uniform H0, Kirchhoff | uniform H0, shear |" in text


@pytest.mark.slow
def test_profile_solid_quick_solids_are_the_full_runs(tmp_path):
    """The quick mode's solids (~25 s CPU) at the committed run's first depths: the same forces."""
    ps = load_benchmark("profile_solid")
    r = _run("profile_solid", "--quick", "--out-dir", str(tmp_path))  # a process: its pool pickles fe_case
    assert r.returncode == 0, r.stderr[-2000:]
    quick = json.loads((tmp_path / "results" / "profile_solid-quick.json").read_text())
    committed = json.loads((BENCH / "results" / "profile_solid.json").read_text())
    for p, n in ps.QUICK_WALLS:
        q, c = quick[ps.key(p, n)], committed[ps.key(p, n)]
        assert q["success"] and q["delta"] == pytest.approx([p * k for k in ps.QUICK_DEPTHS])
        np.testing.assert_allclose(q["force"], c["force"][:len(q["force"])], rtol=1e-6)
        assert c["delta"][:len(q["delta"])] == pytest.approx(q["delta"])
    assert (tmp_path / "results" / "profile_solid-quick.md").exists()
