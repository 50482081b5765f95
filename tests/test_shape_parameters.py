"""The registry of shape parameters (shellbvp.shape_parameters, issue 43 item 5): one
declaration per parameter, and fit(), FitResult, the CLI, the batch table and the fit file
take every registered parameter from it."""

import math

import numpy as np
import pytest

import shellbvp as sb
import shellbvp.fitting.intervals
from shellbvp.shape_parameters import DERIVED, SHAPE_PARAMETERS, Derived

from fake_curves import FakeCurve

R_L, MU_H, D0 = 0.3e-3, 52.0, 0.01e-3


def test_free_and_the_fit_name_aliases_are_one_path(closed_form):
    x = np.linspace(0.01, 0.4, 40)
    force = MU_H * R_L * FakeCurve(sb.Scene.preset("fit", beta=0.02), x).force
    force *= 1 + 0.02 * np.random.default_rng(1).standard_normal(x.size)
    d, scene = R_L * x + D0, sb.Scene.preset("fit")
    new = sb.fit(scene, d, force, R_L=R_L, free=("beta",), bounds={"beta": (1e-3, 0.1)})
    old = sb.fit(scene, d, force, R_L=R_L, fit_beta=True, beta_bounds=(1e-3, 0.1))
    assert new.to_dict() == old.to_dict() and new.fitted == ("mu_H", "offset", "beta")
    assert new.beta_ci95 == new.shape_ci95["beta"] and new.alpha_ci95 is None and new.pressure_Pa is None
    with pytest.raises(TypeError, match="fit_betta"):
        sb.fit(scene, d, force, R_L=R_L, fit_betta=True)
    with pytest.raises(ValueError, match="unknown shape parameter 'gamma'"):
        sb.fit(scene, d, force, R_L=R_L, free=("gamma",))
    with pytest.raises(AttributeError):
        new.no_such_thing


def test_every_registered_parameter_reaches_the_cli_the_table_and_the_file():
    from shellbvp.batch import TABLE_COLUMNS
    from shellbvp.cli import build_parser
    from shellbvp.fitrecord import PARAMETER_UNITS

    fit_parser = build_parser()._subparsers._group_actions[0].choices["fit"]
    options = {o for a in fit_parser._actions for o in a.option_strings}
    for name, p in SHAPE_PARAMETERS.items():
        assert {f"--fit-{name}", f"--{name}-range"} <= options
        assert PARAMETER_UNITS[name] == p.unit
        assert (name if p.unit == "1" else f"{name} ({p.unit})") in TABLE_COLUMNS
    for name, d in DERIVED.items():
        assert PARAMETER_UNITS[name] == d.unit and f"{name} 95% low ({d.unit})" in TABLE_COLUMNS


def test_a_derived_interval_on_the_log_scale_stays_positive():
    """A ratio such as mu*H / H: its interval from the linearised logarithm is positive and
    asymmetric; the plain one of the same covariance is symmetric (and here reaches below 0)."""
    ratio = dict(value=lambda x, mu_H, R_L: mu_H / x, gradient=lambda x, mu_H, R_L: (1 / x, -mu_H / x ** 2))
    plain = Derived("r", "1", "r", "", "", **ratio)
    logged = Derived("r", "1", "r", "", "", log_interval=True, **ratio)
    cov = np.diag([1.0, 0.0, 0.36])  # (mu_H, offset, theta); theta = ln x, x = 1: sd(ln x) = 0.6
    value, (lo, hi) = shellbvp.fitting.intervals._linearised(plain, 1.0, 1.0, 2.0, 1.0, cov, 2.0)
    assert value == 2.0 and lo == pytest.approx(2.0 - 2 * math.sqrt(1 + 4 * 0.36)) and lo < 0
    value, (lo, hi) = shellbvp.fitting.intervals._linearised(logged, 1.0, 1.0, 2.0, 1.0, cov, 2.0)
    half = 2 * math.sqrt(0.25 + 0.36)  # sd of ln(mu_H / x): (1/mu_H, -1) against the covariance
    assert (lo, hi) == pytest.approx((2 * math.exp(-half), 2 * math.exp(half))) and lo > 0


def test_the_declarations_examples_run():
    import doctest

    import shellbvp.shape_parameters

    result = doctest.testmod(shellbvp.shape_parameters, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
