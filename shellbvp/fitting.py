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
plus a proportional part, both estimated from the squared residuals by
non-negative least squares -- it covers either kind of noise and anything
between).  Intervals of mu*H and d0 come from the linearised covariance (with the
shape parameter's theta as a third column when fitted) and Student's t; the fitted shape
parameter's quantities in lab units that depend on mu*H too (the pressure in Pa) from the
same covariance.  ``benchmarks/fit_coverage.py`` measures their coverage.
"""

from __future__ import annotations

import logging
import math
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, special  # (scipy.stats: 0.4 s more to import, for four quantiles)
from scipy.interpolate import CubicSpline, PchipInterpolator

from .fit_checks import (
    FIT_STATUS,
    FIT_WARNINGS,
    PLAUSIBLE_MU_H,
    QUALITY_RULES,
    TREND_P,
    check_result,
    diagnostics_lines,
    fit_diagnostics,
    fit_quality,
    rank_trend,
    runs_in_depth_order,
    runs_test,
)
from .instrument import read_force_csv
from .shape_parameters import DERIVED, SHAPE_PARAMETERS, ShapeParameter, shape_parameter

log = logging.getLogger(__name__)

__all__ = ["FitResult", "fit", "fit_quality", "diagnostics_lines", "QUALITY_RULES", "read_force_csv", "example_data_path", "WEIGHTS",
           "DEFAULT_WEIGHTS", "FIT_STATUS", "FIT_WARNINGS", "PLAUSIBLE_MU_H", "runs_test", "BASELINES", "MODEL_PARAMETERS", "fit_record",
           "Estimate", "free_parameters"]

#: Force baselines of :func:`fit` (none; a constant b0; b0 + b1 (d - d0)).
BASELINES = ("none", "constant", "linear")
#: The parameters of the model at a fixed curve shape, in the order of the least squares.
MODEL_PARAMETERS = ("mu_H", "offset", "baseline", "baseline_slope")
#: Noise models of :func:`fit`.
WEIGHTS = ("uniform", "relative", "mixed")
#: The default noise model (chosen by the coverage measured in benchmarks/fit_coverage.py).
DEFAULT_WEIGHTS = "mixed"
#: Depths of every model curve (equally spaced up to delta_max).
N_DEPTHS = 40
_MAX_CURVES = 14


def example_data_path():
    """Path of the synthetic Lepidium-like CSV shipped with the package (README example)."""
    from pathlib import Path

    return Path(__file__).parent / "data" / "lepidium_synthetic.csv"


@dataclass(frozen=True)
class Estimate:
    """A quantity a fit reports in lab units beside mu*H (``FitResult.derived``): its value,
    95 % interval and how the CLI shows it (``label = value display_unit   95% CI [..] (note)``);
    ``of`` names the fitted shape parameter it comes from (None: from a given scene value)."""
    value: float
    ci95: tuple
    unit: str
    label: str
    display_unit: str
    note: str
    of: str | None = None


@dataclass
class FitResult:
    """Result of :func:`fit` (SI units).

    Attributes
    ----------
    mu_H : float
        Shear modulus times thickness, N/m (= um*MPa).
    mu_H_ci95 : (float, float)
    offset, offset_ci95 : float, (float, float)
        Displacement origin d0 in m (0 and (0, 0) when not fitted).
    shape_values : dict
        Every shape parameter of :data:`shellbvp.shape_parameters.SHAPE_PARAMETERS` by name:
        its value in the fitted model (the scene's unless fitted; None where the scene has
        none), in the parameter's reported unit.  Also ``res.<name>``: ``res.beta``,
        ``res.alpha`` (Mooney–Rivlin alpha; None for other materials), ``res.pressure``
        (nondimensional ``p R_L/(mu H)``).
    shape_ci95 : dict
        The fitted shape parameter's profile-likelihood 95 % interval (``res.<name>_ci95``;
        None for the others).  A side that reached the search bound is the bound (see
        ``message``).
    derived : dict
        Quantities in lab units that depend on mu*H too, by name (:class:`Estimate`): of the
        fitted shape parameter, with a linearised 95 % interval (the covariance of mu*H and the
        parameter, Student's t), e.g. ``res.pressure_Pa``, ``res.pressure_Pa_ci95`` (``p
        mu_H/R_L``; None unless the pressure was fitted); and mu of a given thickness (``mu``).
    fitted : tuple of str
        The fitted parameters ("mu_H", "offset", and a shape parameter's name).
    weights : str
        The noise model, "uniform", "relative" or "mixed".
    residual_rms : float
        Root-mean-square force residual, N (unweighted).
    n : int
        Number of data points used.
    status : int
        Outcome, a key of :data:`FIT_STATUS` (0: converged and passed the checks
        on the result: finite intervals, mu*H's narrower than mu*H).
    success : bool
        ``status == 0``.
    message : str
        ``FIT_STATUS[status]`` with details (the solver's message).
    warnings : list of str
        Findings that do not fail the fit but need a look (a residual pattern
        the noise model does not explain, an implausible mu*H, a shape
        parameter's interval at its search bound).
    warning_codes : list of str
        The kind of each warning, keys of :data:`FIT_WARNINGS` (same order).
    curve : Curve
        The model curve (nondimensional) at the fitted parameters.
    scene : Scene
        The scene of that curve (fitted beta or alpha).
    curves_computed : int
        Model curves computed for this fit (cached ones not counted).
    interpolation_error : float or None
        With beta or alpha fitted: ``max |F_interpolated - F_curve| / max |F|`` at
        the estimate before its own curve was added (None otherwise).
    R_L : float
    baseline_model : str
        The force baseline fitted, one of :data:`BASELINES`.
    baseline, baseline_ci95 : float, (float, float)
        Force baseline b0 (N) at the contact point and its 95 % interval (0 when not fitted).
    baseline_slope, baseline_slope_ci95 : float, (float, float)
        Its slope b1 (N/m) with ``baseline="linear"`` (0 otherwise).
    point_weights : ndarray
        The noise model's weight (1/sigma, largest 1) of each data point as given (NaN
        where a value was missing).
    correlation : ndarray or None
        Correlation matrix of the fitted parameters (order of ``fitted``), from the linearised
        covariance.
    noise_sigma : float
        The estimated noise (N) of the most weighted point; the weighted reduced chi-square is 1
        by construction, since the noise scale is estimated from the residuals.
    aic, bic : float
        Akaike and Bayesian information criteria (Gaussian noise with the noise model's
        weights and an estimated scale): compare models fitted to the same rows with the
        same weights (lower is better).
    runs_p, residual_autocorrelation : float
        The runs test's p of the residuals' signs in depth order (small: a pattern) and their
        lag-1 autocorrelation (near 0 for independent noise).
    quality : str
        ``good``, ``fair`` or ``poor`` (:func:`fit_quality`).

    Examples
    --------
    >>> import shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> d, F = sb.read_force_csv(example_data_path())
    >>> res = sb.fit(sb.Scene.preset("fit"), d, F, R_L=0.3e-3)
    >>> res.success, res.fitted, res.weights, res.n
    (True, ('mu_H', 'offset'), 'mixed', 40)
    >>> lo, hi = res.mu_H_ci95
    >>> bool(lo < res.mu_H < hi), bool(lo < 52 < hi)       # the truth is 52 N/m
    (True, True)
    >>> print(f"{res.model_force(0.1e-3) * 1e3:.2f} mN at 0.1 mm")
    14.03 mN at 0.1 mm
    >>> res.baseline_model, res.baseline                   # no baseline unless asked for
    ('none', 0.0)
    """

    mu_H: float
    mu_H_ci95: tuple
    offset: float
    offset_ci95: tuple
    residual_rms: float
    n: int
    status: int
    message: str
    R_L: float
    curve: object = field(repr=False, default=None)
    _model: object = field(repr=False, default=None)
    shape_values: dict = field(default_factory=dict)
    shape_ci95: dict = field(default_factory=dict)
    derived: dict = field(default_factory=dict)
    fitted: tuple = ("mu_H", "offset")
    weights: str = DEFAULT_WEIGHTS
    scene: object = field(repr=False, default=None)
    curves_computed: int = 0
    interpolation_error: float = None
    warnings: list = field(default_factory=list)
    warning_codes: list = field(default_factory=list)
    baseline_model: str = "none"
    baseline: float = 0.0
    baseline_ci95: tuple = (0.0, 0.0)
    baseline_slope: float = 0.0
    baseline_slope_ci95: tuple = (0.0, 0.0)
    point_weights: object = field(repr=False, default=None)
    correlation: object = field(repr=False, default=None)
    noise_sigma: float = float("nan")
    aic: float = float("nan")
    bic: float = float("nan")
    runs_p: float = float("nan")
    residual_autocorrelation: float = float("nan")

    @property
    def success(self):
        """True when the fit converged and passed its checks (``status == 0``)."""
        return self.status == 0

    def __getattr__(self, name):
        """``res.<p>`` and ``res.<p>_ci95`` of every shape parameter and derived quantity (None
        where there is none)."""
        base, ci = (name[:-5], True) if name.endswith("_ci95") else (name, False)
        if base in SHAPE_PARAMETERS:
            return self.__dict__.get("shape_ci95" if ci else "shape_values", {}).get(base)
        if base in DERIVED:
            e = self.__dict__.get("derived", {}).get(base)
            return None if e is None else (e.ci95 if ci else e.value)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    @property
    def thickness(self):
        """The shell's thickness H (m) when the scene was given one (``Scene(thickness=H/R_L)``,
        ``--thickness``) or a fit estimated it: then beta is the 3D plate's and mu follows from
        mu*H; None otherwise."""
        if self.shape_values.get("thickness") is not None:
            return self.shape_values["thickness"]
        eps = getattr(self.scene, "thickness", None)
        return None if eps is None else eps * self.R_L

    @property
    def mu(self):
        """The shear modulus mu = mu*H / H (Pa), with the thickness known or fitted (else None)."""
        e = self.derived.get("mu")
        return None if e is None else e.value

    @property
    def mu_ci95(self):
        """mu's 95 % interval (Pa): with a given thickness mu*H's over H (H taken as exact)."""
        e = self.derived.get("mu")
        return None if e is None else e.ci95

    @property
    def quality(self) -> str:
        """``good``, ``fair`` or ``poor`` by the transparent rules of :func:`fit_quality`."""
        return fit_quality(self.success, self.warning_codes, self.mu_H, self.mu_H_ci95, self.correlation,
                           self.fitted)

    @property
    def model_error(self):
        """``(error, extrapolated)``: the shell model's largest measured error in F against 3D
        elasticity at this thickness over the mapped scenes (:func:`shellbvp.thickness.model_error`),
        to stand beside the statistical interval; None without a thickness or a map for the model."""
        from .thickness import model_error

        return model_error(self.scene)

    def model_force(self, displacement, mu_H=None):
        """Fitted model force (N) at displacements (m); with ``mu_H`` (N/m), the same model at
        that mu*H (e.g. an end of ``mu_H_ci95``), offset and baseline as fitted."""
        return self._model(np.asarray(displacement, float), self.mu_H if mu_H is None else float(mu_H), self.offset)

    def to_dict(self):
        """A JSON-ready dict (non-finite numbers as None, so the JSON is strict)."""
        def num(v):
            return None if v is None or not math.isfinite(v) else float(v)

        ci = (lambda v: None if v is None else [num(x) for x in v])
        shape = {}
        for name in (*SHAPE_PARAMETERS, *DERIVED):
            shape[name], shape[f"{name}_ci95"] = num(getattr(self, name)), ci(getattr(self, f"{name}_ci95"))
        return {"mu_H": num(self.mu_H), "mu_H_ci95": ci(self.mu_H_ci95), "offset": num(self.offset),
                "offset_ci95": ci(self.offset_ci95), **shape, "fitted": list(self.fitted),
                "weights": self.weights, "residual": num(self.residual_rms), "residual_rms": num(self.residual_rms),
                "n": self.n, "success": self.success, "status": self.status, "message": self.message,
                "warnings": list(self.warnings), "warning_codes": list(self.warning_codes), "R_L": self.R_L,
                "curves_computed": self.curves_computed, "interpolation_error": num(self.interpolation_error),
                "baseline_model": self.baseline_model, "baseline": num(self.baseline),
                "baseline_ci95": ci(self.baseline_ci95), "baseline_slope": num(self.baseline_slope),
                "baseline_slope_ci95": ci(self.baseline_slope_ci95),
                "thickness": None if self.thickness is None else num(self.thickness), "mu": None if self.mu is None
                else num(self.mu), "mu_ci95": ci(self.mu_ci95),
                "quality": self.quality, "noise_sigma": num(self.noise_sigma), "aic": num(self.aic),
                "bic": num(self.bic), "runs_p": num(self.runs_p),
                "residual_autocorrelation": num(self.residual_autocorrelation),
                "correlation": None if self.correlation is None else
                [[num(v) for v in row] for row in np.asarray(self.correlation)],
                "model_error": None if self.model_error is None else num(self.model_error[0]),
                "model_error_extrapolated": None if self.model_error is None else self.model_error[1],
                "units": {"mu_H": "N/m (= um*MPa)", "offset": "m", "residual": "N (rms)",
                          "residual_rms": "N", "R_L": "m",
                          **{p.name: p.unit_text or p.unit for p in SHAPE_PARAMETERS.values()},
                          **{d.name: d.unit for d in DERIVED.values()},
                          "baseline": "N", "baseline_slope": "N/m", "thickness": "m", "mu": "Pa",
                          "model_error": "1 (fraction of F)", "noise_sigma": "N (of the most weighted point)",
                          "aic": "1", "bic": "1", "runs_p": "1", "residual_autocorrelation": "1",
                          "correlation": "1 (order of fitted)"}}


# -- model curves ------------------------------------------------------------------------------
_CACHE: OrderedDict = OrderedDict()
_CACHE_SIZE = 32


def clear_model_curves():
    """Forget the model curves memoised in this process (the next fit computes its own)."""
    _CACHE.clear()


def _model_curve(scene, deltas, tol, counter=None, progress=None):
    """The curve of ``scene`` at ``deltas`` (memoised per process: repeated fits reuse it);
    ``progress(description, delta_max) -> (bar, callback)`` draws its progress."""
    from .continuation import curve

    try:
        key = (scene, tuple(float(x) for x in deltas), float(tol))
        hash(key)
    except TypeError:
        key = None
    if key is not None and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    _check_model_start(scene, float(deltas[0]), tol)
    bar, callback = progress("model curve", float(deltas[-1])) if progress is not None else (None, None)
    try:
        c = curve(scene, deltas=deltas, tol=tol, estimate_error=False, callback=callback)
    finally:
        if bar is not None:
            bar.close()
    if counter is not None:
        counter[0] += 1
    c.solutions = []  # profiles are not needed here; keep the cache small
    if scene.transverse_shear:
        c = _with_shear(c)
    if key is not None:
        _CACHE[key] = c
        while len(_CACHE) > _CACHE_SIZE:
            _CACHE.popitem(last=False)
    return c


def _with_shear(c):
    """The model curve's force at its own depths taken as the thick shell's (``delta +
    shear_delta``, :mod:`shellbvp.thickness`), up to the deepest one it reaches."""
    import dataclasses

    F = c.force_at(c.delta)
    n = int(np.argmax(~np.isfinite(F))) if not np.all(np.isfinite(F)) else F.size
    points = {k: np.asarray(v)[:n] for k, v in c.points.items()}
    points["force"] = F[:n]
    return dataclasses.replace(c, points=points, flags=list(c.flags[:n]))


def _check_model_start(scene, delta, tol):
    """ValueError unless the model curve can start at its shallowest depth ``delta`` (one solve).

    A curve at requested depths starts from a single contact cap; at depths where
    the scene's contact is the point-load limit (far shallower than the shell's
    size) it cannot start, so data that shallow are reported before the curve.
    """
    from .configurations import is_single_cap
    from .state import solve

    sol = solve(scene, delta=delta, tol=tol, estimate_error=False, topology="cap")
    if not (sol.success and is_single_cap(sol)):
        why = (sol.message if not sol.success else "the contact there is the point-load limit (the contact cap "
               "is exponentially small), from which the model curve cannot start")
        raise ValueError(f"the model curve cannot start at its shallowest depth delta = {delta:.3g} "
                         f"(1/{N_DEPTHS} of delta_max = 1.2 x the deepest data depth / R_L): {why}. "
                         f"Check the displacement units and the rim radius R_L (--radius): data this shallow "
                         f"against R_L do not determine mu*H with this scene")


def _beyond_message(c, need):
    return (f"the data reach delta = {need:.4g} (deepest displacement / R_L) but the model curve ends at "
            f"delta = {c.delta[-1]:.4g} ({c.stop_reason}): the model cannot explain the deepest points; "
            f"fit the data up to delta = {c.delta[-1]:.4g} x R_L, or check the units and R_L (--radius)")


class _Shape:
    """Nondimensional force F(delta; theta) from model curves at nodes theta_k on one delta grid.

    Every node must reach ``need`` (the deepest datum): without a shape
    parameter (one node, theta None) a curve that ends before it is a
    ValueError; with one, ``add`` returns False.  F is a cubic spline across
    the nodes at each depth and a monotone cubic (PCHIP) in delta.
    """

    def __init__(self, scene_at, grid, tol, need, counter, progress=None):
        self.scene_at, self.grid, self.tol, self.need, self.counter = scene_at, grid, tol, need, counter
        self.progress = progress
        self.nodes = {}  # theta -> curve
        self._spline = None

    def add(self, theta):
        """Compute the node curve at theta; False if it does not reach the data."""
        c = _model_curve(self.scene_at(theta), self.grid, self.tol, self.counter, self.progress)
        if len(c) < 3:
            raise ValueError(f"the model curve of this scene could not be computed to the data's depths "
                             f"({c.stop_reason})")
        if c.delta[-1] < self.need * (1 - 1e-12):
            if theta is not None:
                return False
            raise ValueError(_beyond_message(c, self.need))
        self.nodes[theta] = c
        self._spline = None
        return True

    @property
    def thetas(self):
        return sorted(self.nodes)

    def _table(self):
        if self._spline is None:
            th = self.thetas
            m = min(len(self.nodes[t]) for t in th)
            rows = np.array([np.r_[0.0, self.nodes[t].force[:m]] for t in th])
            self.top = float(self.grid[m - 1])
            self.x = np.r_[0.0, self.grid[:m]]
            self._spline = rows[0] if len(th) == 1 else CubicSpline(th, rows, axis=0)
        return self._spline

    def at(self, theta):
        """(F, dF/ddelta, top): PCHIP of F in delta at theta."""
        sp = self._table()
        vals = sp if isinstance(sp, np.ndarray) else sp(theta)
        P = PchipInterpolator(self.x, vals, extrapolate=False)
        return P, P.derivative(), self.top


# -- least squares at a fixed shape ------------------------------------------------------------
class _Model:
    """Weighted least squares at a fixed curve shape F(delta).

    ``F_i = mu_H R_L F((d_i - d0)/R_L) + b0 + b1 (d_i - d0)``: the parameter vector is
    always ``q = (mu_H, d0, b0, b1)`` (:data:`MODEL_PARAMETERS`); the ones not fitted stay
    0.  The model is linear in mu_H, b0 and b1, so the start is a search over d0 with
    those three solved exactly at every trial d0 (variable projection), then all free
    parameters are refined together.
    """

    def __init__(self, d, f, R_L, fit_offset, baseline, loss):
        self.d, self.f, self.R_L, self.loss = d, f, R_L, loss
        self.free = np.array([True, bool(fit_offset), baseline != "none", baseline == "linear"])
        self.big = 1e3 * (np.max(np.abs(f)) + 1)
        self.fscale = float(np.max(np.abs(f))) or 1.0

    @staticmethod
    def shape(P, top, x):  # nondimensional model force, 0 before contact, NaN beyond the curve
        x = np.asarray(x, float)
        out = np.where(x <= 0, 0.0, P(np.clip(x, 0, top)))
        return np.where(x > top, np.nan, out)

    def full(self, p):
        """The free parameters ``p`` -> ``q = (mu_H, d0, b0, b1)``."""
        q = np.zeros(4)
        q[self.free] = p
        return q

    def baseline(self, disp, q):
        """The force baseline b0 + b1 (d - d0), N."""
        return q[2] + q[3] * (np.asarray(disp, float) - q[1])

    def indentation(self, P, top, disp, q):
        """The shell's force (model minus baseline), N."""
        return q[0] * self.R_L * self.shape(P, top, (np.asarray(disp, float) - q[1]) / self.R_L)

    def force(self, P, top, disp, q):
        return self.indentation(P, top, disp, q) + self.baseline(disp, q)

    def _columns(self, P, top, d0):
        """Columns of the linear parameters (mu_H, b0, b1) at a fixed d0 (the free ones)."""
        cols = [self.R_L * self.shape(P, top, (self.d - d0) / self.R_L), np.ones_like(self.d), self.d - d0]
        return [c for c, free in zip(cols, self.free[[0, 2, 3]]) if free]

    def start(self, P, top, w):
        """Start values: the best d0 on a grid (mu_H, b0, b1 solved exactly at each)."""
        d = self.d
        if not self.free[1]:
            trial = np.array([0.0])
        else:
            depth_ok = np.max(d) - top * self.R_L  # deeper data would be beyond the curve
            k = int(np.sum(self.free))
            lo, hi = max(depth_ok, np.min(d) - 0.5 * np.ptp(d)), np.sort(d)[-(k + 1)]
            trial = np.linspace(lo, hi, 160) if hi > lo else np.array([lo])
        best = (np.inf, None)
        for d0 in trial:
            cols = self._columns(P, top, d0)
            A = w[:, None] * np.column_stack(cols)
            if not np.all(np.isfinite(A)):
                continue
            coef, *_ = np.linalg.lstsq(A, w * self.f, rcond=None)
            if not coef[0] > 0:
                continue
            r = A @ coef - w * self.f
            rss = float(r @ r)
            if rss < best[0]:
                q = np.zeros(4)
                q[[0, 2, 3]] = self._spread(coef)
                q[1] = d0
                best = (rss, q)
        if best[1] is None:  # no trial gives a positive mu_H: start at d0 = 0 with a unit-scale mu_H
            q = np.zeros(4)
            q[0] = 1.0
            return q[self.free]
        return best[1][self.free]

    def _spread(self, coef):
        """(mu_H, b0, b1) from the coefficients of the free linear columns."""
        out = np.zeros(3)
        out[self.free[[0, 2, 3]]] = coef
        return out

    def fit(self, P, dP, top, w, start=None):
        """Weighted least squares of the free parameters at a fixed shape: (result, weighted RSS,
        weighted Jacobian); ``result.x`` holds the free parameters (see :meth:`full`)."""
        d, f, R_L = self.d, self.f, self.R_L

        def residual(p):
            r = self.force(P, top, d, self.full(p)) - f
            return w * np.nan_to_num(r, nan=self.big)

        def jac(p):
            mu_H, d0, _, b1 = self.full(p)
            x = (d - d0) / R_L
            ds = np.where((x > 0) & (x <= top), dP(np.clip(x, 0, top)), 0.0)
            cols = [R_L * np.nan_to_num(self.shape(P, top, x)), -mu_H * np.nan_to_num(ds) - b1,
                    np.ones_like(d), d - d0]
            return w[:, None] * np.stack([c for c, free in zip(cols, self.free) if free], axis=1)

        start = self.start(P, top, w) if start is None else np.asarray(start, float)
        scale = np.array([abs(start[0]) or 1.0, 0.01 * R_L, 0.01 * self.fscale, 0.01 * self.fscale / R_L])
        res = optimize.least_squares(residual, start, jac=jac, x_scale=scale[self.free], loss=self.loss,
                                     method="trf")
        r = residual(res.x)
        return res, float(np.dot(r, r)), jac(res.x)


def _weights(kind, model_force, f, floor, w_prev):
    """Weights 1/sigma_i of the noise model, from the current model force (IRLS)."""
    if kind == "uniform":
        return np.ones_like(f)
    m = np.abs(np.nan_to_num(model_force))
    fmax = np.max(np.abs(f))
    if kind == "relative":
        return 1.0 / np.maximum(m, floor * fmax)
    # mixed: sigma^2 = a^2 + b^2 F^2, (a^2, b^2) >= 0 by least squares on the squared residuals
    # (each row scaled by the previous sigma^2: squared residuals have variance ~ sigma^4)
    r2 = (np.nan_to_num(model_force) - f) ** 2
    s2_prev = 1.0 / w_prev ** 2
    A = np.column_stack([np.ones_like(m), (m / fmax) ** 2]) / s2_prev[:, None]
    coef, _ = optimize.nnls(A, r2 / s2_prev)
    s2 = coef[0] + coef[1] * (m / fmax) ** 2
    if not np.any(s2 > 0):
        return np.ones_like(f)
    s2 = np.maximum(s2, 1e-6 * np.max(s2))
    return 1.0 / np.sqrt(s2 / np.max(s2))


def _check_data(d, f, k, origin=0.0):
    """Checks of the data before any model curve; returns the finite rows, or raises ValueError.

    ``k`` is the number of fitted parameters.  NaN rows are dropped (missing
    values); infinite values, too few distinct displacements and a force that
    does not increase with depth are errors.
    """
    if d.shape != f.shape:
        raise ValueError(f"displacement and force must have the same length; got {d.size} and {f.size}")
    for name, v in (("displacement", d), ("force", f)):
        bad = np.flatnonzero(np.isinf(v))
        if bad.size:
            raise ValueError(f"{name} must be finite; got {v[bad[0]]} at index {bad[0]} "
                             f"({bad.size} infinite values)")
    keep = np.isfinite(d) & np.isfinite(f)
    d, f = d[keep], f[keep]
    need = max(3, k + 2)
    if d.size < need:
        raise ValueError(f"need at least {need} finite data points; got {d.size}")
    distinct = np.unique(d).size
    if distinct < need:
        raise ValueError(f"displacement: need at least {need} distinct values to fit {k} parameters; got "
                         f"{distinct} (the data are {d.size} points at {distinct} depth(s))")
    if np.max(d) <= origin:
        raise ValueError("displacement must reach positive values (indentation into the shell)" if origin == 0 else
                         f"displacement must reach beyond the contact point guess {origin:g} m")
    if np.ptp(f) == 0:
        raise ValueError(f"force is constant ({f[0]:g} N at every point): it must increase with the depth "
                         "of indentation")
    rho, p, p_less = rank_trend(d, f)
    if not p < TREND_P and p_less < TREND_P:
        raise ValueError(f"force falls as the displacement grows (Spearman rank correlation {rho:.2f}): the "
                         "displacement runs the other way (an AFM height falls as the tip goes in) or the "
                         "compression is recorded as a negative force; flip one with --invert displacement or "
                         "--invert force (read_instrument(..., invert=...))")
    if not p < TREND_P:
        raise ValueError(f"force does not increase with displacement (Spearman rank correlation {rho:.2f}, "
                         f"one-sided p = {p:.2g}, needed < {TREND_P:g}): these data show no indentation "
                         "response to fit (check the columns and their order with --columns)")
    return d, f


def _check_bounds(name, bounds, lo_ok, hi_ok, value):
    try:
        lo, hi = (float(v) for v in bounds)
    except (TypeError, ValueError):
        raise ValueError(f"{name}_bounds must be two numbers (low, high); got {bounds!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo_ok(lo) and hi_ok(hi) and lo < hi):
        raise ValueError(f"{name}_bounds must satisfy the valid range of {name} with low < high; got {bounds!r}")
    if not lo <= value <= hi:
        raise ValueError(f"the scene's {name} = {value:g} (the start of the fit) must lie within "
                         f"{name}_bounds = ({lo:g}, {hi:g})")
    return lo, hi


def fit(scene, displacement, force, *, R_L, fit_offset=True, free=(), bounds=None, weights=None, floor=0.05,
        delta_max=None, tol=1e-6, loss="linear", baseline="none", contact_guess=None, progress=None, **aliases):
    """Least-squares fit of mu*H (the displacement origin, and a shape parameter) to measured data.

    Parameters
    ----------
    scene : Scene
        Shape, indenter, material and beta (nondimensional); a free shape parameter's value
        in it is the start of the search.
    displacement, force : array_like
        Measured indenter displacement (m, > 0 into the shell) and force (N).
    R_L : float
        Rim radius of the sample (m).
    fit_offset : bool
        Also fit the origin of the displacement (contact point).
    baseline : {"none", "constant", "linear"}
        Force baseline fitted with the contact point (as nanite does): ``"constant"`` adds
        a force offset b0 (the force the instrument reads before contact), ``"linear"``
        also a slope, ``b0 + b1 (d - d0)`` (a tilted baseline: drift or drag, continued
        through contact).  It needs data before the contact point (the approach) to be
        determined well.
    contact_guess : float, optional
        A first guess of the contact point (m; e.g. :func:`shellbvp.instrument.estimate_contact`):
        the model curve is computed to 1.2 x the depth of the data beyond it.  Default 0
        (displacements measured from about the contact point).
    progress : callable, optional
        ``progress(description, delta_max) -> (bar, callback)`` for each model curve computed
        (e.g. ``lambda d, m: shellbvp.progress.curve_progress(m, d)``); None: silent.
    free : sequence of str
        Also fit a shape parameter, a name of :data:`shellbvp.shape_parameters.SHAPE_PARAMETERS`
        (one at most), e.g. ``"beta"``, the Mooney–Rivlin ``"alpha"`` (subset of [0, 1]), the
        ``"pressure"`` below the shell (nondimensional ``p R_L/(mu H)``; default range from 0 to
        the larger of 4 times the scene's and ``40 sqrt(3 beta)``, i.e. Vella's ``tau = p R^2/(4
        sqrt(B Y))`` up to 10 for a pole of unit curvature) or the shell's ``"thickness"``
        (``H/R_L``, from the scene's; beta follows it).  With the pressure fitted, one curve gives
        mu*H and the pressure in Pa (Vella et al. 2012's assay, with the full model); with the
        thickness, H and the modulus mu = mu*H / H.
    bounds : dict, optional
        ``{name: (low, high)}``: the search range of the free parameter (nondimensional, as in
        the scene); default the parameter's own.
    **aliases
        ``fit_<name>=True`` and ``<name>_bounds=(low, high)`` for each shape parameter (e.g.
        ``fit_beta=True, beta_bounds=(1e-3, 0.1)``): the same as ``free`` and ``bounds``.
    weights : {"uniform", "relative", "mixed"}, optional
        Noise model: the same force noise at every point, noise proportional
        to the force, or both (``sigma^2 = a^2 + b^2 F^2``, a and b estimated);
        default :data:`DEFAULT_WEIGHTS` ("mixed", see benchmarks/fit_coverage.py).
    floor : float
        With relative weights, forces below ``floor * max|force|`` are weighted
        as if they were that large (near the contact point F -> 0); in (0, 1].
    delta_max : float, optional
        Largest depth of the model curves (default: 1.2 x the largest measured depth/R_L).
    tol : float
        Collocation tolerance of the model curves.
    loss : str
        scipy.optimize.least_squares loss ('linear', or 'soft_l1' to damp outliers).

    Returns
    -------
    FitResult
        ``status`` (:data:`FIT_STATUS`) 0 only when the solver converged, mu*H > 0
        and the 95 % intervals of mu*H and the offset are finite with mu*H's
        narrower than mu*H itself.  ``warnings``: a residual sign pattern the
        noise model does not explain (:func:`runs_test`, p < :data:`RUNS_P`, at
        least :data:`RUNS_MIN_POINTS` points), mu*H outside :data:`PLAUSIBLE_MU_H`,
        a shape parameter's interval at its search bound.

    Raises
    ------
    ValueError
        For arguments out of range and for data the fit cannot use, before any
        model curve is computed: infinite values, fewer than ``max(3, p + 2)``
        distinct displacements (p fitted parameters), a force that does not
        increase with displacement (Spearman, one-sided p >= :data:`TREND_P`),
        data too shallow for the model curve to start (one solve at its first
        depth); and, once the curve is computed, data deeper than it reaches.

    Examples
    --------
    The synthetic record shipped with the package (preset ``fit``, R_L = 0.3 mm,
    mu*H = 52 N/m, 2 % noise); one model curve, about 3 s:

    >>> import shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> d, F = sb.read_force_csv(example_data_path())
    >>> res = sb.fit(sb.Scene.preset("fit"), d, F, R_L=0.3e-3)
    >>> print(f"mu*H = {res.mu_H:.2f} N/m [{res.mu_H_ci95[0]:.2f}, {res.mu_H_ci95[1]:.2f}], "
    ...       f"offset {res.offset * 1e6:.2f} um")
    mu*H = 51.91 N/m [51.53, 52.29], offset 9.95 um

    Data the fit cannot use are refused before any curve is computed:

    >>> sb.fit(sb.Scene.preset("fit"), d[:3], F[:3], R_L=0.3e-3)
    Traceback (most recent call last):
    ...
    ValueError: ...
    """
    weights = DEFAULT_WEIGHTS if weights is None else weights
    if weights not in WEIGHTS:
        raise ValueError(f"weights must be one of {WEIGHTS}; got {weights!r}")
    if not (isinstance(floor, (int, float)) and 0 < floor <= 1):
        raise ValueError(f"floor (of relative weights, fraction of max |force|) must be in (0, 1]; got {floor!r}")
    free, bounds = free_parameters(free, bounds, aliases)
    if baseline not in BASELINES:
        raise ValueError(f"baseline must be one of {BASELINES}; got {baseline!r}")
    origin = 0.0 if contact_guess is None else contact_guess
    if not (isinstance(origin, (int, float)) and math.isfinite(origin)):
        raise ValueError(f"contact_guess (m) must be a finite number; got {contact_guess!r}")
    d = np.asarray(displacement, float).ravel()
    f = np.asarray(force, float).ravel()
    keep = np.isfinite(d) & np.isfinite(f) if d.shape == f.shape else None
    k = 1 + bool(fit_offset) + len(free) + (baseline != "none") + (baseline == "linear")
    d, f = _check_data(d, f, k, float(origin))
    if not (isinstance(R_L, (int, float)) and math.isfinite(R_L) and R_L > 0):
        raise ValueError(f"R_L (rim radius, m) must be a finite number > 0; got {R_L!r}")
    sp = _search_of(scene, free[0], bounds.get(free[0])) if free else None
    depth = (np.max(d) - origin) / R_L  # the deepest datum's delta, if the contact is at the guess
    dm = 1.2 * depth if delta_max is None else float(delta_max)
    if not (math.isfinite(dm) and dm > 0):
        raise ValueError(f"delta_max must be > 0; got {delta_max!r}")
    grid = dm * np.arange(1, N_DEPTHS + 1) / N_DEPTHS
    counter = [0]
    mdl = _Model(d, f, R_L, fit_offset, baseline, loss)
    noise = _Noise(weights, floor)
    if sp is None:
        shape = _Shape(lambda th: scene, grid, tol, depth, counter, progress)
        shape.add(None)
        P, dP, top = shape.at(None)
        res, rss, J, w = noise.irls(mdl, P, dP, top)
        fitted = _Fitted(res, rss, J, w, scene, shape.nodes[None], P, top)
        notes = []
    else:
        search = _ProfileSearch(sp, _Shape(sp.scene_at, grid, tol, depth, counter, progress), mdl, depth)
        fitted = search.run(noise, k)
        notes = search.notes
    return _fit_result(fitted, mdl, sp, k, notes, keep, weights, baseline, counter[0])


def free_parameters(free=(), bounds=None, aliases=None):
    """``(free, bounds)`` of :func:`fit` checked, its ``fit_<name>`` and ``<name>_bounds``
    aliases folded in: a tuple of shape parameter names (one at most) and ``{name: bounds}``."""
    free = (free,) if isinstance(free, str) else tuple(free)
    bounds = dict(bounds or {})
    for key, value in (aliases or {}).items():
        if key.startswith("fit_") and key[4:] in SHAPE_PARAMETERS:
            free += (key[4:],) if value else ()
        elif key.endswith("_bounds") and key[:-7] in SHAPE_PARAMETERS:
            if value is not None:
                bounds[key[:-7]] = value
        else:
            raise TypeError(f"fit() got an unexpected keyword argument {key!r}")
    for name in free + tuple(bounds):
        shape_parameter(name)
    free = tuple(dict.fromkeys(free))
    if len(free) > 1:
        raise ValueError(f"{', '.join(f'fit_{n}' for n in SHAPE_PARAMETERS)}: fit one of "
                         f"{', '.join(SHAPE_PARAMETERS)} at a time (each changes the curve's shape only weakly; two "
                         f"with mu*H are not identifiable from one curve); got {', '.join(free)}")
    return free, bounds


@dataclass
class _ShapeSearch:
    """The shape parameter fitted with mu*H: its declaration, its search range, step and start
    in theta (``ln x`` or ``x``) and the scene at a theta."""
    param: ShapeParameter
    bounds: tuple
    step: float
    theta0: float
    scene_at: object

    @property
    def name(self):
        return self.param.name


def _search_of(scene, name, bounds):
    """The :class:`_ShapeSearch` of the free parameter ``name`` (its bounds checked)."""
    param = shape_parameter(name)
    why = param.unavailable(scene)
    if why:
        raise ValueError(why)
    x0 = param.get(scene)
    lo, hi = _check_bounds(name, param.default_bounds(scene) if bounds is None else bounds, param.low_ok,
                           param.high_ok, x0)
    return _ShapeSearch(param, (param.to_theta(lo), param.to_theta(hi)), param.step(scene), param.to_theta(x0),
                           lambda th: param.set(scene, param.from_theta(th)))


@dataclass
class _Noise:
    """The noise model's weights, re-estimated from the model force (IRLS)."""
    kind: str
    floor: float

    def reweight(self, mdl, P, top, q, w):
        """(new weights, their largest relative change from ``w``)."""
        w_new = _weights(self.kind, mdl.indentation(P, top, mdl.d, q), mdl.f - mdl.baseline(mdl.d, q), self.floor, w)
        return w_new, np.max(np.abs(w_new / w - 1))

    def irls(self, mdl, P, dP, top):
        """Fit at a fixed shape, iteratively reweighted: (result, RSS, Jacobian, weights)."""
        w = np.ones_like(mdl.f)
        res, rss, J = mdl.fit(P, dP, top, w)
        for it in range(8):
            if self.kind == "uniform":
                break
            w, change = self.reweight(mdl, P, top, mdl.full(res.x), w)
            change = change if it > 0 else np.inf
            res, rss, J = mdl.fit(P, dP, top, w, start=res.x)
            if change < 1e-6:
                break
        return res, rss, J, w


@dataclass
class _Fitted:
    """What a fit found: the least-squares result at the fitted shape, its weighted RSS and
    Jacobian (a column for the shape parameter too), the weights, the scene and model curve
    reported, the shape F(delta) fitted, and the shape parameter's estimate and interval."""
    res: object
    rss: float
    J: np.ndarray
    w: np.ndarray
    scene: object
    curve: object
    P: object
    top: float
    theta: float | None = None
    theta_ci: tuple | None = None
    interpolation_error: float | None = None


class _ProfileSearch:
    """The shape parameter by its profile likelihood: the weighted RSS with mu*H (and the
    offset and baseline) fitted at each theta, on model curves at nodes in theta (a
    :class:`_Shape`) added where the search needs them; its 95 % interval where the RSS
    crosses the likelihood-ratio threshold."""

    def __init__(self, sp, shape, mdl, depth):
        self.sp, self.shape, self.mdl = sp, shape, mdl
        self.lim = [sp.bounds[0], sp.bounds[1]]  # shrinks where node curves do not reach the data
        self.notes = []
        self.w = None
        if not shape.add(sp.theta0):
            raise ValueError(f"the model curve at the scene's {sp.name} ends before the deepest data point "
                             f"(delta = {depth:.4g}): fit shallower data, or check the units and R_L")

    def extend(self, side):
        """Add the next node beyond the nodes on side -1 (low) or +1 (high); False at the limit."""
        shape, lim, step, name = self.shape, self.lim, self.sp.step, self.sp.name
        th = shape.thetas
        edge = th[0] if side < 0 else th[-1]
        if (edge <= lim[0] + 1e-12) if side < 0 else (edge >= lim[1] - 1e-12):
            return False
        if shape.counter[0] >= _MAX_CURVES:
            self.notes.append(("max_curves", f"stopped adding model curves at {_MAX_CURVES}"))
            return False
        new = edge + side * step
        if side < 0:
            new = lim[0] if new < lim[0] + 0.25 * step else new
        else:
            new = lim[1] if new > lim[1] - 0.25 * step else new
        if shape.add(new):
            return True
        # this curve ends before the data: the range ends between edge and new
        lim[0 if side < 0 else 1] = edge
        self.notes.append(("search_range", f"model curves at {name} = {_show(self.sp.param, new)} end before the "
                           f"deepest data point; searched {name} up to {_show(self.sp.param, edge)}"))
        return False

    def profile(self, theta):
        """(weighted RSS, least-squares result) at ``theta``, with the current weights."""
        P, dP, top = self.shape.at(theta)
        res, rss, J = self.mdl.fit(P, dP, top, self.w)
        return rss, res

    def estimate(self):
        """The theta of least profiled RSS (nodes added while it lies at the end of them)."""
        while True:
            th = self.shape.thetas
            vals = [self.profile(t)[0] for t in th]
            i = int(np.argmin(vals))
            if i == 0 and self.extend(-1):
                continue
            if i == len(th) - 1 and self.extend(+1):
                continue
            a, b = th[max(i - 1, 0)], th[min(i + 1, len(th) - 1)]
            if a == b:
                return th[i]
            r = optimize.minimize_scalar(lambda t: self.profile(t)[0], bounds=(a, b), method="bounded",
                                         options={"xatol": 1e-5 * self.sp.step})
            return float(r.x) if r.fun <= vals[i] else th[i]

    def _on_a_node(self, theta_hat, margin):
        """The estimate with the curve at it: it moves onto the nearest node when that node's
        profiled RSS is within 1 % of the interval's likelihood-ratio margin of the minimum
        (indistinguishable from it; the reported curve is then the fitted one); otherwise one
        more curve at the estimate, which measures the interpolation error (the first such
        curve's, before any exact one) and joins the nodes.  (theta, interpolation error)."""
        shape, grid = self.shape, self.shape.grid
        interp_err = None
        for _ in range(3):
            rss_hat = self.profile(theta_hat)[0]
            near = min(shape.thetas, key=lambda t: abs(t - theta_hat))
            if self.profile(near)[0] - rss_hat <= 0.01 * margin * rss_hat:
                theta_hat = near
                break
            P_old, _, top_old = shape.at(theta_hat)
            if not shape.add(theta_hat):
                break
            ce = shape.nodes[theta_hat]
            m = min(len(ce), int(np.sum(grid <= top_old + 1e-15)))
            err = float(np.max(np.abs(P_old(ce.delta[:m]) - ce.force[:m])) / np.max(np.abs(ce.force[:m])))
            interp_err = err if interp_err is None else interp_err
            theta_hat = self.estimate()
        return theta_hat, 0.0 if interp_err is None else interp_err

    def crossing(self, side, theta_hat, thr):
        """Where the profiled RSS crosses ``thr`` on ``side`` of the estimate: (theta, True if
        the search range ended first)."""
        while True:
            th = self.shape.thetas
            pts = [t for t in th if (t < theta_hat if side < 0 else t > theta_hat)]
            pts = pts[::-1] if side < 0 else pts
            inner = theta_hat
            for t in pts:
                if self.profile(t)[0] > thr:
                    return float(optimize.brentq(lambda u: self.profile(u)[0] - thr, min(inner, t), max(inner, t),
                                                 xtol=1e-6 * self.sp.step)), False
                inner = t
            if not self.extend(side):
                return (th[0] if side < 0 else th[-1]), True

    def run(self, noise, k):
        """The fit with the shape parameter (``k`` parameters in all): :class:`_Fitted`."""
        sp, shape, mdl = self.sp, self.shape, self.mdl
        self.extend(-1)
        self.extend(+1)
        self.w = noise.irls(mdl, *shape.at(sp.theta0))[3]  # the noise model's weights at the start value
        theta_hat = self.estimate()
        for it in range(8):
            if noise.kind == "uniform":
                break
            rss, res = self.profile(theta_hat)
            P, dP, top = shape.at(theta_hat)
            self.w, change = noise.reweight(mdl, P, top, mdl.full(res.x), self.w)
            change = change if it > 0 else np.inf
            theta_hat = self.estimate()
            if change < 1e-6:
                break
        dof = max(mdl.d.size - k, 1)
        margin = special.fdtri(1, dof, 0.95) / dof  # thr = RSS_min (1 + margin)
        theta_hat, interp_err = self._on_a_node(theta_hat, margin)
        rss_min, res = self.profile(theta_hat)
        thr = rss_min * (1 + margin)
        (c_lo, open_lo), (c_hi, open_hi) = self.crossing(-1, theta_hat, thr), self.crossing(+1, theta_hat, thr)
        if open_lo or open_hi:
            name, lim = sp.name, self.lim
            self.notes.append(("search_range", f"the 95% interval of {name} reaches the end of the searched range "
                               f"({_show(sp.param, lim[0])}, {_show(sp.param, lim[1])}); {name} is not determined "
                               f"by the data on that side"))
        P, dP, top = shape.at(theta_hat)
        res, rss, J = mdl.fit(P, dP, top, self.w, start=res.x)
        # the shape parameter's column of the Jacobian (finite differences across the interpolated curves)
        # (central; one-sided at the end of the nodes)
        h = 1e-4 * sp.step
        ths = [min(max(t, shape.thetas[0]), shape.thetas[-1]) for t in (theta_hat - h, theta_hat + h)]
        Fp = [mdl.force(*_drop(shape.at(t)), mdl.d, mdl.full(res.x)) for t in ths]
        col = self.w * np.nan_to_num((Fp[1] - Fp[0]) / (ths[1] - ths[0]))
        near = min(shape.thetas, key=lambda t: abs(t - theta_hat))
        return _Fitted(res, rss, np.column_stack([J, col]), self.w, shape.scene_at(near), shape.nodes[near], P, top,
                       theta_hat, (c_lo, c_hi), interp_err)


def _fit_result(fitted, mdl, sp, k, notes, keep, weights, baseline, curves_computed):
    """The :class:`FitResult` of what a fit found: Wald (t) intervals of the free parameters
    from the weighted Jacobian, the shape parameter's profile interval, status and warnings."""
    res, rss, J, w, P, top, R_L = fitted.res, fitted.rss, fitted.J, fitted.w, fitted.P, fitted.top, mdl.R_L
    d, f = mdl.d, mdl.f
    n = d.size
    dof = max(n - k, 1)
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
        return mu_H * R_L * _Model.shape(P, top, (disp - d0) / R_L) + b0 + b1 * (disp - d0)

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
    status, checks = check_result(bool(res.success), mu_H, mu_ci, off_ci, bool(np.all(np.isfinite(resid))),
                                   resid.size, runs)
    found = notes + checks
    for _, text in found:
        log.info("fit: warning: %s", text)
    message = f"{FIT_STATUS[status]} (least squares: {res.message})"
    point_weights = np.full(keep.size, np.nan)
    point_weights[keep] = w / np.max(w)
    diagnostics = fit_diagnostics(cov, rss, n, J.shape[1], w * resid, d, runs)
    return FitResult(mu_H=mu_H, mu_H_ci95=mu_ci, offset=d0,
                     offset_ci95=off_ci, residual_rms=float(np.sqrt(np.mean(np.nan_to_num(resid, nan=mdl.big) ** 2))),
                     n=n, status=status, message=message, R_L=float(R_L), curve=fitted.curve, _model=model,
                     shape_values=values, shape_ci95=intervals, derived=derived, fitted=fitted_names,
                     weights=weights, scene=fit_scene, curves_computed=curves_computed,
                     interpolation_error=fitted.interpolation_error, warnings=[t for _, t in found],
                     warning_codes=[code for code, _ in found], baseline_model=baseline, baseline=b0,
                     baseline_ci95=ci[2], baseline_slope=b1, baseline_slope_ci95=ci[3],
                     point_weights=point_weights, **diagnostics)


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
    """``{"mu": Estimate}`` of a scene with a thickness (mu*H over H, H taken as exact), else {}."""
    from .units import format_in

    eps = getattr(scene, "thickness", None)
    if eps is None:
        return {}
    H = eps * R_L
    return {"mu": Estimate(mu_H / H, (mu_H_ci[0] / H, mu_H_ci[1] / H), "Pa", "mu", "MPa",
                           f"H = {format_in(H, 'um', 'length')}, eps = H/R_L = {eps:.3g}, beta = eps^2/3")}


def _drop(pdt):
    return pdt[0], pdt[2]


def _show(param, theta):
    return f"{param.from_theta(theta):.3g}"


def fit_record(scene, record, *, R_L, segment="loading", baseline="auto", **options):
    """Fit one segment of an instrument record (:func:`shellbvp.instrument.read_instrument`).

    Parameters
    ----------
    scene : Scene
    record : InstrumentRecord
    R_L : float
        Rim radius (m).
    segment : {"loading", "retraction", "all"}
        Rows to fit (:meth:`InstrumentRecord.mask`): by default the pushing part, the
        approach and the loading, never the retraction with it.
    baseline : {"auto", "none", "constant", "linear"}
        ``auto``: a constant baseline when the segment has an approach before contact
        (:func:`shellbvp.instrument.estimate_contact` finds one), none otherwise.
    **options
        Passed to :func:`fit` (``fit_offset``, ``free``, ``weights``, ``tol``, ...).

    Returns
    -------
    result : FitResult
    used : ndarray of bool, shape (len(record),)
        The rows fitted.  With ``segment="loading"`` the record's pushing rows are
        relabelled at the fitted contact point (before it 'approach').

    Raises
    ------
    ValueError
        An unknown segment or baseline, a segment with fewer than 3 rows (the message
        gives each segment's count), or what :func:`fit` refuses.

    Examples
    --------
    An instrument record made from the shipped example (mu*H = 52 N/m, contact at
    0.01 mm): an approach at a force baseline of 0.05 mN, the loading, and a
    retraction that carries less force (hysteresis), in um and uN:

    >>> import os, tempfile
    >>> import numpy as np
    >>> import shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> d, F = sb.read_force_csv(example_data_path())             # m, N
    >>> disp = np.r_[np.linspace(0, 9e-6, 10), d, d[::-1]]
    >>> force = np.r_[np.zeros(10), F, 0.85 * F[::-1]] + 50e-6
    >>> path = os.path.join(tempfile.mkdtemp(), "seed1.tsv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("Time (s)\\tDisplacement (um)\\tForce (uN)\\n")
    ...     _ = fh.writelines(f"{0.1 * i:.1f}\\t{a * 1e6:.3f}\\t{b * 1e6:.3f}\\n"
    ...                       for i, (a, b) in enumerate(zip(disp, force)))
    >>> rec = sb.read_instrument(path)
    >>> res, used = sb.fit_record(sb.Scene.preset("fit"), rec, R_L=0.3e-3)
    >>> res.success, res.fitted, res.baseline_model
    (True, ('mu_H', 'offset', 'baseline'), 'constant')
    >>> int(used.sum()), rec.counts()                 # approach and loading fitted, not the retraction
    (50, {'approach': 10, 'loading': 40, 'retraction': 40})
    >>> lo, hi = res.mu_H_ci95
    >>> bool(lo < 52 < hi)
    True
    >>> print(f"baseline {res.baseline * 1e3:.3f} mN, contact at {res.offset * 1e3:.4f} mm")
    baseline 0.050 mN, contact at 0.0100 mm
    """
    from .instrument import estimate_contact

    if baseline not in ("auto",) + BASELINES:
        raise ValueError(f"baseline must be one of {('auto',) + BASELINES}; got {baseline!r}")
    used = record.mask(segment)
    if used.sum() < 3:
        raise ValueError(f"{record.path}: the {segment} segment has {int(used.sum())} rows; the record's segments "
                         f"are {record.counts()} (by the direction of the displacement in file order"
                         f"{' and time' if record.time is not None else ''}); choose another with --segment "
                         f"(one of loading, retraction, all)")
    d, f = record.displacement[used], record.force[used]
    guess = estimate_contact(d, f)
    if baseline == "auto":
        baseline = "constant" if guess is not None else "none"
    if not options.get("fit_offset", True):
        guess = 0.0  # the contact point is known: displacements are measured from it
    elif guess is None:
        # no baseline to read: the record starts in contact.  Displacements measured from about
        # the contact (the old convention) keep 0; otherwise the first row is the best guess.
        lo = float(np.min(d))
        guess = 0.0 if 0.0 <= lo and np.max(d) <= 3 * np.ptp(d) else lo
    res = fit(scene, d, f, R_L=R_L, baseline=baseline, contact_guess=guess, **options)
    counts = record.counts()
    if segment == "all" and counts.get("retraction") and counts.get("loading"):
        text = (f"the fitted rows mix the loading ({counts['loading']} rows) and the retraction "
                f"({counts['retraction']} rows) of the record: with hysteresis the two branches differ and the "
                f"fit of both is biased; fit one with --segment loading or retraction")
        res.warnings.append(text)
        res.warning_codes.append("mixed_segments")
    if segment == "loading":
        others = record.other_pushes()
        if others:
            where = ", ".join(f"rows {a + 1}-{b + 1}" for a, b, _ in others)
            rows = np.flatnonzero(used)
            res.warnings.append(f"the record holds {len(others) + 1} loading passes: rows {rows[0] + 1}-{rows[-1] + 1} "
                                f"(the longest push) were fitted, {where} left out; if the passes differ (a "
                                f"sample that changed, a re-test), cut the file and fit each")
            res.warning_codes.append("several_loadings")
        record.relabel(res.offset)
    return res, used
