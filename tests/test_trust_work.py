"""Bounded work and honest options (issue 59, items 6-7) and stated stability verdicts (issue 56, item 5)."""

import json
import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

import shellbvp as sb
from shellbvp.cli import main
from shellbvp.curve_stability import assess, verdict
from shellbvp.io import FirstInstability
from shellbvp.modal_stability import stability_size

NEO = sb.Scene.preset("base", material=sb.NeoHookean())


def test_fe_size_is_the_mesh_fe_curve_builds():
    from shellbvp.fe import FE_DEFAULTS, _build, fe_size

    pytest.importorskip("felupe")
    size = fe_size(NEO, 0.1)
    model = _build(NEO, 0.1, **{k: v for k, v in FE_DEFAULTS.items() if k not in ("tol", "delta_tol")})
    assert size.elements == model.elements
    assert size.dofs == sum(f.values.size for f in model.field.fields)


def test_an_oversized_solid_is_refused_from_its_estimate():
    from shellbvp.fe import fe_size

    with pytest.raises(ValueError, match=r"31426x3 elements, 1,634,166 unknowns.*over the limit of 50,000"):
        sb.fe_curve(NEO, 1e-4, [1e-4])  # issue 59: 3.4 GB in 12 s, then a traceback
    with pytest.raises(ValueError, match="over the limit of 1,000"):
        sb.validate(NEO, thickness=0.05, max_dofs=1000)
    with sb.options(max_fe_dofs=1000), pytest.raises(ValueError, match="over the limit of 1,000"):
        sb.fe_curve(NEO, 0.05, [0.05])
    for bad in (0, -5, 2.5, "many"):
        with pytest.raises(ValueError, match="max_dofs must be a positive integer"):
            sb.fe_curve(NEO, 0.05, [0.05], max_dofs=bad)
    # the estimate stays cheap however thin: the count is not enumerated past 1e5 elements
    assert fe_size(NEO, 1e-9).elements[0] > 1e9


def test_stability_cost_grows_like_one_over_sqrt_beta_and_is_refused_over_the_limit():
    small, large = (stability_size(sb.Scene.preset("base", beta=b))[2] for b in (1e-5, 1e-9))
    assert 50 < large / small < 200  # elements and modes both ~ beta^(-1/4)
    state = sb.solve(sb.Scene.preset("base"), delta=0.3)
    with pytest.raises(ValueError, match=r"stability: beta = 0.01 needs .* unknowns .* over the limit of 10 "):
        sb.stability(state, modes=range(4), max_dofs=10)
    res = sb.stability(state, modes=(n for n in range(3)))  # a generator: counted without being used up
    assert list(res.modes) == [0, 1, 2]


def test_cli_refuses_oversized_work_in_one_line(capsys):
    cases = [(["validate", "--neo-hookean", "--thickness", "1e-4"], "the 3D solid would need"),
             (["validate", "--neo-hookean", "--thickness", "0.05", "--max-fe-dofs", "100"], "limit of 100 "),
             (["curve", "--beta", "1e-9", "--stability", "locate"], "stability: beta = 1e-09 needs"),
             (["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--beta", "1e-9", "--stability"],
              "stability: beta = 1e-09 needs"),
             (["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--neo-hookean", "--thickness", "30nm",
               "--model", "solid"], "the 3D solid would need"),
             (["fit", "--example", "--preset", "fit", "--radius", "0.3mm", "--max-nodes", "5"], "--max-nodes"),
             (["curve", "--max-nodes", "5"], r"--max-nodes: must be an integer in \[100"),
             (["curve", "--max-stability-dofs", "0"], "must be a positive integer")]
    for argv, message in cases:
        assert _exit_status(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("shellbvp: error:"), (argv, err)
        assert re.search(message, err), (argv, err)


def _exit_status(argv):
    """``main(argv)``'s exit status, also where argparse exits."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def test_cli_commands_without_a_solve_take_no_solver_options(capsys):
    for argv in (["convexity", "--tol", "1e-3"], ["compile", "--max-nodes", "100"]):
        assert _exit_status(argv) == 2
        assert "unrecognized arguments" in capsys.readouterr().err


def test_every_accepted_option_is_read():
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))
    try:
        from trust_work import unread_options
    finally:
        sys.path.pop(0)
    unread = [f"{cmd} {opt}" for cmd, opts in unread_options().items() for opt, read in opts if not read]
    assert unread == []


def test_a_solve_that_runs_out_of_memory_is_a_failed_status(monkeypatch):
    import scipy.integrate

    def exhausted(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(scipy.integrate, "solve_bvp", exhausted)
    s = sb.solve(sb.Scene.preset("base"), delta=0.1)
    assert not s.success and "memory ran out" in s.message


def test_first_instability_with_an_unknown_bracket_end_is_strict_json():
    first = FirstInstability(0.1, 0.5, 2, False, (math.nan, 0.1), "unstable from the first state analysed")
    text = json.dumps(first.to_dict(), allow_nan=False)
    back = FirstInstability.from_dict(json.loads(text))
    assert back.bracket[1] == 0.1 and math.isnan(back.bracket[0]) and back.delta == 0.1


def test_a_stable_curve_says_so_in_memory_and_from_its_file(tmp_path):
    c = sb.curve(sb.Scene.preset("base"), deltas=[0.1, 0.2], estimate_error=False)
    assess(c, "off")
    assert verdict(c) == "stability: not checked"
    seen = []
    assess(c, "points", progress=seen.append)
    assert seen == [pytest.approx(0.1), pytest.approx(0.2)]
    line = verdict(c)
    assert line.startswith("stability: checked, stable to delta = 0.2 (2 of 2 states analysed, modes n = 0..")
    c.to_hdf5(tmp_path / "c.h5")
    assert verdict(sb.read_curve(tmp_path / "c.h5")) == line
    c.first_instability = FirstInstability(0.15, 0.3, 1, False, (0.1, 0.2), "between two recorded points")
    assert "loses axisymmetric stability at delta = 0.15" in verdict(c)
    c.points["stability_min"] = np.full(2, np.nan)
    c.settings["stability_note"] = "the state did not converge"
    assert verdict(c) == "stability: not checked at any state (the state did not converge)"
