"""Many fits on one model curve at once: the pixels of a force map fitted together.

Every pixel of a map fitted with one scene fits mu*H, the contact point and a baseline against
the SAME model curve F(delta) (:func:`shellbvp.fitting.fit`'s shell model at a fixed shape).
:func:`fit_batch` does for a list of pixels what ``fit`` does for each -- the same checks of the
data (:func:`~shellbvp.fitting.fit_data.fit_inputs`), the same start (the best contact point of
160 trials with the linear parameters solved exactly at each), the same noise models
re-estimated from the model force (iteratively reweighted, at most 8 times), the same weights
check and the same intervals, statuses and warnings
(:func:`~shellbvp.fitting.intervals.result_of`) -- with the model, its slope, the Jacobians and
the weights evaluated for all pixels in one numpy expression (:class:`SharedShape`,
:class:`Stack`) and the least squares of each pixel solved by a Levenberg-Marquardt iteration run
on all of them together, converged to a relative change of the cost below
:data:`COST_TOL` (scipy's ``least_squares``, used for one fit, stops at 1e-8).

The results agree with one ``fit`` per pixel to the tolerance of scipy's own stopping
(tests/test_fit_batched.py states it); the least-squares part of a result's message names this
solver.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from scipy.optimize import OptimizeResult

from .curves import ModelCurves, beyond_message
from .fit_data import fit_inputs
from .intervals import result_of, weights_check_of
from .least_squares import Fitted
from .solid import auto_model

__all__ = ["batchable", "fit_batch", "SharedShape", "Stack", "COST_TOL", "START_TRIALS"]

#: A pixel's least squares stop when an accepted step lowers its cost by less than this fraction
COST_TOL = 1e-13
#: Trial contact points of the start (as LeastSquaresModel.start)
START_TRIALS = 160
#: The most iterations of one least-squares solve
MAX_ITERATIONS = 200
#: Options of :func:`shellbvp.fitting.fit` a batch takes (with a shell model, no shape parameter,
#: the linear loss and no stability check; others: one fit per pixel)
_OPTIONS = {"fit_offset", "weights", "floor", "delta_max", "tol", "loss", "model", "max_depth", "max_force", "bounds",
            "weights_check", "progress", "free", "stability", "mesh_check"}


def batchable(scene, options) -> bool:
    """True when :func:`fit_batch` fits pixels with these options of ``fit`` as ``fit`` does."""
    if set(options) - _OPTIONS or options.get("free") or options.get("stability"):
        return False
    if options.get("loss", "linear") != "linear":
        return False
    model = options.get("model", "auto")
    return model == "shell" or (model == "auto" and auto_model(scene, (), False)[0] == "shell")


class SharedShape:
    """The nondimensional model force F(delta) of one curve (its PCHIP ``P`` up to ``top``) and
    its slope at many points at once, as ``LeastSquaresModel.shape`` gives them: 0 before
    contact (delta <= 0), NaN beyond ``top``; the slope 0 outside (0, top]."""

    def __init__(self, P, top):
        self.x, self.top = np.asarray(P.x, float), float(top)
        self.c = [np.ascontiguousarray(row) for row in np.asarray(P.c, float)]
        self.left = np.ascontiguousarray(self.x[:-1])
        h = np.diff(self.x)
        # the curves' depths are equally spaced: the interval of a point is its depth over the spacing
        self.inv_h = 1.0 / h[0] if np.allclose(h, h[0], rtol=1e-12, atol=0) else None

    def _intervals(self, Xc):
        last = self.left.size - 1
        if self.inv_h is None:
            return np.clip(np.searchsorted(self.x, Xc, side="right") - 1, 0, last)
        j = (Xc * self.inv_h).astype(np.intp)
        np.minimum(j, last, out=j)
        return j

    def __call__(self, X, slope=False):
        top = self.top
        Xc = np.clip(X, 0.0, top)
        j = self._intervals(Xc)
        t = Xc - self.left.take(j)
        c0, c1, c2 = (c.take(j) for c in self.c[:3])
        value = c0 * t
        value += c1
        value *= t
        value += c2
        value *= t
        value += self.c[3].take(j)
        outside = X <= 0
        value[outside] = 0.0
        value[X > top] = np.nan
        if not slope:
            return value
        ds = 3 * c0 * t
        ds += 2 * c1
        ds *= t
        ds += c2
        ds[outside | (X > top)] = 0.0
        return value, ds


class Stack:
    """The data of many pixels padded into arrays ``(pixels, rows)`` (``valid`` marks each pixel's
    own rows; padding carries weight 0), with the model ``F_i = mu_H R_L F((d_i - d0)/R_L) + b0 +
    b1 (d_i - d0)`` of ``LeastSquaresModel`` (parameters ``q = (mu_H, d0, b0, b1)``, the ``free``
    ones fitted) on one :class:`SharedShape`."""

    def __init__(self, mdls, shape):
        self.n = np.array([m.d.size for m in mdls])
        B, N = len(mdls), int(self.n.max())
        self.valid = np.arange(N)[None, :] < self.n[:, None]
        self.d = np.empty((B, N))
        self.f = np.zeros((B, N))
        for i, m in enumerate(mdls):
            self.d[i] = m.d[0]
            self.d[i, :m.d.size], self.f[i, :m.d.size] = m.d, m.f
        self.R_L, self.free, self.shape = mdls[0].R_L, mdls[0].free, shape
        self.big = np.array([m.big for m in mdls])[:, None]
        self.fscale = np.array([m.fscale for m in mdls])
        # each pixel's rows in depth order (stable, padding last): the mixed weights' local scatter
        self.order = np.argsort(np.where(self.valid, self.d, np.inf), axis=1, kind="stable")

    def full(self, p):
        q = np.zeros((p.shape[0], 4))
        q[:, self.free] = p
        return q

    def residual(self, p, w, rows, jac=True):
        """Weighted residuals ``(pixels, rows)`` (NaN model force: ``big``) and, with ``jac``, the
        weighted Jacobian ``(pixels, rows, free)`` of the pixels ``rows`` at parameters ``p``."""
        d, f, R_L = self.d[rows], self.f[rows], self.R_L
        q = self.full(p)
        x = (d - q[:, 1:2]) / R_L
        S, dS = self.shape(x, slope=True) if jac else (self.shape(x), None)
        model = q[:, :1] * R_L * S + q[:, 2:3] + q[:, 3:4] * (d - q[:, 1:2])
        r = w * np.where(np.isnan(model), self.big[rows], model - f)
        if not jac:
            return r, None
        cols = [R_L * np.nan_to_num(S), -q[:, :1] * np.nan_to_num(dS) - q[:, 3:4], np.ones_like(d), d - q[:, 1:2]]
        return r, w[:, :, None] * np.stack([c for c, free in zip(cols, self.free) if free], axis=2)

    def scale(self, p):
        """x_scale of each pixel's free parameters, as ``LeastSquaresModel.fit`` sets it."""
        mu = np.abs(self.full(p)[:, 0])
        s = np.stack([np.where(mu > 0, mu, 1.0), np.full_like(mu, 0.01 * self.R_L), 0.01 * self.fscale,
                      0.01 * self.fscale / self.R_L], axis=1)
        return s[:, self.free]

    def solve(self, p0, w):
        """Levenberg-Marquardt on every pixel from ``p0`` with weights ``w`` (both per pixel):
        ``(p, rss, J, converged, iterations)``, rss the weighted residual sum of squares and J the
        weighted Jacobian at ``p``."""
        B = p0.shape[0]
        p, scale = p0.astype(float).copy(), self.scale(p0)
        r, J = self.residual(p, w, slice(None))
        cost = np.einsum("bn,bn->b", r, r)
        lam = np.full(B, 1e-3)
        active, done, its = np.ones(B, bool), np.zeros(B, bool), np.zeros(B, int)
        for _ in range(MAX_ITERATIONS):
            a = np.flatnonzero(active)
            if a.size == 0:
                break
            Js = J[a] * scale[a][:, None, :]
            A = np.einsum("bnk,bnl->bkl", Js, Js)
            g = np.einsum("bnk,bn->bk", Js, r[a])
            D = np.diagonal(A, axis1=1, axis2=2)
            D = np.where(D > 0, D, 1.0)
            M = A + lam[a][:, None, None] * (D[:, :, None] * np.eye(D.shape[1]))
            step = -np.linalg.solve(M, g[:, :, None])[:, :, 0]
            predicted = -2 * np.einsum("bk,bk->b", g, step) - np.einsum("bk,bkl,bl->b", step, A, step)
            flat = ~(predicted > COST_TOL * cost[a])  # at the minimum to the tolerance (or no descent left)
            p_new = p[a] + step * scale[a]
            r_new, J_new = self.residual(p_new, w[a], a)
            cost_new = np.einsum("bn,bn->b", r_new, r_new)
            better = cost_new < cost[a]
            small = better & (cost[a] - cost_new <= COST_TOL * cost[a])
            take = a[better]
            p[take], r[take], J[take], cost[take] = p_new[better], r_new[better], J_new[better], cost_new[better]
            lam[a] = np.where(better, np.maximum(lam[a] / 10, 1e-12), lam[a] * 10)
            its[a] += 1
            stop = small | (flat & ~better) | (lam[a] > 1e16)
            done[a[stop]] = True
            active[a[stop]] = False
        return p, cost, J, done, its

    def _model_and_force(self, p):
        """Each pixel's model force and measured force less its baseline, at ``p``."""
        q = self.full(p)
        model = q[:, :1] * self.R_L * self.shape((self.d - q[:, 1:2]) / self.R_L)
        return model, self.f - (q[:, 2:3] + q[:, 3:4] * (self.d - q[:, 1:2]))

    def weights(self, kind, floor, p, w):
        """The noise model's new weights (``NoiseModel.reweight`` of every pixel) and each
        pixel's largest relative change of them."""
        valid = self.valid
        if kind == "uniform":
            new = valid.astype(float)
        else:
            model, f = self._model_and_force(p)
            m = np.where(valid, np.abs(np.nan_to_num(model)), 0.0)
            fmax = np.max(np.where(valid, np.abs(f), 0.0), axis=1, keepdims=True)
            if kind == "relative":
                new = np.where(valid, 1.0 / np.maximum(m, floor * fmax), 0.0)
            else:
                new = self._mixed(np.nan_to_num(model) - f, m / fmax, w, floor)[0]
        with np.errstate(divide="ignore", invalid="ignore"):
            change = np.max(np.where(valid, np.abs(new / w - 1), 0.0), axis=1)
        return new, change

    def rows(self, kind, floor, p, w):
        """``NoiseModel.rows`` of every pixel: the rows its noise scale is read from (all of them
        but for mixed weights, where rows whose noise lies below the floor count by its share)."""
        if kind != "mixed":
            return self.n.astype(float)
        model, f = self._model_and_force(p)
        m = np.where(self.valid, np.abs(np.nan_to_num(model)), 0.0)
        fmax = np.max(np.where(self.valid, np.abs(f), 0.0), axis=1, keepdims=True)
        return self._mixed(np.nan_to_num(model) - f, m / fmax, w, floor)[1]

    def _mixed(self, resid, m_rel, w, floor):
        """Mixed weights (``sigma^2 = a^2 + b^2 F^2``, ``least_squares._mixed_variance``) and each
        pixel's rows read for the noise: each row's squared noise from the residuals' local scatter
        in depth order, (a^2, b^2) >= 0 by non-negative least squares scaled by the previous
        sigma^2 (two unknowns: the best of the unconstrained solution and the two with one
        coefficient 0, exactly); the weights assume the proportional part at ``floor`` of the
        largest force at least."""
        valid, n, order = self.valid, self.n, self.order
        rs = np.take_along_axis(resid, order, axis=1)
        second = (rs[:, :-2] - 2 * rs[:, 1:-1] + rs[:, 2:]) ** 2 / 6
        srt = np.empty_like(rs)
        srt[:, 1:-1] = second
        srt[:, 0] = second[:, 0]
        rows = np.arange(rs.shape[0])
        srt[rows, n - 1] = second[rows, n - 3]  # the last row takes its neighbour's
        r2 = np.empty_like(rs)
        np.put_along_axis(r2, order, srt, axis=1)
        with np.errstate(divide="ignore"):
            s2_prev = np.where(valid, 1.0 / w ** 2, 0.0)
            inv = np.where(valid, 1.0 / s2_prev, 0.0)
        a0, a1, b = inv, m_rel ** 2 * inv, np.where(valid, r2, 0.0) * inv
        G00, G01, G11 = (np.einsum("bn,bn->b", u, v) for u, v in ((a0, a0), (a0, a1), (a1, a1)))
        h0, h1 = np.einsum("bn,bn->b", a0, b), np.einsum("bn,bn->b", a1, b)
        det = G00 * G11 - G01 ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            both = np.stack([(G11 * h0 - G01 * h1) / det, (G00 * h1 - G01 * h0) / det], axis=1)
            cands = [both, np.stack([np.maximum(h0 / G00, 0), 0 * h0], axis=1),
                     np.stack([0 * h0, np.maximum(h1 / G11, 0)], axis=1), np.zeros((h0.size, 2))]
        best, coef = np.full(h0.size, np.inf), np.zeros((h0.size, 2))
        for c in cands:
            ok = np.all(np.isfinite(c) & (c >= 0), axis=1)
            obj = c[:, 0] ** 2 * G00 + 2 * c[:, 0] * c[:, 1] * G01 + c[:, 1] ** 2 * G11 - 2 * (c[:, 0] * h0 + c[:, 1] * h1)
            take = ok & (obj < best)
            best, coef = np.where(take, obj, best), np.where(take[:, None], c, coef)
        noise = np.where(valid, coef[:, :1] + coef[:, 1:] * m_rel ** 2, 0.0)
        s2 = np.where(valid, coef[:, :1] + coef[:, 1:] * np.maximum(m_rel, floor) ** 2, 0.0)
        top = np.max(s2, axis=1, keepdims=True)
        with np.errstate(divide="ignore", invalid="ignore"):
            s2 = np.maximum(s2, 1e-6 * top)
            out = np.where(valid, 1.0 / np.sqrt(s2 / top), 0.0)
            rows = np.sum(np.where(valid, noise / s2, 0.0), axis=1)
        found = top[:, 0] > 0
        return (np.where((top > 0) & valid, out, valid.astype(float)), np.where(found, rows, self.n.astype(float)))

    def start(self, mdls, P, top):
        """``LeastSquaresModel.start`` of every pixel (weights 1): the trial contact point of
        least RSS with mu_H, b0 and b1 solved exactly at each (mu_H > 0), that trial's solution
        found again by ``lstsq`` as there; the RSS of every trial from the projection of the
        model column off the baseline's columns (whose span, 1 and d, is the same at every
        trial)."""
        B, N = self.d.shape
        valid, d, f, R_L, free = self.valid, self.d, self.f, self.R_L, self.free
        trials = np.full((B, START_TRIALS), np.nan)
        for i, m in enumerate(mdls):
            trials[i, :1] = 0.0
            if free[1]:
                di = m.d
                lo, hi = max(np.max(di) - top * R_L, np.min(di) - 0.5 * np.ptp(di)), np.sort(di)[-(int(np.sum(free)) + 1)]
                trials[i, :] = np.linspace(lo, hi, START_TRIALS) if hi > lo else np.r_[lo, np.full(START_TRIALS - 1, np.nan)]
        basis = []  # an orthonormal basis of the baseline's columns on each pixel's rows
        if free[2]:
            basis.append(valid / np.sqrt(self.n)[:, None])
        if free[3]:
            v = np.where(valid, d - np.einsum("bn,bn->b", d, basis[0])[:, None] * basis[0], 0.0)
            basis.append(v / np.sqrt(np.einsum("bn,bn->b", v, v))[:, None])
        fp = f - sum(np.einsum("bn,bn->b", f, q)[:, None] * q for q in basis) if basis else f.copy()
        ff = np.einsum("bn,bn->b", fp, fp)
        rss = np.full((B, START_TRIALS), np.inf)
        step = max(1, 2 ** 18 // (START_TRIALS * N))  # about 2 MB a temporary array
        for lo in range(0, B, step):
            sl = slice(lo, min(B, lo + step))
            S = R_L * self.shape((d[sl, None, :] - trials[sl, :, None]) / R_L)
            bad = np.any(np.isnan(S) & valid[sl, None, :], axis=2) | np.isnan(trials[sl])
            S = np.where(valid[sl, None, :] & ~np.isnan(S), S, 0.0)
            ss = np.einsum("btn,btn->bt", S, S)
            for q in basis:
                ss = ss - np.einsum("btn,bn->bt", S, q[sl]) ** 2
            sf = np.einsum("btn,bn->bt", S, fp[sl])
            with np.errstate(divide="ignore", invalid="ignore"):
                coef, r = sf / ss, ff[sl, None] - sf ** 2 / ss
            ok = ~bad & (ss > 1e-12 * np.einsum("btn,btn->bt", S, S)) & (coef > 0) & np.isfinite(r)
            rss[sl] = np.where(ok, r, np.inf)
        out = np.zeros((B, int(np.sum(free))))
        for i, m in enumerate(mdls):
            if not np.isfinite(rss[i]).any():
                q = np.zeros(4)
                q[0] = 1.0
                out[i] = q[free]
                continue
            out[i] = m.solved_at(P, top, trials[i, int(np.argmin(rss[i]))])[free]
        return out

    def irls(self, kind, floor, p0):
        """``NoiseModel.irls`` of every pixel from ``p0``: ``(p, rss, J, w, converged, iterations)``."""
        w = self.valid.astype(float)
        p, rss, J, ok, its = self.solve(p0, w)
        if kind == "uniform":
            return p, rss, J, w, ok, its
        going = np.ones(p.shape[0], bool)
        for it in range(8):
            a = np.flatnonzero(going)
            if a.size == 0:
                break
            sub = _Rows(self, a)
            w_new, change = sub.weights(kind, floor, p[a], w[a])
            change = change if it > 0 else np.full(a.size, np.inf)
            pa, rssa, Ja, oka, itsa = sub.solve(p[a], w_new)
            p[a], rss[a], J[a], w[a], ok[a], its[a] = pa, rssa, Ja, w_new, oka, its[a] + itsa
            going[a[change < 1e-6]] = False
        return p, rss, J, w, ok, its


class _Rows(Stack):
    """The pixels ``rows`` of a :class:`Stack` (a view of its arrays for the ones still iterating)."""

    def __init__(self, stack, rows):  # noqa: D107 -- no Stack.__init__: the arrays are the stack's rows
        self.n, self.valid, self.d, self.f = stack.n[rows], stack.valid[rows], stack.d[rows], stack.f[rows]
        self.R_L, self.free, self.shape = stack.R_L, stack.free, stack.shape
        self.big, self.fscale, self.order = stack.big[rows], stack.fscale[rows], stack.order[rows]


def fit_batch(scene, pixels, *, R_L, tol=1e-6, progress=None, chunk=256, curves=None, **options) -> list:
    """:func:`shellbvp.fitting.fit` of each pixel ``(displacement, force, baseline,
    contact_guess, delta_max)`` with one scene and ``options`` (:func:`batchable`), the pixels of
    one model curve (the same ``delta_max``) fitted together in chunks of ``chunk``: a list of
    :class:`FitResult`, or the ``ValueError`` that ``fit`` raises for that pixel, in the order
    of ``pixels``.  ``curves``: a dict in which the model curves are kept for the next call
    (a map fitted in parts)."""
    if not batchable(scene, options):
        raise ValueError(f"fit_batch: these options fit one pixel at a time ({sorted(options)})")
    out, groups = [None] * len(pixels), {}
    kwargs = {k: v for k, v in options.items() if k not in ("mesh_check",)}
    note = auto_model(scene, (), False)[1] if options.get("model", "auto") == "auto" else ""
    kwargs = {k: v for k, v in kwargs.items() if k not in ("progress", "delta_max")}
    for i, (d, f, baseline, guess, delta_max) in enumerate(pixels):
        try:
            inputs = fit_inputs(scene, d, f, R_L=R_L, baseline=baseline, contact_guess=guess, delta_max=delta_max,
                                **kwargs)
        except ValueError as exc:
            out[i] = exc
            continue
        groups.setdefault((inputs.grid.tobytes(), tuple(inputs.mdl.free)), []).append((i, inputs))
    kept = {} if curves is None else curves
    for key, members in groups.items():
        counter = [0]
        if key[0] not in kept:
            node = ModelCurves(lambda th: scene, members[0][1].grid, tol, 0.0, counter, progress)
            try:
                node.add(None)
                kept[key[0]] = (node.nodes[None], node.at(None))
            except ValueError as exc:
                kept[key[0]] = exc
        if isinstance(kept[key[0]], Exception):
            for i, _ in members:
                out[i] = kept[key[0]]
            continue
        c, (P, dP, top) = kept[key[0]]
        fits = []
        for i, inputs in members:
            if c.delta[-1] < inputs.depth * (1 - 1e-12):
                out[i] = ValueError(beyond_message(c, inputs.depth))
            else:
                fits.append((i, inputs))
        shape, computed = SharedShape(P, top), counter[0]
        for lo in range(0, len(fits), chunk):
            part = fits[lo:lo + chunk]
            for (i, inputs), res in zip(part, _fit_chunk(scene, part, c, (P, dP, top), shape, computed)):
                out[i] = dataclasses.replace(res, model_note=note, **inputs.ranges)
            computed = 0  # the curve computed is counted once, on the first pixel fitted with it
    return out


def _fit_chunk(scene, part, curve, interpolated, shape, computed):
    """The FitResults of the pixels ``part`` (``[(index, FitInputs)]``) on one model curve
    (``interpolated``: its ``(P, dP, top)``); ``computed`` curves counted on the first."""
    P, dP, top = interpolated
    mdls = [inputs.mdl for _, inputs in part]
    first = part[0][1]
    stack = Stack(mdls, shape)
    p, rss, J, w, ok, its = stack.irls(first.noise.kind, first.noise.floor, stack.start(mdls, P, top))
    rows = stack.rows(first.noise.kind, first.noise.floor, p, w)
    other = None
    if first.check is not None:
        po, rsso, Jo, wo, _, _ = stack.irls(first.check.kind, first.check.floor, p.copy())
        rows_check = stack.rows(first.check.kind, first.check.floor, po, wo)
    results = []
    for b, (_, inputs) in enumerate(part):
        n, k = stack.n[b], inputs.k
        message = (f"batched Levenberg-Marquardt: the cost's relative change fell below {COST_TOL:g} after "
                   f"{its[b]} iterations" if ok[b] else
                   f"batched Levenberg-Marquardt: no convergence in {its[b]} iterations")
        res = OptimizeResult(x=p[b].copy(), success=bool(ok[b]), message=message, nfev=int(its[b]))
        fitted = Fitted(res, float(rss[b]), J[b, :n], w[b, :n], scene, curve, P, top, dP=dP, rows=float(rows[b]))
        if first.check is not None:
            other = weights_check_of(first.check.kind, float(stack.full(po[b:b + 1])[0, 0]), float(rsso[b]),
                                     Jo[b, :n], max(min(rows_check[b], rows[b]) - k, 1))
        results.append(result_of(fitted, inputs.mdl, None, k, [], inputs.keep, inputs.weights, inputs.baseline,
                                 computed if b == 0 else 0, "shell", inputs.check, refitted=other))
    return results
