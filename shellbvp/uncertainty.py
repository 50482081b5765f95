"""mu*H with the uncertainty of the geometry: how sure is the modulus, given that the shell's
shape and the indenter were measured with some error?

The scene's parameters (those flagged ``uncertainty`` in :mod:`shellbvp.scene_parameters`: beta,
rho, gamma, the Mooney-Rivlin alpha) are known as ``x +- u``,
``u`` a standard uncertainty (one standard deviation, as in the GUM).  The fit of mu*H is
repeated with each parameter at ``x - u`` and ``x + u`` (the others nominal; every fit its own
model curve, all of them through one ``concurrent.futures`` executor), which gives the
sensitivity by central differences, ``c = (mu_H(x + u) - mu_H(x - u)) / (2 u)``, and the
parameter's contribution ``u_x(mu_H) = |c| u``.  The contributions are combined in quadrature
(first-order propagation, the parameters independent), ``u_geom^2 = sum u_x^2``, and with the
fit's own interval (noise in the data): the 95 % interval of mu*H is
``mu_H +- sqrt(h_fit^2 + (z u_geom)^2)`` with ``h_fit`` the half-width of the fit's 95 %
interval and ``z = 1.96``.  ``mu_H(x - u)`` and ``mu_H(x + u)`` are reported too: where the
response is far from linear they differ from ``mu_H -+ c u`` and the first-order result should
be read with care (``nonlinearity`` in the table).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from .fitting import fit, free_parameters
from .scene_parameters import LiveNames, parameters_that, scene_parameter, scene_with
from .shape_parameters import SHAPE_PARAMETERS
from .sweeps import local_pool
from .units import parse_uncertain

log = logging.getLogger(__name__)

__all__ = ["UNCERTAIN_PARAMETERS", "GeometryFit", "fit_with_geometry", "parse_uncertain", "Z95"]

#: Scene parameters that may carry an uncertainty: those of the registry
#: (:mod:`shellbvp.scene_parameters`) flagged ``uncertainty``, in its order.
UNCERTAIN_PARAMETERS = LiveNames(lambda: [p.name for p in parameters_that("uncertainty")])
#: Coverage factor of a 95 % interval of a normal quantity.
Z95 = 1.959963984540054


def _perturbed(scene, name, value):
    return scene_with(scene, {name: value})


def _nominal(scene, name):
    return scene_parameter(name).get(scene)


def _check_uncertainty(scene, uncertainty, fit_kwargs):
    """The perturbed scenes {(name, sign): scene}, checked before any fit (ValueError naming it)."""
    if not isinstance(uncertainty, dict) or not uncertainty:
        raise ValueError(f"uncertainty must be a non-empty mapping of {UNCERTAIN_PARAMETERS} to standard "
                         f"uncertainties; got {uncertainty!r}")

    aliases = {k: v for k, v in fit_kwargs.items() if k.startswith("fit_") and k[4:] in SHAPE_PARAMETERS}
    free, _ = free_parameters(fit_kwargs.get("free", ()), None, aliases)
    fitted = {quantity: name for name in free for quantity in SHAPE_PARAMETERS[name].sets}
    scenes = {}
    for name, u in uncertainty.items():
        if name not in UNCERTAIN_PARAMETERS:
            raise ValueError(f"uncertainty: {name!r} is not a scene parameter with an uncertainty; choose from "
                             f"{UNCERTAIN_PARAMETERS}")
        why = scene_parameter(name).needs(scene)
        if why:
            raise ValueError(f"uncertainty: {why}")
        if name in fitted:
            raise ValueError(f"uncertainty: {name} is fitted (fit_{fitted[name]}=True); its uncertainty comes from "
                             f"the fit")
        if isinstance(u, bool) or not isinstance(u, (int, float)) or not (math.isfinite(u) and u > 0):
            raise ValueError(f"uncertainty: {name} must have a finite uncertainty > 0; got {u!r}")
        x = _nominal(scene, name)
        for sign in (-1, 1):
            try:
                scenes[name, sign] = _perturbed(scene, name, x + sign * u)
            except ValueError as exc:
                raise ValueError(f"uncertainty: the scene at {name} = {x:g} {'+-'[sign < 0]} {u:g} is not valid "
                                 f"({exc}); give a smaller uncertainty") from None
    return scenes


def fit_record(scene, displacement, force, R_L, fit_kwargs) -> dict:
    """One fit as a plain record (what a worker returns): mu*H, its interval, status."""
    try:
        r = fit(scene, displacement, force, R_L=R_L, **fit_kwargs)
    except ValueError as exc:  # e.g. the perturbed model curve does not reach the data: reported
        return {"success": False, "status": None, "message": str(exc), "mu_H": float("nan"),
                "mu_H_ci95": (float("nan"), float("nan")), "n": 0, "fitted": (), "curves_computed": 0}
    return {"success": r.success, "status": r.status, "message": r.message, "mu_H": float(r.mu_H),
            "mu_H_ci95": tuple(float(v) for v in r.mu_H_ci95), "n": r.n, "fitted": tuple(r.fitted),
            "curves_computed": r.curves_computed, "offset": float(r.offset)}


@dataclass
class GeometryFit:
    """Result of :func:`fit_with_geometry` (SI units: mu*H in N/m).

    Attributes
    ----------
    mu_H : float
        The nominal fit's mu*H.
    mu_H_ci95_fit : (float, float)
        Its 95 % interval from the data's noise alone (the nominal :class:`FitResult`'s).
    mu_H_ci95 : (float, float)
        The 95 % interval with the geometry's uncertainty.
    u_geometry : float
        Combined standard uncertainty of mu*H from the parameters (N/m, one standard deviation).
    contributions : list of dict
        Per parameter: ``parameter``, ``value``, ``uncertainty``, ``mu_H_minus``, ``mu_H_plus``
        (fits at value -+ uncertainty), ``sensitivity`` (d mu_H / d parameter), ``u_mu_H``
        (``abs(sensitivity) * uncertainty``), ``nonlinearity`` ((mu_H_plus + mu_H_minus)/2 - mu_H),
        ``share`` (fraction of the interval's variance), and last the fit's own line
        (``parameter`` "noise (fit)").
    nominal : FitResult
    success : bool
        Every fit succeeded.
    message : str
    fits_computed : int

    Examples
    --------
    >>> import shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> d, F = sb.read_force_csv(example_data_path())
    >>> g = sb.fit_with_geometry(sb.Scene.preset("fit"), d[:20], F[:20], R_L=0.3e-3,
    ...                          uncertainty={"rho": 0.02}, workers=1, tol=1e-4)
    >>> [c["parameter"] for c in g.contributions]
    ['rho', 'noise (fit)']
    >>> print(g.table())                                       # doctest: +ELLIPSIS
    parameter        value      +-u  mu*H at -u  mu*H at +u  d(mu*H)/dx  u(mu*H)  share
    rho             0.3333     0.02 ...
    noise (fit) ...
    """

    mu_H: float
    mu_H_ci95_fit: tuple
    mu_H_ci95: tuple
    u_geometry: float
    contributions: list
    nominal: object = field(repr=False)
    success: bool = True
    message: str = ""
    fits_computed: int = 0

    def table(self) -> str:
        """The contributions as an aligned text table."""
        head = (f"{'parameter':<12s} {'value':>9s} {'+-u':>8s} {'mu*H at -u':>11s} {'mu*H at +u':>11s} "
                f"{'d(mu*H)/dx':>11s} {'u(mu*H)':>8s} {'share':>6s}")
        rows = [head]
        for c in self.contributions:
            if c["parameter"] == "noise (fit)":
                rows.append(f"{c['parameter']:<12s} {'':>9s} {'':>8s} {'':>11s} {'':>11s} {'':>11s} "
                            f"{c['u_mu_H']:8.3g} {c['share']:6.1%}")
            else:
                rows.append(f"{c['parameter']:<12s} {c['value']:9.4g} {c['uncertainty']:8.3g} "
                            f"{c['mu_H_minus']:11.4g} {c['mu_H_plus']:11.4g} {c['sensitivity']:11.4g} "
                            f"{c['u_mu_H']:8.3g} {c['share']:6.1%}")
        return "\n".join(rows)

    def to_dict(self) -> dict:
        def num(v):
            return None if v is None or not math.isfinite(v) else float(v)

        return {"mu_H": num(self.mu_H), "mu_H_ci95": [num(v) for v in self.mu_H_ci95],
                "mu_H_ci95_fit": [num(v) for v in self.mu_H_ci95_fit], "u_geometry": num(self.u_geometry),
                "contributions": [{k: num(v) if isinstance(v, float) else v for k, v in c.items()}
                                  for c in self.contributions],
                "success": self.success, "message": self.message, "fits_computed": self.fits_computed,
                "units": {"mu_H": "N/m (= um*MPa)", "u_geometry": "N/m (one standard deviation)",
                          "u_mu_H": "N/m (one standard deviation)", "sensitivity": "N/m per unit of the parameter"}}


def fit_with_geometry(scene, displacement, force, *, R_L, uncertainty, executor=None, workers=None,
                      **fit_kwargs) -> GeometryFit:
    """Fit mu*H as :func:`shellbvp.fit` does, with an interval that includes the geometry's uncertainty.

    Parameters
    ----------
    scene : Scene
        The nominal scene.
    displacement, force : array_like
        Measured data (m, N), as for :func:`shellbvp.fit`.
    R_L : float
        Rim radius (m).
    uncertainty : dict
        ``{name: u}``: standard uncertainties (one standard deviation) of scene parameters,
        names from :data:`UNCERTAIN_PARAMETERS` (e.g. ``{"gamma": 0.2, "rho": 0.02}``).
    executor : concurrent.futures.Executor, optional
        Where the ``1 + 2 len(uncertainty)`` fits (each with its model curve) run; default
        a local process pool of ``workers`` processes (all cores), or with ``workers=1``
        this process.  Not shut down here.
    **fit_kwargs
        Passed on to :func:`shellbvp.fit` (``fit_offset``, ``weights``, ``tol``, ...).  The fits
        at ``VALUE +- u`` skip the weights check (``weights_check=False``): they give mu*H's
        sensitivity to the geometry, and the nominal fit's check says whether the model follows
        the data.

    Returns
    -------
    GeometryFit
        ``success`` False (and NaN intervals) when any of the fits fails (``message`` says which).

    Raises
    ------
    ValueError
        Before any fit: an unknown parameter, an uncertainty that is not > 0, a perturbed
        scene that is not valid (e.g. ``gamma + u >= 1/rho``), a fitted parameter given an
        uncertainty; and the data checks of :func:`shellbvp.fit`.

    Examples
    --------
    The first half of the shipped synthetic record (true mu*H 52 N/m) with the indenter's
    radius known to +- 0.02 (6 %); 3 fits, each with a model curve (``tol=1e-4`` to keep the
    example short):

    >>> import shellbvp as sb
    >>> from shellbvp.fitting import example_data_path
    >>> d, F = sb.read_force_csv(example_data_path())
    >>> g = sb.fit_with_geometry(sb.Scene.preset("fit"), d[:20], F[:20], R_L=0.3e-3, uncertainty={"rho": 0.02},
    ...                          workers=1, tol=1e-4)
    >>> g.success, g.fits_computed
    (True, 3)
    >>> (lo, hi), (glo, ghi) = g.mu_H_ci95_fit, g.mu_H_ci95
    >>> bool(glo < lo < 52 < hi < ghi), bool((ghi - glo) > 5 * (hi - lo))   # much wider than the noise's
    (True, True)
    """
    from scipy import special

    scenes = _check_uncertainty(scene, uncertainty, fit_kwargs)
    d = np.asarray(displacement, float)
    f = np.asarray(force, float)
    scene.model()  # derived here, once, before any worker needs it (they load it from the cache)
    nominal = fit(scene, d, f, R_L=R_L, **fit_kwargs)  # the data are checked here, before the other fits
    tasks = list(scenes.items())
    # the fits at VALUE +- U ask what mu*H that geometry gives, not whether it follows the data:
    # a scene off by its uncertainty may fail the weights check, whose verdict belongs to the nominal fit
    fit_kwargs = {**fit_kwargs, "weights_check": False}
    own = None
    try:
        if executor is None and workers == 1:
            records = [fit_record(s, d, f, R_L, fit_kwargs) for _, s in tasks]
        else:
            if executor is None:
                executor = own = local_pool(workers)
            futures = [executor.submit(fit_record, s, d, f, R_L, fit_kwargs) for _, s in tasks]
            records = [fut.result() for fut in futures]
    finally:
        if own is not None:
            own.shutdown(wait=True, cancel_futures=True)
    by = {key: rec for (key, _), rec in zip(tasks, records)}
    failed = [f"{name} {'+-'[sign < 0]} u: {rec['message']}" for (name, sign), rec in by.items() if not rec["success"]]
    if not nominal.success:
        failed.insert(0, f"nominal fit: {nominal.message}")
    lo, hi = nominal.mu_H_ci95
    h_fit = (hi - lo) / 2
    contributions = []
    for name, u in uncertainty.items():
        minus, plus = by[name, -1]["mu_H"], by[name, 1]["mu_H"]
        c = (plus - minus) / (2 * u)
        contributions.append({"parameter": name, "value": _nominal(scene, name), "uncertainty": float(u),
                              "mu_H_minus": minus, "mu_H_plus": plus, "sensitivity": c, "u_mu_H": abs(c) * u,
                              "nonlinearity": (plus + minus) / 2 - nominal.mu_H})
    u_geom = math.sqrt(sum(c["u_mu_H"] ** 2 for c in contributions))
    half = math.sqrt(h_fit ** 2 + (Z95 * u_geom) ** 2)
    # the fit's own standard uncertainty (its interval is mu_H +- t u with Student's t)
    dof = max(nominal.n - len(nominal.fitted), 1)
    u_fit = h_fit / special.stdtrit(dof, 0.975)
    var = {c["parameter"]: (Z95 * c["u_mu_H"]) ** 2 for c in contributions}
    total = h_fit ** 2 + sum(var.values())
    for c in contributions:
        c["share"] = var[c["parameter"]] / total if total > 0 else float("nan")
    contributions.append({"parameter": "noise (fit)", "u_mu_H": u_fit, "share": h_fit ** 2 / total if total > 0
                          else float("nan")})
    ok = not failed and all(math.isfinite(v) for v in (half, nominal.mu_H))
    ci = (nominal.mu_H - half, nominal.mu_H + half) if ok else (float("nan"), float("nan"))
    message = "mu*H with the geometry's uncertainty" if ok else "; ".join(failed) or "a fit gave no finite mu*H"
    return GeometryFit(mu_H=float(nominal.mu_H), mu_H_ci95_fit=(float(lo), float(hi)), mu_H_ci95=ci,
                       u_geometry=u_geom, contributions=contributions, nominal=nominal, success=ok, message=message,
                       fits_computed=1 + len(tasks))
