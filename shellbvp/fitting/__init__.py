"""Fit mu*H (a displacement origin, and optionally a shape parameter) to a measured curve.

The model force scales linearly in mu*H (``F_SI = mu_H R_L F(delta)``), so
one model curve serves a fit of mu*H and the contact point: it is computed
once on a grid of depths and interpolated (monotone cubic) in delta.  The
unknowns are ``mu_H`` and, optionally, the origin offset ``d0`` of the
displacement (real contact points are uncertain) and a force baseline (what the
instrument reads before contact, as nanite fits it with the contact point):
``F_i = mu_H R_L F((d_i - d0)/R_L) + b0 + b1 (d_i - d0)``, the first term 0 for
``d_i <= d0`` (b0, b1 fitted or 0).  :func:`fit_record` fits a segment of an
instrument record (:mod:`shellbvp.instrument`), the loading by default.

A shape parameter (:mod:`shellbvp.shape_parameters`: beta, the Mooney–Rivlin alpha, ...)
changes the *shape* of the curve.  Fitting one of them uses a few model curves at trial
values theta (nodes, spaced as its declaration says: e.g. a factor 2 in beta, 0.2 in alpha)
on a common delta grid and interpolates F across them (cubic spline in ``theta = ln x`` or
``x`` at every grid depth).  The parameter is estimated by minimising the profiled residual
(mu*H and d0 refitted at each trial value); nodes are added where the
minimum or the interval reaches the edge of the nodes, and a last curve is
computed at the estimate (the interpolation error there is reported).  Its
95 % interval is the profile-likelihood interval
``RSS(theta) <= RSS_min (1 + F_{1,n-p}(0.95)/(n-p))``.

Noise models (``weights``), all by iteratively reweighted least squares with
the weights from the current model force F_i: ``"uniform"`` (homoscedastic:
the same force noise at every point), ``"relative"`` (noise proportional to
the force: residuals divided by ``max(|F_i|, floor * max|F_data|)``) and
``"mixed"`` (the default: ``sigma_i^2 = a^2 + b^2 F_i^2``, an additive floor
plus a proportional part, both estimated from the residuals' local scatter by
non-negative least squares -- it covers either kind of noise and anything
between; the proportional part is weighted at ``floor * max|F_data|`` at least, 0.02 by
default, :data:`WEIGHT_FLOORS`, and the noise scale is read from the rows that carry noise:
rows read as exactly constant, a noise-free approach, do not count).  Intervals of mu*H and d0
come from the linearised covariance (with the shape parameter's theta as a third column when
fitted) and Student's t; the fitted shape
parameter's quantities in lab units that depend on mu*H too (the pressure in Pa) from the
same covariance.  ``benchmarks/fit_coverage.py`` measures their coverage.

The package's modules, each one job: :mod:`~shellbvp.fitting.fit_data` (the functions a user
calls), :mod:`~shellbvp.fitting.curves` (the model curves and their interpolation),
:mod:`~shellbvp.fitting.least_squares` (the least squares at a fixed shape and the noise
models), :mod:`~shellbvp.fitting.profile` (a shape parameter's profile likelihood),
:mod:`~shellbvp.fitting.intervals` (intervals, checks and the result built) and
:mod:`~shellbvp.fitting.result` (:class:`FitResult`).
"""

from __future__ import annotations

from ..fit_checks import (FIT_STATUS, FIT_WARNINGS, PLAUSIBLE_MU_H, QUALITY_RULES, diagnostics_lines, fit_quality,
                          runs_test)
from ..instrument import read_force_csv
from .curves import N_DEPTHS, clear_model_curves
from .fit_data import example_data_path, fit, fit_record, free_parameters
from .least_squares import BASELINES, DEFAULT_WEIGHTS, MODEL_PARAMETERS, WEIGHT_FLOORS, WEIGHTS
from .result import Estimate, FitResult

__all__ = ["FitResult", "fit", "fit_quality", "diagnostics_lines", "QUALITY_RULES", "read_force_csv",
           "example_data_path", "WEIGHTS", "DEFAULT_WEIGHTS", "WEIGHT_FLOORS", "FIT_STATUS", "FIT_WARNINGS", "PLAUSIBLE_MU_H",
           "runs_test", "BASELINES", "MODEL_PARAMETERS", "fit_record", "Estimate", "free_parameters", "N_DEPTHS",
           "clear_model_curves"]
