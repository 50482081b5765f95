"""The one natural continuation (shellbvp.march) on toy families of states."""

import math
from types import SimpleNamespace

import pytest

from shellbvp.march import Steps, march


def _family(fails_between=None, invalid_from=None):
    """solve_at of a toy family: a state at every u, failing on an interval (a step that lands
    there fails), invalid from a value on; records every value tried."""
    tried = []

    def solve_at(u, states):
        tried.append(u)
        ok = not (fails_between and fails_between[0] < u < fails_between[1])
        return SimpleNamespace(success=ok, valid=invalid_from is None or u < invalid_from, delta=u)

    return solve_at, tried


def test_a_march_reaches_its_target_with_growing_steps():
    solve_at, tried = _family()
    m = march(0.0, 1.0, solve_at, Steps(0.1))
    assert m.reached and m.reason == "" and m.last.delta == 1.0 and m.at == 1.0
    assert tried[:3] == pytest.approx([0.1, 0.25, 0.475], rel=1e-15) and m.solves == len(tried)


def test_a_failed_step_is_shrunk_and_the_march_stops_when_it_is_too_small():
    solve_at, tried = _family(fails_between=(0.5, 2.0))  # no state beyond 0.5
    m = march(0.0, 1.0, solve_at, Steps(0.1, too_small=lambda s, u: s < 1e-3))
    assert not m.reached and m.reason == "step" and 0.498 < m.at <= 0.5 < m.tried < 0.502
    assert not m.failed.success and all(s.success for s in m.states)


def test_stop_done_and_the_solve_budget_end_a_march_with_their_reason():
    solve_at, _ = _family(invalid_from=0.45)
    m = march(0.0, 1.0, solve_at, Steps(0.1), stop=lambda s, u, states: "invalid" if not s.valid else None)
    assert not m.reached and m.reason == "invalid" and m.failed.delta >= 0.45 and m.last.delta < 0.45
    m = march(0.0, 1.0, solve_at, Steps(0.1), done=lambda states: "half" if states and states[-1].delta > 0.5 else None)
    assert m.reached and m.reason == "half" and m.last.delta > 0.5
    m = march(0.0, 1.0, solve_at, Steps(0.01, grow=lambda s: s), max_solves=5)
    assert not m.reached and m.reason == "solves" and m.solves == 5 and math.isclose(m.at, 0.05)
    m = march(0.0, math.inf, solve_at, Steps(0.3, advance=lambda u, s, t: u + s if u + s <= 1.0 else None))
    assert m.reason == "range" and m.at == 0.3 + 0.45


def test_a_march_downwards_and_with_relative_steps():
    solve_at, tried = _family()
    steps = Steps(0.3, advance=lambda u, f, t: max(t, u * (1 - f)), grow=lambda f: min(1.5 * f, 0.5))
    m = march(1.0, 0.01, solve_at, steps, history=[SimpleNamespace(success=True, delta=1.0)])
    assert m.reached and m.last.delta == 0.01 and tried[0] == 0.7 and len(m.states) == 1 + m.solves
