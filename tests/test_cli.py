"""The shellbvp command line (subprocess: what a user runs)."""

import json
import os
import subprocess
import sys

import h5py
import pytest

import shellbvp as sb


def run(*args, cwd=None):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "shellbvp", *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=600)


def test_curve_without_arguments_writes_base_h5(tmp_path, cli_main):
    r = run(cwd=tmp_path)  # python -m shellbvp, as a user's first run; the checks after it in this process
    assert r.returncode == 0, r.stderr
    assert "wrote base.h5" in r.stdout and " s" in r.stdout
    c = sb.read_curve(tmp_path / "base.h5")
    assert c.complete and c.delta[-1] == pytest.approx(0.5) and c.scene == sb.Scene.preset("base")
    # no progress bar when not on a terminal: at most a plain line every options.progress_seconds
    # (a loaded machine takes that long)
    assert "\r" not in r.stderr and all(line.startswith("curve base: delta") for line in r.stderr.splitlines())
    first = (tmp_path / "base.h5").read_bytes()
    again = cli_main(cwd=tmp_path)  # the quick start twice: a new name, the first result kept
    assert again.returncode == 0 and "wrote base-2.h5" in again.stdout, again.stderr
    assert (tmp_path / "base.h5").read_bytes() == first
    taken = cli_main("curve", "-o", "base.h5", cwd=tmp_path)  # a name given: never replaced without --overwrite
    assert taken.returncode == 2 and "exists" in taken.stderr and "--overwrite" in taken.stderr
    info = cli_main("info", "base.h5", cwd=tmp_path)
    assert info.returncode == 0 and "delta_max = 0.5 reached" in info.stdout and "gamma=1" in info.stdout


def test_curve_with_options_and_points(tmp_path):
    r = run("curve", "--preset", "flat", "--beta", "0.02", "--contact", "paper", "--points", "4",
            "--delta-max", "0.2", "--radius", "1mm", "--muH", "52N/m", "-o", "f.h5", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "R_L = 1 mm and mu*H = 52 N/m: displacement up to 0.2 mm" in r.stdout, r.stdout
    with h5py.File(tmp_path / "f.h5") as f:
        g = f["entry/curve"]
        assert g.attrs["scene_beta"] == 0.02 and g.attrs["scene_contact"] == "paper"
        assert len(g["delta"]) == 4 and "force_N" in g and g.attrs["R_L_m"] == 0.001


def test_solve_prints_state_and_json(tmp_path, cli_main):
    run = cli_main  # the command's main in this process (python -m shellbvp: the tests above)
    r = run("solve", "--preset", "base", "--delta", "0.2", "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert out["success"] and out["delta"] == 0.2
    assert out["force"] == pytest.approx(sb.solve(sb.Scene.preset("base"), delta=0.2).force, abs=1e-8)
    r = run("solve", "--preset", "base", "--delta", "0.2", "--radius", "300um", "--muH", "52N/m", "--json")
    si = json.loads(r.stdout)
    assert si["displacement_m"] == pytest.approx(0.2 * 300e-6) and si["force_N"] == pytest.approx(52 * 3e-4 * si["force"])
    r = run("solve", "--preset", "base", "--delta", "0.2", "--radius", "300um", "--muH", "52N/m")
    assert "displacement: 60 um" in r.stdout and "force (SI): 0.005677 N" in r.stdout
    r = run("solve", "--load", str(out["force"]), "--profiles")
    assert r.returncode == 0 and "lambda_theta" in r.stdout and "0.2" in r.stdout


def test_presets_lists_all():
    r = run("presets")
    assert r.returncode == 0
    for name in sb.PRESETS:
        assert name in r.stdout


@pytest.mark.parametrize("args,words", [
    (["curve", "--rho", "-0.2", "-o", "x.h5"], ["rho", "> 0"]),
    (["curve", "--beta", "-1", "-o", "x.h5"], ["beta", "> 0"]),
    (["curve", "--gamma", "5", "-o", "x.h5"], ["gamma", "< 5"]),
    (["curve", "--alpha", "2", "-o", "x.h5"], ["alpha", "[0, 1]"]),
    (["curve", "--gent-jm", "0", "-o", "x.h5"], ["Jm", "> 0"]),
    (["curve", "--delta-max", "0", "-o", "x.h5"], ["delta_max", "> 0"]),
    (["curve", "--preset", "nope", "-o", "x.h5"], ["preset", "base"]),
    (["curve", "-o", "/nonexistent-dir/x.h5"], ["directory", "not exist"]),
    (["info", "missing.h5"], ["missing.h5", "no such file"]),
    (["solve", "--delta", "-1"], ["delta", "> 0"]),
    (["curve", "--xi", "3"], ["xi"]),
    # quantities carry their unit in every subcommand; a bare number says which unit to add
    (["curve", "--radius", "0.3", "--muH", "52N/m", "-o", "x.h5"], ["--radius", "needs a unit", "0.3mm"]),
    (["curve", "--radius", "0.3mm", "--muH", "52", "-o", "x.h5"], ["--muH", "needs a unit", "52N/m"]),
    (["fit", "--example", "--radius", "0.3"], ["--radius", "needs a unit", "0.3mm"]),
    (["fit", "--example", "--radius", "0.3 blorp"], ["--radius", "unknown length unit", "mm"]),
    (["fit", "--example", "--radius", "0mm"], ["--radius", "> 0"]),
    (["curve", "--radius", "0.3mm", "--muH", "52N", "-o", "x.h5"], ["--muH", "unknown mu_H unit", "N/m"]),
])
def test_bad_input_exits_with_one_line_message(tmp_path, cli_main, args, words):
    r = cli_main(*args, cwd=tmp_path)  # in this process: the same checks (the entry point: the tests around)
    assert r.returncode == 2, (r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_info_rejects_foreign_and_corrupt_files(tmp_path, cli_main):
    with h5py.File(tmp_path / "foreign.h5", "w") as f:
        f["x"] = [1]
    (tmp_path / "corrupt.h5").write_bytes(b"not hdf5 at all")
    for name in ("foreign.h5", "corrupt.h5"):
        r = cli_main("info", name, cwd=tmp_path)  # in this process
        assert r.returncode == 2 and name in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("argv", [["solve", "--gamma", "5_0"], ["solve", "--delta", "inf"], ["solve", "--rho", "nan"],
                                  ["curve", "--delta-max", "1e999"], ["solve", "--beta", "１"],
                                  ["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--fit-beta",
                                   "--beta-range", "5_0,1"]])
def test_numbers_python_reads_but_a_person_would_not_write_are_refused(argv, capsys):
    from shellbvp.cli import main

    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own error exit
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("shellbvp: error:") and "Traceback" not in err
    assert "plain finite number" in err or "two numbers" in err, err


@pytest.mark.parametrize("argv", [["fit", "--json", "--example", "--radius"], ["solve", "--json", "--delta", "5"],
                                  ["solve", "--json", "--delta", "5_0"], ["solve", "--json", "--bogus"]])
def test_json_runs_print_one_json_document_on_bad_input_too(argv, capsys):
    from shellbvp.cli import main

    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    out = capsys.readouterr().out
    doc = json.loads(out)  # exactly one document: json.loads refuses trailing text
    assert code == 2 and doc["exit_status"] == 2 and doc["success"] is False and doc["message"]


def test_version(capsys):
    from shellbvp.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"shellbvp {sb.__version__}"


@pytest.mark.parametrize("argv, words", [
    (["fit", "--frobnicate"], "unrecognized arguments: --frobnicate"),  # not "--radius is required"
    (["fit", "--example", "--frobnicate", "--json"], "unrecognized arguments: --frobnicate"),
    (["sweep", "--frobnicate"], "unrecognized arguments: --frobnicate"),
    (["fit", "--example"], "the following arguments are required: --radius/--rim-radius"),
    (["plot"], "the following arguments are required: files")])
def test_an_unknown_option_is_reported_before_a_missing_one(argv, words, capsys):
    from shellbvp.cli import main

    with pytest.raises(SystemExit) as exc:
        main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and err == f"shellbvp: error: {words}\n"


def test_fit_names_its_sample_in_lab_units(capsys):
    """No silent default scene: fit needs a preset or the geometry; lengths in lab units give the
    same scene as the ratios, and the summary names it in those units."""
    from shellbvp.cli import main

    assert main(["fit", "--example", "--radius", "0.3mm"]) == 2
    err = capsys.readouterr().err
    assert "fit needs the sample" in err and "--indenter-radius" in err and "--rise" in err
    assert main(["fit", "--example", "--radius", "0.3mm", "--rho", "0.3333", "--gamma", "2.5"]) == 2
    assert "missing its bending stiffness" in capsys.readouterr().err
    assert main(["fit", "--example", "--rim-radius", "0.3mm", "--indenter-radius", "100um", "--rise", "0.75mm",
                 "--thickness", "15um", "--json", "--model", "shell"]) == 0      # the scene's units, not the model
    lab = json.loads(capsys.readouterr().out)
    assert main(["fit", "--example", "--radius", "0.3mm", "--preset", "fit", "--thickness", "0.05", "--json",
                 "--model", "shell"]) == 0
    preset = json.loads(capsys.readouterr().out)
    assert lab["mu_H"] == pytest.approx(preset["mu_H"], rel=1e-9)
    assert main(["fit", "--example", "--radius", "0.3mm", "--preset", "fit", "--thickness", "15um", "--model",
                 "shell"]) == 0
    out = capsys.readouterr().out
    assert "scene  = preset fit with thickness; shell: spheroidal bowl (indented from inside), rise 750 um (gamma 2.5)" in out
    assert "indenter: sphere of radius 100 um" in out and "thickness 15 um" in out
    assert main(["solve", "--indenter-radius", "0.1mm"]) == 2
    assert "--indenter-radius 0.1 mm is a length: it needs --radius" in capsys.readouterr().err


def test_a_dome_in_lab_units_by_a_negative_rise_or_dome(capsys, tmp_path):
    """Issue 56 item 4: `--rise -5um` was an argparse error and a positive rise always a bowl.  A
    negative rise (both spellings) and `--rise 5um --dome` give the dome gamma = -rise/R_L; the
    summary says bowl or dome; contradictions are one-line errors."""
    from shellbvp.cli import build_parser, main, scene_from_args

    def scene(*options):
        return scene_from_args(build_parser().parse_args(["solve", "--radius", "10um", "--indenter-radius", "2.5um",
                                                          *options]))

    for options in (["--rise", "-5um"], ["--rise=-5um"], ["--rise", "5um", "--dome"], ["--gamma", "-0.5"]):
        assert scene(*options).gamma == pytest.approx(-0.5), options
    assert scene("--rise", "5um").gamma == pytest.approx(0.5)
    assert scene("--gamma", "-5e-1").gamma == pytest.approx(-0.5)  # a negative number in any spelling is a value
    assert "dome (indented from outside), rise 5 um (gamma -0.5)" in scene("--rise", "-5um").describe(10e-6)
    assert "bowl (indented from inside), rise 5 um (gamma 0.5)" in scene("--rise", "5um").describe(10e-6)
    for options, says in ((["--rise", "-5um", "--dome"], "give the dome's height as a length > 0"),
                          (["--gamma", "-0.5", "--dome"], "--dome goes with --rise")):
        assert main(["solve", "--radius", "10um", "--muH", "1N/m", *options]) == 2
        err = capsys.readouterr().err
        assert err.startswith("shellbvp: error: ") and says in err and err.count("\n") == 1, err
    assert main(["curve", "--radius", "10um", "--muH", "1N/m", "--indenter-radius", "2.5um", "--rise", "5um",
                 "--dome", "--thickness", "0.5um", "--points", "2", "--delta-max", "0.02", "-o",
                 str(tmp_path / "dome.h5"), "-q"]) == 0
    assert "shell: spheroidal dome (indented from outside), rise 5 um (gamma -0.5)" in capsys.readouterr().out


def test_every_option_has_help():
    from shellbvp.cli import build_parser

    p = build_parser()
    bare = [(name, a.option_strings) for name, sp in p._subparsers._group_actions[0].choices.items()
            for a in sp._actions if a.option_strings and a.help is None]
    assert bare == []


def test_depths_and_forces_in_lab_units_are_made_nondimensional_by_the_scales(tmp_path, cli_main):
    """``solve --delta 60um``, ``--force 5.7mN`` and ``curve --delta-max 60um`` with --radius
    (and --muH for a force) are the model's delta = 60 um / R_L and F = F / (mu H R_L); without
    the scales, a one-line error names what is missing."""
    run = cli_main  # in this process
    r = run("solve", "--preset", "base", "--delta", "60um", "--radius", "0.3mm", "--muH", "52N/m", "--json")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["delta"] == pytest.approx(0.2, rel=1e-12)
    r = run("solve", "--preset", "base", "--force", "5.7mN", "--radius", "0.3mm", "--muH", "52N/m", "--json")
    assert json.loads(r.stdout)["force"] == pytest.approx(5.7e-3 / (52 * 0.3e-3), rel=1e-9)
    r = run("solve", "--preset", "base", "--delta", "60um")
    assert r.returncode == 2 and "--delta 60 um needs --radius" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = run("solve", "--preset", "base", "--force", "5mN", "--radius", "0.3mm")
    assert r.returncode == 2 and "needs --radius and --muH" in r.stderr
    out = tmp_path / "c.h5"
    r = run("curve", "--delta-max", "60um", "--points", "2", "--radius", "0.3mm", "--muH", "52N/m", "-o", str(out), "-q")
    assert r.returncode == 0, r.stderr
    assert sb.read_curve(out).delta[-1] == pytest.approx(0.2, rel=1e-9)


def test_validate_takes_its_depth_in_lab_units_with_the_rim_radius(tmp_path, cli_main):
    """validate --delta-max 1mm with --radius 0.3mm is 3.33 rim radii: refused by its range, in
    rim radii, before the 3D model is built; without --radius the unit is refused by name."""
    run = cli_main  # in this process
    r = run("validate", "--thickness", "0.05", "--delta-max", "1mm", "--radius", "0.3mm", cwd=tmp_path)
    assert r.returncode == 2 and "--delta-max must be in (0, 2]; got 3.33333" in r.stderr, r.stderr
    r = run("validate", "--thickness", "0.05", "--delta-max", "100um", cwd=tmp_path)
    assert r.returncode == 2 and "--delta-max 100 um needs --radius" in r.stderr, r.stderr


def test_sweep_takes_its_depth_and_force_in_lab_units_as_curve_does(tmp_path):
    """sweep --delta-max 60um --force-max 5mN with --radius 0.3mm --muH 52N/m: every curve of the
    file runs to delta = 60 um / R_L and stops at F = 5 mN / (mu H R_L); without a scale, a one-line
    error names the one missing, before any curve."""
    out = tmp_path / "g.h5"
    r = run("sweep", "--rho", "0.2,0.25", "--delta-max", "60um", "-o", str(out), cwd=tmp_path)
    assert r.returncode == 2 and "--delta-max 60 um needs --radius" in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not out.exists()
    r = run("sweep", "--rho", "0.2,0.25", "--delta-max", "0.2", "--force-max", "5mN", "--radius", "0.3mm",
            "-o", str(out), cwd=tmp_path)
    assert r.returncode == 2 and "missing --muH" in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not out.exists()
    r = run("sweep", "--rho", "0.2,0.25", "--delta-max", "60um", "--force-max", "5mN", "--radius", "0.3mm",
            "--muH", "52N/m", "--points", "3", "--workers", "1", "-q", "-o", str(out), cwd=tmp_path)
    assert r.returncode == 1, r.stderr  # both curves stop at the force: 'stopped', not 'complete'
    grid = sb.read_sweep(out)
    assert grid.delta_max == pytest.approx(60e-6 / 0.3e-3, rel=1e-12)
    assert sorted(grid.curves) == [0, 1]
    for curve in grid.curves.values():
        assert curve.force[-1] >= 5e-3 / (52 * 0.3e-3) > curve.force[-2]
        assert "force_max" in curve.stop_reason


def test_data_in_bare_si_is_printed_in_units_that_suit_its_size(tmp_path):
    # AFM files come in m and N: a fit of a 2 um, 3 nN curve prints um and nN (files keep SI)
    from shellbvp.cli.handlers.fit import _shown_units
    from shellbvp.units import readable_unit

    assert [readable_unit(v, "length") for v in (0.3, 2e-3, 2e-6, 1.5e-7, 1e-12, 0.0)] == ["mm", "mm", "um", "nm",
                                                                                        "nm", "m"]
    assert [readable_unit(v, "force") for v in (2.0, 3e-9, -4e-11)] == ["N", "nN", "pN"]
    si, mm = tmp_path / "si.csv", tmp_path / "mm.csv"
    si.write_text("displacement (m),force (N)\n" + "".join(f"{i * 2e-7:.3e},{i * i * 3e-11:.3e}\n"
                                                            for i in range(11)))
    mm.write_text("displacement (mm),force (N)\n0,0\n0.001,1e-9\n0.002,3e-9\n0.003,6e-9\n")
    assert _shown_units(sb.read_instrument(si)) == ("um", "nN")
    assert _shown_units(sb.read_instrument(mm)) == ("mm", "nN")  # the data's own unit where it has one


def test_code_generation_is_announced_on_a_terminal_only(capsys, monkeypatch):
    # the first run of a structure waits 5-25 s for its code: a terminal is told why
    import argparse
    import io
    import logging

    from shellbvp.cli.common import show_code_generation

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    log = logging.getLogger("shellbvp.model")
    monkeypatch.setattr(log, "handlers", [])
    monkeypatch.setattr(log, "propagate", log.propagate)
    level = log.level
    try:
        for quiet, stream in ((True, Terminal()), (False, io.StringIO())):  # -q, or stderr a file: nothing
            show_code_generation(argparse.Namespace(verbose=False, quiet=quiet), stream)
            assert log.handlers == []
        show_code_generation(argparse.Namespace(verbose=False, quiet=False), Terminal())
        log.info("deriving %s", "x")
        log.debug("not shown")
        assert capsys.readouterr().err == "shellbvp: deriving x\n"
    finally:
        log.setLevel(level)  # setLevel, not the attribute: it clears logging's cache


def test_solve_offers_every_configuration_the_registry_lets_be_asked_for(capsys):
    """`solve --topology` takes its choices from the registry (issue 57), not from a list of its own."""
    from shellbvp.cli import main
    from shellbvp.configurations import asked

    assert main(["solve", "--topology", "no-such-configuration"]) == 2
    err = capsys.readouterr().err
    assert all(name in err for name in asked()) and len(asked()) > 4
