"""The fits a user calls: :func:`fit` (measured displacement and force, checked before any
model curve, then mu*H, the contact point, a baseline and optionally a shape parameter) and
:func:`fit_record` (one segment of an instrument record); :func:`free_parameters` reads what
a fit frees."""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from ..fit_checks import TREND_P, other_weights, rank_trend
from ..instrument import estimate_contact
from ..shape_parameters import SHAPE_PARAMETERS, shape_parameter
from .curves import N_DEPTHS, ModelCurves
from .intervals import result_of
from .least_squares import BASELINES, DEFAULT_WEIGHTS, WEIGHTS, Fitted, LeastSquaresModel, NoiseModel
from .axisymmetry import check_axisymmetry
from .profile import ProfileSearch, search_of
from .solid import FIT_MODELS, auto_model, check_solid_fit, shell_or_solid, solid_curve

__all__ = ["fit", "fit_record", "free_parameters", "example_data_path", "fit_inputs", "FitInputs", "record_rows",
           "RecordRows", "segment_warnings"]


def example_data_path():
    """Path of the synthetic Lepidium-like CSV shipped with the package (README example)."""
    from pathlib import Path

    return Path(__file__).parents[1] / "data" / "lepidium_synthetic.csv"


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


def _within_depth(d, f, keep, max_depth, origin, k):
    """The rows (d, f, and ``keep``, the fitted rows of the input) no deeper than ``max_depth``
    (m) beyond ``origin``, the contact point's first guess; ValueError for a range that is not a
    length > 0 or that leaves too few rows to fit."""
    if not (isinstance(max_depth, (int, float)) and math.isfinite(max_depth) and max_depth > 0):
        raise ValueError(f"max_depth (the deepest depth fitted, m from the contact point) must be a finite number "
                         f"> 0; got {max_depth!r}")
    within = ~(d - origin > max_depth)  # NaN rows stay: the checks drop them
    keep = keep & within
    need = max(3, k + 2)
    beyond = np.count_nonzero(np.isfinite(d) & (d > origin))
    inside = np.count_nonzero(keep & (d > origin))
    if np.count_nonzero(keep) < need or (beyond and inside < need):
        raise ValueError(f"max_depth = {max_depth:.4g} m (--max-depth) leaves {inside} of {beyond} rows beyond the "
                         f"contact point's first guess ({origin:.4g} m); need at least {need}: give a deeper range")
    return d[within], f[within], keep


def _below_force(d, f, keep, max_force, k):
    """The rows (d, f, and ``keep``) whose force is at most ``max_force`` (N); ValueError for a
    bound that is not a force > 0 or that leaves too few rows to fit."""
    if not (isinstance(max_force, (int, float)) and math.isfinite(max_force) and max_force > 0):
        raise ValueError(f"max_force (the largest force fitted, N) must be a finite number > 0; got {max_force!r}")
    within = ~(f > max_force)  # NaN rows stay: the checks drop them
    keep = keep & within
    need = max(3, k + 2)
    if np.count_nonzero(keep) < need:
        raise ValueError(f"max_force = {max_force:.4g} N (--force-max) leaves {np.count_nonzero(keep)} of "
                         f"{np.count_nonzero(np.isfinite(f))} rows; need at least {need}: give a larger force")
    return d[within], f[within], keep


@dataclasses.dataclass(frozen=True)
class FitInputs:
    """What :func:`fit` fits, its arguments checked (:func:`fit_inputs`): the data's rows
    ``d``, ``f`` (finite, within the fitting range), ``keep`` (those rows among the given),
    ``k`` fitted parameters, the contact point's guess ``origin`` (m), the deepest datum's
    ``depth`` (delta) and the model curve's ``grid`` of depths, the least squares ``mdl``, the
    noise models (``noise`` and the weights check's ``check``), a free shape parameter's
    ``search`` (or None) and the fitting ranges reported."""
    d: np.ndarray
    f: np.ndarray
    keep: np.ndarray
    k: int
    origin: float
    depth: float
    grid: np.ndarray
    mdl: LeastSquaresModel
    noise: NoiseModel
    check: object
    search: object
    ranges: dict
    weights: str
    baseline: str
    free: tuple


def fit_inputs(scene, displacement, force, *, R_L, fit_offset=True, free=(), bounds=None, weights=None, floor=None,
               delta_max=None, loss="linear", baseline="none", contact_guess=None, shared=None, stability=False,
               model="auto", max_depth=None, max_force=None, weights_check=True, aliases=None) -> FitInputs:
    """:func:`fit`'s arguments and data checked (its ValueErrors, before any model curve), as a
    :class:`FitInputs`; a force map's pixels fitted together (:mod:`shellbvp.fitting.batched`)
    are checked by the same function."""
    weights = DEFAULT_WEIGHTS if weights is None else weights
    if weights not in WEIGHTS:
        raise ValueError(f"weights must be one of {WEIGHTS}; got {weights!r}")
    if floor is not None and not (isinstance(floor, (int, float)) and 0 < floor <= 1):
        raise ValueError(f"floor (of relative and mixed weights, fraction of max |force|) must be in (0, 1]; "
                         f"got {floor!r}")
    free, bounds = free_parameters(free, bounds, aliases or {})
    if model not in FIT_MODELS:
        raise ValueError(f"model must be one of {FIT_MODELS}; got {model!r}")
    if model == "solid":
        check_solid_fit(scene, free)
        if stability or shared is not None:
            raise ValueError("model='solid': the stability check and shared curves (force maps with a geometry per "
                             "pixel) are the shell model's; use model='shell' for them")
    if baseline not in BASELINES:
        raise ValueError(f"baseline must be one of {BASELINES}; got {baseline!r}")
    origin = 0.0 if contact_guess is None else contact_guess
    if not (isinstance(origin, (int, float)) and math.isfinite(origin)):
        raise ValueError(f"contact_guess (m) must be a finite number; got {contact_guess!r}")
    d = np.asarray(displacement, float).ravel()
    f = np.asarray(force, float).ravel()
    keep = np.isfinite(d) & np.isfinite(f) if d.shape == f.shape else None
    k = 1 + bool(fit_offset) + len(free) + (baseline != "none") + (baseline == "linear")
    if max_depth is not None and keep is not None:
        d, f, keep = _within_depth(d, f, keep, max_depth, float(origin), k)
    if max_force is not None and keep is not None:
        d, f, keep = _below_force(d, f, keep, max_force, k)
    d, f = _check_data(d, f, k, float(origin))
    if not (isinstance(R_L, (int, float)) and math.isfinite(R_L) and R_L > 0):
        raise ValueError(f"R_L (rim radius, m) must be a finite number > 0; got {R_L!r}")
    sp = search_of(scene, free[0], bounds.get(free[0])) if free else None
    depth = (np.max(d) - origin) / R_L  # the deepest datum's delta, if the contact is at the guess
    dm = 1.2 * depth if delta_max is None else float(delta_max)
    if not (math.isfinite(dm) and dm > 0):
        raise ValueError(f"delta_max must be > 0; got {delta_max!r}")
    grid = dm * np.arange(1, N_DEPTHS + 1) / N_DEPTHS
    mdl = LeastSquaresModel(d, f, R_L, fit_offset, baseline, loss)
    noise = NoiseModel.of(weights, floor)
    check = NoiseModel.of(other_weights(weights), floor) if weights_check else None
    ranges = {"max_depth": None if max_depth is None else float(max_depth),
              "max_force": None if max_force is None else float(max_force)}
    return FitInputs(d=d, f=f, keep=keep, k=k, origin=float(origin), depth=float(depth), grid=grid, mdl=mdl,
                     noise=noise, check=check, search=sp, ranges=ranges, weights=weights, baseline=baseline,
                     free=free)


def fit(scene, displacement, force, *, R_L, fit_offset=True, free=(), bounds=None, weights=None, floor=None,
        delta_max=None, tol=1e-6, loss="linear", baseline="none", contact_guess=None, progress=None, shared=None,
        stability=False, model="auto", mesh_check=False, max_depth=None, max_force=None, weights_check=True,
        **aliases):
    """Least-squares fit of mu*H (the displacement origin, and a shape parameter) to measured data.

    Parameters
    ----------
    scene : Scene
        Shape, indenter, material and beta (nondimensional); a free shape parameter's value
        in it is the start of the search.
    model : {"auto", "shell", "solid"}
        What is compared with the data: the shell model's curve (its delta, the mid-surface
        pole's displacement, taken as the data's displacement) or the scene's 3D solid
        (:func:`shellbvp.fe_curve`; needs ``scene.thickness`` and the ``fe`` extra), indented by
        the indenter's displacement from first touch, as an instrument records it (of a closed
        shell, the approach of the plates, or of the tip and the substrate)
        (:mod:`shellbvp.fitting.solid`).  The solid fits mu*H, the contact point and a
        baseline; shape parameters, ``stability`` and shared curves are shell-only.
        ``"auto"`` (default): where the solid can be this fit's model and is affordable
        (:func:`shellbvp.fitting.solid.auto_model`), both are fitted and the shell's error on
        this scene is measured by the solid at the level of mu*H: the shell is reported where
        that error lies within its interval, the solid otherwise; else the shell, with its
        mapped error.  ``FitResult.model_note`` says which and why.
    mesh_check : bool
        Where the solid is the reported model: fit again on the solid's curve on a mesh with 2/3
        the elements each way, and report the change of mu*H as the solid's error
        (``FitResult.mesh_error``; one more solid curve, cheaper than the first).
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
    max_depth : float, optional
        A fitting range: the deepest depth fitted (m, > 0), measured from the contact point's
        first guess (``contact_guess``; 0 without one); deeper rows are left out before the
        fit (e.g. past the first instability, or where the model stops following the data).
        Reported as ``FitResult.max_depth``.  Default: every row.
    max_force : float, optional
        A fitting range in force: rows whose force (N, as measured, baseline included) is above
        this are left out before the fit.  Reported as ``FitResult.max_force``.  Default: every row.
    weights_check : bool
        Refit mu*H with another noise model (uniform weights; mixed for a uniform fit) at the
        fitted shape, from the fit's solution (one more least-squares fit, no model curve): when
        the two 95 % intervals of mu*H do not overlap, the fit fails with status 6
        (``weights_disagree``; its numbers are kept).  ``FitResult.weights_check`` holds the
        other fit.  Default True.
    contact_guess : float, optional
        A first guess of the contact point (m; e.g. :func:`shellbvp.instrument.estimate_contact`):
        the model curve is computed to 1.2 x the depth of the data beyond it.  Default 0
        (displacements measured from about the contact point).  A contact point that runs into
        that curve's end (a guess inside the loaded rows) is fitted again, once, on a curve
        reaching half the fitted depth lower (not with ``delta_max`` given).
    progress : callable, optional
        ``progress(description, delta_max) -> (bar, callback)`` for each model curve computed
        (e.g. ``lambda d, m: shellbvp.progress.curve_progress(m, d)``); None: silent.
    stability : bool
        Also look for the first loss of axisymmetric stability of the fitted scene up to the
        deepest fitted depth (a curve with ``stability="locate"``, :mod:`shellbvp.curve_stability`;
        seconds to a minute): a warning (``unstable_depths``) and ``FitResult.first_instability`` when
        the data pass it.
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
    shared : tuple, optional
        ``(model_curves, theta)``: F(delta) interpolated at ``theta`` across the node curves of a
        :class:`~shellbvp.fitting.curves.ModelCurves` built by the caller (a force map with a
        geometry per pixel, :func:`shellbvp.batch.fit_map`): no curve is computed, ``scene`` is
        the one at ``theta`` (reported), ``delta_max`` and ``tol`` are the curves'; no shape
        parameter may be free.
    **aliases
        ``fit_<name>=True`` and ``<name>_bounds=(low, high)`` for each shape parameter (e.g.
        ``fit_beta=True, beta_bounds=(1e-3, 0.1)``): the same as ``free`` and ``bounds``.
    weights : {"uniform", "relative", "mixed"}, optional
        Noise model: the same force noise at every point, noise proportional
        to the force, or both (``sigma^2 = a^2 + b^2 F^2``, a and b estimated);
        default :data:`DEFAULT_WEIGHTS` ("mixed", see benchmarks/fit_coverage.py).
    floor : float, optional
        With relative weights, forces below ``floor * max|force|`` are weighted
        as if they were that large (near the contact point F -> 0); with mixed weights, the
        noise's proportional part likewise; in (0, 1].  Default :data:`WEIGHT_FLOORS` (0.05
        relative, 0.02 mixed; the weights check's other noise model takes its own).
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
    mu*H = 51.91 N/m [51.52, 52.30], offset 9.95 um

    Data the fit cannot use are refused before any curve is computed:

    >>> sb.fit(sb.Scene.preset("fit"), d[:3], F[:3], R_L=0.3e-3)
    Traceback (most recent call last):
    ...
    ValueError: ...
    """
    inputs = fit_inputs(scene, displacement, force, R_L=R_L, fit_offset=fit_offset, free=free, bounds=bounds,
                        weights=weights, floor=floor, delta_max=delta_max, loss=loss, baseline=baseline,
                        contact_guess=contact_guess, shared=shared, stability=stability, model=model,
                        max_depth=max_depth, max_force=max_force, weights_check=weights_check, aliases=aliases)
    d, keep, k, origin, sp, depth, grid, mdl, noise, check, ranges = (
        inputs.d, inputs.keep, inputs.k, inputs.origin, inputs.search, inputs.depth, inputs.grid, inputs.mdl,
        inputs.noise, inputs.check, inputs.ranges)
    weights, baseline, free = inputs.weights, inputs.baseline, inputs.free
    if shared is not None:
        if sp is not None:
            raise ValueError(f"{sp.name} is given per pixel: it cannot also be fitted")
        if stability:
            raise ValueError("stability is checked for one fit at a time, not per pixel of a map on shared curves "
                             "(each pixel would need a curve of its own)")
        res = _fit_on_shared(shared, scene, mdl, noise, depth, k, keep, weights, baseline, check)
        return dataclasses.replace(res, **ranges)

    def run(name, coarse=False):
        """The fit with model ``name`` (the solid on the mesh check's mesh with ``coarse``)."""
        counter = [0]
        if sp is None:
            source = functools.partial(solid_curve, coarse=coarse) if name == "solid" else None
            shape = ModelCurves(lambda th: scene, grid, tol, depth, counter, progress, source=source)
            shape.add(None)
            P, dP, top = shape.at(None)
            res, rss, J, w = noise.irls(mdl, P, dP, top)
            fitted = Fitted(res, rss, J, w, scene, shape.nodes[None], P, top, dP=dP,
                            rows=noise.rows(mdl, P, top, mdl.full(res.x), w))
            notes = []
        else:
            search = ProfileSearch(sp, ModelCurves(sp.scene_at, grid, tol, depth, counter, progress), mdl, depth)
            fitted = search.run(noise, k)
            notes = search.notes
        res = dataclasses.replace(result_of(fitted, mdl, sp, k, notes, keep, weights, baseline, counter[0], name,
                                            check), **ranges)
        if stability and res.scene is not None and math.isfinite(res.offset):
            check_axisymmetry(res, (float(np.max(d)) - res.offset) / R_L, tol, progress)
        return res

    if model != "auto":
        res = run(model)
    else:
        choice, why = auto_model(scene, free, stability)
        res = dataclasses.replace(run("shell"), model_note=why) if choice == "shell" else \
            shell_or_solid(run("shell"), run("solid"))
    lower = _contact_at_curve_end(res, d, R_L) if fit_offset and delta_max is None else None
    if lower is not None:  # the contact point ran into the model curve's end: again, on a curve reaching past it
        again = fit(scene, displacement, force, R_L=R_L, fit_offset=fit_offset, free=free, bounds=bounds,
                    weights=weights, floor=floor, delta_max=1.2 * (float(np.max(d)) - lower) / R_L, tol=tol, loss=loss,
                    baseline=baseline, contact_guess=contact_guess, progress=progress, stability=stability,
                    model=model, mesh_check=mesh_check, max_depth=max_depth, max_force=max_force,
                    weights_check=weights_check, **aliases)
        return dataclasses.replace(again, curves_computed=again.curves_computed + res.curves_computed)
    if mesh_check and res.model == "solid" and res.success:
        coarse = run("solid", coarse=True)
        res = dataclasses.replace(res, mesh_error=abs(coarse.mu_H / res.mu_H - 1),
                                  curves_computed=res.curves_computed + coarse.curves_computed)
    return res


def _contact_at_curve_end(res, d, R_L):
    """Where to fit again from when ``res``'s contact point ran into the end of its model curve
    (the deepest datum ``max(d)`` at the curve's last depth: the data would put the contact
    lower, e.g. a first guess inside the loaded rows): a contact point (m) half the fitted depth
    lower (no lower than the start's search, half the data's span below the first row); else None."""
    depths = getattr(res.curve, "delta", None)
    if depths is None or not len(depths) or not math.isfinite(res.offset):
        return None
    deepest = float(np.max(d))
    reach = deepest - float(np.max(depths)) * R_L  # the lowest contact point the curve allows
    if res.offset > reach + 1e-3 * (deepest - reach):
        return None
    lower = max(float(np.min(d) - 0.5 * np.ptp(d)), res.offset - 0.5 * (deepest - res.offset))
    return lower if lower < res.offset else None


def _fit_on_shared(shared, scene, mdl, noise, depth, k, keep, weights, baseline, check=None):
    """:func:`fit` on the curve interpolated at ``theta`` across shared node curves (no curve computed)."""
    curves, theta = shared
    P, dP, top = curves.at(theta)
    if depth > top * (1 + 1e-9):
        raise ValueError(f"the data reach delta = {depth:.4g} (deepest displacement / R_L), beyond the shared "
                         f"model curves' end at delta = {top:.4g}")
    res, rss, J, w = noise.irls(mdl, P, dP, top)
    near = min(curves.thetas, key=lambda t: abs(t - theta))
    fitted = Fitted(res, rss, J, w, scene, curves.nodes[near], P, top,
                    interpolation_error=getattr(curves, "interpolation_error", None), dP=dP,
                    rows=noise.rows(mdl, P, top, mdl.full(res.x), w))
    return result_of(fitted, mdl, None, k, [], keep, weights, baseline, 0, check=check)


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
    rows = record_rows(record, segment, baseline, options.get("fit_offset", True))
    res = fit(scene, rows.d, rows.f, R_L=R_L, baseline=rows.baseline, contact_guess=rows.guess, **options)
    for code, text in segment_warnings(record, segment, rows.used):
        res.warnings.append(text)
        res.warning_codes.append(code)
    if segment == "loading":
        record.relabel(res.offset)
    return res, rows.used


@dataclasses.dataclass(frozen=True)
class RecordRows:
    """The rows of a record :func:`fit_record` fits: ``used`` (a mask of the record's rows), their
    displacement ``d`` and force ``f``, the ``baseline`` fitted (``auto`` resolved) and the
    contact point's first ``guess`` (m)."""
    used: np.ndarray
    d: np.ndarray
    f: np.ndarray
    baseline: str
    guess: float


def record_rows(record, segment="loading", baseline="auto", fit_offset=True, estimate="find") -> RecordRows:
    """The rows of ``record``'s ``segment`` that :func:`fit_record` fits, its baseline and contact
    guess (ValueError: an unknown baseline, a segment of fewer than 3 rows); ``estimate``: the
    contact estimate of those rows when known (:func:`shellbvp.instrument.estimate_contact`;
    ``"find"``: found here)."""
    if baseline not in ("auto",) + BASELINES:
        raise ValueError(f"baseline must be one of {('auto',) + BASELINES}; got {baseline!r}")
    used = record.mask(segment)
    if used.sum() < 3:
        raise ValueError(f"{record.path}: the {segment} segment has {int(used.sum())} rows; the record's segments "
                         f"are {record.counts()} (by the direction of the displacement in file order"
                         f"{' and time' if record.time is not None else ''}); choose another with --segment "
                         f"(one of loading, retraction, all)")
    d, f = record.displacement[used], record.force[used]
    if isinstance(estimate, str):
        estimate = estimate_contact(d, f)
    if baseline == "auto":
        baseline = "constant" if estimate is not None else "none"
    return RecordRows(used, d, f, baseline, _contact_guess(d, estimate, fit_offset))


def _contact_guess(d, estimate, fit_offset):
    """The contact point (m) a fit of a record's rows at displacements ``d`` starts from, given
    the ``estimate`` read from the approach's baseline (None: none could be read)."""
    if not fit_offset:
        return 0.0  # the contact point is known: displacements are measured from it
    if estimate is not None:
        return estimate
    # no baseline to read: the record starts in contact.  Displacements measured from about
    # the contact (the old convention) keep 0; otherwise the first row is the best guess.
    lo = float(np.min(d))
    return 0.0 if 0.0 <= lo and np.max(d) <= 3 * np.ptp(d) else lo


def segment_warnings(record, segment, used) -> list:
    """``[(code, text)]``: warnings of a fit of ``record``'s ``used`` rows (``segment``) about
    its segments: the loading and the retraction fitted together, or loading passes left out."""
    out = []
    counts = record.counts()
    if segment == "all" and counts.get("retraction") and counts.get("loading"):
        out.append(("mixed_segments",
                    f"the fitted rows mix the loading ({counts['loading']} rows) and the retraction "
                    f"({counts['retraction']} rows) of the record: with hysteresis the two branches differ and the "
                    f"fit of both is biased; fit one with --segment loading or retraction"))
    if segment == "loading":
        others = record.other_pushes()
        if others:
            where = ", ".join(f"rows {a + 1}-{b + 1}" for a, b, _ in others)
            rows = np.flatnonzero(used)
            out.append(("several_loadings",
                        f"the record holds {len(others) + 1} loading passes: rows {rows[0] + 1}-{rows[-1] + 1} "
                        f"(the longest push) were fitted, {where} left out; if the passes differ (a "
                        f"sample that changed, a re-test), cut the file and fit each"))
    return out
