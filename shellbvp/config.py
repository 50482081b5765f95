"""Switches of the algorithms and timings of the interface, in one place.

Every switch stands where the package is measured and tested.  Turning one off is for
measurement (``benchmarks/speed_vs_baseline.py`` runs the ablations) and for checks that a
fast path changes nothing; the timings are for the interface.  Change them for a block of
code with :func:`options`, which restores them on the way out::

    import shellbvp as sb

    with sb.options(collocation=False):      # scipy's own collocation algebra
        c = sb.curve(sb.Scene.preset("base"))

The module that acts on an option reads it from :data:`OPTIONS` when it acts.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
from dataclasses import dataclass, field

__all__ = ["Options", "OPTIONS", "options"]


def _progress_seconds() -> float:
    try:
        return max(float(os.environ.get("SHELLBVP_PROGRESS_SECONDS", "10")), 0.0)
    except ValueError:
        return 10.0


@dataclass
class Options:
    """The options and their values.

    Attributes
    ----------
    collocation : bool
        Assemble solve_bvp's collocation matrix without its zeros (``shellbvp.collocation``);
        False: scipy's own assembly and SuperLU.
    compiled_elimination : bool
        With compiled kernels, factorise the collocation matrix by their elimination node by
        node; False: assembly and SuperLU, as with numpy.
    collocation_max_growth : float
        Partial pivoting's growth (the factors' largest entry over the matrix's) above which
        the compiled factors are not trusted and SuperLU factorises the matrix (on the
        stability grid and the presets the growth stayed below 50).
    equidistribute : bool
        A warm start's mesh equidistributes the residual of the state it starts from; False:
        every third node of that state's mesh.
    quadratic_predictor : bool
        A step of natural continuation in delta from three converged states of one
        configuration extrapolates their quadratic in delta (its error is a step's cube, the
        secant's its square: solve_bvp's Newton takes 15-20 % fewer steps on the cap curves
        through shooting's depths).  Not on the adaptive curve's arclength steps.
    secant_max_ln_sc : float
        A secant (or quadratic) predictor is made only while it moves ln Sc by at most this
        much: past it the contact radius changes by orders of magnitude and the step fails at
        its node budget, where the plain warm start converges (``inf``: no guard).
    first_step : float
        The adaptive curve's first arclength step, in chords from the point below the first:
        twice the chord fails on base, flat and dome (one solve refined to its node budget,
        ~20 ms, then halved); once the chord costs the stability grid's curves 1-3 points each
        (2659 against 2608, 80 s against 68 s).
    warm_first : bool
        A lift-off state is continued from the previous one of its configuration first;
        False: the cap's guesses first.
    split_rule : bool
        The split cap+line(tip) is not probed where the pole was lifted at the previous point
        and the line still holds it above the tip; False: probed wherever the cap is pressed
        at the pole.
    split_first : bool
        Where the lifted pole is down on the tip, the split before the annulus; False: the
        annulus first.
    tighten : bool
        A curve's point whose error estimate exceeds tol is solved again, tighter; False: kept.
    progress_seconds : float
        Seconds between progress lines when stderr is not a terminal (environment variable
        ``SHELLBVP_PROGRESS_SECONDS``, default 10).
    health_seconds : float
        Seconds a sweep waits for a finished curve before it asks whether a Dask cluster is
        still there.
    compile_in_background : bool
        With numba and ``SHELLBVP_KERNELS=auto``, a structure whose kernels are not compiled
        is compiled in a background process once the numpy kernels have taken
        ``kernels.START_AFTER_S``; False (default): not compiled but by ``shellbvp compile``
        (a compile, ~15-40 s, repays over many curves, not within one command).
    model_curve_cache : bool
        A fit's model curves are kept in the code cache's ``curves/`` folder and read back by
        the next fit of the same scene and depths, in any process (:mod:`shellbvp.fitting.curves`);
        False: computed in every process.
    max_fe_dofs : float
        The largest 3D solid (:func:`shellbvp.fe_curve`, ``validate``, ``fit --model solid``)
        built, in unknowns, estimated from the scene before the mesh is (:func:`shellbvp.fe.fe_size`):
        50,000 is about 30 min and 330 MB on a 2-core machine.  Larger ones are refused in one line.
    max_stability_dofs : float
        The largest stability analysis of a state (:func:`shellbvp.stability`), in unknowns summed
        over its modes (6 per node and mode): 300,000 is about 15 s, the hemisphere at beta ~ 1e-7
        (the cost grows like 1/sqrt(beta)).  Larger ones are refused in one line.

    Examples
    --------
    >>> from shellbvp.config import OPTIONS
    >>> OPTIONS.collocation, OPTIONS.first_step
    (True, 2.0)
    """

    collocation: bool = True
    compiled_elimination: bool = True
    collocation_max_growth: float = 1e6
    equidistribute: bool = True
    quadratic_predictor: bool = True
    secant_max_ln_sc: float = 1.0
    first_step: float = 2.0
    warm_first: bool = True
    split_rule: bool = True
    split_first: bool = True
    tighten: bool = True
    progress_seconds: float = field(default_factory=_progress_seconds)
    health_seconds: float = 10.0
    compile_in_background: bool = False
    model_curve_cache: bool = True
    max_fe_dofs: float = 50_000
    max_stability_dofs: float = 300_000


#: The options in force
OPTIONS = Options()

_FIELDS = {f.name: f for f in dataclasses.fields(Options)}


def _checked(name, value):
    if name not in _FIELDS:
        raise ValueError(f"unknown option {name!r}; the options are {', '.join(_FIELDS)}")
    if _FIELDS[name].type in ("bool", bool):
        if not isinstance(value, bool):
            raise ValueError(f"option {name} must be True or False; got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value) or value < 0:
        raise ValueError(f"option {name} must be a number >= 0; got {value!r}")
    return float(value)


@contextlib.contextmanager
def options(**changes):
    """Options changed for a block of code (checked first; restored on the way out, also on
    an error).

    Parameters
    ----------
    **changes
        ``name=value`` for fields of :class:`Options`.

    Returns
    -------
    context manager
        Yields :data:`OPTIONS` with the changes in force.

    Examples
    --------
    >>> import shellbvp as sb
    >>> from shellbvp.config import OPTIONS
    >>> with sb.options(tighten=False):
    ...     OPTIONS.tighten
    False
    >>> OPTIONS.tighten
    True
    >>> with sb.options(tighten="no"):
    ...     pass
    Traceback (most recent call last):
    ...
    ValueError: option tighten must be True or False; got 'no'
    """
    checked = {name: _checked(name, value) for name, value in changes.items()}
    before = {name: getattr(OPTIONS, name) for name in checked}
    for name, value in checked.items():
        setattr(OPTIONS, name, value)
    try:
        yield OPTIONS
    finally:
        for name, value in before.items():
            setattr(OPTIONS, name, value)
