"""A shape parameter fitted with mu*H by its profile likelihood: its search range checked
(:func:`search_of`), model curves added at nodes in theta where the search needs them, the
estimate where the profiled residual is least (mu*H, the offset and the baseline refitted at
every trial value) and its 95 % interval where the residual crosses the likelihood-ratio
threshold ``RSS(theta) <= RSS_min (1 + F_{1,n-p}(0.95)/(n-p))`` (:class:`ProfileSearch`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from ..shape_parameters import ShapeParameter, shape_parameter
from .least_squares import Fitted

__all__ = ["ShapeSearch", "search_of", "ProfileSearch"]

#: The most model curves one fit computes while it searches a shape parameter.
_MAX_CURVES = 14


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


@dataclass
class ShapeSearch:
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


def search_of(scene, name, bounds):
    """The :class:`ShapeSearch` of the free parameter ``name`` (its bounds checked)."""
    param = shape_parameter(name)
    why = param.unavailable(scene)
    if why:
        raise ValueError(why)
    x0 = param.get(scene)
    lo, hi = _check_bounds(name, param.default_bounds(scene) if bounds is None else bounds, param.low_ok,
                           param.high_ok, x0)
    return ShapeSearch(param, (param.to_theta(lo), param.to_theta(hi)), param.step(scene), param.to_theta(x0),
                       lambda th: param.set(scene, param.from_theta(th)))


class ProfileSearch:
    """The shape parameter by its profile likelihood: the weighted RSS with mu*H (and the
    offset and baseline) fitted at each theta, on model curves at nodes in theta (a
    :class:`~shellbvp.fitting.curves.ModelCurves`) added where the search needs them; its 95 %
    interval where the RSS crosses the likelihood-ratio threshold."""

    def __init__(self, sp, shape, mdl, depth):
        self.sp, self.shape, self.mdl = sp, shape, mdl
        self.lim = [sp.bounds[0], sp.bounds[1]]  # shrinks where node curves do not reach the data
        self.notes = []
        self.w = None
        if not shape.add(sp.theta0):
            raise ValueError(f"the model curve at the scene's {sp.name} ends before the deepest data point "
                             f"(delta = {depth:.4g}): fit shallower data (--max-depth), or check the units and R_L")

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
        """The fit with the shape parameter (``k`` parameters in all): :class:`Fitted`."""
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
        P, _, top = shape.at(theta_hat)
        rows = noise.rows(mdl, P, top, mdl.full(self.profile(theta_hat)[1].x), self.w)
        dof = max(rows - k, 1)
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
        return Fitted(res, rss, np.column_stack([J, col]), self.w, shape.scene_at(near), shape.nodes[near], P, top,
                      theta_hat, (c_lo, c_hi), interp_err, dP=dP, rows=rows)


def _drop(pdt):
    return pdt[0], pdt[2]


def _show(param, theta):
    return f"{param.from_theta(theta):.3g}"
