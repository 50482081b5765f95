"""A fit's intervals and its result: Wald (Student's t) intervals of the free parameters from
the weighted Jacobian, the shape parameter's profile interval, the linearised intervals of
the quantities in lab units that depend on mu*H too, the checks on the result (status and
warnings) and the diagnostics, gathered in a :class:`~shellbvp.fitting.result.FitResult`
(:func:`result_of`)."""

from __future__ import annotations

import logging
import math

import numpy as np
from scipy import special

from ..fit_checks import (FIT_STATUS, WEIGHTS_DISAGREE, check_result, contact_misfit, fit_diagnostics,
                          residual_autocorrelation, runs_in_depth_order, weights_disagreement)
from ..scene_parameters import scene_parameter
from ..shape_parameters import SHAPE_PARAMETERS
from ..units import format_in
from .least_squares import MODEL_PARAMETERS, LeastSquaresModel
from .result import Estimate, FitResult

log = logging.getLogger(__name__)

__all__ = ["result_of", "weights_check_of"]


def result_of(fitted, mdl, sp, k, notes, keep, weights, baseline, curves_computed, fit_model="shell", check=None,
              refitted=None):
    """The :class:`FitResult` of what a fit found: Wald (t) intervals of the free parameters
    from the weighted Jacobian, the shape parameter's profile interval, status and warnings;
    ``check``: the :class:`~shellbvp.fitting.least_squares.NoiseModel` the fit's mu*H is checked
    against (refitted at the fitted shape from the fit's solution), or None; ``refitted``: that
    refit done already (:func:`weights_check_of`; a force map's pixels refit together)."""
    res, rss, J, w, P, top, R_L = fitted.res, fitted.rss, fitted.J, fitted.w, fitted.P, fitted.top, mdl.R_L
    d, f = mdl.d, mdl.f
    n = d.size
    dof = max((n if fitted.rows is None else fitted.rows) - k, 1)  # zero-noise rows do not count
    cov = None
    try:
        cov = np.linalg.inv(J.T @ J) * rss / dof
        half_free = special.stdtrit(dof, 0.975) * np.sqrt(np.diag(cov))
    except np.linalg.LinAlgError:
        half_free = np.full(J.shape[1], np.nan)
    q = mdl.full(res.x)
    half = np.zeros(4)
    half[mdl.free] = half_free[:int(np.sum(mdl.free))]
    ci = [(float(v - h), float(v + h)) for v, h in zip(q, half)]
    mu_H, d0, b0, b1 = (float(v) for v in q)
    off_ci = ci[1]

    def model(disp, mu_H, d0, b0=b0, b1=b1):
        disp = np.asarray(disp, float)
        return mu_H * R_L * LeastSquaresModel.shape(P, top, (disp - d0) / R_L) + b0 + b1 * (disp - d0)

    resid = model(d, mu_H, d0) - f
    name = sp.name if sp is not None else None
    fitted_names = tuple(nm for nm, free in zip(MODEL_PARAMETERS, mdl.free) if free) + ((name,) if name else ())
    fit_scene, theta_hat, theta_ci = fitted.scene, fitted.theta, fitted.theta_ci
    # the others' values in the scene at the estimate (the reported curve's scene is the nearest node's)
    at_estimate = fit_scene if sp is None else sp.scene_at(theta_hat)
    values, intervals = {}, {}
    for param in SHAPE_PARAMETERS.values():
        x = param.get(at_estimate)
        values[param.name] = None if x is None else float(param.reported(x, R_L))
    derived = _given_thickness(fit_scene, mu_H, ci[0], R_L)
    if sp is not None:
        param = sp.param
        x_hat = param.from_theta(theta_hat)
        values[name] = float(param.reported(x_hat, R_L))
        intervals[name] = tuple(float(param.reported(param.from_theta(v), R_L)) for v in theta_ci)
        t = special.stdtrit(dof, 0.975)
        for dq in param.derived:
            value, interval = _linearised(dq, x_hat, param.dx_dtheta(theta_hat), q[0], R_L, cov, t)
            derived[dq.name] = Estimate(value, interval, dq.unit, dq.label, dq.display_unit, dq.note, name)
    mu_ci = ci[0]
    runs = runs_in_depth_order(resid, d)
    contact = contact_misfit(resid, d, model(d, mu_H, d0, 0.0, 0.0))
    status, checks = check_result(bool(res.success), mu_H, mu_ci, off_ci, bool(np.all(np.isfinite(resid))),
                                   resid.size, runs, contact, residual_autocorrelation(w * resid, d))
    found = notes + checks
    for _, text in found:
        log.info("fit: warning: %s", text)
    other = refitted if refitted is not None else \
        None if check is None or fitted.dP is None else _refit_weighted(fitted, mdl, check, k)
    detail = weights_disagreement(weights, mu_H, mu_ci, other) if status == 0 else None
    if detail is not None:
        status = WEIGHTS_DISAGREE
    if other is not None:
        other["agree"] = detail is None
    message = FIT_STATUS[status] + (f": {detail}" if detail else "") + f" (least squares: {res.message})"
    point_weights = np.full(keep.size, np.nan)
    point_weights[keep] = w / np.max(w)
    diagnostics = fit_diagnostics(cov, rss, n, J.shape[1], w * resid, d, runs, dof)
    return FitResult(mu_H=mu_H, mu_H_ci95=mu_ci, offset=d0,
                     offset_ci95=off_ci, residual_rms=float(np.sqrt(np.mean(np.nan_to_num(resid, nan=mdl.big) ** 2))),
                     n=n, status=status, message=message, R_L=float(R_L), curve=fitted.curve, _model=model,
                     shape_values=values, shape_ci95=intervals, derived=derived, fitted=fitted_names,
                     weights=weights, scene=fit_scene, curves_computed=curves_computed,
                     interpolation_error=fitted.interpolation_error, warnings=[t for _, t in found],
                     warning_codes=[code for code, _ in found], baseline_model=baseline, baseline=b0,
                     baseline_ci95=ci[2], baseline_slope=b1, baseline_slope_ci95=ci[3],
                     point_weights=point_weights, model=fit_model, weights_check=other, **diagnostics)


def _refit_weighted(fitted, mdl, noise, k):
    """``{"weights", "mu_H", "mu_H_ci95"}``: mu*H and its 95 % (Wald, t) interval refitted with
    the noise model ``noise`` at the fitted shape, from the fit's solution (no model curve;
    ``k`` parameters fitted in all).  Its noise scale is read from the rows that carry noise by
    either fit's noise model (the mixed one's: rows read as exactly constant do not count)."""
    res, rss, J, w = noise.irls(mdl, fitted.P, fitted.dP, fitted.top, start=fitted.res.x)
    rows = noise.rows(mdl, fitted.P, fitted.top, mdl.full(res.x), w)
    dof = max(min(rows, mdl.d.size if fitted.rows is None else fitted.rows) - k, 1)
    return weights_check_of(noise.kind, float(mdl.full(res.x)[0]), rss, J, dof)


def weights_check_of(kind, mu_H, rss, J, dof) -> dict:
    """``{"weights", "mu_H", "mu_H_ci95"}`` of a refit with the noise model ``kind``: mu*H, its
    weighted RSS and Jacobian (mu*H's column first), the degrees of freedom."""
    try:
        half = float(special.stdtrit(dof, 0.975) * math.sqrt(np.linalg.inv(J.T @ J)[0, 0] * rss / dof))
    except (np.linalg.LinAlgError, ValueError):
        half = math.nan
    return {"weights": kind, "mu_H": mu_H, "mu_H_ci95": (mu_H - half, mu_H + half)}


def _linearised(dq, x, dx_dtheta, mu_H, R_L, cov, t):
    """The derived quantity ``dq`` (:class:`shellbvp.shape_parameters.Derived`) and its interval
    from the covariance of (mu_H, ..., theta) (theta, the shape parameter's search variable, last):
    ``value +- t sd`` or, with ``dq.log_interval``, ``value exp(-+ t sd(ln value))``."""
    value = dq.value(x, mu_H, R_L)
    if cov is None or not np.all(np.isfinite(cov)):
        return float(value), (math.nan, math.nan)
    d_mu_H, d_x = dq.gradient(x, mu_H, R_L)
    g = np.zeros(cov.shape[0])
    g[0], g[-1] = d_mu_H, d_x * dx_dtheta
    if dq.log_interval:
        g = g / value
    half = t * math.sqrt(max(float(g @ cov @ g), 0.0))
    if dq.log_interval:
        return float(value), (float(value * math.exp(-half)), float(value * math.exp(half)))
    return float(value), (float(value - half), float(value + half))


def _given_thickness(scene, mu_H, mu_H_ci, R_L):
    """``{"mu": Estimate, "E": Estimate}`` of a scene with a thickness (mu*H over H, H taken as
    exact; E = 3 mu, incompressible), else {}: the same quantities a fitted thickness gives."""
    eps = getattr(scene, "thickness", None)  # H / R_L
    if eps is None:
        return {}
    H = scene_parameter("thickness").to_lab(eps, R_L)  # m
    return {"mu": Estimate(mu_H / H, (mu_H_ci[0] / H, mu_H_ci[1] / H), "Pa", "mu", "MPa",
                           f"H = {format_in(H, 'um', 'length')}, eps = H/R_L = {eps:.3g}, beta = eps^2/3"),
            "E": Estimate(3 * mu_H / H, (3 * mu_H_ci[0] / H, 3 * mu_H_ci[1] / H), "Pa", "E", "MPa",
                          "E = 3 mu, incompressible")}
