"""The checks a fit passes and the words it is judged by: its statuses and warnings, the
trend and runs tests on the data and residuals, the diagnostics of the covariance, and the
rating of a fit's quality (good, fair, poor)."""

from __future__ import annotations

import math

import numpy as np
from scipy import special

__all__ = ["FIT_STATUS", "FIT_WARNINGS", "PLAUSIBLE_MU_H", "TREND_P", "RUNS_P", "RUNS_MIN_POINTS", "QUALITY_RULES",
           "CONTACT_MISFIT", "POOR_WARNINGS", "POOR_TOGETHER", "WEIGHTS_DISAGREE", "WEIGHTS_LEVEL",
           "AUTOCORRELATION_LEVEL",
           "other_weights", "weights_disagreement", "weights_check_line", "rank_trend", "runs_test", "depth_order",
           "runs_in_depth_order", "residual_autocorrelation", "contact_misfit", "fit_diagnostics", "fit_quality",
           "diagnostics_lines", "check_result"]


#: Outcomes of a fit that ran (``FitResult.status``); ``success`` is ``status == 0``.
#: Data the fit cannot use at all raise ``ValueError`` before any model curve is computed.
FIT_STATUS = {
    0: "the fit converged and passed its checks",
    1: "the least-squares solver did not converge",
    2: "the fitted mu*H is not positive",
    3: "the model force is not finite at every data point",
    4: "a 95 % interval (mu*H or the offset) is not finite",
    5: "the 95 % interval of mu*H is wider than mu*H itself: the data do not determine mu*H",
    6: "weights_disagree: refitted with another noise model, mu*H's 95 % interval does not overlap the fit's (the "
       "model misses the data's shape where the weightings stress them differently)",
}

#: The status of a fit whose weightings disagree (:func:`weights_disagreement`).
WEIGHTS_DISAGREE = 6

#: The weights check's level: the two estimates of mu*H disagree when they lie further apart than
#: this many times the sum of their 95 % half-widths (1: the intervals do not overlap).  Measured in
#: benchmarks/weights_check_rate.py (false alarms on records of the right model, power on wrong ones).
WEIGHTS_LEVEL = 1.0


#: Kinds of warning (``FitResult.warning_codes``; the texts are in ``FitResult.warnings``).
FIT_WARNINGS = {
    "residual_runs": "the residuals' signs form long runs (runs test): the model does not follow the data",
    "residual_autocorrelation": "successive residuals (in depth order) are correlated beyond AUTOCORRELATION_LEVEL: "
                                "the model's shape misses the data's (first suspect: the rim radius)",
    "contact_misfit": "where the model carries force (beyond the contact point) its residuals are systematic and "
                      "large: the model misses the contact region (rated poor)",
    "implausible_mu_H": "mu*H is far outside the values of soft shells (PLAUSIBLE_MU_H): check the units",
    "search_range": "a shape parameter's interval or search reached the end of its range",
    "max_curves": "the number of model curves reached its limit",
    "mixed_segments": "the fitted rows mix the loading and the retraction of an instrument record",
    "several_loadings": "the record holds more than one loading pass; one was fitted, the others left out",
    "unstable_depths": "the fitted depths pass the first instability of the axisymmetric shell (fit(stability=True))",
}


#: mu*H (N/m) of soft shells, from red-cell membranes (~1e-5) to thick rubber (~1e4); a fit
#: outside this range gets a warning (a header in kN for data in mN gives 1e6 x the truth).
PLAUSIBLE_MU_H = (1e-6, 1e5)


#: One-sided p-value below which the force counts as not increasing with depth (Spearman).
TREND_P = 0.01


#: One-sided p-value of the runs test below which the residual pattern is a warning, and the
#: least number of points for the test.
RUNS_P = 1e-3


RUNS_MIN_POINTS = 10


#: A systematic residual in the contact region that rates a fit poor: the largest mean residual
#: over a tenth of the rows where the model carries force (in depth order), as a fraction of the
#: largest force the model carries there, when those rows' signs also fail the runs test.
CONTACT_MISFIT = 0.05


#: The lag-1 autocorrelation of the weighted residuals in depth order above which a fit gets the
#: warning ``residual_autocorrelation`` (and only where it is also beyond chance for independent
#: noise: ``r1 sqrt(n)`` above the normal quantile of :data:`RUNS_P`).  Measured in
#: benchmarks/weights_check_rate.py: above 0.5 in 3 of 5,000 fits of the right model, in every
#: fit with a rim radius 2x or 0.5x off but a few of the noisiest.
AUTOCORRELATION_LEVEL = 0.5


#: Warnings that rate a fit poor whatever its interval (:func:`fit_quality`).
POOR_WARNINGS = ("contact_misfit",)


#: Warnings that rate a fit poor together (:func:`fit_quality`): the residuals' signs run and their
#: values follow each other in depth order -- they trace a curve the model does not follow (a wrong
#: rim radius, a contact point the fit could not reach), and mu*H's interval does not say how well
#: it is known.  Neither warned in 12,800 fits of the right model (benchmarks/weights_check_rate.py).
POOR_TOGETHER = ("residual_runs", "residual_autocorrelation")


def _average_ranks(x):
    """Ranks 1..n of ``x``, ties given the mean of the ranks they share."""
    _, inverse, counts = np.unique(x, return_inverse=True, return_counts=True)
    return (np.cumsum(counts) - (counts - 1) / 2.0)[inverse]


def rank_trend(d, f):
    """Spearman's rank correlation of ``f`` with ``d`` and its one-sided p-values for an increase
    and for a decrease, by the t approximation (as ``scipy.stats.spearmanr``)."""
    rho = np.corrcoef(_average_ranks(d), _average_ranks(f))[0, 1]  # (a numpy float: 1/0 is inf)
    dof = d.size - 2
    with np.errstate(divide="ignore", invalid="ignore"):
        t = rho * np.sqrt(np.clip(dof / ((rho + 1.0) * (1.0 - rho)), 0, None))
    return float(rho), float(special.stdtr(dof, -t)), float(special.stdtr(dof, t))


def runs_test(residual):
    """One-sided Wald–Wolfowitz runs test for too few runs of signs (a systematic misfit).

    Parameters
    ----------
    residual : array_like
        Residuals in the order of the data (by displacement); zeros are skipped.

    Returns
    -------
    runs : int
        Number of runs of equal sign.
    p : float
        P(so few runs or fewer) for independent signs (normal approximation).
    """
    sgn = np.sign(np.asarray(residual, float))
    sgn = sgn[sgn != 0]
    n1, n2 = int(np.sum(sgn > 0)), int(np.sum(sgn < 0))
    n = n1 + n2
    runs = 1 + int(np.sum(sgn[1:] != sgn[:-1])) if n else 0
    if n1 == 0 or n2 == 0:
        return runs, float(0.5 ** max(n - 1, 0))  # every sign the same
    mean = 2.0 * n1 * n2 / n + 1
    var = (mean - 1) * (mean - 2) / (n - 1)
    return runs, float(special.ndtr((runs + 0.5 - mean) / math.sqrt(var))) if var > 0 else 1.0


def depth_order(resid, disp):
    """Indices of the rows in depth order, without the rows whose residual equals a neighbour's
    exactly: a force read as exactly constant (a noise-free approach, a synthetic record's) has
    no noise whose signs or correlation could be tested, and would be one long run."""
    order = np.argsort(disp, kind="stable")
    r = np.asarray(resid, float)[order]
    same = r[1:] == r[:-1]
    return order[~(np.r_[False, same] | np.r_[same, False])]


def runs_in_depth_order(resid, disp):
    """``(runs, p)`` of :func:`runs_test` on the residuals in depth order (signs only: weights do
    not matter; rows of exactly equal residuals left out, :func:`depth_order`); None for too few
    points or a non-finite residual."""
    if not np.all(np.isfinite(resid)):
        return None
    order = depth_order(resid, disp)
    return runs_test(resid[order]) if order.size >= RUNS_MIN_POINTS else None


def contact_misfit(resid, disp, indentation):
    """The residuals where the model carries force (``indentation > 0``: beyond the contact
    point), in depth order: ``(runs, p, n, largest)`` with :func:`runs_test`'s runs and p on
    those ``n`` rows and ``largest``, the largest mean residual over a tenth of them relative to
    the largest ``indentation`` there (a misfit averages to a trend, noise to ~0); None for
    fewer than :data:`RUNS_MIN_POINTS` such rows or a residual that is not finite there."""
    carries = np.asarray(indentation, float) > 0
    r = np.asarray(resid, float)[carries]
    if r.size < RUNS_MIN_POINTS or not np.all(np.isfinite(r)):
        return None
    r = r[np.argsort(np.asarray(disp, float)[carries], kind="stable")]
    runs, p = runs_test(r)
    trend = max(abs(float(np.mean(b))) for b in np.array_split(r, 10))
    return runs, p, int(r.size), trend / float(np.max(np.asarray(indentation, float)[carries]))


def fit_diagnostics(cov, rss, n, k, weighted_resid, disp, runs, dof=None) -> dict:
    """The fit's correlation matrix (order of ``fitted``), the noise scale (``rss / dof``; ``dof``
    default ``n - k``), AIC and BIC and two residual diagnostics (the runs test's p, ``runs``, and
    the lag-1 autocorrelation in depth order)."""
    corr = None
    if cov is not None and np.all(np.isfinite(cov)):
        sd = np.sqrt(np.diag(cov))
        if np.all(sd > 0):
            corr = np.clip(cov / np.outer(sd, sd), -1.0, 1.0)
    dof = max(n - k, 1) if dof is None else dof
    out = {"correlation": corr, "noise_sigma": float(math.sqrt(rss / dof)) if rss >= 0 else float("nan"),
           "aic": float("nan"), "bic": float("nan"), "runs_p": float("nan"), "residual_autocorrelation": float("nan")}
    if rss > 0 and n > 0:  # Gaussian with the noise model's relative weights and an estimated scale (k + 1)
        ll = n * math.log(rss / n)
        out["aic"], out["bic"] = float(ll + 2 * (k + 1)), float(ll + (k + 1) * math.log(n))
    if runs is not None:
        out["runs_p"] = runs[1]
        ac = residual_autocorrelation(weighted_resid, disp)
        if ac is not None:
            out["residual_autocorrelation"] = ac[0]
    return out


def residual_autocorrelation(weighted_resid, disp):
    """``(r1, n)``: the lag-1 autocorrelation of the weighted residuals in depth order over the
    ``n`` rows of :func:`depth_order`; None for fewer than :data:`RUNS_MIN_POINTS` rows, a
    residual that is not finite or residuals all equal."""
    r = np.asarray(weighted_resid, float)
    if not np.all(np.isfinite(r)):
        return None
    c = r[depth_order(r, disp)]
    c = c - c.mean()
    if c.size < RUNS_MIN_POINTS or not np.dot(c, c) > 0:
        return None
    return float(np.dot(c[1:], c[:-1]) / np.dot(c, c)), int(c.size)


#: Rules of :func:`fit_quality`: mu*H's 95 % half-width relative to mu*H for "good" and "fair",
#: the largest absolute correlation of mu*H with another fitted parameter for "good".
QUALITY_RULES = {"good_halfwidth": 0.05, "fair_halfwidth": 0.20, "good_correlation": 0.98}


def fit_quality(success, warning_codes, mu_H, mu_ci, correlation=None, fitted=(), model_error=None) -> str:
    """A transparent rating of one fit: ``good``, ``fair`` or ``poor``.

    * poor: the fit failed its checks, a warning of :data:`POOR_WARNINGS` (the model misses the
      contact region) or both of :data:`POOR_TOGETHER` (residuals that trace a curve: their signs
      run and their values follow each other), mu*H's 95 % interval is wider than +-20 % of it,
      or the model's own error
      (``model_error``, a fraction, where known) is larger than that
      interval: then the interval does not say how well mu*H is known;
    * good: succeeded without warnings, the interval within +-5 %, and mu*H not correlated with
      another fitted parameter beyond abs(r) = 0.98 (then the data cannot tell them apart);
    * fair: everything between.

    The rules are :data:`QUALITY_RULES`; nanite rates curves with a trained regressor instead.
    """
    if not success or not (mu_H > 0) or not all(math.isfinite(v) for v in mu_ci) or \
            any(code in POOR_WARNINGS for code in warning_codes) or all(c in warning_codes for c in POOR_TOGETHER):
        return "poor"
    half = (mu_ci[1] - mu_ci[0]) / 2 / mu_H
    if half > QUALITY_RULES["fair_halfwidth"] or (model_error is not None and model_error > half):
        return "poor"
    r = 0.0
    if correlation is not None and "mu_H" in fitted and len(fitted) > 1:
        i = list(fitted).index("mu_H")
        row = np.abs(np.delete(np.asarray(correlation, float)[i], i))
        r = float(np.nanmax(row)) if row.size else 0.0
    if not warning_codes and half <= QUALITY_RULES["good_halfwidth"] and r <= QUALITY_RULES["good_correlation"]:
        return "good"
    return "fair"


def diagnostics_lines(quality, fitted, correlation, values, show_force=lambda v: f"{v:.4g} N") -> list:
    """Two lines for a fit's summary: its quality rating and its diagnostics (``values``: noise_sigma,
    aic, bic, runs_p, residual_autocorrelation)."""
    rules = (f"rules: mu*H's 95 % interval within +-{100 * QUALITY_RULES['good_halfwidth']:g} % (good) or "
             f"+-{100 * QUALITY_RULES['fair_halfwidth']:g} % (fair) and wider than the model's error where known, "
             f"no warnings, |corr(mu_H, .)| <= {QUALITY_RULES['good_correlation']:g}")
    parts = []
    if math.isfinite(values.get("noise_sigma", math.nan)):
        parts.append(f"noise {show_force(values['noise_sigma'])}")
    if math.isfinite(values.get("aic", math.nan)):
        parts.append(f"AIC {values['aic']:.1f}, BIC {values['bic']:.1f}")
    if math.isfinite(values.get("runs_p", math.nan)):
        parts.append(f"runs test p = {values['runs_p']:.2g}, lag-1 autocorrelation "
                     f"{values['residual_autocorrelation']:.2f}")
    if correlation is not None and len(fitted) > 1:
        c = np.asarray(correlation, float)
        parts += [f"corr({a}, {b}) = {c[i, j]:+.2f}" for i, a in enumerate(fitted) for j, b in enumerate(fitted)
                  if i < j]
    return [f"quality = {quality} ({rules})", "diagnostics = " + ("; ".join(parts) if parts else "none")]


def other_weights(kind):
    """The noise model a fit with weights ``kind`` is checked against: uniform, or for a uniform
    fit the default's (mixed)."""
    return "mixed" if kind == "uniform" else "uniform"


def weights_disagreement(kind, mu_H, mu_ci, other):
    """The message's detail when the fit's mu*H (weights ``kind``, 95 % interval ``mu_ci``) and
    ``other`` (``{"weights", "mu_H", "mu_H_ci95"}``: the same model refitted with another noise
    model) lie further apart than :data:`WEIGHTS_LEVEL` times the sum of their 95 % half-widths
    (at 1: the intervals do not overlap); None when they agree or cannot be compared (a value
    that is not finite)."""
    if other is None:
        return None
    a, b = other["mu_H_ci95"]
    values = (mu_H, *mu_ci, other["mu_H"], a, b)
    if not all(math.isfinite(v) for v in values) or \
            abs(mu_H - other["mu_H"]) <= WEIGHTS_LEVEL * (mu_ci[1] - mu_ci[0] + b - a) / 2:
        return None
    return (f"{kind} weights give mu*H = {mu_H:.4g} N/m [{mu_ci[0]:.4g}, {mu_ci[1]:.4g}], {other['weights']} weights "
            f"{other['mu_H']:.4g} N/m [{a:.4g}, {b:.4g}]; plot the fit, fit a range where the model follows "
            "the data (--max-depth, --force-max), try --baseline linear and check the scene (indenter radius, "
            "rise, thickness); --no-weights-check reports the fit without this check")


def weights_check_line(kind, check):
    """One line of a fit's summary: what its weights check found (``FitResult.weights_check``)."""
    if check is None:
        return f"weights = {kind}; not checked against another noise model"
    a, b = check["mu_H_ci95"]
    verdict = "the intervals overlap" if check["agree"] else "the intervals do not overlap: not a success"
    return (f"weights = {kind}; checked: {check['weights']} weights give mu*H = {check['mu_H']:.4g} N/m "
            f"[{a:.4g}, {b:.4g}] ({verdict})")


def check_result(res_ok, mu_H, mu_ci, off_ci, resid_ok, n, runs, contact=None, autocorrelation=None):
    """Status and warnings of a fitted result (see :data:`FIT_STATUS`, :data:`FIT_WARNINGS`);
    ``contact``: :func:`contact_misfit` of the fit, ``autocorrelation``:
    :func:`residual_autocorrelation` of its weighted residuals, or None."""
    warnings = []
    if not res_ok:
        status = 1
    elif not mu_H > 0:
        status = 2
    elif not resid_ok:
        status = 3
    elif not all(math.isfinite(v) for v in (*mu_ci, *off_ci)):
        status = 4
    elif mu_ci[1] - mu_ci[0] > mu_H:
        status = 5
    else:
        status = 0
    if runs is not None and runs[1] < RUNS_P:
        warnings.append(("residual_runs", f"the residuals' signs form {runs[0]} runs over {n} points "
                         f"(runs test p = {runs[1]:.2g} < {RUNS_P:g}): a pattern the noise model does not explain; "
                         "the model (scene, contact point, weights) does not follow the data"))
    if autocorrelation is not None:
        r1, rows = autocorrelation
        if r1 > AUTOCORRELATION_LEVEL and r1 * math.sqrt(rows) > -special.ndtri(RUNS_P):
            warnings.append(("residual_autocorrelation", f"successive residuals are correlated (lag-1 autocorrelation "
                             f"{r1:.2f} > {AUTOCORRELATION_LEVEL:g} over {rows} rows in depth order): the model's "
                             "shape misses the data's and mu*H's interval does not say how well it is known; check "
                             "the sample's lengths, the rim radius first (--radius: a wrong R_L gives a wrong mu*H "
                             "with a narrow interval), then the indenter radius, rise and thickness"))
    if contact is not None and contact[1] < RUNS_P and contact[3] > CONTACT_MISFIT:
        warnings.append(("contact_misfit", f"the model misses the contact region: where it carries force "
                         f"({contact[2]} rows beyond the contact point) its residuals run in {contact[0]} runs "
                         f"(p = {contact[1]:.2g}) "
                         f"and their mean over a tenth of those rows reaches {100 * contact[3]:.0f} % of the force "
                         "there (rated poor; mu*H does not describe these data); plot the fit (shellbvp plot), try "
                         "another --weights, a fitting range (--max-depth), --baseline linear, and check the scene "
                         "(indenter radius, rise, thickness) and the segment"))
    lo, hi = PLAUSIBLE_MU_H
    if status != 2 and math.isfinite(mu_H) and not lo <= mu_H <= hi:
        warnings.append(("implausible_mu_H", f"mu*H = {mu_H:.3g} N/m is far outside the range of soft shells "
                         f"({lo:g} to {hi:g} N/m): check the units of the data (header or --units) and R_L"))
    return status, warnings
