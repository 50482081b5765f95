"""What a fit reports: :class:`FitResult` (mu*H, the offset, the baseline and a shape
parameter with their intervals, the checks' status and warnings, the diagnostics) and
:class:`Estimate`, a quantity in lab units beside mu*H; a result's JSON form (``to_dict``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..fit_checks import fit_quality
from ..scene_parameters import scene_parameter
from ..shape_parameters import DERIVED, SHAPE_PARAMETERS
from ..thickness import model_error
from .apparent import apparent_modulus
from .least_squares import DEFAULT_WEIGHTS

__all__ = ["Estimate", "FitResult"]


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
    max_depth : float or None
        The fitting range (m): rows deeper than this beyond the contact point's first guess were
        left out (``fit(max_depth=...)``); None: every row.
    max_force : float or None
        The fitting range (N): rows whose force is above this were left out (``fit(max_force=...)``);
        None: every row.
    weights : str
        The noise model, "uniform", "relative" or "mixed".
    weights_check : dict or None
        With ``fit(..., weights_check=True)`` (the default): the same model refitted with another
        noise model (uniform; mixed for a uniform fit) at the fitted shape from the fit's
        solution: ``{"weights", "mu_H", "mu_H_ci95", "agree"}``.  When the two intervals of mu*H
        do not overlap the fit fails (status 6, ``weights_disagree``; the numbers are kept).  None:
        not checked.
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
    model : str
        What was compared with the data: ``"shell"`` (the shell model) or ``"solid"`` (the 3D
        solid, :mod:`shellbvp.fitting.solid`).
    model_note : str
        With ``model="auto"``: which model was reported and why.
    measured_model_error : float or None
        With ``model="auto"`` where both were fitted: ``|mu_H(shell) / mu_H(solid) - 1|``, the
        shell model's error on this scene measured by the solid (None otherwise).
    mesh_error : float or None
        With ``fit(..., mesh_check=True)`` and the solid reported: ``|mu_H(coarser mesh) / mu_H -
        1|``, the solid's discretisation error in mu*H (quadratic elements: a bound of the finer
        mesh's error about 1.25x itself); None otherwise.
    curve : Curve or SolidCurve
        The model curve (nondimensional) at the fitted parameters: its ``delta`` is the
        mid-surface pole's displacement (shell) or the indenter's (solid), / R_L.
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
    first_instability : FirstInstability or None
        With ``fit(..., stability=True)``: where the fitted scene's curve first loses
        axisymmetric stability, if within the fitted depths (:mod:`shellbvp.curve_stability`);
        ``stability_note`` says what was not analysed.
    stability_verdict : str
        One line: "stability: not checked" (the default), or checked and stable to which
        depth, or where it is lost (:func:`shellbvp.curve_stability.verdict`).
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
    first_instability: object = None
    stability_note: str = ""
    stability_verdict: str = "stability: not checked"
    model: str = "shell"
    model_note: str = ""
    measured_model_error: float = None
    mesh_error: float = None
    max_depth: float = None
    max_force: float = None
    weights_check: dict = None

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
        """The shell's thickness H in m -- its lab form, where ``Scene.thickness`` is H / R_L
        (:mod:`shellbvp.scene_parameters`) -- when the scene was given one
        (``Scene(thickness=H/R_L)``, ``--thickness``) or a fit estimated it: then beta is the 3D
        plate's and mu follows from mu*H; None otherwise."""
        if self.shape_values.get("thickness") is not None:
            return self.shape_values["thickness"]  # reported in m
        eps = getattr(self.scene, "thickness", None)
        return None if eps is None else scene_parameter("thickness").to_lab(eps, self.R_L)

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
        error = self.model_error
        return fit_quality(self.success, self.warning_codes, self.mu_H, self.mu_H_ci95, self.correlation,
                           self.fitted, None if error is None else error[0])

    @property
    def model_error(self):
        """``(error, extrapolated)``: the shell model's error to stand beside the statistical
        interval -- measured on this scene by the solid (``measured_model_error``, a fraction
        of mu*H) where ``model="auto"`` fitted both, else its largest measured error in F against
        3D elasticity at this thickness over the mapped scenes (:func:`shellbvp.thickness.model_error`);
        None without a thickness or a map for the model; for the solid, its mesh's error where
        checked (``mesh_error``), else None."""
        if self.model == "solid":
            return None if self.mesh_error is None else (self.mesh_error, False)
        if self.measured_model_error is not None:
            return self.measured_model_error, False
        return model_error(self.scene)

    def model_force(self, displacement, mu_H=None):
        """Fitted model force (N) at displacements (m); with ``mu_H`` (N/m), the same model at
        that mu*H (e.g. an end of ``mu_H_ci95``), offset and baseline as fitted."""
        return self._model(np.asarray(displacement, float), self.mu_H if mu_H is None else float(mu_H), self.offset)

    def apparent_modulus(self, displacement, force):
        """E(delta), the apparent modulus against depth (:func:`shellbvp.fitting.apparent.apparent_modulus`):
        for each point of the data (m, N) beyond the fitted contact point, the mu*H (and E =
        3 mu*H / H with a thickness) that the model would need to pass through it alone; flat over
        depth when the model follows the data's shape."""
        return apparent_modulus(displacement, force,
                                lambda x: self._model(x, 1.0, self.offset) - self._model(x, 0.0, self.offset),
                                offset=self.offset, baseline=self.baseline, baseline_slope=self.baseline_slope,
                                thickness=self.thickness)

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
                "model": self.model, "model_note": self.model_note, "max_depth": num(self.max_depth),
                "max_force": num(self.max_force), "weights_check": None if self.weights_check is None else
                {**self.weights_check, "mu_H": num(self.weights_check["mu_H"]),
                 "mu_H_ci95": ci(self.weights_check["mu_H_ci95"])},
                "measured_model_error": num(self.measured_model_error), "mesh_error": num(self.mesh_error),
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
                "first_instability": None if self.first_instability is None else self.first_instability.to_dict(),
                "stability_note": self.stability_note,
                "stability_verdict": self.stability_verdict,
                "model_error": None if self.model_error is None else num(self.model_error[0]),
                "model_error_extrapolated": None if self.model_error is None else self.model_error[1],
                "units": {"mu_H": "N/m (= um*MPa)", "offset": "m", "max_depth": "m", "max_force": "N",
                          "residual": "N (rms)",
                          "residual_rms": "N", "R_L": "m",
                          **{p.name: p.unit_text or p.unit for p in SHAPE_PARAMETERS.values()},
                          **{d.name: d.unit for d in DERIVED.values()},
                          "baseline": "N", "baseline_slope": "N/m", "thickness": scene_parameter("thickness").lab.unit,
                          "mu": "Pa",
                          "model_error": "1 (fraction of F)", "noise_sigma": "N (of the most weighted point)",
                          "aic": "1", "bic": "1", "runs_p": "1", "residual_autocorrelation": "1",
                          "correlation": "1 (order of fitted)"}}
