"""The benchmark driver (benchmarks/run.py) and the work–precision helpers.

The fast tests check the plan and argument parsing only; the slow one runs
``run.py --quick`` into a temporary directory (a smoke test of every step).
"""

import functools
import importlib.util
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import pytest
from benchmark_modules import load_benchmark

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"


@functools.lru_cache(maxsize=1)
def _census():
    """This checkout's census, measured once for the tests that read it (~7 s each)."""
    return _load("architecture").census()


def _load(name):
    return load_benchmark(name)


@pytest.fixture(scope="module")
def run():
    return _load("run")


@pytest.fixture(scope="module")
def wp():
    return _load("work_precision")


def test_every_script_is_a_step_or_a_listed_tool(run):
    """A script added to benchmarks/ must be given a step in benchmarks/steps.py or be listed
    there as a tool (with the reason); a listed tool must exist."""
    steps = _load("steps")
    scripts = {p.name for p in BENCH.glob("*.py")}
    in_plan = {s.script for s in steps.STEPS}
    stray = sorted(scripts - in_plan - set(steps.TOOLS))
    assert not stray, f"neither a step nor a tool in benchmarks/steps.py: {stray}"
    assert not (in_plan | set(steps.TOOLS)) - scripts, "a step or tool without its script"
    assert not in_plan & set(steps.TOOLS), "both a step and a tool"
    assert all(why.strip() for why in steps.TOOLS.values())


def test_every_result_file_is_written_by_a_step_or_kept_as_a_record():
    """Each file of benchmarks/results/ is an output of a step (full or quick) or a record listed
    with why it is kept (a run at another commit, text kept by hand)."""
    steps = _load("steps")
    unclaimed = sorted(p.name for p in (BENCH / "results").iterdir() if p.is_file() and not steps.claimed(p.name))
    assert not unclaimed, unclaimed
    assert steps.claimed("stability-quick.json") and not steps.claimed("stability-nope.json")
    for pattern in steps.RECORDS:  # a record that no longer exists is dropped from the list
        assert list((BENCH / "results").glob(pattern)), pattern


def test_full_plan_regenerates_everything(run):
    steps = _load("steps")
    names = [s.name for s in steps.STEPS]
    assert len(names) == len(set(names))
    planned = [s.name for s, _ in run.plan()]
    assert set(names) - set(planned) <= {"paper_figures"} | {s.name for s in steps.STEPS if s.needs}
    for s, argv in run.plan():
        assert argv[0] == sys.executable and Path(argv[1]).exists()
        assert "--quick" not in argv and s.outputs
        assert all(o.startswith(("results/", "figures/")) for o in s.outputs)
    assert "paper_figures" in [s.name for s, _ in run.plan(figures=True)]
    assert {s.group for s in steps.STEPS} == set(steps.GROUPS)


def test_the_out_option_of_each_step_is_one_its_script_takes():
    """``out="dir"``: the script takes --out-dir (through checkout.add_output_args, or its own);
    ``out=None``: it takes none yet (when it does, the plan must pass it); a quick mode is the
    script's own --quick."""
    steps = _load("steps")
    for s in steps.STEPS:
        src = (BENCH / s.script).read_text()
        takes_dir = "add_output_args(" in src or '"--out-dir"' in src
        if s.out == "dir":
            assert takes_dir, s.name
        elif s.out is None:
            assert not takes_dir, f"{s.name}: its script takes --out-dir now: set out='dir' in steps.py"
        else:
            assert f'"{s.out[0]}"' in src, s.name
        if s.quick is not None:
            assert s.quick[0] == "--quick" and ('"--quick"' in src or "quick=" in src), s.name


def test_quick_plan_writes_separate_files(run, tmp_path):
    skipped = []
    steps = run.plan(quick=True, out=tmp_path, skipped=skipped)
    names = [s.name for s, _ in steps]
    assert "work_precision" in names and "shooting" not in names and "paper_figures" not in names
    for s, argv in steps:
        assert "--quick" in argv
        if s.out == "dir":
            assert argv[argv.index("--out-dir") + 1] == str(tmp_path)
        else:
            assert argv[argv.index(s.out[0]) + 1].startswith(str(tmp_path / "results") + "/")
        assert s.quick_outputs and all("-quick" in o for o in s.quick_outputs)
    assert {s.name for s, _ in skipped} | set(names) == {s.name for s in _load("steps").STEPS}
    # --out: every step writes under it (bending_choice, stability_contact, thick_fits and closed_solid
    # took no output option before); a step without one is left out rather than write into benchmarks/
    full = run.plan(figures=True, out=tmp_path)
    assert [s.name for s, _ in full] == [s.name for s, _ in run.plan(figures=True)]
    lone = _load("steps").Step("x", "x.py", "model", out=None)
    assert lone.argv(False, None, "py") and lone.argv(False, tmp_path, "py") is None
    for s, argv in full:  # nothing of benchmarks/ named as an output
        assert str(tmp_path) in " ".join(argv) or s.out == "dir" and "--out-dir" in argv, s.name
        assert not any(a.startswith(str(BENCH / "results")) for a in argv), s.name
    shoot = dict((s.name, a) for s, a in run.plan(out=tmp_path))["shooting"]
    assert shoot[shoot.index("--out") + 1] == str(tmp_path / "results" / "shooting.json")
    shoot = dict((s.name, a) for s, a in run.plan())["shooting"]
    assert shoot[shoot.index("--out") + 1] == str(BENCH / "results" / "shooting.json")


def test_arguments(run):
    a = run.parse_args(["--quick", "--only", "work_precision,profile", "--out", "/tmp/x"])
    assert a.quick and a.only == ["work_precision", "profile"] and a.out == "/tmp/x"
    assert [s.name for s, _ in run.plan(a.quick, a.only, a.figures, a.out)] == ["work_precision", "profile"]
    by_group = [s.name for s, _ in run.plan(only=["stability", "vella"])]
    assert by_group[:2] == ["vella", "stability"]  # plan order: vella (model) before the stability group
    assert "hoop_indicator" in by_group and by_group[-1] == "stability_pressure"
    assert [s.name for s, _ in run.plan(only=["model"])][-1] == "vella"
    with pytest.raises(ValueError, match="unknown steps"):
        run.plan(only=["nope"])
    assert run.main(["--only", "nope"]) == 2


def test_list(run, capsys):
    assert run.main(["--list", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "work_precision.py --quick" in out and "shooting" in out
    assert "shooting precision: left out: no quick mode" in " ".join(out.split())


def test_work_precision_arguments(wp):
    q = wp.parse_args(["--quick"])
    assert q.presets == ["base"] and q.points == 10 and q.name == "work_precision-quick" and q.every_1e10 == 0
    f = wp.parse_args([])
    assert f.presets == list(wp.PRESETS) and f.points == 40 and f.tols == wp.TOLS and f.shoot == ["base"]
    assert f.name == "work_precision"


def test_time_at_equal_error(wp):
    series = [(1e-3, 1.0), (1e-5, 2.0), (1e-7, 4.0)]
    t, how = wp.time_at_error(series, 1e-4)
    assert how == "interp" and t == pytest.approx(math.sqrt(2.0))
    assert wp.time_at_error(series, 1e-9) == (None, "not reached")
    assert wp.time_at_error(series, 1e-2) == (1.0, "bound")
    # a slower run that is also less accurate never makes an error level more expensive
    t, _ = wp.time_at_error([(1e-3, 5.0), (1e-5, 2.0)], 1e-4)
    assert t == pytest.approx(2.0)


def test_equal_error_both_ways(wp):
    coll = [dict(tol=t, max_rel=e, per_point_ms=ms, all_converged=True, points=4)
            for t, e, ms in ((1e-4, 1e-5, 10.0), (1e-6, 1e-7, 20.0))]
    shoot = [dict(rtol=1e-6, max_rel=1e-6, max_rel_F_equal_lambda0=1e-7, per_point_ms=400.0, converged=4, points=4)]
    ee = wp.equal_error(coll, shoot, 4)
    (s,) = ee["shooting_points"]
    assert s["how"] == "interp" and s["ratio"] == pytest.approx(400 / (10 * 2 ** 0.5))
    c = {q["tol"]: q for q in ee["collocation_points"]}
    assert c[1e-4]["how"] == "bound" and c[1e-4]["ratio"] == pytest.approx(40.0)
    assert c[1e-6]["ratio"] is None  # shooting never got to 1e-7
    ee = wp.equal_error(coll, shoot, 4, "max_rel_F_equal_lambda0")
    assert ee["shooting_points"][0]["ratio"] == pytest.approx(20.0)


@pytest.mark.slow
def test_quick_run_smoke(tmp_path):
    start = time.time()
    r = subprocess.run([sys.executable, str(BENCH / "run.py"), "--quick", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=3600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    summary = json.loads((tmp_path / "results" / "run-quick.json").read_text())
    assert all(s["returncode"] == 0 for s in summary["steps"])
    ran = {s["step"] for s in summary["steps"]}
    steps = _load("steps")
    assert ran == {s.name for s in steps.STEPS if s.quick is not None}
    for s in steps.STEPS:  # every quick step wrote what the plan says it writes (kernels: only with numba)
        if s.name in ran and not (s.name == "kernels" and importlib.util.find_spec("numba") is None):
            for name in s.quick_outputs:
                assert (tmp_path / name).exists(), (s.name, name)
    wp = json.loads((tmp_path / "results" / "work_precision-quick.json").read_text())
    base = wp["presets"]["base"]
    assert all(r["all_converged"] for r in base["natural"])
    assert max(r["max_rel"] for r in base["natural"]) < 1e-3
    # nothing written into the committed results
    assert not [p.name for p in (BENCH / "results").iterdir() if p.stat().st_mtime >= start]


def test_speed_vs_baseline_compares_points_of_the_same_depth_and_topology():
    sv = _load("speed_vs_baseline")
    ref = dict(delta=[0.1, 0.2, 0.3], force=[1.0, 2.0, 3.0], topology=["line", "cap", "cap"])
    run = dict(delta=[0.1, 0.2, 0.3], force=[1.5, 2.0 + 2e-7, 3.0 - 3e-6], topology=["cap", "cap", "cap"])
    worst, compared, left = sv.f_error(run, ref)
    assert compared == 2 and left == 1  # the depth where the reference is a line: left out
    assert worst == pytest.approx(1e-6)
    assert list(sv._distinct([0.3, 0.1, 0.1 * (1 + 1e-14), 0.2])) == [0.1, 0.2, 0.3]
    with pytest.raises(SystemExit):
        sv.parse_args(["--repeat", "0"])


def test_speed_vs_baseline_shooting_ratio_takes_the_cheapest_shooting_at_equal_or_better_error():
    sv = _load("speed_vs_baseline")
    shots = [dict(rtol=1e-6, per_point_ms=100.0, max_rel=5e-7, converged=20, points=20),  # too inaccurate
             dict(rtol=1e-7, per_point_ms=150.0, max_rel=2e-7, converged=19, points=20),  # one failed
             dict(rtol=1e-8, per_point_ms=200.0, max_rel=4e-8, converged=20, points=20),
             dict(rtol=1e-9, per_point_ms=300.0, max_rel=2e-9, converged=20, points=20)]
    case = dict(shooting=shots, rows={"this commit": dict(ms_per_point=20.0, f_error=3e-7)},
                same_states={"this commit": dict(ms_per_point=5.0, f_error=3e-7, compared=20, depths=20),
                             "this commit, numba": dict(ms_per_point=2.0, f_error=1e-8, compared=20, depths=20)})
    assert sv.shooting_ratio(case) == (pytest.approx(10.0), False)  # 200 / 20: rtol 1e-8
    assert sv.shooting_ratio(case, same=True) == (pytest.approx(40.0), False)  # 200 / 5
    assert sv.shooting_ratio(case, "this commit, numba", same=True) == (pytest.approx(150.0), False)  # 300 / 2
    assert sv.shooting_ratio(case, "this commit, numba") == (None, False)  # not run
    # no shooting rtol as accurate: its most accurate one's time, a lower bound
    case["same_states"]["this commit"]["f_error"] = 1e-10
    assert sv.shooting_ratio(case, same=True) == (pytest.approx(60.0), True)  # 300 / 5
    sv.ratios(case)
    assert case["shooting_ratio_same_bound"] and not case["shooting_ratio_bound"]


def test_speed_vs_baseline_shooting_states_count_near_repeats_once():
    sv = _load("speed_vs_baseline")
    d = [0.1, 0.16, 0.16 + 1e-10, 0.2, 0.2 * (1 + 2e-7), 0.25 + 3e-11, 0.25 + 5e-11]
    start = [dict(Sc=0.1, u=0.0)] * len(d)
    start[3] = None  # not a cap: not shot, and the next state is not its repeat
    assert sv.shooting_states(dict(delta=d, start=start)) == [1, 4, 5]


def test_speed_vs_baseline_continuation_time_leaves_the_first_point_out():
    sv = _load("speed_vs_baseline")
    runs = [dict(points=11, cpu=1.2, first_point_cpu=0.2), dict(points=11, cpu=1.5, first_point_cpu=0.1),
            dict(points=11, cpu=1.1, first_point_cpu=0.3)]
    assert sv._continuation_ms(runs) == pytest.approx(1e3 * 1.0 / 10)  # median of 1.0, 1.4, 0.8
    runs[1]["first_point_cpu"] = None  # a run without it: no measure
    assert sv._continuation_ms(runs) is None
    shots = [dict(rtol=1e-8, per_point_ms=200.0, max_rel=4e-8, converged=20, points=20)]
    case = dict(shooting=shots, rows={}, same_states={"this commit": dict(
        ms_per_point=5.0, continuation_ms_per_point=4.0, f_error=1e-7, compared=20, depths=20)})
    sv.ratios(case)
    assert case["shooting_ratio_same"] == pytest.approx(40.0)
    assert case["shooting_ratio_same_cont"] == pytest.approx(50.0)
    assert case["shooting_ratio_numba_same_cont"] is None  # not run


def test_speed_vs_baseline_shooting_rounds_are_merged_by_their_median_time():
    sv = _load("speed_vs_baseline")

    def row(rtol, cpu):
        return dict(rtol=rtol, points=20, converged=20, max_rel=1e-8, cpu=cpu, wall=cpu + 0.1, per_point_ms=50 * cpu)

    rounds = [[row(1e-6, 1.0), row(1e-8, 4.0)], [row(1e-6, 3.0), row(1e-8, 2.0)], [row(1e-6, 2.0), row(1e-8, 9.0)]]
    merged = sv._median_shots(rounds)
    assert [r["rtol"] for r in merged] == [1e-6, 1e-8]
    assert [r["cpu"] for r in merged] == [2.0, 4.0] and merged[1]["per_point_ms"] == pytest.approx(200.0)
    assert merged[0]["cpu_runs"] == [1.0, 3.0, 2.0] and all(r["same_every_round"] for r in merged)
    rounds[1][0]["converged"] = 19
    assert not sv._median_shots(rounds)[0]["same_every_round"]
    assert sv._median_shots([]) == []


def test_speed_vs_baseline_equal_error_both_ways_pairs_each_shooting_rtol_with_the_cheapest_tol():
    sv = _load("speed_vs_baseline")
    shots = [dict(rtol=1e-6, per_point_ms=100.0, max_rel=5e-6, converged=20, points=20),
             dict(rtol=1e-8, per_point_ms=200.0, max_rel=4e-8, converged=20, points=20),
             dict(rtol=1e-9, per_point_ms=300.0, max_rel=2e-9, converged=20, points=20)]
    tols = [dict(tol=1e-6, ms_per_point=8.0, f_error=4e-9, compared=20, depths=20),
            dict(tol=1e-5, ms_per_point=6.0, f_error=3e-8, compared=20, depths=20),
            dict(tol=1e-4, ms_per_point=4.0, f_error=2e-6, compared=19, depths=20)]  # one point not compared
    case = dict(shooting=shots, rows={}, same_states={"this commit": dict(tols[0], tols=tols)})
    pairs = sv.equal_error(case, "this commit")
    assert [(q["rtol"], q["tol"]) for q in pairs] == [(1e-6, 1e-5), (1e-8, 1e-5), (1e-9, None)]
    assert pairs[0]["ratio"] == pytest.approx(100 / 6) and pairs[1]["ratio"] == pytest.approx(200 / 6)
    sv.ratios(case)  # the smallest ratio over the accuracies both reached; the one left out counted
    assert case["shooting_ratio_both"] == pytest.approx(100 / 6) and case["shooting_ratio_both_missing"] == 1
    tols[0].update(f_error=1e-9, ms_per_point=20.0)
    sv.ratios(case)
    assert case["shooting_ratio_both"] == pytest.approx(15.0) and case["shooting_ratio_both_missing"] == 0  # 300/20


def test_point_budget_charges_each_category_its_exclusive_time():
    pb = _load("point_budget")

    class Spin:
        @staticmethod
        def inner():
            t0 = time.process_time()
            while time.process_time() - t0 < 0.02:
                pass

        @staticmethod
        def outer():
            t0 = time.process_time()
            while time.process_time() - t0 < 0.01:
                pass
            Spin.inner()

    timers = pb.Timers()
    timers.wrap(Spin, "inner", pb.KERNELS)
    timers.wrap(Spin, "outer", pb.CALLBACKS)
    Spin.outer()
    timers.remove()
    assert not hasattr(Spin.outer, "__wrapped__") and Spin.outer.__name__ == "outer"  # restored
    assert timers.calls[pb.KERNELS] == timers.calls[pb.CALLBACKS] == 1
    assert 0.02 <= timers.spent[pb.KERNELS] < 0.03
    assert 0.01 <= timers.spent[pb.CALLBACKS] < 0.02  # the inner call's time is not charged twice


def test_the_modules_split_by_job_are_none_over_600_lines():
    """benchmarks/architecture.py on this checkout: fitting, sweep, the 3D reference, the chain and
    the instrument files are split by job, none of their modules over 600 lines (at f55cc39
    ``chain`` had 851 and ``instrument`` 768)."""
    census = _census()
    split = {m: n for m, n in census["long_modules"].items()
             if m.split(".")[0] in ("fitting", "sweep", "fe", "chain", "instrument", "instrument_record", "segments")}
    assert not split, split


def test_the_structure_census_holds_what_the_redesign_reached():
    """benchmarks/architecture.py on this checkout: no natural-continuation loop written out
    beside shellbvp.march, results built in two places only (the diagnosis, failure()), and no
    .get on a result (what is left are dicts of other kinds: scene, switch, settings, points)."""
    census = _census()
    assert census["step_loops"] == []
    assert census["solution_builds"] == {"diagnosis": 1, "solution": 1}
    receivers = {where.split("(")[1].rstrip(")") for where in census["result_gets"]}
    assert receivers <= {"sc", "s", "settings", "p"}, receivers
    # configuration names are compared in the registry only, and the census knows every name
    assert set(census["name_comparisons"]) <= {"configurations.registry"}, census["name_comparisons"]
    # no function of the package named in a "module:function" string (issue 57: 16 at 011499a)
    assert census["string_hooks"] == {}, census["string_hooks"]
    # a curve's settings are written by their owner only (issue 57: 5 writes below continuation at 8e0f2e3)
    assert census["settings_writes"] == {}, census["settings_writes"]
    import ast
    seen = _load("architecture")._settings_write
    writes = ['st["x"] = 1', 'del curve.settings["x"]', 'st.setdefault("x", [])', 'settings["x"].append(1)']
    assert all(any(seen(n) for n in ast.walk(ast.parse(w))) for w in writes)
    assert not any(seen(n) for n in ast.walk(ast.parse('y = st["x"] + settings.get("x", 0)')))
    from shellbvp.configurations import CONFIGURATION_NAMES
    assert _load("architecture").configuration_names(BENCH.parent) == set(CONFIGURATION_NAMES)


def test_the_census_counts_that_are_zero_stay_zero():
    """benchmarks/architecture.py on this checkout (issue 57): no string hook, no write of a
    curve's settings below their owner, no instrument format named outside shellbvp/readers/
    (23 at 971ae76: afm_read 13, batch 6, afm_jpk 4), no contact or edge model compared by name, or
    tabled by hand, outside shellbvp/edge_models.py (26 comparisons and 8 tables at 9070cc8), no
    module over 600 lines, no natural-continuation loop written out, no write of a Solution's field
    outside solution and diagnosis (a state is built once; 37 at 9070cc8: liftoff 11, cylinder 6,
    recorder 5, state 5, inflation 4, continuation 3, legs 1, pointload 1, switches 1)."""
    census = _census()
    for key in ("string_hooks", "settings_writes", "format_names", "edge_model_comparisons", "edge_model_tables",
                "long_modules", "step_loops", "solution_writes"):
        assert not census[key], (key, census[key])


def test_function_level_imports_of_the_package_stand_where_they_are_known():
    """benchmarks/architecture.py on this checkout (issue 57): the package's imports inside functions
    are the command line's of modules that load numpy (its parser must not), and only these: each
    subcommand's module imports its handler (``cli/handlers/NAME.py``, whose imports stand at its
    top) on dispatch, and cli/scene_options.py's ``scene_from_args`` the scene (145 at eab5e9b, in 40
    modules; 59 at 33d1b76, 58 of them the command line's in its handlers)."""
    import ast

    from shellbvp.cli import COMMANDS

    census = _census()
    assert census["function_imports_package_rest"] == {}
    commands = {c.__name__.removeprefix("shellbvp.") for c in COMMANDS}
    deferred = census["function_imports_cli_deferred"]
    assert {m: n for m, n in deferred.items() if m in commands} == dict.fromkeys(commands, 1)
    assert set(deferred) - commands <= {"cli.scene_options"} and deferred.get("cli.scene_options", 0) <= 2, deferred
    assert set(census["function_imports_package"]) == set(deferred)  # none in the handlers
    for command in COMMANDS:  # the one late import of a subcommand's module is its handler's
        name = command.__name__.rpartition(".")[2]
        tree = ast.parse(Path(command.__file__).read_text())
        late = [ast.unparse(n) for f in tree.body if isinstance(f, ast.FunctionDef) for n in ast.walk(f)
                if isinstance(n, (ast.Import, ast.ImportFrom))]
        assert late == [f"from .handlers import {name}"], (name, late)


def test_the_census_knows_which_modules_load_numpy():
    """The census's reason for the command line's late imports is what importing shows: a module
    loads numpy through a package above it (chain, readers: their __init__) and a registry's
    package through the modules it discovers."""
    census = _load("architecture")
    numeric = census.numeric_modules(BENCH.parent)
    light = ["shellbvp.units", "shellbvp.cli.common", "shellbvp.scene_parameters", "shellbvp.paths"]
    heavy = ["shellbvp.scene", "shellbvp.readers.registry", "shellbvp.chain.blocks", "shellbvp.sweeps.executors"]
    assert not set(light) & numeric and set(heavy) <= numeric
    code = ("import importlib, sys\nfor m in sys.argv[1:]:\n    importlib.import_module(m)\n"
            "    print('numpy' in sys.modules)\n")
    for name in light + heavy:
        out = subprocess.run([sys.executable, "-c", code, name], capture_output=True, text=True, check=True,
                             cwd=BENCH.parent).stdout.split()
        assert out == [str(name in heavy)], name


def test_the_census_sees_what_it_counts(tmp_path):
    """Each count of issue 57 on a checkout made to hold one of each: a string hook, a write of a
    Solution's field, a table of scene parameters, late imports of the package (the command line's
    of a module that loads numpy apart) and of an optional dependency, a reader's file name ending
    outside the readers, and edge models compared by name
    and tabled (the rim's "pinned" compared is not an edge's)."""
    pkg = tmp_path / "shellbvp"
    (pkg / "configurations").mkdir(parents=True)
    (pkg / "readers").mkdir()
    (pkg / "configurations" / "cap.py").write_text('X = Configuration("cap")\n')
    (pkg / "scene.py").write_text("class Scene:\n    gamma: float = 1.0\n    rho: float = 0.2\n    xi: int = 1\n")
    (pkg / "solution.py").write_text("class Solution:\n    force: float = 0.0\n    wall_time: float = 0.0\n")
    (pkg / "readers" / "jpk.py").write_text('SUFFIXES = (".jpk-force",)\nREADERS = (Reader(name="JPK"),)\n')
    (pkg / "state.py").write_text("def solve():\n    pass\n")
    (pkg / "edge_models.py").write_text('A = EdgeModel("smooth")\nB = EdgeModel("paper")\nC = ("smooth", "paper")\n')
    (pkg / "edges.py").write_text('def g(scene, m):\n    x = scene.contact == "smooth" or scene.rim == "paper"\n'
                                  '    return m in ("smooth", "paper") or x\n')
    (pkg / "bad.py").write_text(
        'HOOK = "state:solve"\nNAMES = ("gamma", "rho")\nENDING = ".jpk-force"\n'
        'def f(sol, self):\n    import afmformats\n    from . import state\n    sol.force = 1.0\n'
        '    setattr(sol, "wall_time", 2.0)\n    self.force = 3.0\n    return ENDING == "JPK"\n')
    (pkg / "heavy.py").write_text("import numpy\n")
    (pkg / "light.py").write_text("import json\n")
    (pkg / "cli").mkdir()
    (pkg / "cli" / "__init__.py").write_text("")
    (pkg / "cli" / "run.py").write_text("def run():\n    from ..heavy import x\n    from ..light import y\n"
                                        "    from .. import light\n")
    (tmp_path / "pyproject.toml").write_text('[project.optional-dependencies]\nafm = ["afmformats>=0.18"]\n'
                                             'test = ["pytest>=7"]\n[tool.x]\n')
    census = _load("architecture").census(tmp_path)
    assert census["string_hooks"] == {"bad": 1}
    assert census["solution_writes"] == {"bad": 2}        # self.force is another class's
    assert census["parameter_tables"] == {"bad": 1}
    assert census["function_imports_package"] == {"bad": 1, "cli.run": 3}
    # the command line defers what loads numpy past its parser; the rest must move to the top
    assert census["function_imports_cli_deferred"] == {"cli.run": 1}
    assert census["function_imports_package_rest"] == {"bad": 1, "cli.run": 2}
    assert census["function_imports_optional"] == {"bad": 1}
    assert census["format_names"] == {"bad": 2}           # the ending, and the reader's name compared
    assert census["edge_model_comparisons"] == {"edges": 2}  # not the rim's, nor inside the registry
    assert census["edge_model_tables"] == {"edges": 1}
